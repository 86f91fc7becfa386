"""Invariants of the attitude module (NumPy reference, and the C++ core
through its hooks): unit quaternions, proper orthonormal DCMs, and the round
trips Euler <-> DCM <-> quaternion <-> rotation vector.

Tolerances: 1e-15 to 2.2e-15 on unit quantities is 5 to 10 ulp, the rounding
of a few chained products; round trips through atan2 near pitch = +-89 deg lose up to
~1e-13 rad (the conditioning of roll/yaw there grows as 1/cos(pitch) ~ 57).
"""
import numpy as np
from hypothesis import given
from hypothesis import strategies as st
from numpy.testing import assert_allclose

import hooks
from pyins.reference import attitude
from pyins.units import DEG_TO_RAD
from strategies import euler_angles, quaternions, rotation_vectors, unit_vectors

ENGINES = {"reference": attitude, "core": hooks}


def _proper_rotation(m):
    # 2.2e-15 = 10 ulp at 1.0: each DCM element sums four products of
    # quaternion components, and m m^T and det(m) add three more products,
    # so a handful of roundings is expected; a non-rotation would be off by O(1).
    assert_allclose(m @ m.T, np.eye(3), rtol=0, atol=2.2e-15)
    assert abs(np.linalg.det(m) - 1.0) < 2.2e-15


def _same_rotation(q1, q2, atol):
    # q and -q are the same rotation
    assert min(np.max(np.abs(q1 - q2)), np.max(np.abs(q1 + q2))) <= atol


@given(v=rotation_vectors())
def test_rotvec_quat_roundtrip(v):
    for mod in ENGINES.values():
        q = mod.rotvec_to_quat(v)
        assert abs(np.linalg.norm(q) - 1.0) < 1e-15
        _proper_rotation(mod.quat_to_mat(q))
        back = mod.quat_to_rotvec(attitude.quat_normalize(q))
        angle = np.linalg.norm(v)
        if angle < np.pi - 1e-6:       # at pi, v and -v are the same rotation
            assert_allclose(back, v, rtol=0, atol=1e-15 * max(1.0, angle))


@given(q=quaternions())
def test_quat_dcm_roundtrip(q):
    for mod in ENGINES.values():
        m = mod.quat_to_mat(q)
        _proper_rotation(m)
        _same_rotation(mod.mat_to_quat(m), q, 1e-15)


@given(e=euler_angles())
def test_euler_dcm_quat_roundtrip(e):
    for mod in ENGINES.values():
        m = mod.euler_to_mat(e)
        _proper_rotation(m)
        tol = 1e-15 / max(np.cos(e[0]), 1e-2) * 10
        assert_allclose(_wrapped(mod.mat_to_euler(m) - e), 0.0, rtol=0, atol=tol)
        q = mod.mat_to_quat(m)
        assert_allclose(_wrapped(mod.mat_to_euler(mod.quat_to_mat(q)) - e), 0.0, rtol=0, atol=tol)


def _wrapped(d):
    """Angle differences in [-pi, pi): roll or yaw -pi and +pi are one angle,
    and atan2 returns either at the boundary (the flaky +-pi round trip)."""
    return (np.asarray(d) + np.pi) % (2.0 * np.pi) - np.pi


@given(e=euler_angles())
def test_euler_convention(e):
    """C_b^n = Rz(yaw) Rx(pitch) Ry(roll); the bow of a level ship at yaw psi
    points to [-sin psi, cos psi, 0] (yaw counter-clockwise from North)."""
    pitch, roll, yaw = e
    rx = np.array([[1, 0, 0], [0, np.cos(pitch), -np.sin(pitch)], [0, np.sin(pitch), np.cos(pitch)]])
    ry = np.array([[np.cos(roll), 0, np.sin(roll)], [0, 1, 0], [-np.sin(roll), 0, np.cos(roll)]])
    assert_allclose(attitude.euler_to_mat(e), attitude.rot_z(yaw) @ rx @ ry, rtol=0, atol=1e-15)
    level = attitude.euler_to_mat([0.0, 0.0, yaw])
    assert_allclose(level @ [0, 1, 0], [-np.sin(yaw), np.cos(yaw), 0], atol=1e-15)


def test_heading_and_yaw():
    deg = DEG_TO_RAD
    assert attitude.yaw_to_heading(0.0) == 0.0
    assert np.signbit(attitude.yaw_to_heading(-0.0)) is np.False_ or attitude.yaw_to_heading(-0.0) == 0.0
    assert not np.signbit(attitude.yaw_to_heading(0.0))
    assert abs(attitude.yaw_to_heading(90 * deg) - 270 * deg) < 1e-15   # west
    assert abs(attitude.yaw_to_heading(-90 * deg) - 90 * deg) < 1e-15   # east
    assert abs(attitude.heading_to_yaw(90 * deg) + 90 * deg) < 1e-15
    for h in np.linspace(0, 2 * np.pi, 37, endpoint=False):
        assert abs(attitude.yaw_to_heading(attitude.heading_to_yaw(h)) - h) < 1e-14
    # a yaw a hair west of north (below half an ulp of 2 pi) is heading 0, not
    # 2 pi (found by the C ABI fuzzer, tests/fuzz/regressions)
    for yaw in (5e-324, 6.7e-322, 1e-300, 1e-17, 4.4e-16):
        h = attitude.yaw_to_heading(yaw)
        assert 0.0 <= h < 2 * np.pi, (yaw, h)
    assert attitude.yaw_to_heading(1e-15) == 2 * np.pi - 1e-15


@given(angle=st.floats(1e-9, np.sqrt(attitude.ROTVEC_SERIES2)), u=unit_vectors())
def test_rotvec_series_branch_equals_closed_form(angle, u):
    """The Taylor branches (to theta^6, and to theta^2 alone below
    ROTVEC_TINY2, where a tick's rotation of n always is) must agree with
    cos/sin to 1 ulp (2.2e-16) where they are used, or a switch would put a
    step into the attitude."""
    v = u * angle
    half = 0.5 * angle
    closed = np.concatenate([[np.cos(half)], np.sin(half) / angle * v])
    assert_allclose(attitude.rotvec_to_quat(v), closed, rtol=0, atol=2.2e-16)


@given(q=quaternions(), v1=st.tuples(*[st.floats(-1, 1)] * 3), v2=st.tuples(*[st.floats(-1, 1)] * 3),
       noise=st.floats(0.0, 1e-3))
def test_coarse_triad_is_a_rotation_and_exact_without_noise(q, v1, v2, noise):
    """The TRIAD replacing seed 000 eq. 8 is a proper rotation even with
    noisy vectors, and recovers the rotation exactly from noise-free ones."""
    from hypothesis import assume

    from pyins.reference import coarse_align
    v1, v2 = np.array(v1), np.array(v2)
    assume(np.linalg.norm(np.cross(v1, v2)) > 1e-2 and np.linalg.norm(v2) > 1e-2)
    c = attitude.quat_to_mat(q)
    exact = coarse_align.solve_mat_i_ib0(c @ v1, c @ v2, v1, v2)
    assert_allclose(exact, c, rtol=0, atol=1e-13)   # conditioning of the pair, >= 1e-2
    noisy = coarse_align.solve_mat_i_ib0(c @ v1 + noise, c @ v2 - noise, v1, v2)
    _proper_rotation(noisy)


@given(q=quaternions(), angle=st.floats(-np.pi, np.pi))
def test_quat_mul_z_is_quat_mul_bit_for_bit(q, angle):
    """The record's ship attitude q_np [c, 0, 0, s] by the product without
    its zero terms: the same bits as the full product for finite nonzero
    components (the golden records depend on it)."""
    c, s = np.cos(0.5 * angle), np.sin(0.5 * angle)
    full = attitude.quat_mul(q, np.array([c, 0.0, 0.0, s]))
    short = attitude.quat_mul_z(q, c, s)
    nonzero = full != 0.0
    assert full[nonzero].tobytes() == short[nonzero].tobytes()
    assert np.all(short[~nonzero] == 0.0)


@given(q=quaternions(), e=st.floats(-1e-8, 1e-8), far=st.floats(1e-7, 0.5))
def test_quat_renormalize_is_exact_near_unit_and_normalizes_far_from_it(q, e, far):
    """One Newton step from |q|^2 = 1 + e leaves |q|^2 - 1 ~ 3 e^2 / 4: for
    |e| <= 1e-8 (the renormalised quaternion is a product of unit ones, e ~
    1e-15) as near unit as quat_normalize's result and within 2 ulps of it;
    further from unit it is quat_normalize."""
    near = q * np.sqrt(1.0 + e)
    r = attitude.quat_renormalize(near)
    n = attitude.quat_normalize(near)
    # |r|^2 as far from 1 as the divided one's, to 2 ulps (4.4e-16: the
    # sum of four squares rounds too)
    assert abs(np.dot(r, r) - 1.0) <= abs(np.dot(n, n) - 1.0) + 4.5e-16
    assert_allclose(r, n, rtol=0, atol=4.5e-16)
    q_far = q * np.sqrt(1.0 + far)
    assert attitude.quat_renormalize(q_far).tobytes() == attitude.quat_normalize(q_far).tobytes()
