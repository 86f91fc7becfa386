"""The metrics: what a run (or a group of runs) scored, one table.

Every metric the project computes, prints or compares with a paper is one
row of `TABLE`, in the manner of nmayorov/pyins's per-quantity threshold
table: its name, dimension (a `pyins.units` dimension), SI unit, the unit the
papers write it in (and the scale from SI), what it means and the function
that computes it. The order of the table is the order metrics are listed in
(summary.json, campaign tables, the report).

Two scopes:

- "run": one run's records against its truth (`run_metrics`). They are
  computed in stages: "position" (position and velocity errors) for a run
  that navigates (an alignment holds the site: the ship's own surge and sway
  are no INS error), "nav" for every run with records, "alignment" when the
  firmware aligns (the theoretical limit of an alignment, seed 001 eq. 21),
  "static_fine" when a fine alignment runs on a static base (seed 001: the
  filter's errors beside the limits), "aided" for a run that navigates
  with external references ([references] in its scenario), "outages" for
  one whose GNSS positions have gaps (KF-GINS's outage figure).
- "group": over the runs of one scenario or campaign group (seeds,
  headings): seed 000's Table 1 std (`group_metrics`).

`display(name, values_si)` is the unit a metric is shown in: arcsec for
level errors, arcmin for heading errors, m or nmi for positions (nmi when
the values reach half a nautical mile).

Steps of a run's metrics:
1. the navigation errors against the truth (`nav_errors`);
2. the nav stage, every run;
3. the alignment stage, against the limit at the final true attitude;
4. the static fine-alignment stage, the filter's drift estimate beside the
   limit at t = 0.
"""
import math
from dataclasses import dataclass
from functools import cached_property
from typing import Callable

import numpy as np

from pyins import analysis, sim
from pyins.reference import abi, attitude, earth
from pyins.reference.fine_align import EPS, EPS_NU, PHI
from pyins.units import (ARCMIN_TO_RAD, ARCSEC_TO_RAD, DPH_TO_RPS, NMI_TO_M, TWO_PI, UNITS)

__all__ = ["Metric", "TABLE", "NAMES", "FIGURE_METRICS", "RUN_METRICS", "GROUP_METRICS", "NavErrors",
           "nav_errors", "run_metrics", "start", "scored", "group_metrics", "aligned", "aligned_at", "info",
           "dimension", "describe", "si_unit", "si_name", "display"]


# ---------------------------------------------------------------------------
# 1. Navigation errors against the truth
# ---------------------------------------------------------------------------
@dataclass
class NavErrors:
    """Errors of the firmware against the truth at each kept tick."""
    time_s: np.ndarray       #: ship time [s]
    north_m: np.ndarray      #: position error, north [m]
    east_m: np.ndarray       #: position error, east [m]
    horizontal_m: np.ndarray  #: horizontal position error [m]
    vel_n_mps: np.ndarray    #: velocity error, ENU (N, 3) [m/s]
    att_n_rad: np.ndarray    #: attitude error phi in n (E, N, U) (N, 3) [rad]:
    #:                          C_b^n(computed) = (I - phi x) C_b^n(true)


def _normalize(q):
    """`pyins.reference.attitude.quat_normalize` over (4, N): unit, w >= 0."""
    n = np.sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3])
    n = np.where(q[0] < 0.0, -n, n)
    return q * (1.0 / n)


def _rotvec(q):
    """`pyins.reference.attitude.quat_to_rotvec` over (4, N) unit quaternions
    with w >= 0: the same small-angle branch (t = r / w < 1e-5)."""
    r = np.sqrt(q[1] * q[1] + q[2] * q[2] + q[3] * q[3])
    small = r < 1e-5 * q[0]
    t = r / q[0]
    with np.errstate(invalid="ignore", divide="ignore"):
        k = np.where(small, 2.0 / q[0] * (1.0 - t * t / 3.0), 2.0 * np.arctan2(r, q[0]) / r)
    return k * q[1:]


def position_errors(lat_rad, lon_rad, lat_t, lon_t, height_t):
    """North and east errors [m] of positions against true ones: the latitude
    and longitude differences (the latter wrapped to (-pi, pi]) on the true
    position's radii of curvature (WGS-84)."""
    rm, rn = earth.principal_radii(np.sin(lat_t))
    north = (lat_rad - lat_t) * (rm + height_t)
    dlon = np.mod(lon_rad - lon_t + np.pi, TWO_PI) - np.pi
    return north, dlon * (rn + height_t) * np.cos(lat_t)


def nav_errors(result):
    """Position, velocity and attitude errors of a result with ``outputs``
    (firmware records), ``truth`` (pyins.sim.Truth at the same ticks) and
    ``dt`` (an open_loop.RunResult or a records.FilResult)."""
    out, tr = result.outputs, result.truth
    north, east = position_errors(out["lat_rad"], out["lon_rad"], tr.lat, tr.lon, tr.height)
    # q_err = q_nb(computed) (x) conj(q_nb(true)) = rotation by -phi in n: the
    # mirror's formulas on every record at once ((4, N) arrays, element by element)
    q_err = attitude.quat_mul(np.asarray(out["quat_nb"]).T, attitude.quat_conj(np.asarray(tr.quat_nb).T))
    att = -_rotvec(_normalize(q_err)).T
    return NavErrors(time_s=out["tick"] * result.dt, north_m=north, east_m=east,
                     horizontal_m=np.hypot(north, east), vel_n_mps=out["vel_n_mps"] - tr.vel_n,
                     att_n_rad=att)


class _Run:
    """What the run metrics read, reduced from a run's records chunk by chunk
    (`add`), so a run of any length is scored in memory bounded by one chunk:
    the last record's errors, the maxima over the navigating records and over
    all of them, the sums of squares over the same two sets, each GNSS
    outage's largest horizontal error, and the alignment limits (computed
    once). A maximum is np.maximum's (a NaN anywhere stays NaN, as
    ndarray.max does); a sum of squares is exact to 2^-106 (math.fsum,
    carried as its rounded value and remainder), so no figure depends on the
    chunking."""

    _MAXED = ("h", "level", "heading", "vel")

    def __init__(self, spec, end_s):
        self.spec = spec
        self.max_all = dict.fromkeys(self._MAXED, -np.inf)
        self.max_nav = dict.fromkeys(self._MAXED, -np.inf)
        self.sq_all = {"h": [0.0, 0.0], "heading": [0.0, 0.0]}     # [rounded sum, remainder]
        self.sq_nav = {"h": [0.0, 0.0], "heading": [0.0, 0.0]}
        self.n_all = self.n_nav = 0
        #: each GNSS outage (start, end) [s] (``end_s``: the last record's time) and its
        #: largest horizontal error so far
        self.windows = gnss_outages(getattr(spec, "refs", None), spec.dt, end_s)
        self.window_max = [0.0] * len(self.windows)
        self.last = None          # the last record's errors, truth and filter state

    def add(self, res, errors=None):
        """Fold in the next chunk of records (a records.FilResult, in tick order);
        ``errors``: its `nav_errors` when the caller has them already."""
        if len(res.outputs) == 0:
            return
        e = nav_errors(res) if errors is None else errors
        att = e.att_n_rad
        nav = np.asarray(res.outputs["mode"]) == abi.PYINS_MODE_NAVIGATE
        per = {"h": e.horizontal_m, "level": np.abs(att[:, :2]).max(axis=1), "heading": np.abs(att[:, 2]),
               "vel": np.abs(e.vel_n_mps[:, :2]).max(axis=1)}
        any_nav = bool(nav.any())
        for k, x in per.items():
            self.max_all[k] = np.maximum(self.max_all[k], x.max())
            if any_nav:
                self.max_nav[k] = np.maximum(self.max_nav[k], x[nav].max())
        for k in self.sq_all:
            sq = per[k] * per[k]
            _fold(self.sq_all[k], sq)
            if any_nav:
                _fold(self.sq_nav[k], sq[nav])
        self.n_all += len(nav)
        self.n_nav += int(np.count_nonzero(nav))
        t = e.time_s
        for i, (a, b) in enumerate(self.windows):
            x = e.horizontal_m[(t >= a) & (t <= b)]
            if len(x):
                self.window_max[i] = np.maximum(self.window_max[i], x.max())
        out = res.outputs[-1]
        self.last = dict(h=e.horizontal_m[-1], att=att[-1].copy(), level=per["level"][-1],
                         kf_x=np.array(out["kf_x"]), n_ref_rejected=np.array(out["n_ref_rejected"]),
                         lat=float(res.truth.lat[-1]), euler=np.array(res.truth.euler[-1]))

    @property
    def navigates(self):
        """The firmware navigated (during an alignment it holds the site and zero
        velocity: a position or velocity error then is the ship's own motion,
        not the INS's)."""
        return self.n_nav > 1

    def over_nav(self, k):
        """The largest of quantity k over the navigating records (all of them
        when none navigates)."""
        return float(self.max_nav[k] if self.n_nav else self.max_all[k])

    def over_judged(self, k):
        """The largest of attitude quantity k ("level", "heading") over the
        records the attitude is judged on: from the end of the alignment (the
        unaligned start is not the INS's error); an alignment-only run: its
        last record; a run given its attitude: all of them."""
        aligns = self.spec.config.get("coarse_ticks", 0) or self.spec.config.get("fine_ticks", 0)
        if not aligns:
            return float(self.max_all[k])
        if self.n_nav:
            return float(self.max_nav[k])
        return float(self.last["level"] if k == "level" else abs(self.last["att"][2]))

    def rms_nav(self, k):
        """RMS of quantity k ("h", "heading") over the navigating records (all
        when none navigates)."""
        s, n = (self.sq_nav[k], self.n_nav) if self.n_nav else (self.sq_all[k], self.n_all)
        return float(np.sqrt(s[0] / n))

    @property
    def outage_drifts(self):
        """The largest horizontal error of each GNSS outage (`gnss_outages`) [m]."""
        return np.array(self.window_max, dtype=float)

    @cached_property
    def final_limits(self):
        """The alignment limits at the final true attitude (seed 001 eq. 21)."""
        return analysis.alignment_limits(self.last["lat"], self.last["euler"],
                                         self.spec.errors.gyro_bias, self.spec.errors.accel_bias)

    @cached_property
    def vs_limit(self):
        """phi at the end minus its limit."""
        return self.last["att"] - self.final_limits.phi_n

    @cached_property
    def start_limits(self):
        """The limits of the static base at t = 0 (seed 001)."""
        st = self.spec.motion.state(np.array([0.0]))
        return analysis.alignment_limits(float(st.lat[0]), st.euler[0], self.spec.errors.gyro_bias,
                                         self.spec.errors.accel_bias)

    @cached_property
    def drift_error(self):
        """True minus estimated drift in n at the end [E, N, U] (the 5-state
        filter estimates no eps_E: taken as 0)."""
        kf_x = self.last["kf_x"]
        if self.spec.config.get("fine_states", 8) == 5:
            eps = np.concatenate([[0.0], kf_x[EPS_NU]])
        else:
            eps = np.asarray(kf_x[EPS])
        return self.start_limits.eps_n - eps


def _fold(acc, x):
    """acc = [s, r] (a sum carried as its rounded value and remainder) plus
    the values x, rounded once (math.fsum): the same whatever the chunks.
    A sum that is not finite (an inf or NaN among the values, or past the
    largest double) is what ndarray.sum gives, inf or NaN, as the whole
    records' mean would be."""
    values = [acc[0], acc[1], *x.tolist()]
    try:
        s = math.fsum(values)
    except (OverflowError, ValueError):      # past the largest double; inf - inf
        with np.errstate(over="ignore", invalid="ignore"):
            s = float(np.sum(values))
    if math.isfinite(s):
        values.append(-s)
        acc[1] = math.fsum(values)
    else:
        acc[1] = 0.0
    acc[0] = s


def _std(variants):
    """Sample std (ddof 1) of the final [phi_E, phi_N, phi_U] over the
    variants, or None with fewer than two."""
    finals = np.array([[v["metrics"][k] for k in ("phi_e_final", "phi_n_final", "phi_u_final")]
                       for v in variants if "phi_e_final" in v["metrics"]])
    return finals.std(axis=0, ddof=1) if len(finals) >= 2 else None


# ---------------------------------------------------------------------------
# The table
# ---------------------------------------------------------------------------
@dataclass(frozen=True)
class Metric:
    """One metric. ``unit``/``scale``: the papers' unit and its size in SI
    (value shown = value_si / scale); ``figure``: a [paper] figure may name
    it; ``stage``: when a run computes it (see the module docstring);
    ``compute``: the function (a run's `_Run` -> float; group: the
    variants' summary entries -> float, given at least two)."""
    name: str
    dimension: str
    unit: str
    scale: float
    description: str
    scope: str
    stage: str
    figure: bool
    compute: Callable

    @property
    def si_unit(self):
        return next(iter(UNITS[self.dimension])) if self.dimension in UNITS else ""


def _m(name, dimension, unit, scale, description, compute, stage="nav", figure=True):
    scope = "group" if stage == "group" else "run"
    return Metric(name, dimension, unit, scale, " ".join(description.split()), scope, stage, figure,
                  compute)


_M, _ARCSEC, _ARCMIN = 1.0, ARCSEC_TO_RAD, ARCMIN_TO_RAD
TABLE = (
    _m("horizontal_error_final", "length", "m", _M,
       "horizontal position error at the end of the run (a run that navigates: an alignment holds "
       "the site)",
       lambda r: float(r.last["h"]), stage="position"),
    _m("horizontal_error_max", "length", "m", _M,
       "largest horizontal position error while navigating (after the alignment, if any)",
       lambda r: r.over_nav("h"), stage="position"),
    _m("level_error_final", "angle", "arcsec", _ARCSEC,
       "larger of |phi_E|, |phi_N| at the end of the run",
       lambda r: float(r.last["level"])),
    _m("level_error_max", "angle", "arcsec", _ARCSEC,
       "largest |phi_E|, |phi_N| from the end of the alignment (the whole run when the attitude is "
       "given; an alignment-only run: at its end)",
       lambda r: r.over_judged("level")),
    _m("heading_error_final", "angle", "arcmin", _ARCMIN,
       "|phi_U| at the end of the run",
       lambda r: float(abs(r.last["att"][2]))),
    _m("heading_error_max", "angle", "arcmin", _ARCMIN,
       "largest |phi_U| from the end of the alignment (the whole run when the attitude is given; an "
       "alignment-only run: at its end)",
       lambda r: r.over_judged("heading")),
    _m("velocity_error_max", "velocity", "m/s", 1.0,
       "largest horizontal velocity error component while navigating (after the alignment, if any)",
       lambda r: r.over_nav("vel"), stage="position"),
    _m("horizontal_error_rms", "length", "m", _M,
       "RMS horizontal position error while navigating (a run with external references: "
       "[references] in its scenario)",
       lambda r: r.rms_nav("h"), stage="aided"),
    _m("heading_error_rms", "angle", "arcmin", _ARCMIN,
       "RMS |phi_U| while navigating (a run with external references)",
       lambda r: r.rms_nav("heading"), stage="aided"),
    _m("references_rejected", "dimensionless", "", 1.0,
       "references the firmware's innovation gate rejected, all kinds (a run with external "
       "references)",
       lambda r: float(np.sum(r.last["n_ref_rejected"])), stage="aided", figure=False),
    _m("outage_drift_rms", "length", "m", _M,
       "RMS over the GNSS outages (gaps of more than 2.5 fix intervals in the position fixes) of each "
       "outage's largest horizontal error (KF-GINS's figure: 60-s outages every 180 s)",
       lambda r: float(np.sqrt(np.mean(np.square(r.outage_drifts)))), stage="outages"),
    _m("level_error_std", "angle", "arcsec", _ARCSEC,
       "std of the final pitch and roll errors over the runs of a campaign (seeds, headings)",
       lambda vs: float(_std(vs)[:2].max()), stage="group"),
    _m("heading_error_std", "angle", "arcmin", _ARCMIN,
       "std of the final heading error over the runs of a campaign",
       lambda vs: float(_std(vs)[2]), stage="group"),
    _m("level_error_vs_limit_final", "angle", "arcsec", _ARCSEC,
       "larger of |phi_E - limit|, |phi_N - limit| at the end (alignment: against the theoretical "
       "limit, which any alignment shares)",
       lambda r: float(np.abs(r.vs_limit[:2]).max()), stage="alignment"),
    _m("heading_error_vs_limit_final", "angle", "arcmin", _ARCMIN,
       "|phi_U - limit| at the end (alignment)",
       lambda r: float(abs(r.vs_limit[2])), stage="alignment"),
    _m("att_east_gap_final", "angle", "arcmin", _ARCMIN,
       "|phi_E error - theoretical limit| at the end (alignment)",
       lambda r: float(abs(r.last["att"][0] - r.start_limits.phi_n[0])), stage="static_fine"),
    _m("att_up_gap_final", "angle", "arcmin", _ARCMIN,
       "|phi_U error - theoretical limit| at the end (alignment)",
       lambda r: float(abs(r.last["att"][2] - r.start_limits.phi_n[2])), stage="static_fine"),
    _m("drift_north_gap_final", "angular_rate", "deg/h", DPH_TO_RPS,
       "|eps_N estimate error - limit| at the end (fine alignment)",
       lambda r: float(abs(r.drift_error[1] - r.start_limits.eps_n_limit[1])), stage="static_fine"),
    _m("phi_e_final", "angle", "arcsec", _ARCSEC,
       "phi_E (east attitude error) at the end of the run",
       lambda r: float(r.last["att"][0]), figure=False),
    _m("phi_n_final", "angle", "arcsec", _ARCSEC,
       "phi_N (north attitude error) at the end of the run",
       lambda r: float(r.last["att"][1]), figure=False),
    _m("phi_u_final", "angle", "arcmin", _ARCMIN,
       "phi_U (up attitude error, heading) at the end of the run",
       lambda r: float(r.last["att"][2]), figure=False),
)
_BY_NAME = {m.name: m for m in TABLE}
NAMES = tuple(_BY_NAME)                                            #: every metric, in order
FIGURE_METRICS = tuple(m.name for m in TABLE if m.figure)           #: what [paper] figures name
RUN_METRICS = tuple(m.name for m in TABLE if m.scope == "run")
GROUP_METRICS = tuple(m.name for m in TABLE if m.scope == "group")
_STAGES = ("position", "aided", "outages", "nav", "alignment", "static_fine")


# ---------------------------------------------------------------------------
# 2-4. Computing them
# ---------------------------------------------------------------------------
def _stages(spec):
    """The stages of run metrics ``spec`` (a pyins.scenario.RunSpec) computes."""
    yield "nav"
    if spec.config.get("coarse_ticks", 0) or spec.config.get("fine_ticks", 0):
        yield "alignment"
    if spec.config.get("fine_ticks", 0) and isinstance(spec.motion, sim.Static):
        yield "static_fine"


def record_steps(errors):
    """How much the errors move from one record to the next: (velocity, the
    larger of |d dv_E|, |d dv_N| [m/s]; position, |d (dE, dN)| [m]), one
    value per pair of records. At a mode switch they are its jump (the
    at-sea bound: under 1 cm/s and 1 m a second)."""
    dv = np.abs(np.diff(errors.vel_n_mps[:, :2], axis=0)).max(axis=1)
    dp = np.hypot(np.diff(errors.north_m), np.diff(errors.east_m))
    return dv, dp


def gnss_outages(refs, dt, end_s=None):
    """The GNSS outages of references ``refs`` (REF_DTYPE, or None): the gaps
    between position fixes longer than 2.5 times their usual interval (the
    median), as [(start, end)] in seconds, from the last fix before a gap to
    the first after it; with ``end_s`` (the run's end) also the time after
    the last fix when it is such a gap."""
    if refs is None:
        return []
    ticks = refs["tick"][refs["kind"] == abi.PYINS_REF_GNSS_POS]
    if len(ticks) < 3:
        return []
    gaps = np.diff(ticks)
    usual = float(np.median(gaps))
    big = np.flatnonzero(gaps > 2.5 * usual)
    out = [(float(ticks[i] * dt), float(ticks[i + 1] * dt)) for i in big]
    if end_s is not None and end_s - ticks[-1] * dt > 2.5 * usual * dt:
        out.append((float(ticks[-1] * dt), float(end_s)))
    return out


def run_metrics(spec, res):
    """The run metrics of one run (SI units): ``res`` holds its records
    and truth (a records.FilResult); {} when it has no records. The same
    figures as `scored` on the records in chunks (`records.score_variant`)."""
    if len(res.outputs) == 0:
        return {}
    run = start(spec, float(res.outputs["tick"][-1]) * res.dt)        # 1.
    run.add(res)
    return scored(run)


def start(spec, end_s):
    """A run's metrics to be folded chunk by chunk (``.add(FilResult)``, in
    tick order), the last record at ``end_s`` [s]; `scored` gives them."""
    return _Run(spec, end_s)


def scored(run):
    """The run metrics (SI units) of a `start`ed run that has folded in all
    its records; {} when it had none."""
    if run.last is None:
        return {}
    spec = run.spec
    stages = [*(["position"] if run.navigates else []),
              *(["aided"] if run.navigates and getattr(spec, "refs", None) is not None else []),
              *(["outages"] if run.navigates and gnss_outages(getattr(spec, "refs", None), spec.dt) else []),
              *_stages(spec)]
    return {m.name: m.compute(run) for m in TABLE if m.stage in stages}   # 2-4., in the table's order


def group_metrics(variants):
    """The group metrics over summary entries (each with ``metrics``): {}
    with fewer than two runs that have the final attitude errors."""
    if _std(variants) is None:
        return {}
    return {m.name: m.compute(variants) for m in TABLE if m.scope == "group"}


# ---------------------------------------------------------------------------
# Lookups
# ---------------------------------------------------------------------------
def info(name):
    """The `Metric` of ``name``, or None."""
    return _BY_NAME.get(name)


def dimension(name):
    """The `pyins.units` dimension of a metric ("dimensionless" if unknown)."""
    m = _BY_NAME.get(name)
    return m.dimension if m else "dimensionless"


def describe(name):
    """What a metric means ("" if unknown)."""
    m = _BY_NAME.get(name)
    return m.description if m else ""


def si_unit(name):
    """The SI unit a metric is held in ("rad", "m", "m/s", "rad/s"; "" if unknown)."""
    m = _BY_NAME.get(name)
    return m.si_unit if m else ""


_SI_SUFFIX = {"length": "_m", "angle": "_rad", "velocity": "_mps", "angular_rate": "_rad_s"}


def si_name(name):
    """``level_error_final`` -> ``level_error_final_rad`` (the SI unit in the name)."""
    return name + _SI_SUFFIX.get(dimension(name), "")


def display(name, values_si=()):
    """(unit, scale) a metric is shown in: value shown = value_si / scale.

    Horizontal errors are shown in nmi when any of ``values_si`` (None
    ignored) exceeds half a nautical mile, else in m; every other metric in
    its unit of the table; unknown names plainly, ("", 1.0).
    """
    if name.startswith("horizontal_error"):
        big = max((abs(v) for v in values_si if v is not None), default=0.0)
        return ("nmi", NMI_TO_M) if big > 0.5 * NMI_TO_M else ("m", 1.0)
    m = _BY_NAME.get(name)
    return (m.unit, m.scale) if m else ("", 1.0)


# ---------------------------------------------------------------------------
# Which alignment ran and how sure it was (a run's and a replay's summary)
# ---------------------------------------------------------------------------
#: enum pyins_coarse_method's names, as the scenario files write them
COARSE_NAMES = {abi.PYINS_COARSE_TRIAD: "TRIAD", abi.PYINS_COARSE_FIT: "FIT", abi.PYINS_COARSE_EQ8: "EQ8",
                abi.PYINS_COARSE_FIT_VEL: "FIT_VEL (under way)"}


def alignment_method(cfg, hz):
    """Which alignment ran, in words, from the firmware configuration ``cfg``
    (a dict of pyins_config fields; an absent field the firmware's default)
    at ``hz`` ticks a second: its coarse method and length, then the fine
    filter or the navigation filter that refined it; None when the run does
    not align (it starts navigating from the configured attitude)."""
    parts = []
    if cfg.get("coarse_ticks", 0) > 0:
        name = COARSE_NAMES.get(cfg.get("coarse_method", abi.PYINS_COARSE_TRIAD), "unknown")
        parts.append(f"coarse {name} {cfg['coarse_ticks'] / hz:g} s")
    if cfg.get("fine_ticks", 0) > 0:
        states = cfg.get("fine_states") or 5
        parts.append(f"fine {states}-state {'moving-base ' if states == 12 else ''}filter "
                     f"{cfg['fine_ticks'] / hz:g} s")
    if not parts:
        return None
    if cfg.get("nav_mode", abi.PYINS_NAV_AUTO) != abi.PYINS_NAV_UNDAMPED:
        parts.append("the navigation filter while a reference aids it")
    return ", then ".join(parts)


def alignment_heading_sigma(rec):
    """The heading sigma [arcmin] of a record (the first in navigation: as
    navigation began): the navigation filter's, else the fine filter's;
    None where no filter estimates it (a coarse alignment alone, undamped)."""
    if rec["nav_sigma_heading_rad"] > 0.0:
        return float(rec["nav_sigma_heading_rad"]) / ARCMIN_TO_RAD
    if rec["kf_states"]:
        return float(rec["kf_sigma"][PHI][2]) / ARCMIN_TO_RAD
    return None


def aligned(cfg, hz, outputs):
    """A run's alignment for its summary: {"method", "time_s" (navigation
    began), "heading_sigma_arcmin" (then)}; None when it does not align or
    never reached navigation."""
    if not len(outputs):
        return None
    nav = np.flatnonzero(outputs["mode"] == abi.PYINS_MODE_NAVIGATE)
    return aligned_at(cfg, hz, outputs[nav[0]] if len(nav) else None)


def aligned_at(cfg, hz, first):
    """`aligned` from ``first``, the first navigating record (None: it never
    navigated)."""
    method = alignment_method(cfg, hz)
    if method is None or first is None:
        return None
    return dict(method=method, time_s=float(first["tick"]) / hz, heading_sigma_arcmin=alignment_heading_sigma(first))
