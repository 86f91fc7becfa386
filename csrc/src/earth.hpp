// earth.hpp: WGS-84 Earth model for the navigation frame n = East-North-Up.
//
// Mirrored line for line by pyins/reference/earth.py. The simulator uses the
// reference module, so plant and firmware share one Earth model (docs/design.md §4).
//
// References: NIMA TR8350.2 (2000) eqs. 4-1, 4-3 (normal gravity);
// Qin Yongyuan, "Inertial Navigation" (2014) sec. 4.1 (radii, rates).
#pragma once

#include "types.hpp"
#include "units.hpp"

namespace pyins::earth {

// --- WGS-84 defining and derived constants (earth.py: A, F, ...) ---------
inline constexpr double kA = 6378137.0;                  ///< semi-major axis [m]
inline constexpr double kF = 1.0 / 298.257223563;        ///< flattening [-]
inline constexpr double kE2 = kF * (2.0 - kF);           ///< first eccentricity squared [-]
inline constexpr double kB = kA * (1.0 - kF);            ///< semi-minor axis [m]
inline constexpr double kOmegaIe = 7.2921151467e-5;      ///< Earth rotation rate [rad/s]
inline constexpr double kGM = 3.986004418e14;            ///< gravitational constant [m^3/s^2]
inline constexpr double kGammaE = 9.7803253359;          ///< normal gravity, equator [m/s^2]
inline constexpr double kSomigliana = 0.00193185265241;  ///< Somigliana k [-]
inline constexpr double kMGrav = kOmegaIe * kOmegaIe * kA * kA * kB / kGM;  ///< m [-]

/// Meridian (R_M) and prime-vertical (R_N) radii of curvature [m].
struct PrincipalRadii {
    double rm;
    double rn;
};

/// Radii of curvature at a latitude given by its sine. Qin (2014) eq. 4.1.7.
PrincipalRadii principal_radii(double sin_lat);

/// Normal gravity magnitude [m/s^2] (includes the centrifugal part; acts
/// along -Up). TR8350.2 eqs. 4-1 and 4-3.
double normal_gravity(double sin_lat, double height);

/// Earth quantities at one position and velocity.
struct Earth {
    double sin_lat;
    double cos_lat;
    double tan_lat;
    double rm_h;       ///< R_M + h [m]
    double rn_h;       ///< R_N + h [m]
    Vec3 omega_ie_n;   ///< Earth rate in n [rad/s]
    Vec3 omega_en_n;   ///< transport rate in n [rad/s]
    Vec3 omega_in_n;   ///< omega_ie_n + omega_en_n [rad/s]
    Vec3 gravity_n;    ///< normal gravity vector in n [m/s^2]
};

/// All Earth quantities the strapdown update needs. Qin (2014) eqs.
/// 4.1.9-4.1.11 (ENU). Precondition: |cos_lat| > 0.
Earth earth_at(double sin_lat, double cos_lat, double height, const Vec3& vel_n);

/// [lat_dot, lon_dot, h_dot] [rad/s, rad/s, m/s]. Qin (2014) eq. 4.1.12.
Vec3 position_rate(const Earth& earth, const Vec3& vel_n);

/// The Earth terms of one position (latitude L0 and height) in the form a
/// navigation tick uses them: the radii as inverses, so that the tick
/// multiplies where earth_at and position_rate divide. The strapdown keeps
/// them while the position stays near where they were computed
/// (strapdown.hpp, "Earth terms"); a tick carries the latitude-dependent
/// ones to its own latitude L = L0 + d to first order in d.
struct PositionTerms {
    double lat;            ///< latitude L0 they were computed at [rad]
    double height;         ///< height they were computed at [m]
    double inv_rm_h;       ///< 1 / (R_M + h) [1/m]
    double inv_rn_h;       ///< 1 / (R_N + h) [1/m]
    double tan_inv_rn_h;   ///< tan L0 / (R_N + h) [1/m]
    double sec2_inv_rn_h;  ///< its derivative in L: 1 / ((R_N + h) cos^2 L0) [1/m]
    double inv_rn_h_cos;   ///< 1 / ((R_N + h) cos L0) [1/m]
    double tan_lat;        ///< tan L0: d/dL of 1 / cos L is tan L / cos L
    Vec3 omega_ie_n;       ///< Earth rate in n at L0 [rad/s]
    double gravity;        ///< normal gravity magnitude [m/s^2]
};

/// The terms at latitude lat (its sine and cosine given) and height. Qin
/// (2014) eqs. 4.1.7, 4.1.9-4.1.12; TR8350.2 eqs. 4-1, 4-3, with one
/// 1 / sqrt(1 - e^2 sin^2 L) shared by R_N, R_M and gamma_0.
/// Precondition: |cos_lat| > 0.
PositionTerms position_terms(double lat, double sin_lat, double cos_lat, double height);

/// Earth rate at L0 + d, to first order in d: Omega [0, cos L0 - d sin L0,
/// sin L0 + d cos L0] (Qin (2014) eq. 4.1.9; the d^2 / 2 left out is
/// < 1e-12 of Omega for |d| <= 1e-6 rad).
Vec3 earth_rate(const PositionTerms& p, double d);

/// Transport rate omega_en^n = [-vN, vE, vE tan L] / (R + h) (Qin (2014)
/// eq. 4.1.10) at L0 + d, tan L to first order in d.
Vec3 transport_rate(const PositionTerms& p, double d, const Vec3& vel_n);

/// [lat_dot, lon_dot, h_dot] (Qin (2014) eq. 4.1.12) at L0 + d, 1 / cos L
/// to first order in d.
Vec3 position_rate(const PositionTerms& p, double d, const Vec3& vel_n);

}  // namespace pyins::earth
