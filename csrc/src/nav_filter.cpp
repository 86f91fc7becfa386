// nav_filter.cpp: see nav_filter.hpp. Mirrored by pyins/reference/nav_filter.py.
#include "nav_filter.hpp"

#include "earth.hpp"

namespace pyins::nav_filter {

using M12 = kalman::Mat<kStates, kStates>;

namespace {

/// P symmetrised from its two triangles.
void symmetrise(M12& p) {
    for (int i = 0; i < kStates; ++i) {
        for (int j = i + 1; j < kStates; ++j) {
            const double s = 0.5 * (p(i, j) + p(j, i));
            p(i, j) = s;
            p(j, i) = s;
        }
    }
}

}  // namespace

void init(NavFilter& f, const Params& prm, const Mat3& c_np) {
    f.prm = prm;
    f.x = kalman::Vec<kStates>::Zero();
    kalman::Vec<kStates> sigma;
    sigma(kPhi + 0) = prm.sigma0_att[0];
    sigma(kPhi + 1) = prm.sigma0_att[1];
    sigma(kPhi + 2) = prm.sigma0_att[2];
    sigma(kVel + 0) = prm.sigma0_vel;
    sigma(kVel + 1) = prm.sigma0_vel;
    sigma(kPos + 0) = prm.sigma0_pos;
    sigma(kPos + 1) = prm.sigma0_pos;
    sigma(kEps + 0) = prm.sigma0_gyro;
    sigma(kEps + 1) = prm.sigma0_gyro;
    sigma(kEps + 2) = prm.sigma0_gyro;
    sigma(kNabla + 0) = prm.sigma0_accel;
    sigma(kNabla + 1) = prm.sigma0_accel;
    f.p = M12::Zero();
    for (int i = 0; i < kStates; ++i) {
        f.p(i, i) = sigma(i) * sigma(i);
    }
    f.dv_sum = Vec3::Zero();
    f.c_start = c_np;
    f.ticks = 0;
    f.move_angle = 0.0;
    f.move_q = 0.0;
    f.healthy = 1;
    f.gyro_bias = Vec3::Zero();
    f.accel_bias = Vec3::Zero();
}

M12 system_matrix(const Motion& m, const Vec3& f_n, const Mat3& c_np) {
    const double w = earth::kOmegaIe;
    const double tan_lat = m.sin_lat / m.cos_lat;
    const double sec2 = 1.0 / (m.cos_lat * m.cos_lat);
    // w_in = w_ie + w_en
    const double w_e = -m.vel_n / m.rm_h;
    const double w_n = w * m.cos_lat + m.vel_e / m.rn_h;
    const double w_u = w * m.sin_lat + m.vel_e * tan_lat / m.rn_h;
    // 2 w_ie + w_en, up component (the horizontal rows of its cross product with dv)
    const double w2_u = 2.0 * w * m.sin_lat + m.vel_e * tan_lat / m.rn_h;
    M12 f = M12::Zero();
    // phi' = -w_in x phi + dw_in - C eps
    f(kPhi + 0, kPhi + 1) = w_u;
    f(kPhi + 0, kPhi + 2) = -w_n;
    f(kPhi + 1, kPhi + 0) = -w_u;
    f(kPhi + 1, kPhi + 2) = w_e;
    f(kPhi + 2, kPhi + 0) = w_n;
    f(kPhi + 2, kPhi + 1) = -w_e;
    f(kPhi + 0, kVel + 1) = -1.0 / m.rm_h;
    f(kPhi + 1, kVel + 0) = 1.0 / m.rn_h;
    f(kPhi + 2, kVel + 0) = tan_lat / m.rn_h;
    f(kPhi + 1, kPos + 1) = -w * m.sin_lat / m.rm_h;
    f(kPhi + 2, kPos + 1) = (w * m.cos_lat + m.vel_e * sec2 / m.rn_h) / m.rm_h;
    for (int i = 0; i < 3; ++i) {
        for (int j = 0; j < 3; ++j) {
            f(kPhi + i, kEps + j) = -c_np(i, j);
        }
    }
    // dv' = f x phi - (2 w_ie + w_en) x dv + v x (2 dw_ie + dw_en) + C nabla
    f(kVel + 0, kPhi + 1) = -f_n(2);
    f(kVel + 0, kPhi + 2) = f_n(1);
    f(kVel + 1, kPhi + 0) = f_n(2);
    f(kVel + 1, kPhi + 2) = -f_n(0);
    // a_U = dv_E tanL / R_N + (2 w_ie cosL + v_E sec^2 L / R_N) dL
    const double au_dve = tan_lat / m.rn_h;
    const double au_dpn = (2.0 * w * m.cos_lat + m.vel_e * sec2 / m.rn_h) / m.rm_h;
    f(kVel + 0, kVel + 0) = m.vel_n * au_dve;
    f(kVel + 0, kVel + 1) = w2_u;
    f(kVel + 0, kPos + 1) = m.vel_n * au_dpn;
    f(kVel + 1, kVel + 0) = -w2_u - m.vel_e * au_dve;
    f(kVel + 1, kPos + 1) = -m.vel_e * au_dpn;
    for (int i = 0; i < 2; ++i) {
        for (int j = 0; j < 2; ++j) {
            f(kVel + i, kNabla + j) = c_np(i, j);
        }
    }
    // dp' = dv
    f(kPos + 0, kVel + 0) = 1.0;
    f(kPos + 1, kVel + 1) = 1.0;
    return f;
}

void predict(NavFilter& f, const Motion& m, const Mat3& c_np) {
    if (f.ticks == 0) {
        return;
    }
    const double span = static_cast<double>(f.ticks) * f.prm.dt;
    const Mat3 c_mean = 0.5 * (f.c_start + c_np);
    // coefficient-based products (lazyProduct): moving_align.cpp says why
    const M12 ft = system_matrix(m, f.dv_sum / span, c_mean) * span;
    M12 phi = ft + 0.5 * ft.lazyProduct(ft);
    for (int i = 0; i < kStates; ++i) {
        phi(i, i) = phi(i, i) + 1.0;
    }
    {
        const kalman::Vec<kStates> xp = phi.lazyProduct(f.x);
        f.x = xp;
    }
    {
        const M12 ap = phi.lazyProduct(f.p);
        f.p = ap.lazyProduct(phi.transpose());
    }
    const double q_att = f.prm.gyro_arw * f.prm.gyro_arw * span;
    const double q_vel = f.prm.accel_vrw * f.prm.accel_vrw * span;
    f.p(kPhi + 0, kPhi + 0) = f.p(kPhi + 0, kPhi + 0) + q_att;
    f.p(kPhi + 1, kPhi + 1) = f.p(kPhi + 1, kPhi + 1) + q_att;
    f.p(kPhi + 2, kPhi + 2) = f.p(kPhi + 2, kPhi + 2) + q_att;
    f.p(kVel + 0, kVel + 0) = f.p(kVel + 0, kVel + 0) + q_vel;
    f.p(kVel + 1, kVel + 1) = f.p(kVel + 1, kVel + 1) + q_vel;
    if (f.prm.gyro_bias_rw > 0.0) {
        const double q_eps = f.prm.gyro_bias_rw * f.prm.gyro_bias_rw * span;
        f.p(kEps + 0, kEps + 0) = f.p(kEps + 0, kEps + 0) + q_eps;
        f.p(kEps + 1, kEps + 1) = f.p(kEps + 1, kEps + 1) + q_eps;
        f.p(kEps + 2, kEps + 2) = f.p(kEps + 2, kEps + 2) + q_eps;
    }
    if (f.move_q > 0.0) {
        const double q_tilt = f.prm.table_mis * f.prm.table_mis * f.move_q;
        const double q_head = f.prm.table_scale * f.prm.table_scale * f.move_q;
        f.p(kPhi + 0, kPhi + 0) = f.p(kPhi + 0, kPhi + 0) + q_tilt;
        f.p(kPhi + 1, kPhi + 1) = f.p(kPhi + 1, kPhi + 1) + q_tilt;
        f.p(kPhi + 2, kPhi + 2) = f.p(kPhi + 2, kPhi + 2) + q_head;
    }
    f.move_q = 0.0;
    symmetrise(f.p);
    f.dv_sum = Vec3::Zero();
    f.c_start = c_np;
    f.ticks = 0;
    if (!kalman::diagonal_positive<kStates>(f.p)) {
        f.healthy = 0;
    }
}

double nis_pair(const NavFilter& f, int k, const double z[2], const double r[2]) {
    const double s00 = f.p(k, k) + r[0];
    const double s01 = f.p(k, k + 1);
    const double s11 = f.p(k + 1, k + 1) + r[1];
    const double nu0 = z[0] - f.x(k);
    const double nu1 = z[1] - f.x(k + 1);
    const double det = s00 * s11 - s01 * s01;
    // nu^T S^-1 nu with S^-1 = [s11, -s01; -s01, s00] / det
    return (nu0 * (s11 * nu0 - s01 * nu1) + nu1 * (s00 * nu1 - s01 * nu0)) / det;
}

void update_pair(NavFilter& f, int k0, const double z[2], const double r[2]) {
    // two scalar updates, Joseph form for a unit row (moving_align.cpp)
    for (int c = 0; c < 2; ++c) {
        const int k = k0 + c;
        const double s = f.p(k, k) + r[c];
        const double nu = z[c] - f.x(k);
        const kalman::Vec<kStates> gain = f.p.col(k) / s;
        f.x = f.x + gain * nu;
        M12 a = f.p;
        for (int i = 0; i < kStates; ++i) {
            for (int j = 0; j < kStates; ++j) {
                a(i, j) = a(i, j) - gain(i) * f.p(k, j);
            }
        }
        for (int i = 0; i < kStates; ++i) {
            const double aik = a(i, k);
            for (int j = 0; j < kStates; ++j) {
                f.p(i, j) = a(i, j) - aik * gain(j) + r[c] * gain(i) * gain(j);
            }
        }
        symmetrise(f.p);
    }
    if (!kalman::diagonal_positive<kStates>(f.p)) {
        f.healthy = 0;
    }
}

void reset_feedback(NavFilter& f) {
    f.gyro_bias(0) = f.gyro_bias(0) + f.x(kEps + 0);
    f.gyro_bias(1) = f.gyro_bias(1) + f.x(kEps + 1);
    f.gyro_bias(2) = f.gyro_bias(2) + f.x(kEps + 2);
    f.accel_bias(0) = f.accel_bias(0) + f.x(kNabla + 0);
    f.accel_bias(1) = f.accel_bias(1) + f.x(kNabla + 1);
    f.x = kalman::Vec<kStates>::Zero();
}

}  // namespace pyins::nav_filter
