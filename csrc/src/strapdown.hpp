// strapdown.hpp: one strapdown update of attitude, velocity and position from
// the increments of one tick, in the local-level ENU frame.
//
// Mirrored by pyins/reference/strapdown.py.
//
// Structure: Savage's two-speed algorithm with one IMU sample per update and
// "past-value" coning and sculling corrections, as laid out by Yan Gongmin:
// - Savage, "Strapdown inertial navigation integration algorithm design",
//   J. Guidance 21(1) (attitude, coning) and 21(2) (velocity, sculling), 1998.
// - Yan Gongmin, "Strapdown inertial navigation algorithm and integrated
//   navigation principles" (NWPU Press, 2019), sec. 4.1 / PSINS insupdate:
//   velocity with the rotation of n over the tick (eq. 4.1.27); attitude
//   q_np(k) = q(-T omega_in^n) q_np(k-1) q(phi_k) (eq. 4.1.8).
//
// Coning and sculling use the current and the two previous ticks' increments:
// the coefficients are exact when the angular rate and specific force are
// quadratic in time over those three ticks (tools/derive_coning.py derives
// them with sympy); the textbook two-sample form (1/12) leaves a rectified
// drift on a swinging ship. The velocity rotation compensation also keeps
// the second-order term (1/6) dtheta x (dtheta x dv) (Savage 1998 Part 2,
// eq. 26 expanded to second order), without which a swinging IMU sees a
// rectified velocity error. The first two ticks after init, lacking
// history, use the lower orders (no correction, then the two-sample 1/12
// form). Measurements: docs/core.md, "Coning and sculling: three samples".
//
// Earth terms: the radii, Earth rate and gravity depend on the position
// alone, which a ship moves by well under a metre a tick. They are kept
// (earth::PositionTerms, radii as inverses so a tick multiplies where it
// would divide) and computed again when the latitude has moved more than
// kTermsLatStep (1e-6 rad, 6.4 m) or the height more than kTermsHeightStep
// (0.01 m) from where they were. A tick carries the latitude-dependent ones
// (Earth rate, tan L, 1 / cos L) to its own latitude to first order in
// d = L - L0 (the d^2 terms left out are < 1e-10 of themselves below 80 deg
// of latitude; docs/core.md, "Earth quantities", says what the terms cost
// without this carry). What stays stale is the radii's dependence on
// latitude and height, 1e-8 of themselves at most (R_M: 3 e^2 sin L cos L
// per radian; 1 mm of position over 100 km). Gravity is kept only while the
// vertical channel is held (then it reaches nothing but that clamped
// channel); a free channel's dynamics are gravity's own feedback (-2 g / R
// per metre, e-folding in ~570 s), so it takes gravity at each tick's
// latitude and height.
//
// Latitude sine and cosine (for those terms): the sine and cosine of an
// anchor latitude L0 are kept, and those of L = L0 + d are its angle sums
// with the series of d: cos d = 1 - d^2/2 + d^4/24, sin d = d - d^3/6 (the
// next terms, d^6/720 and d^5/120, are below 1e-22 for |d| <=
// kLatAnchorStep: the result is the sine to a few roundings, as
// pmath::sincos is); the anchor moves to L when |d| would exceed the step
// (640 m). A dozen operations instead of a reduction and two kernels.
#pragma once

#include "earth.hpp"
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

/// Increments of the ticks before the current one.
struct History {
    Vec3 dtheta1;    ///< angle increment of tick k-1 [rad]
    Vec3 dv1;        ///< velocity increment of tick k-1 [m/s]
    Vec3 dtheta2;    ///< angle increment of tick k-2 [rad]
    Vec3 dv2;        ///< velocity increment of tick k-2 [m/s]
    int count;       ///< how many of those are valid: 0, 1 or 2
    // The past terms of the three-sample compensation are last tick's near
    // terms (th2*th1 then was th1*th), kept instead of computed again: the
    // same operands, the same bits, three cross products fewer a tick.
    Vec3 cone1;      ///< th2*th1 (valid with count 2) [rad^2]
    Vec3 scul1;      ///< th2*dv1 + dv2*th1 (valid with count 2) [rad m/s]
};

/// Everything the update carries from one tick to the next.
/// Largest |lat - anchor| before the anchor moves [rad] (640 m).
inline constexpr double kLatAnchorStep = 1.0e-4;
/// Largest latitude move before the Earth terms are computed again [rad] (6.4 m).
inline constexpr double kTermsLatStep = 1.0e-6;
/// Largest height move before the Earth terms are computed again [m].
inline constexpr double kTermsHeightStep = 0.01;

struct Strapdown {
    NavState nav;
    History hist;
    double lat0;          ///< the anchor latitude [rad]
    double sin_lat0;      ///< its sine and cosine (pmath::sincos)
    double cos_lat0;
    earth::PositionTerms terms;   ///< the Earth terms near nav's position
    Vec3 prev_dvel_n;     ///< v(k-1) - v(k-2), for the mid-tick velocity [m/s]
    Vertical vertical;
    double ref_height;    ///< height held in kHold mode [m]
    double ref_lon;       ///< longitude at the start [rad] (the alignment site)
};

/// Two-sample coefficient (linear rate over two ticks): 1/12.
inline constexpr double kOneTwelfth = 1.0 / 12.0;
/// Three-sample coefficients (quadratic rate over three ticks), x 1/720.
inline constexpr double kC3Near = 121.0 / 720.0;   ///< (k-1) x (k)
inline constexpr double kC3Far = -31.0 / 720.0;    ///< (k-2) x (k)
inline constexpr double kC3Past = 1.0 / 720.0;     ///< (k-2) x (k-1)
inline constexpr double kOneSixth = 1.0 / 6.0;

/// Rotation vector and velocity increment, compensated.
struct Compensated {
    Vec3 phi;        ///< rotation of p over the tick [rad]
    Vec3 dv_p;       ///< velocity increment in p at the start of the tick [m/s]
    Vec3 cone_near;  ///< th1*th (0 without history): next tick's History::cone1
    Vec3 scul_near;  ///< th1*dv + dv1*th (0 without history): next tick's History::scul1
};

/// Coning, sculling and rotation compensation of one tick's increments:
///   phi  = dtheta + cone
///   dv_p = dv + (1/2) dtheta x dv + (1/6) dtheta x (dtheta x dv) + scul
/// with, for 2 ticks of history (a x b written a*b):
///   cone = c_n th1*th + c_f th2*th + c_p th2*th1
///   scul = c_n (th1*dv + dv1*th) + c_f (th2*dv + dv2*th) + c_p (th2*dv1 + dv2*th1)
/// for 1 tick: cone = th1*th / 12, scul = (th1*dv + dv1*th) / 12; for none: 0.
/// The past terms are read from h.cone1, h.scul1 (see History).
Compensated compensate(const Vec3& dtheta, const Vec3& dv, const History& h);

/// Shift this tick's increments, and its near terms (c, from compensate on
/// them), into the history.
void push_history(History& h, const Vec3& dtheta, const Vec3& dv, const Compensated& c);

/// A history from its increments alone, its past terms computed (the test
/// hooks, which are handed increments).
History history_of(const Vec3& dtheta1, const Vec3& dv1, const Vec3& dtheta2, const Vec3& dv2, int count);

/// Sine and cosine of s.nav.lat from the anchor (moved when too far).
void lat_sincos(Strapdown& s, double* sin_lat, double* cos_lat);

/// The Earth terms at s.nav's position: those kept, or computed again when
/// the position has moved more than kTermsLatStep / kTermsHeightStep.
const earth::PositionTerms& position_terms(Strapdown& s);

/// Start a strapdown at a navigation state.
Strapdown make_strapdown(const NavState& nav, Vertical vertical);

/// One update over a tick of dt seconds. Precondition: finite inputs.
/// Returns the tick's specific-force velocity increment in n [m/s] (the
/// fine alignment's measurement).
Vec3 update(Strapdown& s, const Vec3& dtheta_p, const Vec3& dv_p, double dt);

}  // namespace pyins::strapdown
