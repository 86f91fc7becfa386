"""Thin wrappers around the core's test hooks (pyins_core_testing.h), so the
cross-check tests call C++ functions with the reference's signatures."""
import numpy as np

from pyins import native

ffi, lib = native.ffi, native.lib
if not native.HAS_TEST_HOOKS:
    raise ImportError("the core library was built without PYINS_TEST_HOOKS; "
                      "rebuild with `pip install .` (hooks are on by default)")


def _d(n):
    return ffi.new(f"double[{n}]")


def _in(a):
    a = np.ascontiguousarray(a, dtype=np.float64).ravel()
    return ffi.from_buffer("double[]", a), a


def _out(buf, n):
    return np.frombuffer(ffi.buffer(buf, 8 * n), dtype=np.float64).copy()


def call(name, *arrays, n_out, scalars=()):
    """lib.pyins_t_<name>(*arrays, *scalars, out[n_out]) -> out array."""
    keep = [_in(a) for a in arrays]
    out = _d(n_out)
    getattr(lib, "pyins_t_" + name)(*[k[0] for k in keep], *scalars, out)
    return _out(out, n_out)


def principal_radii(sin_lat):
    rm, rn = _d(1), _d(1)
    lib.pyins_t_principal_radii(sin_lat, rm, rn)
    return rm[0], rn[0]


def normal_gravity(sin_lat, h):
    return lib.pyins_t_normal_gravity(sin_lat, h)


def earth_at(sin_lat, cos_lat, h, vel_n):
    out = ffi.new("pyins_t_earth *")
    v, _keep = _in(vel_n)
    lib.pyins_t_earth_at(sin_lat, cos_lat, h, v, out)
    return out


def position_rate(sin_lat, cos_lat, h, vel_n):
    v, _keep = _in(vel_n)
    out = _d(3)
    lib.pyins_t_position_rate(sin_lat, cos_lat, h, v, out)
    return _out(out, 3)


def quat_mul(p, q):
    return call("quat_mul", p, q, n_out=4)


def quat_normalize(q):
    return call("quat_normalize", q, n_out=4)


def quat_to_mat(q):
    return call("quat_to_mat", q, n_out=9).reshape(3, 3)


def mat_to_quat(m):
    return call("mat_to_quat", m, n_out=4)


def rotvec_to_quat(v):
    return call("rotvec_to_quat", v, n_out=4)


def quat_to_rotvec(q):
    return call("quat_to_rotvec", q, n_out=3)


def rot_z(a):
    out = _d(9)
    lib.pyins_t_rot_z(a, out)
    return _out(out, 9).reshape(3, 3)


def euler_to_mat(e):
    return call("euler_to_mat", e, n_out=9).reshape(3, 3)


def mat_to_euler(m):
    return call("mat_to_euler", m, n_out=3)


def mat_orthonormalize(m):
    return call("mat_orthonormalize", m, n_out=9).reshape(3, 3)


def compensate(dtheta, dv, h):
    """h: a reference strapdown.History."""
    keep = [_in(a) for a in (dtheta, dv, h.dtheta1, h.dv1, h.dtheta2, h.dv2)]
    phi, dvp = _d(3), _d(3)
    lib.pyins_t_compensate(*[k[0] for k in keep], h.count, phi, dvp)
    return _out(phi, 3), _out(dvp, 3)


def strapdown_state(s):
    """A pyins_t_strapdown from a reference Strapdown."""
    c = ffi.new("pyins_t_strapdown *")
    c.lat, c.lon, c.height = s.nav.lat, s.nav.lon, s.nav.height
    for i in range(3):
        c.vel_n[i] = s.nav.vel_n[i]
        c.dtheta1[i] = s.hist.dtheta1[i]
        c.dv1[i] = s.hist.dv1[i]
        c.dtheta2[i] = s.hist.dtheta2[i]
        c.dv2[i] = s.hist.dv2[i]
        c.prev_dvel_n[i] = s.prev_dvel_n[i]
    for i in range(4):
        c.quat_np[i] = s.nav.quat_np[i]
    c.hist_count = s.hist.count
    c.vertical = s.vertical
    c.ref_height = s.ref_height
    return c


def strapdown_update(c, dtheta, dv, dt):
    keep = [_in(a) for a in (dtheta, dv)]
    lib.pyins_t_strapdown_update(c, keep[0][0], keep[1][0], dt)
