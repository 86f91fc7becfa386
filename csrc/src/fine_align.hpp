// fine_align.hpp: static-base Kalman fine alignment (seed 001: Yan Gongmin,
// Qin Yongyuan, Computer Simulation 2006, no. 10, p. 36), full 8-state and
// reduced 5-state filters, for the IMU frame p.
//
// Mirrored by pyins/reference/fine_align.py.
//
// States (n = ENU, phi: C_p^n' = (I - phi x) C_p^n):
//   8-state X = [phi_E phi_N phi_U eps_E eps_N eps_U nabla_E nabla_N]   (eq. 11)
//   5-state X = [phi_E^ phi_N^ phi_U^ eps_N^ eps_U^]                     (eqs. 21-24)
// Dynamics (eq. 10, static base):
//   phi_E' =  w_U phi_N - w_N phi_U - eps_E,  phi_N' = -w_U phi_E - eps_N,
//   phi_U' =  w_N phi_E - eps_U;  eps, nabla constant.
// Measurement (eq. 15, with (15b)'s sign typo corrected as H and (23b) show):
//   Z = [f_E f_N] of C_p^n' f^p = [-g phi_N + nabla_E, g phi_E + nabla_N] + v.
// Discretisation: Phi = I + F T + (F T)^2 / 2 (F is constant on a static
// base; the next term is < 1e-20 at T = 10 ms), Qd = diag(arw^2 T) on phi
// (isotropic gyros: C Q^b C^T = arw^2 I). The measurement is the specific
// force averaged over meas_every ticks, so R = vrw^2 / (meas_every T) I
// (seed 001 prints R as a copy of Q: a typo; the accelerometer noise
// projected into n is meant). P0 = diag(sigma0)^2 with seed 001's
// sigma0 = 10 x [10', 10', 60', 0.001 deg/h, 0.001 deg/h] by default.
// After a coarse alignment an attitude sigma left 0 fits the coarse result
// instead (sigma0_after_coarse below): seed 001's 600' of heading lets the
// first updates swing a heading the coarse phase had right to arc-minutes.
// Integrity: the normalised innovation squared of each update (chi-square,
// 2 degrees of freedom, mean 2 while the model holds) is averaged over
// windows of nis_window updates; a window mean beyond nis_max says the
// measurements do not fit the static-base model (a heaving ship, an unknown
// lever arm, a noise density set too low) and clears `consistent` for good.
// With 100 updates the mean of a consistent window has a sigma of
// sqrt(4 / 100) = 0.2: the default bound 4 is 10 sigma. Until the first
// window is complete the firmware reports the estimate as provisional (a
// wide prior lets the first updates take a wave's acceleration for a tilt).
// Feedback (recommended by the paper; the firmware's choice, not this
// module's): after each update the attitude is corrected by phi^ and phi^
// reset to zero (reset_phi); open loop leaves the attitude alone and reports
// the corrected one.
// Measurements and design notes: docs/core.md, "Fine alignment (seed 001)",
// "Fine alignment after a coarse one" and "Measurement noise of the fine
// alignment"; docs/concepts.md, "Integrity"; docs/papers.md, seed 001.
#pragma once

#include <cstdint>

#include "kalman.hpp"
#include "types.hpp"
#include "units.hpp"

namespace pyins::fine_align {

struct Params {
    double sin_lat;
    double cos_lat;
    double gravity;          ///< [m/s^2]
    double dt;               ///< tick [s]
    int32_t meas_every;      ///< ticks per measurement
    int32_t nis_window;      ///< updates per NIS window; 0: no test
    double gyro_arw;         ///< [rad/sqrt(s)]
    double accel_vrw;        ///< [(m/s)/sqrt(s)]
    double sigma0_att[3];    ///< [rad] E, N, U
    double sigma0_gyro;      ///< [rad/s]
    double sigma0_accel;     ///< [m/s^2] (8-state only)
    double nis_max;          ///< bound on a window's mean NIS
};
// The two int32 side by side: no padding, so a Params copied from a stack
// local (FineFilter::init) carries no undefined bytes into a snapshot.
static_assert(sizeof(Params) == 12 * sizeof(double) + 2 * sizeof(int32_t), "fine_align::Params has no padding");

/// State indices, the layouts above (the mirror's PHI, EPS, NABLA, EPS_NU),
/// in the order the output record's kf_x and kf_sigma hold them.
inline constexpr int kPhi = 0;     ///< phi_E, phi_N, phi_U (both; the 5-state's transformed phi^)
inline constexpr int kEps = 3;     ///< eps_E, eps_N, eps_U (8-state)
inline constexpr int kNabla = 6;   ///< nabla_E, nabla_N (8-state)
inline constexpr int kEpsNU = 3;   ///< eps_N^, eps_U^ (5-state)

template <int N>
struct FineAlign {
    static_assert(N == 5 || N == 8, "the 5-state or the 8-state filter");
    kalman::Vec<N> x;
    kalman::Mat<N, N> p;
    kalman::Mat<N, N> phi;
    kalman::Mat<N, N> qd;
    kalman::Mat<2, N> h;
    kalman::Mat<2, 2> r;
    Vec3 dv_sum;             ///< specific-force velocity increments in n' since the last update
    int32_t meas_count;      ///< ticks in dv_sum
    int32_t meas_every;
    double meas_span;        ///< meas_every * dt [s]
    bool healthy;            ///< P positive definite (diagonal check) after every step
    bool consistent;         ///< no NIS window beyond nis_max so far
    int32_t nis_window;
    double nis_max;
    double nis_sum;          ///< NIS of the updates of the current window
    int32_t nis_count;       ///< updates in it
    double nis_mean;         ///< mean NIS of the last complete window (0 before)
    int32_t nis_windows;     ///< complete windows so far
};

/// Continuous-time F of eq. 10 / eq. 23 for this filter.
template <int N>
kalman::Mat<N, N> system_matrix(double sin_lat, double cos_lat);

/// The initial attitude sigma after a coarse alignment: margin x the
/// coarse phase's expected error, never below the floor nor above the cap.
inline constexpr double kAfterCoarseMargin = 3.0;
inline constexpr double kAfterCoarseFloor = 1.0 * kArcminToRad;   ///< [rad]

/// Replace each sigma0_att[i] that is 0 by the fit to a coarse alignment of
/// coarse_s seconds whose solution wandered by `wander` (sine) over its last
/// fifth, from the errors prm states (seed 001 §2's limits; docs/papers.md):
///   level^2   = (sigma0_accel / g)^2 + accel_vrw^2 / (g^2 T)
///   heading^2 = (sigma0_gyro / w_N)^2 + (tan L sigma0_accel / g)^2
///               + gyro_arw^2 / (w_N^2 T),   w_N = Omega_ie cos L
///   sigma0_att = min(cap, max(floor, margin sqrt(term^2 + wander^2)))
/// (the white-noise terms: the sensor noise averaged over the T seconds).
void sigma0_after_coarse(Params& prm, double coarse_s, double wander, const double cap[3]);

template <int N>
void init(FineAlign<N>& f, const Params& prm);

/// One tick: time update, then a measurement update when meas_every ticks
/// of specific force have been gathered. dv_sf_n: the tick's specific-force
/// velocity increment projected into n' by the current attitude [m/s].
/// Returns true when a measurement update happened.
template <int N>
bool step(FineAlign<N>& f, const Vec3& dv_sf_n);

/// The attitude error estimate phi^ (E, N, U) [rad].
template <int N>
Vec3 phi(const FineAlign<N>& f) {
    return Vec3(f.x(kPhi + 0), f.x(kPhi + 1), f.x(kPhi + 2));
}

/// After feeding phi^ back into the attitude: phi^ = 0.
template <int N>
void reset_phi(FineAlign<N>& f) {
    f.x(kPhi + 0) = 0.0;
    f.x(kPhi + 1) = 0.0;
    f.x(kPhi + 2) = 0.0;
}

extern template struct FineAlign<5>;
extern template struct FineAlign<8>;

}  // namespace pyins::fine_align
