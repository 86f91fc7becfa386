// strapdown.cpp: see strapdown.hpp. Mirrored by pyins/reference/strapdown.py.
#include "strapdown.hpp"

#include <cmath>

#include "attitude.hpp"
#include "earth.hpp"
#include "math_portable.hpp"
#include "units.hpp"

namespace pyins::strapdown {

using attitude::cross;

Compensated compensate(const Vec3& dtheta, const Vec3& dv, const History& h) {
    Compensated c;
    Vec3 cone = Vec3::Zero();
    Vec3 scul = Vec3::Zero();
    c.cone_near = Vec3::Zero();
    c.scul_near = Vec3::Zero();
    if (h.count >= 1) {
        c.cone_near = cross(h.dtheta1, dtheta);
        c.scul_near = cross(h.dtheta1, dv) + cross(h.dv1, dtheta);
    }
    if (h.count >= 2) {
        cone = kC3Near * c.cone_near + kC3Far * cross(h.dtheta2, dtheta) + kC3Past * h.cone1;
        scul = kC3Near * c.scul_near + kC3Far * (cross(h.dtheta2, dv) + cross(h.dv2, dtheta)) +
               kC3Past * h.scul1;
    } else if (h.count == 1) {
        cone = kOneTwelfth * c.cone_near;
        scul = kOneTwelfth * c.scul_near;
    }
    c.phi = dtheta + cone;
    const Vec3 dv_rot = 0.5 * cross(dtheta, dv) + kOneSixth * cross(dtheta, cross(dtheta, dv));
    c.dv_p = dv + dv_rot + scul;
    return c;
}

void push_history(History& h, const Vec3& dtheta, const Vec3& dv, const Compensated& c) {
    h.dtheta2 = h.dtheta1;
    h.dv2 = h.dv1;
    h.dtheta1 = dtheta;
    h.dv1 = dv;
    h.cone1 = c.cone_near;
    h.scul1 = c.scul_near;
    if (h.count < 2) {
        h.count = h.count + 1;
    }
}

History history_of(const Vec3& dtheta1, const Vec3& dv1, const Vec3& dtheta2, const Vec3& dv2, int count) {
    History h;
    h.dtheta1 = dtheta1;
    h.dv1 = dv1;
    h.dtheta2 = dtheta2;
    h.dv2 = dv2;
    h.count = count;
    h.cone1 = cross(dtheta2, dtheta1);
    h.scul1 = cross(dtheta2, dv1) + cross(dv2, dtheta1);
    return h;
}

void lat_sincos(Strapdown& s, double* sin_lat, double* cos_lat) {
    double d = s.nav.lat - s.lat0;
    if (!(std::fabs(d) <= kLatAnchorStep)) {  // also a NaN
        s.lat0 = s.nav.lat;
        pmath::sincos(s.lat0, &s.sin_lat0, &s.cos_lat0);
        d = 0.0;
    }
    const double d2 = d * d;
    const double cd = 1.0 - d2 * (0.5 - d2 * (1.0 / 24.0));
    const double sd = d * (1.0 - d2 * (1.0 / 6.0));
    *sin_lat = s.sin_lat0 * cd + s.cos_lat0 * sd;
    *cos_lat = s.cos_lat0 * cd - s.sin_lat0 * sd;
}

const earth::PositionTerms& position_terms(Strapdown& s) {
    if (!(std::fabs(s.nav.lat - s.terms.lat) <= kTermsLatStep &&
          std::fabs(s.nav.height - s.terms.height) <= kTermsHeightStep)) {  // also a NaN
        double sin_lat;
        double cos_lat;
        lat_sincos(s, &sin_lat, &cos_lat);
        s.terms = earth::position_terms(s.nav.lat, sin_lat, cos_lat, s.nav.height);
    }
    return s.terms;
}

Strapdown make_strapdown(const NavState& nav, Vertical vertical) {
    Strapdown s;
    s.nav = nav;
    s.lat0 = nav.lat;
    pmath::sincos(s.lat0, &s.sin_lat0, &s.cos_lat0);
    s.terms = earth::position_terms(nav.lat, s.sin_lat0, s.cos_lat0, nav.height);
    s.hist.dtheta1 = Vec3::Zero();
    s.hist.dv1 = Vec3::Zero();
    s.hist.dtheta2 = Vec3::Zero();
    s.hist.dv2 = Vec3::Zero();
    s.hist.count = 0;
    s.hist.cone1 = Vec3::Zero();
    s.hist.scul1 = Vec3::Zero();
    s.prev_dvel_n = Vec3::Zero();
    s.vertical = vertical;
    s.ref_height = nav.height;
    s.ref_lon = nav.lon;
    if (vertical == Vertical::kHold) {
        s.nav.vel_n(2) = 0.0;
    }
    return s;
}

PYINS_HOT_FLATTEN Vec3 update(Strapdown& s, const Vec3& dtheta_p, const Vec3& dv_p, double dt) {
    // 1. Coning, sculling and rotation compensation (strapdown.hpp).
    const Compensated c = compensate(dtheta_p, dv_p, s.hist);

    // 2. Earth quantities at the start position (the terms kept near it,
    //    strapdown.hpp) with the velocity extrapolated to mid-tick (Yan 2019
    //    sec. 4.1.4). The position is not extrapolated: half a tick moves a
    //    ship < 0.1 m, which changes gravity by < 1e-9 m/s^2.
    const Vec3 vel_mid = s.nav.vel_n + 0.5 * s.prev_dvel_n;
    const earth::PositionTerms& p = position_terms(s);
    const double d = s.nav.lat - p.lat;   // |d| <= kTermsLatStep
    const Vec3 omega_ie_n = earth::earth_rate(p, d);
    const Vec3 omega_en_n = earth::transport_rate(p, d, vel_mid);
    const Vec3 omega_in_n = omega_ie_n + omega_en_n;
    double gravity = p.gravity;
    if (s.vertical == Vertical::kFree) {
        // a free vertical channel's dynamics are gravity's own feedback:
        // gravity at this tick's position, exactly (strapdown.hpp)
        double sin_lat;
        double cos_lat;
        lat_sincos(s, &sin_lat, &cos_lat);
        gravity = earth::normal_gravity(sin_lat, s.nav.height);
    }
    const Vec3 gravity_n(0.0, 0.0, -gravity);

    // 3. Velocity: specific force rotated into n with the rotation of n over
    //    the tick, then gravity and Coriolis (Yan 2019 eq. 4.1.27).
    const Vec3 dv_n0 = attitude::quat_rotate(s.nav.quat_np, c.dv_p);
    const Vec3 dv_sf_n = dv_n0 - 0.5 * dt * cross(omega_in_n, dv_n0);
    const Vec3 coriolis_n = cross(2.0 * omega_ie_n + omega_en_n, vel_mid);
    const Vec3 dv_cor_n = (gravity_n - coriolis_n) * dt;
    Vec3 vel_new = s.nav.vel_n + dv_sf_n + dv_cor_n;
    if (s.vertical == Vertical::kHold) {
        vel_new(2) = 0.0;
    }

    // 4. Position by the trapezoidal rule (Qin 2014 eq. 4.1.12).
    const Vec3 vel_avg = 0.5 * (s.nav.vel_n + vel_new);
    const Vec3 pos_rate = earth::position_rate(p, d, vel_avg);
    s.nav.lat = s.nav.lat + pos_rate(0) * dt;
    double lon = s.nav.lon + pos_rate(1) * dt;
    if (lon > kPi) {
        lon = lon - kTwoPi;
    } else if (lon <= -kPi) {
        lon = lon + kTwoPi;
    }
    s.nav.lon = lon;
    if (s.vertical == Vertical::kHold) {
        s.nav.height = s.ref_height;
    } else {
        s.nav.height = s.nav.height + pos_rate(2) * dt;
    }

    // 5. Attitude: q_np(k) = q(-T omega_in^n) q_np(k-1) q(phi) (Yan eq. 4.1.8).
    const Quat q_nn = attitude::rotvec_to_quat(-dt * omega_in_n);
    const Quat q_pp = attitude::rotvec_to_quat(c.phi);
    s.nav.quat_np = attitude::quat_renormalize(
        attitude::quat_mul(attitude::quat_mul(q_nn, s.nav.quat_np), q_pp));

    // 6. Memory for the next tick.
    s.prev_dvel_n = vel_new - s.nav.vel_n;
    s.nav.vel_n = vel_new;
    push_history(s.hist, dtheta_p, dv_p, c);
    return dv_sf_n;
}

}  // namespace pyins::strapdown
