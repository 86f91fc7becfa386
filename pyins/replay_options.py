"""The options of ``pyins replay``, as the user gave them, made into the
firmware's configuration and checked before anything runs.

`config` is a guarded sequence of named steps:

1. the rate: the log's (its time column, an .npz's dt, or --dt), else
   --rate, else the scenario's; any two more than 1 % apart are an error,
   and the firmware steps at a whole number of Hz (`rate_hz`);
2. the initial state: the scenario's, or the site a PSINS header names,
   overridden by --lat/--lon/--height/--attitude;
3. the firmware's settings (alignment times in seconds at the log's rate,
   the filter, its noise and sigma0 with units);
4. what the firmware cannot be right without, refused: no position, no
   attitude and no coarse alignment, a value outside the firmware's limits
   (stated in the user's options, `pyins.limits`).

Every refusal is an `OptionError` (a ValueError): one line, exit 2.
"""
import numpy as np

from pyins import limits, scenario, units
from pyins.reference import abi
from pyins.scenario import schema
from pyins.units import ScenarioError

__all__ = ["config", "rate_hz", "quantity", "limited", "ticks_of", "NAMES", "OptionError"]


class OptionError(ValueError):
    """A replay option the firmware cannot be right with: one line for the user."""


#: The navigation filter's model of the IMU: the field (and the scenario key
#: that bounds it: the same refusal either way) and its option; 0 means what
#: it means there ("not modelled"), not a default
NAV_MODEL = {"nav_gyro_bias_rw": "--nav-gyro-bias-rw", "nav_table_scale_sigma": "--nav-table-scale",
             "nav_table_mis_sigma": "--nav-table-mis", "nav_level_scale_sigma": "--nav-level-scale",
             "nav_level_mis_sigma": "--nav-level-mis"}

#: How the replay command names the firmware fields it sets (`pyins.limits`).
NAMES = {"tick_hz": "--rate", "lat_rad": "--lat", "lon_rad": "--lon", "height_m": "--height",
         "euler_b_rad": "--attitude", "coarse_ticks": "--coarse",
         "coarse_output_every_ticks": "--coarse-every", "coarse_method": "--coarse-method",
         "fine_ticks": "--fine", "fine_states": "--fine-states",
         "fine_gyro_arw": "--gyro-arw", "fine_accel_vrw": "--accel-vrw",
         "fine_sigma0_att_rad": "--fine-sigma0", **NAV_MODEL}


def rate_hz(args, data, spec):
    """The log's sample rate [Hz] as the firmware's whole-number tick rate:
    from the log (its time column, its dt, or --dt), else --rate, else the
    scenario's; any two that disagree by more than 1 % are an error.
    ``data``: anything with ``dt`` and ``metadata`` (a `pyins.logs.LogReader`,
    whose probe gave them before the first block, or an ImuData)."""
    rate, where = None, None
    if data.dt:
        rate, where = 1.0 / data.dt, ("--dt" if args.dt is not None else f"the log ({args.log})")
    if args.rate is not None:
        if not args.rate > 0:
            raise OptionError(f"--rate: {args.rate:g} Hz must be positive")
        if rate is not None and abs(args.rate - rate) > 0.01 * rate:
            raise OptionError(f"--rate {args.rate:g} Hz disagrees with {where}: {rate:.6g} Hz")
        rate, where = float(args.rate), "--rate"
    if spec is not None:
        scn_rate = 1.0 / spec.dt
        if rate is not None and abs(scn_rate - rate) > 0.01 * rate:
            raise OptionError(f"{where} gives {rate:.6g} Hz, the scenario {spec.scenario!r} runs at "
                              f"{scn_rate:g} Hz: its truth would not fit the log")
        if rate is None:
            rate, where = scn_rate, f"the scenario {spec.scenario!r}"
    if rate is None:
        raise OptionError(f"{args.log}: no sample rate: the log has no time column or dt; give --rate HZ")
    hz = int(round(rate))
    # 1 ns: the reader rounds an inferred tick to it
    if hz < 1 or abs(1.0 / hz - 1.0 / rate) > 1e-9 + 1e-6 / rate:
        raise OptionError(f"{where}: {rate:.9g} Hz is not a whole number of Hz; the firmware steps at an "
                          "integer tick rate (resample the log)")
    return hz


def quantity(option, text, dimension):
    """A quantity the user wrote with its unit, in SI (`pyins.units`)."""
    try:
        return units.parse_quantity(text, dimension)
    except ScenarioError as exc:
        raise OptionError(f"{option} {text!r}: {exc.reason}") from None


#: the most ticks a time option may come to (the configuration's fields are 32-bit)
MAX_TICKS = 2**31 - 1


def ticks_of(option, seconds, hz, zero=None):
    """A time option [s] in whole ticks at ``hz``. ``zero``: what 0 means
    (None: 0 is not a value of this option). A time that rounds to 0 ticks
    is refused: the firmware would read the 0 as its default or as "none"."""
    if not (np.isfinite(seconds) and seconds >= 0):
        raise OptionError(f"{option}: {seconds:g} s must be a time of zero or more seconds")
    ticks = round(seconds * hz)
    if ticks > MAX_TICKS:
        raise OptionError(f"{option}: {seconds:g} s is more than the firmware counts "
                          f"({MAX_TICKS / hz:.6g} s at {hz} Hz)")
    if seconds == 0 and zero is None:
        raise OptionError(f"{option}: 0 s is not an interval: give at least one tick "
                          f"({1.0 / hz:g} s at {hz} Hz), or leave {option} out for the default")
    if ticks > 0 and abs(ticks - seconds * hz) > 1e-6:
        lo, hi = np.floor(seconds * hz), np.ceil(seconds * hz)
        raise OptionError(f"{option}: {seconds:g} s is not a whole number of ticks at {hz} Hz (a tick is "
                          f"{1.0 / hz:g} s): give {lo / hz:g} s or {hi / hz:g} s")
    if ticks == 0 and seconds > 0:
        way = f"0 for {zero}, or at least" if zero else "at least"
        raise OptionError(f"{option}: {seconds:g} s rounds to 0 ticks at {hz} Hz (a tick is "
                          f"{1.0 / hz:g} s): give {way} one tick")
    return int(ticks)


def limited(option, text, key):
    """A firmware quantity the user wrote with its unit, in SI, within the
    limits the scenario file's key ``key`` holds it to (`pyins.scenario.schema`):
    the same value is refused on the command line and in a scenario."""
    k = schema.FIRMWARE_KEYS[key]
    value = quantity(option, text, k.kind)
    lo = None if k.lo is None else units.parse_quantity(k.lo, k.kind)
    hi = None if k.hi is None else units.parse_quantity(k.hi, k.kind)
    low = lo is not None and (value <= lo if k.lo_open else value < lo)
    if not np.isfinite(value) or low or (hi is not None and value > hi):
        zero = " (0 is not 'the default': leave the option out for that)" if value == 0 else ""
        raise OptionError(f"{option} {text!r}: must be {'more than' if k.lo_open else 'at least'} "
                          f"{k.lo} and at most {k.hi}{zero}")
    return value


def _early(cfg):
    """The refusal of a coarse output interval too long for the first solution, in --coarse-every."""
    r = limits.resolved(cfg)
    hz = r["tick_hz"]
    first, every = r["coarse_first_output_ticks"] / hz, r["coarse_output_every_ticks"] / hz
    if r["coarse_method"] in (abi.PYINS_COARSE_FIT, abi.PYINS_COARSE_FIT_VEL):
        return limits.explain(abi.PYINS_E_CONFIG_ALIGN_EARLY, cfg, NAMES)
    return (f"--coarse-every: an output interval of {every:g} s is too long: the first coarse "
            f"solution comes at {first:g} s and needs at least one interval of history before it "
            f"(at most {r['coarse_ratio'] * first:g} s)")


def config(args, data, spec, cfg, say=print):
    """The firmware configuration of a replay and its tick rate [Hz]: ``cfg``
    (the scenario's, or empty) completed from the options ``args`` and the
    log ``data`` (its ``dt`` and ``metadata``: a `pyins.logs.LogReader` or an
    ImuData); ``say`` prints a notice."""
    # 1. the rate
    hz = rate_hz(args, data, spec)
    cfg["tick_hz"] = hz

    # 2. the initial state
    site = data.metadata.get("psins_header")
    if site and spec is None and args.lat is None and args.lon is None:
        # a PSINS .imu names its site in its header: used, and said
        cfg.update(lat_rad=np.radians(site["lat0_deg"]), lon_rad=np.radians(site["lon0_deg"]),
                   height_m=site["height0_m"])
        say(f"  site from the log's header: {site['lat0_deg']} N {site['lon0_deg']} E "
            f"{site['height0_m']} m (--lat/--lon/--height override it)")
    for name, val in (("lat_rad", args.lat), ("lon_rad", args.lon)):
        if val is not None:
            cfg[name] = np.radians(val)
    if args.height is not None:
        cfg["height_m"] = args.height
    if args.attitude is not None:
        cfg["euler_b_rad"] = np.radians(args.attitude)

    # 3. the firmware's settings
    for option, field, val, zero in (("--coarse", "coarse_ticks", args.coarse, "no coarse alignment"),
                                     ("--fine", "fine_ticks", args.fine, "no fine alignment"),
                                     ("--coarse-every", "coarse_output_every_ticks", args.coarse_every, None)):
        if val is not None:
            cfg[field] = ticks_of(option, val, hz, zero)
    if args.coarse_method is not None:
        cfg["coarse_method"] = scenario.COARSE_METHODS[args.coarse_method]
    if args.fine_states is not None:
        cfg["fine_states"] = args.fine_states
    if args.fine_correction is not None:
        cfg["fine_correction"] = scenario.FINE_CORRECTIONS[args.fine_correction]
    if args.fine_noise is not None:
        cfg["fine_noise"] = scenario.FINE_NOISES[args.fine_noise]
    if args.vertical is not None:
        cfg["vertical_mode"] = args.vertical
    # the core reads 0 here as "its default": a 0 the user wrote is refused, never swapped
    if args.fine_sigma0 is not None:
        cfg["fine_sigma0_att_rad"] = [limited("--fine-sigma0", t, "fine_sigma0_att") for t in args.fine_sigma0]
    if args.gyro_arw is not None:
        cfg["fine_gyro_arw"] = limited("--gyro-arw", args.gyro_arw, "fine_gyro_arw")
    if args.accel_vrw is not None:
        cfg["fine_accel_vrw"] = limited("--accel-vrw", args.accel_vrw, "fine_accel_vrw")
    for key, option in NAV_MODEL.items():
        text = getattr(args, option[2:].replace("-", "_"), None)
        if text is not None:
            cfg[key] = limited(option, text, key)

    # 4. what the firmware cannot be right without, refused before it runs
    if "lat_rad" not in cfg:
        raise OptionError(f"{args.log}: no initial position: give --scenario or --lat/--lon/--height "
                          "(and --attitude, or --coarse to align)")
    if "euler_b_rad" not in cfg and cfg.get("coarse_ticks", 0) <= 0:
        raise OptionError(f"{args.log}: no initial attitude: give --attitude PITCH ROLL YAW [deg], or "
                          "--coarse SECONDS to align on the log (without either the firmware would start "
                          "level and facing north)")
    refused = limits.check(cfg, NAMES)
    if refused is not None:
        raise OptionError(_early(cfg) if refused[0] == abi.PYINS_E_CONFIG_ALIGN_EARLY else refused[1])
    return cfg, hz
