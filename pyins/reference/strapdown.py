"""One strapdown update of attitude, velocity and position (ENU).

Mirrors ``csrc/src/strapdown.{hpp,cpp}``: same names, same order of
operations. See the C++ header for the algorithm and its sources (Savage
1998 two-sample coning/sculling; Yan Gongmin 2019 sec. 4.1 velocity and
attitude updates).
"""
from dataclasses import dataclass, field

import numpy as np

from . import attitude, earth
from .attitude import cross

VERTICAL_HOLD = 0  #: Vertical::kHold
VERTICAL_FREE = 1  #: Vertical::kFree
ONE_TWELFTH = 1.0 / 12.0  #: kOneTwelfth, the two-sample coning/sculling coefficient


@dataclass
class NavState:
    lat: float                 #: geodetic latitude [rad]
    lon: float                 #: longitude [rad], kept in (-pi, pi]
    height: float              #: [m]
    vel_n: np.ndarray          #: ENU velocity [m/s]
    quat_np: np.ndarray        #: C_p^n as [w, x, y, z]


@dataclass
class Strapdown:
    nav: NavState
    prev_dtheta_p: np.ndarray = field(default_factory=lambda: np.zeros(3))
    prev_dv_p: np.ndarray = field(default_factory=lambda: np.zeros(3))
    prev_dvel_n: np.ndarray = field(default_factory=lambda: np.zeros(3))
    has_prev: bool = False
    vertical: int = VERTICAL_HOLD
    ref_height: float = 0.0


def compensate(dtheta, dv, prev_dtheta, prev_dv):
    """Two-sample coning, sculling and rotation compensation.

    Returns ``(phi, dv_p)``; see ``pyins::strapdown::compensate``.
    """
    phi = dtheta + ONE_TWELFTH * cross(prev_dtheta, dtheta)
    dv_rot = 0.5 * cross(dtheta, dv)
    dv_scul = ONE_TWELFTH * (cross(prev_dtheta, dv) + cross(prev_dv, dtheta))
    dv_p = dv + dv_rot + dv_scul
    return phi, dv_p


def make_strapdown(nav, vertical):
    s = Strapdown(nav=NavState(nav.lat, nav.lon, nav.height,
                               np.array(nav.vel_n, dtype=float),
                               np.array(nav.quat_np, dtype=float)),
                  vertical=vertical, ref_height=nav.height)
    if vertical == VERTICAL_HOLD:
        s.nav.vel_n[2] = 0.0
    return s


def update(s, dtheta_p, dv_p, dt):
    """One update over a tick of ``dt`` seconds (mirrors ``strapdown::update``)."""
    # 1. Coning, sculling, rotation compensation (zero before the first tick).
    prev_dtheta = s.prev_dtheta_p if s.has_prev else dtheta_p
    prev_dv = s.prev_dv_p if s.has_prev else dv_p
    phi, dv_comp = compensate(dtheta_p, dv_p, prev_dtheta, prev_dv)

    # 2. Earth at the start position, velocity extrapolated to mid-tick.
    vel_mid = s.nav.vel_n + 0.5 * s.prev_dvel_n
    sin_lat = np.sin(s.nav.lat)
    cos_lat = np.cos(s.nav.lat)
    e = earth.earth_at(sin_lat, cos_lat, s.nav.height, vel_mid)

    # 3. Velocity (Yan 2019 eq. 4.1.27).
    mat_np = attitude.quat_to_mat(s.nav.quat_np)
    dv_n0 = mat_np @ dv_comp
    dv_sf_n = dv_n0 - 0.5 * dt * cross(e.omega_in_n, dv_n0)
    coriolis_n = cross(2.0 * e.omega_ie_n + e.omega_en_n, vel_mid)
    dv_cor_n = (e.gravity_n - coriolis_n) * dt
    vel_new = s.nav.vel_n + dv_sf_n + dv_cor_n
    if s.vertical == VERTICAL_HOLD:
        vel_new[2] = 0.0

    # 4. Position, trapezoidal rule (Qin 2014 eq. 4.1.12).
    vel_avg = 0.5 * (s.nav.vel_n + vel_new)
    pos_rate = earth.position_rate(e, vel_avg)
    s.nav.lat = s.nav.lat + pos_rate[0] * dt
    lon = s.nav.lon + pos_rate[1] * dt
    if lon > np.pi:
        lon = lon - 2.0 * np.pi
    elif lon <= -np.pi:
        lon = lon + 2.0 * np.pi
    s.nav.lon = lon
    if s.vertical == VERTICAL_HOLD:
        s.nav.height = s.ref_height
    else:
        s.nav.height = s.nav.height + pos_rate[2] * dt

    # 5. Attitude: q_np(k) = q(-T omega_in^n) q_np(k-1) q(phi) (Yan eq. 4.1.8).
    q_nn = attitude.rotvec_to_quat(-dt * e.omega_in_n)
    q_pp = attitude.rotvec_to_quat(phi)
    s.nav.quat_np = attitude.quat_normalize(
        attitude.quat_mul(attitude.quat_mul(q_nn, s.nav.quat_np), q_pp))

    # 6. Memory for the next tick.
    s.prev_dvel_n = vel_new - s.nav.vel_n
    s.nav.vel_n = vel_new
    s.prev_dtheta_p = np.array(dtheta_p, dtype=float)
    s.prev_dv_p = np.array(dv_p, dtype=float)
    s.has_prev = True
