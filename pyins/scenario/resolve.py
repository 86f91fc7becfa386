"""Scenario files (TOML): what to simulate, how the firmware is set up, what to compare.

A scenario file names a ship motion (a fixed-position one may add heave,
surge and sway of the ship's reference point and lever arms to the IMU:
`pyins.sim.ShipAtSea`), sensor errors (a preset and/or values with units
such as ``"0.003 deg/h"``), the turntable and its indexing scheme, the
firmware configuration (alignment, ...), errors of the initial
state, the duration, the noise seed and the record interval; optionally a
``[compare]`` table that runs variants side by side, the ``[paper]``
figures it reproduces and which ``[outputs]`` to write. docs/scenarios.md
is the reference of every key.

Everything is validated when the file is loaded: an unknown key (with the
closest known key suggested), a wrong or missing unit, a value out of range
or of the wrong type, malformed TOML (with its line), an unknown preset,
scheme or motion kind all raise `ScenarioError`, whose message is one line
``FILE: key.path: reason``. When the compiled firmware is installed, its
own configuration check (``pyins_config_check``) runs too.

    >>> sc = load("seed002_exp1")            # a built-in, or a path to a .toml file
    >>> for run in sc.runs():                 # one RunSpec per [compare] value
    ...     result = run.run()                # pyins.fil.run_fil(...)  # doctest: +SKIP

The built-in scenarios are TOML files in ``pyins/scenarios/`` (shipped in
the wheel: scikit-build-core's ``wheel.packages = ["pyins"]`` copies every
file of the package directory that git does not ignore, as it does for the
headers CMake installs beside the library); `builtin_path` says where one
is, to copy and edit it.

The firmware runs at 100 Hz (`TICK_HZ`), the rate `pyins.fil.run_fil` uses;
every time that becomes a tick count (duration, record interval, alignment
and stop lengths...) must be a whole number of ticks.
"""
import copy
import difflib
import hashlib
import json
import math
import re
from dataclasses import dataclass
from pathlib import Path

try:
    import tomllib
except ImportError:            # Python 3.10: the same parser as a package
    import tomli as tomllib

import numpy as np

from pyins import sim
from pyins.reference import attitude, earth
from pyins.sim import motion as sim_motion
from pyins.sim import ship as sim_ship
from pyins.sim import turntable
from pyins.units import UNITS, ScenarioError, parse_quantity, split_quantity

__all__ = ["load", "loads", "list_builtin", "builtin_path", "Scenario", "RunSpec", "ScenarioError",
           "format_figure", "in_figure_unit",
           "TICK_HZ", "DT", "METRICS"]

SCHEMA_VERSION = 1
TICK_HZ = 100
DT = 1.0 / TICK_HZ
BUILTIN_DIR = Path(__file__).resolve().parent / "scenarios"


# ---------------------------------------------------------------------------
# The schema: every key of every table, with its kind, default and range.
# ---------------------------------------------------------------------------
@dataclass(frozen=True)
class Key:
    """One key of a scenario file.

    ``kind``: a `pyins.units` dimension ("angle", "time", ..., "dimensionless")
    or "int", "bool", "text", "choice", "list", "tables" (array of tables).
    ``default`` is written as in a file (``"0 m"``); None: not set (for the
    firmware: its own default). ``lo``/``hi`` are limits written with units;
    ``lo_open``/``hi_open`` exclude them. ``shape``: None (scalar), 3 (one
    value for all three axes or a list of three) or "matrix" (one value for
    all six off-diagonal terms or a 3x3 list with a zero diagonal).
    ``ticks``: a time that must be a whole number of ticks.
    """
    kind: str
    doc: str
    default: object = None
    required: bool = False
    lo: object = None
    hi: object = None
    lo_open: bool = False
    hi_open: bool = False
    shape: object = None
    choices: tuple = ()
    ticks: bool = False


def _angle(doc, default=None, lo=None, hi=None, **kw):
    return Key("angle", doc, default, lo=lo, hi=hi, **kw)


def _time(doc, default=None, lo="0 s", hi="30 d", lo_open=False, **kw):
    return Key("time", doc, default, lo=lo, hi=hi, lo_open=lo_open, ticks=True, **kw)


TOP_KEYS = {
    "name": Key("text", "identifier of the scenario (letters, digits, _ . -); default: the file name"),
    "title": Key("text", "one-line title; default: the name"),
    "description": Key("text", "free text", default=""),
    "duration": _time("ship time simulated", required=True, lo="0 s", lo_open=True),
    "seed": Key("int", "seed of the sensor noise generator", default=0, lo=0),
    "record_every": _time("interval of the kept records", default="1 s", lo="0.01 s"),
}

TABLE_NAMES = ("motion", "sensors", "turntable", "indexing", "firmware", "initial_errors",
               "compare", "paper", "outputs")

_LAT_DEFAULT, _LON_DEFAULT = "34.246 deg", "108.910 deg"
MOTION_COMMON = {
    "kind": Key("choice", "motion profile", required=True,
                choices=("static", "swing", "sea_state", "heading_swing", "manoeuvre")),
    "lat": _angle("geodetic latitude", _LAT_DEFAULT, "-89.9 deg", "89.9 deg"),
    "lon": _angle("longitude", _LON_DEFAULT, "-360 deg", "360 deg"),
    "height": Key("length", "height above the WGS-84 ellipsoid", "0 m", lo="-10 km", hi="100 km"),
    "pitch": _angle("pitch (swing: mean pitch)", "0 deg", "-89.9 deg", "89.9 deg"),
    "roll": _angle("roll (swing: mean roll)", "0 deg", "-180 deg", "180 deg"),
    "yaw": _angle("yaw, counter-clockwise from North (swing: mean; heading swing, "
                  "manoeuvre: initial)", "0 deg", "-360 deg", "360 deg"),
    "heading": _angle("marine heading, clockwise from North: yaw = -heading (give yaw or "
                      "heading)", None, "-360 deg", "360 deg"),
}
MOTION_KINDS = {
    "static": {},
    "swing": {
        "amplitude": _angle("amplitudes of [pitch, roll, yaw]", required=True, lo="0 deg",
                            hi="90 deg", shape=3),
        "frequency": Key("frequency", "frequencies of [pitch, roll, yaw]", required=True,
                         lo="0 Hz", hi="10 Hz", shape=3),
        "phase": _angle("phases of [pitch, roll, yaw]", "0 deg", "-360 deg", "360 deg", shape=3),
    },
    "sea_state": {
        "sea_state": Key("choice", "sea state of seed 000 Table 2", required=True,
                         choices=tuple(sim.SEA_STATES)),
        "phase": _angle("phases of [pitch, roll, yaw]", "0 deg", "-360 deg", "360 deg", shape=3),
    },
    "heading_swing": {
        "experiment": Key("int", "seed 002 experiment 1 (T = 120 s) or 2 (T = 60 s): sets the "
                                 "defaults of every other motion key", lo=1, hi=2),
        "rate_amplitude": Key("angular_rate", "amplitude A of the yaw rate A cos(2 pi t / T)",
                              lo="0 deg/s", hi="100 deg/s", lo_open=True),
        "period": Key("time", "period T", lo="0 s", hi="1 d", lo_open=True),
    },
    "manoeuvre": {
        "speed": Key("velocity", "initial speed", "0 m/s", lo="0 m/s", hi="100 m/s"),
        "segments": Key("tables", "'default' (the 30-min manoeuvre) or legs "
                                  "{kind, duration, speed | angle}", "default"),
    },
}
SEGMENT_KEYS = {
    "kind": Key("choice", "leg", required=True, choices=("accelerate", "decelerate", "cruise", "turn")),
    "duration": _time("length of the leg", required=True, lo="0 s", lo_open=True),
    "speed": Key("velocity", "target speed (accelerate, decelerate)", lo="0 m/s", hi="100 m/s"),
    "angle": _angle("yaw change, counter-clockwise (turn)", None, "-3600 deg", "3600 deg"),
}

#: Keys of the fixed-position kinds (static, swing, sea_state, heading_swing)
#: that make the ship a `pyins.sim.ShipAtSea`: heave, surge and sway of the
#: motion reference point (sinusoids or a wave spectrum) and the lever arms.
#: Any of them present: a ShipAtSea; none: the base profile itself.
SHIP_KEYS = {
    "heave": Key("tables", "heave (up) of the motion reference point: sinusoids "
                           "{amplitude, period, phase}"),
    "surge": Key("tables", "surge (along the mean bow) of the reference point: sinusoids"),
    "sway": Key("tables", "sway (along the mean starboard) of the reference point: sinusoids"),
    "spectrum": Key("table", "heave, surge and sway drawn from a wave spectrum: {name} or "
                             "{hs, tp, kind, gamma, seed, components} (instead of heave/surge/sway)"),
    "lever_b": Key("length", "motion reference point -> turntable centre in the ship frame b "
                             "[x starboard, y bow, z up]; length <= 100 m", lo="-100 m", hi="100 m",
                   shape=3),
    "lever_p": Key("length", "turntable centre -> accelerometer triad in the IMU frame p (turns "
                             "with the table); length <= 100 m", lo="-100 m", hi="100 m", shape=3),
}
#: Keys of one sinusoid of heave, surge or sway: a sin(2 pi t / T + phase).
COMPONENT_KEYS = {
    "amplitude": Key("length", "amplitude a", required=True, lo="-100 m", hi="100 m"),
    "period": Key("time", "period T (not only whole ticks)", required=True, lo="0 s", hi="1 d",
                  lo_open=True),
    "phase": _angle("phase at t = 0", "0 deg", "-360 deg", "360 deg"),
}
#: Keys of [motion] spectrum (pyins.sim.sea_spectrum_motion).
SPECTRUM_KEYS = {
    "name": Key("choice", "a preset sea of pyins.sim.SEA_STATE_SPECTRA: sets the defaults of hs, "
                          "tp and gamma", choices=tuple(sim.SEA_STATE_SPECTRA)),
    "hs": Key("length", "significant wave height (required without name)", lo="0 m", hi="30 m",
              lo_open=True),
    "tp": Key("time", "peak period (required without name)", lo="0 s", hi="60 s", lo_open=True),
    "kind": Key("choice", "JONSWAP or (modified) Pierson-Moskowitz", "jonswap",
                choices=("jonswap", "pm")),
    "gamma": Key("dimensionless", "JONSWAP peak enhancement (default 3.3, a preset's own; not "
                                  "used by pm)", lo=1, hi=7),
    "seed": Key("int", "seed of the components' random phases (not the noise seed)", default=0,
                lo=0),
    "components": Key("int", "sinusoids per axis", default=40, lo=1, hi=1000),
}
_FIXED_KINDS = ("static", "swing", "sea_state", "heading_swing")
_LINEAR_AXES = ("heave", "surge", "sway")
for _kind in _FIXED_KINDS:
    MOTION_KINDS[_kind].update(SHIP_KEYS)

SENSOR_KEYS = {
    "preset": Key("choice", "sensor error preset the values below override", "error_free",
                  choices=tuple(sim.PRESETS)),
    "gyro_bias": Key("angular_rate", "gyro drift", lo="-1 deg/s", hi="1 deg/s", shape=3),
    "gyro_scale": Key("dimensionless", "gyro scale-factor error", lo=-0.01, hi=0.01, shape=3),
    "gyro_misalignment": _angle("gyro installation errors", None, "-1 deg", "1 deg", shape="matrix"),
    "gyro_arw": Key("angle_random_walk", "gyro angle random walk", lo="0 deg/sqrt(h)",
                    hi="10 deg/sqrt(h)"),
    "gyro_quantum": _angle("gyro pulse size (0: none)", None, "0 rad", "1 deg"),
    "accel_bias": Key("acceleration", "accelerometer bias", lo="-1 g", hi="1 g", shape=3),
    "accel_scale": Key("dimensionless", "accelerometer scale-factor error", lo=-0.01, hi=0.01,
                       shape=3),
    "accel_misalignment": _angle("accelerometer installation errors", None, "-1 deg", "1 deg",
                                 shape="matrix"),
    "accel_vrw": Key("velocity_random_walk", "accelerometer velocity random walk",
                     lo="0 ug/sqrt(Hz)", hi="10 mg/sqrt(Hz)"),
    "accel_quantum": Key("velocity", "accelerometer pulse size (0: none)", lo="0 m/s", hi="1 m/s"),
}

_TABLE_FAULTS = {"none": turntable.TABLE_OK, "stall": turntable.TABLE_STALL,
                 "reverse": turntable.TABLE_REVERSE, "jump": turntable.TABLE_JUMP}
TURNTABLE_KEYS = {
    "rate_max": Key("angular_rate", "motor rate limit", lo="0 deg/s", hi="1000 deg/s", lo_open=True),
    "accel_max": Key("angular_acceleration", "motor acceleration limit", lo="0 deg/s^2",
                     hi="10000 deg/s^2", lo_open=True),
    "encoder_lsb": _angle("encoder resolution (0: exact)", None, "0 deg", "1 deg"),
    "initial_angle": _angle("table angle at the start (plant and firmware)", "0 deg", "-360 deg",
                            "360 deg"),
    "fault": Key("choice", "injected motor or encoder fault", "none", choices=tuple(_TABLE_FAULTS)),
    "fault_time": _time("when the fault starts", "0 s"),
    "jump": _angle("encoder jump of the 'jump' fault", "0 deg", "-360 deg", "360 deg"),
}

#: scheme name -> pyins_index_scheme; "seed003" is another name of single_position.
INDEX_SCHEMES = {"none": 0, "single_position": 1, "seed003": 1, "two_position": 2,
                 "four_position": 3, "flexible": 4, "custom": 5, "flexible_derived": 6}
_STEP_MOVES = {"fixed": 1, "flex_cos": 2, "flex_sin": 3}
#: sums name -> pyins_index_sums
INDEX_SUMS = {"stops": 0, "all": 1}
INDEXING_KEYS = {
    "scheme": Key("choice", "indexing scheme", "none", choices=tuple(INDEX_SCHEMES)),
    "sums": Key("choice", "ticks the flexible sums A_c, A_s add up: 'stops' (seed 002) or 'all' "
                "(turns too)", "stops", choices=tuple(INDEX_SUMS)),
    "stop": _time("stop length of the preset schemes (firmware default 60 s single_position, "
                  "300 s others)", None, lo="0.01 s", hi="1 d"),
    "rate": Key("angular_rate", "cruise rate (firmware default 6 deg/s)", lo="0 deg/s",
                hi="1000 deg/s", lo_open=True),
    "acceleration": Key("angular_acceleration", "acceleration (firmware default 30 deg/s^2)",
                        lo="0 deg/s^2", hi="10000 deg/s^2", lo_open=True),
    "delta": Key("dimensionless", "flexible stop threshold (firmware default 0.01)", lo=0, hi=1,
                 lo_open=True),
    "max_flex": _angle("longest flexible turn (firmware default 720 deg)", None, "0 deg", "3600 deg",
                       lo_open=True),
    "tolerance": _angle("encoder vs command tolerance (firmware default 0.5 deg)", None, "0 deg",
                        "180 deg", lo_open=True),
    "timeout": _time("how long the encoder may lag the command (firmware default 2 s)", None,
                     lo="0.01 s", hi="1 h"),
    "jump": _angle("largest believable encoder change per tick (firmware default 5 deg)", None,
                   "0 deg", "360 deg", lo_open=True),
    "steps": Key("tables", "custom scheme: 1 to 8 steps {stop, move, angle}"),
}
STEP_KEYS = {
    "stop": _time("stop before the move", required=True, lo="0.01 s", hi="1 d"),
    "move": Key("choice", "move kind", required=True, choices=tuple(_STEP_MOVES)),
    "angle": _angle("fixed: the turn (signed, counter-clockwise +); flex_*: its sense", None,
                    "-3600 deg", "3600 deg", required=True),
}

_VERTICAL_MODES = {"hold": 0, "free": 1}
_FINE_CORRECTIONS = {"feedback": 0, "open_loop": 1}
#: coarse_method name -> pyins_coarse_method
_COARSE_METHODS = {"triad": 0, "fit": 1}
FIRMWARE_KEYS = {
    "initial_attitude": Key("choice", "attitude the firmware starts from: the true one (plus "
                                      "[initial_errors]) or all Euler angles zero", "truth",
                            choices=("truth", "zero")),
    "vertical_mode": Key("choice", "vertical channel (firmware default hold)",
                         choices=tuple(_VERTICAL_MODES)),
    "coarse_time": _time("coarse alignment length (0: none)", None),
    "coarse_ratio": Key("dimensionless", "coarse alignment ratio r = t_k1 / t_k2 (firmware "
                                         "default 0.5)", lo=0, hi=1, lo_open=True, hi_open=True),
    "coarse_first_output": _time("first coarse solution (firmware default 20 s)", None,
                                 lo="0.01 s"),
    "coarse_output_every": _time("coarse solution interval (firmware default 1 s)", None,
                                 lo="0.01 s"),
    "coarse_method": Key("choice", "coarse alignment: 'triad' (seed 000, a base that does not move) "
                                   "or 'fit' (moving base: heave, surge, sway; firmware default "
                                   "triad)", choices=tuple(_COARSE_METHODS)),
    "lever": Key("choice", "lever arms the firmware is told: 'configured' (the simulated "
                           "motion.lever_b and lever_p) or 'unknown' (zero)", "configured",
                 choices=("configured", "unknown")),
    "fine_time": _time("fine alignment length (0: none)", None),
    "fine_states": Key("int", "fine-alignment filter states, 5 or 8 (firmware default 5)", lo=5, hi=8,
                       choices=(5, 8)),
    "fine_meas_every": _time("fine-alignment measurement interval (firmware default 0.1 s)", None,
                             lo="0.01 s", hi="1 h"),
    "fine_correction": Key("choice", "fine alignment feedback or open loop (firmware default "
                                     "feedback)", choices=tuple(_FINE_CORRECTIONS)),
    "fine_gyro_arw": Key("angle_random_walk", "filter Q: gyro ARW (firmware default "
                                              "0.001 deg/sqrt(h))", lo="0 deg/sqrt(h)",
                         hi="10 deg/sqrt(h)", lo_open=True),
    "fine_accel_vrw": Key("velocity_random_walk", "filter R: accelerometer VRW (firmware default "
                                                  "10 ug/sqrt(Hz))", lo="0 ug/sqrt(Hz)",
                          hi="10 mg/sqrt(Hz)", lo_open=True),
    "fine_sigma0_att": _angle("initial sigma of phi E, N, U (firmware default 100', 100', 600')",
                              None, "0 deg", "180 deg", lo_open=True, shape=3),
    "fine_sigma0_gyro": Key("angular_rate", "initial sigma of the drifts (firmware default "
                                            "0.01 deg/h)", lo="0 deg/h", hi="1 deg/s",
                            lo_open=True),
    "fine_sigma0_accel": Key("acceleration", "initial sigma of the biases (firmware default "
                                             "100 ug)", lo="0 ug", hi="1 g", lo_open=True),
}

INITIAL_ERROR_KEYS = {
    "pitch": _angle("pitch error", None, "-10 deg", "10 deg"),
    "roll": _angle("roll error", None, "-10 deg", "10 deg"),
    "yaw": _angle("yaw error (counter-clockwise)", None, "-180 deg", "180 deg"),
    "heading": _angle("heading error (clockwise): yaw error = -heading error", None,
                      "-180 deg", "180 deg"),
    "phi": _angle("attitude error in n [E, N, U]: C(firmware) = (I - phi x) C(true) "
                  "(instead of pitch/roll/yaw)", None, "-10 deg", "10 deg", shape=3),
    "velocity": Key("velocity", "velocity error [E, N, U]", lo="-100 m/s", hi="100 m/s", shape=3),
    "north": Key("length", "north position error", lo="-100 km", hi="100 km"),
    "east": Key("length", "east position error", lo="-100 km", hi="100 km"),
    "height": Key("length", "height error", lo="-10 km", hi="10 km"),
}

COMPARE_KEYS = {
    "key": Key("text", "the key varied, as a dotted path (e.g. 'indexing.scheme')", required=True),
    "values": Key("list", "its values, one run each, written as in the file", required=True),
    "labels": Key("list", "a label per value; default 'key = value'"),
}

#: metric -> (dimension, meaning). Figures of [paper] name one of these.
METRICS = {
    "horizontal_error_final": ("length", "horizontal position error at the end of the run"),
    "horizontal_error_max": ("length", "largest horizontal position error over the run"),
    "level_error_final": ("angle", "larger of |phi_E|, |phi_N| at the end of the run"),
    "level_error_max": ("angle", "largest |phi_E|, |phi_N| over the run"),
    "heading_error_final": ("angle", "|phi_U| at the end of the run"),
    "heading_error_max": ("angle", "largest |phi_U| over the run"),
    "velocity_error_max": ("velocity", "largest horizontal velocity error component over the run"),
    "level_error_std": ("angle", "std of the final pitch and roll errors over the runs of a "
                                 "campaign (seeds, headings)"),
    "heading_error_std": ("angle", "std of the final heading error over the runs of a campaign"),
    "level_error_vs_limit_final": ("angle", "larger of |phi_E - limit|, |phi_N - limit| at the end "
                                            "(alignment: against the theoretical limit, which any "
                                            "alignment shares)"),
    "heading_error_vs_limit_final": ("angle", "|phi_U - limit| at the end (alignment)"),
    "att_east_gap_final": ("angle", "|phi_E error - theoretical limit| at the end (alignment)"),
    "att_up_gap_final": ("angle", "|phi_U error - theoretical limit| at the end (alignment)"),
    "drift_north_gap_final": ("angular_rate", "|eps_N estimate error - limit| at the end "
                                              "(fine alignment)"),
}
PAPER_KEYS = {
    "citation": Key("text", "the paper, figure or table the figures come from", default=""),
    "note": Key("text", "free text: how to read the figures", default=""),
    "figures": Key("tables", "reference figures {metric, value, relation, variant, note}"),
}
FIGURE_KEYS = {
    "metric": Key("choice", "what the figure measures", required=True, choices=tuple(METRICS)),
    "value": Key("quantity", "the paper's number with its unit (dimension of the metric)",
                 required=True),
    "relation": Key("choice", "'=' a value, '<' or '<=' a bound, '~' approximate", "=",
                    choices=("=", "~", "<", "<=", ">", ">=")),
    "variant": Key("text", "label of the [compare] run it belongs to (default: every run)"),
    "note": Key("text", "free text", default=""),
}
OUTPUT_KEYS = {
    "plots": Key("bool", "write plots", default=True),
    "csv": Key("bool", "write CSV tables of the records", default=True),
    "records": Key("bool", "keep the raw decimated records (outputs.bin, plant.bin)", default=False),
}

#: table name -> its keys (motion: the common keys; kinds add theirs).
TABLES = {"motion": MOTION_COMMON, "sensors": SENSOR_KEYS, "turntable": TURNTABLE_KEYS,
          "indexing": INDEXING_KEYS, "firmware": FIRMWARE_KEYS, "initial_errors": INITIAL_ERROR_KEYS,
          "compare": COMPARE_KEYS, "paper": PAPER_KEYS, "outputs": OUTPUT_KEYS}

_SUFFIX = {"angle": "_rad", "angular_rate": "_rad_s", "angular_acceleration": "_rad_s2",
           "angle_random_walk": "_rad_sqrt_s", "acceleration": "_mps2",
           "velocity_random_walk": "_mps_sqrt_s", "velocity": "_mps", "length": "_m", "time": "_s",
           "frequency": "_hz", "dimensionless": ""}


# ---------------------------------------------------------------------------
# Reading values
# ---------------------------------------------------------------------------
def _join(path, name):
    return f"{path}.{name}" if path else name


#: Words people write for a key -> the key.
_SYNONYMS = {"latitude": "lat", "longitude": "lon", "altitude": "height", "alt": "height",
             "elevation": "height", "time": "duration", "length": "duration",
             "every": "record_every", "noise_seed": "seed"}


def _suggest(name, allowed):
    if _SYNONYMS.get(name) in allowed:
        return _SYNONYMS[name]
    close = difflib.get_close_matches(name, list(allowed), n=1, cutoff=0.5)
    return close[0] if close else None


def _check_keys(table, path, allowed, what=""):
    for name in table:
        if name not in allowed:
            close = _suggest(name, allowed)
            hint = (f"did you mean {close!r}?" if close
                    else f"known keys{what}: {', '.join(allowed)}")
            raise ScenarioError(f"unknown key; {hint}", _join(path, name))


def _need_table(value, where):
    if not isinstance(value, dict):
        raise ScenarioError(f"must be a table ([{where}] or {{ ... }}), got "
                            f"{_type_name(value)} {value!r}", where)
    return value


def _type_name(value):
    return {bool: "boolean", int: "integer", float: "float", str: "string", list: "array",
            dict: "table"}.get(type(value), type(value).__name__)


def _limit(limit, dimension):
    return parse_quantity(limit, dimension) if isinstance(limit, str) else float(limit)


def _range_text(key):
    parts = []
    if key.lo is not None:
        parts.append(f"{'>' if key.lo_open else '>='} {key.lo}")
    if key.hi is not None:
        parts.append(f"{'<' if key.hi_open else '<='} {key.hi}")
    return " and ".join(parts)


def _check_range(value, key, where, raw):
    dim = key.kind if key.kind != "int" else "dimensionless"
    bad = False
    if key.lo is not None:
        lo = _limit(key.lo, dim)
        bad |= value <= lo if key.lo_open else value < lo
    if key.hi is not None:
        hi = _limit(key.hi, dim)
        bad |= value >= hi if key.hi_open else value > hi
    if bad:
        raise ScenarioError(f"out of range: {raw!r} must be {_range_text(key)}", where)


def _whole_ticks(seconds, where, raw):
    ticks = seconds * TICK_HZ
    n = round(ticks)
    if abs(ticks - n) > 1e-9 * max(1.0, abs(ticks)):
        raise ScenarioError(f"{raw!r} is not a whole number of {DT:g} s ticks", where)
    return n


def _scalar(raw, key, where):
    value = parse_quantity(raw, key.kind, where=where, tick_hz=TICK_HZ)
    _check_range(value, key, where, raw)
    if key.ticks:
        value = _whole_ticks(value, where, raw) / TICK_HZ
    return value


def _convert(raw, key, where):
    """A raw TOML value checked against ``key``; quantities in SI."""
    kind = key.kind
    if kind == "text":
        if not isinstance(raw, str):
            raise ScenarioError(f"must be a string, got {_type_name(raw)} {raw!r}", where)
        return raw
    if kind == "bool":
        if not isinstance(raw, bool):
            raise ScenarioError(f"must be true or false, got {_type_name(raw)} {raw!r}", where)
        return raw
    if kind == "int":
        if isinstance(raw, bool) or not isinstance(raw, int):
            raise ScenarioError(f"must be an integer, got {_type_name(raw)} {raw!r}", where)
        if key.choices and raw not in key.choices:
            raise ScenarioError(f"must be one of {', '.join(map(str, key.choices))}, got {raw}", where)
        _check_range(raw, key, where, raw)
        return raw
    if kind == "choice":
        if not isinstance(raw, str):
            raise ScenarioError(f"must be one of {', '.join(map(repr, key.choices))}, got "
                                f"{_type_name(raw)} {raw!r}", where)
        if raw not in key.choices:
            close = difflib.get_close_matches(raw, key.choices, n=1, cutoff=0.6)
            hint = f"; did you mean {close[0]!r}?" if close else ""
            raise ScenarioError(f"unknown value {raw!r}{hint} (choose one of "
                                f"{', '.join(key.choices)})", where)
        return raw
    if kind == "list":
        if not isinstance(raw, list) or not raw:
            raise ScenarioError(f"must be a non-empty array, got {_type_name(raw)} {raw!r}", where)
        return raw
    if key.shape is None:
        return _scalar(raw, key, where)
    if key.shape == 3:
        if isinstance(raw, list):
            if len(raw) != 3:
                raise ScenarioError(f"must be one value for all three axes or a list of 3, got "
                                    f"{len(raw)} values", where)
            return [_scalar(v, key, f"{where}[{i}]") for i, v in enumerate(raw)]
        return [_scalar(raw, key, where)] * 3
    # a 3x3 matrix with a zero diagonal
    if not isinstance(raw, list):
        v = _scalar(raw, key, where)
        return [[0.0 if i == j else v for j in range(3)] for i in range(3)]
    if len(raw) != 3 or not all(isinstance(row, list) and len(row) == 3 for row in raw):
        raise ScenarioError("must be one value for all six off-diagonal terms or a 3x3 array "
                            "[[..., ..., ...], [...], [...]]", where)
    m = [[_scalar(v, key, f"{where}[{i}][{j}]") for j, v in enumerate(row)] for i, row in enumerate(raw)]
    for i in range(3):
        if m[i][i] != 0.0:
            raise ScenarioError(f"the diagonal [{i}][{i}] must be 0 (scale-factor errors go in "
                                f"*_scale)", where)
    return m


def _read(table, path, keys, what=""):
    """Every key of ``keys`` from ``table``: {name: SI value or None}."""
    _check_keys(table, path, keys, what)
    out = {}
    for name, key in keys.items():
        where = _join(path, name)
        if name in table:
            raw = table[name]
        elif key.required:
            raise ScenarioError(f"missing (required: {key.doc})", where)
        else:
            raw = key.default
        if raw is None or key.kind in ("tables", "table", "quantity"):
            out[name] = raw
        else:
            out[name] = _convert(raw, key, where)
    return out


def _si(values, keys):
    """{name: value} -> {name + SI-unit suffix: value} (the resolved form)."""
    return {name + _SUFFIX.get(keys[name].kind, ""): v for name, v in values.items()}


def _array_of_tables(raw, where, lo, hi):
    if not isinstance(raw, list) or not all(isinstance(t, dict) for t in raw):
        raise ScenarioError(f"must be an array of tables ([[{where}]] or [{{...}}, ...]), got "
                            f"{_type_name(raw)}", where)
    if not lo <= len(raw) <= hi:
        raise ScenarioError(f"must have {lo} to {hi} entries, got {len(raw)}", where)
    return raw


# ---------------------------------------------------------------------------
# Resolving a whole file (one variant) into plain SI values
# ---------------------------------------------------------------------------
def _resolve_motion(table, duration_s):
    path = "motion"
    _need_table(table, path)
    if "kind" not in table:
        raise ScenarioError("missing (required: motion profile, one of "
                            f"{', '.join(MOTION_COMMON['kind'].choices)})", "motion.kind")
    kind = _convert(table["kind"], MOTION_COMMON["kind"], "motion.kind")
    if kind not in _FIXED_KINDS:
        for name in SHIP_KEYS:
            if name in table:
                raise ScenarioError(f"not used with kind {kind!r}: heave, surge, sway, spectrum and "
                                    f"lever arms need a fixed-position kind ({', '.join(_FIXED_KINDS)})",
                                    f"motion.{name}")
    keys = dict(MOTION_COMMON)
    keys.update(MOTION_KINDS[kind])
    if kind == "heading_swing":
        exp = table.get("experiment")
        if exp is not None:
            exp = _convert(exp, keys["experiment"], "motion.experiment")
            a_deg, period = sim_motion.SEED002_EXPERIMENTS[exp]
            defaults = {"lat": sim_motion.SEED002_LAT, "lon": sim_motion.SEED002_LON,
                        "height": sim_motion.SEED002_HEIGHT, "pitch": sim_motion.SEED002_PITCH,
                        "roll": sim_motion.SEED002_ROLL, "rate_amplitude": a_deg * earth.DEG_TO_RAD,
                        "period": period}
            if "heading" not in table:
                defaults["yaw"] = sim_motion.SEED002_YAW
        else:
            defaults = {}
            for name in ("rate_amplitude", "period"):
                if name not in table:
                    raise ScenarioError(f"missing (required unless 'experiment' is given: "
                                        f"{keys[name].doc})", f"motion.{name}")
    v = _read(table, path, keys, f" of motion kind {kind!r}")
    if kind == "heading_swing":
        for name, value in defaults.items():       # SI already: exactly the seed 002 constants
            if name not in table:
                v[name] = value
    if "heading" in table:
        if "yaw" in table:
            raise ScenarioError("give either yaw or heading, not both", "motion.heading")
        v["yaw"] = -v["heading"]
    del v["heading"]
    ship = {name: v.pop(name) for name in SHIP_KEYS if name in keys}
    ship = {name: value for name, value in ship.items() if name in table}
    res = _si(v, keys)
    res.update(_resolve_ship(table, ship))
    if any(res.get("lever_p_m", ())):
        try:        # what pyins.fil.run_fil will ask of the motion
            sim.node_rates(_build_motion(res), np.arange(1), dt=DT)
        except ValueError as exc:
            raise ScenarioError(str(exc), "motion.lever_p") from None
    if kind == "manoeuvre":
        res["segments"] = _resolve_segments(v["segments"])
        length = _build_motion(res).duration
        if length + 1e-9 < duration_s:
            raise ScenarioError(f"the manoeuvre lasts {length:g} s, shorter than the duration "
                                f"{duration_s:g} s", "motion.segments")
    return res


def _resolve_components(raw, where):
    """heave/surge/sway: an array of {amplitude, period, phase} (or one table)."""
    if isinstance(raw, dict):
        tables, names = [raw], [where]
    else:
        tables = _array_of_tables(raw, where, 0, 1000)
        names = [f"{where}[{i}]" for i in range(len(tables))]
    return [_si(_read(t, p, COMPONENT_KEYS), COMPONENT_KEYS) for t, p in zip(tables, names)]


def _resolve_spectrum(raw):
    where = "motion.spectrum"
    _need_table(raw, where)
    v = _read(raw, where, SPECTRUM_KEYS)
    if v["name"] is not None:
        preset = sim.SEA_STATE_SPECTRA[v["name"]]
        for name in ("hs", "tp", "gamma"):
            if v[name] is None:
                v[name] = float(preset[name])
    else:
        for name in ("hs", "tp"):
            if v[name] is None:
                raise ScenarioError(f"missing (required unless 'name' is given: "
                                    f"{SPECTRUM_KEYS[name].doc.split(' (')[0]})", f"{where}.{name}")
    if v["kind"] == "pm":
        if "gamma" in raw:
            raise ScenarioError("not used with kind = 'pm' (the Pierson-Moskowitz spectrum has no "
                                "peak enhancement)", f"{where}.gamma")
        v["gamma"] = None
    elif v["gamma"] is None:
        v["gamma"] = 3.3
    res = _si(v, SPECTRUM_KEYS)
    try:
        _spectrum_motion(res)
    except ValueError as exc:
        raise ScenarioError(str(exc), where) from None
    return res


def _spectrum_motion(sp):
    return sim.sea_spectrum_motion(sp["hs_m"], sp["tp_s"], spectrum=sp["kind"],
                                   gamma=sp["gamma"] if sp["gamma"] is not None else 1.0,
                                   seed=sp["seed"], n_components=sp["components"])


def _resolve_ship(table, ship):
    """The resolved ship keys (only those the file gives: a file without them
    resolves, and digests, exactly as before they existed)."""
    out = {}
    for name in _LINEAR_AXES:
        if name in ship:
            out[name] = _resolve_components(ship[name], f"motion.{name}")
    if "spectrum" in ship:
        given = [name for name in _LINEAR_AXES if name in ship]
        if given:
            raise ScenarioError(f"give either a spectrum or heave/surge/sway sinusoids, not both "
                                f"(the file gives {', '.join(given)} too)", "motion.spectrum")
        out["spectrum"] = _resolve_spectrum(ship["spectrum"])
    for name in ("lever_b", "lever_p"):
        if name in ship:
            where = f"motion.{name}"
            if not isinstance(table[name], list):
                raise ScenarioError(f"must be a list of 3 lengths [x starboard, y bow, z up], got "
                                    f"{_type_name(table[name])} {table[name]!r}", where)
            r = [float(x) for x in ship[name]]
            length = math.sqrt(r[0] * r[0] + r[1] * r[1] + r[2] * r[2])
            if length > sim_ship.MAX_METRES:
                raise ScenarioError(f"out of range: the lever arm is {length:g} m long; it must be "
                                    f"<= {sim_ship.MAX_METRES:g} m", where)
            out[name + "_m"] = r
    return out


def _resolve_segments(raw):
    where = "motion.segments"
    if raw == "default":
        return "default"
    if isinstance(raw, str):
        raise ScenarioError(f"must be 'default' or an array of legs, got {raw!r}", where)
    legs = []
    for i, leg in enumerate(_array_of_tables(raw, where, 1, 10_000)):
        p = f"{where}[{i}]"
        v = _read(leg, p, SEGMENT_KEYS)
        if v["kind"] in ("accelerate", "decelerate"):
            if v["speed"] is None:
                raise ScenarioError(f"missing (required for {v['kind']!r}: target speed)", f"{p}.speed")
            if v["angle"] is not None:
                raise ScenarioError(f"not used by an {v['kind']!r} leg", f"{p}.angle")
            value = v["speed"]
        elif v["kind"] == "turn":
            if v["angle"] is None:
                raise ScenarioError("missing (required for 'turn': yaw change)", f"{p}.angle")
            if v["speed"] is not None:
                raise ScenarioError("not used by a 'turn' leg", f"{p}.speed")
            value = v["angle"]
        else:
            for name in ("speed", "angle"):
                if v[name] is not None:
                    raise ScenarioError("not used by a 'cruise' leg", f"{p}.{name}")
            value = 0.0
        legs.append({"kind": v["kind"], "duration_s": v["duration"], "value": value})
    return legs


_SHIP_RESOLVED = ("heave", "surge", "sway", "spectrum", "lever_b_m", "lever_p_m")


def _is_ship(m):
    """True when a resolved [motion] has any ship key (a pyins.sim.ShipAtSea)."""
    return any(k in m for k in _SHIP_RESOLVED)


def _build_motion(m):
    """A pyins.sim motion object from a resolved [motion] dict: the base
    profile, wrapped in a ShipAtSea when any ship key is given."""
    base = _build_base_motion(m)
    if not _is_ship(m):
        return base
    linear = None
    if "spectrum" in m:
        linear = _spectrum_motion(m["spectrum"])
    elif any(a in m for a in _LINEAR_AXES):
        linear = sim.LinearMotion(**{a: [(c["amplitude_m"], c["period_s"], c["phase_rad"])
                                         for c in m.get(a, [])] for a in _LINEAR_AXES})
    return sim.ShipAtSea(base, linear, lever_b=m.get("lever_b_m", (0.0, 0.0, 0.0)),
                         lever_p=m.get("lever_p_m", (0.0, 0.0, 0.0)))


def _build_base_motion(m):
    """The profile of a resolved [motion] dict without its ship keys."""
    kind = m["kind"]
    lat, lon, h = m["lat_rad"], m["lon_rad"], m["height_m"]
    if kind == "static":
        return sim.Static(lat, lon, h, m["pitch_rad"], m["roll_rad"], m["yaw_rad"])
    if kind == "swing":
        return sim.Swing(lat, lon, h, m["pitch_rad"], m["roll_rad"], m["yaw_rad"],
                         m["amplitude_rad"], m["frequency_hz"], m["phase_rad"])
    if kind == "sea_state":
        return sim.sea_state(m["sea_state"], lat, lon, h, m["yaw_rad"], m["pitch_rad"], m["roll_rad"],
                             m["phase_rad"])
    if kind == "heading_swing":
        return sim.HeadingSwing(lat, lon, h, m["pitch_rad"], m["roll_rad"], m["yaw_rad"],
                                m["rate_amplitude_rad_s"], m["period_s"])
    if m["segments"] == "default":
        segments = sim.default_segments(DT)
    else:
        segments = [sim.Segment(s["kind"], round(s["duration_s"] * TICK_HZ), s["value"])
                    for s in m["segments"]]
    try:
        return sim.Manoeuvre(lat, lon, h, m["yaw_rad"], segments, dt=DT, speed0=m["speed_mps"],
                             pitch=m["pitch_rad"], roll=m["roll_rad"])
    except ValueError as exc:
        raise ScenarioError(str(exc), "motion.segments") from None


def _initial_truth(m):
    """(lat, lon, height, vel_n, euler) of the resolved motion at t = 0."""
    if m["kind"] == "manoeuvre":   # closed form (Manoeuvre.state would integrate the whole track)
        yaw, speed = m["yaw_rad"], m["speed_mps"]
        return (m["lat_rad"], m["lon_rad"], m["height_m"],
                np.array([-speed * np.sin(yaw), speed * np.cos(yaw), 0.0]),
                np.array([m["pitch_rad"], m["roll_rad"], yaw]))
    motion = _build_motion(m)
    # a ShipAtSea: the reference point's state, which the firmware's configuration means
    # (pyins.runner.initial_config); every other profile: its own state
    state = motion.reference_state if isinstance(motion, sim.ShipAtSea) else motion.state
    st = state(np.array([0.0]))
    return float(st.lat[0]), float(st.lon[0]), float(st.height[0]), st.vel_n[0], st.euler[0]


def _resolve_sensors(table):
    _need_table(table, "sensors")
    v = _read(table, "sensors", SENSOR_KEYS)
    base = sim.preset(v["preset"])
    out = {"preset": v["preset"]}
    for name, key in SENSOR_KEYS.items():
        if name == "preset":
            continue
        value = v[name] if v[name] is not None else getattr(base, name)
        out[name + _SUFFIX[key.kind]] = np.asarray(value, dtype=float).tolist()
    return out


def _resolve_turntable(table, duration_s):
    _need_table(table, "turntable")
    v = _read(table, "turntable", TURNTABLE_KEYS)
    d = turntable.TableConfig()
    for name, field in (("rate_max", "rate_max_rad_s"), ("accel_max", "accel_max_rad_s2"),
                        ("encoder_lsb", "encoder_lsb_rad")):
        if v[name] is None:
            v[name] = getattr(d, field)
    if v["fault"] == "jump" and v["jump"] == 0.0:
        raise ScenarioError("the 'jump' fault needs a non-zero jump angle", "turntable.jump")
    return _si(v, TURNTABLE_KEYS)


def _resolve_indexing(table):
    _need_table(table, "indexing")
    v = _read(table, "indexing", INDEXING_KEYS)
    custom = v["scheme"] == "custom"
    if v["scheme"] == "seed003":
        v["scheme"] = "single_position"
    steps = None
    if v["steps"] is not None:
        if not custom:
            raise ScenarioError(f"steps are only used with scheme = 'custom' (the scheme is "
                                f"{v['scheme']!r})", "indexing.steps")
        steps = []
        for i, step in enumerate(_array_of_tables(v["steps"], "indexing.steps", 1, 8)):
            s = _read(step, f"indexing.steps[{i}]", STEP_KEYS)
            if s["angle"] == 0.0:
                raise ScenarioError("out of range: the angle of a step must not be zero",
                                    f"indexing.steps[{i}].angle")
            steps.append({"stop_s": s["stop"], "move": s["move"], "angle_rad": s["angle"]})
    if custom:
        if steps is None:
            raise ScenarioError("missing (required with scheme = 'custom': 1 to 8 steps)",
                                "indexing.steps")
        for name in ("rate", "acceleration"):
            if v[name] is None:
                raise ScenarioError("missing (required with scheme = 'custom')", f"indexing.{name}")
        if v["delta"] is None and any(s["move"] != "fixed" for s in steps):
            raise ScenarioError("missing (required with flexible steps)", "indexing.delta")
        if v["stop"] is not None:
            raise ScenarioError("not used with scheme = 'custom' (each step has its own stop)",
                                "indexing.stop")
    out = _si(v, INDEXING_KEYS)
    out["scheme_number"] = INDEX_SCHEMES[v["scheme"]]
    out["steps"] = steps
    return out


def _resolve_firmware(table, duration_s):
    _need_table(table, "firmware")
    v = _read(table, "firmware", FIRMWARE_KEYS)
    align = (v["coarse_time"] or 0.0) + (v["fine_time"] or 0.0)
    if align > duration_s + 1e-9:
        key = "firmware.fine_time" if v["fine_time"] else "firmware.coarse_time"
        raise ScenarioError(f"out of range: the alignment ({align:g} s) is longer than the duration "
                            f"({duration_s:g} s)", key)
    return _si(v, FIRMWARE_KEYS)


def _resolve_initial_errors(table, firmware):
    _need_table(table, "initial_errors")
    v = _read(table, "initial_errors", INITIAL_ERROR_KEYS)
    if v["heading"] is not None:
        if v["yaw"] is not None:
            raise ScenarioError("give either yaw or heading, not both", "initial_errors.heading")
        v["yaw"] = -v["heading"]
    del v["heading"]
    euler_keys = [k for k in ("pitch", "roll", "yaw") if v[k] is not None]
    if v["phi"] is not None and euler_keys:
        raise ScenarioError("give the attitude error either as phi or as pitch/roll/yaw, not both",
                            "initial_errors.phi")
    if firmware["initial_attitude"] == "zero" and (v["phi"] is not None or euler_keys):
        key = "initial_errors.phi" if v["phi"] is not None else f"initial_errors.{euler_keys[0]}"
        raise ScenarioError("an attitude error cannot be applied with firmware.initial_attitude = "
                            "'zero'", key)
    keys = dict(INITIAL_ERROR_KEYS)
    del keys["heading"]
    return _si(v, keys)


def _resolve_paper(table, labels):
    _need_table(table, "paper")
    v = _read(table, "paper", PAPER_KEYS)
    figures = []
    for i, fig in enumerate(_array_of_tables(v["figures"] or [], "paper.figures", 0, 1000)):
        p = f"paper.figures[{i}]"
        f = _read(fig, p, FIGURE_KEYS)
        dim = METRICS[f["metric"]][0]
        value_si = parse_quantity(f["value"], dim, where=f"{p}.value")
        number, unit = split_quantity(f["value"]) if isinstance(f["value"], str) else (0.0, "")
        if f["variant"] is not None and not labels:
            raise ScenarioError("a variant is only named with [compare]", f"{p}.variant")
        if f["variant"] is not None and f["variant"] not in labels:
            raise ScenarioError(f"unknown variant {f['variant']!r} (the runs are labelled "
                                f"{', '.join(map(repr, labels))})", f"{p}.variant")
        figures.append({"metric": f["metric"], "relation": f["relation"], "value": number,
                        "unit": unit, "value_si": value_si, "variant": f["variant"],
                        "note": f["note"]})
    return {"citation": v["citation"], "note": v["note"], "figures": figures}


def _resolve(data, stem):
    """The resolved form (a plain dict, SI) of one variant: everything but
    [compare] and [paper], which concern the scenario as a whole."""
    _check_keys(data, "", list(TOP_KEYS) + list(TABLE_NAMES))
    top = _read({k: v for k, v in data.items() if k in TOP_KEYS}, "", TOP_KEYS)
    name = top["name"] if top["name"] is not None else stem
    if not re.fullmatch(r"[A-Za-z0-9_.-]+", name):
        raise ScenarioError(f"{name!r} may hold only letters, digits, '_', '.' and '-'", "name")
    duration_s = top["duration"]
    if top["record_every"] > duration_s:
        raise ScenarioError(f"out of range: {top['record_every']:g} s is longer than the duration "
                            f"({duration_s:g} s)", "record_every")
    if "motion" not in data:
        raise ScenarioError("missing table [motion] (required: the ship's motion)", "motion")
    motion = _resolve_motion(data["motion"], duration_s)
    firmware = _resolve_firmware(data.get("firmware", {}), duration_s)
    # keys newer than schema 1's files are resolved only when they say
    # something, so that the older files keep their digests
    if firmware["coarse_method"] is None:
        del firmware["coarse_method"]
    if firmware["lever"] == "configured" and not _is_ship(motion):
        del firmware["lever"]
    res = {
        "schema": SCHEMA_VERSION,
        "name": name,
        "title": top["title"] if top["title"] is not None else name,
        "description": top["description"],
        "tick_s": DT,
        "duration_s": duration_s,
        "seed": top["seed"],
        "record_every_s": top["record_every"],
        "motion": motion,
        "sensors": _resolve_sensors(data.get("sensors", {})),
        "turntable": _resolve_turntable(data.get("turntable", {}), duration_s),
        "indexing": _resolve_indexing(data.get("indexing", {})),
        "firmware": firmware,
        "initial_errors": _resolve_initial_errors(data.get("initial_errors", {}), firmware),
        "outputs": _read(_need_table(data.get("outputs", {}), "outputs"), "outputs", OUTPUT_KEYS),
    }
    return res


# ---------------------------------------------------------------------------
# Firmware configuration, sensor errors and table of a resolved variant
# ---------------------------------------------------------------------------
def _ticks(seconds):
    return int(round(seconds * TICK_HZ))


def _firmware_config(res):
    """The overrides for ``fil.run_fil(config=...)``: only what the scenario
    sets (keys it leaves unset keep the firmware's defaults, and the initial
    state is the truth, filled in by ``runner.initial_config``)."""
    fw, ix, ie = res["firmware"], res["indexing"], res["initial_errors"]
    cfg = {"index_scheme": ix["scheme_number"]}
    if fw["vertical_mode"] is not None:
        cfg["vertical_mode"] = _VERTICAL_MODES[fw["vertical_mode"]]
    for name, c_name in (("coarse_time_s", "coarse_ticks"),
                         ("coarse_first_output_s", "coarse_first_output_ticks"),
                         ("coarse_output_every_s", "coarse_output_every_ticks"),
                         ("fine_time_s", "fine_ticks"), ("fine_meas_every_s", "fine_meas_every_ticks")):
        if fw[name] is not None:
            cfg[c_name] = _ticks(fw[name])
    for name, c_name in (("coarse_ratio", "coarse_ratio"), ("fine_states", "fine_states"),
                         ("fine_gyro_arw_rad_sqrt_s", "fine_gyro_arw"),
                         ("fine_accel_vrw_mps_sqrt_s", "fine_accel_vrw"),
                         ("fine_sigma0_att_rad", "fine_sigma0_att_rad"),
                         ("fine_sigma0_gyro_rad_s", "fine_sigma0_gyro"),
                         ("fine_sigma0_accel_mps2", "fine_sigma0_accel")):
        if fw[name] is not None:
            cfg[c_name] = fw[name]
    if fw["fine_correction"] is not None:
        cfg["fine_correction"] = _FINE_CORRECTIONS[fw["fine_correction"]]
    if fw.get("coarse_method") is not None:
        cfg["coarse_method"] = _COARSE_METHODS[fw["coarse_method"]]
    if fw.get("lever") == "unknown":
        # what an unknown lever arm costs: the firmware navigates the reference point as if
        # the accelerometers were there (runner.initial_config would give it the motion's)
        cfg["lever_b_m"] = [0.0, 0.0, 0.0]
        cfg["lever_p_m"] = [0.0, 0.0, 0.0]
    for name, c_name in (("stop_s", "index_stop_ticks"), ("timeout_s", "index_timeout_ticks")):
        if ix[name] is not None:
            cfg[c_name] = _ticks(ix[name])
    for name, c_name in (("rate_rad_s", "index_rate_rad_s"), ("acceleration_rad_s2", "index_accel_rad_s2"),
                         ("delta", "index_delta"), ("max_flex_rad", "index_max_flex_rad"),
                         ("tolerance_rad", "index_tolerance_rad"), ("jump_rad", "index_jump_rad")):
        if ix[name] is not None:
            cfg[c_name] = ix[name]
    if ix["sums"] != "stops":
        cfg["index_sums"] = INDEX_SUMS[ix["sums"]]
    if ix["steps"] is not None:
        cfg["index_n_steps"] = len(ix["steps"])
        cfg["index_steps"] = [(_ticks(s["stop_s"]), _STEP_MOVES[s["move"]], s["angle_rad"])
                              for s in ix["steps"]]
    if res["turntable"]["initial_angle_rad"] != 0.0:
        cfg["table_angle_rad"] = res["turntable"]["initial_angle_rad"]

    # the initial state: the truth plus the initial errors (as
    # tools/reproduce_seed002.py initial_errors does: position errors over
    # the radii of curvature at the ellipsoid)
    lat, lon, h, vel, euler = _initial_truth(res["motion"])
    if fw["initial_attitude"] == "zero":
        cfg["euler_b_rad"] = [0.0, 0.0, 0.0]
    elif ie["phi_rad"] is not None:
        phi = np.array(ie["phi_rad"])
        cfg["euler_b_rad"] = attitude.mat_to_euler(attitude.rotvec_to_mat(-phi)
                                                   @ attitude.euler_to_mat(euler))
    elif any(ie[k] is not None for k in ("pitch_rad", "roll_rad", "yaw_rad")):
        cfg["euler_b_rad"] = euler + np.array([ie["pitch_rad"] or 0.0, ie["roll_rad"] or 0.0,
                                               ie["yaw_rad"] or 0.0])
    if ie["velocity_mps"] is not None:
        cfg["vel_n_mps"] = vel + np.array(ie["velocity_mps"])
    rm, rn = earth.principal_radii(np.sin(lat))
    if ie["north_m"] is not None:
        cfg["lat_rad"] = lat + ie["north_m"] / rm
    if ie["east_m"] is not None:
        cfg["lon_rad"] = lon + ie["east_m"] / (rn * np.cos(lat))
    if ie["height_m"] is not None:
        cfg["height_m"] = h + ie["height_m"]
    return cfg


def _sensor_errors(s):
    return sim.SensorErrors(
        gyro_bias=np.array(s["gyro_bias_rad_s"]), gyro_scale=np.array(s["gyro_scale"]),
        gyro_misalignment=np.array(s["gyro_misalignment_rad"]), gyro_arw=s["gyro_arw_rad_sqrt_s"],
        gyro_quantum=s["gyro_quantum_rad"], accel_bias=np.array(s["accel_bias_mps2"]),
        accel_scale=np.array(s["accel_scale"]), accel_misalignment=np.array(s["accel_misalignment_rad"]),
        accel_vrw=s["accel_vrw_mps_sqrt_s"], accel_quantum=s["accel_quantum_mps"])


def _table_config(t):
    return turntable.TableConfig(rate_max_rad_s=t["rate_max_rad_s"], accel_max_rad_s2=t["accel_max_rad_s2"],
                                 encoder_lsb_rad=t["encoder_lsb_rad"], jump_rad=t["jump_rad"],
                                 fault_tick=_ticks(t["fault_time_s"]), fault=_TABLE_FAULTS[t["fault"]])


#: pyins_status name -> the scenario key it most likely concerns.
_STATUS_KEYS = {
    "PYINS_E_CONFIG_LAT": "motion.lat", "PYINS_E_CONFIG_LON": "motion.lon",
    "PYINS_E_CONFIG_HEIGHT": "motion.height", "PYINS_E_CONFIG_VEL": "initial_errors.velocity",
    "PYINS_E_CONFIG_ATT": "motion", "PYINS_E_CONFIG_MODE": "firmware.vertical_mode",
    "PYINS_E_CONFIG_ALIGN_RATIO": "firmware.coarse_ratio",
    "PYINS_E_CONFIG_ALIGN_EARLY": "firmware.coarse_first_output",
    "PYINS_E_CONFIG_ALIGN_LONG": "firmware.coarse_time",
    "PYINS_E_CONFIG_ALIGN_TICKS": "firmware.coarse_time", "PYINS_E_CONFIG_FINE": "firmware.fine_states",
    "PYINS_E_CONFIG_NOISE": "firmware", "PYINS_E_CONFIG_INDEX_SCHEME": "indexing.scheme",
    "PYINS_E_CONFIG_INDEX_EMPTY": "indexing.steps", "PYINS_E_CONFIG_INDEX_RATE": "indexing.rate",
    "PYINS_E_CONFIG_INDEX_DELTA": "indexing.delta", "PYINS_E_CONFIG_INDEX_STEP": "indexing",
    "PYINS_E_CONFIG_INDEX_SUMS": "indexing.sums", "PYINS_E_CONFIG_LEVER": "motion.lever_b",
    "PYINS_E_CONFIG_COARSE_METHOD": "firmware.coarse_method",
}


def _firmware_check(res, cfg):
    """The firmware's own check of the configuration (pyins_config_check),
    when the compiled core is installed; nothing otherwise."""
    try:
        from pyins import native
    except ImportError:
        return
    m = res["motion"]
    lat, lon, h, vel, euler = _initial_truth(m)
    full = dict(lat_rad=lat, lon_rad=lon, height_m=h, vel_n_mps=vel, euler_b_rad=euler,
                table_angle_rad=0.0)
    if _is_ship(m):     # the lever arms runner.initial_config hands over (cfg may zero them)
        full.update(lever_b_m=m.get("lever_b_m", [0.0] * 3), lever_p_m=m.get("lever_p_m", [0.0] * 3))
    full.update(cfg)
    status = native.lib.pyins_config_check(native.make_config(full))
    if status != 0:
        name = native.status_str(status).split(":")[0]
        raise ScenarioError(f"the firmware refuses the configuration: {native.status_str(status)}",
                            _STATUS_KEYS.get(name, "firmware"))


# ---------------------------------------------------------------------------
# Public API
# ---------------------------------------------------------------------------
@dataclass
class RunSpec:
    """One run of a scenario: everything ``pyins.fil.run_fil`` needs.

    ``run()`` calls ``fil.run_fil(motion, duration_ticks, config=config,
    errors=errors, seed=seed, table=table, every=every, dt=dt, **kwargs)``.
    """
    label: str                    #: the [compare] label (the scenario name without [compare])
    index: int                    #: position among the scenario's runs
    scenario: str                 #: the scenario's name
    motion: object                #: a pyins.sim motion profile (fresh object per RunSpec)
    errors: object                #: pyins.sim.SensorErrors
    config: dict                  #: firmware configuration overrides (fil.run_fil config=)
    table: object                 #: pyins.sim.turntable.TableConfig
    duration_ticks: int
    seed: int
    every: int                    #: record interval [ticks]
    dt: float = DT
    outputs: dict = None          #: the resolved [outputs] (plots, csv, records)

    def run(self, **kwargs):
        """Run it through the firmware in the loop; returns a fil.FilResult."""
        from pyins import fil
        return fil.run_fil(self.motion, self.duration_ticks, config=self.config, errors=self.errors,
                           seed=self.seed, table=self.table, every=self.every, dt=self.dt, **kwargs)


def _runspec(res, label, index):
    return RunSpec(label=label, index=index, scenario=res["name"], motion=_build_motion(res["motion"]),
                   errors=_sensor_errors(res["sensors"]), config=_firmware_config(res),
                   table=_table_config(res["turntable"]), duration_ticks=_ticks(res["duration_s"]),
                   seed=res["seed"], every=_ticks(res["record_every_s"]), dt=DT,
                   outputs=dict(res["outputs"]))


_ALTERNATIVES = {"motion.yaw": "motion.heading", "motion.heading": "motion.yaw",
                 "initial_errors.yaw": "initial_errors.heading",
                 "initial_errors.heading": "initial_errors.yaw"}
_NOT_COMPARABLE = ("name", "title", "description", "compare", "paper", "outputs")


def _set_key(data, path, value):
    """data with ``path`` ("seed", "motion.yaw") set to value (None: removed);
    the other spelling of the same quantity (yaw/heading) is removed."""
    parts = path.split(".")
    if len(parts) > 2 or not all(parts):
        raise ScenarioError("must be 'key' or 'table.key'", path)
    if len(parts) == 2:
        if parts[0] not in TABLES:
            close = difflib.get_close_matches(parts[0], TABLES, n=1)
            hint = f"; did you mean {close[0]!r}?" if close else f" (tables: {', '.join(TABLES)})"
            raise ScenarioError(f"unknown table {parts[0]!r}{hint}", path)
        table = data.setdefault(parts[0], {})
        if not isinstance(table, dict):
            raise ScenarioError("is not a table", parts[0])
    else:
        table = data
    if path in _ALTERNATIVES:
        table.pop(_ALTERNATIVES[path].split(".")[1], None)
    if value is None:
        table.pop(parts[-1], None)
    else:
        table[parts[-1]] = value


def _check_key_path(path, where):
    """``path`` ("seed", "indexing.scheme") names a key of the schema."""
    parts = path.split(".")
    if len(parts) == 1:
        allowed, name = TOP_KEYS, parts[0]
    elif len(parts) == 2 and parts[0] in TABLES:
        allowed, name = dict(TABLES[parts[0]]), parts[1]
        if parts[0] == "motion":
            for kind_keys in MOTION_KINDS.values():
                allowed.update(kind_keys)
    elif len(parts) == 2:
        close = _suggest(parts[0], TABLES)
        hint = f"; did you mean {close!r}?" if close else f" (tables: {', '.join(TABLES)})"
        raise ScenarioError(f"{path!r}: unknown table {parts[0]!r}{hint}", where)
    else:
        raise ScenarioError(f"{path!r} must be 'key' or 'table.key'", where)
    if name not in allowed:
        close = _suggest(name, allowed)
        hint = f"; did you mean {_join(parts[0] if len(parts) == 2 else '', close)!r}?" if close else ""
        raise ScenarioError(f"{path!r} is not a key{hint}", where)


def _canonical(value):
    return json.dumps(value, sort_keys=True, separators=(",", ":"), allow_nan=False)


class Scenario:
    """A loaded, validated scenario.

    ``text`` is the TOML text as read, ``data`` its parsed tables, ``source``
    the file it came from. `resolved` gives every value in SI, `runs` the
    runs, `with_overrides` a changed copy (validated again).
    """

    def __init__(self, text, data, source, stem):
        self.text = text
        self.data = data
        self.source = source
        self._stem = stem
        try:
            self._base = _resolve(data, stem)
            self._compare, self._variants = self._resolve_compare(data)
            labels = [label for label, _ in self._variants]
            self._paper = _resolve_paper(data.get("paper", {}), labels if self._compare else [])
            for label, res in self._variants:
                _firmware_check(res, _firmware_config(res))
        except ScenarioError as exc:
            raise exc.with_source(source) from None

    def _resolve_compare(self, data):
        if "compare" not in data:
            return None, [(self._base["name"], self._base)]
        c = _read(_need_table(data["compare"], "compare"), "compare", COMPARE_KEYS)
        key = c["key"]
        _check_key_path(key, "compare.key")
        if key.split(".")[0] in _NOT_COMPARABLE:
            raise ScenarioError(f"{key!r} cannot be compared (only the run's own keys: seed, "
                                f"duration, record_every, motion.*, sensors.*, ...)", "compare.key")
        labels = c["labels"]
        if labels is None:
            labels = [f"{key} = {v}" for v in c["values"]]
        elif len(labels) != len(c["values"]):
            raise ScenarioError(f"{len(labels)} labels for {len(c['values'])} values", "compare.labels")
        elif not all(isinstance(s, str) for s in labels):
            raise ScenarioError("must be strings", "compare.labels")
        if len(set(labels)) != len(labels):
            raise ScenarioError("labels must differ from each other", "compare.labels")
        variants = []
        for i, value in enumerate(c["values"]):
            d = copy.deepcopy(data)
            del d["compare"]
            d.pop("paper", None)
            try:
                _set_key(d, key, value)
                variants.append((labels[i], _resolve(d, self._stem)))
            except ScenarioError as exc:
                reason = f"{exc.key}: {exc.reason}" if exc.key else exc.reason
                if exc.key != key:
                    reason = f"with {key} = {value!r}: {reason}"
                raise ScenarioError(reason, f"compare.values[{i}]") from None
        return {"key": key, "values": c["values"], "labels": labels}, variants

    # -- properties --------------------------------------------------------
    @property
    def name(self):
        return self._base["name"]

    @property
    def title(self):
        return self._base["title"]

    @property
    def duration_s(self):
        return self._base["duration_s"]

    @property
    def seed(self):
        return self._base["seed"]

    @property
    def labels(self):
        """The labels of the runs, in order."""
        return [label for label, _ in self._variants]

    @property
    def paper(self):
        """The resolved [paper]: citation, note, figures (each with metric,
        value_si, shown, relation, variant, note)."""
        return copy.deepcopy(self._paper)

    @property
    def outputs(self):
        return dict(self._base["outputs"])

    def __repr__(self):
        return f"Scenario({self.name!r}, {len(self._variants)} run(s), source={self.source!r})"

    # -- the API -----------------------------------------------------------
    def resolved(self):
        """Every value of the scenario in SI, as a plain JSON-serialisable
        dict (keys carry their unit: ``lat_rad``, ``duration_s``; None = not
        set, the firmware's default). With [compare], ``compare`` holds the
        key, values and labels and ``variants`` the resolved form of each run."""
        out = copy.deepcopy(self._base)
        out["source"] = self.source
        out["paper"] = self.paper
        if self._compare is not None:
            out["compare"] = copy.deepcopy(self._compare)
            out["variants"] = [dict(label=label, **copy.deepcopy(res)) for label, res in self._variants]
        return out

    def resolved_json(self):
        """`resolved` as indented JSON text (for resolved_scenario.json)."""
        return json.dumps(self.resolved(), indent=2, allow_nan=False) + "\n"

    def digest(self):
        """SHA-256 (hex) of `resolved` in canonical JSON, without ``source``:
        the same scenario loaded from anywhere gives the same digest, any
        change of a value (title and [paper] included) changes it."""
        res = self.resolved()
        del res["source"]
        return hashlib.sha256(_canonical(res).encode()).hexdigest()

    def runs(self):
        """One `RunSpec` per [compare] value (one without [compare])."""
        for i, (label, res) in enumerate(self._variants):
            yield _runspec(res, label, i)

    def with_overrides(self, overrides):
        """A new validated Scenario with keys replaced.

        ``overrides``: {"seed": 3, "motion.yaw": "60 deg", "indexing.scheme":
        "flexible"}: dotted paths as in the file, values as a file writes
        them (quantities as strings with units); None removes a key (back to
        its default). Setting yaw removes heading and the other way round.
        ``text`` stays the original file's; ``source`` says "with overrides".
        """
        data = copy.deepcopy(self.data)
        where = f"{self.source} (with overrides)"
        for path, value in overrides.items():
            try:
                _set_key(data, path, value)
            except ScenarioError as exc:
                raise exc.with_source(where) from None
        return Scenario(self.text, data, where, self._stem)


def loads(text, source="<string>", name=None):
    """A Scenario from TOML text. ``name``: the default of the ``name`` key
    (``load`` passes the file name without .toml)."""
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise ScenarioError(f"malformed TOML: {exc}", "", source) from None
    return Scenario(text, data, source, name or "scenario")


def find_builtin(directory, name, what, names):
    """``directory/name.toml``, or a ScenarioError naming the built-ins
    (``what``: "scenario", "campaign")."""
    path = Path(directory) / f"{name}.toml"
    if not path.is_file():
        close = difflib.get_close_matches(name, names, n=1)
        hint = f"; did you mean {close[0]!r}?" if close else ""
        raise ScenarioError(f"no such file or built-in {what}{hint} (built-ins: {', '.join(names)})",
                            "", name)
    return path


def read_toml_source(path_or_name, builtin):
    """(text, path) of a .toml file, or of the built-in ``builtin(name)``
    returns the path of; unreadable files raise ScenarioError."""
    path = Path(path_or_name)
    if not path.is_file():
        path = builtin(str(path_or_name))
    try:
        return path.read_text(encoding="utf-8"), path
    except (OSError, UnicodeDecodeError) as exc:
        raise ScenarioError(f"cannot read: {exc}", "", str(path_or_name)) from None


def builtin_path(name):
    """The path of built-in scenario ``name`` (to copy and edit)."""
    return find_builtin(BUILTIN_DIR, name, "scenario", [n for n, _ in list_builtin()])


def load(path_or_name):
    """A Scenario from a .toml file, or the built-in of that name."""
    text, path = read_toml_source(path_or_name, builtin_path)
    return loads(text, source=str(path), name=path.stem)


def list_builtin():
    """[(name, title)] of the built-in scenarios, sorted by name."""
    out = []
    for path in sorted(BUILTIN_DIR.glob("*.toml")):
        data = tomllib.loads(path.read_text(encoding="utf-8"))
        out.append((path.stem, data.get("title", path.stem)))
    return out


def format_figure(figure):
    """A [paper] figure as text, e.g. "horizontal_error_final = 8.57 nmi"."""
    return f"{figure['metric']} {figure['relation']} {figure['value']:g} {figure['unit']}".rstrip()


def in_figure_unit(value_si, figure):
    """Our ``value_si`` of a figure's metric, in the unit the paper's
    figure is written in (to print them side by side)."""
    if not figure["unit"]:
        return value_si
    return value_si / UNITS[METRICS[figure["metric"]][0]][figure["unit"]]
