// attitude.hpp: quaternions, DCMs, Euler angles, rotation vectors.
//
// Mirrored by pyins/reference/attitude.py (same names, same operation order).
// Conventions (docs/design.md §2): Hamilton quaternions [w, x, y, z]; quat_nb and
// mat_nb map b to n; Euler [pitch, roll, yaw] with C_b^n = Rz(yaw) Rx(pitch)
// Ry(roll); yaw counter-clockwise from North; heading = (-yaw) mod 2 pi.
//
// References: Qin Yongyuan, "Inertial Navigation" (2014) secs. 9.1-9.2;
// Shepperd (1978), J. Guidance 1(3) (quaternion from a rotation matrix).
#pragma once

#include <cmath>

#include "types.hpp"

namespace pyins::attitude {

/// Below this squared angle [rad^2] rotvec_to_quat uses its Taylor series to
/// theta^6. At theta^2 = 1e-3 (theta = 31.6 mrad, 181 deg/s at 100 Hz, above
/// any ship motion) the first omitted terms are < 1e-19 relative, far below
/// an ulp, and every per-tick rotation avoids sqrt, sin, cos and a division.
inline constexpr double kRotvecSeries2 = 1e-3;
/// Below this squared angle [rad^2] the series stops at theta^2: the terms
/// left out, t^4/384 and t^4/3840, are < 2.6e-17, under half an ulp of c
/// (~1) and of s (~1/2). Every tick's rotation of n (Earth and transport
/// rate, ~1e-6 rad) and an IMU turning < 1.8 deg/s at 100 Hz take it.
inline constexpr double kRotvecTiny2 = 1e-7;
/// Series coefficients: cos(t/2) = 1 - t^2/8 + t^4/384 - t^6/46080,
/// sin(t/2)/t = 1/2 - t^2/48 + t^4/3840 - t^6/645120.
inline constexpr double kCos2 = 1.0 / 8.0;
inline constexpr double kCos4 = 1.0 / 384.0;
inline constexpr double kCos6 = 1.0 / 46080.0;
inline constexpr double kSin2 = 1.0 / 48.0;
inline constexpr double kSin4 = 1.0 / 3840.0;
inline constexpr double kSin6 = 1.0 / 645120.0;

Mat3 skew(const Vec3& v);
/// a x b, written out so the operation order is the reference's.
Vec3 cross(const Vec3& a, const Vec3& b);

Quat quat_mul(const Quat& p, const Quat& q);
/// quat_mul(p, [c, 0, 0, s]): the product with a rotation about z, without
/// the terms multiplied by zero (8 products where quat_mul makes 16; the
/// same bits for finite p but for the sign of a component that is zero).
Quat quat_mul_z(const Quat& p, double c, double s);
Quat quat_conj(const Quat& q);
/// Unit quaternion with non-negative scalar part.
Quat quat_normalize(const Quat& q);
/// Largest | |q|^2 - 1 | quat_renormalize corrects by its Newton step.
inline constexpr double kRenormMax = 1e-8;
/// quat_normalize for a q that is unit to rounding (a product of unit
/// quaternions): q (3 - |q|^2) / 2, one Newton step of 1 / sqrt from 1,
/// whose norm is 1 - (3/4) e^2 for |q|^2 = 1 + e (below an ulp for
/// |e| <= kRenormMax); a q further from unit goes to quat_normalize. No
/// square root or division (the Cortex-M4F's two dearest operations).
/// Defined here: it is inlined into every tick's update and record, where
/// a call and a returned Quat would cost as much as its 20 flops.
inline Quat quat_renormalize(const Quat& q) {
    const double n2 = q.w * q.w + q.x * q.x + q.y * q.y + q.z * q.z;
    if (!(std::fabs(n2 - 1.0) <= kRenormMax)) {  // also a NaN
        return quat_normalize(q);
    }
    double k = 1.5 - 0.5 * n2;
    if (q.w < 0.0) {
        k = -k;
    }
    return Quat{q.w * k, q.x * k, q.y * k, q.z * k};
}
/// q v q* for a unit quaternion q (= quat_to_mat(q) v), as the sandwich
/// product written out: t = 2 r x v, v' = v + w t + r x t, r = [x, y, z]
/// (30 flops against 45 for the matrix and its product).
Vec3 quat_rotate(const Quat& q, const Vec3& v);
/// C from a unit quaternion. Qin (2014) eq. 9.2.34.
Mat3 quat_to_mat(const Quat& q);
/// Unit quaternion (w >= 0) from a rotation matrix, Shepperd's method.
Quat mat_to_quat(const Mat3& m);
/// Quaternion of a rotation vector. Qin (2014) eq. 9.2.44; series branch
/// when |v|^2 < kRotvecSeries2, its first term alone below kRotvecTiny2.
Quat rotvec_to_quat(const Vec3& v);
/// Rotation vector of a unit quaternion, angle in [0, pi].
Vec3 quat_to_rotvec(const Quat& q);
Mat3 rotvec_to_mat(const Vec3& v);
/// Rz(angle), counter-clockwise about +z; C_p^b = rot_z(alpha).
Mat3 rot_z(double angle);
/// C_b^n = Rz(yaw) Rx(pitch) Ry(roll) from [pitch, roll, yaw].
Mat3 euler_to_mat(const Vec3& euler);
/// [pitch, roll, yaw] from C_b^n; pitch in [-pi/2, pi/2]. Qin (2014) 9.1.26.
Vec3 mat_to_euler(const Mat3& m);
Quat euler_to_quat(const Vec3& euler);
Vec3 quat_to_euler(const Quat& q);
/// Nearest proper rotation, through the normalised Shepperd quaternion.
Mat3 mat_orthonormalize(const Mat3& m);
/// Marine heading in [0, 2 pi), clockwise from North, from yaw.
double yaw_to_heading(double yaw);
/// Yaw in (-pi, pi], counter-clockwise from North, from marine heading.
double heading_to_yaw(double heading);

}  // namespace pyins::attitude
