"""External reference sensors of the simulator: GNSS, EM speed log, DVL, zero velocity.

Every generator samples a ship profile of `pyins.sim.motion` / `pyins.sim.ship`
(its ``reference_state`` when it has one, else ``state``) on the IMU's clock and
returns a `References`: the records the firmware takes through its C ABI,
``pyins_ref { int32 kind; int32 reserved; int64 tick; double value[3];
double sigma[3]; }`` (`REF_DTYPE`, 64 bytes), the tick at which each becomes
available (``avail_tick`` = tick + latency) and its error-free value.
A record with tick k is valid at t = k dt from the start of the motion; the
first record of a generator is one period after its start (never tick 0).
Time windows (outages, frozen receiver, offsets) are half-open, t0 <= t < t1.

Kinds (`KIND_NAMES`) and what ``value`` / ``sigma`` hold:

- GNSS_POS: [lat rad, lon rad, h m] of the antenna; sigma [E, N, U] [m].
- GNSS_VEL: ENU velocity of the antenna [m/s]; sigma per axis [m/s].
- SPEED_LOG: value[0] speed through water along the bow axis b y [m/s],
  sigma[0] [m/s]; only component 0 is used, components 1 and 2 are 0.
- DVL: velocity in the DVL frame d [m/s] (bottom track: over ground; water
  track: through water, marked ``reserved`` = 1, which the firmware refuses:
  it uses bottom track alone); sigma per axis.
- ZERO_VEL: value 0, sigma per axis [m/s] (a moored / at-rest declaration).

Lever arms (reference point -> sensor, in b): r_n = C_b^n l placed with the
radii at the reference point (as `pyins.sim.ship` places the IMU), v = v_ref +
C_b^n (w_nb^b x l), w_nb^b from the Euler angles and rates
(`pyins.sim.imu.nb_rate_and_derivative`). Neglected: the transport rate,
w_en^n x r_n (~1.6e-6 rad/s at 10 m/s: 1.6e-5 m/s on a 10 m arm; the Earth
rate is not in an Earth-referenced velocity, Groves 2013 ch. 14 lever arm
with w_eb = w_nb + w_en), and ~|l|^2 / R (16 um at 10 m) of the placement.

Error models
------------
- GNSS (Groves, "Principles of GNSS, Inertial, and Multisensor Integrated
  Navigation Systems", 2nd ed. 2013, ch. 9, sec. 9.3-9.4): white noise per
  ENU axis plus a first-order Gauss-Markov position bias (residual
  atmosphere, ephemeris), discretised exactly (Brown & Hwang, "Introduction
  to Random Signals and Applied Kalman Filtering", 4th ed. 2012, ch. 2-3):
  b_{k+1} = phi b_k + sigma sqrt(1 - phi^2) w_k, phi = exp(-dt / tau),
  b_0 ~ N(0, sigma^2) (stationary); velocity white noise. Faults (Groves
  ch. 17): outages (no fixes); multipath outliers (each fix with
  probability ``outlier_rate`` jumps horizontally by U(outlier_m) metres in
  a uniform direction); a frozen receiver (the last fix before t0 repeated,
  position and velocity, tick advancing; none before t0 -> no fixes);
  offsets (a fixed ENU shift). Order: noise + bias + outliers + offsets,
  outages removed, frozen windows overwrite. The record's sigma is the
  nominal sqrt(noise^2 + bias^2), not informed by the faults.
- EM speed log (Groves ch. 6, dead reckoning; relative velocity v - v_c as
  in Fossen, "Handbook of Marine Craft Hydrodynamics and Motion Control",
  2011, sec. 8.3): along the bow, (1 + scale) v + bias + white noise.
- DVL (Groves ch. 6, Doppler sonar): v_d = (1 + scale) C_b^d C_n^b v + white
  noise, C_d^b = exp([m x]) ~ I + [m x] for the misalignment vector m.
- Current: mean plus a tidal ellipse at the M2 period, 12.42 h (Pugh,
  "Tides, Surges and Mean Sea-Level", 1987), seeded phases, closed form.
An error-free run reports sigma 0, which the files (and the firmware) refuse.

Files on the IMU's clock: `save_refs_csv` / `load_refs_csv`.
"""
from dataclasses import dataclass
from decimal import Decimal, localcontext
from fractions import Fraction

import numpy as np

from pyins.reference import earth
from pyins.sim.exact_time import split_times
from pyins.sim.imu import euler_to_mat, nb_rate_and_derivative
from pyins.units import DEG_TO_RAD, DT, TWO_PI

KIND_GNSS_POS, KIND_GNSS_VEL, KIND_SPEED_LOG, KIND_DVL, KIND_ZERO_VEL = 1, 2, 3, 4, 5
#: kind -> the name used in files.
KIND_NAMES = {KIND_GNSS_POS: "gnss_pos", KIND_GNSS_VEL: "gnss_vel",
              KIND_SPEED_LOG: "speed_log", KIND_DVL: "dvl", KIND_ZERO_VEL: "zero_velocity"}
_KIND_BY_NAME = {name: kind for kind, name in KIND_NAMES.items()}

#: The C ABI's ``pyins_ref``, 64 bytes, no padding.
REF_DTYPE = np.dtype([("kind", "<i4"), ("reserved", "<i4"), ("tick", "<i8"),
                      ("value", "<f8", (3,)), ("sigma", "<f8", (3,))])
assert REF_DTYPE.itemsize == 64

#: M2 semi-diurnal tide period [s] (Pugh 1987): 12.4206 h.
M2_PERIOD_S = 12.4206012 * 3600.0


@dataclass
class References:
    """Reference measurements sorted by (tick, kind)."""
    refs: np.ndarray         #: REF_DTYPE records, (N,)
    avail_tick: np.ndarray   #: int64, tick at which each is available (tick + latency)
    truth_value: np.ndarray  #: (N, 3) error-free value, same units as ``refs["value"]``

    def __len__(self):
        return len(self.refs)

    def select(self, kind):
        """The records of one kind, as a References."""
        m = self.refs["kind"] == kind
        return References(self.refs[m], self.avail_tick[m], self.truth_value[m])


def merge(*references):
    """All records of several References, sorted by (tick, kind), stable."""
    refs = np.concatenate([np.empty(0, REF_DTYPE)] + [r.refs for r in references])
    avail = np.concatenate([np.empty(0, np.int64)] + [r.avail_tick for r in references])
    truth = np.concatenate([np.empty((0, 3))] + [r.truth_value for r in references])
    order = np.lexsort((refs["kind"], refs["tick"]))      # lexsort is stable
    return References(refs[order], avail[order], truth[order])


def _records(kind, ticks, value, sigma, truth, latency_ticks=0):
    r = np.zeros(len(ticks), REF_DTYPE)
    r["kind"], r["tick"] = kind, ticks
    r["value"], r["sigma"] = value, sigma
    return References(r, np.asarray(ticks, np.int64) + int(latency_ticks),
                      np.array(truth, dtype=float).reshape(-1, 3))


# ---------------------------------------------------------------------------
# 1. Sampling the motion
# ---------------------------------------------------------------------------
def _vec3(name, v):
    a = np.array(v, dtype=float)
    a = np.full(3, float(a)) if a.shape == () else a
    if a.shape != (3,) or not np.all(np.isfinite(a)):
        raise ValueError(f"{name} must be a finite scalar or 3 numbers, got {v!r}")
    return a


def _nonneg(name, v):
    a = _vec3(name, v)
    if np.any(a < 0.0):
        raise ValueError(f"{name} must be >= 0, got {v!r}")
    return a


def _to_ticks(name, seconds, dt):
    n = int(round(seconds / dt))
    if abs(n * dt - seconds) > 1e-9 * max(abs(seconds), 1.0):
        raise ValueError(f"{name}: {seconds} s is not a whole number of {dt} s ticks")
    return n


def schedule(duration_s, rate_hz, dt=DT, t0_s=0.0):
    """Ticks t0 + k / rate_hz, k = 1, 2, ..., up to t0 + duration_s (int64).

    1 / (rate_hz dt) must be a whole number of ticks."""
    if not rate_hz > 0.0:
        raise ValueError(f"rate_hz must be > 0, got {rate_hz!r}")
    step = _to_ticks("1 / rate_hz", 1.0 / rate_hz, dt)
    first = _to_ticks("t0_s", t0_s, dt)
    last = first + int(np.floor(duration_s / dt + 1e-9))
    return np.arange(first + step, last + 1, step, dtype=np.int64)


def _state(motion, ticks, dt):
    t_hi, t_lo = split_times(ticks, dt)
    if len(ticks) and ticks[-1] * dt > motion.duration + 1e-9:
        raise ValueError(f"the motion lasts {motion.duration} s; references up to "
                         f"{ticks[-1] * dt} s were asked for")
    fn = getattr(motion, "reference_state", motion.state)
    return fn(t_hi, t_lo), t_hi + t_lo


def antenna(motion, ticks, lever_b=(0.0, 0.0, 0.0), dt=DT):
    """Position [lat, lon, h] (N, 3), ENU velocity (N, 3) and C_b^n (N, 3, 3) of
    the point at ``lever_b`` [m, in b] from the reference point at the given
    ticks (module docstring: lever arms). Also returns the times [s]."""
    ticks = np.asarray(ticks, dtype=np.int64)
    st, t = _state(motion, ticks, dt)
    lever = _vec3("lever_b", lever_b)
    c = euler_to_mat(st.euler)
    pos = np.column_stack([st.lat, st.lon, st.height])
    vel = st.vel_n.copy()
    if np.any(lever != 0.0):
        w, _ = nb_rate_and_derivative(st.euler, st.euler_rate, np.zeros_like(st.euler))
        pos = pos + _enu_to_geodetic(st.lat, st.height, c @ lever)
        vel = vel + np.einsum("nij,nj->ni", c, np.cross(w, lever))
    return pos, vel, c, t


def _enu_to_geodetic(lat, h, d):
    """[dlat, dlon, dh] of ENU offsets d (N, 3) [m] at (lat, h), first order."""
    rm, rn = earth.principal_radii(np.sin(lat))
    return np.column_stack([d[:, 1] / (rm + h), d[:, 0] / ((rn + h) * np.cos(lat)), d[:, 2]])


class Current:
    """A horizontal water current [m/s, ENU]: mean plus a tidal ellipse,

    v(t) = mean_enu + amplitude_mps [cos(w t + phi_E), cos(w t + phi_N), 0],
    w = 2 pi / period_s, phi_E, phi_N uniform from ``seed`` (the ellipse's
    orientation and shape). Closed form, deterministic given the seed, any t.
    ``mean_enu`` has 2 or 3 components (up, if given, 0); the default period
    is the M2 tide's (Pugh 1987).
    """

    def __init__(self, mean_enu=(0.0, 0.0, 0.0), amplitude_mps=0.0, period_s=M2_PERIOD_S,
                 seed=0):
        m = np.array(mean_enu, dtype=float).ravel()
        m = np.append(m, 0.0) if m.shape == (2,) else m
        if m.shape != (3,) or not np.all(np.isfinite(m)) or m[2] != 0.0:
            raise ValueError(f"mean_enu: 2 or 3 finite numbers, up = 0; got {mean_enu!r}")
        if not (amplitude_mps >= 0.0 and period_s > 0.0):
            raise ValueError("amplitude_mps must be >= 0 and period_s > 0")
        self.mean_enu, self.amplitude_mps, self.period_s = m, float(amplitude_mps), float(period_s)
        self.seed = seed
        self.phase = np.random.default_rng(seed).uniform(0.0, TWO_PI, 2)

    def velocity(self, t):
        """Current at times t [s] (1-D) -> (N, 3) [m/s]."""
        t = np.atleast_1d(np.asarray(t, dtype=float))
        v = np.tile(self.mean_enu, (t.shape[0], 1))
        if self.amplitude_mps != 0.0:
            arg = (TWO_PI / self.period_s) * t[:, None] + self.phase
            v[:, :2] += self.amplitude_mps * np.cos(arg)
        return v

    def acceleration(self, t):
        """d/dt of `velocity` at times t [s] (1-D) -> (N, 3) [m/s^2]."""
        t = np.atleast_1d(np.asarray(t, dtype=float))
        a = np.zeros((t.shape[0], 3))
        if self.amplitude_mps != 0.0:
            w = TWO_PI / self.period_s
            a[:, :2] = -self.amplitude_mps * w * np.sin(w * t[:, None] + self.phase)
        return a


def _water(current, t):
    return 0.0 if current is None else current.velocity(t)


# ---------------------------------------------------------------------------
# 2. The generators
# ---------------------------------------------------------------------------
def _gauss_markov(w, phi, sigma):
    """Stationary first-order Gauss-Markov from unit normals w (N, 3), exact
    discretisation with per-step factors phi (N - 1,)."""
    b = np.empty_like(w)
    if len(w):
        b[0] = sigma * w[0]
    q = np.sqrt(1.0 - phi * phi)[:, None] * sigma
    for k in range(1, len(w)):
        b[k] = phi[k - 1] * b[k - 1] + q[k - 1] * w[k]
    return b


def _in_windows(t, windows):
    m = np.zeros(t.shape, bool)
    for t0, t1 in windows:
        m |= (t >= t0) & (t < t1)
    return m


def gnss(motion, duration_s, dt=DT, rate_hz=1.0, lever_b=(0.0, 0.0, 0.0),
         pos_noise_m=(3.0, 3.0, 5.0), vel_noise_mps=0.05, bias_sigma_m=2.0,
         bias_tau_s=300.0, latency_s=0.0, outages=(), outlier_rate=0.0,
         outlier_m=(50.0, 500.0), frozen=(), offsets=(), seed=0, velocity=True, position=True):
    """GNSS position (and velocity) fixes of an antenna at ``lever_b`` [m, b].

    Errors as in the module docstring. ``pos_noise_m`` and ``bias_sigma_m``
    are ENU 1-sigma [m] (scalar or 3), ``bias_tau_s`` the bias correlation
    time [s] (inf: a random constant), ``vel_noise_mps`` [m/s]. ``outages``
    and ``frozen`` are lists of (t0, t1) [s], ``offsets`` of (t0, t1, (dE,
    dN, dU)) [s, m]; ``outlier_m`` = (min, max) jump [m]. ``latency_s`` (a
    whole number of ticks) only delays ``avail_tick``. The random draws do
    not depend on the fault settings: the same seed gives the same noise.
    Returns References: GNSS_POS records when ``position``, GNSS_VEL records
    when ``velocity`` (the draws the same either way).
    """
    if not (position or velocity):
        raise ValueError("gnss: position and velocity both False: no fixes")
    ticks = schedule(duration_s, rate_hz, dt)
    pos_t, vel_t, _, t = antenna(motion, ticks, lever_b, dt)
    n = len(ticks)
    noise_p = _nonneg("pos_noise_m", pos_noise_m)
    noise_v = _nonneg("vel_noise_mps", vel_noise_mps)
    bias_s = _nonneg("bias_sigma_m", bias_sigma_m)
    if not bias_tau_s > 0.0:
        raise ValueError(f"bias_tau_s must be > 0, got {bias_tau_s!r}")
    lo, hi = outlier_m
    if not (0.0 <= outlier_rate <= 1.0 and 0.0 <= lo <= hi):
        raise ValueError("outlier_rate must be in [0, 1] and outlier_m = (min, max) >= 0")
    rng = np.random.default_rng(seed)
    w_p, w_b, w_v = (rng.standard_normal((n, 3)) for _ in range(3))
    u_out, u_mag, u_dir = (rng.random(n) for _ in range(3))

    phi = np.exp(-np.diff(t) / bias_tau_s)
    err = noise_p * w_p + _gauss_markov(w_b, phi, bias_s)
    jump = u_out < outlier_rate
    mag = lo + (hi - lo) * u_mag[jump]
    err[jump, 0] += mag * np.sin(TWO_PI * u_dir[jump])
    err[jump, 1] += mag * np.cos(TWO_PI * u_dir[jump])
    for t0, t1, d in offsets:
        err[_in_windows(t, [(t0, t1)])] += _vec3("offset", d)
    pos = pos_t + _enu_to_geodetic(pos_t[:, 0], pos_t[:, 2], err)
    vel = vel_t + noise_v * w_v

    keep = ~_in_windows(t, outages)
    ticks, t, pos, vel, pos_t, vel_t = (a[keep] for a in (ticks, t, pos, vel, pos_t, vel_t))
    drop = np.zeros(len(t), bool)
    for t0, t1 in frozen:
        inside = np.flatnonzero(_in_windows(t, [(t0, t1)]))
        before = np.flatnonzero(t < t0)
        if before.size:
            pos[inside], vel[inside] = pos[before[-1]], vel[before[-1]]
        else:
            drop[inside] = True
    ticks, pos, vel, pos_t, vel_t = (a[~drop] for a in (ticks, pos, vel, pos_t, vel_t))

    lat_ticks = _to_ticks("latency_s", latency_s, dt)
    sig_p = np.sqrt(noise_p ** 2 + bias_s ** 2)
    vel_out = _records(KIND_GNSS_VEL, ticks, vel, noise_v, vel_t, lat_ticks) if velocity else None
    if not position:
        return vel_out
    out = _records(KIND_GNSS_POS, ticks, pos, sig_p, pos_t, lat_ticks)
    return merge(out, vel_out) if velocity else out


def speed_log(motion, duration_s, current, rate_hz=1.0, scale_factor=0.005, bias_mps=0.0,
              noise_mps=0.05, seed=0, lever_b=(0.0, 0.0, 0.0), dt=DT):
    """EM log: speed through water along the bow axis b y [m/s].

    v = (v_ground(lever) - current) . C_b^n[:, 1], measured (1 + scale_factor)
    v + bias_mps + noise_mps w. ``current`` a `Current` or None (still
    water). Records: value [v, 0, 0], sigma [noise_mps, 0, 0].
    """
    ticks = schedule(duration_s, rate_hz, dt)
    _, vel, c, t = antenna(motion, ticks, lever_b, dt)
    if not noise_mps >= 0.0:
        raise ValueError(f"noise_mps must be >= 0, got {noise_mps!r}")
    v = np.einsum("ni,ni->n", vel - _water(current, t), c[:, :, 1])
    w = np.random.default_rng(seed).standard_normal(len(ticks))
    meas = (1.0 + scale_factor) * v + bias_mps + noise_mps * w
    z = np.zeros(len(ticks))
    return _records(KIND_SPEED_LOG, ticks, np.column_stack([meas, z, z]),
                    [noise_mps, 0.0, 0.0], np.column_stack([v, z, z]))


def rotation_vector_to_mat(m):
    """exp([m x]) (Rodrigues), the rotation by the rotation vector m [rad]."""
    m = _vec3("misalignment_rad", m)
    th = np.linalg.norm(m)
    k = np.array([[0.0, -m[2], m[1]], [m[2], 0.0, -m[0]], [-m[1], m[0], 0.0]])
    if th == 0.0:
        return np.eye(3)
    return np.eye(3) + (np.sin(th) / th) * k + ((1.0 - np.cos(th)) / th ** 2) * (k @ k)


def dvl(motion, duration_s, current=None, misalignment_rad=(0.0, 0.0, 0.0), scale_factor=0.0,
        noise_mps=0.01, rate_hz=1.0, lever_b=(0.0, 0.0, 0.0), seed=0, dt=DT):
    """DVL velocity in its frame d [m/s]: bottom track (``current`` None) or
    water track (a `Current`; its records' ``reserved`` is 1, the C ABI's
    mark of water track, which the firmware refuses with PYINS_E_REF_KIND
    and the files do not hold). C_d^b = exp([m x]) with m =
    ``misalignment_rad``; v_d = (1 + scale_factor) (C_d^b)^T C_n^b v +
    noise_mps w per axis."""
    ticks = schedule(duration_s, rate_hz, dt)
    _, vel, c, t = antenna(motion, ticks, lever_b, dt)
    noise = _nonneg("noise_mps", noise_mps)
    c_bd = rotation_vector_to_mat(misalignment_rad).T
    v_d = np.einsum("ij,nkj,nk->ni", c_bd, c, vel - _water(current, t))
    w = np.random.default_rng(seed).standard_normal((len(ticks), 3))
    meas = (1.0 + scale_factor) * v_d + noise * w
    out = _records(KIND_DVL, ticks, meas, noise, v_d)
    if current is not None:
        out.refs["reserved"] = 1          # water track
    return out


def zero_velocity(duration_s, rate_hz=1.0, sigma_mps=0.01, t0_s=0.0, dt=DT):
    """ZERO_VEL declarations at t0_s + k / rate_hz over (t0_s, t0_s + duration_s]."""
    ticks = schedule(duration_s, rate_hz, dt, t0_s)
    z = np.zeros((len(ticks), 3))
    return _records(KIND_ZERO_VEL, ticks, z, _nonneg("sigma_mps", sigma_mps), z)


# ---------------------------------------------------------------------------
# 3. Files
# ---------------------------------------------------------------------------
#: The header line of a reference file.
CSV_HEADER = "tick,kind,v0,v1,v2,s0,s1,s2"
_DEG = Fraction(DEG_TO_RAD)


def _deg_to_rad(text):
    """Exact decimal degrees -> rad, correctly rounded: fl(d * DEG_TO_RAD)."""
    x = float(Fraction(text) * _DEG)
    return -0.0 if x == 0.0 and text.lstrip().startswith("-") else x


def _rad_to_deg_text(x):
    """Shortest text that `_deg_to_rad` maps back to x exactly."""
    x = float(x)
    d = x / DEG_TO_RAD
    for s in (repr(d), repr(np.nextafter(d, np.inf).item()), repr(np.nextafter(d, -np.inf).item())):
        if _deg_to_rad(s) == x:
            return s
    exact = Fraction(x) / _DEG
    with localcontext() as ctx:
        ctx.prec = 25            # 1e-25 relative: far below half an ulp (1.1e-16)
        return str(Decimal(exact.numerator) / Decimal(exact.denominator))


def _problem(kind, tick, value, sigma, prev_tick):
    """What is wrong with one record, or None."""
    if kind not in KIND_NAMES:
        return f"unknown kind {kind!r}"
    if tick < 0:
        return f"negative tick {tick}"
    if prev_tick is not None and tick < prev_tick:
        return f"tick {tick} after {prev_tick}: ticks must not decrease"
    if not (np.all(np.isfinite(value)) and np.all(np.isfinite(sigma))):
        return "non-finite value or sigma"
    used = 1 if kind == KIND_SPEED_LOG else 3
    if np.any(sigma[:used] <= 0.0):
        return f"sigma {sigma[:used].tolist()} must be > 0"
    if used == 1 and np.any(np.concatenate([value[1:], sigma[1:]]) != 0.0):
        return "speed_log uses component 0 only: v1, v2, s1, s2 must be 0"
    return None


def save_refs_csv(path, refs):
    """Write records (REF_DTYPE array or References) as text on the IMU's clock.

    Layout: the header line `CSV_HEADER`, then one row per record ``tick,
    kind, v0, v1, v2, s0, s1, s2``: tick an integer, kind its name
    (`KIND_NAMES`), value and sigma in SI except gnss_pos lat, lon (v0, v1)
    in DEGREES. Floats are repr (shortest round trip). A lat/lon is a decimal
    d with fl(d * DEG_TO_RAD) == the radian value, d exact (`load_refs_csv`
    multiplies with rationals): the repr of x / DEG_TO_RAD or of a neighbour
    when one maps back, else 25 significant digits (no double does for ~1 in
    6 values: above 64 deg the degree grid is coarser than the radian one).
    So the array comes back bit for bit; a reader doing atof(d) * DEG_TO_RAD
    may be 1 ulp (1e-16 rad) off. ``reserved`` and ``avail_tick`` are not
    written: a ``dvl`` row is bottom track, and a water-track DVL record
    (``reserved`` 1) is refused. Refuses (ValueError naming the record) what
    `load_refs_csv` would.
    """
    refs = refs.refs if isinstance(refs, References) else np.asarray(refs, REF_DTYPE)
    lines, prev = [CSV_HEADER], None
    for i, r in enumerate(refs):
        kind, tick = int(r["kind"]), int(r["tick"])
        bad = _problem(kind, tick, r["value"], r["sigma"], prev)
        if not bad and kind == KIND_DVL and r["reserved"] != 0:
            bad = "a water-track dvl record: the layout's dvl rows are bottom track (over ground)"
        if bad:
            raise ValueError(f"{path}: record {i} (line {i + 2}): {bad}")
        prev = tick
        v = [repr(float(x)) for x in r["value"]]
        if kind == KIND_GNSS_POS:
            v[0], v[1] = (_rad_to_deg_text(x) for x in r["value"][:2])
        lines.append(",".join([str(tick), KIND_NAMES[kind]] + v
                              + [repr(float(x)) for x in r["sigma"]]))
    with open(path, "w", encoding="ascii", newline="\n") as f:
        f.write("\n".join(lines) + "\n")


def load_refs_csv(path):
    """Read a file of `save_refs_csv` -> REF_DTYPE array (lat, lon back in rad).

    Blank lines are skipped. ValueError ``PATH:LINE: reason`` for a wrong
    header, a row without 8 fields, a bad number or tick, an unknown kind, a
    non-finite value or sigma, a used sigma <= 0 (speed_log: s0 only; its v1,
    v2, s1, s2 must be 0), or ticks that decrease.
    """
    with open(path, encoding="ascii") as f:
        text = f.read().splitlines()
    if not text or text[0].strip() != CSV_HEADER:
        raise ValueError(f"{path}:1: the header must be {CSV_HEADER!r}")
    rows, prev = [], None
    for lineno, line in enumerate(text[1:], start=2):
        if not line.strip():
            continue
        f = [s.strip() for s in line.split(",")]
        try:
            if len(f) != 8:
                raise ValueError(f"{len(f)} fields, 8 wanted")
            if f[1] not in _KIND_BY_NAME:
                raise ValueError(f"unknown kind {f[1]!r} (kinds: {', '.join(_KIND_BY_NAME)})")
            kind, tick = _KIND_BY_NAME[f[1]], int(f[0])
            value = np.array([float(s) for s in f[2:5]])
            sigma = np.array([float(s) for s in f[5:8]])
            if kind == KIND_GNSS_POS and np.all(np.isfinite(value)):
                value[0], value[1] = _deg_to_rad(f[2]), _deg_to_rad(f[3])
        except ValueError as e:
            raise ValueError(f"{path}:{lineno}: {e}") from None
        bad = _problem(kind, tick, value, sigma, prev)
        if bad:
            raise ValueError(f"{path}:{lineno}: {bad}")
        prev = tick
        rows.append((kind, 0, tick, value, sigma))
    return np.array(rows, dtype=REF_DTYPE)
