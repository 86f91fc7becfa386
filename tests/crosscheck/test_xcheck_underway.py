"""The coarse alignment under way (PYINS_COARSE_FIT_VEL), C++ against the
NumPy mirror (pyins/reference/coarse_align.py and the firmware around it).

Its pure functions one by one through the test hooks (hypothesis): C_e^n at
the reference point bit for bit (products only); g up^i + C_n^i (w_ie^n x v)
and C_n^i v within 4 ulps of their largest component (pmath's sin and cos
are within 1 ulp of the mirror's libm; 1.05 ulps measured); the solution
from the velocity grid within 1e-12 rad (TRIAD of weighted sums, as FIT's);
the heading sigma bit for bit.

Then the firmware: the built-in scenario under_way (12 kn, 120 s FIT_VEL,
600 s of the navigation filter aided by GNSS) through both engines, every
decision identical and the floats within tests/engines.py's bounds; and two
shorter variants for the paths it does not take: a 200 s alignment (FIT_VEL
halves its 128-point grid), a GNSS antenna's lever arm and an IMU lever arm
(has_lever: place_imu at the references' velocity), and a receiver outage
of 5 s (> kCoarseRefGapS) with 0.3 s of latency (the references reach the
alignment behind its tick), which both engines fault
(PYINS_FAULT_ALIGN_INCONSISTENT).
"""
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import hooks
from engines import assert_engines_agree
from pyins import scenario, units
from pyins.reference import abi, attitude, coarse_align, earth
from pyins.run_scenario import run

ffi, lib = hooks.ffi, hooks.lib
DEG = units.DEG_TO_RAD
ULP = np.finfo(float).eps


def _buf(a):
    return ffi.from_buffer("double[]", np.ascontiguousarray(a, dtype=np.float64))


def _sincos_at(lat_deg, dlon):
    lat = lat_deg * DEG
    return np.sin(lat), np.cos(lat), np.sin(dlon), np.cos(dlon)


# --- the pure functions -------------------------------------------------------
@settings(max_examples=50, deadline=None)
@given(lat=st.floats(-89.0, 89.0), dlon=st.floats(-0.05, 0.05))
def test_mat_n_e_at(lat, dlon):
    sl, cl, sd, cd = _sincos_at(lat, dlon)
    m = ffi.new("double[9]")
    lib.pyins_t_coarse_mat_n_e_at(sl, cl, sd, cd, m)
    want = coarse_align.mat_n_e_at(sl, cl, sd, cd)
    assert np.array_equal(np.array(list(m)).reshape(3, 3), want)
    # a rotation, and the site's C_e^n at dlon = 0
    assert np.abs(want @ want.T - np.eye(3)).max() < 4 * ULP
    assert np.array_equal(coarse_align.mat_n_e_at(sl, cl, 0.0, 1.0), coarse_align.mat_n_e(sl, cl))


@settings(max_examples=100, deadline=None)
@given(t=st.floats(0.0, 3000.0), lat=st.floats(-80.0, 80.0), dlon=st.floats(-0.05, 0.05),
       ve=st.floats(-30.0, 30.0), vn=st.floats(-30.0, 30.0), vu=st.floats(-3.0, 3.0))
def test_known_force_i_and_ref_vel_i(t, lat, dlon, ve, vn, vu):
    sl, cl, sd, cd = _sincos_at(lat, dlon)
    g = earth.normal_gravity(sl, 0.0)
    out = ffi.new("double[3]")
    lib.pyins_t_coarse_known_force_i(t, sl, cl, sd, cd, g, ve, vn, out)
    want = coarse_align.known_force_i(t, sl, cl, sd, cd, g, ve, vn)
    assert np.abs(np.array(list(out)) - want).max() <= 4 * ULP * np.abs(want).max()
    lib.pyins_t_coarse_ref_vel_i(t, sl, cl, sd, cd, ve, vn, vu, out)
    want_v = coarse_align.ref_vel_i(t, sl, cl, sd, cd, ve, vn, vu)
    assert np.abs(np.array(list(out)) - want_v).max() <= 4 * ULP * max(np.abs(want_v).max(), 1e-300)
    # what they are: C_n^i v keeps |v|; at rest the force is g up^i, whose
    # along-axis part is g sin L
    speed = np.sqrt(ve * ve + vn * vn + vu * vu)
    assert abs(np.linalg.norm(want_v) - speed) <= 1e-14 * max(speed, 1.0)
    rest = coarse_align.known_force_i(t, sl, cl, sd, cd, g, 0.0, 0.0)
    assert abs(np.linalg.norm(rest) - g) < 1e-14 * g and abs(rest[2] - g * sl) < 1e-14 * g


def _static_grid(c, n, step, sl, cl, g, rng, noise):
    """v^ib0 and the i side of a static site: v^i = int g up^i (vel_i), v^ib0 =
    C^T (v^i + an unknown constant) and white noise."""
    vi = np.array([coarse_align.vel_i(k * step, sl, cl, g) for k in range(n)])
    vb = (vi + rng.normal(0.0, 1.0, 3)) @ c + rng.normal(0.0, noise, vi.shape)
    return vb, vi


@settings(max_examples=30, deadline=None)
@given(n=st.integers(9, 256), step=st.sampled_from([0.5, 1.0, 2.0, 4.0]),
       euler=st.tuples(st.floats(-3, 3), st.floats(-1.4, 1.4), st.floats(-3, 3)),
       lat=st.floats(-70.0, 70.0), seed=st.integers(0, 1000), noise=st.sampled_from([0.0, 0.05]))
def test_solve_vel_grid(n, step, euler, lat, seed, noise):
    rng = np.random.default_rng(seed)
    sl, cl = np.sin(lat * DEG), np.cos(lat * DEG)
    g = earth.normal_gravity(sl, 0.0)
    c = attitude.euler_to_mat(np.array(euler))
    vb, vi = _static_grid(c, n, step, sl, cl, g, rng, noise)
    m = ffi.new("double[9]")
    lib.pyins_t_coarse_solve_vel_grid(_buf(vb), _buf(vi), n, m)
    want = coarse_align.solve_vel_grid(list(vb), list(vi), n)
    got = np.array(list(m)).reshape(3, 3)
    r = got.T @ want
    assert np.linalg.norm([r[2, 1] - r[1, 2], r[0, 2] - r[2, 0], r[1, 0] - r[0, 1]]) / 2 < 1e-12
    if noise == 0.0:
        # exact vectors: the unknown constant drops out on the grid, C_ib0^i is C
        e = want.T @ c
        assert np.linalg.norm([e[2, 1] - e[1, 2], e[0, 2] - e[2, 0], e[1, 0] - e[0, 1]]) / 2 < 1e-8


@settings(max_examples=50, deadline=None)
@given(n=st.integers(9, 256), step=st.sampled_from([0.01, 0.5, 1.0, 2.0, 4.0]),
       sigma=st.floats(0.001, 1.0), lat=st.floats(-80.0, 80.0))
def test_heading_sigma(n, step, sigma, lat):
    sl, cl = np.sin(lat * DEG), np.cos(lat * DEG)
    g = earth.normal_gravity(sl, 0.0)
    got = lib.pyins_t_coarse_heading_sigma(n, step, sigma * sigma, g, cl)
    assert got == coarse_align.heading_sigma(n, step, sigma * sigma, g, cl)


def test_heading_sigma_is_the_headers():
    """coarse_align.hpp: 50' for 0.05 m/s at 1 Hz over 120 s at 34 deg."""
    sl, cl = np.sin(34.246 * DEG), np.cos(34.246 * DEG)
    s = coarse_align.heading_sigma(121, 1.0, 0.05 ** 2, earth.normal_gravity(sl, 0.0), cl)
    assert 45.0 < s / units.ARCMIN_TO_RAD < 52.0


# --- the firmware ---------------------------------------------------------------
def _variant(*replace, **config):
    """The built-in under_way with text replaced in its file and configuration
    fields set on its run."""
    text = open(scenario.builtin_path("under_way")).read()
    for old, new in replace:
        assert text.count(old) == 1, old
        text = text.replace(old, new)
    spec = next(iter(scenario.loads(text, name="under_way_variant").runs()))
    spec.config.update(config)
    return spec


def _both(spec):
    a = run(spec).outputs
    b = run(spec, engine="reference").outputs
    assert len(a) == len(b) == spec.duration_ticks // spec.every
    return a, b


def test_under_way_the_mirror_aligns_alike():
    """The built-in under_way, its whole 720 s: every decision identical, the
    floats within engines.py's bounds; the coarse alignment's outputs (mode
    COARSE_ALIGN, its attitude once solved) among them."""
    spec = next(iter(scenario.load("under_way").runs()))
    assert spec.config["coarse_method"] == abi.PYINS_COARSE_FIT_VEL
    a, b = _both(spec)
    coarse = a["mode"] == abi.PYINS_MODE_COARSE_ALIGN
    assert coarse.sum() >= 100 and (a["mode"][-1] == abi.PYINS_MODE_NAVIGATE)
    assert (a["fault_flags"] == 0).all()
    # the NIS to 1e-9 absolute (engines.py's bound for NIS of innovations far below
    # their sigma, as test_indexed_alignment's 1e-6): 4.9e-11 measured on a NIS of
    # 0.018 at 614 s, 2.7e-9 of it; the gate decisions are compared exactly
    assert_engines_agree(a, b, nis_abs=1e-9)
    # the coarse phase alone, tighter than the run's bound (nothing but ulps yet)
    assert np.abs(a["quat_np"][coarse] - b["quat_np"][coarse]).max() < 1e-12
    np.testing.assert_array_equal(a["coarse_wander_rad"] > 0, b["coarse_wander_rad"] > 0)
    assert np.abs(a["coarse_wander_rad"] - b["coarse_wander_rad"]).max() < 1e-12


def test_under_way_levers_and_a_grid_that_halves():
    """200 s of FIT_VEL (its 128-point grid halved at 128 s), the antenna 10 m
    forward and 10 m up (simulated and told) and an IMU lever arm told to
    the firmware (not simulated: the voyage has none; the paths are what is
    compared here), 30 s of navigation: the engines alike."""
    spec = _variant(('\nduration = "720 s"', '\nduration = "230 s"'),
                    ('coarse_time = "120 s"', 'coarse_time = "200 s"'),
                    ("seed = 5", 'seed = 5\nlever = ["0 m", "10 m", "10 m"]'),
                    lever_b_m=[1.0, 2.0, -3.0], lever_p_m=[0.1, 0.0, 0.05])
    assert spec.config["gnss_lever_b_m"] == [0.0, 10.0, 10.0]
    a, b = _both(spec)
    assert (a["mode"] == abi.PYINS_MODE_COARSE_ALIGN).sum() >= 190
    assert_engines_agree(a, b)


def test_under_way_a_receiver_outage_faults_both():
    """No fix in [50 s, 55 s) of the alignment (a 5 s gap, over kCoarseRefGapS)
    and the fixes 0.3 s late: both engines end the alignment with
    PYINS_FAULT_ALIGN_INCONSISTENT, and agree throughout."""
    spec = _variant(('\nduration = "720 s"', '\nduration = "130 s"'),
                    ("seed = 5", 'seed = 5\nlatency = "0.3 s"\noutages = [{ start = "50 s", end = "55 s" }]'))
    a, b = _both(spec)
    assert a["fault_flags"][-1] & abi.PYINS_FAULT_ALIGN_INCONSISTENT
    assert not a["fault_flags"][100] & abi.PYINS_FAULT_ALIGN_INCONSISTENT   # at the end of the alignment
    assert_engines_agree(a, b)


@pytest.mark.parametrize("fine_ticks, nav_mode, status", [
    (0, abi.PYINS_NAV_AUTO, abi.PYINS_OK),
    (100, abi.PYINS_NAV_AUTO, abi.PYINS_E_CONFIG_COARSE_METHOD),
    (0, abi.PYINS_NAV_UNDAMPED, abi.PYINS_E_CONFIG_COARSE_METHOD),
])
def test_config_check_under_way(fine_ticks, nav_mode, status):
    """FIT_VEL needs fine_ticks 0 and a navigation filter; it may run past the
    256-point history (it halves its grid): both engines say the same."""
    from pyins import native
    from pyins.reference import c_api, config
    fields = dict(coarse_ticks=40000, coarse_method=abi.PYINS_COARSE_FIT_VEL, fine_ticks=fine_ticks,
                  nav_mode=nav_mode, lat_rad=0.6)
    cfg = native.make_config(fields)
    assert native.lib.pyins_config_check(cfg) == status
    assert config.config_check(c_api.config_from_struct(cfg)) == status
