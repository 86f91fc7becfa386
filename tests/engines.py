"""Holding the C++ core and the NumPy mirror to each other on a run at sea
(tests/atsea): every decision exactly, the floats within bounds far below
anything physical and far above the ulps measured (the mirror's sin, cos
and atan2 are libm's and its sums NumPy's, pyins.reference.c_api: a CI
machine found 1e-19 in a quaternion and 1e-15 in a NIS): position 1e-12
rad (6 um), velocity 1e-9 m/s, the quaternion 0.5e-10 (|dq| ~ angle / 2:
2e-5"), the filter's sigmas and NIS 1e-9 relative, its gyro bias estimate
1e-15 rad/s (2e-10 deg/h)."""
import numpy as np

DECISIONS = ("tick", "mode", "nav_mode", "ref_in_use", "n_ref_used", "n_ref_rejected", "n_ref_skipped",
             "n_ref_stale", "state_flags", "fault_flags")


def assert_engines_agree(a, b):
    """``a``, ``b``: the records (OUTPUT_DTYPE) of the same run through the
    native and the reference engine."""
    for name in DECISIONS:
        assert np.array_equal(a[name], b[name]), name
    assert np.abs(a["lat_rad"] - b["lat_rad"]).max() < 1e-12
    assert np.abs(a["lon_rad"] - b["lon_rad"]).max() < 1e-12
    assert np.abs(a["vel_n_mps"] - b["vel_n_mps"]).max() < 1e-9
    assert np.abs(a["quat_np"] - b["quat_np"]).max() < 0.5e-10
    np.testing.assert_allclose(a["nav_sigma_pos_m"], b["nav_sigma_pos_m"], rtol=1e-9, atol=0.0)
    np.testing.assert_allclose(a["nav_sigma_heading_rad"], b["nav_sigma_heading_rad"], rtol=1e-9, atol=0.0)
    np.testing.assert_allclose(a["nav_nis"], b["nav_nis"], rtol=1e-9, atol=1e-12)
    assert np.abs(a["nav_gyro_bias_rad_s"] - b["nav_gyro_bias_rad_s"]).max() < 1e-15
