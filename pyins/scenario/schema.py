"""The scenario file's schema: every key of every table, with its kind,
default and range (docs/scenarios.md is the same in prose).

`Key` describes one key; the tables map key names to Keys: `TOP_KEYS`, then
one dict per table (`TABLES`), the motion's common keys (`MOTION_COMMON`) and
each kind's own (`MOTION_KINDS`, which the fixed-position kinds extend with
the ship's `SHIP_KEYS`), and the sub-tables (segments, heave/surge/sway
components, the wave spectrum, custom indexing steps, [paper] figures).
Beside them, the names a file writes mapped to the firmware's enums
(`INDEX_SCHEMES`, ...). A [paper] figure names one of `METRICS`, the
figure metrics of `pyins.metrics`.
"""
from dataclasses import dataclass

from pyins import metrics, sim
from pyins.reference import abi
from pyins.sim import turntable

SCHEMA_VERSION = 1


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
               "references", "compare", "paper", "outputs")

_LAT_DEFAULT, _LON_DEFAULT = "34.246 deg", "108.910 deg"
MOTION_COMMON = {
    "kind": Key("choice", "motion profile", required=True,
                choices=("static", "swing", "sea_state", "heading_swing", "at_anchor", "manoeuvre", "voyage")),
    "lat": _angle("geodetic latitude", _LAT_DEFAULT, "-89.9 deg", "89.9 deg"),
    "lon": _angle("longitude", _LON_DEFAULT, "-360 deg", "360 deg"),
    "height": Key("length", "height above the WGS-84 ellipsoid", "0 m", lo="-10 km", hi="100 km"),
    "pitch": _angle("pitch (swing: mean pitch)", "0 deg", "-89.9 deg", "89.9 deg"),
    "roll": _angle("roll (swing: mean roll)", "0 deg", "-180 deg", "180 deg"),
    "yaw": _angle("yaw, counter-clockwise from North (swing: mean; heading swing, "
                  "manoeuvre, voyage: initial; a voyage without it starts on its route's course)",
                  "0 deg", "-360 deg", "360 deg"),
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
    "at_anchor": {
        "sea_state": Key("choice", "sea state of seed 000 Table 2: its pitch and roll (the yaw is the "
                                   "swing's)", required=True, choices=tuple(sim.SEA_STATES)),
        "radius": Key("length", "the anchor -> the motion reference point: the arc's radius", "50 m",
                      lo="0 m", hi="1000 m"),
        "swing_period": Key("time", "period of the swing about the anchor", "40 min", lo="0 s", hi="1 d",
                            lo_open=True),
        "swing_angle": _angle("half angle of the swing (the chain's angle from the mean bow; the bow "
                              "follows it)", "30 deg", "0 deg", "90 deg"),
        "swing_phase": _angle("phase of the swing at t = 0", "0 deg", "-360 deg", "360 deg"),
    },
    "manoeuvre": {
        "speed": Key("velocity", "initial speed", "0 m/s", lo="0 m/s", hi="100 m/s"),
        "segments": Key("tables", "'default' (the 30-min manoeuvre) or legs "
                                  "{kind, duration, speed | angle}", "default"),
    },
    "voyage": {
        "route_seed": Key("int", "seed of the transit's legs (pyins.sim.voyage_segments: a first leg "
                                 "of 10-20 min, then course changes of 20-120 deg at 0.5-1 deg/s, "
                                 "every other one with a speed change within 5-20 kn, legs of "
                                 "30-60 min; the initial course and speed, 8-16 kn)", default=0, lo=0),
        "sea": Key("choice", "the swing of seed 000 Table 2 on top of the track ('none': a flat sea); "
                             "the voyage heaves 0.5 m at 8 s", "general",
                   choices=("general", "ideal", "bad", "none")),
        "speed": Key("velocity", "initial speed through the water (default: the route's, 8-16 kn)", None,
                     lo="0 m/s", hi="100 m/s"),
        "segments": Key("tables", "'route' (route_seed's transit) or legs {kind, duration, speed | "
                                  "angle} as the manoeuvre's: a chosen track under the same sea", "route"),
        "current": Key("velocity", "the water current the ship drifts with, mean [E, N, 0] (its ground "
                                   "velocity: the water velocity along the bow plus the current)", "0 m/s",
                       lo="-10 m/s", hi="10 m/s", shape=3),
        "current_tide": Key("velocity", "a tidal ellipse on the current, at the M2 period (12.42 h), "
                                        "amplitude per axis (its phases from route_seed)", "0 m/s",
                            lo="0 m/s", hi="10 m/s"),
    },
}
SEGMENT_KEYS = {
    "kind": Key("choice", "leg", required=True, choices=("accelerate", "decelerate", "cruise", "turn")),
    "duration": _time("length of the leg", required=True, lo="0 s", lo_open=True),
    "speed": Key("velocity", "target speed (accelerate, decelerate)", lo="0 m/s", hi="100 m/s"),
    "angle": _angle("yaw change, counter-clockwise (turn)", None, "-3600 deg", "3600 deg"),
}

#: Keys of the fixed-position kinds (static, swing, sea_state, heading_swing,
#: at_anchor: its mean position is fixed) that make the ship a `pyins.sim.ShipAtSea`: heave, surge and sway of the
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
_FIXED_KINDS = ("static", "swing", "sea_state", "heading_swing", "at_anchor")
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
                 "four_position": 3, "flexible": 4, "custom": 5, "flexible_derived": 6,
                 "heading_isolation": 7}
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
    # the firmware refuses a step beyond 8 turns, |angle| > 16 pi (config.cpp, PYINS_E_CONFIG_INDEX_STEP)
    "angle": _angle("fixed: the turn (signed, counter-clockwise +); flex_*: its sense", None,
                    "-2880 deg", "2880 deg", required=True),
}

#: the firmware's enums by the names scenario files and the CLI use
NAV_MODES = {"auto": abi.PYINS_NAV_AUTO, "undamped": abi.PYINS_NAV_UNDAMPED,
             "damped": abi.PYINS_NAV_DAMPED, "integrated": abi.PYINS_NAV_INTEGRATED}
VERTICAL_MODES = {"hold": abi.PYINS_VERTICAL_HOLD, "free": abi.PYINS_VERTICAL_FREE}
FINE_CORRECTIONS = {"feedback": abi.PYINS_FINE_FEEDBACK, "open_loop": abi.PYINS_FINE_OPEN_LOOP}
FINE_NOISES = {"measured": abi.PYINS_FINE_NOISE_MEASURED, "configured": abi.PYINS_FINE_NOISE_CONFIGURED}
COARSE_METHODS = {"triad": abi.PYINS_COARSE_TRIAD, "fit": abi.PYINS_COARSE_FIT, "eq8": abi.PYINS_COARSE_EQ8,
                  "fit_vel": abi.PYINS_COARSE_FIT_VEL}
FIRMWARE_KEYS = {
    "initial_attitude": Key("choice", "attitude the firmware starts from: the true one (plus "
                                      "[initial_errors]) or all Euler angles zero", "truth",
                            choices=("truth", "zero")),
    "vertical_mode": Key("choice", "vertical channel (firmware default hold)",
                         choices=tuple(VERTICAL_MODES)),
    "coarse_time": _time("coarse alignment length (0: none)", None),
    "coarse_ratio": Key("dimensionless", "coarse alignment ratio r = t_k1 / t_k2 (firmware "
                                         "default 0.5)", lo=0, hi=1, lo_open=True, hi_open=True),
    "coarse_first_output": _time("first coarse solution (firmware default 20 s)", None,
                                 lo="0.01 s"),
    "coarse_output_every": _time("coarse solution interval (firmware default 1 s)", None,
                                 lo="0.01 s"),
    "coarse_method": Key("choice", "coarse alignment: 'triad' (seed 000, a base that does not move) "
                                   "'fit' (moving base: heave, surge, sway), 'fit_vel' (a ship under way: "
                                   "FIT with the motion taken out by [references.gnss]' velocity; the "
                                   "navigation filter then aligns finely, so no fine_time) or 'eq8' "
                                   "(seed 000 eq. 8 as printed, not orthonormalised; firmware default triad)", choices=tuple(COARSE_METHODS)),
    "lever": Key("choice", "lever arms the firmware is told: 'configured' (the simulated "
                           "motion.lever_b and lever_p) or 'unknown' (zero)", "configured",
                 choices=("configured", "unknown")),
    "fine_time": _time("fine alignment length (0: none)", None),
    "fine_states": Key("int", "fine-alignment filter states: 5 or 8 on a static base, 12 on a moored "
                       "ship (position matched against the site; firmware default 5)", lo=5, hi=12,
                       choices=(5, 8, 12)),
    "fine_meas_every": _time("fine-alignment measurement interval (firmware default 0.1 s)", None,
                             lo="0.01 s", hi="1 h"),
    "fine_correction": Key("choice", "fine alignment feedback or open loop (firmware default "
                                     "feedback)", choices=tuple(FINE_CORRECTIONS)),
    "fine_gyro_arw": Key("angle_random_walk", "filter Q: gyro ARW (firmware default "
                                              "0.001 deg/sqrt(h))", lo="0 deg/sqrt(h)",
                         hi="10 deg/sqrt(h)", lo_open=True),
    "fine_accel_vrw": Key("velocity_random_walk", "filter R: accelerometer VRW (firmware default "
                                                  "10 ug/sqrt(Hz))", lo="0 ug/sqrt(Hz)",
                          hi="10 mg/sqrt(Hz)", lo_open=True),
    "fine_noise": Key("choice", "where the static fine filters' R comes from: 'measured' (the larger of "
                                "fine_accel_vrw and the noise the coarse phase measured, vibration "
                                "included) or 'configured' (fine_accel_vrw alone; firmware default "
                                "measured)", choices=tuple(FINE_NOISES)),
    "fine_sigma0_att": _angle("initial sigma of phi E, N, U (firmware default: fitted to the coarse "
                              "result after a coarse alignment, else 100', 100', 600'; 1', 1', 10' "
                              "for the moving-base filter)",
                              None, "0 deg", "180 deg", lo_open=True, shape=3),
    "fine_sigma0_gyro": Key("angular_rate", "initial sigma of the drifts (firmware default "
                                            "0.01 deg/h)", lo="0 deg/h", hi="1 deg/s",
                            lo_open=True),
    "fine_sigma0_accel": Key("acceleration", "initial sigma of the biases (firmware default "
                                             "100 ug)", lo="0 ug", hi="1 g", lo_open=True),
    "nav_mode": Key("choice", "navigation: 'auto' (integrated while a reference is in use, else "
                              "undamped), 'undamped' (free inertial, references refused), 'damped' "
                              "(level damping by a reference velocity, no filter corrections, no GNSS "
                              "position) or 'integrated' (firmware default auto)",
                    choices=("auto", "undamped", "damped", "integrated")),
    "fine_site_accel": Key("velocity_random_walk", "moving base (fine_states 12): the site's slow "
                                                   "horizontal motion, a ship ranging on its lines, as "
                                                   "a white acceleration density (firmware default 0: "
                                                   "a rigid site)", lo="0 ug/sqrt(Hz)",
                           hi="10 mg/sqrt(Hz)"),
    "fine_site_swing": Key("list", "moving base (fine_states 12) at anchor: the anchorage's bound on the "
                                   "swing, [radius, period, half angle] (e.g. [\"80 m\", \"20 min\", "
                                   "\"30 deg\"]: the chain's radius, the fastest swing, the widest); "
                                   "sets fine_site_accel to the density that covers every swing up to "
                                   "it (pyins.analysis.site_accel_for_swing; not with fine_site_accel)"),
    "nav_gyro_bias_rw": Key("rate_random_walk", "navigation filter: the gyro biases' random walk, "
                                                "their instability (firmware default 0: random "
                                                "constants)", lo="0 deg/h/sqrt(h)",
                            hi="1e-6 rad/s/sqrt(s)"),
    "nav_table_scale_sigma": Key("dimensionless", "navigation filter: prior sigma of the scale "
                                                  "factor of the gyro on the table's axis, a state "
                                                  "(a heading error of that fraction of every table "
                                                  "move; firmware default 0: not modelled; the "
                                                  "IMU's own figure, e.g. 10 ppm)", lo=0.0, hi=0.01),
    "nav_table_mis_sigma": Key("angle", "navigation filter: prior sigma of the other gyros' "
                                        "misalignments to the table's axis, two states (firmware "
                                        "default 0: not modelled; e.g. 10 arcsec)",
                               lo="0 arcsec", hi="0.01 rad"),
    "nav_level_scale_sigma": Key("dimensionless", "navigation filter: prior sigma of the x and y "
                                                  "gyros' scale factors, two states (firmware "
                                                  "default 0: not modelled; e.g. 10 ppm)",
                                 lo=0.0, hi=0.01),
    "nav_level_mis_sigma": Key("angle", "navigation filter: prior sigma of the x and y gyros' "
                                        "misalignments to each other, two states: the Earth's rate "
                                        "through them is a heading error no indexing removes "
                                        "(firmware default 0: not modelled; e.g. 10 arcsec)",
                               lo="0 arcsec", hi="0.01 rad"),
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

#: metric -> (dimension, meaning): the metrics a [paper] figure may name
#: (pyins.metrics.FIGURE_METRICS, in the order of its table).
METRICS = {name: (metrics.dimension(name), metrics.describe(name)) for name in metrics.FIGURE_METRICS}
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

#: Keys of [references.gnss]: a simulated receiver (pyins.sim.references.gnss)
#: whose fixes the firmware navigates with (docs/concepts.md, "At sea").
GNSS_KEYS = {
    "rate": Key("frequency", "fix rate (1 / rate a whole number of ticks)", "1 Hz", lo="0 Hz",
                hi="100 Hz", lo_open=True),
    "pos_noise": Key("length", "white noise of the position, [E, N, U] 1-sigma", "3 m", lo="0 m",
                     hi="1 km", lo_open=True, shape=3),
    "vel_noise": Key("velocity", "white noise of the velocity, per axis", "0.05 m/s", lo="0 m/s",
                     hi="10 m/s", lo_open=True),
    "bias_sigma": Key("length", "first-order Gauss-Markov position bias, 1-sigma per axis (0: none)",
                      "2 m", lo="0 m", hi="1 km"),
    "bias_tau": Key("time", "the bias's correlation time (not only whole ticks)", "300 s", lo="0 s",
                    hi="30 d", lo_open=True),
    "latency": _time("the receiver's latency: a fix reaches the firmware this long after its "
                     "tick (at most the firmware's 1 s)", "0 s", hi="1 s"),
    "outages": Key("tables", "outages {start, end}: no fix in [start, end)"),
    "outage_every": _time("periodic outages (KF-GINS's protocol: 180 s): one every ... (0: none)",
                          "0 s"),
    "outage_length": _time("periodic outages: each lasts ... (KF-GINS's: 60 s)", "60 s",
                           lo="0 s", lo_open=True),
    "outage_from": _time("periodic outages: the first starts at ...", "0 s"),
    "outlier_rate": Key("dimensionless", "share of fixes jumped 50-500 m (multipath)", 0.0, lo=0,
                        hi=1),
    "frozen": Key("tables", "a frozen receiver {start, end}: the last fix before start repeated"),
    "seed": Key("int", "seed of the receiver's noise (not the IMU's)", default=0, lo=0),
    "velocity": Key("bool", "give velocity fixes beside the positions", default=True),
    "position": Key("bool", "give position fixes (firmware.nav_mode 'damped' takes none: false there)",
                    default=True),
    "lever": Key("length", "reference point -> the antenna [x starboard, y bow, z up]: the fixes are the "
                           "antenna's", "0 m", lo="-100 m", hi="100 m", shape=3),
    "lever_told": Key("length", "the antenna's lever arm the firmware is told (its gnss_lever_b_m; "
                                "default: the lever, a surveyed antenna; \"0 m\": not told)", None,
                      lo="-100 m", hi="100 m", shape=3),
}
#: Keys of one window of [references.gnss] outages or frozen.
WINDOW_KEYS = {
    "start": _time("start of the window", required=True, hi="30 d"),
    "end": _time("end of the window (after its start)", required=True, hi="30 d"),
}
#: Keys of [references.zero_velocity]: declarations that the ship is at rest.
ZERO_VELOCITY_KEYS = {
    "rate": Key("frequency", "declarations per second (1 / rate a whole number of ticks)", "1 Hz",
                lo="0 Hz", hi="100 Hz", lo_open=True),
    "sigma": Key("velocity", "sigma per axis", "0.01 m/s", lo="0 m/s", hi="10 m/s", lo_open=True),
    "start": _time("the first declaration after ... (default: the end of the alignment)", None),
}
#: Keys of [references.speed_log]: an EM log (pyins.sim.references.speed_log)
#: in a water current, the firmware's damping reference.
SPEED_LOG_KEYS = {
    "rate": Key("frequency", "readings per second (1 / rate a whole number of ticks)", "1 Hz", lo="0 Hz",
                hi="100 Hz", lo_open=True),
    "noise": Key("velocity", "white noise of a reading", "0.05 m/s", lo="0 m/s", hi="10 m/s"),
    "scale_factor": Key("dimensionless", "scale factor error", 0.005, lo=-0.5, hi=0.5),
    "bias": Key("velocity", "bias of a reading", "0 m/s", lo="-10 m/s", hi="10 m/s"),
    "sigma": Key("velocity", "the sigma the firmware is told (noise, scale factor and what else the "
                             "reading misses)", "0.1 m/s", lo="0 m/s", hi="10 m/s", lo_open=True),
    "seed": Key("int", "seed of the log's noise (not the IMU's)", default=0, lo=0),
}
#: Keys of [references.dvl]: a Doppler velocity log in bottom track (the
#: velocity over ground in its own frame; pyins.sim.references.dvl), a
#: velocity reference of the firmware's filter.
DVL_KEYS = {
    "rate": Key("frequency", "readings per second (1 / rate a whole number of ticks)", "1 Hz", lo="0 Hz",
                hi="100 Hz", lo_open=True),
    "noise": Key("velocity", "white noise of a reading, per axis", "0.01 m/s", lo="0 m/s", hi="10 m/s"),
    "scale_factor": Key("dimensionless", "scale factor error", 0.002, lo=-0.5, hi=0.5),
    "misalignment": _angle("the DVL's mounting, a rotation vector m from the ship's axes: C_d^b = "
                           "exp([m x]), [x, y, z]", "0 deg", "-180 deg", "180 deg", shape=3),
    "misalignment_told": _angle("the mounting the firmware is told (its dvl_align_rad; default: the "
                                "misalignment, a calibrated mounting; \"0 deg\": not told)", None,
                                "-180 deg", "180 deg", shape=3),
    "lever": Key("length", "reference point -> DVL [x starboard, y bow, z up], told to the firmware "
                           "(its dvl_lever_b_m)", "0 m", lo="-100 m", hi="100 m", shape=3),
    "sigma": Key("velocity", "the sigma per axis the firmware is told", "0.01 m/s", lo="0 m/s",
                 hi="10 m/s", lo_open=True),
    "seed": Key("int", "seed of the DVL's noise (not the IMU's)", default=0, lo=0),
}
#: [references] sub-tables -> their keys
REFERENCE_TABLES = {"gnss": GNSS_KEYS, "speed_log": SPEED_LOG_KEYS, "dvl": DVL_KEYS,
                    "zero_velocity": ZERO_VELOCITY_KEYS}

#: table name -> its keys (motion: the common keys; kinds add theirs).
TABLES = {"motion": MOTION_COMMON, "sensors": SENSOR_KEYS, "turntable": TURNTABLE_KEYS,
          "indexing": INDEXING_KEYS, "firmware": FIRMWARE_KEYS, "initial_errors": INITIAL_ERROR_KEYS,
          "compare": COMPARE_KEYS, "paper": PAPER_KEYS, "outputs": OUTPUT_KEYS}

_SUFFIX = {"angle": "_rad", "angular_rate": "_rad_s", "angular_acceleration": "_rad_s2",
           "angle_random_walk": "_rad_sqrt_s", "acceleration": "_mps2", "rate_random_walk": "_rad_s_sqrt_s",
           "velocity_random_walk": "_mps_sqrt_s", "velocity": "_mps", "length": "_m", "time": "_s",
           "frequency": "_hz", "dimensionless": ""}

