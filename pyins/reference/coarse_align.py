"""Inertial-frame coarse alignment (seed 000), for the IMU frame p.

Mirrors ``csrc/src/coarse_align.{hpp,cpp}``; the header explains the method,
the sign of eq. 5, the TRIAD construction that replaces eq. 8 (and eq. 8 as
printed, method EQ8), the lever-arm
velocity it removes and the moving-base method FIT.
"""
import math
from dataclasses import dataclass, field

import numpy as np

from . import attitude, earth, strapdown
from .attitude import cross

HIST_LEN = 256  #: kHistLen
METHOD_TRIAD = 0       #: Method::kTriad (PYINS_COARSE_TRIAD)
METHOD_FIT = 1         #: Method::kFit (PYINS_COARSE_FIT)
METHOD_EQ8 = 2         #: Method::kEq8 (PYINS_COARSE_EQ8)
FIT_MIN_INTERVALS = 8  #: kFitMinIntervals


@dataclass
class Params:
    method: int
    lever: int
    ratio: float
    first_output: int
    output_every: int
    dt: float
    sin_lat: float
    cos_lat: float
    gravity: float
    settle_from: int = 0
    noise_every: int = 0


NOISE_MIN_SAMPLES = 50   #: kNoiseMinSamples


@dataclass
class CoarseAlign:
    prm: Params
    quat_ib0_p: np.ndarray = field(default_factory=lambda: np.array([1.0, 0.0, 0.0, 0.0]))
    vel_ib0: np.ndarray = field(default_factory=lambda: np.zeros(3))
    hist: strapdown.History = field(default_factory=strapdown.History)
    tick: int = 0
    vel_prev: np.ndarray = field(default_factory=lambda: np.zeros(3))
    pos_ib0: np.ndarray = field(default_factory=lambda: np.zeros(3))
    lever_vel0: np.ndarray = field(default_factory=lambda: np.zeros(3))
    grid: list = field(default_factory=lambda: [np.zeros(3)])
    grid_every: int = 0   #: set to prm.output_every at the first update
    mat_i_ib0: np.ndarray = field(default_factory=lambda: np.eye(3))
    solved: bool = False
    settling: bool = False
    settle_ref: np.ndarray = field(default_factory=lambda: np.eye(3))
    wander: float = 0.0
    noise_v: list = field(default_factory=lambda: [np.zeros(3), np.zeros(3), np.zeros(3)])
    noise_seen: int = 0
    noise_sum: float = 0.0
    noise_n: int = 0


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


def solve_eq8(vi1, vi2, vb1, vb2):
    """C_ib0^i by seed 000 eq. 8 as printed, A^-1 B, not orthonormalised
    (mirrors solve_eq8: A^-1 as its adjugate over the determinant)."""
    a3 = cross(vi1, vi2)
    c1 = cross(vi2, a3)
    c2 = cross(a3, vi1)
    # sums of three written out as Eigen's unrolled redux adds them, a0 + (a1 + a2)
    # (NumPy's @ rounds differently): bit-identical
    det = vi1[0] * c1[0] + (vi1[1] * c1[1] + vi1[2] * c1[2])
    inv = np.column_stack([c1 / det, c2 / det, a3 / det])
    b = np.vstack([vb1, vb2, cross(vb1, vb2)])
    return np.array([[inv[i, 0] * b[0, j] + (inv[i, 1] * b[1, j] + inv[i, 2] * b[2, j])
                      for j in range(3)] for i in range(3)])


def pos_i(t, sin_lat, cos_lat, gravity):
    """P^i(t) = integral of v^i, by the series of (1 - cos x) / x^2 and (x - sin x) / x^3."""
    x = earth.OMEGA_IE * t
    x2 = x * x
    c2 = 0.5 - x2 * (1.0 / 24.0 - x2 * (1.0 / 720.0 - x2 * (1.0 / 40320.0 - x2 / 3628800.0)))
    s3 = 1.0 / 6.0 - x2 * (1.0 / 120.0 - x2 * (1.0 / 5040.0 - x2 * (1.0 / 362880.0 - x2 / 39916800.0)))
    gt2 = gravity * t * t
    return np.array([cos_lat * gt2 * c2, cos_lat * gt2 * x * s3, sin_lat * 0.5 * gt2])


def fit_weights(s):
    """phi_a(s), phi_b(s) of FIT (coarse_align.hpp; tools/derive_coarse_fit.py)."""
    u = s * (1.0 - s)
    w = u * u
    phi_a = w * (45360.0 + s * (-350280.0 + s * (766080.0 - 498960.0 * s)))
    phi_b = w * (-27720.0 + s * (221760.0 + s * (-498960.0 + 332640.0 * s)))
    return phi_a, phi_b


def solve_fit(grid, n, t_step, sin_lat, cos_lat, gravity):
    """C_ib0^i by FIT from P^ib0 on the grid points 0 .. n - 1 (mirrors
    solve_fit: the weights made exactly orthogonal to 1 and s on the grid)."""
    k_end = n - 1
    inv_k = 1.0 / float(k_end)
    ia, ib, ba, bb = np.zeros(3), np.zeros(3), np.zeros(3), np.zeros(3)
    i0, i1, b0, b1 = np.zeros(3), np.zeros(3), np.zeros(3), np.zeros(3)
    a0 = a1 = c0 = c1 = s1 = s2 = 0.0
    for k in range(0, k_end + 1):
        s = float(k) * inv_k
        wa, wb = fit_weights(s)
        pi = pos_i(float(k) * t_step, sin_lat, cos_lat, gravity)
        pb = grid[k]
        ia = ia + wa * pi
        ib = ib + wb * pi
        ba = ba + wa * pb
        bb = bb + wb * pb
        i0 = i0 + pi
        i1 = i1 + s * pi
        b0 = b0 + pb
        b1 = b1 + s * pb
        a0 = a0 + wa
        a1 = a1 + wa * s
        c0 = c0 + wb
        c1 = c1 + wb * s
        s1 = s1 + s
        s2 = s2 + s * s
    s0 = float(n)
    det = s0 * s2 - s1 * s1
    alpha_a = (s2 * a0 - s1 * a1) / det
    beta_a = (s0 * a1 - s1 * a0) / det
    alpha_b = (s2 * c0 - s1 * c1) / det
    beta_b = (s0 * c1 - s1 * c0) / det
    ia = ia - alpha_a * i0 - beta_a * i1
    ib = ib - alpha_b * i0 - beta_b * i1
    ba = ba - alpha_a * b0 - beta_a * b1
    bb = bb - alpha_b * b0 - beta_b * b1
    return solve_mat_i_ib0(ib, ia, bb, ba)


def mat_n_e(sin_lat, cos_lat):
    """C_e^n, e's x axis on the site meridian (seed 000 eq. 2)."""
    return np.array([[0.0, 1.0, 0.0], [-sin_lat, 0.0, cos_lat], [cos_lat, 0.0, sin_lat]])


def mat_e_i(t):
    """C_i^e(t) = Rz(w t)^T (seed 000 eq. 2)."""
    s = np.sin(earth.OMEGA_IE * t)
    c = np.cos(earth.OMEGA_IE * t)
    return np.array([[c, s, 0.0], [-s, c, 0.0], [0.0, 0.0, 1.0]])


def rotation_sine(a, b):
    """Sine of the rotation angle between two rotation matrices, 1 beyond 90 deg."""
    r = a.T @ b
    if r[0, 0] + r[1, 1] + r[2, 2] < 1.0:
        return 1.0
    x = 0.5 * (r[2, 1] - r[1, 2])
    y = 0.5 * (r[0, 2] - r[2, 0])
    z = 0.5 * (r[1, 0] - r[0, 1])
    return float(np.sqrt(x * x + y * y + z * z))


def init(prm):
    return CoarseAlign(prm=prm)


def measured_vrw(a):
    """The horizontal specific-force noise density measured so far
    [(m/s)/sqrt(s)]; 0 before NOISE_MIN_SAMPLES (mirrors measured_vrw)."""
    if a.noise_n < NOISE_MIN_SAMPLES:
        return 0.0
    tau = float(a.prm.noise_every) * a.prm.dt
    return math.sqrt(tau / 6.0 * (a.noise_sum / float(a.noise_n)) / 2.0)


def settle(a):
    """The wander test on a new solution (mirrors settle)."""
    if a.tick < a.prm.settle_from:
        return
    if not a.settling:
        a.settling = True
        a.settle_ref = a.mat_i_ib0.copy()
        return
    s = rotation_sine(a.settle_ref, a.mat_i_ib0)
    if s > a.wander:
        a.wander = s


def measure_noise(a, v):
    """One block end of the noise measurement (mirrors measure_noise): the
    second difference of the block means of the specific force, horizontal."""
    if a.noise_seen == 3:
        tau = float(a.prm.noise_every) * a.prm.dt
        d = (v - 3.0 * a.noise_v[0] + 3.0 * a.noise_v[1] - a.noise_v[2]) / tau
        vv = float(v @ v)
        if vv > 0.0:
            up = float(d @ v)
            a.noise_sum = a.noise_sum + (float(d @ d) - up * up / vv)
            a.noise_n = a.noise_n + 1
    else:
        a.noise_seen = a.noise_seen + 1
    a.noise_v = [np.array(v, dtype=float), a.noise_v[0], a.noise_v[1]]


def update(a, dtheta_p, dv_p, lever_vel_p=None):
    """Take one sample; solve C_ib0^i at the output ticks (mirrors update).

    lever_vel_p: u^p at the end of the tick [m/s] (read only with prm.lever).
    """
    c = strapdown.compensate(dtheta_p, dv_p, a.hist)
    phi, dv_comp = c.phi, c.dv_p
    a.vel_ib0 = a.vel_ib0 + attitude.quat_to_mat(a.quat_ib0_p) @ dv_comp
    a.quat_ib0_p = attitude.quat_renormalize(
        attitude.quat_mul(a.quat_ib0_p, attitude.rotvec_to_quat(phi)))
    strapdown.push_history(a.hist, dtheta_p, dv_p, c)
    a.tick = a.tick + 1

    vel = a.vel_ib0
    if a.prm.lever != 0:
        vel = vel - attitude.quat_to_mat(a.quat_ib0_p) @ lever_vel_p
        if a.tick == 1:
            a.lever_vel0 = np.array(lever_vel_p, dtype=float)
    if a.prm.noise_every > 0 and a.tick % a.prm.noise_every == 0:
        measure_noise(a, vel)
    fit = a.prm.method == METHOD_FIT
    if fit:
        a.pos_ib0 = a.pos_ib0 + (0.5 * a.prm.dt) * (a.vel_prev + vel)
        a.vel_prev = vel.copy()

    every = a.prm.output_every
    if a.grid_every == 0:
        a.grid_every = every
    if fit and a.tick % a.grid_every == 0 and len(a.grid) == HIST_LEN:
        # full: every other point at twice the spacing (mirrors update)
        a.grid = a.grid[0:HIST_LEN:2]
        a.grid_every = 2 * a.grid_every
    if a.tick % a.grid_every == 0 and len(a.grid) < HIST_LEN:
        a.grid.append(a.pos_ib0.copy() if fit else vel.copy())
    if a.tick >= a.prm.first_output and (a.tick - a.prm.first_output) % every == 0:
        if fit:
            a.mat_i_ib0 = solve_fit(a.grid, len(a.grid), float(a.grid_every) * a.prm.dt,
                                    a.prm.sin_lat, a.prm.cos_lat, a.prm.gravity)
            a.solved = True
            settle(a)
            return
        k1 = int(a.prm.ratio * float(a.tick) / float(every) + 0.5)
        k1 = min(k1, (a.tick - 1) // every)
        k1 = max(k1, 1)
        t1 = float(k1 * every) * a.prm.dt
        t2 = float(a.tick) * a.prm.dt
        vi1 = vel_i(t1, a.prm.sin_lat, a.prm.cos_lat, a.prm.gravity)
        vi2 = vel_i(t2, a.prm.sin_lat, a.prm.cos_lat, a.prm.gravity)
        vb1 = a.grid[k1]
        vb2 = vel
        if a.prm.lever != 0:
            vb1 = vb1 + a.lever_vel0
            vb2 = vb2 + a.lever_vel0
        if a.prm.method == METHOD_EQ8:
            a.mat_i_ib0 = solve_eq8(vi1, vi2, vb1, vb2)   # seed 000 eq. 8 as printed
        else:
            a.mat_i_ib0 = solve_mat_i_ib0(vi1, vi2, vb1, vb2)
        a.solved = True
        settle(a)


def mat_n_p(a):
    """C_p^n now (seed 000 eq. 1); for EQ8 the rotation of the Euler angles read
    off the product (mirrors mat_n_p). Precondition: a.solved."""
    t = float(a.tick) * a.prm.dt
    m = (mat_n_e(a.prm.sin_lat, a.prm.cos_lat) @ mat_e_i(t) @ a.mat_i_ib0
         @ attitude.quat_to_mat(a.quat_ib0_p))
    if a.prm.method == METHOD_EQ8:
        # seed 000: eq. 8's matrix into eq. 1, the attitude angles read off its elements
        return attitude.euler_to_mat(attitude.mat_to_euler(m))
    return m
