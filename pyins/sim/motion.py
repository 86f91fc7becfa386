"""Ship motion: the analytic base profiles of the simulator.

Every ship profile is an object with a method ``state(t, t_lo=None)`` that
takes a 1-D array of times [s] from the start of the profile and returns a
`MotionState`: latitude, longitude, height, velocity and its derivative in n
(East-North-Up), Euler angles ``[pitch, roll, yaw]`` and their derivatives.
Everything is closed form and smooth inside each tick, so that
`pyins.sim.imu.exact_increments` can integrate the body rates and specific
force by Gauss-Legendre quadrature to double precision. The one exception is
the position of a moving ship (`Manoeuvre`), which is integrated once,
numerically, to double precision.

1. The state and the base class: `MotionState`, `Motion`.
2. At a fixed position: `Static`, `Swing` and the sea states of seed 000
   (`SEA_STATES`, `sea_state`), `HeadingSwing` with the set-up of seed 002
   (``SEED002_*``).
3. Under way: `Segment`, `default_segments`, `Manoeuvre`.

The sea around a moored ship (heave, surge, sway, lever arms, wave spectra)
is `pyins.sim.ship`; the turntable's profiles are `pyins.sim.turntable`.

Conventions (docs/design.md §2): C_b^n = Rz(yaw) Rx(pitch) Ry(roll); yaw is
counter-clockwise positive from North (marine heading = (-yaw) mod 2 pi);
b is x starboard, y bow, z up. SI units.

Time representation
-------------------
``t_lo`` is an optional low-order part of the time: the time meant is the
exact sum ``t + t_lo`` (`pyins.sim.exact_time`). `pyins.sim.imu` builds node
times as such pairs (`split_times`) so that a 24-h or 72-h run keeps sinusoid
phases exact to ~1e-16 rad instead of ulp(2 pi f t) ~ 1e-11 rad: the phase is
reduced to a fraction of a cycle with error-free products (`frac_cycles`).
Users may ignore ``t_lo``.

References
----------
- Qin Yongyuan, "Inertial Navigation" (2nd ed., 2014), sec. 4.1: position
  rates lat_dot = vN / (R_M + h), lon_dot = vE / ((R_N + h) cos lat).
- Seed 000, Table 2 (sea states), docs/papers.md, seed 000 §2; seed 002,
  sec. 3 (heading-swing profiles) and Table 1 (initial state),
  docs/papers.md, seed 002 §7.
"""

from dataclasses import dataclass

import math

import numpy as np
from numpy.polynomial.legendre import leggauss

from pyins.reference import earth
from pyins.sim.exact_time import as_times, frac_cycles
from pyins.units import DEG_TO_RAD, DT, TWO_PI


# ---------------------------------------------------------------------------
# 1. The state and the base class
# ---------------------------------------------------------------------------
@dataclass
class MotionState:
    """Ship state at N times (SI units, n = ENU, Euler ``[pitch, roll, yaw]``)."""
    lat: np.ndarray         #: geodetic latitude [rad], (N,)
    lon: np.ndarray         #: longitude [rad], (N,)
    height: np.ndarray      #: height above the ellipsoid [m], (N,)
    vel_n: np.ndarray       #: velocity in n [m/s], (N, 3)
    acc_n: np.ndarray       #: d(vel_n)/dt [m/s^2], (N, 3)
    euler: np.ndarray       #: [pitch, roll, yaw] [rad], (N, 3)
    euler_rate: np.ndarray  #: d(euler)/dt [rad/s], (N, 3)

    def __len__(self):
        return self.lat.shape[0]


class Motion:
    """Base class of the ship profiles: ``state(t, t_lo=None) -> MotionState``.

    ``duration`` is the length of the profile [s] (``inf`` when unbounded).
    ``frequencies_hz`` are the active frequencies of a profile whose rates
    repeat (``()`` when nothing moves), None when they need not repeat
    (`periodic_ticks`).
    """
    duration = np.inf
    frequencies_hz = None

    def state(self, t, t_lo=None):
        raise NotImplementedError


def periodic_ticks(motion, dt, limit=2_000_000):
    """Ticks after which the ship's body rate and force repeat exactly, or
    None: the least common multiple of each active frequency's whole-tick
    period (at most 1000 cycles, at most ``limit`` ticks); 1 when nothing
    moves; None for a profile that need not repeat (``frequencies_hz`` None).
    The closed loop (`pyins.fil`) computes such a profile's rates once per
    period."""
    freqs = motion.frequencies_hz
    if freqs is None:
        return None
    period = 1
    for f in freqs:
        ticks_per_cycle = 1.0 / (f * dt)
        for cycles in range(1, 1001):
            p = cycles * ticks_per_cycle
            if abs(p - round(p)) < 1e-9 * p:
                break
        else:
            return None
        period = math.lcm(period, int(round(p)))
        if period > limit:
            return None
    return period


# ---------------------------------------------------------------------------
# 2. At a fixed position
# ---------------------------------------------------------------------------
def _fixed_position(obj, n):
    return (np.full(n, obj.lat), np.full(n, obj.lon), np.full(n, obj.height))


class Static(Motion):
    """Ship at rest: fixed position and attitude.

    Parameters
    ----------
    lat, lon : float
        Geodetic latitude and longitude [rad].
    height : float
        Height above the WGS-84 ellipsoid [m].
    pitch, roll, yaw : float
        Euler angles [rad]; yaw counter-clockwise from North.
    """

    frequencies_hz = ()

    def __init__(self, lat, lon, height, pitch=0.0, roll=0.0, yaw=0.0):
        self.lat, self.lon, self.height = float(lat), float(lon), float(height)
        self.euler0 = np.array([pitch, roll, yaw], dtype=float)

    def state(self, t, t_lo=None):
        t, _ = as_times(t, t_lo)
        n = t.shape[0]
        lat, lon, h = _fixed_position(self, n)
        zeros = np.zeros((n, 3))
        return MotionState(lat, lon, h, zeros, zeros.copy(),
                           np.tile(self.euler0, (n, 1)), zeros.copy())

    def euler_accel(self, t, t_lo=None):
        """Second derivative of the Euler angles [rad/s^2], (N, 3): zero."""
        t, _ = as_times(t, t_lo)
        return np.zeros((t.shape[0], 3))


class Swing(Motion):
    """Ship at a fixed position swinging sinusoidally on all three Euler angles.

    ``euler[j](t) = mean[j] + amplitude[j] * sin(2 pi frequency_hz[j] t + phase[j])``
    for j = pitch, roll, yaw; velocity zero.

    Parameters
    ----------
    lat, lon, height : float
        Position [rad, rad, m].
    pitch0, roll0, yaw0 : float
        Mean Euler angles [rad].
    amplitude : array_like (3,)
        Amplitudes [rad], order [pitch, roll, yaw].
    frequency_hz : array_like (3,)
        Frequencies [Hz], same order.
    phase : array_like (3,)
        Phases [rad], same order.
    """

    def __init__(self, lat, lon, height, pitch0, roll0, yaw0,
                 amplitude, frequency_hz, phase=(0.0, 0.0, 0.0)):
        self.lat, self.lon, self.height = float(lat), float(lon), float(height)
        self.mean = np.array([pitch0, roll0, yaw0], dtype=float)
        self.amplitude = np.asarray(amplitude, dtype=float).reshape(3)
        self.frequency_hz = np.asarray(frequency_hz, dtype=float).reshape(3)
        self.phase = np.asarray(phase, dtype=float).reshape(3)

    @property
    def frequencies_hz(self):
        """The active frequencies [Hz]: those with a non-zero amplitude."""
        return tuple(float(f) for amp, f in zip(self.amplitude, self.frequency_hz)
                     if amp != 0.0 and f != 0.0)

    @classmethod
    def sea_state(cls, name, lat, lon, height, yaw0, pitch0=0.0, roll0=0.0,
                  phase=(0.0, 0.0, 0.0)):
        """Swing of seed 000 Table 2 (see `sea_state`)."""
        return sea_state(name, lat, lon, height, yaw0, pitch0, roll0, phase)

    def state(self, t, t_lo=None):
        t, t_lo = as_times(t, t_lo)
        n = t.shape[0]
        euler = np.empty((n, 3))
        rate = np.empty((n, 3))
        for j in range(3):
            phase = TWO_PI * frac_cycles(self.frequency_hz[j], t, t_lo) + self.phase[j]
            omega = TWO_PI * self.frequency_hz[j]
            euler[:, j] = self.mean[j] + self.amplitude[j] * np.sin(phase)
            rate[:, j] = (self.amplitude[j] * omega) * np.cos(phase)
        lat, lon, h = _fixed_position(self, n)
        zeros = np.zeros((n, 3))
        return MotionState(lat, lon, h, zeros, zeros.copy(), euler, rate)

    def euler_accel(self, t, t_lo=None):
        """Second derivative of the Euler angles [rad/s^2], (N, 3).

        ``-amplitude (2 pi f)^2 sin(phase)``, the phase formed exactly as in
        `state` (so HeadingSwing gets ``-A (2 pi / T) sin(2 pi t / T)``).
        """
        t, t_lo = as_times(t, t_lo)
        acc = np.empty((t.shape[0], 3))
        for j in range(3):
            phase = TWO_PI * frac_cycles(self.frequency_hz[j], t, t_lo) + self.phase[j]
            omega = TWO_PI * self.frequency_hz[j]
            acc[:, j] = -(self.amplitude[j] * omega * omega) * np.sin(phase)
        return acc


#: Seed 000 Table 2, the three-axis turntable swing profiles:
#: ``name -> {frame: (amplitude [deg], frequency [Hz])}`` for the inner,
#: middle and outer frames, as printed (docs/papers.md, seed 000 §2).
SEA_STATES = {
    "general": {"inner": (10.0, 0.125), "middle": (4.0, 0.2), "outer": (4.0, 0.2)},
    "ideal": {"inner": (3.0, 0.06), "middle": (2.5, 0.08), "outer": (2.0, 0.08)},
    "bad": {"inner": (16.0, 0.2), "middle": (10.0, 0.3), "outer": (10.0, 0.3)},
}


def sea_state(name, lat, lon, height, yaw0, pitch0=0.0, roll0=0.0,
              phase=(0.0, 0.0, 0.0)):
    """Swing profile of one sea state of seed 000 Table 2 (docs/papers.md, seed 000 §2).

    Mapping of the turntable frames onto the Euler angles: the sequence
    C_b^n = Rz(yaw) Rx(pitch) Ry(roll) is itself the outer-middle-inner gimbal
    order (the outer frame turns about the vertical, the middle frame about
    the turned x axis, the inner frame about the twice-turned y axis), so

    - outer frame  -> yaw,
    - middle frame -> pitch,
    - inner frame  -> roll.

    Example: 'bad' gives roll 16 deg at 0.2 Hz, pitch 10 deg at 0.3 Hz, yaw
    10 deg at 0.3 Hz about the mean attitude (pitch0, roll0, yaw0).

    Parameters
    ----------
    name : {'general', 'ideal', 'bad'}
        Sea state.
    lat, lon, height : float
        Position [rad, rad, m].
    yaw0, pitch0, roll0 : float
        Mean attitude [rad].
    phase : array_like (3,)
        Phases [rad] of [pitch, roll, yaw]; the paper gives none (zero).
    """
    if name not in SEA_STATES:
        raise ValueError(f"unknown sea state {name!r}; choose one of {sorted(SEA_STATES)}")
    s = SEA_STATES[name]
    amp_deg = [s["middle"][0], s["inner"][0], s["outer"][0]]   # pitch, roll, yaw
    freq = [s["middle"][1], s["inner"][1], s["outer"][1]]
    amp = np.array(amp_deg) * DEG_TO_RAD
    return Swing(lat, lon, height, pitch0, roll0, yaw0, amp, freq, phase)


#: Seed 002 Table 1 initial state (docs/papers.md, seed 002 §7): position of
#: Xi'an and the IMU attitude pitch 1 deg, roll -2 deg, IMU heading 15 deg
#: (yaw -15 deg).
SEED002_LAT = 34.246 * DEG_TO_RAD
SEED002_LON = 108.910 * DEG_TO_RAD
SEED002_HEIGHT = 380.0
SEED002_PITCH = 1.0 * DEG_TO_RAD
SEED002_ROLL = -2.0 * DEG_TO_RAD
SEED002_YAW = -15.0 * DEG_TO_RAD
#: Heading-swing experiments of seed 002: number -> (rate amplitude [deg/s],
#: period [s]), omega(t) = 6 cos(2 pi t / T) deg/s (docs/papers.md, seed 002 §7).
SEED002_EXPERIMENTS = {1: (6.0, 120.0), 2: (6.0, 60.0)}


class HeadingSwing(Swing):
    """Heading-only swing of seed 002: yaw rate ``A cos(2 pi t / T)``
    (docs/papers.md, seed 002 §7).

    yaw(t) = yaw0 + A T / (2 pi) sin(2 pi t / T); pitch and roll held
    constant; position fixed; velocity zero. The up-axis rate is taken
    counter-clockwise positive, i.e. it is the yaw rate. (With a non-zero
    pitch or roll this is the rate of the Euler yaw angle, not exactly the
    body z rate.)

    Parameters
    ----------
    lat, lon, height : float
        Position [rad, rad, m].
    pitch, roll, yaw0 : float
        Constant pitch and roll, initial yaw [rad].
    rate_amplitude : float
        A [rad/s].
    period : float
        T [s].
    """

    def __init__(self, lat, lon, height, pitch, roll, yaw0, rate_amplitude, period):
        self.rate_amplitude = float(rate_amplitude)
        self.period = float(period)
        f = 1.0 / self.period
        # amplitude * (2 pi f) == A: the yaw rate of Swing.state is A cos(...).
        amp = self.rate_amplitude / (TWO_PI * f)
        super().__init__(lat, lon, height, pitch, roll, yaw0,
                         [0.0, 0.0, amp], [0.0, 0.0, f])

    @classmethod
    def experiment(cls, number, yaw0=SEED002_YAW):
        """Seed 002 experiment 1 (A = 6 deg/s, T = 120 s) or 2 (T = 60 s).

        Initial state of seed 002 Table 1: 34.246 N, 108.910 E, 380 m, pitch
        1 deg, roll -2 deg, IMU heading 15 deg -> yaw = -15 deg (the table
        angle is 0 at the start, so IMU heading = ship heading).
        """
        if number not in SEED002_EXPERIMENTS:
            raise ValueError(f"seed 002 has experiments 1 and 2, not {number!r}")
        a_deg, period = SEED002_EXPERIMENTS[number]
        return cls(SEED002_LAT, SEED002_LON, SEED002_HEIGHT, SEED002_PITCH,
                   SEED002_ROLL, yaw0, a_deg * DEG_TO_RAD, period)


class NarrowbandYaw(Motion):
    """A ship's random narrowband yaw at a fixed position: seed 002's
    heading swing made random (the claims issue: the scheme ranking of
    seed 002 rests on a perfect sinusoid; a sea's yaw is not one).

    yaw(t) = yaw0 + sum_k a_k sin(2 pi f_k t + phi_k); pitch and roll held
    constant; velocity zero. The spectrum is the linear wave-response
    model of Fossen (Handbook of Marine Craft Hydrodynamics and Motion
    Control, 2011, sec. 8.2.4, eq. 8.118): the yaw angle the output of
    h(s) = K s / (s^2 + 2 lambda w0 s + w0^2) driven by white noise, so its
    density is S(w) ~ w^2 / ((w0^2 - w^2)^2 + (2 lambda w0 w)^2), peaked at
    the encounter frequency w0 = 2 pi / ``peak_period`` with relative
    damping ``damping`` (Fossen's 0.1 for a narrow sea). It is sampled on
    the frequencies f_k = k / ``repeat_s`` within [f0 / 3, 3 f0] (the
    random-phase method: a_k^2 / 2 = S(w_k) dw, phi_k uniform from
    ``seed``), scaled so that the yaw rate's RMS is ``rms_rate``. The yaw
    repeats after ``repeat_s`` (1801 s by default: half an hour, a prime
    number of seconds, so that no indexing cycle of whole seconds shares its
    period), which lets the closed loop compute its rates once
    (`periodic_ticks`): a random yaw for half an hour, then the same again.

    Parameters
    ----------
    lat, lon, height : float
        Position [rad, rad, m].
    pitch, roll, yaw0 : float
        Constant pitch and roll, mean yaw [rad].
    rms_rate : float
        The yaw rate's RMS [rad/s] (seed 002's sinusoid A cos: A / sqrt 2).
    peak_period : float
        2 pi / w0 [s].
    seed : int
        The phases' draw.
    damping : float
        lambda.
    repeat_s : int
        The period of the realisation [s].
    """

    def __init__(self, lat, lon, height, pitch, roll, yaw0, rms_rate, peak_period, seed,
                 damping=0.1, repeat_s=1801):
        self.lat, self.lon, self.height = float(lat), float(lon), float(height)
        self.pitch, self.roll, self.yaw0 = float(pitch), float(roll), float(yaw0)
        if not (rms_rate >= 0.0 and peak_period > 0.0 and 0.0 < damping < 1.0 and int(repeat_s) > 0):
            raise ValueError("NarrowbandYaw: rms_rate >= 0, peak_period > 0, 0 < damping < 1, repeat_s > 0")
        f0 = 1.0 / float(peak_period)
        k = np.arange(max(1, int(np.ceil(f0 / 3.0 * repeat_s))), int(np.floor(3.0 * f0 * repeat_s)) + 1)
        self.freq = k / float(repeat_s)
        w, w0 = TWO_PI * self.freq, TWO_PI * f0
        density = w * w / ((w0 * w0 - w * w) ** 2 + (2.0 * damping * w0 * w) ** 2)
        amp = np.sqrt(2.0 * density)                    # dw common to all: the scale absorbs it
        rate_rms = np.sqrt(0.5 * np.sum((amp * w) ** 2))
        self.amp = amp * (float(rms_rate) / rate_rms) if rate_rms > 0.0 else amp * 0.0
        self.phase = np.random.default_rng(seed).uniform(0.0, TWO_PI, len(k))
        self.rms_rate, self.peak_period, self.damping = float(rms_rate), float(peak_period), float(damping)
        self.repeat_s, self.seed = int(repeat_s), seed

    @property
    def frequencies_hz(self):
        return tuple(float(f) for a, f in zip(self.amp, self.freq) if a != 0.0)

    def _yaw(self, t, t_lo, accel=False):
        """(yaw - yaw0, yaw rate) at t, or the yaw's second derivative with
        ``accel``: one phase, one sine and one cosine per component."""
        t, t_lo = as_times(t, t_lo)
        a0 = np.zeros(t.shape[0])
        a1 = np.zeros(t.shape[0])
        for a, f, ph in zip(self.amp, self.freq, self.phase):
            x = TWO_PI * frac_cycles(f, t, t_lo) + ph
            w = TWO_PI * f
            if accel:
                a0 -= (a * w * w) * np.sin(x)
            else:
                a0 += a * np.sin(x)
                a1 += (a * w) * np.cos(x)
        return a0, a1

    def state(self, t, t_lo=None):
        t, t_lo = as_times(t, t_lo)
        n = t.shape[0]
        yaw, yaw_rate = self._yaw(t, t_lo)
        euler = np.empty((n, 3))
        euler[:, 0], euler[:, 1] = self.pitch, self.roll
        euler[:, 2] = self.yaw0 + yaw
        rate = np.zeros((n, 3))
        rate[:, 2] = yaw_rate
        lat, lon, h = _fixed_position(self, n)
        zeros = np.zeros((n, 3))
        return MotionState(lat, lon, h, zeros, zeros.copy(), euler, rate)

    def euler_accel(self, t, t_lo=None):
        """Second derivative of the Euler angles [rad/s^2], (N, 3)."""
        t, t_lo = as_times(t, t_lo)
        acc = np.zeros((t.shape[0], 3))
        acc[:, 2] = self._yaw(t, t_lo, accel=True)[0]
        return acc


# ---------------------------------------------------------------------------
# 3. Under way
# ---------------------------------------------------------------------------
@dataclass
class Segment:
    """One leg of a `Manoeuvre`.

    kind : 'accelerate', 'decelerate', 'cruise' or 'turn'.
    ticks : duration in whole ticks.
    value : target speed [m/s] for 'accelerate' / 'decelerate', yaw change
        [rad] (counter-clockwise positive, i.e. positive = turn to port) for
        'turn', unused for 'cruise'.
    """
    kind: str
    ticks: int
    value: float = 0.0


def default_segments(dt=DT):
    """The default 30-min manoeuvre (1800 s), durations rounded to ticks of ``dt``.

    accelerate 0 -> 10 m/s in 120 s; cruise 300 s; turn +90 deg (yaw,
    counter-clockwise, to port) in 60 s; cruise 300 s; turn -135 deg (to
    starboard) in 90 s; cruise 300 s; decelerate to 0 in 120 s; stay 510 s.
    Peak turn rate 3 deg/s, peak centripetal acceleration 0.52 m/s^2, peak
    longitudinal acceleration 0.17 m/s^2.
    """
    legs = [("accelerate", 120.0, 10.0), ("cruise", 300.0, 0.0),
            ("turn", 60.0, 90.0 * DEG_TO_RAD), ("cruise", 300.0, 0.0),
            ("turn", 90.0, -135.0 * DEG_TO_RAD), ("cruise", 300.0, 0.0),
            ("decelerate", 120.0, 0.0), ("cruise", 510.0, 0.0)]
    return [Segment(kind, _seconds_to_ticks(sec, dt), value) for kind, sec, value in legs]


def _seconds_to_ticks(sec, dt):
    n = int(round(sec / dt))
    if abs(n * dt - sec) > 1e-9 * max(sec, 1.0):
        raise ValueError(f"{sec} s is not a whole number of {dt} s ticks")
    return n


def _raised_cosine(u):
    """Smooth step g(u) = u - sin(2 pi u) / (2 pi) and g'(u) = 2 sin^2(pi u)."""
    s2 = np.sin(TWO_PI * u)
    return u - s2 / TWO_PI, 1.0 - np.cos(TWO_PI * u)


class Manoeuvre(Motion):
    """A ship under way: level (or constant small pitch/roll), moving along the bow.

    vel_n = speed(t) [-sin(yaw), cos(yaw), 0]; height constant. Speed and yaw
    change only in segments, each a whole number of ticks long, by
    raised-cosine (sin^2) pulses of acceleration or turn rate:

        u = tau / D,   g(u) = u - sin(2 pi u) / (2 pi),   g'(u) = 1 - cos(2 pi u)
        speed = v0 + dv g(u),   accel = dv g'(u) / D
        yaw   = psi0 + dpsi g(u), yaw_rate = dpsi g'(u) / D

    so acceleration, turn rate and their derivatives are continuous at the
    segment boundaries. acc_n = accel [-sin, cos, 0] + speed yaw_rate
    [-cos, -sin, 0].

    Position is not closed form. lat and lon at the tick boundaries are the
    integrals of lat_dot = vN / (R_M + h) and lon_dot = vE / ((R_N + h) cos lat)
    (Qin 2014 sec. 4.1), by Gauss-Legendre quadrature per tick with a
    fixed-point iteration on the latitude (R_M depends on it), block by block
    along the trajectory, until the largest change is below 1e-15 rad. The
    latitude at each quadrature node is itself a Gauss-Legendre integral from
    the tick start (nested quadrature), with the latitude inside that inner
    integral interpolated linearly between the tick boundaries (its
    curvature within a tick, ~3e-13 rad, moves the result by < 1e-20 rad).
    The nesting matters: taking the tick-start latitude at the nodes instead
    accumulates ~1e-12 rad in 30 min. Inside a tick, `state` uses the same nested
    rule from the preceding boundary. The positions are offsets from the start
    accumulated separately, so rounding does not grow with the run length.

    Parameters
    ----------
    lat, lon, height : float
        Start position [rad, rad, m].
    yaw0 : float
        Initial yaw [rad], counter-clockwise from North.
    segments : sequence of `Segment` or tuples ``(kind, ticks[, value])``
        The legs, in order.
    dt : float
        Tick length [s] that the segment durations count.
    speed0 : float
        Initial speed [m/s].
    pitch, roll : float
        Constant pitch and roll [rad].
    nodes : int
        Gauss-Legendre nodes of the position quadrature (per tick and nested).
    current : object or None
        The water current the ship drifts with, an object with
        ``velocity(t)`` and ``acceleration(t)`` ((N,) -> (N, 3) ENU, e.g.
        `pyins.sim.references.Current`): the ground velocity is the speed
        through water along the bow plus the current (the heading stays the
        bow's: the ship crabs); None: still water.
    """

    _BLOCK_TICKS = 8192
    _MAX_ITER = 50
    _TOL = 1e-15

    def __init__(self, lat, lon, height, yaw0, segments, dt=DT, speed0=0.0,
                 pitch=0.0, roll=0.0, nodes=5, current=None):
        self.current = current
        self.lat0, self.lon0, self.height = float(lat), float(lon), float(height)
        self.yaw0 = float(yaw0)
        self.dt = float(dt)
        self.pitch, self.roll = float(pitch), float(roll)
        self.segments = [s if isinstance(s, Segment) else Segment(*s) for s in segments]
        if not self.segments:
            raise ValueError("a Manoeuvre needs at least one segment")
        start, ticks, v0, dv, psi0, dpsi = [], [], [], [], [], []
        n, v, psi = 0, float(speed0), self.yaw0
        for i, seg in enumerate(self.segments):
            if int(seg.ticks) != seg.ticks or seg.ticks <= 0:
                raise ValueError(f"segment {i}: ticks must be a positive integer, got {seg.ticks!r}")
            dspeed = dyaw = 0.0
            if seg.kind == "accelerate":
                if not seg.value > v:
                    raise ValueError(f"segment {i}: accelerate to {seg.value} m/s from {v} m/s")
                dspeed = seg.value - v
            elif seg.kind == "decelerate":
                if not (0.0 <= seg.value < v):
                    raise ValueError(f"segment {i}: decelerate to {seg.value} m/s from {v} m/s")
                dspeed = seg.value - v
            elif seg.kind == "turn":
                dyaw = float(seg.value)
            elif seg.kind != "cruise":
                raise ValueError(f"segment {i}: unknown kind {seg.kind!r}")
            start.append(n)
            ticks.append(int(seg.ticks))
            v0.append(v)
            dv.append(dspeed)
            psi0.append(psi)
            dpsi.append(dyaw)
            n += int(seg.ticks)
            v += dspeed
            psi += dyaw
        self.n_ticks = n
        self.duration = n * self.dt
        self._start_tick = np.array(start, dtype=np.int64)
        self._seg_t0 = self._start_tick * self.dt
        self._seg_len = np.array(ticks, dtype=float) * self.dt
        self._v0, self._dv = np.array(v0), np.array(dv)
        self._psi0, self._dpsi = np.array(psi0), np.array(dpsi)
        self._x, self._w = leggauss(nodes)
        self._s = 0.5 * (1.0 + self._x)   # node positions as fractions of an interval
        self._dlat = None                 # (n_ticks + 1,) lat - lat0 at tick boundaries
        self._dlon = None

    @classmethod
    def default(cls, lat, lon, height, yaw0, dt=DT, **kwargs):
        """The 30-min default manoeuvre (`default_segments`)."""
        return cls(lat, lon, height, yaw0, default_segments(dt), dt=dt, **kwargs)

    # -- closed-form kinematics -------------------------------------------
    def kinematics(self, t):
        """Speed [m/s], acceleration [m/s^2], yaw [rad] and yaw rate [rad/s] at t."""
        t = np.asarray(t, dtype=float)
        k = np.clip(np.searchsorted(self._seg_t0, t, side="right") - 1,
                    0, len(self.segments) - 1)
        length = self._seg_len[k]
        u = np.clip((t - self._seg_t0[k]) / length, 0.0, 1.0)
        g, gp = _raised_cosine(u)
        speed = self._v0[k] + self._dv[k] * g
        accel = self._dv[k] / length * gp
        yaw = self._psi0[k] + self._dpsi[k] * g
        yaw_rate = self._dpsi[k] / length * gp
        return speed, accel, yaw, yaw_rate

    def _vel_ne(self, t):
        speed, _, yaw, _ = self.kinematics(t)
        vn, ve = speed * np.cos(yaw), -speed * np.sin(yaw)
        if self.current is None:
            return vn, ve
        c = self.current.velocity(np.ravel(t)).reshape(np.shape(t) + (3,))
        return vn + c[..., 1], ve + c[..., 0]             # vN, vE over ground

    # -- positions ------------------------------------------------------------
    def _partial(self, t_start, tau, lat_j, lat_j1, vn=None, ve=None):
        """Integrals of lat_dot and lon_dot from t_start to t_start + tau.

        Gauss-Legendre with the module's nodes; the latitude inside is the
        linear interpolation between the tick-boundary values lat_j, lat_j1.
        All arguments broadcast; the node axis is appended last.
        """
        frac = tau[..., None] * self._s
        if vn is None:
            vn, ve = self._vel_ne(t_start[..., None] + frac)
        lat = lat_j[..., None] + (lat_j1 - lat_j)[..., None] * (frac / self.dt)
        sin_lat = np.sin(lat)
        rm, rn = earth.principal_radii(sin_lat)
        lat_rate = vn / (rm + self.height)
        lon_rate = ve / ((rn + self.height) * np.cos(lat))
        acc_lat = np.zeros(np.shape(lat_rate)[:-1])
        acc_lon = np.zeros_like(acc_lat)
        for i, w in enumerate(self._w):
            acc_lat = acc_lat + w * lat_rate[..., i]
            acc_lon = acc_lon + w * lon_rate[..., i]
        half = 0.5 * tau
        return half * acc_lat, half * acc_lon

    def _tick_integrals(self, j, dlat_j, dlat_j1, vn_m, ve_m, vn_s, ve_s):
        """lat and lon increments over ticks j, given the boundary latitudes."""
        lat_j = self.lat0 + dlat_j
        lat_j1 = self.lat0 + dlat_j1
        tj = j * self.dt
        tau = np.broadcast_to(self._s * self.dt, (len(j), len(self._s)))
        part_lat, _ = self._partial(tj[:, None], tau, lat_j[:, None], lat_j1[:, None],
                                    vn_s, ve_s)
        lam = self.lat0 + (dlat_j[:, None] + part_lat)     # latitude at the main nodes
        sin_lam = np.sin(lam)
        rm, rn = earth.principal_radii(sin_lam)
        lat_rate = vn_m / (rm + self.height)
        lon_rate = ve_m / ((rn + self.height) * np.cos(lam))
        d_lat = np.zeros(len(j))
        d_lon = np.zeros(len(j))
        for i, w in enumerate(self._w):
            d_lat = d_lat + w * lat_rate[:, i]
            d_lon = d_lon + w * lon_rate[:, i]
        half = 0.5 * self.dt
        return half * d_lat, half * d_lon

    def _ensure_positions(self):
        if self._dlat is not None:
            return
        m = self.n_ticks
        dlat = np.zeros(m + 1)
        dlon = np.zeros(m + 1)
        s = self._s
        self.iterations = []
        for j0 in range(0, m, self._BLOCK_TICKS):
            j1 = min(j0 + self._BLOCK_TICKS, m)
            j = np.arange(j0, j1)
            tj = j * self.dt
            vn_m, ve_m = self._vel_ne(tj[:, None] + s * self.dt)
            vn_s, ve_s = self._vel_ne(tj[:, None, None] + (s[:, None] * s) * self.dt)
            block = np.full(j1 - j0 + 1, dlat[j0])
            for it in range(1, self._MAX_ITER + 1):
                d_lat, _ = self._tick_integrals(j, block[:-1], block[1:],
                                                vn_m, ve_m, vn_s, ve_s)
                new = dlat[j0] + np.concatenate(([0.0], np.cumsum(d_lat)))
                change = np.max(np.abs(new - block))
                block = new
                if change < self._TOL:
                    break
            else:
                raise RuntimeError(f"position fixed point did not converge in ticks "
                                   f"{j0}..{j1} (last change {change:.3g} rad)")
            self.iterations.append(it)
            _, d_lon = self._tick_integrals(j, block[:-1], block[1:],
                                            vn_m, ve_m, vn_s, ve_s)
            dlat[j0:j1 + 1] = block
            dlon[j0 + 1:j1 + 1] = dlon[j0] + np.cumsum(d_lon)
        self._dlat, self._dlon = dlat, dlon

    def boundary_positions(self):
        """lat, lon [rad] at the tick boundaries 0..n_ticks (times k * dt)."""
        self._ensure_positions()
        return self.lat0 + self._dlat, self.lon0 + self._dlon

    def state(self, t, t_lo=None):
        t, t_lo = as_times(t, t_lo)
        if t_lo is not None:
            t = t + t_lo
        if t.size and (np.min(t) < -1e-9 or np.max(t) > self.duration + 1e-9):
            raise ValueError(f"Manoeuvre is defined on [0, {self.duration}] s; "
                             f"times from {np.min(t)} to {np.max(t)} s were asked for")
        self._ensure_positions()
        q = t / self.dt
        j = np.floor(q)
        j = np.where(q - j > 1.0 - 1e-9, j + 1.0, j)       # snap onto a boundary
        j = np.clip(j, 0, self.n_ticks - 1).astype(np.int64)
        tau = t - j * self.dt
        tj = j * self.dt
        part_lat, part_lon = self._partial(tj, tau, self.lat0 + self._dlat[j],
                                           self.lat0 + self._dlat[j + 1])
        lat = self.lat0 + (self._dlat[j] + part_lat)
        lon = self.lon0 + (self._dlon[j] + part_lon)
        n = t.shape[0]
        speed, accel, yaw, yaw_rate = self.kinematics(t)
        sy, cy = np.sin(yaw), np.cos(yaw)
        vel = np.zeros((n, 3))
        vel[:, 0] = -speed * sy
        vel[:, 1] = speed * cy
        acc = np.zeros((n, 3))
        acc[:, 0] = -accel * sy - speed * yaw_rate * cy
        acc[:, 1] = accel * cy - speed * yaw_rate * sy
        euler = np.empty((n, 3))
        euler[:, 0] = self.pitch
        euler[:, 1] = self.roll
        euler[:, 2] = yaw
        rate = np.zeros((n, 3))
        rate[:, 2] = yaw_rate
        if self.current is not None:          # the drift with the water
            vel = vel + self.current.velocity(t)
            acc = acc + self.current.acceleration(t)
        return MotionState(lat, lon, np.full(n, self.height), vel, acc, euler, rate)
