#!/usr/bin/env python3
"""What the turntable makes observable in the integrated navigation filter at
sea: a covariance analysis of the firmware's filter along a
simulated voyage with GNSS, and the firmware's bias estimates against the
truth (docs/observability.md).

    .venv/bin/python tools/observability_nav.py [--hours 24] [--est-hours 6] [--seeds 6]
                                               [--no-estimates] [--no-fil-check] [--gyro-states]
                                               [--noise filter|sensor] [--out docs/results]

The analysis is of the filter's 12 navigation and bias states (the seven
scale-factor and misalignment states of ABI 0.19 held at 0);
``--gyro-states`` runs it again with them at the scenario's priors
(docs/observability.md, section 5b).

~2.5-3 min with the defaults on a shared 2-core machine (the covariance
analysis ~1 min: 6 cases x 86,400 s of the mirror's filter; the firmware
runs ~1 min; the closed-loop check ~25 s).

1. The set-up is the built-in scenario ``voyage_gnss``'s (`setup_from_scenario`):
   its route (route seed 1 from 34.246 N, 108.910 E, the general sea
   state), its GNSS (1 Hz, 3 m white + a 2 m Gauss-Markov bias over 300 s,
   0.05 m/s), its filter settings (prior 1', 1', 10'; the firmware's
   defaults for the rest: 0.1 m/s, 10 m, 0.01 deg/h, 100 ug, a time update
   every nav_every_ticks = 100 ticks, Q from fine_gyro_arw 0.001 deg/sqrt(h)
   and fine_accel_vrw 10 ug/sqrt(Hz)), its initial errors and seed 002's
   sensor errors.
2. The table's profile is the firmware's own indexing state machine
   (the mirror `pyins.reference.indexing`) stepped through one cycle at the
   tick and repeated (`table_cycle`, `IndexedTable`), the table following
   its command. Cases: the IMU fixed (scheme none), seed 002's two-position
   scheme (the built-in's), and continuous rotation (a custom scheme:
   +8 turns, -8 turns at the default 6 deg/s with a one-tick stop between,
   the longest move the firmware's check accepts); each on the voyage with
   its turns and on a straight course (the same start, speed and sea, no
   turn, no speed change).
3. The covariance analysis (`covariance`) runs the mirror's own
   nav_filter.init / predict / update_pair on the truth: once a second the
   truth's mean specific force over the second (f^n = dv/dt + (2 w_ie +
   w_en) x v - g, the Coriolis and gravity terms at the two ends' mean), its
   C_p^n = C_b^n Rz(alpha) at the second's end (predict takes the mean of
   the two ends, as the firmware does) and its latitude and velocity, then
   the GNSS position pair and the velocity pair with the variances the
   firmware is told (the simulated receiver's own sigmas: its 2 m
   Gauss-Markov bias is added to the 3 m as if it were white, which it is
   not: the analysis is a little optimistic on position). No gate, no
   outage: every fix is used. ``--noise sensor`` replaces the filter's Q by
   the simulated sensors' own densities (0.0005 deg/sqrt(h), 5 ug/sqrt(Hz)).
4. The estimates (`estimates`) are the native firmware's, in the open loop
   (the table driven along the same profile, the firmware told scheme none
   so that it reads the encoder and commands nothing), on the same voyage
   at 100 Hz with the built-in's GNSS, for several sensor-error sets at
   once (the ship's states at the quadrature nodes are computed once a
   chunk and shared: the voyage's track costs ~5 s an hour, the firmware
   0.3 s). The error sets: seed 002's biases and noise alone, its full
   set, and the biases plus each unmodelled term in turn (which one moves
   the accelerometer-bias estimate). ``--seeds N``: the two-position table
   with the biases alone over N noise and receiver seeds, the receiver with
   and without its Gauss-Markov bias, the RMS of the estimate errors beside
   the analysis's sigma. The built-in's configuration runs in the closed
   loop too (`pyins.fil.run_fil`, the firmware commanding the table through
   the plant; ``--no-fil-check`` skips it): its estimates against the open
   loop's.

Prints the tables; writes observability_nav.json and observability_nav.png
to --out.
"""
import argparse
import json
import math
import os
import time
from dataclasses import dataclass, replace

import numpy as np

try:
    import tomllib
except ImportError:            # Python 3.10, as pyins.scenario
    import tomli as tomllib

from pyins import contract, fil, metrics, scenario, sim
from pyins import engine as engines
from pyins.aiding import Aider
from pyins.reference import abi, config as fwconfig, earth, indexing, nav_filter
from pyins.scenario.build import initial_config, initial_errors
from pyins.sim import references, voyage
from pyins.sim.turntable import TableMotion
from pyins.units import ARCSEC_TO_RAD, DEG_TO_RAD, DT, G0, TICK_HZ

DPH = DEG_TO_RAD / 3600.0          #: 1 deg/h [rad/s]
UG = 1e-6 * G0                     #: 1 ug [m/s^2]
STATE_NAMES = ("phi_E", "phi_N", "phi_U", "dv_E", "dv_N", "dp_E", "dp_N",
               "eps_x", "eps_y", "eps_z", "nabla_x", "nabla_y")
#: with the seven scale-factor and misalignment states (ABI 0.19; held at 0 unless --gyro-states)
ALL_STATE_NAMES = STATE_NAMES + ("m_xz", "m_yz", "k_z", "k_x", "k_y", "m_xy", "m_yx")
N_FRAME_NAMES = ("eps_E", "eps_N", "eps_U", "nabla_E", "nabla_N")
CHECK_HOURS = (1.0, 6.0, 24.0)


# ---------------------------------------------------------------------------
# 1. The set-up: the built-in scenario's voyage, GNSS and filter settings
# ---------------------------------------------------------------------------
@dataclass
class Setup:
    lat: float                  #: start [rad]
    lon: float                  #: start [rad]
    height: float               #: [m]
    route_seed: int
    sea: object                 #: the sea state's name (or None)
    prm: nav_filter.Params      #: the filter's settings as the firmware starts it
    gnss: dict                  #: pyins.sim.references.gnss keyword arguments
    phi0: np.ndarray            #: initial attitude error E, N, U [rad]
    errors: sim.SensorErrors    #: the scenario's sensor errors (seed 002)
    seed: int                   #: the sensors' noise seed
    scheme: str                 #: the scenario's indexing scheme
    gyro_states: tuple = (0.0, 0.0, 0.0, 0.0)   #: the scenario's nav_table_scale_sigma, nav_table_mis_sigma,
                                                #: nav_level_scale_sigma, nav_level_mis_sigma (ABI 0.19)


def _or(value, default):
    return default if value is None else value


def setup_from_scenario(name="voyage_gnss"):
    """The `Setup` of a built-in scenario (or a .toml file) with a voyage and
    GNSS. Its settings do not depend on its duration, which is cut to a
    minute before it is loaded (loading builds and checks the voyage: ~4 s
    for voyage_gnss's 2 h)."""
    text, path = scenario.read_toml_source(name, scenario.builtin_path)
    data = tomllib.loads(text)
    data["duration"] = "1 min"
    r = scenario.Scenario(text, data, str(path), path.stem).resolved()
    m, fw, s = r["motion"], r["firmware"], r["sensors"]
    cfg = fwconfig.config_default()
    cfg.update(fine_gyro_arw=_or(fw["fine_gyro_arw_rad_sqrt_s"], 0.0),
               fine_accel_vrw=_or(fw["fine_accel_vrw_mps_sqrt_s"], 0.0),
               fine_sigma0_att_rad=np.array(_or(fw["fine_sigma0_att_rad"], [0.0, 0.0, 0.0]), dtype=float),
               fine_sigma0_gyro=_or(fw["fine_sigma0_gyro_rad_s"], 0.0),
               fine_sigma0_accel=_or(fw["fine_sigma0_accel_mps2"], 0.0))
    if fw["fine_states"] is not None:
        cfg["fine_states"] = fw["fine_states"]
    cfg = fwconfig.config_resolved(cfg)
    # as firmware_nav.start_nav_filter builds it after no alignment (the scenario has none)
    if fw["coarse_time_s"] or fw["fine_time_s"]:
        raise ValueError(f"{name}: the analysis starts the filter as after no alignment; this scenario aligns")
    att = np.array([a if a > 0.0 else fwconfig.DEFAULT_FINE_SIGMA_ATT[i]
                    for i, a in enumerate(cfg["fine_sigma0_att_rad"])])
    prm = nav_filter.Params(dt=1.0 / cfg["tick_hz"], every=cfg["nav_every_ticks"],
                            reject_limit=cfg["nav_reject_limit"], gyro_arw=cfg["fine_gyro_arw"],
                            accel_vrw=cfg["fine_accel_vrw"], gate=cfg["nav_gate"], sigma0_att=att,
                            sigma0_vel=fwconfig.NAV_SIGMA0_VEL, sigma0_pos=fwconfig.NAV_SIGMA0_POS,
                            sigma0_gyro=cfg["fine_sigma0_gyro"], sigma0_accel=cfg["fine_sigma0_accel"])
    g = r["references"]["gnss"]
    gnss = dict(rate_hz=g["rate_hz"], pos_noise_m=g["pos_noise_m"], vel_noise_mps=g["vel_noise_mps"],
                bias_sigma_m=g["bias_sigma_m"], bias_tau_s=g["bias_tau_s"], seed=g["seed"])
    errors = sim.SensorErrors(
        gyro_bias=np.array(s["gyro_bias_rad_s"]), gyro_scale=np.array(s["gyro_scale"]),
        gyro_misalignment=np.array(s["gyro_misalignment_rad"]), gyro_arw=s["gyro_arw_rad_sqrt_s"],
        gyro_quantum=s["gyro_quantum_rad"], accel_bias=np.array(s["accel_bias_mps2"]),
        accel_scale=np.array(s["accel_scale"]), accel_misalignment=np.array(s["accel_misalignment_rad"]),
        accel_vrw=s["accel_vrw_mps_sqrt_s"], accel_quantum=s["accel_quantum_mps"])
    phi0 = np.array(_or(r["initial_errors"]["phi_rad"], [0.0, 0.0, 0.0]), dtype=float)
    return Setup(lat=m["lat_rad"], lon=m["lon_rad"], height=m["height_m"], route_seed=m["route_seed"],
                 sea=None if m["sea"] == "none" else m["sea"], prm=prm, gnss=gnss, phi0=phi0, errors=errors,
                 seed=r["seed"], scheme=r["indexing"]["scheme"],
                 gyro_states=tuple(float(_or(fw[k], 0.0)) for k in (
                     "nav_table_scale_sigma", "nav_table_mis_sigma_rad", "nav_level_scale_sigma",
                     "nav_level_mis_sigma_rad")))


def make_voyage(setup, hours, straight=False, dt=DT):
    """The scenario's voyage of ``hours`` (route seed, start, sea), or with
    ``straight`` its first course and speed held throughout. ``dt`` is the
    track's tick: the legs are whole seconds, and a 1-s track gives the same
    states at whole seconds as the 100-Hz one, 100 times cheaper (checked
    in tests/atsea/test_observability.py)."""
    yaw0, speed0, legs = voyage.voyage_segments(hours, seed=setup.route_seed, dt=dt)
    if straight:
        legs = [voyage.cruise(int(round(hours * 3600.0)), dt)]
    return sim.Voyage(setup.lat, setup.lon, setup.height, yaw0, legs, speed0=speed0, dt=dt, sea=setup.sea)


# ---------------------------------------------------------------------------
# 2. The table's profiles: the firmware's indexing machine, one cycle, repeated
# ---------------------------------------------------------------------------
def scheme_steps(scheme, stop_ticks=None, tick_hz=TICK_HZ):
    """The indexing steps of a case: None for the IMU fixed; the firmware's
    preset for 'two_position' (its default 300 s stops); for 'continuous'
    the custom scheme of continuous rotation the firmware accepts: +8 turns,
    -8 turns (its check's limit, 16 pi), a one-tick stop between."""
    if scheme == "fixed":
        return None
    if scheme == "two_position":
        stop = stop_ticks or fwconfig.DEFAULT_STOP_S * tick_hz
        return indexing.preset_steps(abi.PYINS_INDEX_TWO_POSITION, stop)
    if scheme == "continuous":
        return [indexing.Step(1, indexing.KIND_FIXED, 16.0 * math.pi),
                indexing.Step(1, indexing.KIND_FIXED, -16.0 * math.pi)]
    raise ValueError(f"unknown case scheme {scheme!r}")


def table_cycle(steps, dt=DT):
    """The commanded table angle at the end of each tick of one cycle of the
    mirror's indexing machine (fixed moves only: the headings it reads are
    not used), from 0, the table following its command; the cycle ends with
    its last move's arrival."""
    prm = indexing.Params(steps=steps, rate=fwconfig.DEFAULT_INDEX_RATE, accel=fwconfig.DEFAULT_INDEX_ACCEL,
                          delta=fwconfig.DEFAULT_INDEX_DELTA, max_flex=fwconfig.DEFAULT_INDEX_MAX_FLEX,
                          tolerance=fwconfig.DEFAULT_INDEX_TOLERANCE, jump=fwconfig.DEFAULT_INDEX_JUMP,
                          timeout_ticks=int(fwconfig.DEFAULT_INDEX_TIMEOUT_S / dt), dt=dt)
    if any(s.kind != indexing.KIND_FIXED for s in steps):
        raise ValueError("table_cycle: fixed moves only")
    ix = indexing.init(prm, 0.0)
    out, moves = [], 0
    while moves < len(steps):
        step = ix.step
        indexing.update(ix, ix.cmd_angle, 0.0, 1.0)
        out.append(ix.cmd_angle)
        moves += ix.step != step
    return np.array(out)


class IndexedTable(TableMotion):
    """A table along a repeated indexing cycle: the angle at the end of tick
    k (k >= 1) is cycle[(k - 1) mod L] plus the cycle's net turn times the
    cycles completed, 0 at t = 0, linear inside each tick (the command's
    constant rate over the tick)."""

    def __init__(self, cycle, dt=DT):
        self.cycle = np.asarray(cycle, dtype=float)
        self.dt = float(dt)
        self.net = float(self.cycle[-1])

    def angle_end(self, k):
        """The angle at the end of tick k (int array, k >= 0)."""
        k = np.asarray(k, dtype=np.int64)
        j = np.maximum(k - 1, 0)
        n = len(self.cycle)
        a = self.cycle[j % n] + self.net * (j // n)
        return np.where(k <= 0, 0.0, a)

    def state(self, t, t_lo=None):
        t = np.asarray(t, dtype=float)
        tt = t if t_lo is None else t + np.asarray(t_lo, dtype=float)
        u = tt / self.dt
        k = np.floor(u).astype(np.int64)
        a0, a1 = self.angle_end(k), self.angle_end(k + 1)
        return a0 + (u - k) * (a1 - a0), (a1 - a0) / self.dt


def table_profile(scheme, dt=DT):
    steps = scheme_steps(scheme, tick_hz=int(round(1.0 / dt)))
    return None if steps is None else IndexedTable(table_cycle(steps, dt), dt)


# ---------------------------------------------------------------------------
# 3. The truth once a second
# ---------------------------------------------------------------------------
def truth_per_interval(motion, table, n_intervals, interval_s):
    """C_p^n at the interval ends (n + 1, 3, 3), the mean specific force in n
    over each interval (n, 3), the Motion (nav_filter.Motion) at each end,
    the table angle at each end and the mean rate w_ip^p over each interval
    (n, 3): the rotation vector of C_p^n(k)^T C_p^n(k + 1) over the interval
    plus w_in^n at the two ends' mean, turned into p by their mean attitude."""
    t = np.arange(n_intervals + 1, dtype=float) * interval_s
    st = motion.state(t)
    cbn = sim.euler_to_mat(st.euler)
    alpha = np.zeros(len(t)) if table is None else table.state(t)[0]
    ca, sa = np.cos(alpha), np.sin(alpha)
    rz = np.zeros((len(t), 3, 3))
    rz[:, 0, 0], rz[:, 0, 1], rz[:, 1, 0], rz[:, 1, 1], rz[:, 2, 2] = ca, -sa, sa, ca, 1.0
    cpn = cbn @ rz
    s, c = np.sin(st.lat), np.cos(st.lat)
    rm, rn = earth.principal_radii(s)
    rm_h, rn_h = rm + st.height, rn + st.height
    v = st.vel_n
    w = earth.OMEGA_IE
    # f^n = a^n + (2 w_ie + w_en) x v - g^n (the simulator's, pyins.sim.imu.body_rate_and_force)
    om = np.stack([-v[:, 1] / rm_h, 2.0 * w * c + v[:, 0] / rn_h, 2.0 * w * s + v[:, 0] * (s / c) / rn_h], axis=1)
    extra = np.cross(om, v)
    extra[:, 2] += earth.normal_gravity(s, st.height)
    f_n = np.diff(v, axis=0) / interval_s + 0.5 * (extra[1:] + extra[:-1])
    motions = [nav_filter.Motion(float(s[k]), float(c[k]), float(rm_h[k]), float(rn_h[k]), float(v[k, 0]),
                                 float(v[k, 1])) for k in range(len(t))]
    # w_np^p from the relative rotation over each interval (log map of a rotation < pi)
    d = np.einsum("kji,kjl->kil", cpn[:-1], cpn[1:])
    ang = np.arccos(np.clip(0.5 * (np.trace(d, axis1=1, axis2=2) - 1.0), -1.0, 1.0))
    axis = np.stack([d[:, 2, 1] - d[:, 1, 2], d[:, 0, 2] - d[:, 2, 0], d[:, 1, 0] - d[:, 0, 1]], axis=1)
    scale = np.where(ang > 1e-12, ang / (2.0 * np.sin(np.maximum(ang, 1e-12))), 0.5)
    w_np = axis * scale[:, None] / interval_s
    w_in = np.stack([-v[:, 1] / rm_h, w * c + v[:, 0] / rn_h, w * s + v[:, 0] * (s / c) / rn_h], axis=1)
    c_mid = 0.5 * (cpn[:-1] + cpn[1:])
    w_p = w_np + np.einsum("kji,kj->ki", c_mid, 0.5 * (w_in[:-1] + w_in[1:]))
    return cpn, f_n, motions, alpha, w_p


# ---------------------------------------------------------------------------
# 4. The covariance analysis with the mirror's filter
# ---------------------------------------------------------------------------
def gnss_variances(setup, motion):
    """(r_pos (2,), r_vel (2,)): the variances the firmware is told, from the
    simulated receiver's own records (pyins.sim.references.gnss)."""
    g = references.gnss(motion, 2.0, dt=DT, **setup.gnss)
    pos = g.refs[g.refs["kind"] == abi.PYINS_REF_GNSS_POS][0]["sigma"]
    vel = g.refs[g.refs["kind"] == abi.PYINS_REF_GNSS_VEL][0]["sigma"]
    return np.asarray(pos[:2]) ** 2, np.asarray(vel[:2]) ** 2


@dataclass
class Covariance:
    time_s: np.ndarray          #: (n + 1,)
    sigma: np.ndarray           #: (n + 1, 12) sqrt(diag P) after each second's fixes
    sigma_pred: np.ndarray      #: (n + 1, 12) the same before them (after the time update): what the
                                #: firmware's record of that tick carries (a fix of tick T is applied after
                                #: tick T's record)
    sigma0: np.ndarray          #: (19,): 0 for the states not modelled
    sigma_n: np.ndarray         #: (n + 1, 5) eps_E, eps_N, eps_U, nabla_E, nabla_N (projected with C_p^n)
    p_at: dict                  #: hour -> P (12, 12) at the check times
    alpha: np.ndarray           #: the table angle at the interval ends [rad]


def covariance(setup, motion, table, hours, noise="filter", check_hours=CHECK_HOURS, gyro_states=False):
    """The filter's covariance along ``motion`` with ``table`` for ``hours``,
    with the mirror's own init / predict / update_pair (module docstring).
    ``gyro_states``: the seven scale-factor and misalignment states (ABI
    0.19) with the scenario's priors, driven by the truth's mean rates;
    else held at 0 (the 12 states of the figures in docs/observability.md)."""
    prm = setup.prm
    if gyro_states:
        ts, tm, ls, lm = setup.gyro_states
        prm = replace(prm, table_scale=ts, table_mis=tm, level_scale=ls, level_mis=lm)
    if noise == "sensor":
        prm = replace(prm, gyro_arw=setup.errors.gyro_arw, accel_vrw=setup.errors.accel_vrw)
    interval = prm.every * prm.dt
    if abs(interval * setup.gnss["rate_hz"] - 1.0) > 1e-9:
        raise ValueError("the analysis takes one GNSS fix per time update")
    n = int(round(hours * 3600.0 / interval))
    cpn, f_n, motions, alpha, w_p = truth_per_interval(motion, table, n, interval)
    r_pos, r_vel = gnss_variances(setup, motion)
    f = nav_filter.init(prm, cpn[0])
    sigma = np.empty((n + 1, nav_filter.STATES))
    sigma_pred = np.empty((n + 1, nav_filter.STATES))
    sigma_n = np.empty((n + 1, 5))
    zero = (0.0, 0.0)
    want = {int(round(h * 3600.0 / interval)): h for h in check_hours if h <= hours}
    p_at = {}

    def record(k):
        p = f.p
        sigma[k] = np.sqrt(np.diag(p))
        c = cpn[k]
        pe = c @ p[nav_filter.EPS:nav_filter.EPS + 3, nav_filter.EPS:nav_filter.EPS + 3] @ c.T
        c2 = c[:2, :2]
        pa = c2 @ p[nav_filter.NABLA:nav_filter.NABLA + 2, nav_filter.NABLA:nav_filter.NABLA + 2] @ c2.T
        sigma_n[k] = np.sqrt(np.concatenate([np.diag(pe), np.diag(pa)]))
        if k in want:
            p_at[want[k]] = p.copy()

    record(0)
    sigma_pred[0] = sigma[0]
    for k in range(1, n + 1):
        # the ticks' specific-force increments gathered (their sum over the interval)
        f.dv_sum = f_n[k - 1] * interval
        f.dtheta_sum = w_p[k - 1] * interval
        f.ticks = prm.every
        nav_filter.predict(f, motions[k], cpn[k])
        sigma_pred[k] = np.sqrt(np.diag(f.p))
        nav_filter.update_pair(f, nav_filter.POS, zero, r_pos)
        nav_filter.update_pair(f, nav_filter.VEL, zero, r_vel)
        nav_filter.reset_feedback(f)
        if not f.healthy:
            raise RuntimeError(f"P lost its positive diagonal at {k * interval} s")
        record(k)
    s0 = sigma[0].copy()
    return Covariance(time_s=np.arange(n + 1) * interval, sigma=sigma, sigma_pred=sigma_pred, sigma0=s0,
                      sigma_n=sigma_n,
                      p_at=p_at, alpha=alpha)


def least_observed(cov, hour, count=3):
    """The ``count`` directions of P normalised by the prior that shrank least
    (eigenvalues of D0^-1 P D0^-1, D0 = diag(sigma0)), each with its states
    of weight > 0.3: [(sqrt(eigenvalue), {state: component})]."""
    # the states with a prior (those not modelled, held at 0, are left out)
    live = np.flatnonzero(cov.sigma0 > 0.0)
    names = [ALL_STATE_NAMES[j] for j in live]
    d = 1.0 / cov.sigma0[live]
    pn = cov.p_at[hour][np.ix_(live, live)] * np.outer(d, d)
    val, vec = np.linalg.eigh(pn)
    out = []
    for i in np.argsort(val)[::-1][:count]:
        v = vec[:, i] * np.sign(vec[np.argmax(np.abs(vec[:, i])), i])
        out.append((float(np.sqrt(max(val[i], 0.0))),
                    {names[j]: round(float(v[j]), 2) for j in np.argsort(-np.abs(v)) if abs(v[j]) > 0.3}))
    return out


CASES = (("fixed", False), ("two_position", False), ("continuous", False),
         ("fixed", True), ("two_position", True), ("continuous", True))


def case_label(scheme, straight):
    return f"{scheme}, {'straight' if straight else 'turns'}"


# ---------------------------------------------------------------------------
# 5. The firmware's estimates against the truth
# ---------------------------------------------------------------------------
class _SharedStates:
    """A motion whose states at the quadrature nodes of a chunk are computed
    once and handed to every table profile of the chunk (`clear` between
    chunks): exact_increments asks for the same times for each."""

    def __init__(self, motion):
        self.motion = motion
        self.cache = {}

    def clear(self):
        self.cache = {}

    def state(self, t, t_lo=None):
        key = (len(t), float(t[0]), float(t[-1]), None if t_lo is None else float(np.asarray(t_lo).ravel()[0]))
        hit = self.cache.get(key)
        if hit is None:
            hit = self.cache[key] = self.motion.state(t, t_lo)
        return hit

    def __getattr__(self, name):
        return getattr(self.motion, name)


def error_sets(full):
    """The sensor-error sets the estimates are run with: seed 002's
    (``full``), its biases and noise alone, and the biases plus one of its
    unmodelled terms at a time."""
    z3, z33 = np.zeros(3), np.zeros((3, 3))
    bias = replace(full, gyro_scale=z3, gyro_misalignment=z33, accel_scale=z3, accel_misalignment=z33)
    mz = np.zeros((3, 3))
    mz[0, 2], mz[1, 2] = full.gyro_misalignment[0, 2], full.gyro_misalignment[1, 2]
    return {
        "bias": bias,
        "full": full,
        "bias+gyro_mis_xz_yz": replace(bias, gyro_misalignment=mz),
        "bias+gyro_mis_other": replace(bias, gyro_misalignment=full.gyro_misalignment - mz),
        "bias+gyro_scale": replace(bias, gyro_scale=full.gyro_scale.copy()),
        "bias+accel_scale_mis": replace(bias, accel_scale=full.accel_scale.copy(),
                                        accel_misalignment=full.accel_misalignment.copy()),
    }


ESTIMATE_RUNS = (("fixed", "bias"), ("fixed", "full"),
                 ("two_position", "bias"), ("two_position", "full"), ("two_position", "bias+gyro_mis_xz_yz"),
                 ("two_position", "bias+gyro_mis_other"), ("two_position", "bias+gyro_scale"),
                 ("two_position", "bias+accel_scale_mis"),
                 ("continuous", "bias"), ("continuous", "full"))


def estimates(setup, motion, hours, runs=ESTIMATE_RUNS, chunk_ticks=60_000, engine="native", every=100,
              gnss_refs=None):
    """The firmware's records for each run of ``runs`` on ``motion`` for
    ``hours``, in the open loop along the tables of `table_profile`, with the
    scenario's GNSS (``gnss_refs``: (refs, avail_tick), None: simulated here)
    and initial errors; the same noise draws in every run. A run is
    (scheme, error-set name of `error_sets`) or a dict(key=, scheme=,
    errors= SensorErrors, refs= (refs, avail_tick) or None, seed= or None).
    Returns {key: dict(outputs, truth, dt, table, errors)}."""
    n_ticks = int(round(hours * 3600.0 / DT))
    if gnss_refs is None:
        g = references.gnss(motion, hours * 3600.0, dt=DT, **setup.gnss)
        gnss_refs = (g.refs.astype(contract.REF_DTYPE), g.avail_tick)
    sets = error_sets(setup.errors)
    runs = [r if isinstance(r, dict) else dict(key=tuple(r), scheme=r[0], errors=sets[r[1]]) for r in runs]
    tables = {r["scheme"]: table_profile(r["scheme"]) for r in runs}
    cfg = dict(initial_errors(motion, phi=setup.phi0), fine_sigma0_att_rad=setup.prm.sigma0_att,
               index_scheme=abi.PYINS_INDEX_NONE)
    live = []
    for r in runs:
        refs, avail = r.get("refs") or gnss_refs
        seed = setup.seed if r.get("seed") is None else r["seed"]
        fw = engines.firmware(engine, initial_config(motion, tables[r["scheme"]], **cfg))
        live.append(dict(r, fw=fw, aider=Aider(refs, avail, tick_hz=TICK_HZ),
                         sensors=sim.SensorModel(r["errors"], seed=seed), outs=[]))
    shared = _SharedStates(motion)
    for a in range(0, n_ticks, chunk_ticks):
        m = min(chunk_ticks, n_ticks - a)
        shared.clear()
        seq = np.arange(a + 1, a + 1 + m, dtype=np.int64)
        for scheme in dict.fromkeys(r["scheme"] for r in runs):
            th, dv, angle = sim.exact_increments(shared, m, DT, 0.0, tables[scheme], 5, start_tick=a)
            for r in live:
                if r["scheme"] != scheme:
                    continue
                mth, mdv = r["sensors"].apply(th, dv)
                samples = contract.make_samples(mth, mdv, angle, seq=seq)
                r["outs"].append(r["aider"].run(r["fw"], samples, every))
    out = {}
    for r in live:
        o = np.concatenate(r["outs"])
        tr = sim.truth_at(motion, o["tick"], dt=DT, table=tables[r["scheme"]])
        out[r["key"]] = dict(outputs=o, truth=tr, dt=DT, table=tables[r["scheme"]], errors=r["errors"])
    return out


def fil_check(setup, motion, hours, gnss_refs, every=100):
    """The built-in's configuration in the closed loop (the firmware
    commanding the two-position table through the plant): its records."""
    refs, avail = gnss_refs
    cfg = dict(initial_errors(motion, phi=setup.phi0), fine_sigma0_att_rad=setup.prm.sigma0_att,
               index_scheme=scenario.INDEX_SCHEMES[setup.scheme])
    return fil.run_fil(motion, int(round(hours * 3600.0 / DT)), config=cfg, errors=setup.errors, seed=setup.seed,
                       every=every, refs=refs, avail_tick=avail)


def misalignment_prediction(errors):
    """What a rotation about z does with the gyro misalignments m_xz, m_yz
    (docs/observability.md, 'Why the accelerometer biases come out wrong'):
    the strapdown turns the frame about u = (m_xz, m_yz, 1) in p instead of
    z, which leaves the computed C_p^n the true one times a constant tilt of
    p, theta_p = (-m_yz, m_xz, 0) ... seen by the accelerometers as a bias
    -g (m_xz, m_yz) in p. Returns (accelerometer-bias offset (2,) [m/s^2],
    tilt of p (3,) [rad]) for gravity G0."""
    mxz, myz = errors.gyro_misalignment[0, 2], errors.gyro_misalignment[1, 2]
    return -G0 * np.array([mxz, myz]), np.array([-myz, mxz, 0.0])


def seed_runs(setup, motion, hours, seeds):
    """Runs of the two-position table with seed 002's biases alone over
    ``seeds`` noise and receiver seeds, each with the scenario's GNSS and
    with the same receiver without its Gauss-Markov bias (white): how far
    the estimates spread, against the analysis's sigma (which takes the
    fixes as white)."""
    bias = error_sets(setup.errors)["bias"]
    runs = []
    for k in range(1, seeds + 1):
        for label, gm in (("GM", setup.gnss["bias_sigma_m"]), ("white", 0.0)):
            g = references.gnss(motion, hours * 3600.0, dt=DT, **dict(setup.gnss, bias_sigma_m=gm, seed=100 + k))
            runs.append(dict(key=("two_position", f"bias, seed {k}, {label}"), scheme="two_position", errors=bias,
                             refs=(g.refs.astype(contract.REF_DTYPE), g.avail_tick), seed=k))
    return runs


def seed_spread(est, setup, cov_gm, cov_white, hours):
    """The RMS over the seeds of the estimate errors at ``hours`` beside the
    analysis's sigma, for the receiver with and without its bias."""
    out = {}
    for label, cov in (("GM", cov_gm), ("white", cov_white)):
        errs = []
        for (scheme, name), res in est.items():
            if not name.endswith(f", {label}") or ", seed " not in name:
                continue
            o = res["outputs"]
            i = int(np.searchsorted(o["tick"], int(round(hours * 3600.0 / DT))))
            i = min(i, len(o) - 1)
            errs.append(np.concatenate([(o["nav_gyro_bias_rad_s"][i] - res["errors"].gyro_bias) / DPH,
                                        (o["nav_accel_bias_mps2"][i, :2] - res["errors"].accel_bias[:2]) / UG]))
        if not errs:
            continue
        errs = np.array(errs)
        kc = min(int(round(hours * 3600.0 / (cov.time_s[1] - cov.time_s[0]))), len(cov.sigma) - 1)
        sig = np.concatenate([cov.sigma[kc, nav_filter.EPS:nav_filter.EPS + 3] / DPH,
                              cov.sigma[kc, nav_filter.NABLA:nav_filter.NABLA + 2] / UG])
        out[label] = dict(runs=len(errs), rms=np.sqrt(np.mean(errs ** 2, axis=0)).tolist(), sigma=sig.tolist(),
                          names=["eps_x_dph", "eps_y_dph", "eps_z_dph", "nabla_x_ug", "nabla_y_ug"])
    return out


def seed001_limits(setup):
    """A fixed IMU on a straight course (seed 001's static limits, for the
    filter's priors): the tilt cannot be known better than the level
    accelerometer bias over g, the heading better than the east gyro bias
    over the Earth rate's horizontal component. [rad]"""
    g = earth.normal_gravity(math.sin(setup.lat), setup.height)
    return dict(level_rad=setup.prm.sigma0_accel / g,
                heading_rad=setup.prm.sigma0_gyro / (earth.OMEGA_IE * math.cos(setup.lat)))


# ---------------------------------------------------------------------------
# 6. The report
# ---------------------------------------------------------------------------
def _fmt(x):
    return f"{x:6.3f}" if x >= 0.001 else f"{x:6.0e}"


def sigma_table(covs, hours):
    """Rows of the sigma ratios: per case and check time, sigma / sigma0 of
    the 12 states and of the n-frame projections."""
    rows = []
    for label, cov in covs.items():
        for h in CHECK_HOURS:
            if h > hours:
                continue
            k = int(round(h * 3600.0 / (cov.time_s[1] - cov.time_s[0])))
            ratio = cov.sigma[k, :len(STATE_NAMES)] / cov.sigma0[:len(STATE_NAMES)]
            s0n = np.array([cov.sigma0[nav_filter.EPS]] * 3 + [cov.sigma0[nav_filter.NABLA]] * 2)
            rows.append(dict(case=label, hours=h, ratio=dict(zip(STATE_NAMES, map(float, ratio))),
                             ratio_n=dict(zip(N_FRAME_NAMES, map(float, cov.sigma_n[k] / s0n)))))
    return rows


def print_sigma_table(rows):
    head = " ".join(f"{n:>7s}" for n in STATE_NAMES + N_FRAME_NAMES)
    print(f"\n{'case':24s} {'t/h':>4s} {head}")
    for r in rows:
        vals = [r["ratio"][n] for n in STATE_NAMES] + [r["ratio_n"][n] for n in N_FRAME_NAMES]
        print(f"{r['case']:24s} {r['hours']:4.0f} " + " ".join(f"{_fmt(v):>7s}" for v in vals))


def estimate_rows(est, covs, setup, hours_list):
    """Per run and time: the gyro and accelerometer bias estimates, their
    errors against the truth and the covariance analysis's sigma there."""
    rows = []
    for (scheme, name), res in est.items():
        o = res["outputs"]
        tb_a = res["errors"].accel_bias[:2]
        tb_g = res["errors"].gyro_bias
        cov = covs.get(case_label(scheme, False))
        e = metrics.nav_errors(_Res(res))
        for h in hours_list:
            k = int(np.searchsorted(o["tick"], int(round(h * 3600.0 / DT))))
            if k >= len(o):
                continue
            g_est = o["nav_gyro_bias_rad_s"][k]
            a_est = o["nav_accel_bias_mps2"][k][:2]
            sig = None
            if cov is not None:
                kc = int(round(h * 3600.0 / (cov.time_s[1] - cov.time_s[0])))
                if kc < len(cov.sigma):
                    sig = cov.sigma[kc]
            last = (e.time_s > h * 3600.0 - 3600.0) & (e.time_s <= h * 3600.0)
            rows.append(dict(
                scheme=scheme, errors=name, hours=h,
                gyro_est_dph=(g_est / DPH).tolist(), gyro_true_dph=(tb_g / DPH).tolist(),
                gyro_sigma_dph=None if sig is None else (sig[nav_filter.EPS:nav_filter.EPS + 3] / DPH).tolist(),
                accel_est_ug=(a_est / UG).tolist(), accel_true_ug=(tb_a / UG).tolist(),
                accel_sigma_ug=None if sig is None else (sig[nav_filter.NABLA:nav_filter.NABLA + 2] / UG).tolist(),
                level_rms_arcsec=(np.sqrt(np.mean(e.att_n_rad[last, :2] ** 2, axis=0)) / ARCSEC_TO_RAD).tolist(),
                heading_rms_arcsec=float(np.sqrt(np.mean(e.att_n_rad[last, 2] ** 2)) / ARCSEC_TO_RAD),
                horizontal_rms_m=float(np.sqrt(np.mean(e.horizontal_m[last] ** 2)))))
    return rows


class _Res:
    def __init__(self, d):
        self.outputs, self.truth, self.dt = d["outputs"], d["truth"], d["dt"]


def print_estimates(rows):
    print(f"\n{'scheme':13s} {'errors':21s} {'t/h':>3s}  {'gyro bias est - true [deg/h] (sigma)':44s} "
          f"{'accel bias est (true) [ug], sigma':38s} {'level rms E,N [arcsec]':>22s}")
    for r in rows:
        ge = np.array(r["gyro_est_dph"]) - np.array(r["gyro_true_dph"])
        gs = r["gyro_sigma_dph"] or [float("nan")] * 3
        g = " ".join(f"{d:+.4f}({s:.4f})" for d, s in zip(ge, gs))
        a_s = r["accel_sigma_ug"] or [float("nan")] * 2
        a = " ".join(f"{e:+6.1f}({t:+5.1f})" for e, t in zip(r["accel_est_ug"], r["accel_true_ug"]))
        print(f"{r['scheme']:13s} {r['errors']:21s} {r['hours']:3.0f}  {g:44s} {a} s {a_s[0]:4.1f}   "
              f"{r['level_rms_arcsec'][0]:6.1f} {r['level_rms_arcsec'][1]:6.1f}")


def plot(path, covs, est, setup, est_hours):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(3, 3, figsize=(15, 12))
    styles = {"fixed": "C0", "two_position": "C1", "continuous": "C2"}
    # row 1: sigma / sigma0 of a few states in every case
    for j, (name, frame, idx) in enumerate((("east gyro bias eps_E (n)", "n", 0),
                                            ("vertical gyro bias eps_z (p)", "p", nav_filter.EPS + 2),
                                            ("east accel. bias nabla_E (n)", "n", 3))):
        a = ax[0, j]
        for label, cov in covs.items():
            scheme, course = label.split(", ")
            if frame == "p":
                y = cov.sigma[:, idx] / cov.sigma0[idx]
            else:
                y = cov.sigma_n[:, idx] / (cov.sigma0[nav_filter.EPS] if idx < 3 else cov.sigma0[nav_filter.NABLA])
            a.semilogy(cov.time_s / 3600.0, y, color=styles[scheme], lw=0.8 if course == "turns" else 1.6,
                       ls="-" if course == "turns" else "--", label=label)
        a.set_title(f"{name}: sigma / sigma0")
        a.set_xlabel("time [h]")
        a.grid(True, which="both", alpha=0.3)
        a.set_ylim(1e-3, 1.5)
    ax[0, 0].legend(fontsize=8)
    # row 2: gyro bias estimate - truth, two-position, bias-only and full, with +-3 sigma of the analysis
    cov = covs.get(case_label("two_position", False))
    for i in range(3):
        a = ax[1, i]
        for name, colour, ls in (("full", "C3", "-"), ("bias", "C1", "--"), ("bias, white GNSS", "C2", "-")):
            res = est.get(("two_position", name))
            if res is None:
                continue
            o = res["outputs"]
            a.plot(o["tick"] * DT / 3600.0, (o["nav_gyro_bias_rad_s"][:, i] - setup.errors.gyro_bias[i]) / DPH,
                   color=colour, ls=ls, label=f"two-position, {name}" + ("" if "GNSS" in name else " errors"))
        res = est.get(("fixed", "bias"))
        if res is not None:
            o = res["outputs"]
            a.plot(o["tick"] * DT / 3600.0, (o["nav_gyro_bias_rad_s"][:, i] - setup.errors.gyro_bias[i]) / DPH,
                   color="C0", alpha=0.7, label="fixed, bias errors")
        if cov is not None:
            t = cov.time_s / 3600.0
            keep = t <= est_hours
            s3 = 3.0 * cov.sigma[keep, nav_filter.EPS + i] / DPH
            a.fill_between(t[keep], -s3, s3, color="C1", alpha=0.15, label="3 sigma (analysis, two-position)")
        a.set_title(f"gyro bias {'xyz'[i]}: estimate - truth [deg/h]")
        a.set_xlabel("time [h]")
        a.set_ylim(-0.012, 0.012)
        a.grid(True, alpha=0.3)
    ax[1, 0].legend(fontsize=8)
    # row 3: accelerometer estimates (bias-only, full, the predicted offset), the level error against the prediction
    offset, tilt_p = misalignment_prediction(setup.errors)
    for i in range(2):
        a = ax[2, i]
        for (scheme, name), colour in ((("two_position", "bias"), "C1"), (("two_position", "full"), "C3"),
                                       (("fixed", "full"), "C0"), (("two_position", "bias+gyro_mis_xz_yz"), "C4")):
            res = est.get((scheme, name))
            if res is None:
                continue
            o = res["outputs"]
            a.plot(o["tick"] * DT / 3600.0, o["nav_accel_bias_mps2"][:, i] / UG, color=colour,
                   label=f"{scheme}, {name}")
        a.axhline(setup.errors.accel_bias[i] / UG, color="k", lw=1, label="true bias")
        a.axhline((setup.errors.accel_bias[i] + offset[i]) / UG, color="k", ls=":", lw=1.5,
                  label="true - g m_{xz,yz} (predicted)")
        a.set_ylim(-45.0, 55.0)
        a.set_title(f"accelerometer bias {'xy'[i]} estimate [ug]")
        a.set_xlabel("time [h]")
        a.grid(True, alpha=0.3)
    ax[2, 0].legend(fontsize=8)
    a = ax[2, 2]
    res = est.get(("two_position", "full"))
    if res is not None:
        e = metrics.nav_errors(_Res(res))
        tr = res["truth"]
        cbn = sim.euler_to_mat(tr.euler)
        al = tr.table_angle
        ca, sa = np.cos(al), np.sin(al)
        pred = np.einsum("kij,kj->ki", cbn, np.stack([ca * tilt_p[0] - sa * tilt_p[1],
                                                      sa * tilt_p[0] + ca * tilt_p[1], np.zeros_like(ca)], 1))
        t = e.time_s / 3600.0
        a.plot(t, e.att_n_rad[:, 0] / ARCSEC_TO_RAD, color="C3", lw=0.6, label="phi_E (two-position, full)")
        a.plot(t, pred[:, 0] / ARCSEC_TO_RAD, color="k", ls=":", lw=1.0, label="C_p^n theta_p, E (predicted)")
        a.set_xlim(0, min(2.0, est_hours))
        a.set_ylim(-30, 30)
        a.legend(fontsize=8)
    a.set_title('phi_E ["]: measured, and the predicted tilt of p')
    a.set_xlabel("time [h]")
    a.grid(True, alpha=0.3)
    fig.suptitle("voyage_gnss's voyage and GNSS. Row 1: the 12-state filter's sigma / sigma0 (the straight course "
                 "dashed: with the table\nit lies on the voyage's line). Rows 2-3: the firmware's bias estimates "
                 "(open loop; 3 sigma of the analysis shaded)")
    fig.tight_layout()
    fig.savefig(path, dpi=90)
    plt.close(fig)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--hours", type=float, default=24.0, help="the covariance analysis's length (default 24)")
    ap.add_argument("--est-hours", type=float, default=6.0, help="the firmware runs' length (default 6)")
    ap.add_argument("--no-estimates", action="store_true", help="the covariance analysis only")
    ap.add_argument("--no-fil-check", action="store_true", help="skip the closed-loop run of the built-in")
    ap.add_argument("--noise", choices=("filter", "sensor"), default="filter",
                    help="Q of the analysis: the filter's configured densities (default) or the sensors'")
    ap.add_argument("--seeds", type=int, default=6,
                    help="noise and receiver seeds of the spread with and without the receiver's bias "
                         "(default 6; 0: none)")
    ap.add_argument("--scenario", default="voyage_gnss")
    ap.add_argument("--gyro-states", action="store_true",
                    help="also the analysis with the seven scale-factor and misalignment states at the "
                         "scenario's priors (ABI 0.19): their sigma / prior and the heading's")
    ap.add_argument("--out", default=os.path.join(os.path.dirname(__file__), "..", "docs", "results"))
    a = ap.parse_args(argv)
    t_all = time.perf_counter()
    setup = setup_from_scenario(a.scenario)
    print(f"set-up from {a.scenario}: filter prior att {np.round(setup.prm.sigma0_att / DEG_TO_RAD * 60, 2)}', "
          f"vel {setup.prm.sigma0_vel} m/s, pos {setup.prm.sigma0_pos} m, gyro {setup.prm.sigma0_gyro / DPH:g} deg/h, "
          f"accel {setup.prm.sigma0_accel / UG:g} ug; Q: arw {setup.prm.gyro_arw / (DEG_TO_RAD / 60):g} deg/sqrt(h), "
          f"vrw {setup.prm.accel_vrw / UG:g} ug/sqrt(Hz) ({a.noise}); time update every {setup.prm.every} ticks")

    # 1. the covariance analysis
    t0 = time.perf_counter()
    covs = {}
    for scheme, straight in CASES:
        motion = make_voyage(setup, a.hours, straight, dt=1.0)
        covs[case_label(scheme, straight)] = covariance(setup, motion, table_profile(scheme), a.hours, a.noise)
    t_cov = time.perf_counter() - t0
    r_pos, r_vel = gnss_variances(setup, make_voyage(setup, 0.01, dt=1.0))
    print(f"GNSS told: position sigma {np.sqrt(r_pos[0]):.3f} m, velocity {np.sqrt(r_vel[0]):.3f} m/s")
    lim = seed001_limits(setup)
    print(f"seed 001's limits for a fixed IMU on a straight course with these priors: level "
          f"{lim['level_rad'] / ARCSEC_TO_RAD:.1f}\" ({lim['level_rad'] / setup.prm.sigma0_att[0]:.3f} of the prior), "
          f"heading {lim['heading_rad'] / (DEG_TO_RAD / 60):.2f}' ({lim['heading_rad'] / setup.prm.sigma0_att[2]:.3f})")
    rows = sigma_table(covs, a.hours)
    print(f"\nsigma / sigma0 (covariance analysis, {a.hours:g} h, {t_cov:.1f} s); "
          f"the (n) columns: eps and nabla projected on E, N, U with C_p^n at that time")
    print_sigma_table(rows)
    h_last = max(h for h in CHECK_HOURS if h <= a.hours)
    print(f"\nthe least observed directions at {h_last:g} h (sqrt of the eigenvalues of P normalised by its prior)")
    least = {}
    for label, cov in covs.items():
        least[label] = least_observed(cov, h_last)
        print(f"  {label:24s} " + "; ".join(f"{s:.2f} {d}" for s, d in least[label]))

    gyro = {}
    if a.gyro_states:
        if not any(setup.gyro_states):
            raise SystemExit(f"--gyro-states: {a.scenario} sets none of the four priors")
        t0 = time.perf_counter()
        gcovs = {}
        for scheme, straight in CASES:
            motion = make_voyage(setup, a.hours, straight, dt=1.0)
            gcovs[case_label(scheme, straight)] = covariance(setup, motion, table_profile(scheme), a.hours,
                                                             a.noise, gyro_states=True)
        names = ("m_xz", "m_yz", "k_z", "k_x", "k_y", "m_xy", "m_yx")
        print(f"\nwith the seven scale-factor and misalignment states (priors {setup.gyro_states[0] * 1e6:g} ppm, "
              f"{setup.gyro_states[1] / ARCSEC_TO_RAD:g} arcsec, {setup.gyro_states[2] * 1e6:g} ppm, "
              f"{setup.gyro_states[3] / ARCSEC_TO_RAD:g} arcsec; {time.perf_counter() - t0:.1f} s): "
              "sigma / prior, and the heading sigma against the 12 states'")
        print(f"{'case':24s} {'t/h':>4s} " + " ".join(f"{n:>7s}" for n in names) + f" {'phi_U':>8s} {'12 st.':>8s}")
        for label, cov in gcovs.items():
            for h in CHECK_HOURS:
                if h > a.hours:
                    continue
                k = int(round(h * 3600.0 / (cov.time_s[1] - cov.time_s[0])))
                r = cov.sigma[k, nav_filter.TAB:] / cov.sigma0[nav_filter.TAB:]
                hd, h12 = cov.sigma[k, nav_filter.PHI + 2], covs[label].sigma[k, nav_filter.PHI + 2]
                gyro.setdefault(label, []).append(dict(hours=h, ratio=dict(zip(names, map(float, r))),
                                                       heading_arcmin=float(hd / (DEG_TO_RAD / 60)),
                                                       heading_12_arcmin=float(h12 / (DEG_TO_RAD / 60))))
                print(f"{label:24s} {h:4.0f} " + " ".join(f"{_fmt(x):>7s}" for x in r)
                      + f" {hd / (DEG_TO_RAD / 60):7.3f}' {h12 / (DEG_TO_RAD / 60):7.3f}'")

    # 2. the estimates against the truth
    est, est_rows, fil_rows, t_est, t_fil, spread = {}, [], None, 0.0, 0.0, {}
    if not a.no_estimates:
        t0 = time.perf_counter()
        motion = make_voyage(setup, a.est_hours, dt=DT)
        g = references.gnss(motion, a.est_hours * 3600.0, dt=DT, **setup.gnss)
        gr = (g.refs.astype(contract.REF_DTYPE), g.avail_tick)
        gw = references.gnss(motion, a.est_hours * 3600.0, dt=DT, **dict(setup.gnss, bias_sigma_m=0.0))
        white = dict(key=("two_position", "bias, white GNSS"), scheme="two_position",
                     errors=error_sets(setup.errors)["bias"], refs=(gw.refs.astype(contract.REF_DTYPE), gw.avail_tick))
        runs = (list(ESTIMATE_RUNS) + [white]
                + (seed_runs(setup, motion, a.est_hours, a.seeds) if a.seeds else []))
        est = estimates(setup, motion, a.est_hours, runs, gnss_refs=gr)
        t_est = time.perf_counter() - t0
        spread = {}
        if a.seeds:
            setup_white = replace(setup, gnss=dict(setup.gnss, bias_sigma_m=0.0))
            m1 = make_voyage(setup, a.est_hours, dt=1.0)
            cov_white = covariance(setup_white, m1, table_profile("two_position"), a.est_hours, a.noise)
            cov_gm = covariance(setup, m1, table_profile("two_position"), a.est_hours, a.noise)
            spread = seed_spread(est, setup, cov_gm, cov_white, a.est_hours)
            est = {k: v for k, v in est.items() if ", seed " not in k[1]}
        hours_list = sorted({h for h in (1.0, 3.0, 6.0, 12.0) if h < a.est_hours} | {a.est_hours})
        est_rows = estimate_rows(est, covs, setup, hours_list)
        offset, tilt_p = misalignment_prediction(setup.errors)
        print(f"\nthe firmware's estimates ({a.est_hours:g} h, open loop, {len(est)} runs, {t_est:.1f} s); "
              f"true gyro bias {np.round(setup.errors.gyro_bias / DPH, 4)} deg/h; predicted accelerometer offset "
              f"of the misalignments -g (m_xz, m_yz) = {np.round(offset / UG, 1)} ug, tilt of p "
              f"{np.round(tilt_p[:2] / ARCSEC_TO_RAD, 1)}\"")
        print_estimates(est_rows)
        for label, sp in spread.items():
            print(f"  two-position, seed 002's biases, {sp['runs']} seeds, receiver {label}: RMS of est - true at "
                  f"{a.est_hours:g} h " + ", ".join(f"{n} {r:.4g} (sigma {sg:.4g})"
                                                   for n, r, sg in zip(sp["names"], sp["rms"], sp["sigma"])))
        if not a.no_fil_check:
            t0 = time.perf_counter()
            res = fil_check(setup, motion, a.est_hours, gr)
            t_fil = time.perf_counter() - t0
            ol = est[("two_position", "full")]["outputs"]
            cl = res.outputs
            k = min(len(ol), len(cl)) - 1
            plant_alpha = res.plant["alpha_rad"]
            prof = est[("two_position", "full")]["table"].state(res.plant["tick"] * DT)[0]
            d_alpha = np.abs(np.angle(np.exp(1j * (plant_alpha - prof))))
            fil_rows = dict(hours=a.est_hours, wall_s=t_fil,
                            gyro_closed_dph=(cl["nav_gyro_bias_rad_s"][k] / DPH).tolist(),
                            gyro_open_dph=(ol["nav_gyro_bias_rad_s"][k] / DPH).tolist(),
                            accel_closed_ug=(cl["nav_accel_bias_mps2"][k][:2] / UG).tolist(),
                            accel_open_ug=(ol["nav_accel_bias_mps2"][k][:2] / UG).tolist(),
                            table_angle_max_diff_deg=float(d_alpha.max() / DEG_TO_RAD),
                            table_angle_p99_diff_deg=float(np.percentile(d_alpha, 99) / DEG_TO_RAD))
            print(f"\nclosed loop (run_fil, the built-in's two-position scheme, seed 002's errors, {t_fil:.1f} s) at "
                  f"{a.est_hours:g} h: gyro {np.round(fil_rows['gyro_closed_dph'], 5)} deg/h (open loop "
                  f"{np.round(fil_rows['gyro_open_dph'], 5)}), accel {np.round(fil_rows['accel_closed_ug'], 1)} ug "
                  f"(open loop {np.round(fil_rows['accel_open_ug'], 1)}); the plant's table angle against the "
                  f"profile: 99 % within {fil_rows['table_angle_p99_diff_deg']:.2f} deg, worst "
                  f"{fil_rows['table_angle_max_diff_deg']:.2f} deg (records every 1 s)")

    # 3. the files
    os.makedirs(a.out, exist_ok=True)
    doc = dict(
        tool="tools/observability_nav.py", scenario=a.scenario, hours=a.hours, est_hours=a.est_hours, noise=a.noise,
        filter=dict(sigma0=dict(zip(STATE_NAMES, map(float, next(iter(covs.values())).sigma0))),
                    gyro_arw_rad_sqrt_s=setup.prm.gyro_arw, accel_vrw_mps_sqrt_s=setup.prm.accel_vrw,
                    every_ticks=setup.prm.every, dt_s=setup.prm.dt),
        gnss=dict(setup.gnss, told_pos_sigma_m=float(np.sqrt(r_pos[0])), told_vel_sigma_mps=float(np.sqrt(r_vel[0]))),
        sigma_ratio=rows,
        least_observed={k: [dict(sigma_ratio=s, direction=d) for s, d in v] for k, v in least.items()},
        seed001_limits=dict(level_arcsec=lim["level_rad"] / ARCSEC_TO_RAD,
                            heading_arcmin=lim["heading_rad"] / (DEG_TO_RAD / 60.0),
                            level_ratio=lim["level_rad"] / setup.prm.sigma0_att[0],
                            heading_ratio=lim["heading_rad"] / setup.prm.sigma0_att[2]),
        estimates=est_rows, seed_spread=spread, fil_check=fil_rows, gyro_states=gyro,
        misalignment_prediction=dict(accel_offset_ug=(misalignment_prediction(setup.errors)[0] / UG).tolist(),
                                     tilt_p_arcsec=(misalignment_prediction(setup.errors)[1] / ARCSEC_TO_RAD).tolist()),
        wall_s=dict(covariance=t_cov, estimates=t_est, fil_check=t_fil, total=time.perf_counter() - t_all))
    jpath = os.path.join(a.out, "observability_nav.json")
    with open(jpath, "w") as f:
        json.dump(doc, f, indent=1)
        f.write("\n")
    ppath = os.path.join(a.out, "observability_nav.png")
    plot(ppath, covs, est, setup, a.est_hours)
    print(f"\nwrote {os.path.normpath(jpath)}, {os.path.normpath(ppath)}; {time.perf_counter() - t_all:.1f} s in all")


if __name__ == "__main__":
    main()
