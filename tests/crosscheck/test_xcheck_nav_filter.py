"""The navigation filter at sea (nav_filter), C++ (test hooks) against the
NumPy reference, function by function and over runs of ticks with gated
updates (hypothesis). Same operations in the same order: F to an ulp of
its entries; a run's state and covariance within 1e-9 relative (the
matrix products are summed in another order), the NIS likewise."""
import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

import hooks
from pyins.reference import attitude, earth, nav_filter
from pyins.units import ARCMIN_TO_RAD, DEG_TO_RAD, DT, G0

ffi, lib = hooks.ffi, hooks.lib


def _motion(lat, ve, vn, h=0.0):
    sl, cl = np.sin(lat), np.cos(lat)
    rm, rn = earth.principal_radii(sl)
    return nav_filter.Motion(sl, cl, rm + h, rn + h, ve, vn)


def _m6(m):
    return [m.sin_lat, m.cos_lat, m.rm_h, m.rn_h, m.vel_e, m.vel_n]


@settings(max_examples=60, deadline=None)
@given(lat=st.floats(-80.0, 80.0), ve=st.floats(-15.0, 15.0), vn=st.floats(-15.0, 15.0),
       f=st.tuples(st.floats(-2, 2), st.floats(-2, 2), st.floats(8, 12)),
       euler=st.tuples(st.floats(-0.3, 0.3), st.floats(-0.3, 0.3), st.floats(-3.1, 3.1)),
       w_p=st.tuples(st.floats(-0.2, 0.2), st.floats(-0.2, 0.2), st.floats(-0.2, 0.2)))
def test_system_matrix(lat, ve, vn, f, euler, w_p):
    m = _motion(lat * DEG_TO_RAD, ve, vn)
    c = attitude.euler_to_mat(np.array(euler))
    want = nav_filter.system_matrix(m, np.array(f), c, np.array(w_p))
    got = hooks.call("nav_system_matrix", _m6(m), f, c, w_p, n_out=133).reshape(7, 19)
    # the same operations on the same doubles: bit for bit
    assert np.array_equal(got, want)


def _params(every, model=False):
    """model: the filter's model beyond its bias states on (a bias random
    walk, the gyros' scale factors and misalignments as states), else off."""
    return nav_filter.Params(dt=DT, every=every, reject_limit=10, gyro_arw=0.001 * DEG_TO_RAD / 60.0,
                             accel_vrw=10e-6 * G0, gate=13.8155,
                             sigma0_att=np.array([1.0, 1.0, 10.0]) * ARCMIN_TO_RAD, sigma0_vel=0.1,
                             sigma0_pos=10.0, sigma0_gyro=0.01 * DEG_TO_RAD / 3600.0,
                             sigma0_accel=100e-6 * G0,
                             gyro_bias_rw=(0.001 * DEG_TO_RAD / 3600.0 / 60.0) if model else 0.0,
                             table_scale=10e-6 if model else 0.0,
                             table_mis=(10.0 / 206264.8) if model else 0.0,
                             level_scale=10e-6 if model else 0.0,
                             level_mis=(10.0 / 206264.8) if model else 0.0)


@settings(max_examples=25, deadline=None)
@given(seed=st.integers(0, 10_000), every=st.sampled_from([1, 7, 100]), n=st.integers(50, 700),
       lat=st.floats(-70.0, 70.0), speed=st.floats(0.0, 12.0), outlier=st.booleans(),
       model=st.booleans())
def test_filter_run(seed, every, n, lat, speed, outlier, model):
    rng = np.random.default_rng(seed)
    prm = _params(every, model)
    # the angle increments: the ship's swing and slow yaw, and table moves
    # of 0.1 rad a tick for a random number of ticks either way
    dtheta = rng.normal(0.0, 1e-3, (n, 3))
    dtheta[:, 2] += 0.001
    for start in rng.integers(0, n, 3):
        dtheta[start:start + rng.integers(1, 40), 2] += rng.choice([-0.1, 0.1])
    yaw = rng.uniform(-np.pi, np.pi, n)
    euler = np.column_stack([rng.normal(0, 0.05, n), rng.normal(0, 0.05, n), np.cumsum(np.full(n, 0.001)) + yaw[0]])
    c = np.array([attitude.euler_to_mat(e) for e in euler])
    dv = np.tile([0.0, 0.0, 9.8 * DT], (n, 1)) + rng.normal(0, 1e-3, (n, 3))
    motions = [_motion(lat * DEG_TO_RAD, speed * np.cos(a), speed * np.sin(a)) for a in yaw]
    kind = np.zeros(n, dtype=np.int32)
    kind[rng.choice(n, size=max(1, n // 40), replace=False)] = rng.integers(1, 3, max(1, n // 40))
    z = rng.normal(0.0, 3.0, (n, 2))
    if outlier:
        z[rng.integers(0, n)] = [400.0, -300.0]   # a multipath jump: gated out by both
    r = np.where(kind[:, None] == 1, 9.0, 0.0025) * np.ones((n, 2))
    # the reference, step by step as the hook
    f = nav_filter.init(prm, c[0])
    nis_ref = np.zeros(n)
    for k in range(n):
        nav_filter.gather(f, dv[k], dtheta[k])
        if f.ticks == f.prm.every:
            nav_filter.predict(f, motions[k], c[k])
        if kind[k]:
            nav_filter.predict(f, motions[k], c[k])
            row = nav_filter.POS if kind[k] == 1 else nav_filter.VEL
            nis_ref[k] = nav_filter.nis_pair(f, row, z[k], r[k])
            if nis_ref[k] <= prm.gate:
                nav_filter.update_pair(f, row, z[k], r[k])
                nav_filter.reset_feedback(f)
                f.c_start = c[k]
    p = ffi.new("pyins_t_nav_params *")
    for name in ("dt", "every", "reject_limit", "gyro_arw", "accel_vrw", "gate", "sigma0_vel",
                 "sigma0_pos", "sigma0_gyro", "sigma0_accel", "gyro_bias_rw", "table_scale", "table_mis",
                 "level_scale", "level_mis"):
        setattr(p, name, getattr(prm, name))
    p.sigma0_att = list(prm.sigma0_att)
    keep = [np.ascontiguousarray(a, dtype=np.float64) for a in
            (c[0], dv, dtheta, [_m6(m) for m in motions], c.reshape(n, 9), z, r)]
    kinds = np.ascontiguousarray(kind)
    nis = np.zeros(n)
    x_out, p_out, b_out = np.zeros(19), np.zeros(361), np.zeros(13)
    ptr = [ffi.from_buffer("double[]", a) for a in keep]
    lib.pyins_t_nav_filter_run(p, ptr[0], ptr[1], ptr[2], ptr[3], ptr[4], ffi.from_buffer("int32_t[]", kinds),
                               ptr[5], ptr[6], n, ffi.from_buffer("double[]", nis),
                               ffi.from_buffer("double[]", x_out), ffi.from_buffer("double[]", p_out),
                               ffi.from_buffer("double[]", b_out))
    # summation order differs (Eigen's coefficient products, NumPy's @): 1e-9 relative
    assert np.allclose(nis, nis_ref, rtol=1e-9, atol=1e-12)
    scale = np.sqrt(np.outer(np.diag(f.p), np.diag(f.p)))
    assert np.all(np.abs(p_out.reshape(19, 19) - f.p) <= 1e-9 * scale)
    assert np.allclose(b_out, np.concatenate([f.gyro_bias, f.accel_bias, f.table_err, f.level_err]),
                       rtol=1e-8, atol=1e-20)
    # the covariance stays symmetric positive definite (semi-definite with
    # the gyros' scale and misalignment states not modelled: their rows and
    # columns stay 0)
    pc = p_out.reshape(19, 19)
    assert np.array_equal(pc, pc.T)
    live = slice(0, 19) if model else slice(0, nav_filter.TAB)
    assert np.all(np.linalg.eigvalsh(pc[live, live]) > 0.0)
    if not model:
        assert not np.any(pc[nav_filter.TAB:, :]) and not np.any(b_out[6:])
