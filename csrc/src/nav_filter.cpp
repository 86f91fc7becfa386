// nav_filter.cpp: see nav_filter.hpp. Mirrored by pyins/reference/nav_filter.py.
#include "nav_filter.hpp"

#include <cmath>

#include "earth.hpp"

namespace pyins::nav_filter {

using MS = kalman::Mat<kStates, kStates>;
using MF = kalman::Mat<kDyn, kStates>;
constexpr int kCon = kStates - kDyn;   ///< the constants: eps, nabla, the scale factors and misalignments
using MD = kalman::Mat<kDyn, kDyn>;
using MDC = kalman::Mat<kDyn, kCon>;

namespace {

/// P symmetrised from its two triangles.
void symmetrise(MS& p) {
    for (int i = 0; i < kStates; ++i) {
        for (int j = i + 1; j < kStates; ++j) {
            const double s = 0.5 * (p(i, j) + p(j, i));
            p(i, j) = s;
            p(j, i) = s;
        }
    }
}

/// P's diagonal positive and finite, the scale-factor and misalignment
/// states' at least not negative (0 while they are not modelled).
bool diagonal_healthy(const MS& p) {
    for (int i = 0; i < kStates; ++i) {
        const double d = p(i, i);
        const bool ok = i < kTab ? d > 0.0 : d >= 0.0;
        if (!ok || !std::isfinite(d)) {   // refuses NaN and Inf
            return false;
        }
    }
    return true;
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
    sigma(kTab + 0) = prm.table_mis;
    sigma(kTab + 1) = prm.table_mis;
    sigma(kTab + 2) = prm.table_scale;
    sigma(kLev + 0) = prm.level_scale;
    sigma(kLev + 1) = prm.level_scale;
    sigma(kLev + 2) = prm.level_mis;
    sigma(kLev + 3) = prm.level_mis;
    f.p = MS::Zero();
    for (int i = 0; i < kStates; ++i) {
        f.p(i, i) = sigma(i) * sigma(i);
    }
    f.dv_sum = Vec3::Zero();
    f.c_start = c_np;
    f.ticks = 0;
    f.dtheta_sum = Vec3::Zero();
    f.healthy = 1;
    f.gyro_bias = Vec3::Zero();
    f.accel_bias = Vec3::Zero();
    f.table_err = Vec3::Zero();
    for (int i = 0; i < 4; ++i) {
        f.level_err[i] = 0.0;
    }
}

MF system_matrix(const Motion& m, const Vec3& f_n, const Mat3& c_np, const Vec3& w_p) {
    const double w = earth::kOmegaIe;
    const double tan_lat = m.sin_lat / m.cos_lat;
    const double sec2 = 1.0 / (m.cos_lat * m.cos_lat);
    // w_in = w_ie + w_en
    const double w_e = -m.vel_n / m.rm_h;
    const double w_n = w * m.cos_lat + m.vel_e / m.rn_h;
    const double w_u = w * m.sin_lat + m.vel_e * tan_lat / m.rn_h;
    // 2 w_ie + w_en, up component (the horizontal rows of its cross product with dv)
    const double w2_u = 2.0 * w * m.sin_lat + m.vel_e * tan_lat / m.rn_h;
    MF f = MF::Zero();
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
    // ... - C [m_xz m_yz k_z]^T w_z: the table-axis errors act as biases of w_z times themselves
    for (int i = 0; i < 3; ++i) {
        for (int j = 0; j < 3; ++j) {
            f(kPhi + i, kTab + j) = -c_np(i, j) * w_p(2);
        }
    }
    // ... - C(:,0) (k_x w_x + m_xy w_y) - C(:,1) (m_yx w_x + k_y w_y)
    for (int i = 0; i < 3; ++i) {
        f(kPhi + i, kLev + 0) = -c_np(i, 0) * w_p(0);
        f(kPhi + i, kLev + 1) = -c_np(i, 1) * w_p(1);
        f(kPhi + i, kLev + 2) = -c_np(i, 0) * w_p(1);
        f(kPhi + i, kLev + 3) = -c_np(i, 1) * w_p(0);
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
    // Phi = I + F T + (F T)^2 / 2 by blocks: F T = [A_d A_c; 0 0], so
    // (F T)^2 = [A_d A_d, A_d A_c; 0 0] (coefficient-based products,
    // lazyProduct: moving_align.cpp says why)
    // (each temporary in its own scope: the frame holds the largest pair,
    // not their sum)
    MD phi_d;
    MDC phi_c;
    {
        MF ft = system_matrix(m, f.dv_sum / span, c_mean, f.dtheta_sum / span);
        ft = ft * span;
        phi_d = ft.leftCols<kDyn>() + 0.5 * ft.leftCols<kDyn>().lazyProduct(ft.leftCols<kDyn>());
        phi_c = ft.rightCols<kCon>() + 0.5 * ft.leftCols<kDyn>().lazyProduct(ft.rightCols<kCon>());
    }
    for (int i = 0; i < kDyn; ++i) {
        phi_d(i, i) = phi_d(i, i) + 1.0;
    }
    {
        const kalman::Vec<kDyn> xd = phi_d.lazyProduct(f.x.head<kDyn>()) + phi_c.lazyProduct(f.x.tail<kCon>());
        f.x.head<kDyn>() = xd;
    }
    {
        // P = [P_dd P_dc; P_cd P_cc]:
        //   P_dc' = Phi_d P_dc + Phi_c P_cc
        //   P_dd' = (Phi_d P_dd + Phi_c P_cd) Phi_d^T + P_dc' Phi_c^T
        //   P_cc' = P_cc
        // (the blocks read in place: no copy of P on the stack)
        const MD t = phi_d.lazyProduct(f.p.topLeftCorner<kDyn, kDyn>()) +
                     phi_c.lazyProduct(f.p.bottomLeftCorner<kCon, kDyn>());
        const MDC n_dc = phi_d.lazyProduct(f.p.topRightCorner<kDyn, kCon>()) +
                         phi_c.lazyProduct(f.p.bottomRightCorner<kCon, kCon>());
        f.p.topLeftCorner<kDyn, kDyn>().noalias() =
            t.lazyProduct(phi_d.transpose()) + n_dc.lazyProduct(phi_c.transpose());
        f.p.topRightCorner<kDyn, kCon>() = n_dc;
        f.p.bottomLeftCorner<kCon, kDyn>() = n_dc.transpose();
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
    symmetrise(f.p);
    f.dv_sum = Vec3::Zero();
    f.dtheta_sum = Vec3::Zero();
    f.c_start = c_np;
    f.ticks = 0;
    if (!diagonal_healthy(f.p)) {
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
        const kalman::Vec<kStates> pk = f.p.col(k);   // = row k (P symmetric)
        const kalman::Vec<kStates> gain = pk / s;
        f.x = f.x + gain * nu;
        // P' = A - A(:,k) K^T + r K K^T with A = P - K P(k,:), in place
        // from the saved column: A(i,j) = P(i,j) - K_i P(k,j), A(i,k) =
        // P(i,k) - K_i P(k,k)
        // The upper triangle, mirrored into the lower (the result is
        // symmetric: half the work of the whole and of symmetrising it).
        const double pkk = pk(k);
        for (int i = 0; i < kStates; ++i) {
            const double aik = pk(i) - gain(i) * pkk;
            for (int j = i; j < kStates; ++j) {
                const double aij = f.p(i, j) - gain(i) * pk(j);
                const double v = aij - aik * gain(j) + r[c] * gain(i) * gain(j);
                f.p(i, j) = v;
                f.p(j, i) = v;
            }
        }
    }
    if (!diagonal_healthy(f.p)) {
        f.healthy = 0;
    }
}

void reset_feedback(NavFilter& f) {
    f.gyro_bias(0) = f.gyro_bias(0) + f.x(kEps + 0);
    f.gyro_bias(1) = f.gyro_bias(1) + f.x(kEps + 1);
    f.gyro_bias(2) = f.gyro_bias(2) + f.x(kEps + 2);
    f.accel_bias(0) = f.accel_bias(0) + f.x(kNabla + 0);
    f.accel_bias(1) = f.accel_bias(1) + f.x(kNabla + 1);
    f.table_err(0) = f.table_err(0) + f.x(kTab + 0);
    f.table_err(1) = f.table_err(1) + f.x(kTab + 1);
    f.table_err(2) = f.table_err(2) + f.x(kTab + 2);
    for (int i = 0; i < 4; ++i) {
        f.level_err[i] = f.level_err[i] + f.x(kLev + i);
    }
    f.x = kalman::Vec<kStates>::Zero();
}

}  // namespace pyins::nav_filter
