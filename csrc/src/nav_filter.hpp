// nav_filter.hpp: the integrated navigation filter at sea: an error-state
// Kalman filter run beside the strapdown in NAVIGATE, 12 states, for the
// IMU frame p on its turntable.
//
// Mirrored by pyins/reference/nav_filter.py. Design notes and measured
// figures: docs/concepts.md, "At sea".
//
// States (errors = computed - true; phi as in fine_align: C_p^n' =
// (I - phi x) C_p^n; the vertical channel held by the height reference, so
// no vertical velocity or position state):
//   X = [phi_E phi_N phi_U dv_E dv_N dp_E dp_N eps_x eps_y eps_z nabla_x nabla_y]
// eps, nabla are the gyro and accelerometer biases left after the
// compensation (random constants) in p: the table turns them in n, which is
// what makes the horizontal gyro biases and the accelerometer biases
// observable at sea (a fixed IMU has eps_E and the level biases hidden
// behind tilt and heading, seed 001). nabla_z is not a state: with the
// vertical held it reaches the horizontal only through the tilt.
//
// Dynamics (Yan Gongmin, "Strapdown inertial navigation algorithm and
// integrated navigation principles", 2019, eqs. 4.2.26-4.2.33; Qin
// Yongyuan, "Inertial Navigation", 2nd ed. 2014, sec. 4.2.4, ENU), with
// w_in = w_ie + w_en, w_en = [-v_N/R_M, v_E/R_N, v_E tanL/R_N], dL = dp_N/R_M:
//   phi'  = -w_in x phi + dw_in - C_p^n eps
//           dw_in = [-dv_N/R_M, dv_E/R_N - w_ie sinL dL,
//                    dv_E tanL/R_N + (w_ie cosL + v_E sec^2 L / R_N) dL]
//   dv'   = f^n x phi - (2 w_ie + w_en) x dv + v x (2 dw_ie + dw_en) + C_p^n nabla
//           (horizontal rows; v_U = dv_U = 0: the v x dw terms keep their
//           up component, v_N a_U and -v_E a_U)
//   dp'   = dv
// f^n is the mean specific force over the interval and C_p^n the mean of
// the attitude at its two ends (the table turns 6 deg in a 1 s interval:
// the trapezoid's error on the mean is 1e-3 of it).
// Discretisation per interval T (nav_every_ticks, or up to a reference's
// tick): Phi = I + F T + (F T)^2 / 2, Qd = diag(arw^2 T on phi, vrw^2 T on
// dv, rw^2 T on eps), symmetrised, as moving_align.
// The table's moves: the errors the filter does not carry as states that
// a turn of the table by a exposes, the scale factor k_z of the gyro on
// its axis (a heading error k_z a) and the misalignments m_xz, m_yz of the
// other two to it (a tilt of at most m a, as the sensed rate turns with
// the table), enter Qd as the growth of (sigma a)^2 over the interval:
// sigma_k^2 d(a^2) on phi_U, sigma_m^2 d(a^2) on phi_E and phi_N (the
// table's axis is the ship's vertical to within its roll and pitch). Each
// move is taken as a fresh draw; on a ship the reverse move takes the
// error back, so this is the conservative side for the sigma, and the tilt
// term costs heading accuracy (the filter reads heading from the tilt's
// growth, which a redrawn tilt hides: 0.64' against 0.29' RMS over 6 h;
// docs/concepts.md, "At sea"). Those errors as states are the fix.
//
// Measurements (all unit rows: the vertical is held): a reference position
// on [dp_E, dp_N], a reference or zero velocity on [dv_E, dv_N] (a DVL's
// velocity turned into n by the firmware, Firmware::dvl_n), R diagonal.
// Each pair is gated by its joint normalised innovation squared nu^T S^-1 nu
// (S = H P H^T + R, chi-square with 2 degrees of freedom while the model
// holds; Bar-Shalom, Li, Kirubarajan 2001, sec. 5.4) before it is used, and
// applied as two scalar Joseph updates (moving_align.hpp says why they equal
// the joint one). Feedback after every update (the firmware's): attitude,
// velocity and position corrected, the biases added to the compensation,
// the state zeroed.
#pragma once

#include <cstdint>

#include "kalman.hpp"
#include "types.hpp"

namespace pyins::nav_filter {

inline constexpr int kStates = 12;
/// State indices.
inline constexpr int kPhi = 0;    ///< phi_E, phi_N, phi_U
inline constexpr int kVel = 3;    ///< dv_E, dv_N
inline constexpr int kPos = 5;    ///< dp_E, dp_N
inline constexpr int kEps = 7;    ///< eps_x, eps_y, eps_z (p)
inline constexpr int kNabla = 10; ///< nabla_x, nabla_y (p)

struct Params {
    double dt;               ///< tick [s]
    int32_t every;           ///< ticks per time update
    int32_t reject_limit;    ///< (the firmware's; kept with the filter's settings)
    double gyro_arw;         ///< [rad/sqrt(s)]
    double accel_vrw;        ///< [(m/s)/sqrt(s)]
    double gate;             ///< bound on a pair's NIS
    double sigma0_att[3];    ///< [rad]
    double sigma0_vel;       ///< [m/s]
    double sigma0_pos;       ///< [m]
    double sigma0_gyro;      ///< [rad/s]
    double sigma0_accel;     ///< [m/s^2]
    double gyro_bias_rw;     ///< the biases' random walk (their instability) [rad/s/sqrt(s)]; 0 = constants
    double table_scale;      ///< sigma of the scale factor of the gyro on the table's axis [-]; 0 = none
    double table_mis;        ///< sigma of the other gyros' misalignment to the table's axis [rad]; 0 = none
};
static_assert(sizeof(Params) == 14 * sizeof(double) + 2 * sizeof(int32_t), "nav_filter::Params has no padding");

/// Where the ship is and how it moves: the linearisation point.
struct Motion {
    double sin_lat;
    double cos_lat;
    double rm_h;             ///< R_M + h [m]
    double rn_h;             ///< R_N + h [m]
    double vel_e;            ///< [m/s]
    double vel_n;            ///< [m/s]
};

struct NavFilter {
    Params prm;
    kalman::Vec<kStates> x;
    kalman::Mat<kStates, kStates> p;
    Vec3 dv_sum;             ///< specific-force velocity increments in n' since the last time update [m/s]
    Mat3 c_start;            ///< C_p^n at the last time update
    int32_t ticks;           ///< ticks gathered since then
    int32_t healthy;         ///< 1 while P's diagonal stayed positive
    double move_angle;       ///< the table's turn since it last stood still [rad]
    double move_q;           ///< growth of move_angle^2 since the last time update [rad^2]
    Vec3 gyro_bias;          ///< compensated gyro biases, p [rad/s]
    Vec3 accel_bias;         ///< compensated accelerometer biases, p (z 0) [m/s^2]
};

/// Start the filter at an attitude C_p^n (c_np): P diagonal from the sigmas.
void init(NavFilter& f, const Params& prm, const Mat3& c_np);

/// One tick's specific-force velocity increment in n' [m/s] and the
/// table's turn over it dalpha [rad]: a move's angle a since the table last
/// stood still, and the growth of a^2 (the variance a scale-factor error
/// sigma_k gives the heading over a move is (sigma_k a)^2: the error is the
/// same fraction of the whole move, not a random walk over its ticks).
inline void gather(NavFilter& f, const Vec3& dv_sf_n, double dalpha) {
    f.dv_sum = f.dv_sum + dv_sf_n;
    f.ticks = f.ticks + 1;
    if (dalpha != 0.0) {
        // (a + da)^2 - a^2
        f.move_q = f.move_q + (2.0 * f.move_angle + dalpha) * dalpha;
        f.move_angle = f.move_angle + dalpha;
    } else {
        f.move_angle = 0.0;
    }
}

/// Continuous-time F for the mean specific force f_n [m/s^2] and the mean
/// attitude c_np.
kalman::Mat<kStates, kStates> system_matrix(const Motion& m, const Vec3& f_n, const Mat3& c_np);

/// Time update over the ticks gathered (nothing when none), at the motion
/// m and the attitude c_np now.
void predict(NavFilter& f, const Motion& m, const Mat3& c_np);

/// The joint NIS of the pair of unit rows k, k + 1 for the innovation z
/// (z - H x with x = 0 after feedback) and variances r.
double nis_pair(const NavFilter& f, int k, const double z[2], const double r[2]);

/// Two scalar Joseph updates of rows k, k + 1.
void update_pair(NavFilter& f, int k, const double z[2], const double r[2]);

/// After the firmware has fed phi, dv, dp back: the biases into the
/// compensation, the state zeroed.
void reset_feedback(NavFilter& f);

}  // namespace pyins::nav_filter
