// units.hpp: the unit constants, each defined once (twins of pyins/units.py).
//
// Everything in the core that converts a unit reads these. SI inside (rad,
// m, s); degrees, arc-minutes, deg/h and g appear only in the defaults
// (config.hpp) and the test hooks. The expressions are the Python twins'
// (same operations in the same order), so each constant is the same double
// on both sides.
#pragma once

namespace pyins {

inline constexpr double kPi = 3.14159265358979323846;   ///< (np.pi)
inline constexpr double kTwoPi = 2.0 * kPi;             ///< (TWO_PI)
inline constexpr double kDegToRad = kPi / 180.0;        ///< (DEG_TO_RAD)
inline constexpr double kArcsecToRad = kDegToRad / 3600.0;  ///< (ARCSEC_TO_RAD)
inline constexpr double kArcminToRad = kDegToRad / 60.0;    ///< (ARCMIN_TO_RAD)
inline constexpr double kDphToRps = kDegToRad / 3600.0;     ///< deg/h -> rad/s (DPH_TO_RPS)
inline constexpr double kG0 = 9.80665;                  ///< standard gravity for ug/mg units [m/s^2] (G0)
inline constexpr double kUgToMps2 = 1e-6 * kG0;         ///< micro-g -> m/s^2 (UG_TO_MPS2)
inline constexpr double kNmiToM = 1852.0;               ///< nautical mile [m] (NMI_TO_M)

}  // namespace pyins
