// coarse_align.hpp: inertial-frame coarse alignment on a static or rocking
// base (seed 000: Gao Chunfeng et al., Infrared and Laser Engineering 2014,
// no. 2, pp. 375-381), written for the IMU frame p.
//
// Mirrored by pyins/reference/coarse_align.py.
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
//   The paper prints the negative (it integrates gravity, not specific force);
//   both sides of eq. 8 flip together. 1 - cos(wt) is computed as
//   2 sin^2(wt/2), which does not cancel for small wt.
// - C_ib0^i from the vector pairs at t_k1 = r t_k2 and t_k2 = now (eqs. 6-8).
//   Eq. 8 as printed inverts a 3x3 matrix of the two vectors and their cross
//   product: under noise the result is not orthonormal. Here the two pairs go
//   through the TRIAD (dual-vector) construction, anchored on v(t_k2) (the
//   longer integral, which averages the swing best); the result is a proper
//   rotation by construction.
// - The v^ib0 history is kept on a grid of output_every ticks in fixed storage
//   (kHistLen entries, no heap); t_k1 is the grid point nearest r t_k2.
#pragma once

#include <cstdint>

#include "strapdown.hpp"
#include "types.hpp"

namespace pyins::coarse_align {

/// Entries of the v^ib0 history: the longest coarse alignment is
/// (kHistLen - 1) * output_every ticks (255 s at 1 s outputs).
inline constexpr int kHistLen = 256;

/// Alignment parameters, all durations in ticks.
struct Params {
    double ratio;            ///< r = t_k1 / t_k2, in (0, 1)
    int32_t first_output;    ///< first attitude solution at this tick
    int32_t output_every;    ///< then every this many ticks; also the history grid
    double dt;               ///< tick period [s]
    double sin_lat;
    double cos_lat;
    double gravity;          ///< normal gravity at the site [m/s^2]
};

struct CoarseAlign {
    Params prm;
    Quat quat_ib0_p;         ///< C_p^ib0
    Vec3 vel_ib0;            ///< v^ib0 [m/s]
    strapdown::History hist; ///< previous increments (coning, sculling)
    int64_t tick;            ///< samples taken
    Vec3 hist_vel[kHistLen]; ///< v^ib0 at ticks 0, every, 2 every, ...
    int32_t hist_count;
    Mat3 mat_i_ib0;          ///< C_ib0^i of the latest solution
    bool solved;             ///< a solution exists
};

/// v^i(t) of seed 000 eq. 5 (specific-force form, see above).
Vec3 vel_i(double t, double sin_lat, double cos_lat, double gravity);

/// Orthonormal triad [a1 a2 a3] from an anchor vector and a second one:
/// a1 = u / |u|, a2 = (w x u) / |w x u|, a3 = a1 x a2.
Mat3 triad(const Vec3& u, const Vec3& w);

/// C_ib0^i from v^i and v^ib0 at t_k1 (index 1) and t_k2 (index 2).
Mat3 solve_mat_i_ib0(const Vec3& vi1, const Vec3& vi2, const Vec3& vb1, const Vec3& vb2);

/// C_e^n for the e frame whose x axis lies on the site meridian (eq. 2).
Mat3 mat_n_e(double sin_lat, double cos_lat);

/// C_i^e(t) = Rz(w t)^T: the Earth's rotation since t0 (eq. 2).
Mat3 mat_e_i(double t);

/// Start an alignment. Precondition: parameters checked by the firmware.
void init(CoarseAlign& a, const Params& prm);

/// Take one sample; solves C_ib0^i at the output ticks.
void update(CoarseAlign& a, const Vec3& dtheta_p, const Vec3& dv_p);

/// C_p^n now. Precondition: a.solved.
Mat3 mat_n_p(const CoarseAlign& a);

}  // namespace pyins::coarse_align
