"""Error analysis: the theoretical limits of static-base alignment.

Seed 001 (Yan Gongmin, Qin Yongyuan 2006), sec. 3.2 and eq. 21: on a static
base three combinations are unobservable, so even a perfect filter leaves

    phi_N = nabla_E / g,          phi_E = -nabla_N / g,
    phi_U = -eps_E / w_N + tan(L) nabla_E / g,
    eps_N: (nabla_N / g) w_U,     eps_U: -(nabla_N / g) w_N     (true - estimate)

with w_N = W cos L, w_U = W sin L and nabla, eps the n-frame projections of
the body-frame accelerometer biases and gyro drifts. The 8-state filter
cannot estimate eps_E, nabla_E, nabla_N at all (their limit is their own
value); the reduced 5-state filter estimates the transformed states of eq. 21
exactly in the limit, i.e. ``reduced_truth`` below.

The rest is error theory too, of a ship at a fixed position: the linear
error model of a static INS (`static_error_model`, `predict_static_fil`),
the share of a constant drift a rotating IMU leaves (`drift_surviving` and
its history), the table angle between records (`table_history`) and the
linear error equations stepped from record to record (`error_matrix`,
`propagate_errors`, `noise_covariance`). The error budget of a run, which
drives them with the run's history and checks itself against the firmware
in the loop, is `pyins.budget`. This room sits low: it imports the
reference's attitude and Earth model only, so `pyins.metrics` can use it.
"""
from dataclasses import dataclass

import numpy as np

from pyins.reference import attitude, earth


@dataclass
class AlignmentLimits:
    """Limits as true minus estimate (attitude: phi in n, C' = (I - phi x) C)."""
    phi_n: np.ndarray          #: [phi_E, phi_N, phi_U] [rad]
    eps_n_limit: np.ndarray    #: [eps_E, eps_N, eps_U] limit [rad/s]; eps_E: its own value
    nabla_n: np.ndarray        #: [nabla_E, nabla_N] [m/s^2], never estimated (8-state)
    eps_n: np.ndarray          #: the drifts projected into n [rad/s]


def alignment_limits(lat, euler_b, gyro_bias_b, accel_bias_b, height=0.0):
    """Theoretical limiting accuracies for a static IMU at ``euler_b``.

    ``gyro_bias_b`` [rad/s] and ``accel_bias_b`` [m/s^2] are in the IMU frame.
    """
    mat_nb = attitude.euler_to_mat(np.asarray(euler_b, dtype=float))
    nabla = mat_nb @ np.asarray(accel_bias_b, dtype=float)
    eps = mat_nb @ np.asarray(gyro_bias_b, dtype=float)
    g = earth.normal_gravity(np.sin(lat), height)
    w_n = earth.OMEGA_IE * np.cos(lat)
    w_u = earth.OMEGA_IE * np.sin(lat)
    phi = np.array([-nabla[1] / g, nabla[0] / g, -eps[0] / w_n + np.tan(lat) * nabla[0] / g])
    eps_lim = np.array([eps[0], nabla[1] / g * w_u, -nabla[1] / g * w_n])
    return AlignmentLimits(phi_n=phi, eps_n_limit=eps_lim, nabla_n=nabla[:2], eps_n=eps)


def reduced_truth(limits, phi_true=np.zeros(3)):
    """True values of the 5 transformed states of seed 001 eq. 21, for an
    attitude error ``phi_true`` [rad] (with feedback: the residual error).

    [phi_E + nabla_N/g, phi_N - nabla_E/g, phi_U + eps_E/w_N - tanL nabla_E/g,
     eps_N - (nabla_N/g) w_U, eps_U + (nabla_N/g) w_N]
    = [phi - phi_limit, eps_N - eps_N_limit, eps_U - eps_U_limit].
    """
    phi_hat = np.asarray(phi_true, dtype=float) - limits.phi_n
    eps_hat = limits.eps_n[1:] - limits.eps_n_limit[1:]
    return np.concatenate([phi_hat, eps_hat])


def swing_cubic(radius, period, swing, window, phases=72, points=400):
    """The largest t^3 coefficient [m/s^3] a swing at anchor puts into a
    window of ``window`` seconds, over the swing's phase at the window's
    start: the reference point on the chain's circle (`pyins.sim.ship.
    anchor_linear`: radius [m], period [s], half angle ``swing`` [rad]),
    its horizontal displacement fitted by least squares with a cubic in
    time, the cubic term's norm. The moving-base filter reads heading from
    that term (csrc/src/moving_align.hpp: p_N = -(1/6) g W cos L phi_U
    t^3), so a swing whose cubic is c looks like a heading error of
    6 c / (g W cos L). For a window well inside a period it is the
    displacement's third derivative / 6 (Taylor; r swing w^3 / 6 at most,
    w = 2 pi / period); once the window holds a few periods it falls as
    window^-3."""
    t = np.linspace(0.0, window, points)
    basis = np.vander(t / window, 4, increasing=True)
    pinv = np.linalg.pinv(basis)[3] / window ** 3
    ph = np.linspace(0.0, 2.0 * np.pi, phases, endpoint=False)
    theta = swing * np.sin(2.0 * np.pi * t / period + ph[:, None])      # (phases, points)
    c_e = (-radius * np.sin(theta)) @ pinv
    c_n = (radius * (1.0 - np.cos(theta))) @ pinv
    return float(np.max(np.hypot(c_e, c_n)))


def site_accel_for_swing(radius, period, swing, longest=None):
    """The site-motion density q [m/s^2/sqrt(Hz)] (the firmware's
    ``fine_site_accel``) under which the moving-base filter's heading sigma
    covers a swing at anchor of ``radius`` [m], ``period`` [s] and half
    angle ``swing`` [rad] at every alignment length up to ``longest`` [s]
    (default three periods).

    Told q, the filter takes the site's displacement as an integrated
    random walk, whose t^3 coefficient over a window T has the sigma
    q / sqrt(3 T^3) (csrc/src/moving_align.hpp: the Fisher information 3
    k^2 T^3 / q^2 of the heading, k = g W cos L / 6). The swing's own
    cubic (`swing_cubic`) is c(T), so q = max over T of c(T) sqrt(3 T^3)
    makes the site's share of the heading sigma at least the heading the
    swing can fake at every T: the filter's sigma, and with it ATT_VALID,
    then holds for every swing up to this one (any phase, any heading of
    the ship). The maximum lies near T = period. A bound of the anchorage
    (the chain's radius, the fastest swing, the widest angle) gives the
    q to configure; a smaller swing is covered by it.
    """
    longest = 3.0 * period if longest is None else float(longest)
    windows = np.geomspace(10.0, longest, 120)
    return max(swing_cubic(radius, period, swing, w) * np.sqrt(3.0 * w ** 3) for w in windows)


# ---------------------------------------------------------------------------
# Linear error model of a static INS (an error-budget tool)
# ---------------------------------------------------------------------------
@dataclass
class StaticErrors:
    """Errors predicted by the linear model at the times asked for."""
    time_s: np.ndarray
    att_n_rad: np.ndarray    #: phi (E, N, U), (N, 3), same sign as metrics.NavErrors
    vel_n_mps: np.ndarray    #: (N, 2) east, north
    north_m: np.ndarray
    east_m: np.ndarray
    horizontal_m: np.ndarray


def static_error_model(lat, times_s, eps_n, nabla_n=None, height=0.0, step_s=0.5):
    """Propagate the linear phi-angle error equations of a static INS.

    Qin Yongyuan, "Inertial Navigation" (2014), sec. 4.2 (ENU, psi = 0 ship
    at rest, vertical channel held):

        phi'  = -omega_ie x phi + d_omega_in - eps^n
                d_omega_in = [-dvN/RM, dvE/RN - W sinL dL, dvE tanL/RN + W cosL dL]
        dvE'  = -g phi_N + 2 W sinL dvN + nabla_E
        dvN'  =  g phi_E - 2 W sinL dvE + nabla_N
        dL'   = dvN / RM,   dlambda' = dvE / (RN cosL)

    with its Schuler (84 min), Earth-rate (24 h) and Foucault couplings.
    ``eps_n`` is the gyro drift in n [rad/s]: a 3-vector, or a function that
    maps an array of times (N,) to drifts (N, 3) (a rotating IMU:
    C_p^n(t) eps^p); ``nabla_n`` likewise for the accelerometer bias (E, N
    used). Integrated by fourth-order Runge-Kutta with ``step_s`` (the
    inputs are sampled on the half-step grid); returns StaticErrors at
    ``times_s``.
    """
    times_s = np.asarray(times_s, dtype=float)
    half = 0.5 * step_s
    grid = np.arange(0.0, times_s.max() + 2 * step_s, half)

    def sampled(src):
        if src is None:
            return np.zeros((len(grid), 3))
        if callable(src):
            return np.asarray(src(grid), dtype=float).reshape(len(grid), 3)
        return np.tile(np.asarray(src, dtype=float), (len(grid), 1))

    eps_grid = sampled(eps_n)
    nab_grid = sampled(nabla_n)

    def eps_f(t):
        return eps_grid[int(round(t / half))]

    def nab_f(t):
        return nab_grid[int(round(t / half))]
    sin_lat, cos_lat = np.sin(lat), np.cos(lat)
    rm, rn = earth.principal_radii(sin_lat)
    rm_h, rn_h = rm + height, rn + height
    g = earth.normal_gravity(sin_lat, height)
    w = earth.OMEGA_IE
    w_n, w_u = w * cos_lat, w * sin_lat

    def f(t, x):
        phi_e, phi_n, phi_u, dve, dvn, dlat, _ = x
        eps = eps_f(t)
        nab = nab_f(t)
        return np.array([
            w_u * phi_n - w_n * phi_u - dvn / rm_h - eps[0],
            -w_u * phi_e + dve / rn_h - w_u * dlat - eps[1],
            w_n * phi_e + dve * np.tan(lat) / rn_h + w_n * dlat - eps[2],
            -g * phi_n + 2.0 * w_u * dvn + nab[0],
            g * phi_e - 2.0 * w_u * dve + nab[1],
            dvn / rm_h,
            dve / (rn_h * cos_lat),
        ])

    x = np.zeros(7)
    t = 0.0
    out = np.zeros((len(times_s), 7))
    for i, target in enumerate(times_s):
        while t < target - 1e-9:
            h = step_s
            if target - t < step_s - 1e-9:
                raise ValueError(f"times_s must be multiples of step_s ({step_s} s); got {target}")
            k1 = f(t, x)
            k2 = f(t + 0.5 * h, x + 0.5 * h * k1)
            k3 = f(t + 0.5 * h, x + 0.5 * h * k2)
            k4 = f(t + h, x + h * k3)
            x = x + (h / 6.0) * (k1 + 2.0 * k2 + 2.0 * k3 + k4)
            t = t + h
        out[i] = x
    north = out[:, 5] * rm_h
    east = out[:, 6] * rn_h * cos_lat
    return StaticErrors(time_s=times_s, att_n_rad=out[:, :3], vel_n_mps=out[:, 3:5], north_m=north,
                        east_m=east, horizontal_m=np.hypot(north, east))


def table_projected(bias_p, euler_b, rec_time_s, rec_alpha_rad, alpha0=0.0):
    """The IMU-frame constant ``bias_p`` (3,) seen in n on a static ship at
    ``euler_b`` whose table turned as recorded (times [s], angles [rad],
    unwrapped; ``alpha0`` at t = 0): a function of time for
    ``static_error_model``.

    C_p^n(t) = C_b^n Rz(alpha(t)) (docs/design.md §2); alpha is interpolated
    linearly between records, exact while the table turns at constant rate
    or stands still.
    """
    mat_nb = attitude.euler_to_mat(np.asarray(euler_b, dtype=float))
    b = np.asarray(bias_p, dtype=float)
    t_rec = np.concatenate([[0.0], np.asarray(rec_time_s, dtype=float)])
    a_rec = np.concatenate([[alpha0], np.asarray(rec_alpha_rad, dtype=float)])

    def in_n(t):
        alpha = np.interp(t, t_rec, a_rec)
        c, s = np.cos(alpha), np.sin(alpha)
        in_b = np.column_stack([c * b[0] - s * b[1], s * b[0] + c * b[1], np.full_like(t, b[2])])
        return in_b @ mat_nb.T
    return in_n


def predict_static_fil(result, lat, euler_b, gyro_bias_p, accel_bias_p, times_s, alpha0=0.0,
                       step_s=0.5):
    """What the linear error model says a static FIL run should show.

    ``result`` is a ``pyins.records.FilResult`` (its plant records give the table
    angle); the constant gyro drifts and accelerometer biases of the IMU
    frame are projected through the table angle and propagated by
    ``static_error_model``. Scale-factor, installation and random errors are
    left out: for a static ship they are second order.
    """
    t_rec = result.plant["tick"] * result.dt
    alpha = result.plant["alpha_rad"]
    return static_error_model(lat, times_s, table_projected(gyro_bias_p, euler_b, t_rec, alpha, alpha0),
                              table_projected(accel_bias_p, euler_b, t_rec, alpha, alpha0),
                              step_s=step_s)


def drift_surviving(yaw_p, mask=None):
    """The fraction of a constant x/y drift of the IMU that survives the
    modulation (the proxy of docs/papers.md, seed 002 §10): |sum of [cos psi,
    sin psi]| / number of samples, psi the IMU yaw sampled uniformly (e.g.
    an output record every second). With ``mask`` only the masked samples
    are summed (still divided by all of them), e.g. the stopped ones: the
    parts add up as vectors."""
    psi = np.asarray(yaw_p, dtype=float)
    sel = psi if mask is None else psi[np.asarray(mask, dtype=bool)]
    return float(np.hypot(np.cos(sel).sum(), np.sin(sel).sum()) / len(psi))


def table_nodes(table, a, b, x, w):
    """Gauss-Legendre nodes (x, w on [-1, 1]) on the record intervals a..b-1
    of ``table`` (`table_history`), each split at its kink: (times, alpha,
    rate, weights), each (b - a, 2 len(x)); the weights are in seconds (they
    sum to the interval, h)."""
    nodes = len(x)
    t0, tk = table.t0[a:b, None], table.t_kink[a:b, None]
    l1, l2 = tk - t0, t0 + table.h - tk
    u = 0.5 * (1.0 + x)[None, :]
    times = np.concatenate([t0 + l1 * u, tk + l2 * u], axis=1)
    r0, r1 = table.rate0[a:b, None], table.rate1[a:b, None]
    al = table.alpha0[a:b, None]
    alpha = np.concatenate([al + r0 * l1 * u, al + r0 * l1 + r1 * l2 * u], axis=1)
    rate = np.concatenate([np.broadcast_to(r0, (b - a, nodes)), np.broadcast_to(r1, (b - a, nodes))], axis=1)
    weights = np.concatenate([l1 * w[None, :], l2 * w[None, :]], axis=1) / 2.0
    return times, alpha, rate, weights


def drift_surviving_history(motion, table, nodes=4, chunk=7200):
    """The proxy of ``drift_surviving`` at the full rate, without sampling:
    (all, stopped, turning) = |time mean of [cos psi_p, sin psi_p]| over the
    run, psi_p(t) = psi_b(t) + alpha(t) (the records' yaw_p_rad), the ship's
    yaw from the analytic ``motion`` and the table angle from its history
    ``table`` (`table_history`: exact between the plant's records when the
    turns start within a tick, as seed 002's 600 deg/s^2; a corner in place
    of a slower ramp), integrated by ``nodes`` Gauss-Legendre nodes on each
    piece of each record interval. "stopped" sums the pieces where the table
    rate is 0, "turning" the others; all three are divided by the whole
    duration, so the parts add up as vectors.

    Measured against 100 Hz records (every tick's yaw_p_rad): seed 002
    exp. 2, traditional scheme, 72 h, 25.9 M records: 0.01570 / 0.00047 /
    0.01563 both ways (1 Hz records: 0.0157 / 0.0005 / 0.0156); 1 h and 6 h
    runs of both experiments agree with 100 Hz to 1e-5."""
    x, w = np.polynomial.legendre.leggauss(nodes)
    k_all = len(table.t0)
    c_all = s_all = c_stop = s_stop = 0.0
    for a in range(0, k_all, chunk):
        b = min(k_all, a + chunk)
        times, alpha, rate, weights = table_nodes(table, a, b, x, w)
        psi = motion.state(times.ravel()).euler[:, 2].reshape(times.shape) + alpha
        cw, sw = np.cos(psi) * weights, np.sin(psi) * weights
        stop = rate == 0.0
        c_all, s_all = c_all + cw.sum(), s_all + sw.sum()
        c_stop, s_stop = c_stop + cw[stop].sum(), s_stop + sw[stop].sum()
    duration = k_all * table.h
    return (float(np.hypot(c_all, s_all) / duration), float(np.hypot(c_stop, s_stop) / duration),
            float(np.hypot(c_all - c_stop, s_all - s_stop) / duration))


def drift_surviving_of_run(motion, result, config=None):
    """``drift_surviving_history`` of a firmware-in-the-loop run (a
    records.FilResult with its plant records, of ``motion``; ``config`` the
    firmware configuration, for the initial table angle)."""
    alpha0 = float((config or {}).get("table_angle_rad", 0.0))
    t_rec = np.asarray(result.plant["tick"], dtype=float) * result.dt
    table = table_history(t_rec, result.plant["alpha_rad"], result.plant["rate_rad_s"], alpha0, 0.0)
    return drift_surviving_history(motion, table)


@dataclass
class TableHistory:
    """The table angle over each record interval [t0_k, t0_k + h]: linear
    at ``rate0`` up to ``t_kink`` and at ``rate1`` after it (a turn that
    starts or stops inside the interval), alpha = ``alpha0`` at t0_k."""
    t0: np.ndarray
    h: float
    t_kink: np.ndarray
    alpha0: np.ndarray
    rate0: np.ndarray
    rate1: np.ndarray


def table_history(rec_time_s, rec_alpha_rad, rec_rate_rad_s=None, alpha0=0.0, rate0=0.0, kinks=True):
    """The table angle between records spaced evenly by h from t = h (the
    plant's records of a FIL run: ``alpha_rad``, ``rate_rad_s``).

    With the rates (and ``kinks``) an interval whose end rates differ holds
    one kink where a turn starts or stops, placed so that both end angles
    and rates hold: tau = (d_alpha - r1 h) / (r0 - r1) after its start
    (exact for a motor that reaches its rate within a tick, e.g. seed 002's
    600 deg/s^2; a 30 deg/s^2 ramp of 0.2 s is replaced by a corner at its
    middle, 0.15 deg off at most). Otherwise the angle is linear between
    the records (the table turns through a turn's first and last second as
    if at its mean rate: 1.5 deg off at most at 6 deg/s)."""
    t = np.concatenate([[0.0], np.asarray(rec_time_s, dtype=float)])
    a = np.concatenate([[alpha0], np.asarray(rec_alpha_rad, dtype=float)])
    h = float(t[1] - t[0])
    if np.any(np.abs(np.diff(t) - h) > 1e-9 * max(1.0, t[-1])):
        raise ValueError("table_history: the records must be evenly spaced from t = h")
    d = np.diff(a)
    mean = d / h
    r_a = np.full(len(d), mean)
    r_b = mean.copy()
    t_kink = t[1:].copy()
    if kinks and rec_rate_rad_s is not None:
        r = np.concatenate([[rate0], np.asarray(rec_rate_rad_s, dtype=float)])
        ra, rb = r[:-1], r[1:]
        differ = ra != rb
        with np.errstate(divide="ignore", invalid="ignore"):
            tau = np.where(differ, (d - rb * h) / np.where(differ, ra - rb, 1.0), -1.0)
        ok = differ & (tau >= 0.0) & (tau <= h)
        r_a = np.where(ok, ra, mean)
        r_b = np.where(ok, rb, mean)
        t_kink = np.where(ok, t[:-1] + tau, t[1:])
    return TableHistory(t0=t[:-1], h=h, t_kink=t_kink, alpha0=a[:-1], rate0=r_a, rate1=r_b)


def error_matrix(lat, height=0.0):
    """(F, G_gyro, G_accel) of the linear error equations of a ship at a
    fixed position, state [phi_E, phi_N, phi_U, dv_E, dv_N, dL, dlambda]:
    the equations of `static_error_model` (Qin 2014 sec. 4.2, vertical
    channel held) as x' = F x + G_gyro eps^n + G_accel nabla^n."""
    sin_lat, cos_lat = np.sin(lat), np.cos(lat)
    rm, rn = earth.principal_radii(sin_lat)
    rm_h, rn_h = rm + height, rn + height
    g = earth.normal_gravity(sin_lat, height)
    w_n, w_u = earth.OMEGA_IE * cos_lat, earth.OMEGA_IE * sin_lat
    f = np.zeros((7, 7))
    f[0, 1], f[0, 2], f[0, 4] = w_u, -w_n, -1.0 / rm_h
    f[1, 0], f[1, 3], f[1, 5] = -w_u, 1.0 / rn_h, -w_u
    f[2, 0], f[2, 3], f[2, 5] = w_n, np.tan(lat) / rn_h, w_n
    f[3, 1], f[3, 4] = -g, 2.0 * w_u
    f[4, 0], f[4, 3] = g, -2.0 * w_u
    f[5, 4] = 1.0 / rm_h
    f[6, 3] = 1.0 / (rn_h * cos_lat)
    g_gyro = np.zeros((7, 3))
    g_gyro[:3] = -np.eye(3)
    g_accel = np.zeros((7, 3))
    g_accel[3, 0] = g_accel[4, 1] = 1.0
    return f, g_gyro, g_accel


def _expm(a):
    """exp(a) of a small square matrix: scaling and squaring of the Taylor
    series (to degree 18 at norm <= 0.5: the next term is < 1e-22)."""
    norm = np.abs(a).sum(axis=1).max()
    s = max(0, int(np.ceil(np.log2(norm / 0.5)))) if norm > 0.5 else 0
    b = a / (2.0 ** s)
    out = np.eye(len(a))
    term = np.eye(len(a))
    for k in range(1, 19):
        term = term @ b / k
        out = out + term
    for _ in range(s):
        out = out @ out
    return out


def discretize(f, g, h):
    """(Phi, Gamma) of x' = F x + G u with u constant over a step h:
    Phi = exp(F h), Gamma = integral_0^h exp(F s) ds G (the exponential of
    the augmented matrix [[F, G], [0, 0]] h; Van Loan 1978)."""
    n, m = g.shape
    aug = np.zeros((n + m, n + m))
    aug[:n, :n] = f * h
    aug[:n, n:] = g * h
    e = _expm(aug)
    return e[:n, :n], e[:n, n:]


def propagate_errors(lat, height, h, eps_n, nabla_n, x0=None, keep_every=1):
    """Step the linear error model (`error_matrix`) from t = 0 through K
    intervals of ``h`` with each interval's mean forcing: eps_n and
    nabla_n (S, K, 3) for S sources at once (columns of the same model),
    x0 (S, 7) their initial states. The step is exact for a forcing
    constant over the interval; the forcing's variation inside it weighs
    with (F h)^2 ~ (omega_s h)^2 = 1.5e-6 at h = 1 s (omega_s the Schuler
    frequency) and does not accumulate. Returns (times (N,), states
    (S, N, 7)) at every ``keep_every``-th interval end."""
    f, g_gyro, g_accel = error_matrix(lat, height)
    phi, gam = discretize(f, np.hstack([g_gyro, g_accel]), h)
    eps_n, nabla_n = np.asarray(eps_n, dtype=float), np.asarray(nabla_n, dtype=float)
    n_src, k_all, _ = eps_n.shape
    u = np.einsum("ij,skj->ksi", gam, np.concatenate([eps_n, nabla_n], axis=2))   # (K, S, 7)
    x = np.zeros((n_src, 7)) if x0 is None else np.array(x0, dtype=float).reshape(n_src, 7)
    phi_t = phi.T.copy()
    keep = np.arange(keep_every - 1, k_all, keep_every)
    out = np.empty((len(keep), n_src, 7))
    j = 0
    for k in range(k_all):
        x = x @ phi_t + u[k]
        if j < len(keep) and k == keep[j]:
            out[j] = x
            j += 1
    return (keep + 1) * h, out.transpose(1, 0, 2)


def noise_covariance(lat, height, h, n_steps, gyro_arw, accel_vrw, keep_every=1):
    """Covariance of the errors the sensors' white noise drives: an angle
    random walk ``gyro_arw`` [rad/sqrt(s)] and a velocity random walk
    ``accel_vrw`` [(m/s)/sqrt(s)], the same on every axis of a triad, so that
    C_p^n q C_n^p = q I whatever the attitude history (the plant draws them
    so: pyins.sim.sensors). Stepped with the model of `propagate_errors`:
    P <- Phi P Phi^T + Gamma (Q / h) Gamma^T, the noise's mean over a step
    having the variance q / h (exact for the integrators, (F h)^2 off
    elsewhere). Returns (times (N,), P (N, 7, 7)) at every
    ``keep_every``-th step end; P = 0 at t = 0 (no initial uncertainty)."""
    f, g_gyro, g_accel = error_matrix(lat, height)
    phi, gam = discretize(f, np.hstack([g_gyro, g_accel]), h)
    q = np.diag([gyro_arw ** 2] * 3 + [accel_vrw ** 2] * 3) / h
    qd = gam @ q @ gam.T
    keep = np.arange(keep_every - 1, n_steps, keep_every)
    out = np.empty((len(keep), 7, 7))
    cov = np.zeros((7, 7))
    j = 0
    for k in range(n_steps):
        cov = phi @ cov @ phi.T + qd
        if j < len(keep) and k == keep[j]:
            out[j] = cov
            j += 1
    return (keep + 1) * h, out
