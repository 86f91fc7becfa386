// moving_align.cpp: see moving_align.hpp. Mirrored by pyins/reference/moving_align.py.
#include "moving_align.hpp"

#include "earth.hpp"
#include "math_portable.hpp"

namespace pyins::moving_align {

using M12 = kalman::Mat<kStates, kStates>;

void init(MovingAlign& m, const Params& prm) {
    m.prm = prm;
    m.x = kalman::Vec<kStates>::Zero();
    kalman::Vec<kStates> sigma;
    sigma(kPhi + 0) = prm.sigma0_att[0];
    sigma(kPhi + 1) = prm.sigma0_att[1];
    sigma(kPhi + 2) = prm.sigma0_att[2];
    sigma(kVel + 0) = prm.sigma0_vel;
    sigma(kVel + 1) = prm.sigma0_vel;
    sigma(kPos + 0) = prm.pos_sigma;   // the waves' displacement at the start
    sigma(kPos + 1) = prm.pos_sigma;
    sigma(kEps + 0) = prm.sigma0_gyro;
    sigma(kEps + 1) = prm.sigma0_gyro;
    sigma(kEps + 2) = prm.sigma0_gyro;
    sigma(kNabla + 0) = prm.sigma0_accel;
    sigma(kNabla + 1) = prm.sigma0_accel;
    m.p = M12::Zero();
    for (int i = 0; i < kStates; ++i) {
        m.p(i, i) = sigma(i) * sigma(i);
    }
    m.dv_sum = Vec3::Zero();
    m.meas_count = 0;
    m.healthy = true;
    m.consistent = true;
    m.nis_sum = 0.0;
    m.nis_count = 0;
    m.nis_mean = 0.0;
    m.nis_windows = 0;
}

void sigma0_after_coarse(Params& prm, double coarse_s, double wander, double gravity) {
    if (!(prm.site_accel > 0.0)) {
        return;
    }
    // header: the level q / (g sqrt(T)), the heading q / (k sqrt(3 T^3)), k = g w_N / 6
    const double k = gravity * earth::kOmegaIe * prm.cos_lat / 6.0;
    const double level = prm.site_accel / (gravity * pmath::sqrt(coarse_s));
    const double heading = prm.site_accel / (k * pmath::sqrt(3.0 * coarse_s * coarse_s * coarse_s));
    const double w2 = wander * wander;
    const double add[3] = {level * level + w2, level * level + w2, heading * heading + w2};
    for (int i = 0; i < 3; ++i) {
        const double s = prm.sigma0_att[i];
        prm.sigma0_att[i] = pmath::sqrt(s * s + kSiteMargin * kSiteMargin * add[i]);
    }
}

M12 system_matrix(const Params& prm, const Vec3& f_n) {
    const double w_n = earth::kOmegaIe * prm.cos_lat;
    const double w_u = earth::kOmegaIe * prm.sin_lat;
    const double tan_lat = prm.sin_lat / prm.cos_lat;
    M12 f = M12::Zero();
    // phi' = phi x w_ie + dw_en(dv) - eps, w_ie = [0, w_N, w_U]
    f(kPhi + 0, kPhi + 1) = w_u;
    f(kPhi + 0, kPhi + 2) = -w_n;
    f(kPhi + 1, kPhi + 0) = -w_u;
    f(kPhi + 2, kPhi + 0) = w_n;
    f(kPhi + 0, kVel + 1) = -1.0 / prm.rm_h;
    f(kPhi + 1, kVel + 0) = 1.0 / prm.rn_h;
    f(kPhi + 2, kVel + 0) = tan_lat / prm.rn_h;
    f(kPhi + 0, kEps + 0) = -1.0;
    f(kPhi + 1, kEps + 1) = -1.0;
    f(kPhi + 2, kEps + 2) = -1.0;
    // dv' = f x phi + nabla - 2 w_ie x dv (horizontal)
    f(kVel + 0, kPhi + 1) = -f_n(2);
    f(kVel + 0, kPhi + 2) = f_n(1);
    f(kVel + 1, kPhi + 0) = f_n(2);
    f(kVel + 1, kPhi + 2) = -f_n(0);
    f(kVel + 0, kVel + 1) = 2.0 * w_u;
    f(kVel + 1, kVel + 0) = -2.0 * w_u;
    f(kVel + 0, kNabla + 0) = 1.0;
    f(kVel + 1, kNabla + 1) = 1.0;
    // dp' = dv
    f(kPos + 0, kVel + 0) = 1.0;
    f(kPos + 1, kVel + 1) = 1.0;
    return f;
}

bool step(MovingAlign& m, const Vec3& dv_sf_n, const double z_en[2]) {
    m.dv_sum = m.dv_sum + dv_sf_n;
    m.meas_count = m.meas_count + 1;
    if (m.meas_count != m.prm.meas_every) {
        return false;
    }
    // Products are coefficient-based (lazyProduct): at 12 x 12 Eigen would
    // otherwise take its blocked GEMM kernel, 20 KB of code and 6 KB of
    // stack on the Cortex-M (measured by tools/size_report.py).
    const double span = static_cast<double>(m.prm.meas_every) * m.prm.dt;
    const M12 ft = system_matrix(m.prm, m.dv_sum / span) * span;
    M12 phi = ft + 0.5 * ft.lazyProduct(ft);
    for (int i = 0; i < kStates; ++i) {
        phi(i, i) = phi(i, i) + 1.0;
    }
    // Time update: x = Phi x, P = Phi P Phi^T + Qd (Qd diagonal:
    // arw^2 T on phi, (vrw^2 + site_accel^2) T on dv: the site's slow
    // motion, header), symmetrised.
    {
        // lazyProduct evaluates straight into its destination: never alias
        const kalman::Vec<kStates> xp = phi.lazyProduct(m.x);
        m.x = xp;
    }
    {
        const M12 ap = phi.lazyProduct(m.p);
        m.p = ap.lazyProduct(phi.transpose());
    }
    const double q_att = m.prm.gyro_arw * m.prm.gyro_arw * span;
    const double q_vel = (m.prm.accel_vrw * m.prm.accel_vrw + m.prm.site_accel * m.prm.site_accel) * span;
    m.p(kPhi + 0, kPhi + 0) = m.p(kPhi + 0, kPhi + 0) + q_att;
    m.p(kPhi + 1, kPhi + 1) = m.p(kPhi + 1, kPhi + 1) + q_att;
    m.p(kPhi + 2, kPhi + 2) = m.p(kPhi + 2, kPhi + 2) + q_att;
    m.p(kVel + 0, kVel + 0) = m.p(kVel + 0, kVel + 0) + q_vel;
    m.p(kVel + 1, kVel + 1) = m.p(kVel + 1, kVel + 1) + q_vel;
    for (int i = 0; i < kStates; ++i) {
        for (int j = i + 1; j < kStates; ++j) {
            const double s = 0.5 * (m.p(i, j) + m.p(j, i));
            m.p(i, j) = s;
            m.p(j, i) = s;
        }
    }
    // Measurement update, E then N: H is a unit row e_k and R diagonal, so
    // the two scalar updates equal the joint one and their NIS add up to the
    // joint NIS (Bar-Shalom et al. 2001, sec. 5.4). Joseph form as in
    // kalman.hpp, written for a unit row: A = (I - K e_k^T) P, then
    // P = A - (A e_k) K^T + r K K^T (rounding in K then enters P only at
    // second order).
    const double r_pos = m.prm.pos_sigma * m.prm.pos_sigma;
    double nis = 0.0;
    for (int c = 0; c < 2; ++c) {
        const int k = kPos + c;
        const double s = m.p(k, k) + r_pos;
        const double nu = z_en[c] - m.x(k);
        nis = nis + nu * nu / s;
        const kalman::Vec<kStates> gain = m.p.col(k) / s;
        m.x = m.x + gain * nu;
        M12 a = m.p;
        for (int i = 0; i < kStates; ++i) {
            for (int j = 0; j < kStates; ++j) {
                a(i, j) = a(i, j) - gain(i) * m.p(k, j);
            }
        }
        for (int i = 0; i < kStates; ++i) {
            const double aik = a(i, k);
            for (int j = 0; j < kStates; ++j) {
                m.p(i, j) = a(i, j) - aik * gain(j) + r_pos * gain(i) * gain(j);
            }
        }
        for (int i = 0; i < kStates; ++i) {
            for (int j = i + 1; j < kStates; ++j) {
                const double v = 0.5 * (m.p(i, j) + m.p(j, i));
                m.p(i, j) = v;
                m.p(j, i) = v;
            }
        }
    }
    m.dv_sum = Vec3::Zero();
    m.meas_count = 0;
    if (m.prm.nis_window > 0) {
        m.nis_sum = m.nis_sum + nis;
        m.nis_count = m.nis_count + 1;
        if (m.nis_count == m.prm.nis_window) {
            m.nis_mean = m.nis_sum / static_cast<double>(m.prm.nis_window);
            m.nis_windows = m.nis_windows + 1;
            m.consistent = m.consistent && m.nis_mean <= m.prm.nis_max;
            m.nis_sum = 0.0;
            m.nis_count = 0;
        }
    }
    m.healthy = m.healthy && kalman::diagonal_positive<kStates>(m.p);
    return true;
}

void reset_feedback(MovingAlign& m) {
    for (int i = 0; i < kEps; ++i) {
        m.x(i) = 0.0;
    }
}

}  // namespace pyins::moving_align
