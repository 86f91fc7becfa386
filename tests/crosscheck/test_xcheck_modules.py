"""C++ core vs NumPy reference, function by function, on random inputs.

Where the two run the same IEEE operations in the same order the results
must be bit-identical (assert_array_equal). Where a portable sin/cos/atan2
(core) stands against NumPy's, each may differ by 1 ulp, so results of unit
magnitude (quaternion and DCM elements, angles below pi) may differ by a
few ulp: TOL_UNIT = 2 eps = 4.44e-16 is 2 ulp at 1.0 (and 1e-15 rad = 2e-10 arc-sec).
"""
import numpy as np
from hypothesis import example, given
from hypothesis import strategies as st
from numpy.testing import assert_allclose, assert_array_equal

import hooks
from pyins.reference import attitude, earth, strapdown
from strategies import euler_angles, finite, heights, latitudes, quaternions, rotation_vectors, vectors

TOL_UNIT = 2.0 * np.finfo(float).eps     # 2 ulp of a unit-magnitude quantity (4.4408921e-16: written
                                         # 4.4e-16 before, which refused an exact 2 ulp at 0.55)
TOL_ANGLE = 1e-15      # rad; angles from atan2 (portable vs libm, 1 ulp of pi ~ 4.4e-16)


@given(lat=latitudes())
@example(lat=0.0)
@example(lat=np.deg2rad(89.0))
def test_principal_radii_and_gravity_bit_identical(lat):
    s = np.sin(lat)
    assert hooks.principal_radii(s) == earth.principal_radii(s)
    for h in (0.0, 380.0, -20.0, 9000.0):
        assert hooks.normal_gravity(s, h) == earth.normal_gravity(s, h)


@given(lat=latitudes(), h=heights(), vel=vectors(30.0))
def test_earth_at_bit_identical(lat, h, vel):
    s, c = np.sin(lat), np.cos(lat)
    got = hooks.earth_at(s, c, h, vel)
    ref = earth.earth_at(s, c, h, vel)
    for name in ("sin_lat", "cos_lat", "tan_lat", "rm_h", "rn_h"):
        assert getattr(got, name) == getattr(ref, name), name
    for name in ("omega_ie_n", "omega_en_n", "omega_in_n", "gravity_n"):
        assert_array_equal(np.array(list(getattr(got, name))), getattr(ref, name), err_msg=name)
    assert_array_equal(hooks.position_rate(s, c, h, vel), earth.position_rate(ref, vel))


@given(p=quaternions(), q=quaternions())
def test_quaternion_algebra_bit_identical(p, q):
    assert_array_equal(hooks.quat_mul(p, q), attitude.quat_mul(p, q))
    assert_array_equal(hooks.quat_normalize(2.5 * q), attitude.quat_normalize(2.5 * q))
    assert_array_equal(hooks.quat_to_mat(q), attitude.quat_to_mat(q))
    m = attitude.quat_to_mat(q)
    assert_array_equal(hooks.mat_to_quat(m), attitude.mat_to_quat(m))
    assert_array_equal(hooks.mat_orthonormalize(m), attitude.mat_orthonormalize(m))


@given(v=rotation_vectors())
@example(v=np.zeros(3))
@example(v=np.array([0.0, 0.0, np.sqrt(1e-3)]))  # series boundary
@example(v=np.array([0.0, 0.0, np.pi]))       # 180 degrees
@example(v=np.array([3.5e-3, -2e-3, 1e-7]))   # one tick of a bad sea state
def test_rotation_vector_conversions(v):
    q_c = hooks.rotvec_to_quat(v)
    q_r = attitude.rotvec_to_quat(v)
    assert_allclose(q_c, q_r, rtol=0, atol=TOL_UNIT)
    if v @ v < attitude.ROTVEC_SERIES2:   # no trig in the series branch
        assert_array_equal(q_c, q_r)
    q = attitude.quat_normalize(q_r)
    assert_allclose(hooks.quat_to_rotvec(q), attitude.quat_to_rotvec(q), rtol=0, atol=TOL_ANGLE)


@given(e=euler_angles())
def test_euler_conversions(e):
    assert_allclose(hooks.euler_to_mat(e), attitude.euler_to_mat(e), rtol=0, atol=TOL_UNIT)
    m = attitude.euler_to_mat(e)
    assert_allclose(hooks.mat_to_euler(m), attitude.mat_to_euler(m), rtol=0, atol=TOL_ANGLE)


@given(a=finite(-20.0, 20.0))
def test_rot_z_and_heading(a):
    assert_allclose(hooks.rot_z(a), attitude.rot_z(a), rtol=0, atol=TOL_UNIT)
    assert hooks.lib.pyins_t_yaw_to_heading(a) == attitude.yaw_to_heading(a)
    assert hooks.lib.pyins_t_heading_to_yaw(a) == attitude.heading_to_yaw(a)


def test_heading_of_tiny_yaws():
    """Yaws below half an ulp of 2 pi give heading 0 (not 2 pi) in both."""
    for yaw in (5e-324, 6.7e-322, 1e-300, 1e-17, 4.4e-16, 1e-15, -1e-17, 0.0, -0.0):
        h = hooks.lib.pyins_t_yaw_to_heading(yaw)
        assert 0.0 <= h < 2 * np.pi
        assert h == attitude.yaw_to_heading(yaw)


def histories():
    return st.builds(strapdown.History, vectors(0.01), vectors(0.5), vectors(0.01), vectors(0.5),
                     st.sampled_from([0, 1, 2]))


@given(dtheta=vectors(0.01), dv=vectors(0.5), h=histories())
def test_compensate_bit_identical(dtheta, dv, h):
    phi_c, dv_c = hooks.compensate(dtheta, dv, h)
    phi_r, dv_r = strapdown.compensate(dtheta, dv, h)[:2]
    assert_array_equal(phi_c, phi_r)
    assert_array_equal(dv_c, dv_r)


@given(lat=latitudes(), h=heights(), vel=vectors(15.0), e=euler_angles(),
       dtheta=vectors(0.005), dv=vectors(0.2), hist=histories(),
       prev_dvel=vectors(0.01), free=st.booleans())
def test_strapdown_update_one_tick(lat, h, vel, e, dtheta, dv, hist, prev_dvel, free):
    """One update from a random state: position to 1e-15 rad (~6 nm), velocity
    to 2 ulps of its largest component (velocities up to 15 m/s: ulps of
    1.8e-15 m/s; 1e-15 m/s absolute, as this test held before, is below one
    ulp above 8 m/s, and a state at 89 deg S once differed by that one ulp),
    attitude to 2 ulp: a few roundings of difference between Eigen's and
    NumPy's 3x3 product and the portable vs libm sin/cos."""
    nav = strapdown.NavState(lat, 0.3, h, vel.copy(), attitude.euler_to_quat(e))
    s = strapdown.make_strapdown(nav, strapdown.VERTICAL_FREE if free else strapdown.VERTICAL_HOLD)
    s.hist, s.prev_dvel_n = hist, prev_dvel
    c = hooks.strapdown_state(s)
    hooks.strapdown_update(c, dtheta, dv, 0.01)
    strapdown.update(s, dtheta, dv, 0.01)
    assert abs(c.lat - s.nav.lat) <= 1e-15 and abs(c.lon - s.nav.lon) <= 1e-15
    assert abs(c.height - s.nav.height) <= 1e-9     # m; h ~ 1e4 m carries 2e-12 m ulps
    assert_allclose(list(c.vel_n), s.nav.vel_n, rtol=0,
                    atol=max(1e-15, 2.0 * float(np.spacing(np.abs(s.nav.vel_n).max()))))
    assert_allclose(list(c.quat_np), s.nav.quat_np, rtol=0, atol=TOL_UNIT)
    assert_array_equal(list(c.dtheta1), dtheta)
    assert_array_equal(list(c.dtheta2), s.hist.dtheta2)
    assert c.hist_count == s.hist.count
