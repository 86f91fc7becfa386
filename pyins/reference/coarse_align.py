"""Inertial-frame coarse alignment (seed 000), for the IMU frame p.

Mirrors ``csrc/src/coarse_align.{hpp,cpp}``; the header explains the method,
the sign of eq. 5 and the TRIAD construction that replaces eq. 8.
"""
from dataclasses import dataclass, field

import numpy as np

from . import attitude, earth, strapdown
from .attitude import cross

HIST_LEN = 256  #: kHistLen


@dataclass
class Params:
    ratio: float
    first_output: int
    output_every: int
    dt: float
    sin_lat: float
    cos_lat: float
    gravity: float


@dataclass
class CoarseAlign:
    prm: Params
    quat_ib0_p: np.ndarray = field(default_factory=lambda: np.array([1.0, 0.0, 0.0, 0.0]))
    vel_ib0: np.ndarray = field(default_factory=lambda: np.zeros(3))
    hist: strapdown.History = field(default_factory=strapdown.History)
    tick: int = 0
    hist_vel: list = field(default_factory=lambda: [np.zeros(3)])
    mat_i_ib0: np.ndarray = field(default_factory=lambda: np.eye(3))
    solved: bool = False


def vel_i(t, sin_lat, cos_lat, gravity):
    """v^i(t), seed 000 eq. 5 in specific-force form (coarse_align.hpp)."""
    w = earth.OMEGA_IE
    s = np.sin(w * t)
    s_half = np.sin(0.5 * w * t)
    one_minus_cos = 2.0 * s_half * s_half
    return np.array([gravity * cos_lat * s / w, gravity * cos_lat * one_minus_cos / w,
                     gravity * sin_lat * t])


def triad(u, w):
    """[a1 a2 a3]: a1 = u/|u|, a2 = (w x u)/|w x u|, a3 = a1 x a2."""
    a1 = u / np.sqrt(u @ u)
    wu = cross(w, u)
    a2 = wu / np.sqrt(wu @ wu)
    a3 = cross(a1, a2)
    return np.column_stack([a1, a2, a3])


def solve_mat_i_ib0(vi1, vi2, vb1, vb2):
    """C_ib0^i from the pairs at t_k1 (1) and t_k2 (2), anchored on t_k2."""
    ti = triad(vi2, vi1)
    tb = triad(vb2, vb1)
    return ti @ tb.T


def mat_n_e(sin_lat, cos_lat):
    """C_e^n, e's x axis on the site meridian (seed 000 eq. 2)."""
    return np.array([[0.0, 1.0, 0.0], [-sin_lat, 0.0, cos_lat], [cos_lat, 0.0, sin_lat]])


def mat_e_i(t):
    """C_i^e(t) = Rz(w t)^T (seed 000 eq. 2)."""
    s = np.sin(earth.OMEGA_IE * t)
    c = np.cos(earth.OMEGA_IE * t)
    return np.array([[c, s, 0.0], [-s, c, 0.0], [0.0, 0.0, 1.0]])


def init(prm):
    return CoarseAlign(prm=prm)


def update(a, dtheta_p, dv_p):
    """Take one sample; solve C_ib0^i at the output ticks (mirrors update)."""
    phi, dv_comp = strapdown.compensate(dtheta_p, dv_p, a.hist)
    a.vel_ib0 = a.vel_ib0 + attitude.quat_to_mat(a.quat_ib0_p) @ dv_comp
    a.quat_ib0_p = attitude.quat_normalize(
        attitude.quat_mul(a.quat_ib0_p, attitude.rotvec_to_quat(phi)))
    strapdown.push_history(a.hist, dtheta_p, dv_p)
    a.tick = a.tick + 1

    every = a.prm.output_every
    if a.tick % every == 0 and len(a.hist_vel) < HIST_LEN:
        a.hist_vel.append(a.vel_ib0.copy())
    if a.tick >= a.prm.first_output and (a.tick - a.prm.first_output) % every == 0:
        k1 = int(a.prm.ratio * float(a.tick) / float(every) + 0.5)
        k1 = min(k1, (a.tick - 1) // every)
        k1 = max(k1, 1)
        t1 = float(k1 * every) * a.prm.dt
        t2 = float(a.tick) * a.prm.dt
        vi1 = vel_i(t1, a.prm.sin_lat, a.prm.cos_lat, a.prm.gravity)
        vi2 = vel_i(t2, a.prm.sin_lat, a.prm.cos_lat, a.prm.gravity)
        a.mat_i_ib0 = solve_mat_i_ib0(vi1, vi2, a.hist_vel[k1], a.vel_ib0)
        a.solved = True


def mat_n_p(a):
    """C_p^n now (seed 000 eq. 1). Precondition: a.solved."""
    t = float(a.tick) * a.prm.dt
    return (mat_n_e(a.prm.sin_lat, a.prm.cos_lat) @ mat_e_i(t) @ a.mat_i_ib0
            @ attitude.quat_to_mat(a.quat_ib0_p))
