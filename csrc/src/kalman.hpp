// kalman.hpp: fixed-size linear Kalman filter steps (no heap).
//
// Mirrored by pyins/reference/kalman.py. Joseph-form update (Bucy & Joseph
// 1968; Grewal & Andrews, "Kalman Filtering", 4th ed., eq. 4.25), symmetrised
// after every step; positive definiteness is checked on the diagonal and
// reported, never enforced silently.
#pragma once

#include <cmath>

#include "types.hpp"

namespace pyins::kalman {

template <int N>
using Vec = Eigen::Matrix<double, N, 1>;
template <int R, int C>
using Mat = Eigen::Matrix<double, R, C>;

/// x <- Phi x;  P <- Phi P Phi^T + Qd, symmetrised.
///
/// The N x N products are coefficient-based (lazyProduct, each element a dot
/// product in index order), for every N: from N = 7 on (rows + cols + depth
/// >= 20) Eigen would choose its blocked matrix kernel, whose code (with a
/// heap fallback that only inlining at -O3 removes) is several KB of a
/// Cortex-M7's 64 KiB budget, for 8 x 8 products that need none of it.
template <int N>
void predict(Vec<N>& x, Mat<N, N>& p, const Mat<N, N>& phi, const Mat<N, N>& qd) {
    x = phi * x;
    const Mat<N, N> phi_p = phi.lazyProduct(p);
    const Mat<N, N> pp = phi_p.lazyProduct(phi.transpose()) + qd;
    p = 0.5 * (pp + pp.transpose());
}

/// Measurement update with z = H x + v, v ~ N(0, R), Joseph form:
///   K = P H^T (H P H^T + R)^-1,  x <- x + K (z - H x),
///   P <- (I - K H) P (I - K H)^T + K R K^T, symmetrised.
/// The innovation covariance is inverted in closed form for M = 2.
/// Returns the normalised innovation squared nu^T S^-1 nu, nu = z - H x,
/// S = H P H^T + R: chi-square with 2 degrees of freedom (mean 2) while the
/// model holds (Bar-Shalom, Li, Kirubarajan, "Estimation with Applications
/// to Tracking and Navigation", 2001, sec. 5.4).
template <int N>
double update2(Vec<N>& x, Mat<N, N>& p, const Mat<2, N>& h, const Vec<2>& z, const Mat<2, 2>& r) {
    const Mat<2, 2> s = h * p * h.transpose() + r;
    const double det = s(0, 0) * s(1, 1) - s(0, 1) * s(1, 0);
    Mat<2, 2> s_inv;
    s_inv << s(1, 1) / det, -s(0, 1) / det,
             -s(1, 0) / det, s(0, 0) / det;
    const Mat<N, 2> k = p * h.transpose() * s_inv;
    const Vec<2> nu = z - h * x;
    const double nis = nu.dot(s_inv * nu);
    x = x + k * nu;
    const Mat<N, N> ikh = Mat<N, N>::Identity() - k * h;
    const Mat<N, N> ikh_p = ikh.lazyProduct(p);
    const Mat<N, N> pj = ikh_p.lazyProduct(ikh.transpose()) + k * r * k.transpose();
    p = 0.5 * (pj + pj.transpose());
    return nis;
}

/// True when every diagonal element is finite and positive.
template <int N>
bool diagonal_positive(const Mat<N, N>& p) {
    for (int i = 0; i < N; ++i) {
        const double d = p(i, i);
        if (!(d > 0.0) || !std::isfinite(d)) {   // refuses NaN, <= 0 and Inf
            return false;
        }
    }
    return true;
}

}  // namespace pyins::kalman
