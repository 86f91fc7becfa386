// fine_align.cpp: see fine_align.hpp. Mirrored by pyins/reference/fine_align.py.
#include "fine_align.hpp"

#include "earth.hpp"
#include "math_portable.hpp"

namespace pyins::fine_align {

template struct FineAlign<5>;
template struct FineAlign<8>;

template <int N>
kalman::Mat<N, N> system_matrix(double sin_lat, double cos_lat) {
    const double w_n = earth::kOmegaIe * cos_lat;
    const double w_u = earth::kOmegaIe * sin_lat;
    kalman::Mat<N, N> f = kalman::Mat<N, N>::Zero();
    // phi' = phi x w_ie - eps, w_ie = [0, w_N, w_U]
    f(kPhi + 0, kPhi + 1) = w_u;
    f(kPhi + 0, kPhi + 2) = -w_n;
    f(kPhi + 1, kPhi + 0) = -w_u;
    f(kPhi + 2, kPhi + 0) = w_n;
    if constexpr (N == 8) {
        f(kPhi + 0, kEps + 0) = -1.0;
        f(kPhi + 1, kEps + 1) = -1.0;
        f(kPhi + 2, kEps + 2) = -1.0;
    } else {
        f(kPhi + 1, kEpsNU + 0) = -1.0;
        f(kPhi + 2, kEpsNU + 1) = -1.0;
    }
    return f;
}

void sigma0_after_coarse(Params& prm, double coarse_s, double wander, const double cap[3]) {
    const double w_n = earth::kOmegaIe * prm.cos_lat;
    // seed 001 §2: phi_E = -nabla_N / g, phi_N = nabla_E / g
    const double lev_b = prm.sigma0_accel / prm.gravity;
    const double lev_n = prm.accel_vrw / prm.gravity;
    const double level2 = lev_b * lev_b + lev_n * lev_n / coarse_s;
    // seed 001 §2: phi_U = -eps_E / w_N + tan L nabla_E / g
    const double hd_b = prm.sigma0_gyro / w_n;
    const double hd_l = prm.sin_lat / prm.cos_lat * lev_b;
    const double hd_n = prm.gyro_arw / w_n;
    const double head2 = hd_b * hd_b + hd_l * hd_l + hd_n * hd_n / coarse_s;
    const double w2 = wander * wander;
    const double fit[3] = {kAfterCoarseMargin * pmath::sqrt(level2 + w2),
                           kAfterCoarseMargin * pmath::sqrt(level2 + w2),
                           kAfterCoarseMargin * pmath::sqrt(head2 + w2)};
    for (int i = 0; i < 3; ++i) {
        if (prm.sigma0_att[i] == 0.0) {
            double v = fit[i];
            if (!(v >= kAfterCoarseFloor)) {  // also a NaN
                v = kAfterCoarseFloor;
            }
            if (v > cap[i]) {
                v = cap[i];
            }
            prm.sigma0_att[i] = v;
        }
    }
}

template <int N>
void init(FineAlign<N>& f, const Params& prm) {
    const kalman::Mat<N, N> ft = system_matrix<N>(prm.sin_lat, prm.cos_lat) * prm.dt;
    f.phi = kalman::Mat<N, N>::Identity() + ft + 0.5 * (ft * ft);
    f.qd = kalman::Mat<N, N>::Zero();
    const double q_att = prm.gyro_arw * prm.gyro_arw * prm.dt;
    f.qd(kPhi + 0, kPhi + 0) = q_att;
    f.qd(kPhi + 1, kPhi + 1) = q_att;
    f.qd(kPhi + 2, kPhi + 2) = q_att;

    const double g = prm.gravity;
    f.h = kalman::Mat<2, N>::Zero();
    // Z = [f_E f_N] = [-g phi_N + nabla_E, g phi_E + nabla_N]
    f.h(0, kPhi + 1) = -g;
    f.h(1, kPhi + 0) = g;
    if constexpr (N == 8) {
        f.h(0, kNabla + 0) = 1.0;
        f.h(1, kNabla + 1) = 1.0;
    }
    const double r = prm.accel_vrw * prm.accel_vrw / (static_cast<double>(prm.meas_every) * prm.dt);
    f.r << r, 0.0,
           0.0, r;

    kalman::Vec<N> sigma;
    sigma(kPhi + 0) = prm.sigma0_att[0];
    sigma(kPhi + 1) = prm.sigma0_att[1];
    sigma(kPhi + 2) = prm.sigma0_att[2];
    if constexpr (N == 8) {
        sigma(kEps + 0) = prm.sigma0_gyro;
        sigma(kEps + 1) = prm.sigma0_gyro;
        sigma(kEps + 2) = prm.sigma0_gyro;
        sigma(kNabla + 0) = prm.sigma0_accel;
        sigma(kNabla + 1) = prm.sigma0_accel;
    } else {
        sigma(kEpsNU + 0) = prm.sigma0_gyro;
        sigma(kEpsNU + 1) = prm.sigma0_gyro;
    }
    f.p = kalman::Mat<N, N>::Zero();
    for (int i = 0; i < N; ++i) {
        f.p(i, i) = sigma(i) * sigma(i);
    }
    f.x = kalman::Vec<N>::Zero();
    f.dv_sum = Vec3::Zero();
    f.meas_count = 0;
    f.meas_every = prm.meas_every;
    f.meas_span = static_cast<double>(prm.meas_every) * prm.dt;
    f.healthy = true;
    f.consistent = true;
    f.nis_window = prm.nis_window;
    f.nis_max = prm.nis_max;
    f.nis_sum = 0.0;
    f.nis_count = 0;
    f.nis_mean = 0.0;
    f.nis_windows = 0;
}

template <int N>
bool step(FineAlign<N>& f, const Vec3& dv_sf_n) {
    kalman::predict<N>(f.x, f.p, f.phi, f.qd);
    f.dv_sum = f.dv_sum + dv_sf_n;
    f.meas_count = f.meas_count + 1;
    const bool updated = f.meas_count == f.meas_every;
    if (updated) {
        // z = mean specific force over the interval, E and N components.
        kalman::Vec<2> z;
        z(0) = f.dv_sum(0) / f.meas_span;
        z(1) = f.dv_sum(1) / f.meas_span;
        const double nis = kalman::update2<N>(f.x, f.p, f.h, z, f.r);
        f.dv_sum = Vec3::Zero();
        f.meas_count = 0;
        if (f.nis_window > 0) {
            f.nis_sum = f.nis_sum + nis;
            f.nis_count = f.nis_count + 1;
            if (f.nis_count == f.nis_window) {
                f.nis_mean = f.nis_sum / static_cast<double>(f.nis_window);
                f.nis_windows = f.nis_windows + 1;
                // !(<=) also catches a NaN
                f.consistent = f.consistent && f.nis_mean <= f.nis_max;
                f.nis_sum = 0.0;
                f.nis_count = 0;
            }
        }
    }
    f.healthy = f.healthy && kalman::diagonal_positive<N>(f.p);
    return updated;
}

template kalman::Mat<5, 5> system_matrix<5>(double, double);
template kalman::Mat<8, 8> system_matrix<8>(double, double);
template void init<5>(FineAlign<5>&, const Params&);
template void init<8>(FineAlign<8>&, const Params&);
template bool step<5>(FineAlign<5>&, const Vec3&);
template bool step<8>(FineAlign<8>&, const Vec3&);

}  // namespace pyins::fine_align
