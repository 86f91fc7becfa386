// moving_align.hpp: moving-base Kalman fine alignment of a moored ship by
// position matching, 12 states, for the IMU frame p.
//
// Mirrored by pyins/reference/moving_align.py. Measurements and design
// notes: docs/concepts.md, "Alignment on a moving base" and "Integrity".
//
// Why: seed 001's static filters measure the specific force in n, which on
// a heaving ship carries the waves' acceleration, and they fail (their NIS
// test flags it). Here the strapdown runs free in the horizontal (the
// vertical channel held) and the measurement is the reference point's
// position relative to the mooring site: a wave enters as a zero-mean
// displacement, its acceleration / w^2, which the filter takes as
// measurement noise; tilt and heading act through the velocity and
// position errors they make grow (the velocity-matching idea of PSINS's
// alignvn, in position, which the waves disturb less).
//
// States (phi as in fine_align: C_p^n' = (I - phi x) C_p^n; errors =
// computed - true; eps, nabla in n, random constants):
//   X = [phi_E phi_N phi_U dv_E dv_N dp_E dp_N eps_E eps_N eps_U nabla_E nabla_N]
// Dynamics, linearised about the ship at rest (Qin Yongyuan, "Inertial
// Navigation", 2nd ed. 2014, eqs. 4.2.6 and 4.2.15, ENU, vertical held):
//   phi'  = phi x w_ie^n + [-dv_N / R_M, dv_E / R_N, dv_E tanL / R_N] - eps
//   dv_E' = f_N phi_U - f_U phi_N + 2 w_U dv_N + nabla_E      (f x phi + nabla)
//   dv_N' = f_U phi_E - f_E phi_U - 2 w_U dv_E + nabla_N
//   dp'   = dv
// with f^n the mean specific force over the interval. The static part
// (phi x w_ie - eps) is seed 001's eq. 10.
// Measurement every meas_every ticks: z = [E, N] offset of the reference
// point from the site [m] = dp + d_wave + v, R = pos_sigma^2 I.
// Discretisation once per interval T: Phi = I + F T + (F T)^2 / 2, Qd =
// diag(arw^2 T on phi, vrw^2 T on dv); the update as two scalar updates
// (H a unit row, R diagonal). Feedback after every update (the
// firmware corrects attitude, velocity and position and zeroes phi, dv, dp).
// Integrity: the same NIS windows as fine_align.
//
// The site's slow motion (site_accel; docs/concepts.md, "What integrity
// catches and what it cannot"). A ship ranging on its lines moves the
// reference point by metres at periods of minutes: in z that is not white
// noise but a smooth displacement d, and the filter reads heading from the
// cubic p_N = -(1/6) g w_N phi_U t^3 (1' is 3.2 m over 480 s), so d of a
// period near the alignment's length becomes arc-minutes of heading that
// the filter, taking d as white, reports with a sigma of ~3'. Modelled:
// d'' = white acceleration of density q = site_accel (an integrated random
// walk). The filter's position and velocity states then stand for the
// reference point's offset from the site, dp + d, dv + d', whose dynamics
// are dp's plus that acceleration: Qd on dv gains q^2 T (the same model as
// two more states for d, with d absorbed into dp, dv: no new state; the
// feedback then moves the navigation to the site's mean, by up to the
// ranging's amplitude). The heading's information from position over T
// against that acceleration, the t^2 term free (tilt, bias): the second
// derivative of the signal, 6 k phi_U (t - T/2), k = g w_N / 6, whitened by q,
// integrates to 3 k^2 T^3 / q^2 (Fisher information of the t^3 coefficient,
// e.g. Bar-Shalom et al. 2001, sec. 2.7.2); so a coarse alignment of T_c
// seconds leaves phi_U a sigma of at least q / (k sqrt(3 T_c^3)) and the
// level q / (g sqrt(T_c)) (the constant acceleration's). sigma0_after_coarse
// adds these (and the coarse wander) to the prior, kSiteMargin times, in
// quadrature: 120 s of FIT and q = 1000 ug/sqrt(Hz) give 150' of heading.
// With q = 0 (a rigid site: the default) nothing changes, bit for bit.
#pragma once

#include <cstdint>

#include "kalman.hpp"
#include "types.hpp"

namespace pyins::moving_align {

inline constexpr int kStates = 12;
/// State indices.
inline constexpr int kPhi = 0;    ///< phi_E, phi_N, phi_U
inline constexpr int kVel = 3;    ///< dv_E, dv_N
inline constexpr int kPos = 5;    ///< dp_E, dp_N
inline constexpr int kEps = 7;    ///< eps_E, eps_N, eps_U
inline constexpr int kNabla = 10; ///< nabla_E, nabla_N
/// The prior's margin on what the site motion and the wander leave the
/// coarse result (fine_align::kAfterCoarseMargin's 3, for the same reason).
inline constexpr double kSiteMargin = 3.0;

struct Params {
    double sin_lat;
    double cos_lat;
    double rm_h;             ///< R_M + h at the site [m]
    double rn_h;             ///< R_N + h at the site [m]
    double dt;               ///< tick [s]
    int32_t meas_every;      ///< ticks per update
    int32_t nis_window;      ///< updates per NIS window; 0: no test
    double gyro_arw;         ///< [rad/sqrt(s)]
    double accel_vrw;        ///< [(m/s)/sqrt(s)]
    double pos_sigma;        ///< R: the waves' horizontal displacement [m]
    double site_accel;       ///< the site's slow motion: white acceleration density [m/s^2/sqrt(Hz)]; 0: rigid
    double sigma0_att[3];    ///< [rad]
    double sigma0_vel;       ///< [m/s]
    double sigma0_gyro;      ///< [rad/s]
    double sigma0_accel;     ///< [m/s^2]
    double nis_max;
};
// The two int32 side by side: no padding, so a Params copied from a stack
// local (MovingAlign::prm) carries no undefined bytes into a snapshot.
static_assert(sizeof(Params) == 16 * sizeof(double) + 2 * sizeof(int32_t), "moving_align::Params has no padding");

struct MovingAlign {
    Params prm;
    kalman::Vec<kStates> x;
    kalman::Mat<kStates, kStates> p;
    Vec3 dv_sum;             ///< specific-force velocity increments in n' since the last update
    int32_t meas_count;
    bool healthy;
    bool consistent;
    double nis_sum;
    int32_t nis_count;
    double nis_mean;
    int32_t nis_windows;
};

void init(MovingAlign& m, const Params& prm);

/// After a coarse alignment of coarse_s seconds that wandered by `wander`
/// (sine): sigma0_att[i] = sqrt(sigma0_att[i]^2 + kSiteMargin^2 (s_i^2 +
/// wander^2)), s = the site motion's level and heading sigmas (header);
/// nothing when site_accel is 0. gravity [m/s^2] at the site.
void sigma0_after_coarse(Params& prm, double coarse_s, double wander, double gravity);

/// Continuous-time F for the mean specific force f_n [m/s^2].
kalman::Mat<kStates, kStates> system_matrix(const Params& prm, const Vec3& f_n);

/// One tick: gather the specific force; at the end of an interval predict
/// over it and update with z_en, the reference point's [E, N] offset from
/// the site [m] (read only then; `measure` says whether it is due).
/// Returns true when an update happened.
bool step(MovingAlign& m, const Vec3& dv_sf_n, const double z_en[2]);

/// True when this tick ends an interval (the firmware forms z then).
inline bool measure(const MovingAlign& m) { return m.meas_count + 1 == m.prm.meas_every; }

/// After the feedback: phi, dv, dp = 0.
void reset_feedback(MovingAlign& m);

}  // namespace pyins::moving_align
