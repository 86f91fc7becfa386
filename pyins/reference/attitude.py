"""Attitude: quaternions, direction cosine matrices, Euler angles, rotation vectors.

Mirrors ``csrc/src/attitude.{hpp,cpp}``, same names, same order of operations.

Conventions (docs/design.md §2)
-------------------------------
- Quaternions are Hamilton, scalar first, ``[w, x, y, z]``. ``quat_nb`` rotates
  a vector from b to n: ``v_n = quat_nb (x) v_b (x) conj(quat_nb)``.
- ``mat_nb`` is C_b^n (columns are the b axes expressed in n).
- Euler angles ``[pitch, roll, yaw]`` with C_b^n = Rz(yaw) Rx(pitch) Ry(roll):
  pitch about x (starboard), roll about y (bow), yaw about z (up). Yaw is
  counter-clockwise positive from North. The marine heading is clockwise from
  North in [0, 2 pi): ``heading = (-yaw) mod 2 pi`` (``yaw_to_heading``).
- A rotation vector ``v`` is the rotation by |v| about v / |v|.

References
----------
- Qin Yongyuan, "Inertial Navigation" (2014), sec. 9.2 (quaternion, rotation
  vector), sec. 9.1 / eq. 9.1.26 (Euler angles from C_b^n, ENU, z-x-y order).
- Shepperd (1978), "Quaternion from rotation matrix", J. Guidance 1(3).
"""
import numpy as np

#: Below this squared angle [rad^2] rotvec_to_quat uses its Taylor series to
#: theta^6 (attitude.hpp: kRotvecSeries2). At theta^2 = 1e-3 (31.6 mrad, 181
#: deg/s at 100 Hz) the first omitted terms are < 1e-19 relative.
ROTVEC_SERIES2 = 1e-3
ROTVEC_TINY2 = 1e-7    #: kRotvecTiny2: below it the series' first term alone
COS2, COS4, COS6 = 1.0 / 8.0, 1.0 / 384.0, 1.0 / 46080.0      #: kCos2, kCos4, kCos6
SIN2, SIN4, SIN6 = 1.0 / 48.0, 1.0 / 3840.0, 1.0 / 645120.0   #: kSin2, kSin4, kSin6

TWO_PI = 2.0 * np.pi


def skew(v):
    """Cross-product matrix: skew(a) @ b == cross(a, b)."""
    return np.array([[0.0, -v[2], v[1]],
                     [v[2], 0.0, -v[0]],
                     [-v[1], v[0], 0.0]])


def cross(a, b):
    """a x b, written out (mirrors pyins::attitude::cross)."""
    return np.array([a[1] * b[2] - a[2] * b[1],
                     a[2] * b[0] - a[0] * b[2],
                     a[0] * b[1] - a[1] * b[0]])


def quat_mul(p, q):
    """Hamilton product p (x) q."""
    pw, px, py, pz = p
    qw, qx, qy, qz = q
    return np.array([
        pw * qw - px * qx - py * qy - pz * qz,
        pw * qx + px * qw + py * qz - pz * qy,
        pw * qy - px * qz + py * qw + pz * qx,
        pw * qz + px * qy - py * qx + pz * qw,
    ])


def quat_mul_z(p, c, s):
    """quat_mul(p, [c, 0, 0, s]) without the terms multiplied by zero
    (mirrors pyins::attitude::quat_mul_z)."""
    return np.array([p[0] * c - p[3] * s, p[1] * c + p[2] * s, p[2] * c - p[1] * s, p[0] * s + p[3] * c])


def quat_conj(q):
    return np.array([q[0], -q[1], -q[2], -q[3]])


def quat_normalize(q):
    """Unit quaternion with non-negative scalar part."""
    n = np.sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3])
    if q[0] < 0.0:
        n = -n
    inv = 1.0 / n
    return np.array([q[0] * inv, q[1] * inv, q[2] * inv, q[3] * inv])


RENORM_MAX = 1e-8   #: kRenormMax


def quat_renormalize(q):
    """quat_normalize for a q unit to rounding: q (3 - |q|^2) / 2, one
    Newton step of 1 / sqrt from 1 (mirrors pyins::attitude::quat_renormalize;
    attitude.hpp gives the error); further from unit, quat_normalize."""
    n2 = q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]
    if not abs(n2 - 1.0) <= RENORM_MAX:
        return quat_normalize(q)
    k = 1.5 - 0.5 * n2
    if q[0] < 0.0:
        k = -k
    return np.array([q[0] * k, q[1] * k, q[2] * k, q[3] * k])


def quat_rotate(q, v):
    """q v q* for a unit q, written out: t = 2 r x v, v' = v + w t + r x t
    (mirrors pyins::attitude::quat_rotate)."""
    r = np.array([q[1], q[2], q[3]])
    t = 2.0 * cross(r, v)
    return v + q[0] * t + cross(r, t)


def quat_to_mat(q):
    """C from a unit quaternion (Qin 2014 eq. 9.2.34)."""
    w, x, y, z = q
    ww, xx, yy, zz = w * w, x * x, y * y, z * z
    xy, xz, yz = x * y, x * z, y * z
    wx, wy, wz = w * x, w * y, w * z
    return np.array([
        [ww + xx - yy - zz, 2.0 * (xy - wz), 2.0 * (xz + wy)],
        [2.0 * (xy + wz), ww - xx + yy - zz, 2.0 * (yz - wx)],
        [2.0 * (xz - wy), 2.0 * (yz + wx), ww - xx - yy + zz],
    ])


def mat_to_quat(m):
    """Unit quaternion (w >= 0) from a rotation matrix, Shepperd's method.

    Picks the largest of 4w^2, 4x^2, 4y^2, 4z^2 as the pivot so the square
    root never takes a small argument.
    """
    tr = m[0, 0] + m[1, 1] + m[2, 2]
    if tr >= m[0, 0] and tr >= m[1, 1] and tr >= m[2, 2]:
        s = 2.0 * np.sqrt(1.0 + tr)
        q = np.array([0.25 * s, (m[2, 1] - m[1, 2]) / s,
                      (m[0, 2] - m[2, 0]) / s, (m[1, 0] - m[0, 1]) / s])
    elif m[0, 0] >= m[1, 1] and m[0, 0] >= m[2, 2]:
        s = 2.0 * np.sqrt(1.0 + m[0, 0] - m[1, 1] - m[2, 2])
        q = np.array([(m[2, 1] - m[1, 2]) / s, 0.25 * s,
                      (m[0, 1] + m[1, 0]) / s, (m[0, 2] + m[2, 0]) / s])
    elif m[1, 1] >= m[2, 2]:
        s = 2.0 * np.sqrt(1.0 - m[0, 0] + m[1, 1] - m[2, 2])
        q = np.array([(m[0, 2] - m[2, 0]) / s, (m[0, 1] + m[1, 0]) / s,
                      0.25 * s, (m[1, 2] + m[2, 1]) / s])
    else:
        s = 2.0 * np.sqrt(1.0 - m[0, 0] - m[1, 1] + m[2, 2])
        q = np.array([(m[1, 0] - m[0, 1]) / s, (m[0, 2] + m[2, 0]) / s,
                      (m[1, 2] + m[2, 1]) / s, 0.25 * s])
    return quat_normalize(q)


def rotvec_to_quat(v):
    """Quaternion of the rotation vector v (Qin 2014 eq. 9.2.44).

    Small-angle branch: Taylor series of cos(theta/2) and sin(theta/2)/theta
    to theta^6 (Horner form) when theta^2 < ROTVEC_SERIES2, to theta^2 when
    theta^2 < ROTVEC_TINY2 (what it leaves out is under half an ulp).
    """
    theta2 = v[0] * v[0] + v[1] * v[1] + v[2] * v[2]
    if theta2 < ROTVEC_TINY2:
        c = 1.0 - theta2 * COS2
        s = 0.5 - theta2 * SIN2
    elif theta2 < ROTVEC_SERIES2:
        c = 1.0 - theta2 * (COS2 - theta2 * (COS4 - theta2 * COS6))
        s = 0.5 - theta2 * (SIN2 - theta2 * (SIN4 - theta2 * SIN6))
    else:
        theta = np.sqrt(theta2)
        half = 0.5 * theta
        c = np.cos(half)
        s = np.sin(half) / theta
    return np.array([c, s * v[0], s * v[1], s * v[2]])


def quat_to_rotvec(q):
    """Rotation vector of a unit quaternion, angle in [0, pi].

    Small-angle branch: 2 atan2(r, w) / r = (2 / w)(1 - t^2 / 3) with t = r / w
    when t < 1e-5 (first omitted term t^4 / 5 < 1e-20).
    """
    if q[0] < 0.0:
        q = -q
    r = np.sqrt(q[1] * q[1] + q[2] * q[2] + q[3] * q[3])
    if r < 1e-5 * q[0]:
        t = r / q[0]
        k = 2.0 / q[0] * (1.0 - t * t / 3.0)
    else:
        k = 2.0 * np.arctan2(r, q[0]) / r
    return np.array([k * q[1], k * q[2], k * q[3]])


def rotvec_to_mat(v):
    return quat_to_mat(rotvec_to_quat(v))


def rot_z(angle):
    """Rz(angle): rotation by angle about z, counter-clockwise seen from +z.

    C_p^b = rot_z(alpha) for the turntable angle alpha (docs/design.md §2).
    """
    c = np.cos(angle)
    s = np.sin(angle)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def euler_to_mat(euler):
    """C_b^n = Rz(yaw) Rx(pitch) Ry(roll) from [pitch, roll, yaw]."""
    sp, cp = np.sin(euler[0]), np.cos(euler[0])
    sr, cr = np.sin(euler[1]), np.cos(euler[1])
    sy, cy = np.sin(euler[2]), np.cos(euler[2])
    return np.array([
        [cy * cr - sy * sp * sr, -sy * cp, cy * sr + sy * sp * cr],
        [sy * cr + cy * sp * sr, cy * cp, sy * sr - cy * sp * cr],
        [-cp * sr, sp, cp * cr],
    ])


def mat_to_euler(m):
    """[pitch, roll, yaw] from C_b^n (Qin 2014 eq. 9.1.26 form).

    pitch = atan2(C21, sqrt(C20^2 + C22^2)) in [-pi/2, pi/2] (well conditioned
    near +-90 deg, unlike asin), roll = atan2(-C20, C22), yaw = atan2(-C01, C11).
    At exactly +-90 deg pitch roll and yaw are not separable; the formulas then
    return what atan2(0, 0) gives.
    """
    return _euler_of(m[2, 0], m[2, 1], m[2, 2], m[0, 1], m[1, 1])


def _euler_of(c20, c21, c22, c01, c11):
    """[pitch, roll, yaw] from the five elements of C_b^n they depend on
    (mirrors euler_of in attitude.cpp)."""
    pitch = np.arctan2(c21, np.sqrt(c20 * c20 + c22 * c22))
    roll = np.arctan2(-c20, c22)
    yaw = np.arctan2(-c01, c11)
    return np.array([pitch, roll, yaw])


def euler_to_quat(euler):
    return mat_to_quat(euler_to_mat(euler))


def quat_to_euler(q):
    """The five elements of quat_to_mat(q) the angles read, by its
    expressions (mirrors quat_to_euler: the same values as
    mat_to_euler(quat_to_mat(q)))."""
    w, x, y, z = q
    ww, xx, yy, zz = w * w, x * x, y * y, z * z
    return _euler_of(2.0 * (x * z - w * y), 2.0 * (y * z + w * x), ww - xx - yy + zz,
                     2.0 * (x * y - w * z), ww - xx + yy - zz)


def mat_orthonormalize(m):
    """Nearest proper rotation, through the normalised Shepperd quaternion."""
    return quat_to_mat(mat_to_quat(m))


def yaw_to_heading(yaw):
    """Marine heading [rad], clockwise from North in [0, 2 pi), from yaw (CCW)."""
    if -np.pi < yaw <= np.pi:      # the usual case (yaw from atan2): no fmod
        h = -yaw
        if h < 0.0:
            # a yaw below half an ulp of 2 pi (4.4e-16) rounds to 2 pi: north
            w = h + TWO_PI
            return w if w < TWO_PI else 0.0
        return h + 0.0   # + 0.0 turns -0.0 into +0.0
    h = np.fmod(-yaw, TWO_PI)
    if h < 0.0:
        h = h + TWO_PI
    if h >= TWO_PI:
        h = 0.0
    return h + 0.0  # turns -0.0 into +0.0


def heading_to_yaw(heading):
    """Yaw [rad], counter-clockwise from North in (-pi, pi], from marine heading."""
    y = np.fmod(-heading, TWO_PI)
    if y <= -np.pi:
        y = y + TWO_PI
    elif y > np.pi:
        y = y - TWO_PI
    return y
