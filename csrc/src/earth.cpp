// earth.cpp: see earth.hpp. Mirrored by pyins/reference/earth.py.
#include "earth.hpp"

#include "math_portable.hpp"

namespace pyins::earth {

PrincipalRadii principal_radii(double sin_lat) {
    const double x = 1.0 - kE2 * sin_lat * sin_lat;
    const double sqrt_x = pmath::sqrt(x);
    const double rn = kA / sqrt_x;
    const double rm = rn * (1.0 - kE2) / x;
    return {rm, rn};
}

namespace {

/// gamma0 at height h, s2 = sin^2 L (TR8350.2 eq. 4-3).
double at_height(double gamma0, double s2, double height) {
    const double c1 = 2.0 / kA * (1.0 + kF + kMGrav - 2.0 * kF * s2);
    const double c2 = 3.0 / (kA * kA);
    return gamma0 * (1.0 - c1 * height + c2 * height * height);
}

}  // namespace

double normal_gravity(double sin_lat, double height) {
    const double s2 = sin_lat * sin_lat;
    const double gamma0 = kGammaE * (1.0 + kSomigliana * s2) / pmath::sqrt(1.0 - kE2 * s2);
    return at_height(gamma0, s2, height);
}

Earth earth_at(double sin_lat, double cos_lat, double height, const Vec3& vel_n) {
    const PrincipalRadii r = principal_radii(sin_lat);
    Earth e;
    e.sin_lat = sin_lat;
    e.cos_lat = cos_lat;
    e.rm_h = r.rm + height;
    e.rn_h = r.rn + height;
    e.tan_lat = sin_lat / cos_lat;
    e.omega_ie_n = Vec3(0.0, kOmegaIe * cos_lat, kOmegaIe * sin_lat);
    e.omega_en_n = Vec3(-vel_n(1) / e.rm_h, vel_n(0) / e.rn_h, vel_n(0) / e.rn_h * e.tan_lat);
    e.omega_in_n = e.omega_ie_n + e.omega_en_n;
    e.gravity_n = Vec3(0.0, 0.0, -normal_gravity(sin_lat, height));
    return e;
}

Vec3 position_rate(const Earth& earth, const Vec3& vel_n) {
    const double lat_dot = vel_n(1) / earth.rm_h;
    const double lon_dot = vel_n(0) / (earth.rn_h * earth.cos_lat);
    return Vec3(lat_dot, lon_dot, vel_n(2));
}

PositionTerms position_terms(double lat, double sin_lat, double cos_lat, double height) {
    // four divisions (1 / sqrt(x), the two inverse radii, 1 / cos L) where
    // principal_radii, normal_gravity and earth_at make seven: on the M4F a
    // division is ten multiplications' worth
    const double s2 = sin_lat * sin_lat;
    const double x = 1.0 - kE2 * s2;
    const double inv_sqrt_x = 1.0 / pmath::sqrt(x);
    const double rn = kA * inv_sqrt_x;                               // a / sqrt(x)
    const double rm = rn * (1.0 - kE2) * (inv_sqrt_x * inv_sqrt_x);  // a (1 - e^2) / x^(3/2)
    const double gamma0 = kGammaE * (1.0 + kSomigliana * s2) * inv_sqrt_x;
    const double inv_cos = 1.0 / cos_lat;
    PositionTerms p;
    p.lat = lat;
    p.height = height;
    p.inv_rm_h = 1.0 / (rm + height);
    p.inv_rn_h = 1.0 / (rn + height);
    p.tan_lat = sin_lat * inv_cos;
    p.tan_inv_rn_h = p.tan_lat * p.inv_rn_h;
    p.inv_rn_h_cos = p.inv_rn_h * inv_cos;
    p.sec2_inv_rn_h = p.inv_rn_h_cos * inv_cos;
    p.omega_ie_n = Vec3(0.0, kOmegaIe * cos_lat, kOmegaIe * sin_lat);
    p.gravity = at_height(gamma0, s2, height);
    return p;
}

Vec3 earth_rate(const PositionTerms& p, double d) {
    // cos(L0 + d) = cos L0 - d sin L0, sin(L0 + d) = sin L0 + d cos L0
    return Vec3(0.0, p.omega_ie_n(1) - d * p.omega_ie_n(2), p.omega_ie_n(2) + d * p.omega_ie_n(1));
}

Vec3 transport_rate(const PositionTerms& p, double d, const Vec3& vel_n) {
    return Vec3(-vel_n(1) * p.inv_rm_h, vel_n(0) * p.inv_rn_h,
                vel_n(0) * (p.tan_inv_rn_h + d * p.sec2_inv_rn_h));
}

Vec3 position_rate(const PositionTerms& p, double d, const Vec3& vel_n) {
    return Vec3(vel_n(1) * p.inv_rm_h, vel_n(0) * (p.inv_rn_h_cos * (1.0 + d * p.tan_lat)), vel_n(2));
}

}  // namespace pyins::earth
