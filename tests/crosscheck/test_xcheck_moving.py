"""The moving-base functions one by one, C++ (test hooks) against the NumPy
reference (hypothesis): FIT's closed-form P^i, its weights, its solution on
random grids, the rotation sine of the wander test, and the 12-state
moving-base filter. Same operations in the same order: the scalar functions
agree to an ulp; the solution within 1e-12 rad (TRIAD of weighted sums);
the filter within 1e-9 relative (matrix products summed in another order)."""
import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

import hooks
from pyins.reference import attitude, coarse_align, earth, moving_align  # noqa: I001
from pyins.units import DT
from pyins import units

ffi, lib = hooks.ffi, hooks.lib
DEG = units.DEG_TO_RAD


@settings(max_examples=50, deadline=None)
@given(t=st.floats(0.0, 3000.0), lat=st.floats(-80.0, 80.0))
def test_pos_i_and_weights(t, lat):
    sl, cl = np.sin(lat * DEG), np.cos(lat * DEG)
    g = earth.normal_gravity(sl, 0.0)
    out = ffi.new("double[3]")
    lib.pyins_t_coarse_pos_i(t, sl, cl, g, out)
    want = coarse_align.pos_i(t, sl, cl, g)
    assert np.all(np.abs(np.array(list(out)) - want) <= 2e-16 * np.maximum(np.abs(want), 1e-300))
    s = t / 3000.0
    a, b = ffi.new("double *"), ffi.new("double *")
    lib.pyins_t_coarse_fit_weights(s, a, b)
    assert (a[0], b[0]) == coarse_align.fit_weights(s)


@settings(max_examples=30, deadline=None)
@given(n=st.integers(9, 256), step=st.sampled_from([0.5, 1.0, 2.0, 4.0]),
       euler=st.tuples(st.floats(-3, 3), st.floats(-1.4, 1.4), st.floats(-3, 3)),
       lat=st.floats(-70.0, 70.0), seed=st.integers(0, 1000))
def test_solve_fit(n, step, euler, lat, seed):
    rng = np.random.default_rng(seed)
    sl, cl = np.sin(lat * DEG), np.cos(lat * DEG)
    g = earth.normal_gravity(sl, 0.0)
    c = attitude.euler_to_mat(np.array(euler))
    grid = np.array([c @ coarse_align.pos_i(k * step, sl, cl, g) for k in range(n)])
    grid = grid + rng.normal(0.0, 0.3, grid.shape) + rng.normal(0.0, 0.5, 3) * (np.arange(n) * step)[:, None]
    grid[0] = 0.0
    m = ffi.new("double[9]")
    lib.pyins_t_coarse_solve_fit(ffi.from_buffer("double[]", np.ascontiguousarray(grid)), n, step,
                                 sl, cl, g, m)
    want = coarse_align.solve_fit(list(grid), n, step, sl, cl, g)
    got = np.array(list(m)).reshape(3, 3)
    r = got.T @ want
    assert np.linalg.norm([r[2, 1] - r[1, 2], r[0, 2] - r[2, 0], r[1, 0] - r[0, 1]]) / 2 < 1e-12


@settings(max_examples=50, deadline=None)
@given(e1=st.tuples(st.floats(-3, 3), st.floats(-1.5, 1.5), st.floats(-3, 3)),
       e2=st.tuples(st.floats(-3, 3), st.floats(-1.5, 1.5), st.floats(-3, 3)))
def test_rotation_sine(e1, e2):
    a, b = attitude.euler_to_mat(np.array(e1)), attitude.euler_to_mat(np.array(e2))
    got = lib.pyins_t_coarse_rotation_sine(ffi.from_buffer("double[]", np.ascontiguousarray(a)),
                                           ffi.from_buffer("double[]", np.ascontiguousarray(b)))
    want = coarse_align.rotation_sine(a, b)
    assert abs(got - want) <= 1e-15
    # and it is the sine of the angle between them (1 beyond 90 deg)
    angle = np.linalg.norm(attitude.quat_to_rotvec(attitude.mat_to_quat(a.T @ b)))
    assert abs(want - (np.sin(angle) if angle < np.pi / 2 else 1.0)) < 1e-12


_MOVING_FIELDS = ("sin_lat", "cos_lat", "rm_h", "rn_h", "dt", "meas_every", "nis_window", "gyro_arw",
                  "accel_vrw", "pos_sigma", "sigma0_vel", "sigma0_gyro", "sigma0_accel", "nis_max",
                  "site_accel")


def _fill(cp, prm):
    """The hook's pyins_t_moving_params from a moving_align.Params."""
    for name in _MOVING_FIELDS:
        setattr(cp, name, getattr(prm, name))
    for i in range(3):
        cp.sigma0_att[i] = prm.sigma0_att[i]


@settings(max_examples=50, deadline=None)
@given(lat=st.floats(-70.0, 70.0), coarse_s=st.floats(20.0, 3600.0), wander=st.floats(0.0, 0.02),
       site=st.sampled_from([0.0, 1e-4, 1e-3, 9.8e-3, 5e-2]), seed=st.integers(0, 1000))
def test_sigma0_after_coarse_bit_identical(lat, coarse_s, wander, site, seed):
    """The prior the site motion leaves a coarse result: C++ == NumPy bit for bit; nothing
    changes on a rigid site; and the heading's share is the header's q / (k sqrt(3 T^3))."""
    rng = np.random.default_rng(seed)
    sl, cl = np.sin(lat * DEG), np.cos(lat * DEG)
    rm, rn = earth.principal_radii(sl)
    g = earth.normal_gravity(sl, 0.0)
    att = rng.uniform(1e-4, 1e-2, 3)
    prm = moving_align.Params(
        sin_lat=sl, cos_lat=cl, rm_h=rm, rn_h=rn, dt=DT, meas_every=100, gyro_arw=1e-6,
        accel_vrw=1e-4, pos_sigma=0.5, site_accel=site, sigma0_att=att.copy(), sigma0_vel=0.5,
        sigma0_gyro=5e-8, sigma0_accel=1e-3)
    cp = ffi.new("pyins_t_moving_params *")
    _fill(cp, prm)
    out = ffi.new("double[3]")
    lib.pyins_t_moving_sigma0_after_coarse(cp, coarse_s, wander, g, out)
    moving_align.sigma0_after_coarse(prm, coarse_s, wander, g)
    assert list(out) == list(prm.sigma0_att)
    if site == 0.0:
        assert list(prm.sigma0_att) == list(att)
    else:
        k = g * earth.OMEGA_IE * cl / 6.0
        heading = site / (k * np.sqrt(3.0 * coarse_s ** 3))
        want = np.sqrt(att[2] ** 2 + 9.0 * (heading ** 2 + wander ** 2))
        assert abs(prm.sigma0_att[2] - want) <= 1e-12 * want


@settings(max_examples=15, deadline=None)
@given(lat=st.floats(-70.0, 70.0), every=st.sampled_from([10, 50, 100]), n=st.integers(100, 2500),
       window=st.sampled_from([0, 3, 10]), seed=st.integers(0, 1000), site=st.sampled_from([False, True]))
def test_moving_align_filter(lat, every, n, window, seed, site):
    rng = np.random.default_rng(seed)
    sl, cl = np.sin(lat * DEG), np.cos(lat * DEG)
    rm, rn = earth.principal_radii(sl)
    prm = moving_align.Params(
        sin_lat=sl, cos_lat=cl, rm_h=rm, rn_h=rn, dt=DT, meas_every=every,
        gyro_arw=rng.uniform(1e-7, 1e-5), accel_vrw=rng.uniform(1e-5, 1e-3),
        pos_sigma=rng.uniform(0.05, 1.0), site_accel=rng.uniform(1e-4, 3e-2) if site else 0.0,
        sigma0_att=rng.uniform(1e-4, 1e-2, 3),
        sigma0_vel=rng.uniform(0.05, 1.0), sigma0_gyro=rng.uniform(1e-8, 1e-6),
        sigma0_accel=rng.uniform(1e-5, 1e-3), nis_window=window, nis_max=4.0)
    dv = np.tile([0.0, 0.0, 9.8 * 0.01], (n, 1)) + rng.normal(0.0, 1e-4, (n, 3))
    z = rng.normal(0.0, 0.3, (n, 2))
    m = moving_align.init(prm)
    updates = sum(moving_align.step(m, dv[k], z[k]) for k in range(n))
    cp = ffi.new("pyins_t_moving_params *")
    _fill(cp, prm)
    x = ffi.new("double[12]")
    p = ffi.new("double[144]")
    nis = ffi.new("double *")
    got = lib.pyins_t_moving_align_run(cp, ffi.from_buffer("double[]", np.ascontiguousarray(dv)),
                                       ffi.from_buffer("double[]", np.ascontiguousarray(z)), n, x, p, nis)
    assert got == updates == n // every
    sig = np.sqrt(np.diag(m.p))
    xc = np.array(list(x))
    pc = np.array(list(p)).reshape(12, 12)
    assert np.all(np.abs(xc - m.x) <= 1e-9 * np.maximum(np.abs(m.x), sig))
    assert np.all(np.abs(pc - m.p) <= 1e-9 * np.outer(sig, sig))
    assert abs(nis[0] - m.nis_mean) <= 1e-9 * max(m.nis_mean, 1e-12)


@settings(max_examples=50, deadline=None)
@given(euler=st.tuples(st.floats(-3, 3), st.floats(-1.4, 1.4), st.floats(-3, 3)),
       lat=st.floats(-70.0, 70.0), t2=st.floats(20.0, 255.0), r=st.sampled_from([0.25, 0.5, 0.75]),
       seed=st.integers(0, 1000))
def test_solve_eq8_bit_identical(euler, lat, t2, r, seed):
    """Seed 000 eq. 8 as printed (EQ8): C++ == NumPy bit for bit on noisy vector pairs;
    on exact ones (v^ib0 = C^T v^i) it is C within 1e-9 (the inverse of a nearly singular
    A: |v1 x v2| / |v1| |v2| is ~w t_k2 (1 - r) ~ 1e-3 at 20 s)."""
    rng = np.random.default_rng(seed)
    sl, cl = np.sin(lat * DEG), np.cos(lat * DEG)
    g = earth.normal_gravity(sl, 0.0)
    c = attitude.euler_to_mat(np.array(euler))
    vi1, vi2 = coarse_align.vel_i(r * t2, sl, cl, g), coarse_align.vel_i(t2, sl, cl, g)
    for noise in (0.0, 0.01):
        vb1 = c.T @ vi1 + rng.normal(0.0, noise, 3)
        vb2 = c.T @ vi2 + rng.normal(0.0, noise, 3)
        m = ffi.new("double[9]")
        buf = [ffi.from_buffer("double[]", np.ascontiguousarray(v)) for v in (vi1, vi2, vb1, vb2)]
        lib.pyins_t_coarse_solve_eq8(*buf, m)
        got = np.array(list(m)).reshape(3, 3)
        want = coarse_align.solve_eq8(vi1, vi2, vb1, vb2)
        assert np.array_equal(got, want)
        if noise == 0.0:
            assert np.abs(want - c).max() < 1e-9


def test_moving_base_with_site_motion_firmware_cpp_equals_reference():
    """The firmware with the site-motion model (fine_site_accel): 40 s of FIT on the ranging
    ship, then 60 s of the moving-base filter, the prior from sigma0_after_coarse; the C core
    and the NumPy mirror record by record (the tolerances of test_xcheck_lever's moving base:
    one longitude ulp is 2.4e-9 of the 0.5 m measurement sigma, a random walk of them over
    the updates stays under 1e-7 sigma)."""
    from pyins import native, scenario, sim
    from pyins.reference import firmware as ref_firmware
    m = sim.moored("general", 34.246 * DEG, 108.91 * DEG, 0.0, 0.7)
    m.linear = sim.LinearMotion(heave=m.linear.heave, surge=(*m.linear.surge, (0.5, 120.0, 0.0)),
                                sway=(*m.linear.sway, (0.5, 120.0, np.pi / 2)))
    cfg = scenario.initial_config(m, None, coarse_ticks=4000, coarse_method=1, fine_ticks=6000,
                                  fine_states=12, fine_site_accel=9.8e-3)
    n = 10000
    dtheta, dv, alpha = sim.exact_increments(m, n)
    out_c = native.Firmware(cfg).run(native.make_samples(dtheta, dv, alpha), every=100)
    ref = ref_firmware.Firmware(cfg)
    j = 0
    for k in range(n):
        status, r = ref.step(dtheta[k], dv[k], alpha[k])
        assert status == 0
        if (k + 1) % 100:
            continue
        c = out_c[j]
        j += 1
        assert c["tick"] == r["tick"] and c["state_flags"] == r["state_flags"], k
        q_err = attitude.quat_mul(c["quat_np"], attitude.quat_conj(r["quat_np"]))
        assert np.linalg.norm(attitude.quat_to_rotvec(attitude.quat_normalize(q_err))) < 1e-10, k
        floor = 1e-7 * np.maximum(np.abs(r["kf_sigma"]), 1e-12)
        assert np.all(np.abs(c["kf_sigma"] - r["kf_sigma"]) <= 1e-9 * np.abs(r["kf_sigma"]) + floor), k
        assert np.all(np.abs(c["kf_x"] - r["kf_x"]) <= 1e-9 * np.abs(r["kf_x"]) + floor), k
    assert j == n // 100
    # the prior took the site term: 40 s of FIT leave phi_U far more than the default 10'
    assert out_c["kf_sigma"][40, 2] > 100.0 * units.ARCMIN_TO_RAD
