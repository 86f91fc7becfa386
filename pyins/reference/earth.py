"""WGS-84 Earth model: radii of curvature, normal gravity, Earth and transport rates.

Mirrors ``csrc/src/earth.{hpp,cpp}`` function for function, with the same names
and the same order of operations, so the two can be read side by side. The
simulator (``pyins.sim``) uses this same module, so an error-free simulation
shows only algorithm error (docs/design.md §4).

Navigation frame n is East-North-Up. All quantities SI: rad, m, s, m/s.

References
----------
- NIMA TR8350.2 (2000), "Department of Defense World Geodetic System 1984",
  eqs. 4-1 (Somigliana normal gravity on the ellipsoid) and 4-3 (its
  second-order expansion in height).
- Qin Yongyuan, "Inertial Navigation" (2nd ed., 2014), section 4.1: radii of
  curvature R_M, R_N; the ENU transport rate; position rates.
"""
from dataclasses import dataclass

import numpy as np

# --- WGS-84 defining and derived constants (earth.hpp: kA, kF, ...) ---------
A = 6378137.0                      #: semi-major axis [m] (kA)
F = 1.0 / 298.257223563            #: flattening [-] (kF)
E2 = F * (2.0 - F)                 #: first eccentricity squared [-] (kE2)
B = A * (1.0 - F)                  #: semi-minor axis [m] (kB)
OMEGA_IE = 7.2921151467e-5         #: Earth rotation rate [rad/s] (kOmegaIe)
GM = 3.986004418e14                #: gravitational constant [m^3/s^2] (kGM)
GAMMA_E = 9.7803253359             #: normal gravity at the equator [m/s^2] (kGammaE)
K_SOMIGLIANA = 0.00193185265241    #: Somigliana constant k [-] (kSomigliana)
M_GRAV = OMEGA_IE * OMEGA_IE * A * A * B / GM  #: m = w^2 a^2 b / GM [-] (kMGrav)

# The unit conversions (degrees, arcmin, deg/h, ug, ...) are pyins.units
# (units.hpp), not part of the Earth model.


def principal_radii(sin_lat):
    """Meridian R_M and prime-vertical R_N radii of curvature [m].

    Mirrors ``pyins::earth::principal_radii``. Qin (2014) eq. 4.1.7.
    """
    x = 1.0 - E2 * sin_lat * sin_lat
    sqrt_x = np.sqrt(x)
    rn = A / sqrt_x
    rm = rn * (1.0 - E2) / x
    return rm, rn


def normal_gravity(sin_lat, height):
    """Magnitude of normal gravity [m/s^2] at geodetic latitude and height.

    Mirrors ``pyins::earth::normal_gravity``. TR8350.2 eqs. 4-1 and 4-3. It
    includes the centrifugal part, and points along -Up of the ellipsoid normal.
    """
    s2 = sin_lat * sin_lat
    gamma0 = GAMMA_E * (1.0 + K_SOMIGLIANA * s2) / np.sqrt(1.0 - E2 * s2)
    return _at_height(gamma0, s2, height)


def _at_height(gamma0, s2, height):
    """gamma0 at height h, s2 = sin^2 L (mirrors at_height in earth.cpp;
    TR8350.2 eq. 4-3)."""
    c1 = 2.0 / A * (1.0 + F + M_GRAV - 2.0 * F * s2)
    c2 = 3.0 / (A * A)
    return gamma0 * (1.0 - c1 * height + c2 * height * height)


@dataclass
class Earth:
    """Earth quantities at one position and velocity (mirrors ``pyins::earth::Earth``)."""
    sin_lat: float
    cos_lat: float
    tan_lat: float
    rm_h: float          #: R_M + h [m]
    rn_h: float          #: R_N + h [m]
    omega_ie_n: np.ndarray   #: Earth rate in n [rad/s]
    omega_en_n: np.ndarray   #: transport rate in n [rad/s]
    omega_in_n: np.ndarray   #: omega_ie_n + omega_en_n [rad/s]
    gravity_n: np.ndarray    #: normal gravity vector in n [m/s^2]


def earth_at(sin_lat, cos_lat, height, vel_n):
    """All Earth quantities the strapdown update needs at one point.

    Mirrors ``pyins::earth::earth_at``. The caller passes sin and cos of the
    latitude (the C++ core computes them with its own portable sin/cos).
    Qin (2014) eqs. 4.1.9-4.1.11 (ENU): omega_ie^n = [0, W cosL, W sinL],
    omega_en^n = [-vN/(RM+h), vE/(RN+h), vE tanL/(RN+h)].
    """
    rm, rn = principal_radii(sin_lat)
    rm_h = rm + height
    rn_h = rn + height
    tan_lat = sin_lat / cos_lat
    omega_ie_n = np.array([0.0, OMEGA_IE * cos_lat, OMEGA_IE * sin_lat])
    omega_en_n = np.array([-vel_n[1] / rm_h, vel_n[0] / rn_h, vel_n[0] / rn_h * tan_lat])
    omega_in_n = omega_ie_n + omega_en_n
    gravity_n = np.array([0.0, 0.0, -normal_gravity(sin_lat, height)])
    return Earth(sin_lat, cos_lat, tan_lat, rm_h, rn_h,
                 omega_ie_n, omega_en_n, omega_in_n, gravity_n)


def position_rate(earth, vel_n):
    """Rates of latitude, longitude [rad/s] and height [m/s].

    Mirrors ``pyins::earth::position_rate`` of an `Earth` (that of
    `PositionTerms` is `position_rate_of_terms`). Qin (2014) eq. 4.1.12.
    """
    lat_dot = vel_n[1] / earth.rm_h
    lon_dot = vel_n[0] / (earth.rn_h * earth.cos_lat)
    return np.array([lat_dot, lon_dot, vel_n[2]])


@dataclass
class PositionTerms:
    """The Earth terms of one position (latitude L0, height), radii as
    inverses (mirrors ``pyins::earth::PositionTerms``; strapdown keeps them
    near the position, a tick carries them to its latitude L0 + d)."""
    lat: float               #: latitude L0 they were computed at [rad]
    height: float            #: height they were computed at [m]
    inv_rm_h: float          #: 1 / (R_M + h) [1/m]
    inv_rn_h: float          #: 1 / (R_N + h) [1/m]
    tan_inv_rn_h: float      #: tan L0 / (R_N + h) [1/m]
    sec2_inv_rn_h: float     #: its derivative in L: 1 / ((R_N + h) cos^2 L0) [1/m]
    inv_rn_h_cos: float      #: 1 / ((R_N + h) cos L0) [1/m]
    tan_lat: float           #: tan L0
    omega_ie_n: np.ndarray   #: Earth rate in n at L0 [rad/s]
    gravity: float           #: normal gravity magnitude [m/s^2]


def position_terms(lat, sin_lat, cos_lat, height):
    """The terms at one latitude (its sine and cosine given) and height
    (mirrors ``pyins::earth::position_terms``: four divisions where
    principal_radii, normal_gravity and earth_at make seven). Qin (2014)
    eqs. 4.1.7, 4.1.9-4.1.12; TR8350.2 eqs. 4-1, 4-3."""
    s2 = sin_lat * sin_lat
    x = 1.0 - E2 * s2
    inv_sqrt_x = 1.0 / np.sqrt(x)
    rn = A * inv_sqrt_x                                 # a / sqrt(x)
    rm = rn * (1.0 - E2) * (inv_sqrt_x * inv_sqrt_x)    # a (1 - e^2) / x^(3/2)
    gamma0 = GAMMA_E * (1.0 + K_SOMIGLIANA * s2) * inv_sqrt_x
    inv_cos = 1.0 / cos_lat
    inv_rm_h = 1.0 / (rm + height)
    inv_rn_h = 1.0 / (rn + height)
    tan_lat = sin_lat * inv_cos
    inv_rn_h_cos = inv_rn_h * inv_cos
    return PositionTerms(lat=lat, height=height, inv_rm_h=inv_rm_h, inv_rn_h=inv_rn_h,
                         tan_inv_rn_h=tan_lat * inv_rn_h, sec2_inv_rn_h=inv_rn_h_cos * inv_cos,
                         inv_rn_h_cos=inv_rn_h_cos, tan_lat=tan_lat,
                         omega_ie_n=np.array([0.0, OMEGA_IE * cos_lat, OMEGA_IE * sin_lat]),
                         gravity=_at_height(gamma0, s2, height))


def earth_rate(p, d):
    """Earth rate at L0 + d to first order in d (mirrors
    ``pyins::earth::earth_rate``; Qin (2014) eq. 4.1.9)."""
    return np.array([0.0, p.omega_ie_n[1] - d * p.omega_ie_n[2], p.omega_ie_n[2] + d * p.omega_ie_n[1]])


def transport_rate(p, d, vel_n):
    """omega_en^n at L0 + d, tan L to first order in d (mirrors
    ``pyins::earth::transport_rate``; Qin (2014) eq. 4.1.10)."""
    return np.array([-vel_n[1] * p.inv_rm_h, vel_n[0] * p.inv_rn_h,
                     vel_n[0] * (p.tan_inv_rn_h + d * p.sec2_inv_rn_h)])


def position_rate_of_terms(p, d, vel_n):
    """[lat_dot, lon_dot, h_dot] at L0 + d, 1 / cos L to first order in d
    (mirrors ``pyins::earth::position_rate`` of PositionTerms; Qin (2014)
    eq. 4.1.12)."""
    return np.array([vel_n[1] * p.inv_rm_h, vel_n[0] * (p.inv_rn_h_cos * (1.0 + d * p.tan_lat)), vel_n[2]])
