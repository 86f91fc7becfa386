// coarse_align.hpp: inertial-frame coarse alignment on a static or rocking
// base (seed 000: Gao Chunfeng et al., Infrared and Laser Engineering 2014,
// no. 2, pp. 375-381), and on a moored ship (method FIT), written for the
// IMU frame p.
//
// Mirrored by pyins/reference/coarse_align.py. Measurements and design
// notes: docs/core.md, "Coarse alignment (seed 000)" and "Eq. 8 as
// printed"; docs/concepts.md, "Alignment on a moving base" and "Integrity";
// docs/papers.md, seed 000.
//
//   C_p^n(t) = C_e^n C_i^e(t) C_ib0^i C_p^ib0(t)                 (seed 000 eq. 1)
//
// - C_p^ib0(t): the IMU attitude relative to itself at t0, propagated from the
//   gyro increments (quaternion, with the strapdown module's coning terms).
// - v^ib0(t) = integral of C_p^ib0 f^p dt, from the velocity increments with
//   rotation and sculling compensation.
// - v^i(t) = integral of f^i dt in closed form (seed 000 eq. 5): with the e
//   frame's x axis on the site meridian and f^e = g [cosL, 0, sinL],
//     v^i = g [cosL sin(wt)/w, cosL (1 - cos(wt))/w, sinL t].
//   Correction: the paper prints the negative (it integrates gravity, not
//   specific force); both sides of eq. 8 flip together. 1 - cos(wt) is
//   computed as 2 sin^2(wt/2), which does not cancel for small wt.
// - C_ib0^i from the vector pairs at t_k1 = r t_k2 and t_k2 = now (eqs. 6-8).
//   Correction: eq. 8 as printed inverts a 3x3 matrix of the two vectors and
//   their cross product, which under noise is not orthonormal. Here the two
//   pairs go through the TRIAD (dual-vector) construction, anchored on
//   v(t_k2) (the longer integral, which averages the swing best); the
//   result is a proper rotation by construction.
// - Method EQ8: eq. 8 as printed, C_ib0^i = A^-1 B with the rows of A
//   v^i(t_k1), v^i(t_k2), v^i(t_k1) x v^i(t_k2) and of B the same in ib0
//   (same t_k1, history and lever velocity as TRIAD); A^-1 is the adjugate
//   over the determinant, the exact inverse. The print's sign does not
//   matter: with D = diag(-1, -1, 1), (D A)^-1 D B = A^-1 B. As in the
//   paper the matrix goes into eq. 1 without orthonormalisation, and the
//   attitude is read off the product as its Euler angles (pitch from C32,
//   roll from C31, C33, yaw from C12, C22), whose rotation mat_n_p returns
//   (Shepperd's quaternion of a matrix that is not a rotation depends on
//   its branch, i.e. on the heading). The wander test reads the skew part
//   of R^T C.
// - The v^ib0 history is kept on a grid of output_every ticks in fixed storage
//   (kHistLen entries, no heap); t_k1 is the grid point nearest r t_k2.
//
// Lever arm: the accelerometers sit at r^p from the ship's reference point
// (lever_b + the table's sensor offset), so their velocity integral carries
// the lever velocity, d/dt (C_p^i r^p) = C_p^i u^p with
// u^p = (w_ip^p - alpha' z) x (Rz(alpha)^T lever_b) + w_ip^p x lever_p
// (the firmware computes u^p each tick from the gyro and encoder). It
// integrates exactly to C_p^ib0(t) u^p(t) - u^p(t0), which is removed, so
// the vectors are the reference point's; no angular acceleration is
// differentiated from the gyro.
//
// Moving base (method FIT). Eq. 4 assumes that the disturbance integrates to
// zero; on a moored ship the velocity integral carries v_D(t) - v_D(t0), a
// bounded wave velocity plus an unknown constant. FIT integrates once more,
// P(t) = integral of v dt, so that the disturbance is a bounded displacement
// plus a linear term -v_D(t0) t + const, and projects both P^ib0 and P^i on
// two weight functions of s = t / T that are orthogonal to 1 and s (the
// unknown initial velocity and offset drop out) and vanish with their slope
// at both ends (a wave's leakage falls as (w T)^-3):
//   phi_a(s) = s^2 (1-s)^2 q_a(s), also orthogonal to s^3: picks the t^2
//              term of gravity, int phi_a s^2 ds = 1;
//   phi_b(s) = s^2 (1-s)^2 q_b(s), also orthogonal to s^2: picks the t^3
//              term the Earth's rotation adds (g cos L w t^3 / 6 on y_i),
//              int phi_b s^3 ds = 1
// (tools/derive_coarse_fit.py derives the weights). The two pairs of
// weighted sums go through the same TRIAD, anchored on the gravity pair.
// The static-base limit is the same as TRIAD's (the biases enter the t^2
// and t^3 terms as in the classical analytic alignment). P^i is closed
// form: g [cosL (1 - cos wt) / w^2, cosL (wt - sin wt) / w^2, sinL t^2 / 2],
// by its series (no cancellation, no trigonometry).
//
// Integrity: C_ib0^i is a constant; a solution that converges stops moving.
// From the first output at or after settle_from (the last fifth of the
// alignment, chosen by the firmware) each solution is compared with that
// first one, and the largest rotation between them is kept as its sine
// (`wander`; 1 for 90 deg or more). Every coarse solution is provisional:
// the firmware reports none with PYINS_STATE_ATT_VALID before the alignment
// has ended and passed this test.
//
// Under way (method FIT_VEL). A ship under way moves by hundreds of metres
// in an alignment: FIT's unknown initial velocity is no longer the whole of
// it. With a reference velocity v^n of the reference point (a GNSS receiver's,
// time-tagged) the motion is taken out of the inertial side instead. For the
// reference point (f^n = v' + (2 w_ie + w_en) x v - g^n, Titterton & Weston
// eq. 3.74) and d/dt (C_n^i v) = C_n^i (v' + w_in x v):
//   C_n^i f^n = d/dt (C_n^i v) + C_n^i (w_ie^n x v) + g up^i,
// so the reference point's v^i = int f^i is
//   v^i(t) = C_n^i(t) v(t) + K(t) - C_n^i(0) v(0),  K = int (g up^i + C_n^i (w_ie^n x v)),
// and C_ib0^i v^ib0(t) = v^i(t) with an unknown constant. Here n is the frame
// at the SHIP (its latitude and longitude carried from t0 by the reference
// velocity, R_M + h and R_N + h of the site): the transport rate turns it
// v / R against the Earth's Omega cos L, which a fixed n would read as a
// heading bias of v / (R Omega cos L), 54' at 12 kn and 34 deg. K is
// integrated each tick by the trapezoid rule (its integrand at the tick
// ends, the velocity in it the last reference's).
// The solution is FIT's at the velocity level: v^ib0 and v^i on the grid
// projected on two weights of s = t / T orthogonal to 1 (the unknown
// constant drops out exactly on the grid), the Legendre polynomials
//   psi_a(s) = s - 1/2 (the gravity term, g up^i t),
//   psi_b(s) = s^2 - s + 1/6 (the Earth's rotation of it, g cos L Omega t^2 / 2),
// made exactly orthogonal to 1 (psi_a) and to 1 and s (psi_b) on the grid,
// and the two pairs through the TRIAD anchored on the gravity pair. The
// reference's white velocity noise (sigma per sample) is what limits it, and
// least squares on {1, t, t^2} is the best a linear fit does with it: the
// heading's sigma is sigma / sqrt(sum q_k^2) / (g cos L Omega / 2), q the
// grid's quadratic orthogonal to 1 and t in seconds (heading_sigma()): 50'
// for 0.05 m/s at 1 Hz over 120 s at 34 deg. FIT's end-tapered weights
// (the waves) are not needed: the reference's velocity carries the waves,
// and at the position level they would pick the velocity noise up as a
// random walk (165' in the same case).
// A grid point's i side (the grid's upper half) is K at its tick at once,
// and C_n^i v when the first reference at or after its tick comes (v linear
// between references; ref_done counts the complete points; the solution
// uses those, so it lags a reference interval, which C_ib0^i, a constant,
// does not mind). The points before the first reference (their velocity
// would be a guess) are left out of the fit (grid_from). At t0 the ib0 side
// is the lever velocities' alone (the accelerometers' and the antenna's from
// the reference point), taken from the first sample's rates: off by
// |w'| dt / 2 |r|, millimetres per second.
// The reference's antenna sits at l^b from the reference point: it moves at
// v + d/dt (C_b^n l^b), and C_n^i d/dt(C_b^n l) = d/dt (C_b^i l) less
// w_in x terms of 1e-4 m/s; C_b^i l^b = C_ib0^i C_p^ib0 C_b^p l^b, so that
// term's derivative moves to the ib0 side: the grid holds v^ib0 + C_p^ib0 u
// with u = (w_ip^p - alpha' z) x C_b^p l^b (ref_lever_p, passed to update()).
// The reference's vertical velocity is taken where the receiver gives it
// (sigma[2] > 0): it carries the heave and the vertical part of the
// antenna's lever velocity, which the ib0 side holds whole. Without one
// (NMEA's RMC has none) the heave and that part are left to the weights,
// which are not tapered: a wave's velocity leaks in as about 1 / (omega T)
// of it (not measured here: the simulated receiver gives the vertical).
// The wander test expects the noise to move the solution: the firmware
// allows a wander of kWanderSigmas times settle_sigma (the sigma of the
// test's first solution) where that is more than integrity_coarse_rad.
// Integrity: the longest interval without a reference (ref_gap, from t0)
// is kept; the firmware faults an alignment whose gap exceeded ref_gap_max
// ticks.
//
// Noise (for the fine alignment's R; docs/core.md, "Measurement noise of
// the fine alignment"). The static fine filters measure the specific force
// averaged over tau = noise_every ticks; their R must be the variance of
// that mean, on a real site the sensor noise plus vibration. The coarse
// phase measures it on the same interval: m_k, the reference point's mean
// specific force in ib0 over block k (attitude motion removed by C_p^ib0,
// the lever velocity removed as above), and its second difference
// d_k = m_k - 2 m_(k-1) + m_(k-2) = (V_k - 3 V_(k-1) + 3 V_(k-2) - V_(k-3)) / tau
// (V: v^ib0 at the block ends), which cancels any trend linear over 3 tau
// (the Earth's rotation of gravity in ib0, a bias drift) and scales a
// sinusoid of angular frequency w (a wave's slow acceleration) by
// (2 sin(w tau / 2))^2 ~ (w tau)^2. For white noise of density q,
// Var(d) = 6 q^2 / tau per axis; of the two horizontal axes (d less its
// component along v^ib0, the direction of the mean specific force, i.e. up):
//   q^2 = tau / 6 * mean(|d_h|^2) / 2.
#pragma once

#include <cstdint>

#include "strapdown.hpp"
#include "types.hpp"

namespace pyins::coarse_align {

/// Entries of the v^ib0 history: the longest TRIAD alignment is
/// (kHistLen - 1) * output_every ticks (255 s at 1 s outputs); FIT halves
/// the grid when it fills and has no limit.
inline constexpr int kHistLen = 256;

/// How C_ib0^i is solved (enum pyins_coarse_method).
enum class Method : int32_t { kTriad = 0, kFit = 1, kEq8 = 2, kFitVel = 3 };

/// FIT_VEL holds its grid of v^ib0 in grid[0 .. kFitVelLen - 1] and the i
/// side on the same points (K, then + C_n^i v once a reference covers it)
/// in grid[kFitVelLen ..]: no storage beyond FIT's (it halves its grid at
/// kFitVelLen points, 128 s at 1 s outputs).
inline constexpr int32_t kFitVelLen = kHistLen / 2;

/// FIT_VEL's wander test: the noise moves the solution by about its sigma
/// over the last fifth (the first solution's sigma is (5/4)^2.5 = 1.75 times
/// the last's); four of its sigmas before integrity calls it unsettled.
inline constexpr double kWanderSigmas = 4.0;

/// FIT needs this many grid intervals at its first output (a polynomial
/// weight of degree 7 sampled on fewer points is not orthogonal to 1 and s).
inline constexpr int32_t kFitMinIntervals = 8;

/// Alignment parameters, all durations in ticks.
struct Params {
    int32_t method;          ///< enum Method
    int32_t lever;           ///< 1: remove the lever velocity passed to update()
    double ratio;            ///< r = t_k1 / t_k2, in (0, 1) (TRIAD)
    int32_t first_output;    ///< first attitude solution at this tick
    int32_t output_every;    ///< then every this many ticks; also the history grid
    double dt;               ///< tick period [s]
    double sin_lat;
    double cos_lat;
    double gravity;          ///< normal gravity at the site [m/s^2]
    int64_t settle_from;     ///< first tick of the wander test
    int32_t noise_every;     ///< ticks per block of the noise measurement (tau); 0: none
    int32_t ref_gap_max = 0; ///< FIT_VEL: the longest interval without a reference it trusts [ticks]
                             ///< (also fills the tail: no padding, so a Params copied from a stack
                             ///< local (CoarseAlign::prm) carries no undefined bytes into a snapshot)
    double rm_h = 0.0;       ///< FIT_VEL: R_M + h at the site [m]
    double rn_h = 0.0;       ///< FIT_VEL: R_N + h at the site [m]
};
static_assert(sizeof(Params) == 6 * sizeof(int32_t) + 7 * sizeof(double) + sizeof(int64_t),
              "coarse_align::Params has no padding");

/// Second differences needed before measured_vrw reports a value (5 s at
/// 10 blocks per second: the estimate's relative sigma is then ~15 %).
inline constexpr int64_t kNoiseMinSamples = 50;

struct CoarseAlign {
    Params prm;
    Quat quat_ib0_p;         ///< C_p^ib0
    Vec3 vel_ib0;            ///< v^ib0 [m/s]
    strapdown::History hist; ///< previous increments (coning, sculling)
    int64_t tick;            ///< samples taken
    Vec3 vel_prev;           ///< reference-point v^ib0 (less u^p(t0)) at the last tick (FIT)
    Vec3 pos_ib0;            ///< its integral [m] (FIT)
    Vec3 lever_vel0;         ///< u^p(t0) [m/s] (TRIAD)
    Vec3 grid[kHistLen];     ///< at ticks 0, grid_every, 2 grid_every, ...: v^ib0 (TRIAD) or P^ib0 (FIT)
    int32_t hist_count;
    int64_t grid_every;      ///< grid spacing [ticks]: output_every, doubled by FIT each time the grid fills
    Mat3 mat_i_ib0;          ///< C_ib0^i of the latest solution
    bool solved;             ///< a solution exists
    bool settling;           ///< settle_ref holds the first solution of the wander test
    Mat3 settle_ref;         ///< that solution
    double wander;           ///< sine of the largest rotation from it since (0 before)
    Vec3 noise_v[3];         ///< V at the last three block ends, newest first
    int32_t noise_seen;      ///< block ends seen (capped at 3)
    double noise_sum;        ///< sum of |d_h|^2 [(m/s^2)^2]
    int64_t noise_n;         ///< second differences in it
    // Under way (FIT_VEL; see the header)
    int32_t ref_done;        ///< grid points whose i side is complete
    int32_t ref_count;       ///< references taken (capped at 2^30)
    int32_t grid_from;       ///< the first grid point at or after the first reference: the fit's first
    int32_t reserved_fv;     ///< (keeps the layout free of padding)
    double dlat;             ///< the reference point's latitude since t0 [rad]
    double dlon;             ///< its longitude since t0 [rad]
    double ref_vel[2];       ///< the last reference velocity (E, N) [m/s]
    int64_t ref_tick;        ///< its tick, counted as tick is (-1: none yet)
    int64_t ref_gap;         ///< the longest interval without a reference so far [ticks]
    Vec3 known_f;            ///< g up^i + C_n^i (w_ie^n x v) at the last tick [m/s^2]
    Vec3 known_v;            ///< its integral, K [m/s]
    Vec3 ref_cv;             ///< C_n^i v at t_ref [m/s]
    double ref_var;          ///< sum of the references' horizontal variances, max(E, N) [m^2/s^2]
    double sigma_heading;    ///< the latest solution's heading sigma (heading_sigma) [rad]
    double settle_sigma;     ///< FIT_VEL: sigma_heading of the wander test's first solution [rad]
};

/// Sine of the rotation angle between two rotation matrices (1 beyond 90 deg).
double rotation_sine(const Mat3& a, const Mat3& b);

/// v^i(t) of seed 000 eq. 5 (specific-force form, see above).
Vec3 vel_i(double t, double sin_lat, double cos_lat, double gravity);

/// Orthonormal triad [a1 a2 a3] from an anchor vector and a second one:
/// a1 = u / |u|, a2 = (w x u) / |w x u|, a3 = a1 x a2.
Mat3 triad(const Vec3& u, const Vec3& w);

/// C_ib0^i from v^i and v^ib0 at t_k1 (index 1) and t_k2 (index 2).
Mat3 solve_mat_i_ib0(const Vec3& vi1, const Vec3& vi2, const Vec3& vb1, const Vec3& vb2);

/// C_ib0^i by seed 000 eq. 8 as printed: A^-1 B (not orthonormalised).
Mat3 solve_eq8(const Vec3& vi1, const Vec3& vi2, const Vec3& vb1, const Vec3& vb2);

/// P^i(t) = integral of v^i: the position integral of the specific force (FIT).
Vec3 pos_i(double t, double sin_lat, double cos_lat, double gravity);

/// The FIT weights phi_a(s), phi_b(s) (see the header comment).
void fit_weights(double s, double* phi_a, double* phi_b);

/// C_ib0^i by FIT from P^ib0 on the grid points 0 .. n - 1 (spacing t_step [s]).
Mat3 solve_fit(const Vec3* grid, int32_t n, double t_step, double sin_lat, double cos_lat,
               double gravity);

/// C_e^n for the e frame whose x axis lies on the site meridian (eq. 2).
Mat3 mat_n_e(double sin_lat, double cos_lat);

/// C_i^e(t) = Rz(w t)^T: the Earth's rotation since t0 (eq. 2).
Mat3 mat_e_i(double t);

/// The horizontal specific-force noise density measured so far (see the
/// header) [(m/s)/sqrt(s)]; 0 before kNoiseMinSamples second differences.
double measured_vrw(const CoarseAlign& a);

/// Start an alignment. Precondition: parameters checked by the firmware.
void init(CoarseAlign& a, const Params& prm);

/// Take one sample; solves C_ib0^i at the output ticks. lever_vel_p: u^p at
/// the end of the tick [m/s] (read only with prm.lever); ref_lever_p: the
/// reference's antenna's velocity from the reference point in p, d/dt
/// (C_p^i C_b^p l^b) in p [m/s] (read only by FIT_VEL).
void update(CoarseAlign& a, const Vec3& dtheta_p, const Vec3& dv_p, const Vec3& lever_vel_p,
            const Vec3& ref_lever_p);

/// FIT_VEL: C_n^e at the reference point (rows E, N, U in the e frame whose
/// x axis lies on the site meridian; dlon from it): mat_n_e turned by dlon.
Mat3 mat_n_e_at(double sin_lat, double cos_lat, double sin_dlon, double cos_dlon);

/// FIT_VEL: g up^i + C_n^i (w_ie^n x v) at time t for the reference point at
/// (lat, dlon) moving at v (E, N) [m/s^2] (see the header).
Vec3 known_force_i(double t, double sin_lat, double cos_lat, double sin_dlon, double cos_dlon,
                   double gravity, double ve, double vn);

/// FIT_VEL: C_n^i v at time t, v = (ve, vn, vu) [m/s].
Vec3 ref_vel_i(double t, double sin_lat, double cos_lat, double sin_dlon, double cos_dlon, double ve,
               double vn, double vu);

/// FIT_VEL: take a reference velocity (E, N, U; U 0 where not measured)
/// [m/s] with its sigma (the larger of E, N) [m/s], valid at alignment tick
/// ref_tick (a.tick or earlier; one not newer than the last is ignored):
/// completes the grid points it covers.
void reference(CoarseAlign& a, double ve, double vn, double vu, double sigma, int64_t ref_tick);

/// FIT_VEL: C_ib0^i from v^ib0 (grid) and the i side (grid_i) on the grid
/// points 0 .. n - 1 by the Legendre weights (see the header).
Mat3 solve_vel_grid(const Vec3* grid, const Vec3* grid_i, int32_t n);

/// FIT_VEL: the heading sigma of a solution on n grid points t_step [s]
/// apart from references of mean variance var [m^2/s^2] (see the header) [rad].
double heading_sigma(int32_t n, double t_step, double var, double gravity, double cos_lat);

/// C_p^n now (eq. 1; FIT_VEL: with n at the reference point now); for EQ8, whose product is not a rotation, the rotation
/// of the Euler angles read off it (see the header). Precondition: a.solved.
Mat3 mat_n_p(const CoarseAlign& a);

}  // namespace pyins::coarse_align
