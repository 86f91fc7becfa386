"""The configuration contract: the C core's pyins_config_check against the
mirror's config.config_check (pyins/reference/config.py), on random
configurations (hypothesis) whose fields sit on and around every limit the
checks hold them to: the same status, the first one that applies.
"""
import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from pyins import native
from pyins.reference import abi, c_api, config

NAN, INF = float("nan"), float("inf")


def values(*edges):
    return st.sampled_from(list(edges))


FIELDS = {
    "tick_hz": values(0, 1, 100, 10000, 10001, -1),
    "vertical_mode": values(0, 1, 2, -1),
    "lat_rad": values(0.0, 0.5, config.MAX_LAT_RAD, np.nextafter(config.MAX_LAT_RAD, 2.0), -1.6, NAN),
    "lon_rad": values(0.0, 3.5, -7.0, 4.0 * np.pi, 13.0, INF),
    "height_m": values(0.0, -1e4, 1e5, 1.0001e5, NAN),
    "vel_n_mps": values([0.0, 0.0, 0.0], [1e4, -1e4, 0.0], [0.0, 1.0001e4, 0.0], [NAN, 0.0, 0.0]),
    "table_angle_rad": values(0.0, -2.0, INF),
    "coarse_ticks": values(0, 100, 2000, 30000, -1),
    "coarse_first_output_ticks": values(0, 50, 100, 2001, -1),
    "coarse_output_every_ticks": values(0, 10, 100, 1000, -1),
    "coarse_ratio": values(0.0, 0.5, 0.999, 1.0, -0.5, NAN),
    "coarse_method": values(0, 1, 2, 3, -1),
    "fine_ticks": values(0, 100, -1),
    "fine_states": values(0, 5, 8, 12, 6),
    "fine_meas_every_ticks": values(0, 1, -1),
    "fine_correction": values(0, 1, 2),
    "fine_gyro_arw": values(0.0, 1e-7, -1e-7, INF),
    "fine_sigma0_att_rad": values([0.0, 0.0, 0.0], [1e-3, 1e-3, 1e-2], [0.0, -1.0, 0.0]),
    "fine_pos_sigma_m": values(0.0, 1.0, NAN),
    "fine_site_accel": values(0.0, 9.8e-3, -1e-3, INF),
    "index_scheme": values(0, 1, 2, 3, 4, 5, 6, 7, 8, -1),
    "index_stop_ticks": values(0, 1, -5),
    "index_n_steps": values(0, 1, 2, 8, 9),
    "index_steps": values([], [(100, 1, np.pi)], [(100, 2, 1.0), (100, 3, -1.0)], [(0, 1, 1.0)],
                          [(10, 1, 0.0)], [(10, 4, 1.0)], [(10, 1, 17.0 * np.pi)]),
    "index_rate_rad_s": values(0.0, 0.1, -0.1, INF),
    "index_delta": values(0.0, 0.01, 1.0, -0.5),
    "index_tolerance_rad": values(0.0, 0.01, -0.01),
    "index_timeout_ticks": values(0, 10, -1),
    "index_sums": values(0, 1, 2),
    "seq_mode": values(0, 1, 2),
    "seq_max_gap_ticks": values(0, 1, 100, 101, -1),
    "sat_gyro_rad": values(0.0, 0.1, -0.1, NAN),
    "lever_b_m": values([0.0, 0.0, 0.0], [60.0, 80.0, 0.0], [60.0, 80.1, 0.0], [INF, 0.0, 0.0]),
    "integrity_nis_window": values(0, -1, -2, 50),
    "integrity_nis_max": values(0.0, 4.0, -1.0, INF),
    "integrity_coarse_rad": values(0.0, 0.01, -0.01, NAN),
    # the DVL's mounting (ABI 0.16): a rotation of at most pi, an arm of at most 100 m
    "dvl_align_rad": values([0.0, 0.0, 0.0], [0.0, 0.0, np.pi], [0.0, 0.0, np.nextafter(np.pi, 4.0)],
                            [1.0, 2.0, 2.0], [0.0, NAN, 0.0]),
    "dvl_lever_b_m": values([0.0, 0.0, 0.0], [0.0, 60.0, -80.0], [0.0, 60.0, -80.1], [0.0, 0.0, -INF]),
    # the GNSS antenna's lever arm: at most 100 m
    "gnss_lever_b_m": values([0.0, 0.0, 0.0], [1.0, 5.0, 25.0], [0.0, 80.0, 60.1], [NAN, 0.0, 0.0]),
    "nav_gyro_bias_rw": values(0.0, 1e-11, config.MAX_NAV_GYRO_BIAS_RW,
                               np.nextafter(config.MAX_NAV_GYRO_BIAS_RW, 1.0), -1e-12, NAN, INF),
    "nav_table_scale_sigma": values(0.0, 1e-5, config.MAX_NAV_TABLE_SIGMA, 0.0100001, -1e-6, NAN),
    "nav_table_mis_sigma": values(0.0, 4.8e-5, config.MAX_NAV_TABLE_SIGMA, 0.0100001, -1e-6, INF),
    "nav_level_scale_sigma": values(0.0, 1e-5, config.MAX_NAV_TABLE_SIGMA, 0.0100001, -1e-6, NAN),
    "nav_level_mis_sigma": values(0.0, 4.8e-5, config.MAX_NAV_TABLE_SIGMA, 0.0100001, -1e-6, INF),
}


@settings(max_examples=400, deadline=None)
@given(st.fixed_dictionaries({}, optional=FIELDS))
def test_config_check_equals_the_core(fields):
    cfg = native.make_config(fields)
    want = native.lib.pyins_config_check(cfg)
    assert config.config_check(c_api.config_from_struct(cfg)) == want


def test_the_default_configuration_is_the_zeroed_struct():
    cfg = native.make_config()
    mirror = c_api.config_from_struct(cfg)
    default = config.config_default()
    assert sorted(default) == sorted(mirror)
    for name, value in default.items():
        if name == "index_steps":
            assert all(tuple(s) == (0, 0, 0.0) for s in mirror[name])
        else:
            np.testing.assert_array_equal(mirror[name], value, err_msg=name)
    assert config.config_check(default) == abi.PYINS_OK
