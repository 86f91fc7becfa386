"""A ship under way at sea: a voyage track, the heel in its turns, the sea-state
swing and heave on top.

`Voyage` is a `Manoeuvre` track (a level ship whose speed and course change in
whole-tick raised-cosine segments, position integrated numerically to double
precision) with, on top, the roll of a steady turn, the seed 000 sea-state
swing (`pyins.sim.motion.sea_state`) and a heave of sinusoids. Everything but
the track's position is closed form and smooth inside each tick, so
`pyins.sim.imu.exact_increments` stays exact. `default_voyage` builds a
multi-hour transit (course change every 30-60 min, speed changes now and
then); `course_change`, `speed_change` and `cruise` make single legs.

1. Legs: `course_change`, `speed_change`, `cruise`.
2. The ship under way: `Voyage`.
3. A default transit: `voyage_segments`, `default_voyage`.

Model (n = ENU, Euler [pitch, roll, yaw], docs/design.md §2)
--------------------------------------------------------------
Track (`Manoeuvre`): speed v(t), course psi_c(t) (yaw convention,
counter-clockwise from North), vN_h = v cos psi_c, vE_h = -v sin psi_c, and
lat, lon from lat_dot = vN_h / (R_M + h0), lon_dot = vE_h / ((R_N + h0) cos lat).
With a water ``current`` c(t) (`pyins.sim.references.Current`), v is the
speed through the water along the bow and the ground velocity is
[vE_h, vN_h] + c: the ship crabs (its heading stays psi_c), its positions
integrate the drift, its acceleration gains c'.

Heave: h = h0 + z(t), z = sum_i a_i sin(2 pi t / T_i + phi_i) (phases exact
over long runs, `pyins.sim.exact_time`). The track's lat, lon are kept; the
velocity is the one they imply at the CURRENT height (Qin 2014 sec. 4.1),

    vN = (R_M + h) lat_dot = vN_h (1 + z / (R_M + h0))
    vE = (R_N + h) cos(lat) lon_dot = vE_h (1 + z / (R_N + h0))
    vU = z'

so position and velocity agree exactly in the firmware's kinematics (the
factor differs from 1 by z / R < 1e-7 for metres of heave). acc_n is the exact
derivative: d/dt (z / (R + h0)) = z' / (R + h0) - z R' / (R + h0)^2 with
R' = dR/dlat lat_dot, dR_M/dlat = 3 R_M e2 s c / x, dR_N/dlat = R_N e2 s c / x
(s = sin lat, c = cos lat, x = 1 - e2 s^2; as `pyins.sim.ship`).

Heel in a turn: in a steady turn of radius R = v / r (r = psi_c') a
displacement ship heels OUTWARD, tan(phi) = v^2 BG / (g R GM) (Barrass &
Derrett; Rawson & Tupper): the centripetal force acts at the centre of
lateral resistance below G. So

    phi_turn = atan(K v r / g),  K = heel_factor (~BG / GM, 1 by default),
    phi_turn' = K (v' r + v r') / g / (1 + (K v r / g)^2).

Sign: r > 0 is a turn to port, outward is starboard, and a positive roll
(Ry about the bow) puts the starboard side down, so phi_turn has the sign of
r. K = 1 gives 0.4 deg at 15 kn and 0.5 deg/s. (The brief inward heel while
the rudder is put over is not modelled.) phi_turn is smooth because v and r
are: their pulses have continuous first derivatives at the segment ends.

Attitude: pitch = pitch0 + swing pitch; roll = roll0 + phi_turn + swing
roll; yaw = psi_c + swing yaw. The yaw swing turns the bow, not the track:
the velocity stays along psi_c (an oscillating drift angle).

Limits: ``state`` is the motion REFERENCE point and the IMU sits at it; no
lever arm, surge or sway is modelled (those are `pyins.sim.ship.ShipAtSea`'s,
for a moored ship). No ``euler_accel``. Not periodic (``frequencies_hz``
None); defined on [0, duration].

References
----------
- Fossen (2011), "Handbook of Marine Craft Hydrodynamics and Motion
  Control", ch. 7 (manoeuvring models; roll coupled into the turn) and
  ch. 8 (sea states and wave-induced motion).
- Barrass & Derrett (2006), "Ship Stability for Masters and Mates", 6th ed.,
  "angle of heel when turning"; Rawson & Tupper (2001), "Basic Ship
  Theory", 5th ed., ch. 13 (heel when turning, outward in the steady turn).
- Qin Yongyuan, "Inertial Navigation" (2nd ed., 2014), sec. 4.1.
- Seed 000 Table 2 (sea states), docs/papers.md, seed 000 §2.
"""
import math

import numpy as np

from pyins.reference import earth
from pyins.sim.exact_time import as_times
from pyins.sim.motion import Manoeuvre, Motion, MotionState, Segment, Swing, sea_state
from pyins.sim.ship import MOORED_SHIP, LinearMotion
from pyins.units import DEG_TO_RAD, DT, G0, NMI_TO_M, TWO_PI

#: One knot [m/s].
KNOT = NMI_TO_M / 3600.0
#: Default peak turn rate of `course_change` [rad/s] (mean rate half of it).
TURN_RATE = 1.0 * DEG_TO_RAD
#: Default peak longitudinal acceleration of `speed_change` [m/s^2].
SPEED_ACCEL = 0.05
#: Default heave: 0.5 m at 8 s (`pyins.sim.ship.MOORED_SHIP`).
HEAVE = MOORED_SHIP["heave"]
#: Gravity of the heel formula [m/s^2] (a ship constant, not the navigation's).
HEEL_G = G0
#: Default start of `default_voyage`: East China Sea, 30 N 123 E, sea level.
START = (30.0 * DEG_TO_RAD, 123.0 * DEG_TO_RAD, 0.0)


# ---------------------------------------------------------------------------
# 1. Legs
# ---------------------------------------------------------------------------
def _ticks(seconds, dt):
    n = int(np.rint(seconds / dt))
    if n <= 0 or abs(n * dt - seconds) > 1e-9 * max(seconds, 1.0):
        raise ValueError(f"{seconds} s is not a positive whole number of {dt} s ticks")
    return n


def cruise(seconds, dt=DT):
    """Steady speed and course for ``seconds`` (a whole number of ticks)."""
    return Segment("cruise", _ticks(float(seconds), dt))


def course_change(dyaw, rate=TURN_RATE, dt=DT):
    """A turn by ``dyaw`` [rad] (counter-clockwise positive = to port) whose
    peak yaw rate is at most ``rate`` [rad/s]: the raised-cosine pulse peaks
    at 2 dyaw / D, so D = 2 |dyaw| / rate, rounded UP to whole seconds."""
    if not (rate > 0.0 and dyaw != 0.0):
        raise ValueError(f"course_change needs dyaw != 0 and rate > 0, got {dyaw}, {rate}")
    return Segment("turn", _ticks(float(math.ceil(2.0 * abs(dyaw) / rate - 1e-9)), dt), float(dyaw))


def speed_change(v_from, v_to, accel=SPEED_ACCEL, dt=DT):
    """Speed from ``v_from`` to ``v_to`` [m/s] with a peak acceleration of at
    most ``accel`` [m/s^2]: D = 2 |dv| / accel, rounded UP to whole seconds."""
    if not (accel > 0.0 and v_to != v_from and v_to >= 0.0):
        raise ValueError(f"speed_change needs v_to != v_from, v_to >= 0, accel > 0, "
                         f"got {v_from}, {v_to}, {accel}")
    sec = float(math.ceil(2.0 * abs(v_to - v_from) / accel - 1e-9))
    return Segment("accelerate" if v_to > v_from else "decelerate", _ticks(sec, dt), float(v_to))


# ---------------------------------------------------------------------------
# 2. The ship under way
# ---------------------------------------------------------------------------
class Voyage(Motion):
    """A ship under way: `Manoeuvre` track + heel in turns + sea swing + heave.

    ``state`` is the motion reference point (where the IMU is taken to be; no
    lever arm is modelled). See the module docstring for the equations.

    Parameters
    ----------
    lat, lon, height : float
        Start position [rad, rad, m]; ``height`` is the mean height h0.
    yaw0 : float
        Initial course [rad], counter-clockwise from North.
    segments : sequence of `Segment` or tuples
        The track's legs (`Manoeuvre`), e.g. from `course_change`,
        `speed_change`, `cruise`, `voyage_segments`.
    speed0 : float
        Initial speed [m/s].
    dt : float
        Tick [s] the segments count.
    sea : {'general', 'ideal', 'bad'}, `Swing` or None
        Swing of seed 000 Table 2 (`sea_state`), a Swing whose oscillation
        (amplitude, frequency, phase; not its mean) is used, or None.
    sea_phase : array_like (3,)
        Phases [rad] of the named sea state's [pitch, roll, yaw].
    heave : sequence of (amplitude [m], period [s], phase [rad])
        Heave components (`pyins.sim.ship.LinearMotion`); () for none.
    heel_factor : float
        K of phi_turn = atan(K v r / g); 0 for no heel.
    pitch0, roll0 : float
        Trim and list [rad].
    nodes : int
        Gauss-Legendre nodes of the track's position quadrature.
    current : object or None
        The water current the ship drifts with (`Manoeuvre`'s ``current``,
        e.g. `pyins.sim.references.Current`); None: still water.
    """

    frequencies_hz = None

    def __init__(self, lat, lon, height, yaw0, segments, speed0=0.0, dt=DT, sea="general",
                 sea_phase=(0.0, 0.0, 0.0), heave=HEAVE, heel_factor=1.0, pitch0=0.0,
                 roll0=0.0, nodes=5, current=None):
        self.track = Manoeuvre(lat, lon, height, yaw0, segments, dt=dt, speed0=speed0, nodes=nodes,
                               current=current)
        self.current = current
        self.lat0, self.lon0, self.height = self.track.lat0, self.track.lon0, self.track.height
        self.dt = self.track.dt
        self.duration = self.track.duration
        self.n_ticks = self.track.n_ticks
        self.segments = self.track.segments
        if sea is None:
            amp, freq, phase = np.zeros(3), np.zeros(3), np.zeros(3)
        elif isinstance(sea, Swing):
            amp, freq, phase = sea.amplitude, sea.frequency_hz, sea.phase
        else:
            sw = sea_state(sea, lat, lon, height, 0.0, phase=sea_phase)
            amp, freq, phase = sw.amplitude, sw.frequency_hz, sw.phase
        self.swing = Swing(lat, lon, height, 0.0, 0.0, 0.0, amp, freq, phase)
        self.heave = LinearMotion(heave=heave)
        self.heel_factor = float(heel_factor)
        self.pitch0, self.roll0 = float(pitch0), float(roll0)
        # the track's yaw pulses, for the yaw acceleration (kinematics omits it)
        t0, length, dpsi, n = [], [], [], 0
        for seg in self.segments:
            t0.append(n * self.dt)
            length.append(seg.ticks * self.dt)
            dpsi.append(float(seg.value) if seg.kind == "turn" else 0.0)
            n += seg.ticks
        self._seg_t0, self._seg_len, self._seg_dpsi = np.array(t0), np.array(length), np.array(dpsi)

    def track_kinematics(self, t):
        """Speed [m/s], its rate [m/s^2], course [rad], turn rate r [rad/s] and
        r' [rad/s^2] of the track at times t (a plain array)."""
        t = np.asarray(t, dtype=float)
        speed, accel, yaw, yaw_rate = self.track.kinematics(t)
        k = np.clip(np.searchsorted(self._seg_t0, t, side="right") - 1, 0, len(self._seg_t0) - 1)
        length = self._seg_len[k]
        u = np.clip((t - self._seg_t0[k]) / length, 0.0, 1.0)
        # r = dpsi g'(u) / D, g' = 1 - cos(2 pi u)  ->  r' = dpsi 2 pi sin(2 pi u) / D^2
        yaw_acc = self._seg_dpsi[k] * TWO_PI / (length * length) * np.sin(TWO_PI * u)
        return speed, accel, yaw, yaw_rate, yaw_acc

    def heel(self, t):
        """phi_turn [rad] and its rate [rad/s] at times t (module docstring)."""
        speed, accel, _, r, r_dot = self.track_kinematics(t)
        kg = self.heel_factor / HEEL_G
        x = kg * speed * r
        return np.arctan(x), kg * (accel * r + speed * r_dot) / (1.0 + x * x)

    def state(self, t, t_lo=None):
        t, t_lo = as_times(t, t_lo)
        tt = t if t_lo is None else t + t_lo
        tr = self.track.state(t, t_lo)
        phi, phi_dot = self.heel(tt)
        sw = self.swing.state(t, t_lo)
        z, zd, zdd = (x[:, 2] for x in self.heave.level(t, t_lo))
        h0 = self.height
        s, c = np.sin(tr.lat), np.cos(tr.lat)
        rm, rn = earth.principal_radii(s)
        x = 1.0 - earth.E2 * s * s
        drm = 3.0 * rm * earth.E2 * s * c / x        # dR_M/dlat
        drn = rn * earth.E2 * s * c / x              # dR_N/dlat
        ve_h, vn_h = tr.vel_n[:, 0], tr.vel_n[:, 1]
        ae_h, an_h = tr.acc_n[:, 0], tr.acc_n[:, 1]
        lat_dot = vn_h / (rm + h0)
        qn, qe = z / (rm + h0), z / (rn + h0)
        dqn = zd / (rm + h0) - z * (drm * lat_dot) / ((rm + h0) * (rm + h0))
        dqe = zd / (rn + h0) - z * (drn * lat_dot) / ((rn + h0) * (rn + h0))
        n = t.shape[0]
        vel = np.empty((n, 3))
        acc = np.empty((n, 3))
        vel[:, 0] = ve_h + ve_h * qe
        vel[:, 1] = vn_h + vn_h * qn
        vel[:, 2] = zd
        acc[:, 0] = (ae_h + ae_h * qe) + ve_h * dqe
        acc[:, 1] = (an_h + an_h * qn) + vn_h * dqn
        acc[:, 2] = zdd
        euler = np.empty((n, 3))
        rate = np.empty((n, 3))
        euler[:, 0] = self.pitch0 + sw.euler[:, 0]
        euler[:, 1] = (self.roll0 + phi) + sw.euler[:, 1]
        euler[:, 2] = tr.euler[:, 2] + sw.euler[:, 2]
        rate[:, 0] = sw.euler_rate[:, 0]
        rate[:, 1] = phi_dot + sw.euler_rate[:, 1]
        rate[:, 2] = tr.euler_rate[:, 2] + sw.euler_rate[:, 2]
        return MotionState(tr.lat, tr.lon, h0 + z, vel, acc, euler, rate)

    def __repr__(self):
        return (f"Voyage({self.duration:g} s, {len(self.segments)} segments, "
                f"heel_factor={self.heel_factor:g}, heave={self.heave.heave!r})")


# ---------------------------------------------------------------------------
# 3. A default transit
# ---------------------------------------------------------------------------
def voyage_segments(hours=6.0, seed=0, dt=DT, first_leg_s=(600, 1200), leg_s=(1800, 3600),
                    speed_kn=(5.0, 20.0), turn_deg=(20.0, 120.0), rate_deg_s=(0.5, 1.0)):
    """(yaw0, speed0, segments) of a transit of ``hours`` (whole seconds).

    From ``numpy.random.default_rng(seed)``: initial course uniform in
    [0, 2 pi), initial speed uniform in [8, 16] kn (to 0.5 kn); a first leg
    of ``first_leg_s`` s (clearing the approach), then course changes of
    +-``turn_deg`` deg at a peak rate in ``rate_deg_s`` deg/s, each followed
    by a leg of ``leg_s`` s; every other course change (the first, the
    third, ...) is followed by a speed change to a new speed in ``speed_kn``
    (at least 1 kn different) at a peak 0.05 m/s^2. The last leg is cut so
    that the voyage lasts exactly ``hours``.
    """
    rng = np.random.default_rng(seed)
    total = int(np.rint(hours * 3600.0))
    yaw0 = float(rng.uniform(0.0, TWO_PI))
    speed = float(np.round(rng.uniform(8.0, 16.0) * 2.0) / 2.0) * KNOT
    speed0 = speed
    legs = [cruise(int(rng.integers(first_leg_s[0], first_leg_s[1] + 1)), dt)]
    events = 0
    while True:
        lo, hi = turn_deg
        dyaw = float(rng.choice([-1.0, 1.0]) * rng.uniform(lo, hi)) * DEG_TO_RAD
        legs.append(course_change(dyaw, float(rng.uniform(*rate_deg_s)) * DEG_TO_RAD, dt))
        if events % 2 == 0:
            while True:
                new = float(np.round(rng.uniform(*speed_kn) * 2.0) / 2.0) * KNOT
                if abs(new - speed) >= KNOT:
                    break
            legs.append(speed_change(speed, new, dt=dt))
            speed = new
        legs.append(cruise(int(rng.integers(leg_s[0], leg_s[1] + 1)), dt))
        events += 1
        if sum(s.ticks for s in legs) * dt >= total:
            break
    out, used = [], 0
    limit = int(np.rint(total / dt))
    for seg in legs:                # cut at the end; a cut manoeuvre becomes a cruise
        if used + seg.ticks <= limit:
            out.append(seg)
            used += seg.ticks
        else:
            if limit > used:
                out.append(Segment("cruise", limit - used))
            break
    return yaw0, speed0, out


def default_voyage(hours=6.0, seed=0, lat=START[0], lon=START[1], height=START[2], dt=DT,
                   **kwargs):
    """A `Voyage` along `voyage_segments` (``hours``, ``seed``) from ``lat``,
    ``lon``, ``height``; ``kwargs`` go to `Voyage` (``sea``, ``heave``,
    ``heel_factor``, ...). The default sea state is 'general'."""
    yaw0, speed0, segments = voyage_segments(hours, seed, dt)
    return Voyage(lat, lon, height, yaw0, segments, speed0=speed0, dt=dt, **kwargs)
