// nav_filter.hpp: the integrated navigation filter at sea: an error-state
// Kalman filter run beside the strapdown in NAVIGATE, 19 states, for the
// IMU frame p on its turntable.
//
// Mirrored by pyins/reference/nav_filter.py. Design notes and measured
// figures: docs/concepts.md, "At sea".
//
// States (errors = computed - true; phi as in fine_align: C_p^n' =
// (I - phi x) C_p^n; the vertical channel held by the height reference, so
// no vertical velocity or position state):
//   X = [phi_E phi_N phi_U dv_E dv_N dp_E dp_N eps_x eps_y eps_z nabla_x nabla_y
//        m_xz m_yz k_z k_x k_y m_xy m_yx]
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
// The table's axis: three states beyond the biases, the errors of the gyro
// triad that the table's own turns expose (its rate, 6 deg/s by default,
// is 1,400 times the Earth's): the misalignments m_xz, m_yz of the x and
// y gyros to the table's axis z (x senses m_xz w_z) and the scale factor k_z of
// the gyro on it, X[kTab..kTab+2] = [m_xz m_yz k_z], random constants
// whose priors are nav_table_mis_sigma and nav_table_scale_sigma (0: the
// state stays 0, not modelled). Their rows of F are those of eps times the
// z rate:  phi' += -C_p^n [m_xz m_yz k_z]^T w_z,  w_z the mean compensated
// z rate over the interval (the sum of dtheta_z / T; with the mean C_p^n,
// as eps). A turn of the table by a then moves the heading by k_z a and
// the tilt by m times the level axes' integral over the turn (2 m for a
// half turn), the reverse turn takes them back, and the filter learns
// them from the tilt's and the heading's response instead of taking each
// move's error as a fresh draw,
// which loses the heading that the tilt's growth carries (0.64' against
// 0.29' RMS over 6 h, ABI 0.18; docs/concepts.md, "At sea"). Feedback: into
// the compensation, dtheta_x -= m_xz dtheta_z, dtheta_y -= m_yz dtheta_z,
// dtheta_z -= k_z dtheta_z (compensate_gyro).
// The level gyros: four more, the scale factors k_x, k_y of the x and y
// gyros and their misalignments to each other m_xy, m_yx (x senses m_xy
// w_y), X[kLev..kLev+3] = [k_x k_y m_xy m_yx], priors nav_level_scale_sigma
// and nav_level_mis_sigma. The Earth's horizontal rate turns with the
// IMU's yaw theta in p, and over a two-position cycle (theta, theta + pi)
// they leave an east drift W_N ((m_xy - m_yx) / 2 + (m_xy + m_yx) / 2
// cos 2 theta + (k_x - k_y) / 2 sin 2 theta) that no indexing modulates
// (its first part not even a continuous rotation): the gyrocompass reads
// it as a heading error of the same size, (m_xy - m_yx) / 2 being the gyro
// triad's own yaw against the accelerometers'. Unmodelled, seed 002's 10"
// misalignments gave a heading NEES of 12-14 on the units where that part
// is 14-19" (30 units, 6 h, ABI 0.19's first cut with 15 states); as
// states they make the heading sigma carry it, and the course changes
// make the cos 2 theta, sin 2 theta parts observable. F's columns:
//   phi' += -C_p^n(:,0) (k_x w_x + m_xy w_y) - C_p^n(:,1) (m_yx w_x + k_y w_y)
// with w the mean compensated rate over the interval.
// The constants' rows of F are zero, so Phi = [Phi_d Phi_c; 0 I] with the
// dynamic block d = (phi, dv, dp), 7 states, and the constants c, 12:
// Phi and Phi P Phi^T are computed by blocks (P_cc unchanged), 4.4e3
// multiplies against 20.6e3 for the dense 19 x 19 (and 5.2e3 for the dense
// 12 x 12 of ABI 0.18).
//
// Measurements (all unit rows: the vertical is held): a reference position
// on [dp_E, dp_N], a reference or zero velocity on [dv_E, dv_N] (a DVL's
// velocity turned into n by the firmware, Firmware::dvl_n), R diagonal.
// Each pair is gated by its joint normalised innovation squared nu^T S^-1 nu
// (S = H P H^T + R, chi-square with 2 degrees of freedom while the model
// holds; Bar-Shalom, Li, Kirubarajan 2001, sec. 5.4) before it is used, and
// applied as two scalar Joseph updates (moving_align.hpp says why they equal
// the joint one). Feedback after every update (the firmware's): attitude,
// velocity and position corrected, the biases, scale factors and
// misalignments added to the compensation, the state zeroed. The scalar
// updates compute P's upper triangle in place from the saved column k and
// mirror it (the Joseph form's result is symmetric: no symmetrising).
#pragma once

#include <cstdint>

#include "kalman.hpp"
#include "types.hpp"

namespace pyins::nav_filter {

inline constexpr int kStates = 19;
/// The dynamic states (phi, dv, dp); the rest are constants (rows of F zero).
inline constexpr int kDyn = 7;
/// State indices.
inline constexpr int kPhi = 0;    ///< phi_E, phi_N, phi_U
inline constexpr int kVel = 3;    ///< dv_E, dv_N
inline constexpr int kPos = 5;    ///< dp_E, dp_N
inline constexpr int kEps = 7;    ///< eps_x, eps_y, eps_z (p)
inline constexpr int kNabla = 10; ///< nabla_x, nabla_y (p)
inline constexpr int kTab = 12;   ///< m_xz, m_yz, k_z: the gyros against the table's axis (p)
inline constexpr int kLev = 15;   ///< k_x, k_y, m_xy, m_yx: the level gyros' scale factors and misalignments

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
    double table_scale;      ///< prior sigma of k_z, the table-axis gyro's scale factor [-]; 0 = not modelled
    double table_mis;        ///< prior sigma of m_xz, m_yz, the other gyros' misalignment to it [rad]; 0 = not modelled
    double level_scale;      ///< prior sigma of k_x, k_y [-]; 0 = not modelled
    double level_mis;        ///< prior sigma of m_xy, m_yx [rad]; 0 = not modelled
};
static_assert(sizeof(Params) == 16 * sizeof(double) + 2 * sizeof(int32_t), "nav_filter::Params has no padding");

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
    Vec3 dtheta_sum;         ///< compensated angle increments since the last time update, p [rad]
    Vec3 gyro_bias;          ///< compensated gyro biases, p [rad/s]
    Vec3 table_err;          ///< compensated m_xz, m_yz, k_z [rad, rad, -]
    double level_err[4];     ///< compensated k_x, k_y, m_xy, m_yx [-, -, rad, rad]
    Vec3 accel_bias;         ///< compensated accelerometer biases, p (z 0) [m/s^2]
};

/// Start the filter at an attitude C_p^n (c_np): P diagonal from the sigmas.
void init(NavFilter& f, const Params& prm, const Mat3& c_np);

/// One tick's specific-force velocity increment in n' [m/s] and its
/// compensated angle increment in p [rad] (the table's turn and the ship's).
inline void gather(NavFilter& f, const Vec3& dv_sf_n, const Vec3& dtheta_p) {
    f.dv_sum = f.dv_sum + dv_sf_n;
    f.dtheta_sum = f.dtheta_sum + dtheta_p;
    f.ticks = f.ticks + 1;
}

/// The gyro increment dtheta_p [rad] over dt [s] with the estimated
/// biases, scale factors and misalignments removed (first order).
inline Vec3 compensate_gyro(const NavFilter& f, const Vec3& dtheta_p, double dt) {
    const Vec3 d = dtheta_p - f.gyro_bias * dt;
    const double* l = f.level_err;
    return Vec3(d(0) - l[0] * dtheta_p(0) - l[2] * dtheta_p(1) - f.table_err(0) * dtheta_p(2),
                d(1) - l[3] * dtheta_p(0) - l[1] * dtheta_p(1) - f.table_err(1) * dtheta_p(2),
                d(2) - f.table_err(2) * dtheta_p(2));
}

/// The rows of F that are not zero (the dynamic states'), for the
/// mean specific force f_n [m/s^2], the mean attitude c_np and the mean
/// compensated rate w_p [rad/s].
kalman::Mat<kDyn, kStates> system_matrix(const Motion& m, const Vec3& f_n, const Mat3& c_np, const Vec3& w_p);

/// Time update over the ticks gathered (nothing when none), at the motion
/// m and the attitude c_np now.
void predict(NavFilter& f, const Motion& m, const Mat3& c_np);

/// The joint NIS of the pair of unit rows k, k + 1 for the innovation z
/// (z - H x with x = 0 after feedback) and variances r.
double nis_pair(const NavFilter& f, int k, const double z[2], const double r[2]);

/// Two scalar Joseph updates of rows k, k + 1.
void update_pair(NavFilter& f, int k, const double z[2], const double r[2]);

/// After the firmware has fed phi, dv, dp back: the biases, scale factors
/// and misalignments into the compensation, the state zeroed.
void reset_feedback(NavFilter& f);

}  // namespace pyins::nav_filter
