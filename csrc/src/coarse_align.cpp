// coarse_align.cpp: see coarse_align.hpp. Mirrored by
// pyins/reference/coarse_align.py.
#include "coarse_align.hpp"

#include "attitude.hpp"
#include "earth.hpp"
#include "math_portable.hpp"

namespace pyins::coarse_align {

using attitude::cross;

Vec3 vel_i(double t, double sin_lat, double cos_lat, double gravity) {
    const double w = earth::kOmegaIe;
    double s;
    double c;
    pmath::sincos(w * t, &s, &c);
    const double s_half = pmath::sin(0.5 * w * t);
    const double one_minus_cos = 2.0 * s_half * s_half;
    return Vec3(gravity * cos_lat * s / w, gravity * cos_lat * one_minus_cos / w,
                gravity * sin_lat * t);
}

Mat3 triad(const Vec3& u, const Vec3& w) {
    const Vec3 a1 = u / pmath::sqrt(u.dot(u));
    const Vec3 wu = cross(w, u);
    const Vec3 a2 = wu / pmath::sqrt(wu.dot(wu));
    const Vec3 a3 = cross(a1, a2);
    Mat3 m;
    m.col(0) = a1;
    m.col(1) = a2;
    m.col(2) = a3;
    return m;
}

Mat3 solve_mat_i_ib0(const Vec3& vi1, const Vec3& vi2, const Vec3& vb1, const Vec3& vb2) {
    const Mat3 ti = triad(vi2, vi1);
    const Mat3 tb = triad(vb2, vb1);
    return ti * tb.transpose();
}

Mat3 mat_n_e(double sin_lat, double cos_lat) {
    Mat3 m;
    m << 0.0, 1.0, 0.0,
         -sin_lat, 0.0, cos_lat,
         cos_lat, 0.0, sin_lat;
    return m;
}

Mat3 mat_e_i(double t) {
    double s;
    double c;
    pmath::sincos(earth::kOmegaIe * t, &s, &c);
    Mat3 m;
    m << c, s, 0.0,
         -s, c, 0.0,
         0.0, 0.0, 1.0;
    return m;
}

void init(CoarseAlign& a, const Params& prm) {
    a.prm = prm;
    a.quat_ib0_p = Quat{1.0, 0.0, 0.0, 0.0};
    a.vel_ib0 = Vec3::Zero();
    a.hist.dtheta1 = Vec3::Zero();
    a.hist.dv1 = Vec3::Zero();
    a.hist.dtheta2 = Vec3::Zero();
    a.hist.dv2 = Vec3::Zero();
    a.hist.count = 0;
    a.tick = 0;
    for (int i = 0; i < kHistLen; ++i) {
        a.hist_vel[i] = Vec3::Zero();
    }
    a.hist_count = 1;  // v^ib0(t0) = 0
    a.mat_i_ib0 = Mat3::Identity();
    a.solved = false;
}

void update(CoarseAlign& a, const Vec3& dtheta_p, const Vec3& dv_p) {
    // Velocity and attitude in ib0: dv rotated by C_p^ib0 at the tick start.
    const strapdown::Compensated c = strapdown::compensate(dtheta_p, dv_p, a.hist);
    a.vel_ib0 = a.vel_ib0 + attitude::quat_to_mat(a.quat_ib0_p) * c.dv_p;
    a.quat_ib0_p = attitude::quat_normalize(
        attitude::quat_mul(a.quat_ib0_p, attitude::rotvec_to_quat(c.phi)));
    strapdown::push_history(a.hist, dtheta_p, dv_p);
    a.tick = a.tick + 1;

    const int64_t every = a.prm.output_every;
    if (a.tick % every == 0 && a.hist_count < kHistLen) {
        a.hist_vel[a.hist_count] = a.vel_ib0;
        a.hist_count = a.hist_count + 1;
    }
    if (a.tick >= a.prm.first_output && (a.tick - a.prm.first_output) % every == 0) {
        // t_k1: the history grid point nearest r t_k2, at least one step in,
        // and before t_k2 (both guaranteed by the firmware's config check).
        const double k1_exact = a.prm.ratio * static_cast<double>(a.tick) / static_cast<double>(every);
        int64_t k1 = static_cast<int64_t>(k1_exact + 0.5);
        const int64_t k1_max = (a.tick - 1) / every;  // strictly before t_k2
        if (k1 > k1_max) {
            k1 = k1_max;
        }
        if (k1 < 1) {
            k1 = 1;
        }
        const double t1 = static_cast<double>(k1 * every) * a.prm.dt;
        const double t2 = static_cast<double>(a.tick) * a.prm.dt;
        const Vec3 vi1 = vel_i(t1, a.prm.sin_lat, a.prm.cos_lat, a.prm.gravity);
        const Vec3 vi2 = vel_i(t2, a.prm.sin_lat, a.prm.cos_lat, a.prm.gravity);
        a.mat_i_ib0 = solve_mat_i_ib0(vi1, vi2, a.hist_vel[k1], a.vel_ib0);
        a.solved = true;
    }
}

Mat3 mat_n_p(const CoarseAlign& a) {
    const double t = static_cast<double>(a.tick) * a.prm.dt;
    return mat_n_e(a.prm.sin_lat, a.prm.cos_lat) * mat_e_i(t) * a.mat_i_ib0 *
           attitude::quat_to_mat(a.quat_ib0_p);
}

}  // namespace pyins::coarse_align
