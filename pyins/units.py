"""Physical quantities written with their units, as scenario files hold them.

``parse_quantity("0.003 deg/h", "angular_rate")`` returns the value in SI
(rad/s). Every dimension has a fixed list of accepted units (`UNITS`); the
conversion factors are the named constants defined below
(DEG_TO_RAD, ARCMIN_TO_RAD, ARCSEC_TO_RAD, DPH_TO_RPS, G0, UG_TO_MPS2,
NMI_TO_M), so ``parse_quantity("30 ug", "acceleration")`` is bit for bit
``30.0 * UG_TO_MPS2``, the number the sensor presets hold.

Plain numbers (no unit)
-----------------------
- Physical quantities need a unit: ``duration = 72`` is refused ("missing
  unit"), because 72 s, 72 min and 72 h are all plausible. The one exception
  is an exact zero (``0`` or ``0.0``), which is zero in every unit.
- Dimensionless quantities (``"dimensionless"``: scale factors, ratios,
  thresholds) take a plain number or ``"ppm"``, ``"ppb"``, ``"%"``.
- Counts and seeds are integers and are not quantities; the scenario
  loader reads them directly.

Ticks
-----
A time may be written in ticks (``"150 ticks"``) only when the tick rate is
known: pass ``tick_hz`` (the scenario loader passes the firmware's 100 Hz).
Without it "ticks" is an unknown unit.

Spelling
--------
Spaces are ignored (``"6 deg / s"`` == ``"6 deg/s"``); ``µ`` and ``μ`` may
stand for ``u``, ``°`` for ``deg``, ``²`` for ``^2``, ``√x`` for ``sqrt(x)``,
``'`` for arcmin and ``"`` for arcsec. Units are case-sensitive (``mg`` is
not ``Mg``) except that ``hz`` is read as ``Hz``.
"""
import math
import re

import numpy as np

# --- the constants, each defined once (csrc/src/units.hpp: kPi, kDegToRad, ...) --
# Everything in pyins that converts a unit or counts a tick reads these.
TWO_PI = 2.0 * np.pi                       #: (kTwoPi)
DEG_TO_RAD = np.pi / 180.0                 #: (kDegToRad)
ARCSEC_TO_RAD = DEG_TO_RAD / 3600.0        #: (kArcsecToRad)
ARCMIN_TO_RAD = DEG_TO_RAD / 60.0          #: (kArcminToRad)
DPH_TO_RPS = DEG_TO_RAD / 3600.0           #: deg/h -> rad/s (kDphToRps)
#: deg/sqrt(h) -> rad/sqrt(s): DEG / sqrt(3600 s) (an angle random walk)
DPSH_TO_RPSS = DEG_TO_RAD / 60.0
G0 = 9.80665                               #: standard gravity for ug/mg units [m/s^2] (kG0)
UG_TO_MPS2 = 1e-6 * G0                     #: micro-g -> m/s^2 (kUgToMps2)
NMI_TO_M = 1852.0                          #: nautical mile [m] (kNmiToM)

#: The firmware's default tick rate [Hz] (kDefaultTickHz) and its tick [s].
#: A scenario runs at this rate; logs may run at others (the firmware's
#: ``tick_hz``), so code that handles logs takes ``dt`` from the data.
TICK_HZ = 100
DT = 1.0 / TICK_HZ


class ScenarioError(ValueError):
    """A mistake in a scenario file or a quantity, as one line:
    ``FILE: key.path: reason`` (parts that are unknown are left out).

    ``source`` is the file (or ``<string>``), ``key`` the dotted key path
    (``sensors.gyro_bias``, ``compare.values[2]``), ``reason`` what is wrong.
    `pyins.scenario` re-exports this class.
    """

    def __init__(self, reason, key="", source=""):
        self.reason = " ".join(str(reason).split())
        self.key = key
        self.source = source
        super().__init__(self.reason)

    def __str__(self):
        return ": ".join(part for part in (self.source, self.key, self.reason) if part)

    def with_source(self, source):
        """The same error attributed to ``source`` (kept if already set)."""
        return ScenarioError(self.reason, self.key, self.source or source)


_DEG = DEG_TO_RAD
_G0 = G0

#: dimension -> {unit: factor to SI}. The SI unit of each dimension is the
#: one with factor 1 listed first.
UNITS = {
    "angle": {"rad": 1.0, "mrad": 1e-3, "urad": 1e-6, "deg": _DEG,
              "arcmin": ARCMIN_TO_RAD, "'": ARCMIN_TO_RAD,
              "arcsec": ARCSEC_TO_RAD, '"': ARCSEC_TO_RAD},
    "angular_rate": {"rad/s": 1.0, "mrad/s": 1e-3, "deg/s": _DEG, "deg/min": _DEG / 60.0,
                     "deg/h": DPH_TO_RPS, "arcsec/s": ARCSEC_TO_RAD},
    "angular_acceleration": {"rad/s^2": 1.0, "deg/s^2": _DEG},
    # 1 deg/sqrt(h) = DEG / sqrt(3600 s) = DEG / 60 rad/sqrt(s) (as pyins.sim.sensors);
    # a rate density [rad/s/sqrt(Hz)] is numerically the same as rad/sqrt(s).
    "angle_random_walk": {"rad/sqrt(s)": 1.0, "deg/sqrt(h)": DPSH_TO_RPSS,
                          "rad/s/sqrt(Hz)": 1.0, "deg/h/sqrt(Hz)": DPH_TO_RPS},
    # a rate's random walk (a gyro bias's instability): 1 deg/h/sqrt(h) = DPH_TO_RPS / 60 rad/s/sqrt(s)
    "rate_random_walk": {"rad/s/sqrt(s)": 1.0, "deg/h/sqrt(h)": DPH_TO_RPS / 60.0},
    "acceleration": {"m/s^2": 1.0, "g": _G0, "mg": 1e-3 * _G0, "ug": UG_TO_MPS2},
    # 1 ug/sqrt(Hz) = UG_TO_MPS2 (m/s^2)/sqrt(Hz), numerically the same in (m/s)/sqrt(s).
    "velocity_random_walk": {"m/s/sqrt(s)": 1.0, "m/s/sqrt(h)": 1.0 / 60.0,
                             "m/s^2/sqrt(Hz)": 1.0, "ug/sqrt(Hz)": UG_TO_MPS2,
                             "mg/sqrt(Hz)": 1e-3 * _G0},
    "velocity": {"m/s": 1.0, "km/h": 1.0 / 3.6, "knot": NMI_TO_M / 3600.0,
                 "kn": NMI_TO_M / 3600.0},
    "length": {"m": 1.0, "mm": 1e-3, "cm": 1e-2, "km": 1e3, "nmi": NMI_TO_M},
    "time": {"s": 1.0, "ms": 1e-3, "min": 60.0, "h": 3600.0, "d": 86400.0},
    "frequency": {"Hz": 1.0, "mHz": 1e-3},
    "dimensionless": {"": 1.0, "ppm": 1e-6, "ppb": 1e-9, "%": 1e-2},
}

#: dimension -> how it reads in a message.
DIMENSION_NAMES = {
    "angle": "an angle", "angular_rate": "an angular rate",
    "angular_acceleration": "an angular acceleration",
    "angle_random_walk": "an angle random walk", "acceleration": "an acceleration",
    "rate_random_walk": "a rate random walk",
    "velocity_random_walk": "a velocity random walk", "velocity": "a velocity",
    "length": "a length", "time": "a time", "frequency": "a frequency",
    "dimensionless": "a dimensionless number",
}

_NUMBER = re.compile(r"^([+-]?(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?)(.*)$")


def _normalise(unit):
    u = "".join(unit.split())
    u = u.replace("µ", "u").replace("μ", "u").replace("°", "deg").replace("²", "^2")
    u = u.replace("**", "^").replace("√h", "sqrt(h)").replace("√s", "sqrt(s)")
    u = u.replace("√Hz", "sqrt(Hz)").replace("hz", "Hz")
    return u


def accepted_units(dimension, tick_hz=None):
    """The units accepted for ``dimension``, as a list of strings."""
    units = [u for u in UNITS[dimension] if u]
    if dimension == "time" and tick_hz:
        units.append("ticks")
    if dimension == "dimensionless":
        units.insert(0, "plain number")
    return units


def _unit_factor(unit, dimension, where, text, tick_hz):
    table = UNITS[dimension]
    if unit in table:
        return table[unit]
    if dimension == "time" and tick_hz and unit in ("tick", "ticks"):
        return 1.0 / tick_hz
    accepted = ", ".join(accepted_units(dimension, tick_hz))
    if unit == "":
        raise ScenarioError(f"missing unit in {text!r}: {DIMENSION_NAMES[dimension]} needs one "
                            f"of {accepted}", where)
    for other, units in UNITS.items():
        if unit in units and other != dimension:
            raise ScenarioError(f"wrong unit {unit!r} in {text!r}: it is a unit of "
                                f"{other.replace('_', ' ')}, "
                                f"but {DIMENSION_NAMES[dimension]} is wanted (units: {accepted})",
                                where)
    raise ScenarioError(f"unknown unit {unit!r} in {text!r} for {DIMENSION_NAMES[dimension]} "
                        f"(units: {accepted})", where)


def parse_quantity(value, dimension, *, where="", tick_hz=None):
    """The value of a quantity in SI units.

    Parameters
    ----------
    value : str or int or float
        ``"<number> <unit>"`` such as ``"0.003 deg/h"``, ``"-10 arcsec"``,
        ``"1e-3 deg/sqrt(h)"``; a plain number only for ``"dimensionless"``
        or an exact zero (see the module docstring).
    dimension : str
        A key of `UNITS`.
    where : str
        The key path named in errors.
    tick_hz : int or None
        Tick rate that ``"ticks"`` counts (times only).

    Returns
    -------
    float
        In rad, rad/s, rad/s^2, rad/sqrt(s), m/s^2, (m/s)/sqrt(s), m/s, m,
        s, Hz or plain.

    Raises
    ------
    ScenarioError
        No number, missing, wrong or unknown unit, not finite, not a string
        or number; the message names ``where`` and lists the accepted units.
    """
    if dimension not in UNITS:
        raise ValueError(f"unknown dimension {dimension!r}; choose one of {sorted(UNITS)}")
    if isinstance(value, bool) or not isinstance(value, (str, int, float)):
        raise ScenarioError(f"must be {DIMENSION_NAMES[dimension]} written as a string such as "
                            f"'{_example(dimension)}', got {type(value).__name__} {value!r}", where)
    if isinstance(value, (int, float)):
        number, unit, text = float(value), None, repr(value)
    else:
        text = value
        try:
            number, unit = split_quantity(value)
        except ValueError:
            raise ScenarioError(f"{value!r} does not start with a number (write e.g. "
                                f"'{_example(dimension)}')", where) from None
    if not math.isfinite(number):
        raise ScenarioError(f"{text} is not a finite number", where)
    if unit is None:       # a plain TOML number
        if dimension == "dimensionless" or number == 0.0:
            return number
        accepted = ", ".join(accepted_units(dimension, tick_hz))
        unit = _example(dimension).split(" ", 1)[1]
        raise ScenarioError(f"missing unit: {value!r} is a plain number but {DIMENSION_NAMES[dimension]} "
                            f"needs a unit, written as a string such as '{value} {unit}' "
                            f"(units: {accepted})", where)
    return number * _unit_factor(unit, dimension, where, text, tick_hz)


def split_quantity(text):
    """``"0.003 deg / h"`` -> ``(0.003, "deg/h")``: the number and the
    normalised unit ("" if none). ValueError if it does not start with a number."""
    m = _NUMBER.match(text.strip())
    if not m:
        raise ValueError(f"{text!r} does not start with a number")
    return float(m.group(1)), _normalise(m.group(2))


def _example(dimension):
    return {"angle": "10 arcsec", "angular_rate": "0.003 deg/h", "time": "72 h",
            "angle_random_walk": "0.0005 deg/sqrt(h)", "acceleration": "30 ug",
            "rate_random_walk": "0.0005 deg/h/sqrt(h)",
            "velocity_random_walk": "5 ug/sqrt(Hz)", "length": "10 m", "velocity": "0.01 m/s",
            "angular_acceleration": "30 deg/s^2", "frequency": "0.2 Hz",
            "dimensionless": "10 ppm"}[dimension]
