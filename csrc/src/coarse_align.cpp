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

Mat3 solve_eq8(const Vec3& vi1, const Vec3& vi2, const Vec3& vb1, const Vec3& vb2) {
    // Seed 000 eq. 8: C_ib0^i = [vi1^T; vi2^T; (vi1 x vi2)^T]^-1 [vb1^T; vb2^T; (vb1 x vb2)^T].
    // Inverse of rows (a1, a2, a3): columns (a2 x a3, a3 x a1, a1 x a2) / a1.(a2 x a3).
    const Vec3 a3 = cross(vi1, vi2);
    const Vec3 c1 = cross(vi2, a3);
    const Vec3 c2 = cross(a3, vi1);
    const double det = vi1.dot(c1);
    Mat3 inv;
    inv.col(0) = c1 / det;
    inv.col(1) = c2 / det;
    inv.col(2) = a3 / det;
    Mat3 b;
    b.row(0) = vb1.transpose();
    b.row(1) = vb2.transpose();
    b.row(2) = cross(vb1, vb2).transpose();
    return inv * b;
}

Vec3 pos_i(double t, double sin_lat, double cos_lat, double gravity) {
    // (1 - cos x) / x^2 and (x - sin x) / x^3, x = w t, by their Taylor
    // series: x < 0.2 rad for any alignment the grid can hold at 10 s
    // outputs, where the first term left out is < 1e-17 of the sum.
    const double x = earth::kOmegaIe * t;
    const double x2 = x * x;
    const double c2 = 0.5 - x2 * (1.0 / 24.0 - x2 * (1.0 / 720.0 - x2 * (1.0 / 40320.0 - x2 / 3628800.0)));
    const double s3 = 1.0 / 6.0 - x2 * (1.0 / 120.0 - x2 * (1.0 / 5040.0 - x2 * (1.0 / 362880.0 - x2 / 39916800.0)));
    const double gt2 = gravity * t * t;
    return Vec3(cos_lat * gt2 * c2, cos_lat * gt2 * x * s3, sin_lat * 0.5 * gt2);
}

void fit_weights(double s, double* phi_a, double* phi_b) {
    // s^2 (1-s)^2 q(s), q by Horner; coefficients exact integers (derived
    // with rational arithmetic: tools/derive_coarse_fit.py).
    const double u = s * (1.0 - s);
    const double w = u * u;
    *phi_a = w * (45360.0 + s * (-350280.0 + s * (766080.0 - 498960.0 * s)));
    *phi_b = w * (-27720.0 + s * (221760.0 + s * (-498960.0 + 332640.0 * s)));
}

namespace {

/// FIT's weighted sums (solve_fit): the i side from grid_i, or by pos_i
/// where grid_i is null.
Mat3 fit_sums(const Vec3* grid, const Vec3* grid_i, int32_t n, double t_step, double sin_lat,
              double cos_lat, double gravity) {
    // Weighted sums over the grid points k = 0 .. K, s = k / K. The weights
    // are made exactly orthogonal to 1 and s on this grid, phi' = phi -
    // (alpha + beta s) with the discrete normal equations, so that the
    // unknown initial velocity and offset drop out exactly (the continuous
    // orthogonality alone leaks 2 % of b T at K = 20, falling as K^-4). The
    // projection is accumulated in the same pass: sum phi' P = sum phi P -
    // alpha sum P - beta sum s P.
    const int32_t k_end = n - 1;
    const double inv_k = 1.0 / static_cast<double>(k_end);
    Vec3 ia = Vec3::Zero();
    Vec3 ib = Vec3::Zero();
    Vec3 ba = Vec3::Zero();
    Vec3 bb = Vec3::Zero();
    Vec3 i0 = Vec3::Zero();
    Vec3 i1 = Vec3::Zero();
    Vec3 b0 = Vec3::Zero();
    Vec3 b1 = Vec3::Zero();
    double a0 = 0.0;   // sum phi_a, sum phi_a s, sum phi_b, sum phi_b s
    double a1 = 0.0;
    double c0 = 0.0;
    double c1 = 0.0;
    double s1 = 0.0;   // sum s, sum s^2 (sum 1 = n)
    double s2 = 0.0;
    for (int32_t k = 0; k <= k_end; ++k) {
        const double s = static_cast<double>(k) * inv_k;
        double wa;
        double wb;
        fit_weights(s, &wa, &wb);
        const Vec3 pi = grid_i != nullptr ? grid_i[k]
                                          : pos_i(static_cast<double>(k) * t_step, sin_lat, cos_lat, gravity);
        const Vec3& pb = grid[k];
        ia = ia + wa * pi;
        ib = ib + wb * pi;
        ba = ba + wa * pb;
        bb = bb + wb * pb;
        i0 = i0 + pi;
        i1 = i1 + s * pi;
        b0 = b0 + pb;
        b1 = b1 + s * pb;
        a0 = a0 + wa;
        a1 = a1 + wa * s;
        c0 = c0 + wb;
        c1 = c1 + wb * s;
        s1 = s1 + s;
        s2 = s2 + s * s;
    }
    // [n s1; s1 s2] [alpha; beta] = [sum phi; sum phi s]
    const double s0 = static_cast<double>(n);
    const double det = s0 * s2 - s1 * s1;
    const double alpha_a = (s2 * a0 - s1 * a1) / det;
    const double beta_a = (s0 * a1 - s1 * a0) / det;
    const double alpha_b = (s2 * c0 - s1 * c1) / det;
    const double beta_b = (s0 * c1 - s1 * c0) / det;
    ia = ia - alpha_a * i0 - beta_a * i1;
    ib = ib - alpha_b * i0 - beta_b * i1;
    ba = ba - alpha_a * b0 - beta_a * b1;
    bb = bb - alpha_b * b0 - beta_b * b1;
    // anchored on the gravity pair (phi_a), turned about it by the Earth-rate pair
    return solve_mat_i_ib0(ib, ia, bb, ba);
}

}  // namespace

Mat3 solve_fit(const Vec3* grid, int32_t n, double t_step, double sin_lat, double cos_lat,
               double gravity) {
    return fit_sums(grid, nullptr, n, t_step, sin_lat, cos_lat, gravity);
}

Mat3 solve_vel_grid(const Vec3* grid, const Vec3* grid_i, int32_t n) {
    // Weighted sums over the grid points k = 0 .. K, s = k / K, the weights
    // s (orthogonal to 1) and s^2 (orthogonal to 1 and s) made exact on the
    // grid by the discrete normal equations, the projections accumulated in
    // one pass as fit_sums does: sum w' v = sum w v - alpha sum v - beta sum s v.
    const int32_t k_end = n - 1;
    const double inv_k = 1.0 / static_cast<double>(k_end);
    Vec3 ia = Vec3::Zero();
    Vec3 ib = Vec3::Zero();
    Vec3 ba = Vec3::Zero();
    Vec3 bb = Vec3::Zero();
    Vec3 i0 = Vec3::Zero();
    Vec3 b0 = Vec3::Zero();
    double s1 = 0.0;   // sum s, sum s^2, sum s^3 (sum 1 = n)
    double s2 = 0.0;
    double s3 = 0.0;
    for (int32_t k = 0; k <= k_end; ++k) {
        const double s = static_cast<double>(k) * inv_k;
        const double ss = s * s;
        const Vec3& vi = grid_i[k];
        const Vec3& vb = grid[k];
        ia = ia + s * vi;
        ib = ib + ss * vi;
        ba = ba + s * vb;
        bb = bb + ss * vb;
        i0 = i0 + vi;
        b0 = b0 + vb;
        s1 = s1 + s;
        s2 = s2 + ss;
        s3 = s3 + ss * s;
    }
    const double s0 = static_cast<double>(n);
    // psi_a = s - s1 / n; psi_b = s^2 - alpha - beta s with
    // [n s1; s1 s2] [alpha; beta] = [s2; s3]
    const double mean_s = s1 / s0;
    const double det = s0 * s2 - s1 * s1;
    const double alpha = (s2 * s2 - s1 * s3) / det;
    const double beta = (s0 * s3 - s1 * s2) / det;
    // sum psi_b v = sum s^2 v - alpha sum v - beta sum s v
    ib = ib - alpha * i0 - beta * ia;
    bb = bb - alpha * b0 - beta * ba;
    ia = ia - mean_s * i0;
    ba = ba - mean_s * b0;
    // anchored on the gravity pair (psi_a), turned about it by the Earth-rate pair
    return solve_mat_i_ib0(ib, ia, bb, ba);
}

double heading_sigma(int32_t n, double t_step, double var, double gravity, double cos_lat) {
    // sigma(b2) = sigma / sqrt(sum q_k^2), q(t) = t^2 - alpha - beta t
    // orthogonal to 1 and t on the grid t_k = k t_step; b2 = g cos L Omega / 2
    double s1 = 0.0;
    double s2 = 0.0;
    double s3 = 0.0;
    double s4 = 0.0;
    for (int32_t k = 0; k < n; ++k) {
        const double t = static_cast<double>(k) * t_step;
        const double tt = t * t;
        s1 = s1 + t;
        s2 = s2 + tt;
        s3 = s3 + tt * t;
        s4 = s4 + tt * tt;
    }
    const double s0 = static_cast<double>(n);
    const double det = s0 * s2 - s1 * s1;
    const double alpha = (s2 * s2 - s1 * s3) / det;
    const double beta = (s0 * s3 - s1 * s2) / det;
    // sum q^2 = sum q t^2 (q is orthogonal to 1 and t) = s4 - alpha s2 - beta s3
    const double qq = s4 - alpha * s2 - beta * s3;
    return pmath::sqrt(var / qq) / (0.5 * gravity * cos_lat * earth::kOmegaIe);
}

Mat3 mat_n_e(double sin_lat, double cos_lat) {
    Mat3 m;
    m << 0.0, 1.0, 0.0,
         -sin_lat, 0.0, cos_lat,
         cos_lat, 0.0, sin_lat;
    return m;
}

Mat3 mat_n_e_at(double sin_lat, double cos_lat, double sin_dlon, double cos_dlon) {
    // rows E, N, U of the reference point in e: mat_n_e's rows turned by dlon about z
    Mat3 m;
    m << -sin_dlon, cos_dlon, 0.0,
         -sin_lat * cos_dlon, -sin_lat * sin_dlon, cos_lat,
         cos_lat * cos_dlon, cos_lat * sin_dlon, sin_lat;
    return m;
}

namespace {

/// C_e^i(t) x = Rz(w t) x.
Vec3 e_to_i(double t, const Vec3& x) {
    double s;
    double c;
    pmath::sincos(earth::kOmegaIe * t, &s, &c);
    return Vec3(c * x(0) - s * x(1), s * x(0) + c * x(1), x(2));
}

/// C_n^e x for n at (lat, dlon): x_E E + x_N N + x_U U (mat_n_e_at's rows).
Vec3 n_to_e(double sin_lat, double cos_lat, double sin_dlon, double cos_dlon, double xe, double xn,
            double xu) {
    return Vec3(-sin_dlon * xe - sin_lat * cos_dlon * xn + cos_lat * cos_dlon * xu,
                cos_dlon * xe - sin_lat * sin_dlon * xn + cos_lat * sin_dlon * xu,
                cos_lat * xn + sin_lat * xu);
}

}  // namespace

Vec3 known_force_i(double t, double sin_lat, double cos_lat, double sin_dlon, double cos_dlon,
                   double gravity, double ve, double vn) {
    // g up + w_ie^n x v, v = (ve, vn, 0), w_ie^n = (0, W cos L, W sin L):
    // w x v = (-W sin L vn, W sin L ve, -W cos L ve)
    const double w = earth::kOmegaIe;
    const double ce = -w * sin_lat * vn;
    const double cn = w * sin_lat * ve;
    const double cu = -w * cos_lat * ve + gravity;
    return e_to_i(t, n_to_e(sin_lat, cos_lat, sin_dlon, cos_dlon, ce, cn, cu));
}

Vec3 ref_vel_i(double t, double sin_lat, double cos_lat, double sin_dlon, double cos_dlon, double ve,
               double vn, double vu) {
    return e_to_i(t, n_to_e(sin_lat, cos_lat, sin_dlon, cos_dlon, ve, vn, vu));
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

double rotation_sine(const Mat3& a, const Mat3& b) {
    // R = a^T b = I cos t + (1 - cos t) u u^T + sin t [u x]: the skew part
    // is sin t u, the trace 1 + 2 cos t.
    const Mat3 r = a.transpose() * b;
    if (r(0, 0) + r(1, 1) + r(2, 2) < 1.0) {
        return 1.0;
    }
    const double x = 0.5 * (r(2, 1) - r(1, 2));
    const double y = 0.5 * (r(0, 2) - r(2, 0));
    const double z = 0.5 * (r(1, 0) - r(0, 1));
    return pmath::sqrt(x * x + y * y + z * z);
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
    a.hist.cone1 = Vec3::Zero();
    a.hist.scul1 = Vec3::Zero();
    a.tick = 0;
    a.vel_prev = Vec3::Zero();
    a.pos_ib0 = Vec3::Zero();
    a.lever_vel0 = Vec3::Zero();
    for (int i = 0; i < kHistLen; ++i) {
        a.grid[i] = Vec3::Zero();
    }
    a.hist_count = 1;  // v^ib0(t0) = 0, P^ib0(t0) = 0
    a.grid_every = prm.output_every;
    a.mat_i_ib0 = Mat3::Identity();
    a.solved = false;
    a.settling = false;
    a.settle_ref = Mat3::Identity();
    a.wander = 0.0;
    for (int i = 0; i < 3; ++i) {
        a.noise_v[i] = Vec3::Zero();
    }
    a.noise_seen = 0;
    a.noise_sum = 0.0;
    a.noise_n = 0;
    a.ref_done = 0;    // even t0's i side waits for C_n^i v(t0)
    a.ref_count = 0;
    a.grid_from = 0;
    a.reserved_fv = 0;
    a.dlat = 0.0;
    a.dlon = 0.0;
    a.ref_vel[0] = 0.0;
    a.ref_vel[1] = 0.0;
    a.ref_tick = -1;
    a.ref_gap = 0;
    a.known_f = known_force_i(0.0, prm.sin_lat, prm.cos_lat, 0.0, 1.0, prm.gravity, 0.0, 0.0);
    a.known_v = Vec3::Zero();
    a.ref_cv = Vec3::Zero();
    a.ref_var = 0.0;
    a.sigma_heading = 0.0;
    a.settle_sigma = 0.0;
}

double measured_vrw(const CoarseAlign& a) {
    if (a.noise_n < kNoiseMinSamples) {
        return 0.0;
    }
    const double tau = static_cast<double>(a.prm.noise_every) * a.prm.dt;
    return pmath::sqrt(tau / 6.0 * (a.noise_sum / static_cast<double>(a.noise_n)) / 2.0);
}

namespace {

/// The wander test on a new solution (see the header).
void settle(CoarseAlign& a) {
    if (a.tick < a.prm.settle_from) {
        return;
    }
    if (!a.settling) {
        a.settling = true;
        a.settle_ref = a.mat_i_ib0;
        a.settle_sigma = a.sigma_heading;
        return;
    }
    const double s = rotation_sine(a.settle_ref, a.mat_i_ib0);
    if (s > a.wander) {
        a.wander = s;
    }
}

/// One block end of the noise measurement (see the header): v, the
/// reference point's v^ib0 now.
void measure_noise(CoarseAlign& a, const Vec3& v) {
    if (a.noise_seen == 3) {
        const double tau = static_cast<double>(a.prm.noise_every) * a.prm.dt;
        const Vec3 d = (v - 3.0 * a.noise_v[0] + 3.0 * a.noise_v[1] - a.noise_v[2]) / tau;
        const double vv = v.dot(v);
        if (vv > 0.0) {
            const double up = d.dot(v);
            a.noise_sum = a.noise_sum + (d.dot(d) - up * up / vv);
            a.noise_n = a.noise_n + 1;
        }
    } else {
        a.noise_seen = a.noise_seen + 1;
    }
    a.noise_v[2] = a.noise_v[1];
    a.noise_v[1] = a.noise_v[0];
    a.noise_v[0] = v;
}

/// FIT_VEL: sin, cos of the reference point's latitude and of dlon now.
void ship_sincos(const CoarseAlign& a, double* sin_lat, double* cos_lat, double* sin_dlon,
                 double* cos_dlon) {
    double sd;
    double cd;
    pmath::sincos(a.dlat, &sd, &cd);
    *sin_lat = a.prm.sin_lat * cd + a.prm.cos_lat * sd;
    *cos_lat = a.prm.cos_lat * cd - a.prm.sin_lat * sd;
    pmath::sincos(a.dlon, sin_dlon, cos_dlon);
}

/// FIT_VEL, once a tick after a.tick advanced: the reference point carried
/// by the last reference velocity, and K (see the header) by the trapezoid rule.
void carry_known(CoarseAlign& a) {
    const double dt = a.prm.dt;
    double sl;
    double cl;
    double sd;
    double cd;
    ship_sincos(a, &sl, &cl, &sd, &cd);
    a.dlat = a.dlat + a.ref_vel[1] * dt / a.prm.rm_h;
    a.dlon = a.dlon + a.ref_vel[0] * dt / (a.prm.rn_h * cl);
    ship_sincos(a, &sl, &cl, &sd, &cd);
    const double t = static_cast<double>(a.tick) * dt;
    const Vec3 f = known_force_i(t, sl, cl, sd, cd, a.prm.gravity, a.ref_vel[0], a.ref_vel[1]);
    a.known_v = a.known_v + (0.5 * dt) * (a.known_f + f);
    a.known_f = f;
}

}  // namespace

void reference(CoarseAlign& a, double ve, double vn, double vu, double sigma, int64_t ref_tick) {
    if (ref_tick < 0 || ref_tick > a.tick || (a.ref_tick >= 0 && ref_tick <= a.ref_tick)) {
        return;   // before the alignment, ahead of it, or not newer than the last: not taken
    }
    const double dt = a.prm.dt;
    double sl;
    double cl;
    double sd;
    double cd;
    ship_sincos(a, &sl, &cl, &sd, &cd);
    const Vec3 cv = ref_vel_i(static_cast<double>(ref_tick) * dt, sl, cl, sd, cd, ve, vn, vu);
    // the previous epoch: the last reference, or t0 with this velocity
    const bool first = a.ref_tick < 0;
    if (first) {
        // the points before it are left out of the fit
        a.grid_from = static_cast<int32_t>((ref_tick + a.grid_every - 1) / a.grid_every);
    }
    const int64_t t_prev = first ? 0 : a.ref_tick;
    const Vec3 cv_prev = first ? cv : a.ref_cv;
    const int64_t gap = ref_tick - t_prev;
    if (gap > a.ref_gap) {
        a.ref_gap = gap;
    }
    // the grid points in (t_prev, ref_tick]: the velocity linear in between
    while (a.ref_done < a.hist_count && static_cast<int64_t>(a.ref_done) * a.grid_every <= ref_tick) {
        const int64_t u = static_cast<int64_t>(a.ref_done) * a.grid_every - t_prev;
        const double frac = gap > 0 ? static_cast<double>(u) / static_cast<double>(gap) : 0.0;
        Vec3& gi = a.grid[kFitVelLen + a.ref_done];
        gi = gi + cv_prev + frac * (cv - cv_prev);
        a.ref_done = a.ref_done + 1;
    }
    a.ref_vel[0] = ve;
    a.ref_vel[1] = vn;
    a.ref_tick = ref_tick;
    a.ref_cv = cv;
    a.ref_var = a.ref_var + sigma * sigma;
    if (a.ref_count < (1 << 30)) {
        a.ref_count = a.ref_count + 1;
    }
}

void update(CoarseAlign& a, const Vec3& dtheta_p, const Vec3& dv_p, const Vec3& lever_vel_p,
            const Vec3& ref_lever_p) {
    // Velocity and attitude in ib0: dv rotated by C_p^ib0 at the tick start.
    const strapdown::Compensated c = strapdown::compensate(dtheta_p, dv_p, a.hist);
    a.vel_ib0 = a.vel_ib0 + attitude::quat_to_mat(a.quat_ib0_p) * c.dv_p;
    a.quat_ib0_p = attitude::quat_renormalize(
        attitude::quat_mul(a.quat_ib0_p, attitude::rotvec_to_quat(c.phi)));
    strapdown::push_history(a.hist, dtheta_p, dv_p, c);
    a.tick = a.tick + 1;

    // The reference point's v^ib0, less the constant u^p(t0) (added back by
    // TRIAD; a linear term of P that FIT ignores).
    Vec3 vel = a.vel_ib0;
    if (a.prm.lever != 0) {
        vel = vel - attitude::quat_to_mat(a.quat_ib0_p) * lever_vel_p;
        if (a.tick == 1) {
            // u^p(t0) from the first sample's rate (its mean over the tick):
            // off by |w'| dt / 2 |r|, a few mm/s on a swinging ship; FIT does
            // not need it.
            a.lever_vel0 = lever_vel_p;
        }
    }
    if (a.prm.noise_every > 0 && a.tick % a.prm.noise_every == 0) {
        measure_noise(a, vel);
    }
    const bool fit_vel = a.prm.method == static_cast<int32_t>(Method::kFitVel);
    const bool fit = a.prm.method == static_cast<int32_t>(Method::kFit) || fit_vel;
    if (fit_vel) {
        carry_known(a);
        if (a.tick == 1) {
            // t0's ib0 side: v^ib0(t0) = 0 less the accelerometers' lever
            // velocity plus the antenna's (see the header)
            a.grid[0] = a.prm.lever != 0 ? ref_lever_p - lever_vel_p : ref_lever_p;
        }
    }
    if (fit && !fit_vel) {
        a.pos_ib0 = a.pos_ib0 + (0.5 * a.prm.dt) * (a.vel_prev + vel);  // trapezoid
        a.vel_prev = vel;
    }

    const int64_t every = a.prm.output_every;
    const int32_t cap = fit_vel ? kFitVelLen : kHistLen;
    if (fit && a.tick % a.grid_every == 0 && a.hist_count == cap) {
        // The grid is full: keep every other point at twice the spacing, so
        // FIT runs as long as asked in fixed storage (P is smooth: its wave
        // content has periods of seconds, the spacing after one halving 2
        // output intervals).
        for (int32_t k = 1; k < cap / 2; ++k) {
            a.grid[k] = a.grid[2 * k];
        }
        if (fit_vel) {
            for (int32_t k = 1; k < cap / 2; ++k) {
                a.grid[kFitVelLen + k] = a.grid[kFitVelLen + 2 * k];
            }
            a.ref_done = (a.ref_done + 1) / 2;   // point k was 2k: complete if 2k < ref_done
            a.grid_from = (a.grid_from + 1) / 2; // and in the fit if 2k >= grid_from
        }
        a.hist_count = cap / 2;
        a.grid_every = 2 * a.grid_every;
    }
    if (a.tick % a.grid_every == 0 && a.hist_count < cap) {
        if (fit_vel) {
            // the antenna's lever on the ib0 side; K now, the reference's integral to come
            a.grid[a.hist_count] = vel + attitude::quat_to_mat(a.quat_ib0_p) * ref_lever_p;
            a.grid[kFitVelLen + a.hist_count] = a.known_v;
        } else {
            a.grid[a.hist_count] = fit ? a.pos_ib0 : vel;
        }
        a.hist_count = a.hist_count + 1;
    }
    if (a.tick >= a.prm.first_output && (a.tick - a.prm.first_output) % every == 0) {
        if (fit_vel) {
            // the grid points a reference has completed (a reference interval behind)
            const int32_t n_fit = a.ref_done - a.grid_from;
            if (n_fit > kFitMinIntervals) {
                a.mat_i_ib0 = solve_vel_grid(a.grid + a.grid_from, a.grid + kFitVelLen + a.grid_from, n_fit);
                a.sigma_heading = heading_sigma(n_fit, static_cast<double>(a.grid_every) * a.prm.dt,
                                                a.ref_var / static_cast<double>(a.ref_count), a.prm.gravity,
                                                a.prm.cos_lat);
                a.solved = true;
                settle(a);
            }
            return;
        }
        if (fit) {
            a.mat_i_ib0 = solve_fit(a.grid, a.hist_count, static_cast<double>(a.grid_every) * a.prm.dt,
                                    a.prm.sin_lat, a.prm.cos_lat, a.prm.gravity);
            a.solved = true;
            settle(a);
            return;
        }
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
        Vec3 vb1 = a.grid[k1];
        Vec3 vb2 = vel;
        if (a.prm.lever != 0) {
            vb1 = vb1 + a.lever_vel0;
            vb2 = vb2 + a.lever_vel0;
        }
        if (a.prm.method == static_cast<int32_t>(Method::kEq8)) {
            a.mat_i_ib0 = solve_eq8(vi1, vi2, vb1, vb2);  // seed 000 eq. 8 as printed
        } else {
            a.mat_i_ib0 = solve_mat_i_ib0(vi1, vi2, vb1, vb2);
        }
        a.solved = true;
        settle(a);
    }
}

Mat3 mat_n_p(const CoarseAlign& a) {
    const double t = static_cast<double>(a.tick) * a.prm.dt;
    Mat3 n_e = mat_n_e(a.prm.sin_lat, a.prm.cos_lat);
    if (a.prm.method == static_cast<int32_t>(Method::kFitVel)) {
        double sl;
        double cl;
        double sd;
        double cd;
        ship_sincos(a, &sl, &cl, &sd, &cd);
        n_e = mat_n_e_at(sl, cl, sd, cd);
    }
    const Mat3 m = n_e * mat_e_i(t) * a.mat_i_ib0 * attitude::quat_to_mat(a.quat_ib0_p);
    if (a.prm.method == static_cast<int32_t>(Method::kEq8)) {
        // seed 000: eq. 8's matrix into eq. 1, the attitude angles read off its elements
        return attitude::euler_to_mat(attitude::mat_to_euler(m));
    }
    return m;
}

}  // namespace pyins::coarse_align
