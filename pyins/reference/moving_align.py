"""Moving-base Kalman fine alignment of a moored ship by position matching.

Mirrors ``csrc/src/moving_align.{hpp,cpp}``; the header gives the model
(12 states [phi, dv_E, dv_N, dp_E, dp_N, eps, nabla_E, nabla_N]), the
measurement (the reference point's offset from the site, the waves as its
noise) and the discretisation.
"""
import math
from dataclasses import dataclass, field

import numpy as np

from . import earth, kalman

STATES = 12       #: kStates
PHI = 0           #: kPhi
VEL = 3           #: kVel
POS = 5           #: kPos
EPS = 7           #: kEps
NABLA = 10        #: kNabla
SITE_MARGIN = 3.0  #: kSiteMargin


@dataclass
class Params:
    sin_lat: float
    cos_lat: float
    rm_h: float
    rn_h: float
    dt: float
    meas_every: int
    gyro_arw: float
    accel_vrw: float
    pos_sigma: float
    site_accel: float
    sigma0_att: np.ndarray
    sigma0_vel: float
    sigma0_gyro: float
    sigma0_accel: float
    nis_window: int = 0
    nis_max: float = 0.0


@dataclass
class MovingAlign:
    prm: Params
    x: np.ndarray = field(default_factory=lambda: np.zeros(STATES))
    p: np.ndarray = field(default_factory=lambda: np.zeros((STATES, STATES)))
    dv_sum: np.ndarray = field(default_factory=lambda: np.zeros(3))
    meas_count: int = 0
    healthy: bool = True
    consistent: bool = True
    nis_sum: float = 0.0
    nis_count: int = 0
    nis_mean: float = 0.0
    nis_windows: int = 0


def init(prm):
    s = prm.sigma0_att
    sigma = np.array([s[0], s[1], s[2], prm.sigma0_vel, prm.sigma0_vel, prm.pos_sigma,
                      prm.pos_sigma, prm.sigma0_gyro, prm.sigma0_gyro, prm.sigma0_gyro,
                      prm.sigma0_accel, prm.sigma0_accel])
    return MovingAlign(prm=prm, p=np.diag(sigma * sigma))


def sigma0_after_coarse(prm, coarse_s, wander, gravity):
    """Add what the site's slow motion and the wander leave a coarse result of coarse_s seconds
    to prm.sigma0_att, in quadrature (mirrors sigma0_after_coarse; the header derives it)."""
    if not prm.site_accel > 0.0:
        return
    k = gravity * earth.OMEGA_IE * prm.cos_lat / 6.0
    level = prm.site_accel / (gravity * math.sqrt(coarse_s))
    heading = prm.site_accel / (k * math.sqrt(3.0 * coarse_s * coarse_s * coarse_s))
    w2 = wander * wander
    add = (level * level + w2, level * level + w2, heading * heading + w2)
    att = np.array(prm.sigma0_att, dtype=float)
    for i in range(3):
        s = att[i]
        att[i] = math.sqrt(s * s + SITE_MARGIN * SITE_MARGIN * add[i])
    prm.sigma0_att = att


def system_matrix(prm, f_n):
    """Continuous-time F for the mean specific force f_n (mirrors system_matrix)."""
    w_n = earth.OMEGA_IE * prm.cos_lat
    w_u = earth.OMEGA_IE * prm.sin_lat
    tan_lat = prm.sin_lat / prm.cos_lat
    f = np.zeros((STATES, STATES))
    f[0, 1] = w_u
    f[0, 2] = -w_n
    f[1, 0] = -w_u
    f[2, 0] = w_n
    f[0, VEL + 1] = -1.0 / prm.rm_h
    f[1, VEL + 0] = 1.0 / prm.rn_h
    f[2, VEL + 0] = tan_lat / prm.rn_h
    f[0, EPS + 0] = -1.0
    f[1, EPS + 1] = -1.0
    f[2, EPS + 2] = -1.0
    f[VEL + 0, 1] = -f_n[2]
    f[VEL + 0, 2] = f_n[1]
    f[VEL + 1, 0] = f_n[2]
    f[VEL + 1, 2] = -f_n[0]
    f[VEL + 0, VEL + 1] = 2.0 * w_u
    f[VEL + 1, VEL + 0] = -2.0 * w_u
    f[VEL + 0, NABLA + 0] = 1.0
    f[VEL + 1, NABLA + 1] = 1.0
    f[POS + 0, VEL + 0] = 1.0
    f[POS + 1, VEL + 1] = 1.0
    return f


def measure(m):
    """True when this tick ends an interval (mirrors measure)."""
    return m.meas_count + 1 == m.prm.meas_every


def step(m, dv_sf_n, z_en):
    """Gather; at the end of an interval predict and update with z_en (mirrors step)."""
    m.dv_sum = m.dv_sum + dv_sf_n
    m.meas_count = m.meas_count + 1
    if m.meas_count != m.prm.meas_every:
        return False
    span = float(m.prm.meas_every) * m.prm.dt
    ft = system_matrix(m.prm, m.dv_sum / span) * span
    phi = ft + 0.5 * (ft @ ft)
    phi[np.diag_indices(STATES)] += 1.0
    m.x = phi @ m.x
    m.p = (phi @ m.p) @ phi.T
    q_att = m.prm.gyro_arw * m.prm.gyro_arw * span
    q_vel = (m.prm.accel_vrw * m.prm.accel_vrw + m.prm.site_accel * m.prm.site_accel) * span
    for i in range(3):
        m.p[i, i] = m.p[i, i] + q_att
    for i in (VEL, VEL + 1):
        m.p[i, i] = m.p[i, i] + q_vel
    m.p = 0.5 * (m.p + m.p.T)
    r_pos = m.prm.pos_sigma * m.prm.pos_sigma
    nis = 0.0
    for c in range(2):     # E then N: two scalar Joseph updates (unit H, diagonal R)
        k = POS + c
        s = m.p[k, k] + r_pos
        nu = z_en[c] - m.x[k]
        nis = nis + nu * nu / s
        gain = m.p[:, k] / s
        m.x = m.x + gain * nu
        a = m.p - np.outer(gain, m.p[k, :])
        m.p = a - np.outer(a[:, k], gain) + r_pos * np.outer(gain, gain)
        m.p = 0.5 * (m.p + m.p.T)
    m.dv_sum = np.zeros(3)
    m.meas_count = 0
    if m.prm.nis_window > 0:
        m.nis_sum = m.nis_sum + nis
        m.nis_count = m.nis_count + 1
        if m.nis_count == m.prm.nis_window:
            m.nis_mean = m.nis_sum / float(m.prm.nis_window)
            m.nis_windows = m.nis_windows + 1
            m.consistent = m.consistent and m.nis_mean <= m.prm.nis_max
            m.nis_sum = 0.0
            m.nis_count = 0
    m.healthy = m.healthy and kalman.diagonal_positive(m.p)
    return True


def reset_feedback(m):
    """phi, dv, dp = 0 after the feedback."""
    m.x[:EPS] = 0.0
