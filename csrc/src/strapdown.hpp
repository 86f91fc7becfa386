// strapdown.hpp: one strapdown update of attitude, velocity and position from
// the increments of one tick, in the local-level ENU frame.
//
// Mirrored by pyins/reference/strapdown.py.
//
// The algorithm is the two-sample ("single sample plus previous sample")
// form of Savage's two-speed structure, as laid out by Yan Gongmin:
// - Savage, "Strapdown inertial navigation integration algorithm design",
//   J. Guidance 21(1), 21(2), 1998: coning (Part 1, eq. 29 form) and
//   sculling (Part 2, eq. 56 form) with the previous tick's increments.
// - Yan Gongmin, "Strapdown inertial navigation algorithm and integrated
//   navigation principles" (NWPU Press, 2019), sec. 4.1 / PSINS insupdate:
//   velocity with the rotation of n over the tick, eq. 4.1.27; attitude
//   q_nb(k) = q(-T omega_in^n) q_nb(k-1) q(phi_k), eq. 4.1.8.
// The IMU frame p is the body being navigated; the turntable angle only
// matters to the firmware's ship-attitude output.
#pragma once

#include "types.hpp"

namespace pyins::strapdown {

/// Vertical channel treatment (pyins_vertical_mode).
enum class Vertical : int { kHold = 0, kFree = 1 };

struct NavState {
    double lat;      ///< geodetic latitude [rad]
    double lon;      ///< longitude [rad], kept in (-pi, pi]
    double height;   ///< height [m]
    Vec3 vel_n;      ///< velocity ENU [m/s]
    Quat quat_np;    ///< attitude of the IMU frame, C_p^n
};

/// Everything the update carries from one tick to the next.
struct Strapdown {
    NavState nav;
    Vec3 prev_dtheta_p;   ///< previous tick's angle increment [rad]
    Vec3 prev_dv_p;       ///< previous tick's velocity increment [m/s]
    Vec3 prev_dvel_n;     ///< v(k-1) - v(k-2), for the mid-tick velocity [m/s]
    bool has_prev;        ///< false until the first update
    Vertical vertical;
    double ref_height;    ///< height held in kHold mode [m]
};

/// 1/12, the two-sample coning and sculling coefficient (Savage 1998).
inline constexpr double kOneTwelfth = 1.0 / 12.0;

/// Rotation vector and velocity increment, compensated.
struct Compensated {
    Vec3 phi;    ///< rotation of p over the tick [rad]
    Vec3 dv_p;   ///< velocity increment in p at the start of the tick [m/s]
};

/// Two-sample coning and sculling plus rotation compensation:
///   phi  = dtheta + (1/12) prev_dtheta x dtheta
///   dv_p = dv + (1/2) dtheta x dv + (1/12)(prev_dtheta x dv + prev_dv x dtheta)
/// (Savage 1998 Part 1 eq. 29 and Part 2 eq. 56, two-sample forms.)
Compensated compensate(const Vec3& dtheta, const Vec3& dv,
                       const Vec3& prev_dtheta, const Vec3& prev_dv);

/// Start a strapdown at a navigation state.
Strapdown make_strapdown(const NavState& nav, Vertical vertical);

/// One update over a tick of dt seconds. Precondition: finite inputs.
void update(Strapdown& s, const Vec3& dtheta_p, const Vec3& dv_p, double dt);

}  // namespace pyins::strapdown
