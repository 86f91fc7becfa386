"""The checks of a log (`pyins.logs`'s docstring, Validation): the nominal
dt, time steps, gaps and irregular steps, finite values, and the magnitude
checks that catch unit mix-ups, over a log seen in windows (`_Scan`)."""
import numpy as np

from pyins.logs.issues import LogIssue, _plural
from pyins.logs.options import ACCEL_UNITS, GYRO_UNITS
from pyins.units import DT, G0

TIME_TOL = 0.01          #: allowed step deviation, fraction of dt (see `pyins.logs`, Validation)
GAP_TICKS = 1.5          #: a step longer than this many dt is a gap
MIN_STEP_TICKS = 0.5     #: a step shorter than this many dt is an error
GYRO_RATE_LIMIT = 10.0   #: [rad/s] above this the gyro unit is wrong
GRAVITY_BAND = (0.5 * G0, 2.0 * G0)  #: [m/s^2] plausible median |specific force|
DEFAULT_DT = DT                     #: [s] for plausibility checks of a CSV without dt
MAX_LISTED = 10          #: gaps listed one by one before a summary


# ---------------------------------------------------------------------------
# Checks: the log seen in windows, each finding counted across all of them
# ---------------------------------------------------------------------------
def _nominal_dt(steps, dt):
    """``dt``, or the median step rounded to 1 ns (unrounded if that would give 0)."""
    if dt is not None:
        return dt
    median = float(np.median(steps))
    return float(np.round(median, 9)) or median


_GYRO_HINTS = {
    ("increments", "rad"): "these look like deg, not rad (gyro_unit='deg')",
    ("increments", "deg"): "these look like rates, not increments (kind='rates')",
    ("rates", "rad/s"): "these look like deg/s, not rad/s (gyro_unit='deg/s')",
    ("rates", "deg/s"): "these look like deg/h, not deg/s (gyro_unit='deg/h')",
    ("rates", "deg/h"): "check gyro_unit and kind",
}

_ACCEL_READINGS = (("increments", "m/s", "m/s increments"), ("rates", "m/s^2", "m/s^2 rates"),
                   ("rates", "g", "g rates"))


def _check_gravity(name, where, kind, accel_unit, accel_raw, dt_nom):
    """The accelerometer's half of the unit checks: median |f| outside
    GRAVITY_BAND. Returns (issues, the kind the accelerometer says the log
    is, or None). It goes before the gyro's: gravity tells increments from
    rates more surely than any gyro level, and its verdict on the kind, if
    any, becomes the gyro's hint."""
    issues = []
    other_kind = None
    raw = float(np.median(np.linalg.norm(accel_raw, axis=1)))
    lo, hi = GRAVITY_BAND

    def as_si(k, unit):
        return raw * ACCEL_UNITS[k][unit] * (1.0 / dt_nom if k == "increments" else 1.0)

    force = as_si(kind, accel_unit)
    if not lo <= force <= hi:
        fits = [(k, label) for k, unit, label in _ACCEL_READINGS
                if (k, unit) != (kind, accel_unit) and lo <= as_si(k, unit) <= hi]
        declared = next((label for k, unit, label in _ACCEL_READINGS
                         if (k, unit) == (kind, accel_unit)), f"{accel_unit} {kind}")
        if fits:
            hint = f"these look like {' or '.join(label for _, label in fits)}, not {declared}"
            if all(k != kind for k, _ in fits):
                other_kind = fits[0][0]
        else:
            hint = ("check accel_unit and kind (plausibility=False for a log without "
                    "gravity)")
        issues.append(LogIssue("error", f"{name}: {where.span()}: median specific force "
                                        f"{force:.4g} m/s^2 (read as {declared}) is far from "
                                        f"1 g = {G0} m/s^2: {hint}"))
    return issues, other_kind


def _check_magnitudes(name, where, kind, gyro_unit, accel_unit, gyro_raw, accel_raw, dt_nom):
    """Unit mix-ups: median |f| outside GRAVITY_BAND, gyro rate above GYRO_RATE_LIMIT
    (the project's own files, read whole)."""
    issues, other_kind = _check_gravity(name, where, kind, accel_unit, accel_raw, dt_nom)
    scan = _Scan(name, None, kind, gyro_unit, plausibility=True)
    scan.dt_nom, scan.other_kind = dt_nom, other_kind
    scan.gyro_check(gyro_raw, where, 0)
    return issues + scan.gyro_issues()


class _Scan:
    """The checks of `read_log` (`pyins.logs`, Validation) over a log seen
    in windows: the probe (the first samples, whole), then one block at a time
    with the last sample before it as row 0, so that every step is checked
    once, across block boundaries too. Each finding keeps its first place and
    its count over the whole log; `issues` words them as `read_log` always
    has, in its order (a non-finite value before any time error, a time error
    before the magnitudes)."""

    def __init__(self, name, timed, kind, gyro_unit, plausibility, dt=None, accel_unit=None):
        self.name, self.timed, self.kind, self.gyro_unit = name, timed, kind, gyro_unit
        self.accel_unit = accel_unit
        self.plausibility, self.dt = plausibility, dt
        self.dt_nom = dt
        self.finite = self.mono = self.one = self.median = self.short = None
        self.n_finite = self.n_mono = self.n_short = 0
        self.gaps, self.n_gaps, self.missing, self.gap_more_at = [], 0, 0, None
        self.irregular, self.n_irregular = None, 0
        self.tick0, self.tick0_value = None, None
        self.gravity, self.other_kind = [], None
        self.gyro, self.n_gyro = None, 0

    # -- the probe: what is decided once, on the first samples ----------------
    def probe(self, values, t, where, accel_raw, eof):
        """The nominal dt (the median step, or dt checked against it), the
        first tick number and the gravity check, from the probe's samples."""
        name = self.name
        if not np.all(np.isfinite(values)):
            return                      # the finite error comes first; nothing else is said
        if self.timed:
            steps = np.diff(t)
            if np.any(steps <= 0.0):
                return                  # the time error comes first
            if steps.size == 0 and self.dt is None:
                self.one = LogIssue("error", f"{name}: {where.at(0)}: one sample: the time step "
                                             f"cannot be inferred; pass dt")
                return
            self.dt_nom = _nominal_dt(steps, self.dt) if steps.size else self.dt
            if steps.size and self.dt is not None:
                median = float(np.median(steps))
                if abs(median - self.dt) > TIME_TOL * self.dt:
                    self.median = LogIssue("error", f"{name}: {where.span()}: median time step "
                                                    f"{median:.9g} s differs from dt={self.dt:g} s "
                                                    f"by more than {TIME_TOL:.0%} (another rate, or "
                                                    f"time not in seconds?)")
                    return
            tick0 = np.floor(t[0] / self.dt_nom + 0.5)
            if not abs(tick0) < 2.0 ** 62:
                self.tick0 = LogIssue("error", f"{name}: {where.at(0)}: time {float(t[0])!r} s is "
                                               f"too large for tick numbers of {self.dt_nom:g} s")
            self.tick0_value = tick0
        if self.plausibility:
            self.gravity, self.other_kind = _check_gravity(name, where, self.kind, self.accel_unit,
                                                           accel_raw, self.dt_nom)

    # -- every window ----------------------------------------------------------
    def window(self, values, t, where, off, gyro_raw):
        """The checks of one window (``off`` = 1 when row 0 of ``t`` and
        ``where`` is the sample before it); returns the ticks each step
        advances (None when the time says nothing yet)."""
        name = self.name
        bad = np.argwhere(~np.isfinite(values))
        if bad.size:
            if self.finite is None:
                k, c = bad[0]
                self.finite = (f"{name}: {where.at(k + off, c)}: {float(values[k, c])!r} is not "
                               f"finite")
            self.n_finite += len(bad)
        ticks = None
        if self.timed:
            steps = np.diff(t)
            bad = np.nonzero(steps <= 0.0)[0]
            if bad.size:
                if self.mono is None:
                    k = bad[0] + 1
                    what = "repeats" if t[k] == t[k - 1] else "goes back from"
                    self.mono = (f"{name}: {where.at(k)}: time {float(t[k])!r} {what} "
                                 f"{float(t[k - 1])!r} at {where.at(k - 1)}: time must increase")
                self.n_mono += bad.size
            if self.dt_nom is None:
                return None
            dt_nom = self.dt_nom
            ratio = steps / dt_nom
            short = np.nonzero(ratio < MIN_STEP_TICKS)[0]
            if short.size:
                if self.short is None:
                    k = short[0] + 1
                    self.short = (f"{name}: {where.at(k)}: time step {steps[k - 1]:.9g} s after "
                                  f"{where.at(k - 1)} is less than half the tick dt={dt_nom:g} s (a "
                                  f"repeated or extra sample?)")
                self.n_short += short.size
            ticks = np.maximum(1, np.floor(ratio + 0.5)).astype(np.int64)
            gaps = np.nonzero(ratio > GAP_TICKS)[0]
            if gaps.size:
                for k in gaps[:max(0, MAX_LISTED - self.n_gaps)]:
                    missing = ticks[k] - 1
                    self.gaps.append(f"{name}: {where.at(k + 1)}: gap of {steps[k]:.9g} s after "
                                     f"{where.at(k)} (t={float(t[k])!r}): "
                                     f"{_plural(missing, 'missing tick')} of {dt_nom:g} s")
                if self.gap_more_at is None and self.n_gaps + gaps.size > MAX_LISTED:
                    self.gap_more_at = where.at(gaps[MAX_LISTED - self.n_gaps] + 1)
                self.n_gaps += gaps.size
                self.missing += int(np.sum(ticks[gaps] - 1))
            irregular = np.nonzero((np.abs(ratio - 1.0) > TIME_TOL) & (ratio <= GAP_TICKS))[0]
            if irregular.size:
                if self.irregular is None:
                    k = irregular[0] + 1
                    self.irregular = (f"{name}: {where.at(k)}: irregular time step "
                                      f"{steps[k - 1]:.9g} s, more than {TIME_TOL:.0%} from the "
                                      f"tick dt={dt_nom:g} s")
                self.n_irregular += irregular.size
        if self.plausibility and self.dt_nom is not None:
            self.gyro_check(gyro_raw, where, off)
        return ticks

    def gyro_check(self, gyro_raw, where, off):
        per_s = 1.0 / self.dt_nom if self.kind == "increments" else 1.0
        rate = np.linalg.norm(gyro_raw, axis=1) * (GYRO_UNITS[self.kind][self.gyro_unit] * per_s)
        over = np.nonzero(rate > GYRO_RATE_LIMIT)[0]
        if over.size:
            if self.gyro is None:
                self.gyro = (where.at(over[0] + off), rate[over[0]])
            self.n_gyro += over.size

    def gyro_issues(self):
        if self.gyro is None:
            return []
        at, rate = self.gyro
        kind = self.kind
        more = f"; {self.n_gyro} samples in all" if self.n_gyro > 1 else ""
        if self.other_kind is not None:
            hint = (f"the accelerometer says these are {self.other_kind}, not {kind} "
                    f"(kind={self.other_kind!r})")
        else:
            hint = _GYRO_HINTS.get((kind, self.gyro_unit), "check gyro_unit, the scale and kind")
        return [LogIssue("error", f"{self.name}: {at}: gyro rate {rate:.4g} rad/s (read as "
                                  f"{self.gyro_unit} {kind}) exceeds {GYRO_RATE_LIMIT:g} "
                                  f"rad/s{more}: {hint}")]

    # -- the verdict -----------------------------------------------------------
    def fatal(self, strict):
        """The log will be refused (an error, or a warning when strict): the
        rest is read only to word the refusal as `read_log` does."""
        return bool(self.finite or self.mono or self.one or self.median or self.short
                    or self.tick0 or self.gravity or self.gyro
                    or (strict and (self.gaps or self.irregular)))

    def issues(self):
        """The findings in `read_log`'s order (errors and warnings)."""
        if self.finite:
            more = (f" ({self.n_finite} non-finite values in all)" if self.n_finite > 1 else "")
            return [LogIssue("error", self.finite + more)]
        out = []
        if self.timed:
            if self.mono:
                more = f" ({self.n_mono} such steps in all)" if self.n_mono > 1 else ""
                return [LogIssue("error", self.mono + more)]
            if self.one:
                return [self.one]
            if self.median:
                return [self.median]
            if self.short:
                more = f" ({self.n_short} such steps in all)" if self.n_short > 1 else ""
                return [LogIssue("error", self.short + more)]
            out += [LogIssue("warning", g) for g in self.gaps]
            if self.n_gaps > MAX_LISTED:
                out.append(LogIssue("warning", f"{self.name}: {self.gap_more_at}: and "
                                               f"{self.n_gaps - MAX_LISTED} more gaps; "
                                               f"{self.n_gaps} gaps, {self.missing} missing "
                                               f"ticks in all"))
            if self.irregular:
                out.append(LogIssue("warning", f"{self.irregular} "
                                               f"({_plural(self.n_irregular, 'such step')} in "
                                               f"all)"))
            if self.tick0:
                out.append(self.tick0)
                return out
        if self.plausibility:
            out += self.gravity + self.gyro_issues()
        return out
