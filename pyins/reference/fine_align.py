"""Static-base Kalman fine alignment, 8-state and reduced 5-state (seed 001).

Mirrors ``csrc/src/fine_align.{hpp,cpp}``; the header gives the model, the
state layouts, the typo corrections and the defaults.
"""
import math
from dataclasses import dataclass

import numpy as np

from pyins.units import ARCMIN_TO_RAD

from . import earth, kalman

# The state layouts (csrc/src/fine_align.hpp; seed 001 eqs. 11 and 21-24),
# which the output record's kf_x and kf_sigma hold in this order:
#   8-state X = [phi_E phi_N phi_U eps_E eps_N eps_U nabla_E nabla_N]
#   5-state X = [phi_E^ phi_N^ phi_U^ eps_N^ eps_U^]
PHI = slice(0, 3)        #: phi (both filters; the 5-state's transformed phi^)
EPS = slice(3, 6)        #: eps_E, eps_N, eps_U (8-state)
NABLA = slice(6, 8)      #: nabla_E, nabla_N (8-state)
EPS_NU = slice(3, 5)     #: eps_N^, eps_U^ (5-state)


@dataclass
class Params:
    sin_lat: float
    cos_lat: float
    gravity: float
    dt: float
    meas_every: int
    gyro_arw: float
    accel_vrw: float
    sigma0_att: np.ndarray
    sigma0_gyro: float
    sigma0_accel: float
    nis_window: int = 0
    nis_max: float = 0.0


@dataclass
class FineAlign:
    n: int
    x: np.ndarray
    p: np.ndarray
    phi: np.ndarray
    qd: np.ndarray
    h: np.ndarray
    r: np.ndarray
    dv_sum: np.ndarray
    meas_count: int
    meas_every: int
    meas_span: float
    healthy: bool
    consistent: bool = True
    nis_window: int = 0
    nis_max: float = 0.0
    nis_sum: float = 0.0
    nis_count: int = 0
    nis_mean: float = 0.0
    nis_windows: int = 0


def system_matrix(n, sin_lat, cos_lat):
    """F of seed 001 eq. 10 (n = 8) or eq. 23 (n = 5)."""
    w_n = earth.OMEGA_IE * cos_lat
    w_u = earth.OMEGA_IE * sin_lat
    f = np.zeros((n, n))
    f[0, 1] = w_u
    f[0, 2] = -w_n
    f[1, 0] = -w_u
    f[2, 0] = w_n
    if n == 8:
        f[0, 3] = -1.0
        f[1, 4] = -1.0
        f[2, 5] = -1.0
    else:
        f[1, 3] = -1.0
        f[2, 4] = -1.0
    return f


#: kAfterCoarseMargin, kAfterCoarseFloor [rad]
AFTER_COARSE_MARGIN = 3.0
AFTER_COARSE_FLOOR = 1.0 * ARCMIN_TO_RAD


def sigma0_after_coarse(prm, coarse_s, wander, cap):
    """Replace each prm.sigma0_att[i] that is 0 by the fit to a coarse
    alignment of coarse_s seconds that wandered by ``wander`` (sine); seed
    001 sec. 2's limits (csrc/src/fine_align.hpp gives the formula)."""
    w_n = earth.OMEGA_IE * prm.cos_lat
    lev_b = prm.sigma0_accel / prm.gravity      # seed 001 sec. 2: phi_E = -nabla_N / g, phi_N = nabla_E / g
    lev_n = prm.accel_vrw / prm.gravity
    level2 = lev_b * lev_b + lev_n * lev_n / coarse_s
    hd_b = prm.sigma0_gyro / w_n                # seed 001 sec. 2: phi_U = -eps_E / w_N + tan L nabla_E / g
    hd_l = prm.sin_lat / prm.cos_lat * lev_b
    hd_n = prm.gyro_arw / w_n
    head2 = hd_b * hd_b + hd_l * hd_l + hd_n * hd_n / coarse_s
    w2 = wander * wander
    fit = (AFTER_COARSE_MARGIN * math.sqrt(level2 + w2), AFTER_COARSE_MARGIN * math.sqrt(level2 + w2),
           AFTER_COARSE_MARGIN * math.sqrt(head2 + w2))
    for i in range(3):
        if prm.sigma0_att[i] == 0.0:
            v = fit[i]
            if not v >= AFTER_COARSE_FLOOR:     # also a NaN
                v = AFTER_COARSE_FLOOR
            if v > cap[i]:
                v = cap[i]
            prm.sigma0_att[i] = v


def init(n, prm):
    ft = system_matrix(n, prm.sin_lat, prm.cos_lat) * prm.dt
    phi = np.eye(n) + ft + 0.5 * (ft @ ft)
    qd = np.zeros((n, n))
    q_att = prm.gyro_arw * prm.gyro_arw * prm.dt
    qd[0, 0] = qd[1, 1] = qd[2, 2] = q_att
    g = prm.gravity
    h = np.zeros((2, n))
    h[0, 1] = -g
    h[1, 0] = g
    if n == 8:
        h[0, 6] = 1.0
        h[1, 7] = 1.0
    r_val = prm.accel_vrw * prm.accel_vrw / (float(prm.meas_every) * prm.dt)
    r = np.array([[r_val, 0.0], [0.0, r_val]])
    if n == 8:
        sigma = np.array([*prm.sigma0_att, prm.sigma0_gyro, prm.sigma0_gyro, prm.sigma0_gyro,
                          prm.sigma0_accel, prm.sigma0_accel])
    else:
        sigma = np.array([*prm.sigma0_att, prm.sigma0_gyro, prm.sigma0_gyro])
    p = np.diag(sigma * sigma)
    return FineAlign(n=n, x=np.zeros(n), p=p, phi=phi, qd=qd, h=h, r=r, dv_sum=np.zeros(3),
                     meas_count=0, meas_every=prm.meas_every,
                     meas_span=float(prm.meas_every) * prm.dt, healthy=True,
                     nis_window=prm.nis_window, nis_max=prm.nis_max)


def step(f, dv_sf_n):
    """Time update, and a measurement update every meas_every ticks."""
    f.x, f.p = kalman.predict(f.x, f.p, f.phi, f.qd)
    f.dv_sum = f.dv_sum + dv_sf_n
    f.meas_count = f.meas_count + 1
    updated = f.meas_count == f.meas_every
    if updated:
        z = np.array([f.dv_sum[0] / f.meas_span, f.dv_sum[1] / f.meas_span])
        f.x, f.p, nis = kalman.update2(f.x, f.p, f.h, z, f.r)
        f.dv_sum = np.zeros(3)
        f.meas_count = 0
        if f.nis_window > 0:
            f.nis_sum = f.nis_sum + nis
            f.nis_count = f.nis_count + 1
            if f.nis_count == f.nis_window:
                f.nis_mean = f.nis_sum / float(f.nis_window)
                f.nis_windows = f.nis_windows + 1
                f.consistent = f.consistent and f.nis_mean <= f.nis_max
                f.nis_sum = 0.0
                f.nis_count = 0
    f.healthy = f.healthy and kalman.diagonal_positive(f.p)
    return updated


def phi(f):
    return f.x[:3].copy()


def reset_phi(f):
    f.x[:3] = 0.0
