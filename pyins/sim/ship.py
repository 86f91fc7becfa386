"""A real ship at the pier: heave, surge and sway, lever arms, wave spectra.

Every profile of `pyins.sim.motion` rotates the ship about the IMU. Here it
rotates about the ship's motion reference point, which also heaves, surges
and sways (`LinearMotion`), and the IMU sits at a lever arm from it
(`ShipAtSea`: ``state`` is the IMU point, ``reference_state`` the reference
point, both closed form, so `pyins.sim.imu.exact_increments` stays exact).
`sea_spectrum_motion` draws a `LinearMotion` from a wave spectrum (presets
`SEA_STATE_SPECTRA`); `moored` is the built-in moored ship (`MOORED_SHIP`).

1. Heave, surge, sway: `LinearMotion`.
2. The ship at sea, lever arms included: `ShipAtSea`.
3. Wave spectra and the ship's response: `pierson_moskowitz`, `jonswap`,
   `dnv_gamma`, `heave_response`, `sea_spectrum_motion`, `SEA_STATE_SPECTRA`,
   `named_sea_spectrum`.
4. The built-in moored ship: `MOORED_SHIP`, `moored`.
5. A ship swinging at anchor: `AT_ANCHOR`, `anchor_linear`, `anchor_swing`,
   `at_anchor`.

Positions (exact by definition)
-------------------------------
A point whose ENU offset from the site (lat0, lon0, h0) is D = (dE, dN, dU)
is placed at

    lat = lat0 + dN / (R_M(lat0) + h0)
    lon = lon0 + dE / ((R_N(lat0) + h0) cos lat0)
    h   = h0 + dU

with the radii FIXED at the site. This is the metric displacement D only to
first order in |D| / R (the difference, ~|D|^2 / R, is 1.6 mm at 100 m and
1 um at 2 m), but it is an exact, closed-form definition of the trajectory. Velocity and acceleration
then follow from it EXACTLY through the firmware's own kinematics (Qin 2014
sec. 4.1), with the radii at the CURRENT latitude:

    vN = (R_M(lat) + h) lat_dot,  vE = (R_N(lat) + h) cos(lat) lon_dot,  vU = h_dot

and acc_n is the exact time derivative of those, using
dR_N/dlat = R_N e2 s c / x and dR_M/dlat = 3 R_M e2 s c / x (s = sin lat,
c = cos lat, x = 1 - e2 s^2; from R_N = a / sqrt(x), R_M = a (1 - e2) / x^1.5,
Qin 2014 eq. 4.1.7). The longitude is not wrapped (a site within 100 m of
the antimeridian would need it).

IMU point
---------
D_imu = d + C_b^n r_b with r_b = lever_b + Rz(alpha) lever_p, so

    D_imu'  = d' + C (w x r + r')
    D_imu'' = d'' + C (w x (w x r) + w' x r + 2 w x r' + r'')

with w = omega_nb^b from the Euler angles and rates and w' its exact
derivative from the Euler accelerations (``euler_accel`` of the base
profile), both by `pyins.sim.imu.nb_rate_and_derivative`; dC/dt = C [w x]
(Qin 2014 sec. 9.1; the lever-arm terms as in Titterton & Weston,
"Strapdown Inertial Navigation Technology", 2nd ed., 2004).

References
----------
- Pierson & Moskowitz (1964), "A proposed spectral form for fully developed
  wind seas ...", J. Geophys. Res. 69(24).
- Hasselmann et al. (1973), "Measurements of wind-wave growth and swell decay
  during the Joint North Sea Wave Project (JONSWAP)", Dtsch. Hydrogr. Z. A8(12).
- DNV-RP-C205 (2010), "Environmental conditions and environmental loads",
  sec. 3.5.5 (PM in its two-parameter Hs/Tp form, JONSWAP, the normalising
  factor 1 - 0.287 ln(gamma), sigma 0.07/0.09, the gamma rule of thumb).
- Fossen (2011), "Handbook of Marine Craft Hydrodynamics and Motion
  Control", ch. 8 (wave spectra, wave amplitudes a_i = sqrt(2 S(w_i) dw),
  motion RAOs).
- WMO No. 306, Manual on Codes, code table 3700 (sea state codes 0-9 by
  significant wave height).
"""
import numbers

import numpy as np

from pyins.reference import earth
from pyins.sim.exact_time import as_times, frac_cycles
from pyins.sim.imu import euler_to_mat, nb_rate_and_derivative
from pyins.sim.motion import Manoeuvre, Motion, MotionState, Static, Swing, sea_state
from pyins.units import DT, TWO_PI

#: Largest linear-motion amplitude and lever-arm length accepted [m].
MAX_METRES = 100.0


# ---------------------------------------------------------------------------
# Validation helpers
# ---------------------------------------------------------------------------
def _real(value):
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, numbers.Real):
        raise TypeError
    return float(value)


def _components(field, entries):
    """Validated ((amplitude, period, phase), ...) of one linear axis."""
    if entries is None:
        return ()
    try:
        entries = list(entries)
    except TypeError:
        raise ValueError(f"{field}: must be a sequence of (amplitude [m], period [s], "
                         f"phase [rad]), got {entries!r}") from None
    out = []
    for i, entry in enumerate(entries):
        try:
            a, period, phase = (_real(v) for v in entry)
        except (TypeError, ValueError):
            raise ValueError(f"{field}[{i}]: must be (amplitude [m], period [s], phase [rad]), "
                             f"got {entry!r}") from None
        if not (np.isfinite(a) and abs(a) <= MAX_METRES):
            raise ValueError(f"{field}[{i}].amplitude: must be a finite number of metres with "
                             f"|a| <= {MAX_METRES:g}, got {a:g}")
        if not (np.isfinite(period) and period > 0.0):
            raise ValueError(f"{field}[{i}].period: must be a positive finite number of seconds, "
                             f"got {period:g}")
        if not np.isfinite(phase):
            raise ValueError(f"{field}[{i}].phase: must be a finite number of radians, got {phase:g}")
        out.append((a, period, phase))
    return tuple(out)


def _lever(field, value):
    try:
        v = np.array(value, dtype=float).reshape(3)
    except (TypeError, ValueError):
        raise ValueError(f"{field}: must be 3 numbers [m], got {value!r}") from None
    for i in range(3):
        if not np.isfinite(v[i]):
            raise ValueError(f"{field}[{i}]: must be a finite number of metres, got {v[i]:g}")
    length = float(np.sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]))
    if length > MAX_METRES:
        raise ValueError(f"{field}: length {length:g} m exceeds {MAX_METRES:g} m")
    return v


def _positive(field, value, unit):
    try:
        v = _real(value)
    except TypeError:
        raise ValueError(f"{field}: must be a positive finite number{unit}, got {value!r}") from None
    if not (np.isfinite(v) and v > 0.0):
        raise ValueError(f"{field}: must be a positive finite number{unit}, got {v:g}")
    return v


# ---------------------------------------------------------------------------
# 1. Heave, surge, sway
# ---------------------------------------------------------------------------
class LinearMotion:
    """Heave, surge and sway of the motion reference point about a fixed mean position.

    Each axis is a sum of ``a sin(2 pi (t + t_lo) / T + phase)``, with the
    phase reduced exactly by `pyins.sim.exact_time.frac_cycles` (exact over 72 h,
    as `Swing`). The axes are those of a fixed level frame along the ship's
    MEAN heading: x = sway (mean starboard), y = surge (mean bow), z = heave
    (up); `ShipAtSea` rotates it into ENU with the base profile's mean yaw.

    Parameters
    ----------
    heave, surge, sway : sequence of (amplitude [m], period [s], phase [rad])
        Components of each axis; amplitude finite, |a| <= 100 m; period
        finite and > 0; phase finite. Empty (or None) means no motion.
    """

    def __init__(self, heave=(), surge=(), sway=()):
        self.heave = _components("heave", heave)
        self.surge = _components("surge", surge)
        self.sway = _components("sway", sway)

    @property
    def periods(self):
        """Periods [s] of every component with a non-zero amplitude."""
        return tuple(p for axis in (self.sway, self.surge, self.heave)
                     for a, p, _ in axis if a != 0.0)

    @staticmethod
    def _axis(components, t, t_lo):
        n = t.shape[0]
        d, v, acc = np.zeros(n), np.zeros(n), np.zeros(n)
        for a, period, phase0 in components:
            f = 1.0 / period
            omega = TWO_PI * f
            phase = TWO_PI * frac_cycles(f, t, t_lo) + phase0
            s, c = np.sin(phase), np.cos(phase)
            d = d + a * s
            v = v + (a * omega) * c
            acc = acc - (a * omega * omega) * s
        return d, v, acc

    def level(self, t, t_lo=None):
        """Displacement, rate and acceleration in the level frame, (N, 3) each.

        Columns [sway, surge, heave] [m, m/s, m/s^2].
        """
        t, t_lo = as_times(t, t_lo)
        out = [np.empty((t.shape[0], 3)) for _ in range(3)]
        for j, comps in enumerate((self.sway, self.surge, self.heave)):
            for k, col in enumerate(self._axis(comps, t, t_lo)):
                out[k][:, j] = col
        return tuple(out)

    def enu(self, t, t_lo=None, yaw=0.0):
        """Displacement, rate and acceleration in ENU [m, m/s, m/s^2], (N, 3) each.

        The level frame turned by Rz(yaw): mean bow = [-sin yaw, cos yaw, 0],
        mean starboard = [cos yaw, sin yaw, 0].
        """
        cy, sy = np.cos(yaw), np.sin(yaw)
        out = []
        for x in self.level(t, t_lo):
            e = np.empty_like(x)
            e[:, 0] = cy * x[:, 0] - sy * x[:, 1]
            e[:, 1] = sy * x[:, 0] + cy * x[:, 1]
            e[:, 2] = x[:, 2]
            out.append(e)
        return tuple(out)

    def __repr__(self):
        return f"LinearMotion(heave={self.heave!r}, surge={self.surge!r}, sway={self.sway!r})"


# ---------------------------------------------------------------------------
# Lever-arm arithmetic
# ---------------------------------------------------------------------------
def _cross(a, b):
    out = np.empty(np.broadcast_shapes(a.shape, b.shape))
    out[..., 0] = a[..., 1] * b[..., 2] - a[..., 2] * b[..., 1]
    out[..., 1] = a[..., 2] * b[..., 0] - a[..., 0] * b[..., 2]
    out[..., 2] = a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0]
    return out


def _mat_vec(m, v):
    """m v for (N, 3, 3) and (N, 3), element-wise (no BLAS)."""
    out = np.empty(v.shape)
    for i in range(3):
        out[:, i] = m[:, i, 0] * v[:, 0] + m[:, i, 1] * v[:, 1] + m[:, i, 2] * v[:, 2]
    return out


# ---------------------------------------------------------------------------
# 2. Ship at sea
# ---------------------------------------------------------------------------
class ShipAtSea(Motion):
    """A fixed-position base profile plus heave/surge/sway and lever arms.

    ``state`` is the state of the IMU point (what the increments are exact
    for), ``reference_state`` that of the motion reference point. Euler
    angles and rates are the base profile's; see the module docstring for
    the position definition and the lever-arm kinematics.

    Parameters
    ----------
    base : Static, Swing or HeadingSwing
        Attitude and site (its lat, lon, height = the mean position of the
        reference point). A `Manoeuvre` is refused.
    linear : LinearMotion or None
        Heave, surge, sway of the reference point (None: it stays at the site).
        Surge and sway are along the base profile's mean yaw.
    lever_b : array_like (3,)
        Reference point -> turntable centre in b [m] (the IMU itself when
        ``lever_p`` is zero). Each component finite, length <= 100 m.
    lever_p : array_like (3,)
        Table axis point -> accelerometer triad in p [m]; turns with the
        table: r_b = lever_b + Rz(alpha) lever_p. Same limits.
    """

    def __init__(self, base, linear=None, lever_b=(0.0, 0.0, 0.0), lever_p=(0.0, 0.0, 0.0)):
        if isinstance(base, Manoeuvre):
            raise ValueError("base: a Manoeuvre moves the ship; ShipAtSea needs a fixed-position "
                             "base profile (Static, Swing or HeadingSwing)")
        if not isinstance(base, (Static, Swing)):
            raise ValueError(f"base: must be a Static, Swing or HeadingSwing profile, "
                             f"got {type(base).__name__}")
        if linear is not None and not isinstance(linear, LinearMotion):
            raise ValueError(f"linear: must be a LinearMotion or None, got {type(linear).__name__}")
        self.base = base
        self.linear = linear
        self.lever_b = _lever("lever_b", lever_b)
        self.lever_p = _lever("lever_p", lever_p)
        self.lat, self.lon, self.height = base.lat, base.lon, base.height
        self.mean_yaw = float(base.euler0[2] if isinstance(base, Static) else base.mean[2])
        self.duration = base.duration
        rm0, rn0 = earth.principal_radii(np.sin(self.lat))
        self._north_m_per_rad = rm0 + self.height
        self._east_m_per_rad = (rn0 + self.height) * np.cos(self.lat)

    # -- what other modules ask ---------------------------------------------
    @property
    def needs_table(self):
        """True when the IMU point depends on the table angle (non-zero lever_p)."""
        return bool(np.any(self.lever_p != 0.0))

    @property
    def is_constant(self):
        """True when nothing moves but the table (Static base, no linear motion)."""
        return isinstance(self.base, Static) and (self.linear is None or not self.linear.periods)

    @property
    def frequencies_hz(self):
        """Active frequencies [Hz] of the base swing and of the linear motion
        (what `pyins.sim.motion.periodic_ticks` needs; empty when nothing moves)."""
        out = []
        if isinstance(self.base, Swing):
            out += [float(f) for a, f in zip(self.base.amplitude, self.base.frequency_hz)
                    if a != 0.0 and f != 0.0]
        if self.linear is not None:
            out += [1.0 / p for p in self.linear.periods]
        return tuple(out)

    # -- kinematics -----------------------------------------------------------
    def _displacement(self, t, t_lo):
        if self.linear is None:
            z = np.zeros((t.shape[0], 3))
            return z, z.copy(), z.copy()
        return self.linear.enu(t, t_lo, self.mean_yaw)

    def _geodetic(self, d, d_dot, d_ddot, base_st):
        """MotionState of the point at ENU offset d(t) from the site (module docstring)."""
        ns, es = self._north_m_per_rad, self._east_m_per_rad
        lat = self.lat + d[:, 1] / ns
        lon = self.lon + d[:, 0] / es
        h = self.height + d[:, 2]
        lat_d, lon_d, h_d = d_dot[:, 1] / ns, d_dot[:, 0] / es, d_dot[:, 2]
        lat_dd, lon_dd, h_dd = d_ddot[:, 1] / ns, d_ddot[:, 0] / es, d_ddot[:, 2]
        s, c = np.sin(lat), np.cos(lat)
        x = 1.0 - earth.E2 * s * s
        rm, rn = earth.principal_radii(s)
        drm = 3.0 * rm * earth.E2 * s * c / x        # dR_M/dlat
        drn = rn * earth.E2 * s * c / x              # dR_N/dlat
        rm_h, rn_h = rm + h, rn + h
        n = lat.shape[0]
        vel = np.empty((n, 3))
        acc = np.empty((n, 3))
        vel[:, 0] = rn_h * c * lon_d
        vel[:, 1] = rm_h * lat_d
        vel[:, 2] = h_d
        acc[:, 0] = ((drn * lat_d + h_d) * c - rn_h * s * lat_d) * lon_d + rn_h * c * lon_dd
        acc[:, 1] = (drm * lat_d + h_d) * lat_d + rm_h * lat_dd
        acc[:, 2] = h_dd
        # + 0.0 turns a -0.0 into +0.0: with nothing moving the state is then
        # bit for bit the base profile's (whose zeros are +0.0).
        return MotionState(lat, lon, h, vel + 0.0, acc + 0.0, base_st.euler, base_st.euler_rate)

    def _lever_terms(self, t, t_lo, table):
        """r_b, dr_b/dt, d2r_b/dt2 [m, m/s, m/s^2], (N, 3) each."""
        n = t.shape[0]
        r = np.tile(self.lever_b, (n, 1))
        r_d = np.zeros((n, 3))
        r_dd = np.zeros((n, 3))
        if self.needs_table:
            if table is None:       # p = b, as exact_increments with table=None
                alpha, ad, add = np.zeros(n), np.zeros(n), np.zeros(n)
            else:
                alpha, ad, add = table.state3(t, t_lo)
            ca, sa = np.cos(alpha), np.sin(alpha)
            lx, ly, lz = self.lever_p
            qx = ca * lx - sa * ly              # q = Rz(alpha) lever_p
            qy = sa * lx + ca * ly
            r[:, 0] = r[:, 0] + qx
            r[:, 1] = r[:, 1] + qy
            r[:, 2] = r[:, 2] + lz
            # d/dt Rz(alpha) q0 = alpha' e_z x q;  e_z x q = [-qy, qx, 0]
            r_d[:, 0] = -ad * qy
            r_d[:, 1] = ad * qx
            r_dd[:, 0] = -add * qy - ad * ad * qx
            r_dd[:, 1] = add * qx - ad * ad * qy
        return r, r_d, r_dd

    def reference_state(self, t, t_lo=None):
        """MotionState of the motion reference point (offset d(t) only)."""
        t, t_lo = as_times(t, t_lo)
        base_st = self.base.state(t, t_lo)
        return self._geodetic(*self._displacement(t, t_lo), base_st)

    def state(self, t, t_lo=None, table=None):
        """MotionState of the IMU point.

        ``table`` (a `pyins.sim.turntable.TableMotion`) is needed only with a
        non-zero ``lever_p``; None means alpha = 0 (p = b).
        """
        t, t_lo = as_times(t, t_lo)
        base_st = self.base.state(t, t_lo)
        d, d_d, d_dd = self._displacement(t, t_lo)
        if np.any(self.lever_b != 0.0) or self.needs_table:
            r, r_d, r_dd = self._lever_terms(t, t_lo, table)
            w, wd = nb_rate_and_derivative(base_st.euler, base_st.euler_rate,
                                           self.base.euler_accel(t, t_lo))
            c = euler_to_mat(base_st.euler)
            wxr = _cross(w, r)
            a1 = wxr + r_d
            a2 = (_cross(w, wxr) + _cross(wd, r)) + (2.0 * _cross(w, r_d) + r_dd)
            d = d + _mat_vec(c, r)
            d_d = d_d + _mat_vec(c, a1)
            d_dd = d_dd + _mat_vec(c, a2)
        return self._geodetic(d, d_d, d_dd, base_st)

    def __repr__(self):
        return (f"ShipAtSea(base={type(self.base).__name__}, linear={self.linear!r}, "
                f"lever_b={self.lever_b.tolist()}, lever_p={self.lever_p.tolist()})")


# ---------------------------------------------------------------------------
# 3. Wave spectra and the ship's response
# ---------------------------------------------------------------------------
def pierson_moskowitz(omega, hs, tp):
    """Modified (two-parameter) Pierson-Moskowitz spectrum S(w) [m^2 s/rad].

    S(w) = 5/16 Hs^2 wp^4 w^-5 exp(-5/4 (w / wp)^-4), wp = 2 pi / Tp
    (DNV-RP-C205 sec. 3.5.5; Pierson & Moskowitz 1964). Its zeroth moment
    is Hs^2 / 16.
    """
    w = np.asarray(omega, dtype=float)
    wp = TWO_PI / tp
    return (5.0 / 16.0) * hs * hs * wp ** 4 * w ** -5.0 * np.exp(-1.25 * (w / wp) ** -4.0)


def jonswap(omega, hs, tp, gamma=3.3):
    """JONSWAP spectrum S(w) [m^2 s/rad] (DNV-RP-C205 sec. 3.5.5).

    S_J = A_gamma S_PM(w) gamma^exp(-0.5 ((w - wp) / (sigma wp))^2), with
    A_gamma = 1 - 0.287 ln(gamma) and sigma = 0.07 (w <= wp) or 0.09 (w > wp)
    (Hasselmann et al. 1973). gamma = 1 is the Pierson-Moskowitz spectrum.
    """
    w = np.asarray(omega, dtype=float)
    wp = TWO_PI / tp
    sigma = np.where(w <= wp, 0.07, 0.09)
    peak = gamma ** np.exp(-0.5 * ((w - wp) / (sigma * wp)) ** 2)
    return (1.0 - 0.287 * np.log(gamma)) * pierson_moskowitz(w, hs, tp) * peak


def dnv_gamma(hs, tp):
    """DNV-RP-C205 sec. 3.5.5 rule for gamma when no value is known:
    5 for Tp / sqrt(Hs) <= 3.6, exp(5.75 - 1.15 Tp / sqrt(Hs)) up to 5, 1 above."""
    r = tp / np.sqrt(hs)
    if r <= 3.6:
        return 5.0
    if r < 5.0:
        return float(np.exp(5.75 - 1.15 * r))
    return 1.0


def heave_response(omega, natural_period=8.0, damping=0.3):
    """|H(w)| of heave per unit wave amplitude: a damped second-order low pass.

    |H| = 1 / sqrt((1 - (w/wn)^2)^2 + (2 zeta w/wn)^2), wn = 2 pi / natural
    period: long waves are followed one to one, short waves are filtered
    out, with a resonance of 1 / (2 zeta) at wn (Fossen 2011 ch. 8, the
    heave RAO of a mass-spring-damper; ~8 s and zeta ~0.3 are typical of a
    mid-size ship). A deliberately simple model, not a hull's RAO.
    """
    u = np.asarray(omega, dtype=float) / (TWO_PI / natural_period)
    return 1.0 / np.sqrt((1.0 - u * u) ** 2 + (2.0 * damping * u) ** 2)


def sea_spectrum_motion(hs, tp, spectrum="jonswap", gamma=3.3, seed=0, n_components=40,
                        band=(0.5, 3.0), natural_period=8.0, damping=0.3, surge_ratio=0.5,
                        sway_ratio=0.4, period_step=DT):
    """Heave, surge and sway of a moored ship in a sea of a standard spectrum.

    The band ``[band[0] wp, band[1] wp]`` (wp = 2 pi / Tp; the default holds
    98.5 % of the PM energy) is cut into ``n_components`` equal slices dw;
    the centre of each slice is turned into a period ROUNDED to a multiple of
    ``period_step`` (DT = 0.01 s: whole ticks at 100 Hz, so the phases are
    exact and the periods rational), and the component at w_i = 2 pi / T_i
    gets the amplitude a_i = |H(w_i)| sqrt(2 S(w_i) dw) (Fossen 2011 ch. 8)
    and a uniform random phase from ``numpy.random.default_rng(seed)`` (one draw
    of shape (3, n): heave, surge, sway rows; independent per axis).

    Ship response: heave `heave_response` (natural period, damping ratio);
    surge and sway ``surge_ratio`` and ``sway_ratio`` times the heave
    response (a moored ship, held by its lines: 0.5 and 0.4 by default).
    The LCM of the rounded periods is far beyond a run, so
    `pyins.sim.motion.periodic_ticks` treats the result as not periodic.

    Parameters
    ----------
    hs, tp : float
        Significant wave height [m] and peak period [s], finite and > 0.
    spectrum : {'jonswap', 'pm'}
        JONSWAP or modified (two-parameter) Pierson-Moskowitz.
    gamma : float
        JONSWAP peak enhancement, 1 <= gamma <= 7 (DNV's range); ignored for 'pm'.
    seed : int
        Seed of the phases.
    n_components : int
        Number of sinusoids per axis.
    band : (float, float)
        Band edges as multiples of wp, 0 < lo < hi.
    natural_period, damping : float
        Heave natural period [s] and damping ratio of `heave_response`.
    surge_ratio, sway_ratio : float
        Surge and sway response as fractions of the heave response (>= 0).
    period_step : float
        Periods are rounded to multiples of this [s].

    Returns
    -------
    LinearMotion
    """
    hs = _positive("hs", hs, " of metres")
    tp = _positive("tp", tp, " of seconds")
    if spectrum not in ("jonswap", "pm"):
        raise ValueError(f"spectrum: must be 'jonswap' or 'pm', got {spectrum!r}")
    if spectrum == "jonswap":
        gamma = _positive("gamma", gamma, "")
        if not 1.0 <= gamma <= 7.0:
            raise ValueError(f"gamma: must be in [1, 7] (DNV-RP-C205 3.5.5), got {gamma:g}")
    if isinstance(n_components, bool) or not isinstance(n_components, numbers.Integral) \
            or n_components < 1:
        raise ValueError(f"n_components: must be a positive integer, got {n_components!r}")
    try:
        lo, hi = (_real(b) for b in band)
    except (TypeError, ValueError):
        raise ValueError(f"band: must be two multiples of the peak frequency, got {band!r}") from None
    if not (np.isfinite(lo) and np.isfinite(hi) and 0.0 < lo < hi):
        raise ValueError(f"band: must satisfy 0 < lo < hi (finite), got ({lo:g}, {hi:g})")
    natural_period = _positive("natural_period", natural_period, " of seconds")
    damping = _positive("damping", damping, "")
    period_step = _positive("period_step", period_step, " of seconds")
    ratios = []
    for name, r in (("surge_ratio", surge_ratio), ("sway_ratio", sway_ratio)):
        try:
            r = _real(r)
        except TypeError:
            raise ValueError(f"{name}: must be a finite number >= 0, got {r!r}") from None
        if not (np.isfinite(r) and r >= 0.0):
            raise ValueError(f"{name}: must be a finite number >= 0, got {r:g}")
        ratios.append(r)
    surge_ratio, sway_ratio = ratios

    wp = TWO_PI / tp
    dw = (hi - lo) * wp / n_components
    w_mid = lo * wp + (np.arange(n_components) + 0.5) * dw
    steps = np.rint(TWO_PI / w_mid / period_step)
    if np.any(steps < 1):
        raise ValueError(f"tp: {tp:g} s is too short for periods rounded to {period_step:g} s")
    periods = steps * period_step
    w = TWO_PI / periods
    s = jonswap(w, hs, tp, gamma) if spectrum == "jonswap" else pierson_moskowitz(w, hs, tp)
    heave_amp = heave_response(w, natural_period, damping) * np.sqrt(2.0 * s * dw)
    if not np.any(heave_amp > 0.0):
        raise ValueError(f"spectrum: no energy in the band {lo:g}..{hi:g} x wp (hs={hs:g} m, "
                         f"tp={tp:g} s): every amplitude is 0")
    phases = np.random.default_rng(seed).uniform(0.0, TWO_PI, size=(3, n_components))
    keep = heave_amp > 0.0

    def axis(ratio, row):
        return [(float(ratio * a), float(p), float(ph))
                for a, p, ph, k in zip(heave_amp, periods, phases[row], keep) if k and ratio * a != 0.0]
    return LinearMotion(heave=axis(1.0, 0), surge=axis(surge_ratio, 1), sway=axis(sway_ratio, 2))


#: Named sea states for `named_sea_spectrum`: ``name -> sea_spectrum_motion``
#: keywords. Hs lies in the band of the WMO sea state code (WMO No. 306, code
#: table 3700: 2 smooth 0.1-0.5 m, 3 slight 0.5-1.25 m, 4 moderate
#: 1.25-2.5 m, 5 rough 2.5-4 m); Tp is a typical peak period for that Hs and
#: gamma follows the DNV-RP-C205 sec. 3.5.5 rule (`dnv_gamma`): gamma = 1, the PM
#: spectrum, for every preset with Tp / sqrt(Hs) >= 5.
SEA_STATE_SPECTRA = {
    "harbour_smooth": dict(hs=0.3, tp=4.0, gamma=1.0),     # WMO 2, sheltered basin
    "moored_slight": dict(hs=0.8, tp=6.0, gamma=1.0),      # WMO 3
    "moored_moderate": dict(hs=1.25, tp=8.0, gamma=1.0),   # WMO 4, lower edge
    "open_rough": dict(hs=3.0, tp=8.0, gamma=1.55),        # WMO 5, Tp/sqrt(Hs) = 4.6
}


def named_sea_spectrum(name, seed=0, **overrides):
    """`sea_spectrum_motion` of a preset of `SEA_STATE_SPECTRA` (JONSWAP with
    the preset's gamma); keywords override the preset or the defaults."""
    if name not in SEA_STATE_SPECTRA:
        raise ValueError(f"unknown spectral sea state {name!r}; choose one of "
                         f"{sorted(SEA_STATE_SPECTRA)}")
    kw = dict(SEA_STATE_SPECTRA[name], spectrum="jonswap", seed=seed)
    kw.update(overrides)
    return sea_spectrum_motion(**kw)


# ---------------------------------------------------------------------------
# 4. The built-in moored ship
# ---------------------------------------------------------------------------
#: Default moored-ship linear motion and lever arm: heave 0.5 m at 8 s, surge
#: 0.3 m at 12 s, sway 0.3 m at 10 s (amplitude [m], period [s], phase
#: [rad]); IMU 0.5 m to starboard, 1.5 m forward, 1.2 m above the motion
#: reference point (lever_b, b frame [m]).
MOORED_SHIP = dict(heave=((0.5, 8.0, 0.0),), surge=((0.3, 12.0, 0.0),),
                   sway=((0.3, 10.0, 0.0),), lever_b=(0.5, 1.5, 1.2))


def moored(sea_state_name, lat, lon, height, yaw0, pitch0=0.0, roll0=0.0,
           phase=(0.0, 0.0, 0.0), lever_p=(0.0, 0.0, 0.0)):
    """A moored ship: seed 000 sea-state swing plus `MOORED_SHIP`.

    Parameters
    ----------
    sea_state_name : {'general', 'ideal', 'bad'}
        Swing of seed 000 Table 2 (`pyins.sim.motion.sea_state`).
    lat, lon, height : float
        Mean position of the motion reference point [rad, rad, m].
    yaw0, pitch0, roll0 : float
        Mean attitude [rad].
    phase : array_like (3,)
        Phases of the swing [rad].
    lever_p : array_like (3,)
        Sensor offset on the table [m] (default none).
    """
    swing = sea_state(sea_state_name, lat, lon, height, yaw0, pitch0, roll0, phase)
    linear = LinearMotion(heave=MOORED_SHIP["heave"], surge=MOORED_SHIP["surge"],
                          sway=MOORED_SHIP["sway"])
    return ShipAtSea(swing, linear, lever_b=MOORED_SHIP["lever_b"], lever_p=lever_p)


# ---------------------------------------------------------------------------
# 5. A ship at anchor
# ---------------------------------------------------------------------------
#: The ship at anchor of the built-in scenario `at_anchor` and of
#: tools/anchor_alignment.py: the chain's radius (the anchor to the motion
#: reference point) [m], the period of the swing [s] and its half angle
#: [rad]: tens of metres over tens of minutes.
AT_ANCHOR = dict(radius=50.0, period=2400.0, swing=30.0 * np.pi / 180.0)

#: Harmonics of the arc kept (`anchor_linear`): the next one, J_7(pi/2),
#: is 6e-6 of the radius (0.5 mm at 80 m).
_ARC_HARMONICS = 6


def _bessel_j(n, x):
    """Bessel function of the first kind J_n(x), its power series
    sum_k (-1)^k (x/2)^(2k+n) / (k! (k+n)!) (Abramowitz & Stegun 9.1.10),
    to double precision for |x| <= pi / 2 (30 terms; the last is below
    1e-40)."""
    term = (x / 2.0) ** n
    for k in range(1, n + 1):
        term = term / k
    total = term
    for k in range(1, 30):
        term = -term * (x / 2.0) ** 2 / (k * (k + n))
        total = total + term
    return total


def _checked_swing(period, swing, phase):
    """The swing's period [s], half angle [rad] and phase [rad] as floats,
    or a ValueError naming the one out of range."""
    period, swing, phase = float(period), float(swing), float(phase)
    if not (np.isfinite(period) and period > 0.0):
        raise ValueError(f"period: {period!r} s, must be finite and > 0")
    if not (np.isfinite(swing) and 0.0 <= swing <= np.pi / 2.0):
        raise ValueError(f"swing: {swing!r} rad, the half angle must be within 0..90 deg")
    if not np.isfinite(phase):
        raise ValueError(f"phase: {phase!r} rad, must be finite")
    return period, swing, phase


def anchor_linear(radius, period, swing, phase=0.0):
    """Sway and surge of a ship's reference point on its arc about the anchor.

    The anchor lies ``radius`` ahead of the mean position along the mean
    bow; the chain's angle from that line is theta(t) = swing sin(2 pi t /
    period + phase), and the ship lies on the circle, its bow towards the
    anchor:

        sway(t)  = -radius sin theta
        surge(t) =  radius (1 - cos theta)     (towards the anchor)

    Both are Fourier series of sin(x), x = 2 pi t / period + phase (the
    Jacobi-Anger expansion, Abramowitz & Stegun 9.1.42-43):

        sin(s sin x) = 2 sum_{k odd}  J_k(s) sin(k x)
        cos(s sin x) = J_0(s) + 2 sum_{k even >= 2} J_k(s) cos(k x)

    kept to the 6th harmonic (the 7th is 0.5 mm at 80 m and 90 deg; with
    the positions' radii fixed at the site the ship stays within 6 mm of
    the circle). The
    constant radius (1 - J_0(s)) is left out: the mean position is the
    arc's mean. Returns ``(surge, sway)`` as `LinearMotion` components
    ((amplitude [m], period [s], phase [rad]), ...).
    """
    radius = float(radius)
    if not (np.isfinite(radius) and 0.0 <= radius <= 1000.0):
        raise ValueError(f"radius: {radius!r} m, must be within 0..1000 m")
    period, swing, phase = _checked_swing(period, swing, phase)
    sway, surge = [], []
    for k in range(1, _ARC_HARMONICS + 1):
        a = 2.0 * radius * _bessel_j(k, swing)
        if k % 2:       # -radius 2 J_k sin(k x)
            sway.append((-a, period / k, k * phase))
        else:           # -radius 2 J_k cos(k x) = -radius 2 J_k sin(k x + pi / 2)
            surge.append((-a, period / k, k * phase + np.pi / 2.0))
    return tuple(surge), tuple(sway)


def anchor_swing(sea_state_name, lat, lon, height, yaw0, period, swing, phase=0.0, pitch0=0.0, roll0=0.0):
    """The attitude of a ship at anchor (`at_anchor`): the sea state's pitch
    and roll, yaw0 - theta(t) with theta(t) = swing sin(2 pi t / period +
    phase)."""
    period, swing, phase = _checked_swing(period, swing, phase)
    sea = sea_state(sea_state_name, lat, lon, height, yaw0, pitch0, roll0)
    return Swing(lat, lon, height, pitch0, roll0, yaw0, [sea.amplitude[0], sea.amplitude[1], swing],
                 [sea.frequency_hz[0], sea.frequency_hz[1], 1.0 / period], [0.0, 0.0, phase + np.pi])


def at_anchor(sea_state_name, lat, lon, height, yaw0, radius=AT_ANCHOR["radius"],
              period=AT_ANCHOR["period"], swing=AT_ANCHOR["swing"], phase=0.0, pitch0=0.0, roll0=0.0,
              heave=MOORED_SHIP["heave"], surge=(), sway=(), lever_b=MOORED_SHIP["lever_b"],
              lever_p=(0.0, 0.0, 0.0)):
    """A ship swinging at anchor.

    The reference point goes round the arc of `anchor_linear` (``radius``,
    ``period``, half angle ``swing``, ``phase``) and the bow follows the
    chain: yaw(t) = yaw0 - theta(t) (counter-clockwise yaw; the ship turns
    to starboard while it swings to port), its rate up to swing 2 pi /
    period (0.08 deg/s at 30 deg and 40 min). Pitch and roll are the sea
    state's (seed 000 Table 2, `pyins.sim.motion.sea_state`); its yaw is
    the swing's alone (the waves' few degrees of yaw at 0.2 Hz left out:
    `Swing` carries one sinusoid per angle). ``heave`` (default the moored
    ship's 0.5 m at 8 s) and any ``surge``/``sway`` sinusoids add to the
    arc; ``lever_b`` (default the moored ship's) and ``lever_p`` as
    `ShipAtSea`. yaw0 is the mean yaw: the mean bow points at the anchor.
    """
    base = anchor_swing(sea_state_name, lat, lon, height, yaw0, period, swing, phase, pitch0, roll0)
    arc_surge, arc_sway = anchor_linear(radius, period, swing, phase)
    linear = LinearMotion(heave=heave, surge=tuple(arc_surge) + tuple(surge), sway=tuple(arc_sway) + tuple(sway))
    return ShipAtSea(base, linear, lever_b=lever_b, lever_p=lever_p)
