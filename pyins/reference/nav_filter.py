"""The integrated navigation filter at sea: an error-state Kalman filter run
beside the strapdown in NAVIGATE, 19 states, for the IMU frame p.

Mirrors ``csrc/src/nav_filter.{hpp,cpp}``; the header gives the model
(X = [phi, dv_E, dv_N, dp_E, dp_N, eps_p, nabla_x, nabla_y, m_xz, m_yz, k_z,
k_x, k_y, m_xy, m_yx], Yan 2019 eqs. 4.2.26-4.2.33 with the ship's
velocity; the gyros' scale factors and misalignments act through the
rates), the time update by blocks (the constants' rows of F are zero), the
gate (the joint NIS of a pair,
chi-square with 2 degrees of freedom) and the feedback.
"""
from dataclasses import dataclass, field

import numpy as np

from . import earth

STATES = 19     #: kStates
DYN = 7         #: kDyn: phi, dv, dp; the rest are constants
PHI = 0         #: kPhi
VEL = 3         #: kVel
POS = 5         #: kPos
EPS = 7         #: kEps (p)
NABLA = 10      #: kNabla (p, x and y)
TAB = 12        #: kTab: m_xz, m_yz, k_z (p)
LEV = 15        #: kLev: k_x, k_y, m_xy, m_yx (p)


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
    table_scale: float = 0.0    #: prior sigma of k_z, the table-axis gyro's scale factor; 0 = not modelled
    table_mis: float = 0.0      #: prior sigma of m_xz, m_yz [rad]; 0 = not modelled
    level_scale: float = 0.0    #: prior sigma of k_x, k_y; 0 = not modelled
    level_mis: float = 0.0      #: prior sigma of m_xy, m_yx [rad]; 0 = not modelled


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
    dtheta_sum: np.ndarray = field(default_factory=lambda: np.zeros(3))
    gyro_bias: np.ndarray = field(default_factory=lambda: np.zeros(3))
    accel_bias: np.ndarray = field(default_factory=lambda: np.zeros(3))
    table_err: np.ndarray = field(default_factory=lambda: np.zeros(3))
    level_err: np.ndarray = field(default_factory=lambda: np.zeros(4))


def init(prm, c_np):
    """The filter at an attitude C_p^n, P diagonal from the sigmas (mirrors init)."""
    s = prm.sigma0_att
    sigma = np.array([s[0], s[1], s[2], prm.sigma0_vel, prm.sigma0_vel, prm.sigma0_pos,
                      prm.sigma0_pos, prm.sigma0_gyro, prm.sigma0_gyro, prm.sigma0_gyro,
                      prm.sigma0_accel, prm.sigma0_accel, prm.table_mis, prm.table_mis,
                      prm.table_scale, prm.level_scale, prm.level_scale, prm.level_mis, prm.level_mis])
    return NavFilter(prm=prm, p=np.diag(sigma * sigma), c_start=np.array(c_np, dtype=float))


def gather(f, dv_sf_n, dtheta_p):
    """One tick's specific-force velocity increment in n' and its
    compensated angle increment in p (mirrors gather)."""
    f.dv_sum = f.dv_sum + dv_sf_n
    f.dtheta_sum = f.dtheta_sum + dtheta_p
    f.ticks = f.ticks + 1


def compensate_gyro(f, dtheta_p, dt):
    """The gyro increment with the estimated biases, scale factors and
    misalignments removed (mirrors compensate_gyro)."""
    d = dtheta_p - f.gyro_bias * dt
    lv = f.level_err
    return np.array([d[0] - lv[0] * dtheta_p[0] - lv[2] * dtheta_p[1] - f.table_err[0] * dtheta_p[2],
                     d[1] - lv[3] * dtheta_p[0] - lv[1] * dtheta_p[1] - f.table_err[1] * dtheta_p[2],
                     d[2] - f.table_err[2] * dtheta_p[2]])


def diagonal_healthy(p):
    """P's diagonal positive and finite, the scale-factor and misalignment
    states' not negative (0 while not modelled; mirrors the anonymous
    diagonal_healthy)."""
    d = np.diag(p)
    return bool(np.all(d[:TAB] > 0.0) and np.all(d[TAB:] >= 0.0) and np.all(np.isfinite(d)))


def system_matrix(m, f_n, c_np, w_p):
    """The dynamic rows of the continuous-time F, 7 x 19, at the mean
    rate w_p (mirrors system_matrix; the header gives the equations)."""
    w = earth.OMEGA_IE
    tan_lat = m.sin_lat / m.cos_lat
    sec2 = 1.0 / (m.cos_lat * m.cos_lat)
    w_e = -m.vel_n / m.rm_h
    w_n = w * m.cos_lat + m.vel_e / m.rn_h
    w_u = w * m.sin_lat + m.vel_e * tan_lat / m.rn_h
    w2_u = 2.0 * w * m.sin_lat + m.vel_e * tan_lat / m.rn_h
    f = np.zeros((DYN, STATES))
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
    # ... - C [m_xz m_yz k_z]^T w_z
    c = np.asarray(c_np)
    f[PHI:PHI + 3, TAB:TAB + 3] = -c * w_p[2]
    # ... - C(:,0) (k_x w_x + m_xy w_y) - C(:,1) (m_yx w_x + k_y w_y)
    f[PHI:PHI + 3, LEV + 0] = -c[:, 0] * w_p[0]
    f[PHI:PHI + 3, LEV + 1] = -c[:, 1] * w_p[1]
    f[PHI:PHI + 3, LEV + 2] = -c[:, 0] * w_p[1]
    f[PHI:PHI + 3, LEV + 3] = -c[:, 1] * w_p[0]
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
    """Time update over the ticks gathered, by blocks (mirrors predict)."""
    if f.ticks == 0:
        return
    span = float(f.ticks) * f.prm.dt
    c_mean = 0.5 * (f.c_start + c_np)
    ft = system_matrix(m, f.dv_sum / span, c_mean, f.dtheta_sum / span) * span
    a_d, a_c = ft[:, :DYN], ft[:, DYN:]
    phi_d = a_d + 0.5 * (a_d @ a_d)
    phi_d[np.diag_indices(DYN)] += 1.0
    phi_c = a_c + 0.5 * (a_d @ a_c)
    x = f.x.copy()
    x[:DYN] = phi_d @ f.x[:DYN] + phi_c @ f.x[DYN:]
    f.x = x
    # P = [P_dd P_dc; P_cd P_cc] (the header gives the blocks)
    t = phi_d @ f.p[:DYN, :DYN] + phi_c @ f.p[DYN:, :DYN]
    n_dc = phi_d @ f.p[:DYN, DYN:] + phi_c @ f.p[DYN:, DYN:]
    n_dd = t @ phi_d.T + n_dc @ phi_c.T
    p = f.p.copy()
    p[:DYN, :DYN] = n_dd
    p[:DYN, DYN:] = n_dc
    p[DYN:, :DYN] = n_dc.T
    q_att = f.prm.gyro_arw * f.prm.gyro_arw * span
    q_vel = f.prm.accel_vrw * f.prm.accel_vrw * span
    for i in range(3):
        p[PHI + i, PHI + i] = p[PHI + i, PHI + i] + q_att
    for i in (VEL, VEL + 1):
        p[i, i] = p[i, i] + q_vel
    if f.prm.gyro_bias_rw > 0.0:
        q_eps = f.prm.gyro_bias_rw * f.prm.gyro_bias_rw * span
        for i in range(3):
            p[EPS + i, EPS + i] = p[EPS + i, EPS + i] + q_eps
    f.p = 0.5 * (p + p.T)
    f.dv_sum = np.zeros(3)
    f.dtheta_sum = np.zeros(3)
    f.c_start = np.array(c_np, dtype=float)
    f.ticks = 0
    if not diagonal_healthy(f.p):
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
    """Two scalar Joseph updates of rows k0, k0 + 1 (mirrors update_pair:
    A = P - K P(k,:), P' = A - A(:,k) K^T + r K K^T, its upper triangle
    mirrored)."""
    for c in range(2):
        k = k0 + c
        pk = f.p[:, k].copy()
        s = pk[k] + r[c]
        nu = z[c] - f.x[k]
        gain = pk / s
        f.x = f.x + gain * nu
        a = f.p - np.outer(gain, pk)
        aik = pk - gain * pk[k]
        full = a - np.outer(aik, gain) + r[c] * np.outer(gain, gain)
        # the upper triangle, mirrored (as the C++)
        f.p = np.triu(full) + np.triu(full, 1).T
    if not diagonal_healthy(f.p):
        f.healthy = 0


def reset_feedback(f):
    """The biases into the compensation, the state zeroed (mirrors reset_feedback)."""
    f.gyro_bias = f.gyro_bias + f.x[EPS:EPS + 3]
    f.accel_bias = f.accel_bias + np.array([f.x[NABLA], f.x[NABLA + 1], 0.0])
    f.table_err = f.table_err + f.x[TAB:TAB + 3]
    f.level_err = f.level_err + f.x[LEV:LEV + 4]
    f.x = np.zeros(STATES)
