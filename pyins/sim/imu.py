"""Exact IMU increments and the true state, from an analytic motion.

For tick k, covering [t0 + k dt, t0 + (k + 1) dt], the increments are

    dtheta_p = integral of omega_ip^p(t) dt,   dv_p = integral of f^p(t) dt,

what a rate-integrating gyro and an integrating accelerometer deliver. They
are the integrals of the instantaneous IMU-frame rate and specific force, NOT
rotated into the tick-start frame (the firmware's coning and sculling
corrections account for that). The integrals are Gauss-Legendre quadratures
(``numpy.polynomial.legendre.leggauss``); with 5 nodes per 10-ms tick they
agree with 8 nodes to ~3e-18 rad and ~1e-16 m/s (rounding level) on the bad
sea state and the manoeuvre (tested), far below the 1e-10 rad per tick that
would already look like a 0.002 deg/h gyro drift. Node times are exact
(hi, lo) pairs (`pyins.sim.exact_time.split_times`), so this holds 24 h or 72 h
into a run as well.

Kinematics (Qin 2014, sec. 4.1 and eqs. 4.1.9-4.1.11 for ENU; sec. 9.1 for
the Euler-angle rates):

    omega_nb^b = Ry(roll)^T (Rx(pitch)^T [0, 0, yaw_dot] + [pitch_dot, 0, 0])
                 + [0, roll_dot, 0]
    omega_ib^b = omega_nb^b + C_n^b (omega_ie^n + omega_en^n)
    f^b        = C_n^b (acc_n + (2 omega_ie^n + omega_en^n) x vel_n - g^n)
    omega_ie^n = [0, W cos lat, W sin lat]
    omega_en^n = [-vN / (R_M + h), vE / (R_N + h), vE tan(lat) / (R_N + h)]
    g^n        = [0, 0, -normal_gravity(lat, h)]       (TR8350.2 eqs. 4-1, 4-3)

and with the turntable (C_p^b = Rz(alpha)):

    omega_ip^p = Rz(alpha)^T omega_ib^b + [0, 0, alpha_dot],  f^p = Rz(alpha)^T f^b.

The Earth model is ``pyins.reference.earth``, shared with the firmware.

Everything is element-wise in NumPy (no BLAS, no pairwise sums), so computing
a run in chunks gives bit-identical results to one call.

For a `pyins.sim.ship.ShipAtSea` the state is that of the IMU point (lever
arms and heave, surge, sway included: its vel_n and acc_n are exact), so the
same formulas give the increments at the sensor; `truth` reports the motion
reference point beside it (``imu_*`` fields).

Ticks and samples: tick interval k (0-based) ends at t0 + (k + 1) dt; its
sample carries the tick number k + 1 (docs/design.md §3: the increment over
[t_{k-1}, t_k] and the encoder angle at t_k). `truth` is the state at the
same instant, so after n samples the firmware should reach ``truth`` row n-1.

1. Attitude and angle helpers: `euler_to_mat`, `euler_to_quat`,
   `wrap_two_pi_mod`, `wrap_pi_mod`.
2. Body rate and specific force: `nb_rate_and_derivative`,
   `body_rate_and_force`.
3. Increments: `node_rates` (for the compiled plant), `exact_increments`.
4. Truth: `Truth`, `truth`, `truth_at`.
5. Chunked generation: `Chunk`, `generate`.
"""
from dataclasses import dataclass

import numpy as np
from numpy.polynomial.legendre import leggauss

from pyins.reference import earth
from pyins.sim.exact_time import split_times
from pyins.sim.motion import Static
from pyins.sim.turntable import Fixed
from pyins.units import DT, TWO_PI

#: Ticks evaluated per internal block (memory bound; results do not depend on it).
BLOCK_TICKS = 20000


# ---------------------------------------------------------------------------
# 1. Attitude and angle helpers, vectorised
# ---------------------------------------------------------------------------
def euler_to_mat(euler):
    """C_b^n = Rz(yaw) Rx(pitch) Ry(roll) for an (N, 3) array -> (N, 3, 3).

    Same element formulas as ``pyins.reference.attitude.euler_to_mat``.
    """
    euler = np.asarray(euler, dtype=float)
    sp, cp = np.sin(euler[..., 0]), np.cos(euler[..., 0])
    sr, cr = np.sin(euler[..., 1]), np.cos(euler[..., 1])
    sy, cy = np.sin(euler[..., 2]), np.cos(euler[..., 2])
    m = np.empty(euler.shape[:-1] + (3, 3))
    m[..., 0, 0] = cy * cr - sy * sp * sr
    m[..., 0, 1] = -sy * cp
    m[..., 0, 2] = cy * sr + sy * sp * cr
    m[..., 1, 0] = sy * cr + cy * sp * sr
    m[..., 1, 1] = cy * cp
    m[..., 1, 2] = sy * sr - cy * sp * cr
    m[..., 2, 0] = -cp * sr
    m[..., 2, 1] = sp
    m[..., 2, 2] = cp * cr
    return m


def euler_to_quat(euler):
    """Unit quaternion quat_nb ``[w, x, y, z]``, w >= 0, of Euler angles (N, 3).

    Vectorised equivalent of ``pyins.reference.attitude.euler_to_quat``
    (which goes through the matrix and Shepperd's method), formed directly as
    the Hamilton product q_z(yaw) (x) q_x(pitch) (x) q_y(roll) of the
    elementary half-angle quaternions, then sign-normalised.
    """
    euler = np.asarray(euler, dtype=float)
    hp, hr, hy = 0.5 * euler[..., 0], 0.5 * euler[..., 1], 0.5 * euler[..., 2]
    cx, sx = np.cos(hp), np.sin(hp)
    cy, sy = np.cos(hr), np.sin(hr)
    cz, sz = np.cos(hy), np.sin(hy)
    # r = q_z (x) q_x
    rw, rx, ry, rz = cz * cx, cz * sx, sz * sx, sz * cx
    # q = r (x) q_y
    q = np.empty(euler.shape[:-1] + (4,))
    q[..., 0] = rw * cy - ry * sy
    q[..., 1] = rx * cy - rz * sy
    q[..., 2] = rw * sy + ry * cy
    q[..., 3] = rx * sy + rz * cy
    norm = np.sqrt(q[..., 0] ** 2 + q[..., 1] ** 2 + q[..., 2] ** 2 + q[..., 3] ** 2)
    norm = np.where(q[..., 0] < 0.0, -norm, norm)
    return q / norm[..., None]


def wrap_two_pi_mod(angle):
    """Angle wrapped to [0, 2 pi) by ``np.mod``, vectorised (the true table angle).

    ``np.mod`` takes the exact floating remainder, so this can differ in the
    last bits from `pyins.reference.angle.wrap_two_pi`, the core's (and
    the plant's) ``a - 2 pi floor(a / 2 pi)``.
    """
    a = np.mod(angle, TWO_PI)
    return np.where(a >= TWO_PI, 0.0, a)


def wrap_pi_mod(angle):
    """Angle wrapped to (-pi, pi] by ``np.mod``, vectorised, for any finite
    angle (the true yaw; the firmware's wrap_pi takes one turn off or on)."""
    a = np.mod(angle + np.pi, TWO_PI) - np.pi
    return np.where(a <= -np.pi, a + TWO_PI, a)


# ---------------------------------------------------------------------------
# 2. Body rate and specific force
# ---------------------------------------------------------------------------
def _nb_rate(sp, cp, sr, cr, dpitch, droll, dyaw):
    """omega_nb^b = Ry^T (Rx^T [0, 0, yaw_dot] + [pitch_dot, 0, 0]) + [0, roll_dot, 0]
    from the sines and cosines of pitch and roll: ``((x, y, z), u1, u2)`` with
    u1 = sin(pitch) yaw_dot, u2 = cos(pitch) yaw_dot (Qin 2014 sec. 9.1)."""
    u1 = sp * dyaw
    u2 = cp * dyaw
    return (cr * dpitch - sr * u2, droll + u1, sr * dpitch + cr * u2), u1, u2


def nb_rate_and_derivative(euler, euler_rate, euler_accel):
    """omega_nb^b and its time derivative [rad/s, rad/s^2], (N, 3) each.

    omega_nb^b as in `body_rate_and_force`, differentiated term by term
    (what the lever arms of `pyins.sim.ship.ShipAtSea` need).
    """
    p, r = euler[:, 0], euler[:, 1]
    dp, dr, dy = euler_rate[:, 0], euler_rate[:, 1], euler_rate[:, 2]
    ddp, ddr, ddy = euler_accel[:, 0], euler_accel[:, 1], euler_accel[:, 2]
    sp, cp = np.sin(p), np.cos(p)
    sr, cr = np.sin(r), np.cos(r)
    (w0, w1, w2), u1, u2 = _nb_rate(sp, cp, sr, cr, dp, dr, dy)
    du1 = cp * dp * dy + sp * ddy
    du2 = -sp * dp * dy + cp * ddy
    w = np.empty(euler.shape)
    w[:, 0] = w0
    w[:, 1] = w1
    w[:, 2] = w2
    wd = np.empty(euler.shape)
    wd[:, 0] = (cr * ddp - sr * dr * dp) - (cr * dr * u2 + sr * du2)
    wd[:, 1] = ddr + du1
    wd[:, 2] = (sr * ddp + cr * dr * dp) + (cr * du2 - sr * dr * u2)
    return w, wd


def body_rate_and_force(st):
    """omega_ib^b and f^b [rad/s, m/s^2], (N, 3) each, from a MotionState.

    Written out component by component (no matrix products) so that every
    output element depends only on its own inputs.
    """
    pitch, roll, yaw = st.euler[:, 0], st.euler[:, 1], st.euler[:, 2]
    dpitch, droll, dyaw = st.euler_rate[:, 0], st.euler_rate[:, 1], st.euler_rate[:, 2]
    sp, cp = np.sin(pitch), np.cos(pitch)
    sr, cr = np.sin(roll), np.cos(roll)
    sy, cy = np.sin(yaw), np.cos(yaw)
    # C_b^n elements (attitude.euler_to_mat); C_n^b v = C^T v.
    c00 = cy * cr - sy * sp * sr
    c01 = -sy * cp
    c02 = cy * sr + sy * sp * cr
    c10 = sy * cr + cy * sp * sr
    c11 = cy * cp
    c12 = sy * sr - cy * sp * cr
    c20 = -cp * sr
    c21 = sp
    c22 = cp * cr

    (wnb_x, wnb_y, wnb_z), _, _ = _nb_rate(sp, cp, sr, cr, dpitch, droll, dyaw)

    # Earth quantities (earth.earth_at, element-wise).
    sin_lat = np.sin(st.lat)
    cos_lat = np.cos(st.lat)
    tan_lat = sin_lat / cos_lat
    rm, rn = earth.principal_radii(sin_lat)
    rm_h = rm + st.height
    rn_h = rn + st.height
    ve, vn, vu = st.vel_n[:, 0], st.vel_n[:, 1], st.vel_n[:, 2]
    wie_y = earth.OMEGA_IE * cos_lat
    wie_z = earth.OMEGA_IE * sin_lat
    wen_x = -vn / rm_h
    wen_y = ve / rn_h
    wen_z = ve / rn_h * tan_lat
    win_x = wen_x
    win_y = wie_y + wen_y
    win_z = wie_z + wen_z
    g = earth.normal_gravity(sin_lat, st.height)

    omega = np.empty((len(st), 3))
    omega[:, 0] = wnb_x + (c00 * win_x + c10 * win_y + c20 * win_z)
    omega[:, 1] = wnb_y + (c01 * win_x + c11 * win_y + c21 * win_z)
    omega[:, 2] = wnb_z + (c02 * win_x + c12 * win_y + c22 * win_z)

    # a = acc_n + (2 omega_ie + omega_en) x vel_n - g^n,  g^n = [0, 0, -g]
    wx = wen_x
    wy = 2.0 * wie_y + wen_y
    wz = 2.0 * wie_z + wen_z
    ax = st.acc_n[:, 0] + (wy * vu - wz * vn)
    ay = st.acc_n[:, 1] + (wz * ve - wx * vu)
    az = st.acc_n[:, 2] + (wx * vn - wy * ve) + g
    force = np.empty((len(st), 3))
    force[:, 0] = c00 * ax + c10 * ay + c20 * az
    force[:, 1] = c01 * ax + c11 * ay + c21 * az
    force[:, 2] = c02 * ax + c12 * ay + c22 * az
    return omega, force


def _to_p(omega_b, force_b, alpha, alpha_dot):
    """Rz(alpha)^T applied to rate and force, plus the table rate on z."""
    ca, sa = np.cos(alpha), np.sin(alpha)
    omega = np.empty_like(omega_b)
    force = np.empty_like(force_b)
    omega[:, 0] = ca * omega_b[:, 0] + sa * omega_b[:, 1]
    omega[:, 1] = -sa * omega_b[:, 0] + ca * omega_b[:, 1]
    omega[:, 2] = omega_b[:, 2] + alpha_dot
    force[:, 0] = ca * force_b[:, 0] + sa * force_b[:, 1]
    force[:, 1] = -sa * force_b[:, 0] + ca * force_b[:, 1]
    force[:, 2] = force_b[:, 2]
    return omega, force


# ---------------------------------------------------------------------------
# 3. Increments
# ---------------------------------------------------------------------------
def _state(motion, t_hi, t_lo, table):
    """The motion's state at the IMU point: a motion whose IMU point moves with
    the table (`pyins.sim.ship.ShipAtSea` with a non-zero lever_p,
    ``needs_table``) is given the table; every other motion is not."""
    if getattr(motion, "needs_table", False):
        return motion.state(t_hi, t_lo, table=table)
    return motion.state(t_hi, t_lo)


def _increments_block(motion, ticks, dt, t0, table, x, w):
    m = len(x)
    n = len(ticks)
    s = 0.5 * (1.0 + x)
    t_hi, t_lo = split_times(ticks[:, None], dt, t0, s[None, :])
    t_hi, t_lo = t_hi.ravel(), t_lo.ravel()
    st = _state(motion, t_hi, t_lo, table)
    omega, force = body_rate_and_force(st)
    if table is not None:
        alpha, alpha_dot = table.state(t_hi, t_lo)
        omega, force = _to_p(omega, force, alpha, alpha_dot)
    omega = omega.reshape(n, m, 3)
    force = force.reshape(n, m, 3)
    dtheta = np.zeros((n, 3))
    dv = np.zeros((n, 3))
    for i in range(m):
        dtheta = dtheta + w[i] * omega[:, i, :]
        dv = dv + w[i] * force[:, i, :]
    half = 0.5 * dt
    return half * dtheta, half * dv


def node_rates(motion, ticks, dt=DT, t0=0.0, nodes=5):
    """The ship's omega_ib^b and f^b at the Gauss-Legendre nodes of ticks.

    Returns ``(omega (n, nodes, 3), force (n, nodes, 3), x, w)`` with x, w the
    abscissae on [-1, 1] and weights: what the firmware-in-the-loop plant
    (pyins_plant.h) integrates after turning them into the IMU frame. A lever
    arm in b (``ShipAtSea.lever_b``) is already in the force at the IMU
    point; a sensor offset that turns with the table (``lever_p``) is not
    representable (the plant turns b-frame values into p) and is refused.
    """
    if getattr(motion, "needs_table", False):
        raise ValueError("lever_p is not supported by the compiled FIL plant yet; use lever_b")
    x, w = np.polynomial.legendre.leggauss(nodes)
    ticks = np.asarray(ticks, dtype=np.int64)
    s = 0.5 * (1.0 + x)
    t_hi, t_lo = split_times(ticks[:, None], dt, t0, s[None, :])
    st = motion.state(t_hi.ravel(), t_lo.ravel())
    omega, force = body_rate_and_force(st)
    n = len(ticks)
    return omega.reshape(n, nodes, 3), force.reshape(n, nodes, 3), x, w


def node_sums(omega, force, w):
    """The weighted node sums sum_j w[j] * omega[:, j] and sum_j w[j] *
    force[:, j] ((n, 3) each) of `node_rates`' arrays, summed from 0.0 in
    the order j = 0, 1, ...: a tick with the table at rest takes exactly
    these (pyins_plant.h, ``node_sum_omega``; the plant's own loop adds in
    the same order, so the bits are the same)."""
    so = np.zeros((omega.shape[0], 3))
    sf = np.zeros((force.shape[0], 3))
    for j in range(len(w)):
        so = so + w[j] * omega[:, j, :]
        sf = sf + w[j] * force[:, j, :]
    return so, sf


def _table_angle_end(table, ticks, dt, t0):
    if table is None:
        return np.zeros(len(ticks))
    t_hi, t_lo = split_times(ticks + 1, dt, t0)
    alpha, _ = table.state(t_hi, t_lo)
    return wrap_two_pi_mod(alpha)


def exact_increments(motion, n_ticks, dt=DT, t0=0.0, table=None, nodes=5, start_tick=0):
    """Exact angle and velocity increments in the IMU frame p.

    Parameters
    ----------
    motion : Motion
        Ship profile (`pyins.sim.motion`).
    n_ticks : int
        Number of ticks.
    dt : float
        Tick length [s].
    t0 : float
        Profile time [s] of tick 0.
    table : TableMotion or None
        Turntable profile; None means p = b (alpha = 0).
    nodes : int
        Gauss-Legendre nodes per tick.
    start_tick : int
        Index of the first tick; tick k covers [t0 + k dt, t0 + (k + 1) dt].
        Chunks ``start_tick = 0, c, 2c, ...`` concatenate bit for bit to one call.

    Returns
    -------
    dtheta_p : ndarray (n_ticks, 3)
        Integral of omega_ip^p over each tick [rad].
    dv_p : ndarray (n_ticks, 3)
        Integral of f^p over each tick [m/s].
    table_angle : ndarray (n_ticks,)
        Table angle at the END of each tick, wrapped to [0, 2 pi) [rad].
    """
    n_ticks = int(n_ticks)
    x, w = leggauss(int(nodes))
    ticks = np.arange(start_tick, start_tick + n_ticks, dtype=np.int64)
    constant = ((isinstance(motion, Static) or getattr(motion, "is_constant", False))
                and (table is None or isinstance(table, Fixed)))
    if constant and n_ticks > 0:
        # Fast path: the integrand does not depend on time, so every tick
        # equals the first one (computed by the generic code, so the two
        # paths agree bit for bit).
        th, v = _increments_block(motion, ticks[:1], dt, t0, table, x, w)
        dtheta = np.repeat(th, n_ticks, axis=0)
        dv = np.repeat(v, n_ticks, axis=0)
    else:
        dtheta = np.empty((n_ticks, 3))
        dv = np.empty((n_ticks, 3))
        for a in range(0, n_ticks, BLOCK_TICKS):
            b = min(a + BLOCK_TICKS, n_ticks)
            dtheta[a:b], dv[a:b] = _increments_block(motion, ticks[a:b], dt, t0, table, x, w)
    return dtheta, dv, _table_angle_end(table, ticks, dt, t0)


# ---------------------------------------------------------------------------
# 4. Truth
# ---------------------------------------------------------------------------
@dataclass
class Truth:
    """True state at the END of each tick (the sample instants).

    ``lat``, ``lon``, ``height`` and ``vel_n`` are those of the ship's motion
    reference point (what the firmware reports once it knows the lever arm);
    the ``imu_*`` fields those of the IMU point, where the increments are
    measured. They differ only for a `pyins.sim.ship.ShipAtSea` with a lever
    arm; otherwise they are equal bit for bit (left None, they are filled in
    as copies of the reference fields).
    """
    tick: np.ndarray        #: tick number k + 1 of each sample, (N,) int64
    time: np.ndarray        #: profile time t0 + tick dt [s] (rounded), (N,)
    lat: np.ndarray         #: reference point [rad], (N,)
    lon: np.ndarray         #: reference point [rad], (N,)
    height: np.ndarray      #: reference point [m], (N,)
    vel_n: np.ndarray       #: reference point [m/s], (N, 3)
    quat_nb: np.ndarray     #: C_b^n as [w, x, y, z], w >= 0, (N, 4)
    euler: np.ndarray       #: [pitch, roll, yaw] [rad], yaw in (-pi, pi], (N, 3)
    table_angle: np.ndarray  #: [rad] in [0, 2 pi), (N,)
    imu_lat: np.ndarray = None      #: IMU point [rad], (N,)
    imu_lon: np.ndarray = None      #: IMU point [rad], (N,)
    imu_height: np.ndarray = None   #: IMU point [m], (N,)
    imu_vel_n: np.ndarray = None    #: IMU point [m/s], (N, 3)

    def __post_init__(self):
        for name in ("lat", "lon", "height", "vel_n"):
            if getattr(self, "imu_" + name) is None:
                setattr(self, "imu_" + name, np.array(getattr(self, name), copy=True))


def truth(motion, n_ticks, dt=DT, t0=0.0, table=None, start_tick=0):
    """True state at the end of ticks start_tick .. start_tick + n_ticks - 1.

    Parameters are those of `exact_increments`. Returns a `Truth`.
    """
    ticks = np.arange(start_tick, start_tick + int(n_ticks), dtype=np.int64)
    return truth_at(motion, ticks + 1, dt=dt, t0=t0, table=table)


def truth_at(motion, sample_ticks, dt=DT, t0=0.0, table=None):
    """True state at the end of the given ticks: sample number k ends at t0 + k dt.

    ``sample_ticks`` may be any int array (e.g. the ``tick`` field of
    decimated firmware records). Returns a `Truth`.
    """
    ticks = np.asarray(sample_ticks, dtype=np.int64) - 1
    t_hi, t_lo = split_times(ticks + 1, dt, t0)
    st = _state(motion, t_hi, t_lo, table)
    ref = motion.reference_state(t_hi, t_lo) if hasattr(motion, "reference_state") else st
    euler = st.euler.copy()
    euler[:, 2] = wrap_pi_mod(euler[:, 2])
    return Truth(tick=ticks + 1, time=t_hi + t_lo, lat=ref.lat, lon=ref.lon,
                 height=ref.height, vel_n=ref.vel_n, quat_nb=euler_to_quat(st.euler),
                 euler=euler, table_angle=_table_angle_end(table, ticks, dt, t0),
                 imu_lat=st.lat.copy(), imu_lon=st.lon.copy(), imu_height=st.height.copy(),
                 imu_vel_n=st.vel_n.copy())


# ---------------------------------------------------------------------------
# 5. Chunked generation
# ---------------------------------------------------------------------------
@dataclass
class Chunk:
    """One chunk of a simulated run.

    ``dtheta_p``/``dv_p`` are what the IMU delivers: the exact increments with
    the sensor errors applied when a sensor model is given, else the exact
    increments themselves.
    """
    first_tick: int             #: tick number of the first sample
    tick: np.ndarray            #: (n,) int64 tick numbers (sample k ends at t0 + tick dt)
    dtheta_p: np.ndarray        #: (n, 3) [rad]
    dv_p: np.ndarray            #: (n, 3) [m/s]
    table_angle: np.ndarray     #: (n,) encoder angle at the sample instant [rad]
    exact_dtheta_p: np.ndarray  #: (n, 3) [rad], error-free
    exact_dv_p: np.ndarray      #: (n, 3) [m/s], error-free
    truth: Truth = None         #: true state at the sample instants, or None


def generate(motion, duration_ticks, chunk_ticks=50000, dt=DT, t0=0.0, table=None,
             sensors=None, nodes=5, with_truth=True):
    """Yield a run as `Chunk` objects of at most ``chunk_ticks`` samples.

    Memory stays bounded by the chunk size, so a 24-h run (8.64 M ticks) is
    fine. Results do not depend on ``chunk_ticks`` (bit for bit).

    Parameters
    ----------
    motion : Motion
        Ship profile.
    duration_ticks : int
        Length of the run in ticks.
    chunk_ticks : int
        Samples per chunk.
    dt, t0, table, nodes
        As in `exact_increments`.
    sensors : SensorModel or None
        Applied to each chunk in order (it carries its own random state and
        quantisation residuals).
    with_truth : bool
        Attach the `Truth` of each chunk.
    """
    duration_ticks = int(duration_ticks)
    chunk_ticks = int(chunk_ticks)
    if chunk_ticks <= 0:
        raise ValueError("chunk_ticks must be positive")
    for a in range(0, duration_ticks, chunk_ticks):
        n = min(chunk_ticks, duration_ticks - a)
        th, dv, angle = exact_increments(motion, n, dt, t0, table, nodes, start_tick=a)
        if sensors is not None:
            mth, mdv = sensors.apply(th, dv)
        else:
            mth, mdv = th, dv
        tr = truth(motion, n, dt, t0, table, start_tick=a) if with_truth else None
        yield Chunk(first_tick=a + 1, tick=np.arange(a + 1, a + 1 + n, dtype=np.int64),
                    dtheta_p=mth, dv_p=mdv, table_angle=angle,
                    exact_dtheta_p=th, exact_dv_p=dv, truth=tr)
