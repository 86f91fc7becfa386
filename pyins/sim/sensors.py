"""Sensor error model of the gyro and accelerometer triads (IMU frame p).

Per tick, for each triad (seed 002 eq. (1), docs/papers.md, seed 002 §4):

    measured = (I + diag(scale) + misalignment) true + bias dt + w,
    w ~ N(0, (random_walk sqrt(dt))^2) per axis, independent between ticks,

then quantisation to whole pulses of size ``quantum`` with the remainder
carried to the next tick, as an RLG or accelerometer pulse counter does. The
counter is modelled on its running sum S_k = S_{k-1} + measured_k: the
output of tick k is quantum (N_k - N_{k-1}) with N_k = floor(S_k / quantum +
1/2), which is the same as rounding (residual + measured) to whole pulses and
carrying the residual. Every 2**16 ticks (counted from the model's first
sample, so independent of how the run is chunked) the running sum is reset to
its residual so it never grows large. All in float64.

``misalignment[i, j]`` (i != j) is the sensitivity of axis i to the input
about / along axis j [rad]; its diagonal is zero.

Units: SI. gyro_arw in rad/sqrt(s), accel_vrw in (m/s)/sqrt(s). The
conversions used by the presets: 1 deg/sqrt(h) = DEG_TO_RAD / 60 rad/sqrt(s);
1 ug/sqrt(Hz) = UG_TO_MPS2 (m/s^2)/sqrt(Hz), which is numerically the same in
(m/s)/sqrt(s); 1 ug = 1e-6 * 9.80665 m/s^2 (``pyins.units.UG_TO_MPS2``).

1. The errors: `SensorErrors`.
2. The pulse counter: `_Quantiser`.
3. The model applied chunk by chunk: `SensorModel`.
4. The presets: `PRESETS`, `preset` (the papers' sensor set-ups as the
   project reads them, docs/papers.md).
5. Random-constant draws: `random_constant_values`, `random_constant_overrides`,
   `draw_random_constants` (each random constant of a preset drawn as
   N(0, sigma^2) with sigma its preset value: production units of the
   grade a paper describes; Monte-Carlo campaigns, docs/results/montecarlo.md).
"""
from dataclasses import dataclass, field, replace

import numpy as np

from pyins.units import ARCSEC_TO_RAD, DPH_TO_RPS, DPSH_TO_RPSS, DT, UG_TO_MPS2

#: deg/sqrt(h) -> rad/sqrt(s)
#: ug/sqrt(Hz) -> (m/s)/sqrt(s)
UGPSHZ_TO_MPSPSS = UG_TO_MPS2
#: ppm -> dimensionless
PPM = 1e-6

#: Ticks between resets of the quantiser's running sum to its residual.
QUANTISER_RESET_TICKS = 1 << 16


# ---------------------------------------------------------------------------
# 1. The errors
# ---------------------------------------------------------------------------
def _vec3():
    return field(default_factory=lambda: np.zeros(3))


def _mat3():
    return field(default_factory=lambda: np.zeros((3, 3)))


@dataclass
class SensorErrors:
    """Errors of both triads, per axis of the p frame, SI units."""
    gyro_bias: np.ndarray = _vec3()             #: [rad/s]
    gyro_scale: np.ndarray = _vec3()            #: scale-factor error [-]
    gyro_misalignment: np.ndarray = _mat3()     #: [rad], zero diagonal
    gyro_arw: float = 0.0                       #: angle random walk [rad/sqrt(s)]
    gyro_quantum: float = 0.0                   #: pulse size [rad], 0 = none
    accel_bias: np.ndarray = _vec3()            #: [m/s^2]
    accel_scale: np.ndarray = _vec3()           #: [-]
    accel_misalignment: np.ndarray = _mat3()    #: [rad], zero diagonal
    accel_vrw: float = 0.0                      #: velocity random walk [(m/s)/sqrt(s)]
    accel_quantum: float = 0.0                  #: pulse size [m/s], 0 = none

    def __post_init__(self):
        for name in ("gyro_bias", "gyro_scale", "accel_bias", "accel_scale"):
            v = np.array(getattr(self, name), dtype=float)
            if v.shape == ():
                v = np.full(3, float(v))
            if v.shape != (3,):
                raise ValueError(f"{name} must have 3 elements, got shape {v.shape}")
            setattr(self, name, v)
        for name in ("gyro_misalignment", "accel_misalignment"):
            m = np.array(getattr(self, name), dtype=float)
            if m.shape != (3, 3):
                raise ValueError(f"{name} must be 3x3, got shape {m.shape}")
            if np.any(np.diag(m) != 0.0):
                raise ValueError(f"{name} must have a zero diagonal (scale errors go in *_scale)")
            setattr(self, name, m)
        for name in ("gyro_arw", "gyro_quantum", "accel_vrw", "accel_quantum"):
            v = float(getattr(self, name))
            if not v >= 0.0:
                raise ValueError(f"{name} must be >= 0, got {v}")
            setattr(self, name, v)


# ---------------------------------------------------------------------------
# 2. The pulse counter
# ---------------------------------------------------------------------------
class _Quantiser:
    """Pulse counter of one triad (see the module docstring)."""

    def __init__(self, quantum):
        self.quantum = quantum
        self.sum = np.zeros(3)            # running sum since the last reset
        self.count = np.zeros(3)          # whole pulses in that sum
        self.ticks = 0                    # samples seen so far

    def __call__(self, x):
        if self.quantum == 0.0:
            self.ticks += len(x)
            return x
        q = self.quantum
        out = np.empty_like(x)
        a = 0
        while a < len(x):
            to_reset = QUANTISER_RESET_TICKS - self.ticks % QUANTISER_RESET_TICKS
            if self.ticks % QUANTISER_RESET_TICKS == 0 and self.ticks > 0:
                self.sum = self.sum - q * self.count      # keep the residual only
                self.count = np.zeros(3)
            b = min(len(x), a + to_reset)
            s = np.cumsum(np.vstack([self.sum, x[a:b]]), axis=0)[1:]
            n = np.floor(s / q + 0.5)
            prev = np.vstack([self.count, n[:-1]])
            out[a:b] = q * (n - prev)
            self.sum, self.count = s[-1].copy(), n[-1].copy()
            self.ticks += b - a
            a = b
        return out

    @property
    def residual(self):
        """What has been measured but not yet output [rad or m/s], (3,)."""
        return self.sum - self.quantum * self.count


# ---------------------------------------------------------------------------
# 3. The model, chunk by chunk
# ---------------------------------------------------------------------------
def _apply_matrix(scale, mis, x):
    """x + (diag(scale) + mis) x, element-wise (no BLAS)."""
    out = np.empty_like(x)
    for i in range(3):
        err = scale[i] * x[:, i] + (mis[i, 0] * x[:, 0] + mis[i, 1] * x[:, 1]
                                    + mis[i, 2] * x[:, 2])
        out[:, i] = err
    return x + out


class SensorModel:
    """Applies `SensorErrors` to exact increments, chunk by chunk.

    Holds its own ``numpy.random.Generator`` (PCG64 seeded with ``seed``) and
    the quantisation residuals, so that applying it to consecutive chunks
    gives bit for bit what one call on the whole run gives, and the same seed
    reproduces a run. Per tick it draws 6 standard normals (gyro x, y, z then
    accelerometer x, y, z) whenever any noise is non-zero.

    Parameters
    ----------
    errors : SensorErrors
    seed : int or None
        Seed of the noise generator.
    dt : float
        Tick length [s].
    """

    def __init__(self, errors, seed, dt=DT):
        self.errors = errors
        self.seed = seed
        self.dt = float(dt)
        self._rng = np.random.default_rng(seed)
        self._gyro_q = _Quantiser(errors.gyro_quantum)
        self._accel_q = _Quantiser(errors.accel_quantum)

    @property
    def residuals(self):
        """Carried quantisation residuals (gyro [rad], accel [m/s])."""
        return self._gyro_q.residual, self._accel_q.residual

    def apply(self, dtheta, dv):
        """Measured increments from exact ones, (N, 3) each, in the p frame."""
        e = self.errors
        dtheta = np.asarray(dtheta, dtype=float)
        dv = np.asarray(dv, dtype=float)
        if dtheta.shape != dv.shape or dtheta.ndim != 2 or dtheta.shape[1] != 3:
            raise ValueError(f"dtheta and dv must both be (N, 3), got {dtheta.shape} and {dv.shape}")
        gyro = _apply_matrix(e.gyro_scale, e.gyro_misalignment, dtheta)
        accel = _apply_matrix(e.accel_scale, e.accel_misalignment, dv)
        gyro = gyro + e.gyro_bias * self.dt
        accel = accel + e.accel_bias * self.dt
        if e.gyro_arw > 0.0 or e.accel_vrw > 0.0:
            z = self._rng.standard_normal((len(dtheta), 6))
            sq = np.sqrt(self.dt)
            gyro = gyro + (e.gyro_arw * sq) * z[:, :3]
            accel = accel + (e.accel_vrw * sq) * z[:, 3:]
        return self._gyro_q(gyro), self._accel_q(accel)


# ---------------------------------------------------------------------------
# 4. Presets
# ---------------------------------------------------------------------------
_AS = ARCSEC_TO_RAD
_DPH = DPH_TO_RPS
_UG = UG_TO_MPS2

#: Seed 003 installation-error matrix (both triads), [rad].
_SEED003_MIS = np.array([[0.0, -2.0, 2.0], [2.0, 0.0, -2.0], [-2.0, 2.0, 0.0]]) * _AS

PRESETS = {
    # No errors at all: the output is the exact increments.
    "error_free": SensorErrors(),
    # Seed 000 (docs/papers.md, seed 000 §2; the paper's Fig. 1): the smallest
    # simulated levels, gyro drift 0.01 deg/h and accelerometer bias 0.1 mg =
    # 100 ug. The paper states no noise, scale-factor, misalignment or
    # quantisation figures for its simulation (and none for its 90-type RLG
    # IMU), so they are zero here.
    "seed000": SensorErrors(gyro_bias=np.full(3, 0.01 * _DPH),
                            accel_bias=np.full(3, 100.0 * _UG)),
    # Seed 001 (docs/papers.md, seed 001 §3): PSINS's imuerrset(1) = imuerrset(0.01, 100,
    # 0.001, 10), the set the paper simulated (docs/papers.md, "How the papers built their
    # error sets"; tests/papers/test_presets_psins.py): drift [0.01 0.01 0.01] deg/h;
    # gyro noise Q = diag(1e-3 deg/h)^2 "as printed", interpreted as an ARW of
    # 0.001 deg/sqrt(h); accelerometer bias 100 ug; accelerometer noise
    # Q = diag(10 ug)^2 interpreted as a VRW of 10 ug/sqrt(Hz).
    "seed001": SensorErrors(gyro_bias=np.full(3, 0.01 * _DPH),
                            gyro_arw=0.001 * DPSH_TO_RPSS,
                            accel_bias=np.full(3, 100.0 * _UG),
                            accel_vrw=10.0 * UGPSHZ_TO_MPSPSS),
    # Seed 002 (docs/papers.md, seed 002 §7, Table 2), as PSINS's imuerrset(0.003, 30, 0.0005,
    # 5, [], [], [], [], 10, 10, 10, 10) builds it, the set the paper simulated (every term
    # +its value; tests/papers/test_presets_psins.py): drift 0.003 deg/h,
    # bias 30 ug (ug likely), ARW 0.0005 deg/sqrt(h), VRW 5 ug/sqrt(Hz)
    # (likely), scale factors 10 ppm on both triads (likely), six gyro
    # installation terms 10" (all off-diagonal), three accelerometer terms
    # 10" in the lower triangle (K_ayx, K_azx, K_azy: lower-triangular model).
    "seed002": SensorErrors(gyro_bias=np.full(3, 0.003 * _DPH),
                            gyro_scale=np.full(3, 10.0 * PPM),
                            gyro_misalignment=(np.ones((3, 3)) - np.eye(3)) * 10.0 * _AS,
                            gyro_arw=0.0005 * DPSH_TO_RPSS,
                            accel_bias=np.full(3, 30.0 * _UG),
                            accel_scale=np.full(3, 10.0 * PPM),
                            accel_misalignment=np.tril(np.ones((3, 3)), -1) * 10.0 * _AS,
                            accel_vrw=5.0 * UGPSHZ_TO_MPSPSS),
    # Seed 003 (docs/papers.md, seed 003 §3): drift 0.003 deg/h; "random
    # error 0.0005 deg/h" interpreted as ARW 0.0005 deg/sqrt(h); gyro
    # scale-factor 0.466 ppm; accelerometer bias 20 ug, scale factor 20 ppm;
    # installation matrix [0, -2", 2"; 2", 0, -2"; -2", 2", 0] for both
    # triads. No accelerometer noise is given (zero). The paper's 1-s sampling is not copied: the
    # model runs at the caller's dt.
    "seed003": SensorErrors(gyro_bias=np.full(3, 0.003 * _DPH),
                            gyro_scale=np.full(3, 0.466 * PPM),
                            gyro_misalignment=_SEED003_MIS.copy(),
                            gyro_arw=0.0005 * DPSH_TO_RPSS,
                            accel_bias=np.full(3, 20.0 * _UG),
                            accel_scale=np.full(3, 20.0 * PPM),
                            accel_misalignment=_SEED003_MIS.copy()),
}


def preset(name, gyro_bias_signs=(1.0, 1.0, 1.0), accel_bias_signs=(1.0, 1.0, 1.0)):
    """A fresh copy of a preset, with an optional sign pattern on the biases.

    Parameters
    ----------
    name : {'error_free', 'seed000', 'seed001', 'seed002', 'seed003'}
        See `PRESETS` for the sources and interpretations.
    gyro_bias_signs, accel_bias_signs : sequence of 3 in {-1, 0, 1}
        Multiply the (positive) preset biases axis by axis.
    """
    if name not in PRESETS:
        raise ValueError(f"unknown sensor preset {name!r}; choose one of {sorted(PRESETS)}")
    p = PRESETS[name]
    return replace(p,
                   gyro_bias=p.gyro_bias * np.asarray(gyro_bias_signs, dtype=float),
                   gyro_scale=p.gyro_scale.copy(),
                   gyro_misalignment=p.gyro_misalignment.copy(),
                   accel_bias=p.accel_bias * np.asarray(accel_bias_signs, dtype=float),
                   accel_scale=p.accel_scale.copy(),
                   accel_misalignment=p.accel_misalignment.copy())


# ---------------------------------------------------------------------------
# 5. Random-constant draws (Monte Carlo over production units, the stated values as 1 sigma)
# ---------------------------------------------------------------------------
#: The terms a paper states as random constants, in the order their standard
#: normals are drawn, with the unit a scenario file writes them in.
RANDOM_CONSTANT_TERMS = (("gyro_bias", "deg/h", DPH_TO_RPS), ("gyro_scale", "ppm", PPM),
                         ("gyro_misalignment", "arcsec", ARCSEC_TO_RAD),
                         ("accel_bias", "ug", UG_TO_MPS2), ("accel_scale", "ppm", PPM),
                         ("accel_misalignment", "arcsec", ARCSEC_TO_RAD))
#: Mixed into every draw's seed so that draw ``d`` is not the noise stream of
#: ``numpy.random.default_rng(d)`` (the scenario seed of the same run).
RANDOM_CONSTANT_SALT = 0x5EED_C0DE


def _sigma_in_unit(value_si, factor):
    """A preset's +1-sigma value in the file's unit, rounded to 12 significant
    digits (0.003 deg/h, not 0.0030000000000000005)."""
    return np.vectorize(lambda x: float(f"{x / factor:.12g}") if x != 0.0 else 0.0,
                        otypes=[float])(np.abs(np.asarray(value_si, dtype=float)))


def random_constant_normals(draw):
    """The 30 standard normals of draw ``draw`` (int >= 0): gyro bias (3),
    gyro scale (3), gyro misalignment (3x3, row by row), accelerometer bias
    (3), scale (3), misalignment (3x3), from PCG64 seeded with
    SeedSequence([RANDOM_CONSTANT_SALT, draw]). Every element is drawn even
    where a preset's sigma is zero, so draw d has the same normals under
    every preset (seed 002 and seed 003 draw d share them)."""
    if isinstance(draw, bool) or not isinstance(draw, (int, np.integer)) or draw < 0:
        raise ValueError(f"a draw must be an integer >= 0, got {draw!r}")
    rng = np.random.default_rng(np.random.SeedSequence([RANDOM_CONSTANT_SALT, int(draw)]))
    return rng.standard_normal(30)


def random_constant_values(name, draw):
    """Draw ``draw`` of preset ``name``'s random constants, in file units.

    The papers state their drifts, biases, scale-factor and installation
    errors as random constants (随机常值) with one value each; the presets
    hold that value with a plus sign on every term, the set the papers
    simulated (PSINS's imuerrset, docs/papers.md "How the papers built their
    error sets"). Here, to spread the figures over production units
    (docs/results/montecarlo.md), every term that
    is non-zero in the preset is drawn independently as N(0, sigma^2) with
    sigma = |preset value| (signs and magnitudes both random); terms the
    preset leaves zero stay zero (e.g. seed 002's upper-triangle
    accelerometer installation terms, every diagonal). A preset whose two
    installation matrices are one and the same skew-symmetric matrix (seed
    003 prints [0, -2", 2"; 2", 0, -2"; -2", 2", 0] for both triads) states
    a common rotation phi of the whole IMU, M = [phi x]: that rotation is
    drawn instead, phi_i ~ N(0, sigma_i^2) with sigma_i the printed element
    (`_common_rotation`), and both triads get the same [phi x], so a drawn
    unit's triads stay orthogonal and consistent with each other, as the
    paper's. The noise terms
    (ARW, VRW, quantum) are not random constants and stay the preset's; their
    random stream is the scenario's ``seed``.

    Returns {term: (values, unit)} with values a (3,) or (3, 3) array in
    ``unit`` (deg/h, ppm, arcsec, ug).
    """
    if name not in PRESETS:
        raise ValueError(f"unknown sensor preset {name!r}; choose one of {sorted(PRESETS)}")
    z = random_constant_normals(draw)
    p = PRESETS[name]
    out, i = {}, 0
    for term, unit, factor in RANDOM_CONSTANT_TERMS:
        sigma = _sigma_in_unit(getattr(p, term), factor)
        n = sigma.size
        out[term] = (sigma * z[i:i + n].reshape(sigma.shape), unit)
        i += n
    common = _common_rotation(p)
    if common is not None:
        # phi from the gyro installation terms' normals at the places [phi x]
        # holds +phi_x, +phi_y, +phi_z: (2, 1), (0, 2), (1, 0)
        zg = z[6:15].reshape(3, 3)
        phi = common * np.array([zg[2, 1], zg[0, 2], zg[1, 0]])
        skew = np.array([[0.0, -phi[2], phi[1]], [phi[2], 0.0, -phi[0]], [-phi[1], phi[0], 0.0]])
        out["gyro_misalignment"] = (skew, "arcsec")
        out["accel_misalignment"] = (skew.copy(), "arcsec")
    return out


def _common_rotation(p):
    """The 1-sigma rotation [arcsec] (x, y, z) when preset ``p`` states its
    installation errors as one common rotation of both triads (the two
    matrices equal, skew-symmetric and not zero), else None."""
    g, a = p.gyro_misalignment, p.accel_misalignment
    if not np.any(g) or not np.array_equal(g, a) or not np.array_equal(g, -g.T):
        return None
    return _sigma_in_unit(np.array([g[2, 1], g[0, 2], g[1, 0]]), ARCSEC_TO_RAD)


def random_constant_overrides(name, draw):
    """Draw ``draw`` of preset ``name`` (`random_constant_values`) as scenario
    overrides: {"sensors.gyro_bias": ["0.0012 deg/h", ...], ...}, each number
    written with repr (exact round trip), zeros as 0. With ``sensors.preset``
    = ``name`` these replace every random constant of the preset."""
    def text(x, unit):
        return 0 if x == 0.0 else f"{float(x)!r} {unit}"
    out = {}
    for term, (values, unit) in random_constant_values(name, draw).items():
        if values.ndim == 1:
            out[f"sensors.{term}"] = [text(x, unit) for x in values]
        else:
            out[f"sensors.{term}"] = [[text(x, unit) for x in row] for row in values]
    return out


def draw_random_constants(name, draw):
    """`SensorErrors` of preset ``name`` with its random constants replaced by
    draw ``draw`` (`random_constant_values`); noise terms as the preset's."""
    vals = random_constant_values(name, draw)
    factors = {term: factor for term, _, factor in RANDOM_CONSTANT_TERMS}
    return replace(PRESETS[name], **{t: v * factors[t] for t, (v, _) in vals.items()})
