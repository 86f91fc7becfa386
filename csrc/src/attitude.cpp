// attitude.cpp: see attitude.hpp. Mirrored by pyins/reference/attitude.py.
#include "attitude.hpp"

#include <cmath>

#include "math_portable.hpp"
#include "units.hpp"

namespace pyins::attitude {

Mat3 skew(const Vec3& v) {
    Mat3 m;
    m << 0.0, -v(2), v(1),
         v(2), 0.0, -v(0),
         -v(1), v(0), 0.0;
    return m;
}

Vec3 cross(const Vec3& a, const Vec3& b) {
    return Vec3(a(1) * b(2) - a(2) * b(1),
                a(2) * b(0) - a(0) * b(2),
                a(0) * b(1) - a(1) * b(0));
}

Quat quat_mul(const Quat& p, const Quat& q) {
    return Quat{
        p.w * q.w - p.x * q.x - p.y * q.y - p.z * q.z,
        p.w * q.x + p.x * q.w + p.y * q.z - p.z * q.y,
        p.w * q.y - p.x * q.z + p.y * q.w + p.z * q.x,
        p.w * q.z + p.x * q.y - p.y * q.x + p.z * q.w,
    };
}

Quat quat_mul_z(const Quat& p, double c, double s) {
    return Quat{p.w * c - p.z * s, p.x * c + p.y * s, p.y * c - p.x * s, p.w * s + p.z * c};
}

Quat quat_conj(const Quat& q) { return Quat{q.w, -q.x, -q.y, -q.z}; }

Quat quat_normalize(const Quat& q) {
    double n = pmath::sqrt(q.w * q.w + q.x * q.x + q.y * q.y + q.z * q.z);
    if (q.w < 0.0) {
        n = -n;
    }
    const double inv = 1.0 / n;
    return Quat{q.w * inv, q.x * inv, q.y * inv, q.z * inv};
}

Vec3 quat_rotate(const Quat& q, const Vec3& v) {
    const Vec3 r(q.x, q.y, q.z);
    const Vec3 t = 2.0 * cross(r, v);
    return v + q.w * t + cross(r, t);
}

Mat3 quat_to_mat(const Quat& q) {
    const double ww = q.w * q.w, xx = q.x * q.x, yy = q.y * q.y, zz = q.z * q.z;
    const double xy = q.x * q.y, xz = q.x * q.z, yz = q.y * q.z;
    const double wx = q.w * q.x, wy = q.w * q.y, wz = q.w * q.z;
    Mat3 m;
    m << ww + xx - yy - zz, 2.0 * (xy - wz), 2.0 * (xz + wy),
         2.0 * (xy + wz), ww - xx + yy - zz, 2.0 * (yz - wx),
         2.0 * (xz - wy), 2.0 * (yz + wx), ww - xx - yy + zz;
    return m;
}

Quat mat_to_quat(const Mat3& m) {
    const double tr = m(0, 0) + m(1, 1) + m(2, 2);
    Quat q;
    if (tr >= m(0, 0) && tr >= m(1, 1) && tr >= m(2, 2)) {
        const double s = 2.0 * pmath::sqrt(1.0 + tr);
        q = Quat{0.25 * s, (m(2, 1) - m(1, 2)) / s, (m(0, 2) - m(2, 0)) / s, (m(1, 0) - m(0, 1)) / s};
    } else if (m(0, 0) >= m(1, 1) && m(0, 0) >= m(2, 2)) {
        const double s = 2.0 * pmath::sqrt(1.0 + m(0, 0) - m(1, 1) - m(2, 2));
        q = Quat{(m(2, 1) - m(1, 2)) / s, 0.25 * s, (m(0, 1) + m(1, 0)) / s, (m(0, 2) + m(2, 0)) / s};
    } else if (m(1, 1) >= m(2, 2)) {
        const double s = 2.0 * pmath::sqrt(1.0 - m(0, 0) + m(1, 1) - m(2, 2));
        q = Quat{(m(0, 2) - m(2, 0)) / s, (m(0, 1) + m(1, 0)) / s, 0.25 * s, (m(1, 2) + m(2, 1)) / s};
    } else {
        const double s = 2.0 * pmath::sqrt(1.0 - m(0, 0) - m(1, 1) + m(2, 2));
        q = Quat{(m(1, 0) - m(0, 1)) / s, (m(0, 2) + m(2, 0)) / s, (m(1, 2) + m(2, 1)) / s, 0.25 * s};
    }
    return quat_normalize(q);
}

Quat rotvec_to_quat(const Vec3& v) {
    const double theta2 = v(0) * v(0) + v(1) * v(1) + v(2) * v(2);
    double c;
    double s;
    if (theta2 < kRotvecTiny2) {
        c = 1.0 - theta2 * kCos2;
        s = 0.5 - theta2 * kSin2;
    } else if (theta2 < kRotvecSeries2) {
        c = 1.0 - theta2 * (kCos2 - theta2 * (kCos4 - theta2 * kCos6));
        s = 0.5 - theta2 * (kSin2 - theta2 * (kSin4 - theta2 * kSin6));
    } else {
        const double theta = pmath::sqrt(theta2);
        const double half = 0.5 * theta;
        double sin_half;
        pmath::sincos(half, &sin_half, &c);
        s = sin_half / theta;
    }
    return Quat{c, s * v(0), s * v(1), s * v(2)};
}

Vec3 quat_to_rotvec(const Quat& q_in) {
    Quat q = q_in;
    if (q.w < 0.0) {
        q = Quat{-q.w, -q.x, -q.y, -q.z};
    }
    const double r = pmath::sqrt(q.x * q.x + q.y * q.y + q.z * q.z);
    double k;
    if (r < 1e-5 * q.w) {
        const double t = r / q.w;
        k = 2.0 / q.w * (1.0 - t * t / 3.0);
    } else {
        k = 2.0 * pmath::atan2(r, q.w) / r;
    }
    return Vec3(k * q.x, k * q.y, k * q.z);
}

Mat3 rotvec_to_mat(const Vec3& v) { return quat_to_mat(rotvec_to_quat(v)); }

Mat3 rot_z(double angle) {
    double s;
    double c;
    pmath::sincos(angle, &s, &c);
    Mat3 m;
    m << c, -s, 0.0,
         s, c, 0.0,
         0.0, 0.0, 1.0;
    return m;
}

Mat3 euler_to_mat(const Vec3& euler) {
    double sp, cp, sr, cr, sy, cy;
    pmath::sincos(euler(0), &sp, &cp);
    pmath::sincos(euler(1), &sr, &cr);
    pmath::sincos(euler(2), &sy, &cy);
    Mat3 m;
    m << cy * cr - sy * sp * sr, -sy * cp, cy * sr + sy * sp * cr,
         sy * cr + cy * sp * sr, cy * cp, sy * sr - cy * sp * cr,
         -cp * sr, sp, cp * cr;
    return m;
}

namespace {

/// [pitch, roll, yaw] from the five elements of C_b^n they depend on.
Vec3 euler_of(double c20, double c21, double c22, double c01, double c11) {
    const double pitch = pmath::atan2(c21, pmath::sqrt(c20 * c20 + c22 * c22));
    const double roll = pmath::atan2(-c20, c22);
    const double yaw = pmath::atan2(-c01, c11);
    return Vec3(pitch, roll, yaw);
}

}  // namespace

Vec3 mat_to_euler(const Mat3& m) { return euler_of(m(2, 0), m(2, 1), m(2, 2), m(0, 1), m(1, 1)); }

Quat euler_to_quat(const Vec3& euler) { return mat_to_quat(euler_to_mat(euler)); }

Vec3 quat_to_euler(const Quat& q) {
    // the five elements of quat_to_mat(q) the angles read, by its expressions
    // (the same bits as mat_to_euler(quat_to_mat(q)); 4 elements fewer)
    const double ww = q.w * q.w, xx = q.x * q.x, yy = q.y * q.y, zz = q.z * q.z;
    return euler_of(2.0 * (q.x * q.z - q.w * q.y), 2.0 * (q.y * q.z + q.w * q.x), ww - xx - yy + zz,
                    2.0 * (q.x * q.y - q.w * q.z), ww - xx + yy - zz);
}

Mat3 mat_orthonormalize(const Mat3& m) { return quat_to_mat(mat_to_quat(m)); }

// std::fmod is exact in IEEE arithmetic (its result is representable), so it
// gives the same bits on glibc and newlib, unlike sin/cos/atan2.
double yaw_to_heading(double yaw) {
    if (yaw > -kPi && yaw <= kPi) {  // the usual case (yaw from atan2): no fmod
        const double h = -yaw;
        if (h < 0.0) {
            // a yaw below half an ulp of 2 pi (4.4e-16) rounds to 2 pi: north
            const double w = h + kTwoPi;
            return w < kTwoPi ? w : 0.0;
        }
        return h + 0.0;  // + 0.0 turns -0.0 into +0.0
    }
    double h = std::fmod(-yaw, kTwoPi);
    if (h < 0.0) {
        h = h + kTwoPi;
    }
    if (h >= kTwoPi) {
        h = 0.0;
    }
    return h + 0.0;  // turns -0.0 into +0.0
}

double heading_to_yaw(double heading) {
    double y = std::fmod(-heading, kTwoPi);
    if (y <= -kPi) {
        y = y + kTwoPi;
    } else if (y > kPi) {
        y = y - kTwoPi;
    }
    return y;
}

}  // namespace pyins::attitude
