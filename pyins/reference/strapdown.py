"""One strapdown update of attitude, velocity and position (ENU).

Mirrors ``csrc/src/strapdown.{hpp,cpp}``: same names, same order of
operations. See the C++ header for the algorithm and its sources (Savage
1998; Yan Gongmin 2019 sec. 4.1) and for the three-sample coning/sculling
coefficients (derived by ``tools/derive_coning.py``).
"""
from dataclasses import dataclass, field
from typing import NamedTuple

import numpy as np

from . import attitude, earth
from .attitude import cross

VERTICAL_HOLD = 0  #: Vertical::kHold
VERTICAL_FREE = 1  #: Vertical::kFree

ONE_TWELFTH = 1.0 / 12.0     #: kOneTwelfth (two-sample coefficient)
C3_NEAR = 121.0 / 720.0      #: kC3Near, (k-1) x (k)
C3_FAR = -31.0 / 720.0       #: kC3Far, (k-2) x (k)
C3_PAST = 1.0 / 720.0        #: kC3Past, (k-2) x (k-1)
ONE_SIXTH = 1.0 / 6.0        #: kOneSixth
LAT_ANCHOR_STEP = 1.0e-4     #: kLatAnchorStep [rad] (640 m)
TERMS_LAT_STEP = 1.0e-6      #: kTermsLatStep [rad] (6.4 m)
TERMS_HEIGHT_STEP = 0.01     #: kTermsHeightStep [m]


def _zeros():
    return np.zeros(3)


@dataclass
class NavState:
    lat: float                 #: geodetic latitude [rad]
    lon: float                 #: longitude [rad], kept in (-pi, pi]
    height: float              #: [m]
    vel_n: np.ndarray          #: ENU velocity [m/s]
    quat_np: np.ndarray        #: C_p^n as [w, x, y, z]


@dataclass
class History:
    """Increments of the ticks before the current one (mirrors History).

    cone1, scul1: the past terms of the three-sample compensation, last
    tick's near terms (see History in strapdown.hpp); computed from the
    increments when not given (what history_of does for the test hooks).
    """
    dtheta1: np.ndarray = field(default_factory=_zeros)   #: tick k-1 [rad]
    dv1: np.ndarray = field(default_factory=_zeros)       #: tick k-1 [m/s]
    dtheta2: np.ndarray = field(default_factory=_zeros)   #: tick k-2 [rad]
    dv2: np.ndarray = field(default_factory=_zeros)       #: tick k-2 [m/s]
    count: int = 0                                        #: valid entries: 0, 1, 2
    cone1: np.ndarray = None                              #: th2 x th1
    scul1: np.ndarray = None                              #: th2 x dv1 + dv2 x th1

    def __post_init__(self):
        if self.cone1 is None:
            self.cone1 = cross(self.dtheta2, self.dtheta1)
        if self.scul1 is None:
            self.scul1 = cross(self.dtheta2, self.dv1) + cross(self.dv2, self.dtheta1)


@dataclass
class Strapdown:
    nav: NavState
    hist: History = field(default_factory=History)
    prev_dvel_n: np.ndarray = field(default_factory=_zeros)
    vertical: int = VERTICAL_HOLD
    ref_height: float = 0.0
    ref_lon: float = 0.0
    lat0: float = None          #: the anchor latitude (None: none yet) [rad]
    sin_lat0: float = 0.0
    cos_lat0: float = 1.0
    terms: earth.PositionTerms = None   #: the Earth terms near nav's position


class Compensated(NamedTuple):
    """Mirrors Compensated."""
    phi: np.ndarray        #: rotation of p over the tick [rad]
    dv_p: np.ndarray       #: velocity increment in p at the start of the tick [m/s]
    cone_near: np.ndarray  #: th1 x th (0 without history)
    scul_near: np.ndarray  #: th1 x dv + dv1 x th (0 without history)


def compensate(dtheta, dv, h):
    """Coning, sculling, rotation compensation (mirrors
    ``pyins::strapdown::compensate``); the past terms from h.cone1, h.scul1."""
    cone = np.zeros(3)
    scul = np.zeros(3)
    cone_near = np.zeros(3)
    scul_near = np.zeros(3)
    if h.count >= 1:
        cone_near = cross(h.dtheta1, dtheta)
        scul_near = cross(h.dtheta1, dv) + cross(h.dv1, dtheta)
    if h.count >= 2:
        cone = C3_NEAR * cone_near + C3_FAR * cross(h.dtheta2, dtheta) + C3_PAST * h.cone1
        scul = (C3_NEAR * scul_near + C3_FAR * (cross(h.dtheta2, dv) + cross(h.dv2, dtheta))
                + C3_PAST * h.scul1)
    elif h.count == 1:
        cone = ONE_TWELFTH * cone_near
        scul = ONE_TWELFTH * scul_near
    phi = dtheta + cone
    dv_rot = 0.5 * cross(dtheta, dv) + ONE_SIXTH * cross(dtheta, cross(dtheta, dv))
    dv_p = dv + dv_rot + scul
    return Compensated(phi, dv_p, cone_near, scul_near)


def push_history(h, dtheta, dv, c):
    """Shift this tick's increments and near terms (``c``, from
    `compensate`) into the history (mirrors push_history)."""
    h.dtheta2 = h.dtheta1
    h.dv2 = h.dv1
    h.dtheta1 = np.array(dtheta, dtype=float)
    h.dv1 = np.array(dv, dtype=float)
    h.cone1 = c.cone_near
    h.scul1 = c.scul_near
    if h.count < 2:
        h.count = h.count + 1


def lat_sincos(s):
    """Sine and cosine of s.nav.lat from the anchor, moved when more than
    LAT_ANCHOR_STEP away (mirrors lat_sincos; strapdown.hpp says why)."""
    d = s.nav.lat - s.lat0 if s.lat0 is not None else np.nan
    if not abs(d) <= LAT_ANCHOR_STEP:
        s.lat0 = s.nav.lat
        s.sin_lat0, s.cos_lat0 = np.sin(s.lat0), np.cos(s.lat0)
        d = 0.0
    d2 = d * d
    cd = 1.0 - d2 * (0.5 - d2 * (1.0 / 24.0))
    sd = d * (1.0 - d2 * (1.0 / 6.0))
    return s.sin_lat0 * cd + s.cos_lat0 * sd, s.cos_lat0 * cd - s.sin_lat0 * sd


def position_terms(s):
    """The Earth terms at s.nav's position: those kept, or computed again
    when it has moved more than TERMS_LAT_STEP / TERMS_HEIGHT_STEP (mirrors
    ``pyins::strapdown::position_terms``; strapdown.hpp says why)."""
    t = s.terms
    if t is None or not (abs(s.nav.lat - t.lat) <= TERMS_LAT_STEP
                         and abs(s.nav.height - t.height) <= TERMS_HEIGHT_STEP):
        sin_lat, cos_lat = lat_sincos(s)
        s.terms = earth.position_terms(s.nav.lat, sin_lat, cos_lat, s.nav.height)
    return s.terms


def make_strapdown(nav, vertical):
    s = Strapdown(nav=NavState(nav.lat, nav.lon, nav.height,
                               np.array(nav.vel_n, dtype=float),
                               np.array(nav.quat_np, dtype=float)),
                  vertical=vertical, ref_height=nav.height, ref_lon=nav.lon,
                  lat0=nav.lat, sin_lat0=np.sin(nav.lat), cos_lat0=np.cos(nav.lat))
    s.terms = earth.position_terms(nav.lat, s.sin_lat0, s.cos_lat0, nav.height)
    if vertical == VERTICAL_HOLD:
        s.nav.vel_n[2] = 0.0
    return s


def update(s, dtheta_p, dv_p, dt):
    """One update over a tick of ``dt`` seconds (mirrors ``strapdown::update``).

    Returns the tick's specific-force velocity increment in n [m/s].
    """
    # 1. Coning, sculling and rotation compensation.
    c = compensate(dtheta_p, dv_p, s.hist)
    phi, dv_comp = c.phi, c.dv_p

    # 2. Earth at the start position (the terms kept near it), velocity
    #    extrapolated to mid-tick.
    vel_mid = s.nav.vel_n + 0.5 * s.prev_dvel_n
    p = position_terms(s)
    d = s.nav.lat - p.lat   # |d| <= TERMS_LAT_STEP
    omega_ie_n = earth.earth_rate(p, d)
    omega_en_n = earth.transport_rate(p, d, vel_mid)
    omega_in_n = omega_ie_n + omega_en_n
    gravity = p.gravity
    if s.vertical == VERTICAL_FREE:
        # a free vertical channel's dynamics are gravity's own feedback:
        # gravity at this tick's position, exactly (strapdown.hpp)
        sin_lat, _ = lat_sincos(s)
        gravity = earth.normal_gravity(sin_lat, s.nav.height)
    gravity_n = np.array([0.0, 0.0, -gravity])

    # 3. Velocity (Yan 2019 eq. 4.1.27).
    dv_n0 = attitude.quat_rotate(s.nav.quat_np, dv_comp)
    dv_sf_n = dv_n0 - 0.5 * dt * cross(omega_in_n, dv_n0)
    coriolis_n = cross(2.0 * omega_ie_n + omega_en_n, vel_mid)
    dv_cor_n = (gravity_n - coriolis_n) * dt
    vel_new = s.nav.vel_n + dv_sf_n + dv_cor_n
    if s.vertical == VERTICAL_HOLD:
        vel_new[2] = 0.0

    # 4. Position, trapezoidal rule (Qin 2014 eq. 4.1.12).
    vel_avg = 0.5 * (s.nav.vel_n + vel_new)
    pos_rate = earth.position_rate_of_terms(p, d, vel_avg)
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
    q_nn = attitude.rotvec_to_quat(-dt * omega_in_n)
    q_pp = attitude.rotvec_to_quat(phi)
    s.nav.quat_np = attitude.quat_renormalize(
        attitude.quat_mul(attitude.quat_mul(q_nn, s.nav.quat_np), q_pp))

    # 6. Memory for the next tick.
    s.prev_dvel_n = vel_new - s.nav.vel_n
    s.nav.vel_n = vel_new
    push_history(s.hist, dtheta_p, dv_p, c)
    return dv_sf_n
