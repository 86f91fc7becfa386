"""The error budget: each sensor error's share of a run's errors, driven by
the run's history, and its check against the firmware in the loop.

A constant drift is not the only error that survives a rotating
IMU: a scale-factor or misalignment error turns the IMU's own rate into a
drift, eps^p(t) = (dK + M) omega_ip^p(t), and the accelerometers' into a
bias, nabla^p(t) = (dK_a + M_a) f^p(t) (the sensor model of
pyins.sim.sensors; the instrument error terms as in Titterton & Weston,
"Strapdown Inertial Navigation Technology" (2nd ed., 2004), ch. 12; Qin
2014 sec. 4.2 for the error equations). Seen in n, eps^n(t) = C_p^n(t)
eps^p(t): the table angle, the ship's swing and its tilt all enter, and
the mean of that product over the run is what a table cannot modulate.
Example (seed 002 exp. 2, the traditional two-position scheme, all six
gyro misalignments +10"): the yaw swing psi' about the vertical of n gives
an up drift psi' u^T M u, u = C_n^p e_Up = (u_x, u_y, ~1) the vertical
seen in the IMU, i.e. psi' [u_x (M_xz + M_zx) + u_y (M_yz + M_zy)] to first
order in the deck's tilt (pitch 1 deg, roll -2 deg), (u_x, u_y) turned by
the table angle. It averages out with a fixed table; with the table's
turns locked in phase to the swing it leaves a mean up drift of
+0.0045 deg/h, 1.5 times the up gyro's own 0.003 deg/h (10.2 nmi in 72 h
against 0.16 nmi on a level deck; docs/concepts.md, "The error budget").

The model:
  1. the table angle between the records, rebuilt from the plant's recorded
     angle and rate (`table_history`);
  2. the ship's attitude, body rate and specific force from the analytic
     motion at Gauss-Legendre nodes inside each record interval, and the
     mean over the interval of eps^n and nabla^n for each source
     (`error_drive`); or, without a motion, from the firmware's recorded
     attitude alone (`error_drive_from_records`, coarser);
  3. the linear error equations of a ship at a fixed position (the static
     model of `pyins.analysis`: phi, dv_E, dv_N, dL, dlambda, vertical
     channel held), which are time-invariant there, stepped exactly from
     record to record with the interval's mean forcing (`propagate_errors`);
  4. every source separately, signed, and their sum (`error_budget`).

The theory it builds on (the table's history, the error equations and
their stepping, the noise's covariance) is `pyins.analysis`; this room
sits above `pyins.fil`, whose runs it models and checks itself against.
"""
from dataclasses import dataclass, replace

import numpy as np

from pyins import fil, metrics
from pyins.analysis import StaticErrors, noise_covariance, propagate_errors, table_history, table_nodes
from pyins.reference import abi, attitude, earth
from pyins.scenario.build import initial_truth
from pyins.sim.imu import body_rate_and_force
from pyins.sim.sensors import SensorErrors

#: The deterministic sensor errors the budget splits a SensorErrors into.
SOURCES = ("gyro_bias", "gyro_scale", "gyro_misalignment", "accel_bias", "accel_scale", "accel_misalignment")
#: The name of the initial-state errors' row.
INITIAL = "initial"
#: The name of the noise's row (1 sigma, not a signed share).
NOISE = "noise"


def split_errors(errors, sources=SOURCES):
    """{source: a SensorErrors holding that field of ``errors`` alone} for
    every non-zero deterministic source (noise and quantisation left out:
    the linear model of the means has no place for them)."""
    out = {}
    for name in sources:
        value = np.array(getattr(errors, name), dtype=float)
        if np.any(value != 0.0):
            out[name] = SensorErrors(**{name: value})
    return out


def element_sources(errors, sources=SOURCES):
    """{name: a SensorErrors holding one element of ``errors`` alone} for
    every non-zero element of its deterministic sources, named
    "gyro_bias[2]", "gyro_misalignment[1,0]", ...: a basis in which every
    SensorErrors with the same non-zero pattern (every draw of a preset,
    `pyins.sim.sensors.random_constant_values`) is a linear combination, the
    model being linear in each element (`element_coefficients`)."""
    out = {}
    for name in sources:
        value = np.array(getattr(errors, name), dtype=float)
        for idx in zip(*np.nonzero(value)):
            one = np.zeros_like(value)
            one[idx] = value[idx]
            out[f"{name}[{','.join(str(int(i)) for i in idx)}]"] = SensorErrors(**{name: one})
    return out


def element_coefficients(basis, errors):
    """The coefficients of ``errors`` (a SensorErrors) in ``basis``
    (`element_sources`), in the basis's order: each element of ``errors``
    divided by the basis's. An element of ``errors`` that is non-zero where
    the basis has none raises ValueError (the model would leave it out)."""
    coef = []
    covered = {name: np.zeros(np.shape(getattr(errors, name)), dtype=bool) for name in SOURCES}
    for e in basis.values():
        name = next(n for n in SOURCES if np.any(getattr(e, n)))
        value = np.asarray(getattr(e, name))
        idx = tuple(int(i[0]) for i in np.nonzero(value))
        coef.append(float(np.asarray(getattr(errors, name))[idx]) / float(value[idx]))
        covered[name][idx] = True
    for name in SOURCES:
        stray = (np.asarray(getattr(errors, name)) != 0.0) & ~covered[name]
        if np.any(stray):
            raise ValueError(f"{name}{[int(i[0]) for i in np.nonzero(stray)]} is non-zero but not in the basis")
    return np.array(coef)


def initial_state_errors(motion, config):
    """The initial errors the firmware starts with, as the model's state
    [phi_E, phi_N, phi_U, dv_E, dv_N, dL, dlambda]: ``config`` (the
    firmware configuration: lat_rad, lon_rad, vel_n_mps, euler_b_rad; a
    missing field is the truth) against the truth of ``motion`` at t = 0.
    phi from C' = (I - phi x) C (docs/design.md §2)."""
    lat, lon, _, vel, euler = initial_truth(motion)
    x0 = np.zeros(7)
    if "euler_b_rad" in config:
        c_true = attitude.euler_to_mat(np.asarray(euler, dtype=float))
        c_fw = attitude.euler_to_mat(np.asarray(config["euler_b_rad"], dtype=float))
        # C' C^T = I - phi x: phi is minus the rotation vector of C' C^T
        x0[:3] = -attitude.quat_to_rotvec(attitude.mat_to_quat(c_fw @ c_true.T))
    if "vel_n_mps" in config:
        x0[3:5] = (np.asarray(config["vel_n_mps"], dtype=float) - vel)[:2]
    x0[5] = config.get("lat_rad", lat) - lat
    x0[6] = config.get("lon_rad", lon) - lon
    return x0


def _mats_nb(euler):
    """C_b^n (N, 3, 3) from [pitch, roll, yaw] (N, 3) (attitude.euler_to_mat)."""
    sp, cp = np.sin(euler[:, 0]), np.cos(euler[:, 0])
    sr, cr = np.sin(euler[:, 1]), np.cos(euler[:, 1])
    sy, cy = np.sin(euler[:, 2]), np.cos(euler[:, 2])
    m = np.empty((len(euler), 3, 3))
    m[:, 0, 0] = cy * cr - sy * sp * sr
    m[:, 0, 1] = -sy * cp
    m[:, 0, 2] = cy * sr + sy * sp * cr
    m[:, 1, 0] = sy * cr + cy * sp * sr
    m[:, 1, 1] = cy * cp
    m[:, 1, 2] = sy * sr - cy * sp * cr
    m[:, 2, 0] = -cp * sr
    m[:, 2, 1] = sp
    m[:, 2, 2] = cp * cr
    return m


def _sensor_terms(errors):
    """(D_g, b_g, D_a, b_a): the error of a rate omega is D_g omega + b_g."""
    d_g = np.diag(np.asarray(errors.gyro_scale, dtype=float)) + np.asarray(errors.gyro_misalignment, dtype=float)
    d_a = np.diag(np.asarray(errors.accel_scale, dtype=float)) + np.asarray(errors.accel_misalignment, dtype=float)
    return d_g, np.asarray(errors.gyro_bias, dtype=float), d_a, np.asarray(errors.accel_bias, dtype=float)


def _drive_from_samples(mat_pn, omega_p, force_p, weights, sources):
    """Weighted means over each interval of C_p^n (D omega^p + b) for each
    source: mat_pn (K, m, 3, 3), omega_p and force_p (K, m, 3), weights
    (K, m) summing to 1 per interval. Returns eps (S, K, 3), nabla (S, K, 3)."""
    eps = np.zeros((len(sources), mat_pn.shape[0], 3))
    nab = np.zeros_like(eps)
    for s, errors in enumerate(sources):
        d_g, b_g, d_a, b_a = _sensor_terms(errors)
        de = omega_p @ d_g.T + b_g                 # (K, m, 3): the gyro's error in p
        da = force_p @ d_a.T + b_a
        eps[s] = np.einsum("km,kmij,kmj->ki", weights, mat_pn, de)
        nab[s] = np.einsum("km,kmij,kmj->ki", weights, mat_pn, da)
    return eps, nab


def error_drive(motion, table, sources, nodes=4, chunk=7200):
    """The mean over each record interval of the gyro error in n, eps^n =
    C_p^n (dK_g + M_g) omega_ip^p + C_p^n b_g, and of the accelerometer
    error nabla^n = C_p^n ((dK_a + M_a) f^p + b_a), for each SensorErrors of
    ``sources`` (a list), on the table's history ``table``
    (`table_history`) and the analytic ``motion`` (pyins.sim).

    Each interval is split at its kink; each piece takes ``nodes``
    Gauss-Legendre nodes, where the motion gives C_b^n, omega_ib^b and f^b
    (pyins.sim.body_rate_and_force, Earth rate included) and the table
    C_p^b = Rz(alpha) (docs/design.md §2): omega_ip^p = Rz(alpha)^T
    omega_ib^b + alpha' z, f^p = Rz(alpha)^T f^b, C_p^n = C_b^n Rz(alpha).
    The swing and the table rate are smooth on each piece, so the means are
    exact to rounding with 4 nodes for seed 002's 60-120 s swings. Returns
    eps (S, K, 3) [rad/s], nabla (S, K, 3) [m/s^2].
    """
    x, w = np.polynomial.legendre.leggauss(nodes)
    k_all = len(table.t0)
    eps = np.zeros((len(sources), k_all, 3))
    nab = np.zeros_like(eps)
    for a in range(0, k_all, chunk):
        b = min(k_all, a + chunk)
        times, alpha, rate, weights = table_nodes(table, a, b, x, w)
        weights = weights / table.h
        st = motion.state(times.ravel())
        omega_b, force_b = body_rate_and_force(st)
        k, m = times.shape
        ca, sa = np.cos(alpha.ravel()), np.sin(alpha.ravel())
        omega_p = np.column_stack([ca * omega_b[:, 0] + sa * omega_b[:, 1],
                                   -sa * omega_b[:, 0] + ca * omega_b[:, 1],
                                   omega_b[:, 2] + rate.ravel()])
        force_p = np.column_stack([ca * force_b[:, 0] + sa * force_b[:, 1],
                                   -sa * force_b[:, 0] + ca * force_b[:, 1], force_b[:, 2]])
        rz = np.zeros((len(ca), 3, 3))
        rz[:, 0, 0], rz[:, 0, 1], rz[:, 1, 0], rz[:, 1, 1], rz[:, 2, 2] = ca, -sa, sa, ca, 1.0
        mat_pn = _mats_nb(st.euler) @ rz
        e, n = _drive_from_samples(mat_pn.reshape(k, m, 3, 3), omega_p.reshape(k, m, 3),
                                   force_p.reshape(k, m, 3), weights, sources)
        eps[:, a:b], nab[:, a:b] = e, n
    return eps, nab


def _quat_mul(p, q):
    """Hamilton products of (N, 4) quaternions [w, x, y, z]."""
    pw, px, py, pz = p.T
    qw, qx, qy, qz = q.T
    return np.column_stack([pw * qw - px * qx - py * qy - pz * qz, pw * qx + px * qw + py * qz - pz * qy,
                            pw * qy - px * qz + py * qw + pz * qx, pw * qz + px * qy - py * qx + pz * qw])


def _quat_mats(q):
    """C (N, 3, 3) of (N, 4) unit quaternions (attitude.quat_to_mat)."""
    w, x, y, z = q.T
    m = np.empty((len(q), 3, 3))
    m[:, 0, 0] = w * w + x * x - y * y - z * z
    m[:, 0, 1] = 2.0 * (x * y - w * z)
    m[:, 0, 2] = 2.0 * (x * z + w * y)
    m[:, 1, 0] = 2.0 * (x * y + w * z)
    m[:, 1, 1] = w * w - x * x + y * y - z * z
    m[:, 1, 2] = 2.0 * (y * z - w * x)
    m[:, 2, 0] = 2.0 * (x * z - w * y)
    m[:, 2, 1] = 2.0 * (y * z + w * x)
    m[:, 2, 2] = w * w - x * x - y * y + z * z
    return m


def error_drive_from_records(rec_quat_np, quat_np0, sources, lat, height=0.0, h=1.0):
    """`error_drive` without the motion: from the attitude C_p^n of the
    records alone (the firmware's ``quat_np``, (K, 4), and ``quat_np0`` at
    t = 0), for a ship at a fixed position. Over each interval the IMU's
    rotation against n is the rotation vector theta between the two
    records' attitudes; the interval's mean rate is omega_ip^p = theta / h +
    C_n^p omega_ie^n and its attitude the half-way one C_p^n(k) exp(theta/2),
    f^p = C_n^p [0, 0, g]. One sample per interval: what a record interval
    cannot resolve (a turn that starts inside it, the swing's curvature)
    is lost; `error_drive` from the motion is the reference."""
    q = np.vstack([np.asarray(quat_np0, dtype=float)[None, :], np.asarray(rec_quat_np, dtype=float)])
    conj = q[:-1] * np.array([1.0, -1.0, -1.0, -1.0])
    rel = _quat_mul(conj, q[1:])
    rel[rel[:, 0] < 0.0] *= -1.0
    r = np.linalg.norm(rel[:, 1:], axis=1)
    angle = 2.0 * np.arctan2(r, rel[:, 0])
    with np.errstate(invalid="ignore", divide="ignore"):
        k = np.where(r > 0.0, angle / np.where(r > 0.0, r, 1.0), 2.0)
    theta = k[:, None] * rel[:, 1:]                                   # rotation over the interval, in p
    half = np.column_stack([np.cos(0.25 * angle), np.where(r > 0.0, np.sin(0.25 * angle) / np.where(
        r > 0.0, r, 1.0), 0.25)[:, None] * rel[:, 1:]])                # exp(theta / 2)
    mat_pn = _quat_mats(_quat_mul(q[:-1], half))
    sin_lat = np.sin(lat)
    w_ie = earth.OMEGA_IE * np.array([0.0, np.cos(lat), sin_lat])
    g_up = np.array([0.0, 0.0, earth.normal_gravity(sin_lat, height)])
    omega_p = theta / h + np.einsum("kji,j->ki", mat_pn, w_ie)
    force_p = np.einsum("kji,j->ki", mat_pn, g_up)
    n = len(mat_pn)
    return _drive_from_samples(mat_pn.reshape(n, 1, 3, 3), omega_p.reshape(n, 1, 3), force_p.reshape(n, 1, 3),
                               np.ones((n, 1)), sources)


@dataclass
class ErrorBudget:
    """Each source's contribution to the errors of a run (linear model)."""
    time_s: np.ndarray          #: (N,) [s]
    names: list                 #: the sources, in order
    states: np.ndarray          #: (S, N, 7): phi E N U [rad], dv E N [m/s], dL, dlambda [rad]
    lat: float
    height: float
    eps_n_mean: np.ndarray      #: (S, 3) each source's gyro error in n over the run, mean [rad/s]
    nabla_n_mean: np.ndarray    #: (S, 3) the accelerometers', mean [m/s^2]
    noise_cov: np.ndarray = None  #: (N, 7, 7) covariance the sensors' noise drives (None: no noise)

    def errors(self, name=None):
        """StaticErrors of one source (None: the sum of all of them), signed
        as pyins.metrics.NavErrors."""
        x = self.states.sum(axis=0) if name is None else self.states[self.names.index(name)]
        rm, rn = earth.principal_radii(np.sin(self.lat))
        north = x[:, 5] * (rm + self.height)
        east = x[:, 6] * (rn + self.height) * np.cos(self.lat)
        return StaticErrors(time_s=self.time_s, att_n_rad=x[:, :3], vel_n_mps=x[:, 3:5], north_m=north,
                            east_m=east, horizontal_m=np.hypot(north, east))

    def position_scale(self):
        """(north, east) metres per radian of (dL, dlambda)."""
        rm, rn = earth.principal_radii(np.sin(self.lat))
        return rm + self.height, (rn + self.height) * np.cos(self.lat)

    def noise(self):
        """The noise's 1 sigma of every error (a StaticErrors of standard
        deviations; horizontal_m = sqrt(sigma_N^2 + sigma_E^2), the RMS of the
        horizontal error), or None without noise."""
        if self.noise_cov is None:
            return None
        sd = np.sqrt(np.diagonal(self.noise_cov, axis1=1, axis2=2))
        kn, ke = self.position_scale()
        north, east = sd[:, 5] * kn, sd[:, 6] * ke
        return StaticErrors(time_s=self.time_s, att_n_rad=sd[:, :3], vel_n_mps=sd[:, 3:5], north_m=north,
                            east_m=east, horizontal_m=np.hypot(north, east))

    def noise_position_cov(self):
        """(N, 2, 2) covariance of the (north, east) error [m^2] the noise drives."""
        kn, ke = self.position_scale()
        scale = np.diag([kn, ke])
        return scale @ self.noise_cov[:, 5:7, 5:7] @ scale


def error_budget(motion, result, errors, config=None, nodes=4, kinks=True, from_records=False,
                 keep_every=1, noise=None):
    """The error budget of a closed-loop run: each source's signed
    contribution to the position, velocity and attitude errors over time.

    ``motion``: the run's ship (a fixed-position pyins.sim profile: static,
    swing, heading swing); ``result``: its pyins.records.FilResult (the
    plant's records give the true table angle and rate, evenly spaced);
    ``errors``: a SensorErrors, split into `SOURCES` (`split_errors`), or a
    dict {name: SensorErrors} of one's own split; ``config``: the firmware
    configuration the run started from (``table_angle_rad``; its initial
    state against the truth is the source "initial", `initial_state_errors`).
    ``from_records``: drive from the firmware's recorded attitude instead of
    the motion (`error_drive_from_records`). ``noise``: (gyro_arw,
    accel_vrw) whose 1 sigma to propagate (`noise_covariance`; None: none).
    Returns an ErrorBudget whose times are the records' (every
    ``keep_every``-th).
    """
    config = config or {}
    srcs = split_errors(errors) if not isinstance(errors, dict) else dict(errors)
    names = list(srcs)
    sensor_sets = [srcs[n] for n in names]
    lat, _, height, _, euler0 = initial_truth(motion)
    t_rec = np.asarray(result.plant["tick"], dtype=float) * result.dt
    alpha0 = float(config.get("table_angle_rad", 0.0))
    if from_records:
        q0 = attitude.mat_to_quat(attitude.euler_to_mat(np.asarray(config.get("euler_b_rad", euler0), dtype=float))
                                  @ attitude.rot_z(alpha0))
        eps, nab = error_drive_from_records(result.outputs["quat_np"], q0, sensor_sets, lat, height,
                                            h=float(t_rec[0]))
    elif sensor_sets:
        table = table_history(t_rec, result.plant["alpha_rad"], result.plant["rate_rad_s"], alpha0, 0.0, kinks)
        eps, nab = error_drive(motion, table, sensor_sets, nodes=nodes)
    else:
        eps = nab = np.zeros((0, len(t_rec), 3))
    x0 = np.zeros((len(names), 7))
    init = initial_state_errors(motion, config)
    if np.any(init != 0.0):
        names.append(INITIAL)
        eps = np.concatenate([eps, np.zeros((1,) + eps.shape[1:])])
        nab = np.concatenate([nab, np.zeros((1,) + nab.shape[1:])])
        x0 = np.vstack([x0, init])
    h = float(t_rec[0])
    times, states = propagate_errors(lat, height, h, eps, nab, x0, keep_every)
    noise_cov = None
    if noise is not None and (noise[0] > 0.0 or noise[1] > 0.0):
        _, noise_cov = noise_covariance(lat, height, h, len(t_rec), noise[0], noise[1], keep_every)
    return ErrorBudget(time_s=times, names=names, states=states, lat=lat, height=height,
                       eps_n_mean=eps.mean(axis=1), nabla_n_mean=nab.mean(axis=1), noise_cov=noise_cov)


# ---------------------------------------------------------------------------
# The error budget of a scenario's run, and its check against the firmware
# ---------------------------------------------------------------------------
#: The configuration fields that carry a scenario's initial errors (pyins.scenario.build.initial_errors).
_INITIAL_FIELDS = ("lat_rad", "lon_rad", "height_m", "vel_n_mps", "euler_b_rad")


def deterministic(errors):
    """``errors`` without noise and quantisation (what the budget models)."""
    return replace(errors, gyro_arw=0.0, accel_vrw=0.0, gyro_quantum=0.0, accel_quantum=0.0)


def compare_with_run(model, nav):
    """How far the model's position errors (StaticErrors) lie from a run's
    (pyins.metrics.NavErrors) at the model's times: ``rel_max`` = max over
    the run of |(dN, dE) model - run| over the run's largest horizontal
    error; ``rel_final`` the same at the end over the run's final one,
    ``rel_24h`` at 24 h over the run's error then (None if not reached);
    ``rel_level``, ``rel_heading``, ``rel_velocity`` the same as rel_max for
    (phi_E, phi_N), phi_U and (dv_E, dv_N)."""
    idx = np.searchsorted(nav.time_s, model.time_s - 1e-6)
    if np.any(idx >= len(nav.time_s)) or np.any(np.abs(nav.time_s[idx] - model.time_s) > 1e-6):
        raise ValueError("compare_with_run: the model's times are not among the run's records")
    diff = np.hypot(model.north_m - nav.north_m[idx], model.east_m - nav.east_m[idx])
    run_h = np.hypot(nav.north_m, nav.east_m)

    def rel(d, r):
        """max |model - run| over max |run| of one quantity (rows: its components)."""
        top = np.linalg.norm(r, axis=1).max()
        return float(np.linalg.norm(d, axis=1).max() / top) if top > 0 else float("inf")
    att, vel = nav.att_n_rad[idx], nav.vel_n_mps[idx, :2]
    at_24h = np.flatnonzero(np.abs(model.time_s - 86400.0) < 1e-6)
    rel_24h = (float(diff[at_24h[0]] / run_h[idx][at_24h[0]]) if len(at_24h) and run_h[idx][at_24h[0]] > 0
               else None)
    return dict(rel_max=float(diff.max() / run_h.max()) if run_h.max() > 0 else float("inf"),
                rel_24h=rel_24h,
                rel_final=float(diff[-1] / run_h[-1]) if run_h[-1] > 0 else float("inf"),
                diff_max_m=float(diff.max()), run_max_m=float(run_h.max()), run_final_m=float(run_h[-1]),
                rel_level=rel(model.att_n_rad[:, :2] - att[:, :2], att[:, :2]),
                rel_heading=rel(model.att_n_rad[:, 2:] - att[:, 2:], att[:, 2:]),
                rel_velocity=rel(model.vel_n_mps - vel, vel))


#: Below this largest horizontal error [m] of the firmware's run a source is not
#: judged relatively (10 % of almost nothing says nothing): the model must then lie
#: within 10 % of it (0.1 m) over the run. The error-free firmware stays below 0.2 mm
#: in 72 h on seed 002's swings, far below it; a uniform accelerometer scale factor
#: (seed 002: 10 ppm on every axis) acts along the held vertical only and leaves
#: nothing horizontal (model and firmware both < 1 mm).
BUDGET_FLOOR_M = 1.0


def budget_verdict(row, tolerance=0.10):
    """(within, text) of a checked row of `run_budget`: its ``rel_max`` within
    ``tolerance``, or, for a run below BUDGET_FLOOR_M, its largest difference
    within ``tolerance`` x BUDGET_FLOOR_M."""
    if row["run_max_m"] >= BUDGET_FLOOR_M:
        return row["rel_max"] <= tolerance, f"{100 * row['rel_max']:.2f} %"
    return (row["diff_max_m"] <= tolerance * BUDGET_FLOOR_M,
            f"({row['diff_max_m']:.2g} m; run < {BUDGET_FLOOR_M:g} m)")


def _row(source, model, nav=None, check=None):
    row = dict(source=source, model_north_m=float(model.north_m[-1]), model_east_m=float(model.east_m[-1]),
               model_final_m=float(model.horizontal_m[-1]), model_max_m=float(model.horizontal_m.max()),
               model_heading_final_rad=float(model.att_n_rad[-1, 2]))
    if nav is not None:
        row.update(fil_north_m=float(nav.north_m[-1]), fil_east_m=float(nav.east_m[-1]),
                   fil_final_m=float(nav.horizontal_m[-1]), fil_max_m=float(nav.horizontal_m.max()),
                   fil_heading_final_rad=float(nav.att_n_rad[-1, 2]), **check)
    return row


#: The ship profiles the model holds for: at a fixed position (pyins.sim).
_FIXED_MOTIONS = ("Static", "Swing", "HeadingSwing", "NarrowbandYaw")


def outside_model(spec):
    """Why the linear model cannot stand for a scenario's run (a
    pyins.scenario.RunSpec), or None when it can: it navigates from t = 0
    (no alignment phase), unaided and undamped (no external reference, no
    damping or integrated mode), with the vertical channel held, on a ship
    at a fixed position."""
    cfg = spec.config
    if cfg.get("coarse_ticks") or cfg.get("fine_ticks"):
        return ("the error budget's linear model navigates from t = 0: the scenario's "
                "firmware.coarse_time and firmware.fine_time must be 0 (no alignment phase)")
    if cfg.get("vertical_mode", 0) != 0:
        return ("the error budget's linear model holds the vertical channel: the scenario's "
                "firmware.vertical_mode must be \"hold\"")
    if getattr(spec, "refs", None) is not None and len(spec.refs):
        return ("the error budget's linear model is of unaided navigation: the scenario has external "
                "references ([references]); damping and the integrated filter are outside it")
    if cfg.get("nav_mode") not in (None, abi.PYINS_NAV_UNDAMPED, abi.PYINS_NAV_AUTO):
        return ("the error budget's linear model is of undamped navigation: the scenario's "
                "firmware.nav_mode must be \"undamped\" (or \"auto\" without references)")
    if type(spec.motion).__name__ not in _FIXED_MOTIONS:
        return (f"the error budget's linear model is of a ship at a fixed position; the scenario's "
                f"motion is a {type(spec.motion).__name__} (a moving base is outside it)")
    return None


def steered_table(spec):
    """True when the scenario's table stops where the firmware's own heading
    says (the flexible schemes, heading isolation, a custom cycle with a
    flexible step): the table's history, which the model takes from one run,
    then depends on the unit's errors, and a budget driven by another run's
    history is an approximation (docs/campaigns.md, "Draws through the error
    budget")."""
    scheme = spec.config.get("index_scheme", abi.PYINS_INDEX_NONE)
    if scheme in (abi.PYINS_INDEX_FLEXIBLE_TWO, abi.PYINS_INDEX_FLEXIBLE_DERIVED, abi.PYINS_INDEX_HEADING_ISOLATION):
        return True
    return scheme == abi.PYINS_INDEX_CUSTOM and any(step[1] != 1 for step in spec.config.get("index_steps", ()))


def run_budget(spec, check=False, duration_ticks=None, keep_every=10, progress=None, phase=None, on_row=None):
    """The error budget of a scenario's run (a pyins.scenario.RunSpec),
    optionally checked against the firmware one source at a time.

    One closed-loop run with every deterministic error of ``spec`` (noise
    and quantisation left out: `deterministic`) and its initial errors gives
    the table's history and the run the model's sum is held to; the model
    splits it by source (`error_budget`). With ``check`` each source also
    runs alone (the others zero, the initial state the truth unless the
    source is "initial") and the model, driven by that run's own table
    history, is compared with it (`compare_with_run`). The model holds for
    navigation from t = 0 with the vertical channel held, on a ship at a
    fixed position. Returns (rows, budget): one dict per source and one
    "sum" row (final north/east [m], final and max horizontal [m], and with
    ``check`` the run's and the relative differences); with noise in
    ``spec.errors`` a last row "noise": its 1 sigma (north, east, horizontal
    RMS; ``one_sigma`` True), which no single run is checked against.
    ``phase(i, n, text)`` is called before each of the n firmware runs,
    ``on_row(row)`` with each row as soon as it is known (the "sum" row
    after the sources).
    """
    cfg = dict(spec.config)
    refusal = outside_model(spec)
    if refusal is not None:
        raise ValueError(refusal)
    n = duration_ticks or spec.duration_ticks
    shortest = 2 * keep_every * max(1, spec.every or 1)   # the model keeps every keep_every-th record
    if n < shortest:
        raise ValueError(f"the duration ({n * spec.dt:g} s) is too short for the error budget: it needs "
                         f"at least {shortest * spec.dt:g} s ({2 * keep_every} records of record_every "
                         f"{max(1, spec.every or 1) * spec.dt:g} s; --hours or --set duration)")
    errs = deterministic(spec.errors)
    count = [0]
    sources = split_errors(errs)
    total_runs = 1 + (len(sources) + int(np.any(initial_state_errors(spec.motion, cfg) != 0.0)) if check else 0)

    def run(errors, config, text):
        if phase is not None:
            phase(count[0], total_runs, text)
        res = fil.run_fil(spec.motion, n, config=config, errors=errors, table=spec.table, every=spec.every)
        count[0] += 1
        if progress is not None:
            progress()
        return res

    def add(row):
        rows.append(row)
        if on_row is not None:
            on_row(row)
    rows = []
    base = run(errs, cfg, "every error together")
    budget = error_budget(spec.motion, base, errs, cfg, keep_every=keep_every,
                          noise=(spec.errors.gyro_arw, spec.errors.accel_vrw))
    clean = {k: v for k, v in cfg.items() if k not in _INITIAL_FIELDS}
    for name in budget.names:
        model = budget.errors(name)
        if not check:
            add(_row(name, model))
            continue
        if name == INITIAL:
            res = run(SensorErrors(), cfg, f"{name} alone")
            own = error_budget(spec.motion, res, {}, cfg, keep_every=keep_every).errors(INITIAL)
        else:
            res = run(sources[name], clean, f"{name} alone")
            own = error_budget(spec.motion, res, {name: sources[name]}, clean, keep_every=keep_every).errors(name)
        nav = metrics.nav_errors(res)
        add(_row(name, own, nav, compare_with_run(own, nav)))
    total = budget.errors()
    nav = metrics.nav_errors(base)
    add(_row("sum", total, nav, compare_with_run(total, nav)))
    sd = budget.noise()
    if sd is not None:      # not a signed share: the 1 sigma of one noise draw's (ARW, VRW)
        add(dict(_row(NOISE, sd), one_sigma=True))
    return rows, budget
