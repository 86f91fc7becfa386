"""Holding the C++ core and the NumPy mirror to each other on a run at sea
(tests/atsea): every decision exactly, the floats within bounds far below
anything physical and far above the ulps measured (the mirror's sin, cos
and atan2 are libm's and its sums NumPy's, pyins.reference.c_api: a CI
machine found 1e-19 in a quaternion and 1e-15 in a NIS): position 1e-12
rad (6 um), velocity 1e-9 m/s, the quaternion 0.5e-10 (|dq| ~ angle / 2:
2e-5"), the filter's sigmas and NIS 1e-9 relative, its gyro bias estimate
1e-15 rad/s (2e-10 deg/h), its scale-factor and misalignment estimates
1e-12."""
import numpy as np

DECISIONS = ("tick", "mode", "nav_mode", "ref_in_use", "n_ref_used", "n_ref_rejected", "n_ref_skipped",
             "n_ref_stale", "state_flags", "fault_flags")


def assert_engines_agree(a, b, nis_abs=None):
    """``a``, ``b``: the records (OUTPUT_DTYPE) of the same run through the
    native and the reference engine. ``nis_abs``: hold the NIS to that
    absolute bound instead of 1e-9 relative, for runs whose NIS are of
    innovations far below their sigma's scale (zero velocity at 0.001 m/s
    on a still site: 5e-9 relative measured on a NIS of 0.012 after 6 min).
    What a NIS decides is its gate (13.8) and the decisions are compared
    exactly above; tools/engines_agree_1h.py holds it to 1e-6 likewise."""
    for name in DECISIONS:
        assert np.array_equal(a[name], b[name]), name
    assert np.abs(a["lat_rad"] - b["lat_rad"]).max() < 1e-12
    assert np.abs(a["lon_rad"] - b["lon_rad"]).max() < 1e-12
    assert np.abs(a["vel_n_mps"] - b["vel_n_mps"]).max() < 1e-9
    assert np.abs(a["quat_np"] - b["quat_np"]).max() < 0.5e-10
    np.testing.assert_allclose(a["nav_sigma_pos_m"], b["nav_sigma_pos_m"], rtol=1e-9, atol=0.0)
    np.testing.assert_allclose(a["nav_sigma_heading_rad"], b["nav_sigma_heading_rad"], rtol=1e-9, atol=0.0)
    if nis_abs is None:
        np.testing.assert_allclose(a["nav_nis"], b["nav_nis"], rtol=1e-9, atol=1e-12)
    else:
        assert np.abs(a["nav_nis"] - b["nav_nis"]).max() < nis_abs
    assert np.abs(a["nav_gyro_bias_rad_s"] - b["nav_gyro_bias_rad_s"]).max() < 1e-15
    # the scale factors and misalignments (ABI 0.19): 1e-12 is 2e-8 of a
    # 10 ppm / 10" prior, as 1e-15 rad/s is of a 0.003 deg/h drift
    assert np.abs(a["nav_table_err"] - b["nav_table_err"]).max() < 1e-12
    assert np.abs(a["nav_level_err"] - b["nav_level_err"]).max() < 1e-12
