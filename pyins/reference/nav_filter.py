"""The integrated navigation filter at sea: an error-state Kalman filter run
beside the strapdown in NAVIGATE, 12 states, for the IMU frame p.

Mirrors ``csrc/src/nav_filter.{hpp,cpp}``; the header gives the model
(X = [phi, dv_E, dv_N, dp_E, dp_N, eps_p, nabla_x, nabla_y], Yan 2019 eqs.
4.2.26-4.2.33 with the ship's velocity), the gate (the joint NIS of a pair,
chi-square with 2 degrees of freedom) and the feedback.
"""
from dataclasses import dataclass, field

import numpy as np

from . import earth, kalman

STATES = 12     #: kStates
PHI = 0         #: kPhi
VEL = 3         #: kVel
POS = 5         #: kPos
EPS = 7         #: kEps (p)
NABLA = 10      #: kNabla (p, x and y)


@dataclass
class Params:
    dt: float
    every: int
    reject_limit: int
    gyro_arw: float
    accel_vrw: float
    gate: float
    sigma0_att: np.ndarray
    sigma0_vel: float
    sigma0_pos: float
    sigma0_gyro: float
    sigma0_accel: float
    gyro_bias_rw: float = 0.0   #: the biases' random walk [rad/s/sqrt(s)]; 0 = constants
    table_scale: float = 0.0    #: sigma of the table-axis gyro's scale factor; 0 = none
    table_mis: float = 0.0      #: sigma of the other gyros' misalignment to the table's axis [rad]


@dataclass
class Motion:
    """The linearisation point (mirrors nav_filter::Motion)."""
    sin_lat: float
    cos_lat: float
    rm_h: float
    rn_h: float
    vel_e: float
    vel_n: float


@dataclass
class NavFilter:
    prm: Params
    x: np.ndarray = field(default_factory=lambda: np.zeros(STATES))
    p: np.ndarray = field(default_factory=lambda: np.zeros((STATES, STATES)))
    dv_sum: np.ndarray = field(default_factory=lambda: np.zeros(3))
    c_start: np.ndarray = field(default_factory=lambda: np.eye(3))
    ticks: int = 0
    healthy: int = 1
    move_angle: float = 0.0
    move_q: float = 0.0
    gyro_bias: np.ndarray = field(default_factory=lambda: np.zeros(3))
    accel_bias: np.ndarray = field(default_factory=lambda: np.zeros(3))


def init(prm, c_np):
    """The filter at an attitude C_p^n, P diagonal from the sigmas (mirrors init)."""
    s = prm.sigma0_att
    sigma = np.array([s[0], s[1], s[2], prm.sigma0_vel, prm.sigma0_vel, prm.sigma0_pos,
                      prm.sigma0_pos, prm.sigma0_gyro, prm.sigma0_gyro, prm.sigma0_gyro,
                      prm.sigma0_accel, prm.sigma0_accel])
    return NavFilter(prm=prm, p=np.diag(sigma * sigma), c_start=np.array(c_np, dtype=float))


def gather(f, dv_sf_n, dalpha):
    """One tick's specific-force velocity increment in n' and the table's
    turn dalpha: the move's angle and the growth of its square (mirrors
    gather)."""
    f.dv_sum = f.dv_sum + dv_sf_n
    f.ticks = f.ticks + 1
    if dalpha != 0.0:
        # (a + da)^2 - a^2
        f.move_q = f.move_q + (2.0 * f.move_angle + dalpha) * dalpha
        f.move_angle = f.move_angle + dalpha
    else:
        f.move_angle = 0.0


def system_matrix(m, f_n, c_np):
    """Continuous-time F (mirrors system_matrix; the header gives the equations)."""
    w = earth.OMEGA_IE
    tan_lat = m.sin_lat / m.cos_lat
    sec2 = 1.0 / (m.cos_lat * m.cos_lat)
    w_e = -m.vel_n / m.rm_h
    w_n = w * m.cos_lat + m.vel_e / m.rn_h
    w_u = w * m.sin_lat + m.vel_e * tan_lat / m.rn_h
    w2_u = 2.0 * w * m.sin_lat + m.vel_e * tan_lat / m.rn_h
    f = np.zeros((STATES, STATES))
    # phi' = -w_in x phi + dw_in - C eps
    f[PHI + 0, PHI + 1] = w_u
    f[PHI + 0, PHI + 2] = -w_n
    f[PHI + 1, PHI + 0] = -w_u
    f[PHI + 1, PHI + 2] = w_e
    f[PHI + 2, PHI + 0] = w_n
    f[PHI + 2, PHI + 1] = -w_e
    f[PHI + 0, VEL + 1] = -1.0 / m.rm_h
    f[PHI + 1, VEL + 0] = 1.0 / m.rn_h
    f[PHI + 2, VEL + 0] = tan_lat / m.rn_h
    f[PHI + 1, POS + 1] = -w * m.sin_lat / m.rm_h
    f[PHI + 2, POS + 1] = (w * m.cos_lat + m.vel_e * sec2 / m.rn_h) / m.rm_h
    f[PHI:PHI + 3, EPS:EPS + 3] = -np.asarray(c_np)
    # dv' = f x phi - (2 w_ie + w_en) x dv + v x (2 dw_ie + dw_en) + C nabla
    f[VEL + 0, PHI + 1] = -f_n[2]
    f[VEL + 0, PHI + 2] = f_n[1]
    f[VEL + 1, PHI + 0] = f_n[2]
    f[VEL + 1, PHI + 2] = -f_n[0]
    au_dve = tan_lat / m.rn_h
    au_dpn = (2.0 * w * m.cos_lat + m.vel_e * sec2 / m.rn_h) / m.rm_h
    f[VEL + 0, VEL + 0] = m.vel_n * au_dve
    f[VEL + 0, VEL + 1] = w2_u
    f[VEL + 0, POS + 1] = m.vel_n * au_dpn
    f[VEL + 1, VEL + 0] = -w2_u - m.vel_e * au_dve
    f[VEL + 1, POS + 1] = -m.vel_e * au_dpn
    f[VEL:VEL + 2, NABLA:NABLA + 2] = np.asarray(c_np)[0:2, 0:2]
    # dp' = dv
    f[POS + 0, VEL + 0] = 1.0
    f[POS + 1, VEL + 1] = 1.0
    return f


def predict(f, m, c_np):
    """Time update over the ticks gathered (mirrors predict)."""
    if f.ticks == 0:
        return
    span = float(f.ticks) * f.prm.dt
    c_mean = 0.5 * (f.c_start + c_np)
    ft = system_matrix(m, f.dv_sum / span, c_mean) * span
    phi = ft + 0.5 * (ft @ ft)
    phi[np.diag_indices(STATES)] += 1.0
    f.x = phi @ f.x
    f.p = (phi @ f.p) @ phi.T
    q_att = f.prm.gyro_arw * f.prm.gyro_arw * span
    q_vel = f.prm.accel_vrw * f.prm.accel_vrw * span
    for i in range(3):
        f.p[PHI + i, PHI + i] = f.p[PHI + i, PHI + i] + q_att
    for i in (VEL, VEL + 1):
        f.p[i, i] = f.p[i, i] + q_vel
    if f.prm.gyro_bias_rw > 0.0:
        q_eps = f.prm.gyro_bias_rw * f.prm.gyro_bias_rw * span
        for i in range(3):
            f.p[EPS + i, EPS + i] = f.p[EPS + i, EPS + i] + q_eps
    if f.move_q > 0.0:
        q_tilt = f.prm.table_mis * f.prm.table_mis * f.move_q
        q_head = f.prm.table_scale * f.prm.table_scale * f.move_q
        f.p[PHI + 0, PHI + 0] = f.p[PHI + 0, PHI + 0] + q_tilt
        f.p[PHI + 1, PHI + 1] = f.p[PHI + 1, PHI + 1] + q_tilt
        f.p[PHI + 2, PHI + 2] = f.p[PHI + 2, PHI + 2] + q_head
    f.move_q = 0.0
    f.p = 0.5 * (f.p + f.p.T)
    f.dv_sum = np.zeros(3)
    f.c_start = np.array(c_np, dtype=float)
    f.ticks = 0
    if not kalman.diagonal_positive(f.p):
        f.healthy = 0


def nis_pair(f, k, z, r):
    """The joint NIS of rows k, k + 1 (mirrors nis_pair)."""
    s00 = f.p[k, k] + r[0]
    s01 = f.p[k, k + 1]
    s11 = f.p[k + 1, k + 1] + r[1]
    nu0 = z[0] - f.x[k]
    nu1 = z[1] - f.x[k + 1]
    det = s00 * s11 - s01 * s01
    return (nu0 * (s11 * nu0 - s01 * nu1) + nu1 * (s00 * nu1 - s01 * nu0)) / det


def update_pair(f, k0, z, r):
    """Two scalar Joseph updates of rows k0, k0 + 1 (mirrors update_pair)."""
    for c in range(2):
        k = k0 + c
        s = f.p[k, k] + r[c]
        nu = z[c] - f.x[k]
        gain = f.p[:, k] / s
        f.x = f.x + gain * nu
        a = f.p - np.outer(gain, f.p[k, :])
        f.p = a - np.outer(a[:, k], gain) + r[c] * np.outer(gain, gain)
        f.p = 0.5 * (f.p + f.p.T)
    if not kalman.diagonal_positive(f.p):
        f.healthy = 0


def reset_feedback(f):
    """The biases into the compensation, the state zeroed (mirrors reset_feedback)."""
    f.gyro_bias = f.gyro_bias + f.x[EPS:EPS + 3]
    f.accel_bias = f.accel_bias + np.array([f.x[NABLA], f.x[NABLA + 1], 0.0])
    f.x = np.zeros(STATES)
