"""Inertial-frame coarse alignment (seed 000), for the IMU frame p.

Mirrors ``csrc/src/coarse_align.{hpp,cpp}``; the header explains the method,
the sign of eq. 5, the TRIAD construction that replaces eq. 8 (and eq. 8 as
printed, method EQ8), the lever-arm
velocity it removes, the moving-base method FIT and the method under way
FIT_VEL (the ship's motion taken out by GNSS velocity references). FIT_VEL's
grid: C++ holds v^ib0 in grid[0 .. kFitVelLen - 1] and the i side in
grid[kFitVelLen ..]; here ``grid`` and ``grid_i``, two lists of the same
length, capped at FIT_VEL_LEN points.
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
METHOD_FIT_VEL = 3     #: Method::kFitVel (PYINS_COARSE_FIT_VEL)
FIT_VEL_LEN = HIST_LEN // 2   #: kFitVelLen: FIT_VEL's grid capacity (points)
WANDER_SIGMAS = 4.0    #: kWanderSigmas: FIT_VEL's wander test, in its heading sigmas
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
    ref_gap_max: int = 0   #: FIT_VEL: the longest interval without a reference it trusts [ticks]
    rm_h: float = 0.0      #: FIT_VEL: R_M + h at the site [m]
    rn_h: float = 0.0      #: FIT_VEL: R_N + h at the site [m]


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
    # Under way (FIT_VEL; coarse_align.hpp, "Under way")
    grid_i: list = field(default_factory=lambda: [np.zeros(3)])   #: the i side on the grid points
    ref_done: int = 0        #: grid points whose i side is complete
    ref_count: int = 0       #: references taken (capped at 2^30)
    grid_from: int = 0       #: the first grid point at or after the first reference: the fit's first
    dlat: float = 0.0        #: the reference point's latitude since t0 [rad]
    dlon: float = 0.0        #: its longitude since t0 [rad]
    ref_vel: list = field(default_factory=lambda: [0.0, 0.0])   #: the last reference velocity (E, N)
    ref_tick: int = -1       #: its tick, counted as tick is (-1: none yet)
    ref_gap: int = 0         #: the longest interval without a reference so far [ticks]
    known_f: np.ndarray = field(default_factory=lambda: np.zeros(3))   #: g up^i + C_n^i (w_ie^n x v)
    known_v: np.ndarray = field(default_factory=lambda: np.zeros(3))   #: its integral, K [m/s]
    ref_cv: np.ndarray = field(default_factory=lambda: np.zeros(3))    #: C_n^i v at t_ref [m/s]
    ref_var: float = 0.0     #: sum of the references' horizontal variances [m^2/s^2]
    sigma_heading: float = 0.0   #: the latest solution's heading sigma [rad]
    settle_sigma: float = 0.0    #: sigma_heading of the wander test's first solution [rad]


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


def fit_sums(grid, grid_i, n, t_step, sin_lat, cos_lat, gravity):
    """FIT's weighted sums (mirrors fit_sums): the i side from grid_i, or by
    pos_i where grid_i is None."""
    k_end = n - 1
    inv_k = 1.0 / float(k_end)
    ia, ib, ba, bb = np.zeros(3), np.zeros(3), np.zeros(3), np.zeros(3)
    i0, i1, b0, b1 = np.zeros(3), np.zeros(3), np.zeros(3), np.zeros(3)
    a0 = a1 = c0 = c1 = s1 = s2 = 0.0
    for k in range(0, k_end + 1):
        s = float(k) * inv_k
        wa, wb = fit_weights(s)
        pi = grid_i[k] if grid_i is not None else pos_i(float(k) * t_step, sin_lat, cos_lat, gravity)
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


def solve_fit(grid, n, t_step, sin_lat, cos_lat, gravity):
    """C_ib0^i by FIT from P^ib0 on the grid points 0 .. n - 1 (mirrors
    solve_fit: the weights made exactly orthogonal to 1 and s on the grid)."""
    return fit_sums(grid, None, n, t_step, sin_lat, cos_lat, gravity)


def solve_vel_grid(grid, grid_i, n):
    """FIT_VEL: C_ib0^i from v^ib0 (grid) and the i side (grid_i) on the grid
    points 0 .. n - 1 by the Legendre weights s - 1/2 and s^2 - s + 1/6 made
    exact on the grid (mirrors solve_vel_grid)."""
    k_end = n - 1
    inv_k = 1.0 / float(k_end)
    ia, ib, ba, bb = np.zeros(3), np.zeros(3), np.zeros(3), np.zeros(3)
    i0, b0 = np.zeros(3), np.zeros(3)
    s1 = s2 = s3 = 0.0
    for k in range(0, k_end + 1):
        s = float(k) * inv_k
        ss = s * s
        vi = grid_i[k]
        vb = grid[k]
        ia = ia + s * vi
        ib = ib + ss * vi
        ba = ba + s * vb
        bb = bb + ss * vb
        i0 = i0 + vi
        b0 = b0 + vb
        s1 = s1 + s
        s2 = s2 + ss
        s3 = s3 + ss * s
    s0 = float(n)
    # psi_a = s - s1 / n; psi_b = s^2 - alpha - beta s, [n s1; s1 s2] [alpha; beta] = [s2; s3]
    mean_s = s1 / s0
    det = s0 * s2 - s1 * s1
    alpha = (s2 * s2 - s1 * s3) / det
    beta = (s0 * s3 - s1 * s2) / det
    ib = ib - alpha * i0 - beta * ia
    bb = bb - alpha * b0 - beta * ba
    ia = ia - mean_s * i0
    ba = ba - mean_s * b0
    # anchored on the gravity pair (psi_a), turned about it by the Earth-rate pair
    return solve_mat_i_ib0(ib, ia, bb, ba)


def heading_sigma(n, t_step, var, gravity, cos_lat):
    """FIT_VEL: the heading sigma of a solution on n grid points t_step [s]
    apart from references of mean variance var [m^2/s^2] [rad] (mirrors
    heading_sigma): sigma / sqrt(sum q_k^2) / (g cos L Omega / 2), q the
    grid's quadratic orthogonal to 1 and t."""
    s1 = s2 = s3 = s4 = 0.0
    for k in range(0, n):
        t = float(k) * t_step
        tt = t * t
        s1 = s1 + t
        s2 = s2 + tt
        s3 = s3 + tt * t
        s4 = s4 + tt * tt
    s0 = float(n)
    det = s0 * s2 - s1 * s1
    alpha = (s2 * s2 - s1 * s3) / det
    beta = (s0 * s3 - s1 * s2) / det
    # sum q^2 = sum q t^2 (q is orthogonal to 1 and t) = s4 - alpha s2 - beta s3
    qq = s4 - alpha * s2 - beta * s3
    return math.sqrt(var / qq) / (0.5 * gravity * cos_lat * earth.OMEGA_IE)


def mat_n_e(sin_lat, cos_lat):
    """C_e^n, e's x axis on the site meridian (seed 000 eq. 2)."""
    return np.array([[0.0, 1.0, 0.0], [-sin_lat, 0.0, cos_lat], [cos_lat, 0.0, sin_lat]])


def mat_n_e_at(sin_lat, cos_lat, sin_dlon, cos_dlon):
    """FIT_VEL: C_e^n at the reference point (rows E, N, U in e; dlon from the
    site meridian): mat_n_e's rows turned by dlon about z (mirrors mat_n_e_at)."""
    return np.array([[-sin_dlon, cos_dlon, 0.0],
                     [-sin_lat * cos_dlon, -sin_lat * sin_dlon, cos_lat],
                     [cos_lat * cos_dlon, cos_lat * sin_dlon, sin_lat]])


def e_to_i(t, x):
    """C_e^i(t) x = Rz(w t) x (mirrors e_to_i)."""
    s = math.sin(earth.OMEGA_IE * t)
    c = math.cos(earth.OMEGA_IE * t)
    return np.array([c * x[0] - s * x[1], s * x[0] + c * x[1], x[2]])


def n_to_e(sin_lat, cos_lat, sin_dlon, cos_dlon, xe, xn, xu):
    """C_n^e x for n at (lat, dlon): x_E E + x_N N + x_U U (mirrors n_to_e)."""
    return np.array([-sin_dlon * xe - sin_lat * cos_dlon * xn + cos_lat * cos_dlon * xu,
                     cos_dlon * xe - sin_lat * sin_dlon * xn + cos_lat * sin_dlon * xu,
                     cos_lat * xn + sin_lat * xu])


def known_force_i(t, sin_lat, cos_lat, sin_dlon, cos_dlon, gravity, ve, vn):
    """FIT_VEL: g up^i + C_n^i (w_ie^n x v) at time t for the reference point at
    (lat, dlon) moving at v (E, N) [m/s^2] (mirrors known_force_i)."""
    w = earth.OMEGA_IE
    ce = -w * sin_lat * vn
    cn = w * sin_lat * ve
    cu = -w * cos_lat * ve + gravity
    return e_to_i(t, n_to_e(sin_lat, cos_lat, sin_dlon, cos_dlon, ce, cn, cu))


def ref_vel_i(t, sin_lat, cos_lat, sin_dlon, cos_dlon, ve, vn, vu):
    """FIT_VEL: C_n^i v at time t, v = (ve, vn, vu) [m/s] (mirrors ref_vel_i)."""
    return e_to_i(t, n_to_e(sin_lat, cos_lat, sin_dlon, cos_dlon, ve, vn, vu))


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
    a = CoarseAlign(prm=prm)
    a.grid_every = prm.output_every
    a.known_f = known_force_i(0.0, prm.sin_lat, prm.cos_lat, 0.0, 1.0, prm.gravity, 0.0, 0.0)
    return a


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
        a.settle_sigma = a.sigma_heading
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


def ship_sincos(a):
    """FIT_VEL: sin, cos of the reference point's latitude and of dlon now
    (mirrors ship_sincos)."""
    sd = math.sin(a.dlat)
    cd = math.cos(a.dlat)
    sin_lat = a.prm.sin_lat * cd + a.prm.cos_lat * sd
    cos_lat = a.prm.cos_lat * cd - a.prm.sin_lat * sd
    return sin_lat, cos_lat, math.sin(a.dlon), math.cos(a.dlon)


def carry_known(a):
    """FIT_VEL, once a tick after a.tick advanced: the reference point carried
    by the last reference velocity, and K by the trapezoid rule (mirrors carry_known)."""
    dt = a.prm.dt
    sl, cl, sd, cd = ship_sincos(a)
    a.dlat = a.dlat + a.ref_vel[1] * dt / a.prm.rm_h
    a.dlon = a.dlon + a.ref_vel[0] * dt / (a.prm.rn_h * cl)
    sl, cl, sd, cd = ship_sincos(a)
    t = float(a.tick) * dt
    f = known_force_i(t, sl, cl, sd, cd, a.prm.gravity, a.ref_vel[0], a.ref_vel[1])
    a.known_v = a.known_v + (0.5 * dt) * (a.known_f + f)
    a.known_f = f


def reference(a, ve, vn, vu, sigma, ref_tick):
    """FIT_VEL: take a reference velocity (E, N, U; U 0 where not measured) [m/s] with its sigma [m/s],
    valid at alignment tick ref_tick (a.tick or earlier; one not newer than
    the last is ignored): completes the grid points it covers (mirrors reference)."""
    if ref_tick < 0 or ref_tick > a.tick or (a.ref_tick >= 0 and ref_tick <= a.ref_tick):
        return   # before the alignment, ahead of it, or not newer than the last: not taken
    dt = a.prm.dt
    sl, cl, sd, cd = ship_sincos(a)
    cv = ref_vel_i(float(ref_tick) * dt, sl, cl, sd, cd, ve, vn, vu)
    # the previous epoch: the last reference, or t0 with this velocity
    first = a.ref_tick < 0
    if first:
        # the points before it are left out of the fit
        a.grid_from = (ref_tick + a.grid_every - 1) // a.grid_every
    t_prev = 0 if first else a.ref_tick
    cv_prev = cv if first else a.ref_cv
    gap = ref_tick - t_prev
    if gap > a.ref_gap:
        a.ref_gap = gap
    # the grid points in (t_prev, ref_tick]: the velocity linear in between
    while a.ref_done < len(a.grid) and a.ref_done * a.grid_every <= ref_tick:
        u = a.ref_done * a.grid_every - t_prev
        frac = float(u) / float(gap) if gap > 0 else 0.0
        a.grid_i[a.ref_done] = a.grid_i[a.ref_done] + cv_prev + frac * (cv - cv_prev)
        a.ref_done = a.ref_done + 1
    a.ref_vel = [float(ve), float(vn)]
    a.ref_tick = ref_tick
    a.ref_cv = cv
    a.ref_var = a.ref_var + sigma * sigma
    if a.ref_count < (1 << 30):
        a.ref_count = a.ref_count + 1


def update(a, dtheta_p, dv_p, lever_vel_p=None, ref_lever_p=None):
    """Take one sample; solve C_ib0^i at the output ticks (mirrors update).

    lever_vel_p: u^p at the end of the tick [m/s] (read only with prm.lever);
    ref_lever_p: the reference's antenna's velocity from the reference point
    in p, (w_ip^p - alpha' z) x C_b^p l^b [m/s] (read only by FIT_VEL).
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
    fit_vel = a.prm.method == METHOD_FIT_VEL
    fit = a.prm.method == METHOD_FIT or fit_vel
    if fit_vel:
        carry_known(a)
        if a.tick == 1:
            # t0's ib0 side: v^ib0(t0) = 0 less the accelerometers' lever
            # velocity plus the antenna's (mirrors update)
            a.grid[0] = ref_lever_p - lever_vel_p if a.prm.lever != 0 else np.array(ref_lever_p, dtype=float)
    if fit and not fit_vel:
        a.pos_ib0 = a.pos_ib0 + (0.5 * a.prm.dt) * (a.vel_prev + vel)
        a.vel_prev = vel.copy()

    every = a.prm.output_every
    if a.grid_every == 0:
        a.grid_every = every
    cap = FIT_VEL_LEN if fit_vel else HIST_LEN
    if fit and a.tick % a.grid_every == 0 and len(a.grid) == cap:
        # full: every other point at twice the spacing (mirrors update)
        a.grid = a.grid[0:cap:2]
        if fit_vel:
            a.grid_i = a.grid_i[0:cap:2]
            a.ref_done = (a.ref_done + 1) // 2   # point k was 2k: complete if 2k < ref_done
            a.grid_from = (a.grid_from + 1) // 2  # and in the fit if 2k >= grid_from
        a.grid_every = 2 * a.grid_every
    if a.tick % a.grid_every == 0 and len(a.grid) < cap:
        if fit_vel:
            # the antenna's lever on the ib0 side; K now, the reference's integral to come
            a.grid.append(vel + attitude.quat_to_mat(a.quat_ib0_p) @ ref_lever_p)
            a.grid_i.append(a.known_v.copy())
        else:
            a.grid.append(a.pos_ib0.copy() if fit else vel.copy())
    if a.tick >= a.prm.first_output and (a.tick - a.prm.first_output) % every == 0:
        if fit_vel:
            # the grid points a reference has completed (a reference interval behind)
            n_fit = a.ref_done - a.grid_from
            if n_fit > FIT_MIN_INTERVALS:
                a.mat_i_ib0 = solve_vel_grid(a.grid[a.grid_from:], a.grid_i[a.grid_from:], n_fit)
                a.sigma_heading = heading_sigma(n_fit, float(a.grid_every) * a.prm.dt,
                                                a.ref_var / float(a.ref_count), a.prm.gravity,
                                                a.prm.cos_lat)
                a.solved = True
                settle(a)
            return
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
    """C_p^n now (seed 000 eq. 1; FIT_VEL: with n at the reference point now);
    for EQ8 the rotation of the Euler angles read off the product (mirrors
    mat_n_p). Precondition: a.solved."""
    t = float(a.tick) * a.prm.dt
    n_e = mat_n_e(a.prm.sin_lat, a.prm.cos_lat)
    if a.prm.method == METHOD_FIT_VEL:
        n_e = mat_n_e_at(*ship_sincos(a))
    m = n_e @ mat_e_i(t) @ a.mat_i_ib0 @ attitude.quat_to_mat(a.quat_ib0_p)
    if a.prm.method == METHOD_EQ8:
        # seed 000: eq. 8's matrix into eq. 1, the attitude angles read off its elements
        return attitude.euler_to_mat(attitude.mat_to_euler(m))
    return m
