"""`pyins replay`: a recorded IMU log through the firmware, its errors
against a reference, its page."""
import os
import re
import shutil
import stat
import sys
import tempfile
import zipfile

import numpy as np

from pyins import aiding, contract, engine, logs, replay, replay_options, report, scenario, truth_track
from pyins.logs import nmea as nmea_files
from pyins.sim import references as reference_files
from pyins.reference import abi
from pyins.reference import config as fw_config
from pyins.report import replay as report_replay

from .common import EXIT_INTERRUPTED, EXIT_OK, InputError, default_out, emit_json, progress_bars, say


#: The examples each subcommand's --help ends with.
EXAMPLES = {
    'replay': "examples:\n  pyins replay imu.npz                       # initial state from the log's scenario\n  pyins replay field.txt --kind rates --gyro-unit deg/s --accel-unit g --axes frd \\\n      --lat 34.246 --lon 108.91 --height 380 --coarse 150 --fine 600\n  pyins replay log200.txt --time-col first --axes frd --lat 34.246 --lon 108.91 \\\n      --height 0 --coarse 300 --coarse-method fit   # the rate (200 Hz) from the time column",
}


def add_replay(cmd):
    """`pyins replay`: its subparser (``cmd(name, help)`` makes one) and options."""
    p = cmd("replay", "run a recorded IMU log through the firmware")
    p.add_argument("log", help="the IMU log: .txt/.dat/.asc, .csv, .bin, .npz, PSINS .imu; "
                   "also gzip/xz/bzip2-compressed (docs/log-formats.md)")
    p.add_argument("--format", choices=logs.FORMATS, help="default: from the extension")
    p.add_argument("--scenario", help="initial state and truth from this scenario")
    p.add_argument("--kind", choices=["increments", "rates"])
    p.add_argument("--gyro-unit", help="increments: rad, deg, arcsec; rates: rad/s, deg/s, deg/h, arcsec/s")
    p.add_argument("--accel-unit", help="increments: m/s, mm/s, ug*s; rates: m/s^2, g, mg, ug")
    p.add_argument("--gyro-scale", type=float, help="gyro unit per count, e.g. 0.1 with --gyro-unit arcsec")
    p.add_argument("--accel-scale", type=float, help="accelerometer unit per count")
    p.add_argument("--columns", metavar="ROLE=NAME,...",
                   help="CSV header names for the roles t, gyro_x..z, accel_x..z, table, e.g. t=time,gyro_x=gx")
    p.add_argument("--allow-gaps", action="store_true",
                   help="replay a log with missing samples: each gap is bridged (the firmware's "
                        "linear interpolation) and named in a WARNING line")
    p.add_argument("--axes", help="axis mapping, e.g. frd or frd->rfu (default rfu)")
    p.add_argument("--time-col", choices=["first", "last", "none"])
    p.add_argument("--dt", type=float, help="sample interval [s] when the log has no time")
    p.add_argument("--rate", type=float, help="sample rate [Hz]: checked against the log's time "
                   "column (within 1 %%); needed when the log has neither time nor dt")
    p.add_argument("--table-angle", type=float, help="a fixed table angle [deg] for logs without one")
    p.add_argument("--lat", type=float, help="initial latitude [deg]")
    p.add_argument("--lon", type=float, help="initial longitude [deg]")
    p.add_argument("--height", type=float, help="initial height [m]")
    p.add_argument("--attitude", type=float, nargs=3, metavar=("PITCH", "ROLL", "YAW"),
                   help="initial attitude [deg] (yaw counter-clockwise = -heading)")
    p.add_argument("--coarse", type=float, help="coarse alignment time [s]")
    p.add_argument("--coarse-method", choices=sorted(scenario.COARSE_METHODS),
                   help="triad (default; at most 255 output intervals), fit (no length limit) or eq8 "
                        "(seed 000 eq. 8 as printed, TRIAD's vectors and limits)")
    p.add_argument("--coarse-every", type=float, help="coarse output interval [s] (default 1 s)")
    p.add_argument("--fine", type=float, help="fine alignment time [s]")
    p.add_argument("--fine-states", type=int, choices=(5, 8, 12),
                   help="fine filter: 5 (default) or 8 states (static base), 12 (moored ship)")
    p.add_argument("--fine-correction", choices=sorted(scenario.FINE_CORRECTIONS))
    p.add_argument("--fine-sigma0", nargs=3, metavar=("E", "N", "U"),
                   help="initial attitude sigmas of the fine filter, with units, e.g. 10\' 10\' 60\'")
    p.add_argument("--gyro-arw", help="gyro noise the fine filter assumes, e.g. \"0.001 deg/sqrt(h)\"")
    p.add_argument("--accel-vrw", help="accelerometer noise the fine filter assumes, e.g. \"10 ug/sqrt(Hz)\"")
    p.add_argument("--fine-noise", choices=sorted(scenario.FINE_NOISES),
                   help="the static fine filters' R: measured (default: the larger of --accel-vrw and the "
                        "noise the coarse phase measures, vibration included) or configured (--accel-vrw alone)")
    p.add_argument("--vertical", choices=("hold", "free"), help="vertical channel (default hold)")
    nav = ("the navigation filter's prior sigma of ", " (a state of the filter; with units; 0 or left out: not "
                                                      "modelled; docs/concepts.md, \"At sea\")")
    p.add_argument("--nav-table-scale", metavar="SIGMA",
                   help=nav[0] + "the z gyro's scale factor, e.g. \"10 ppm\"" + nav[1])
    p.add_argument("--nav-table-mis", metavar="SIGMA",
                   help=nav[0] + "the x and y gyros' misalignments to the table's axis, e.g. \"10 arcsec\"" + nav[1])
    p.add_argument("--nav-level-scale", metavar="SIGMA",
                   help=nav[0] + "the x and y gyros' scale factors, e.g. \"10 ppm\"" + nav[1])
    p.add_argument("--nav-level-mis", metavar="SIGMA",
                   help=nav[0] + "the x and y gyros' misalignments to each other, e.g. \"10 arcsec\"" + nav[1])
    p.add_argument("--nav-gyro-bias-rw", metavar="DENSITY",
                   help="the navigation filter's gyro bias random walk, their instability, e.g. "
                        "\"0.0007 deg/h/sqrt(h)\" (0 or left out: random constants)")
    p.add_argument("--every", type=int, help="record every N samples (default: one a second)")
    p.add_argument("--reference", choices=replay.REFERENCES,
                   help="errors against: parked = the site (--lat/--lon/--height) and zero velocity")
    p.add_argument("--truth", metavar="FILE",
                   help="errors against a reference trajectory: a text file with a header line naming "
                        "t, lat_deg, lon_deg [, height_m, heading_deg], t on the log's clock "
                        "(docs/cli.md, \"pyins replay\")")
    p.add_argument("--refs", metavar="FILE",
                   help="external references used in navigation (GNSS position and velocity, EM speed "
                        "log, DVL bottom track, zero velocity), ticks on the log's clock (tick T: the end of "
                        "its T-th sample): the text layout 'tick,kind,v0,v1,v2,s0,s1,s2' (docs/log-formats.md, "
                        "\"Reference files\")")
    p.add_argument("--gnss", metavar="FILE",
                   help="GNSS fixes used in navigation: an NMEA 0183 file (GGA position, RMC or VTG velocity, "
                        "GST sigmas; needs --nmea-utc-start) or the --refs layout with gnss_pos/gnss_vel rows "
                        "(docs/log-formats.md, \"NMEA 0183\")")
    p.add_argument("--speed-log", metavar="FILE",
                   help="EM speed log used in navigation: an NMEA 0183 file (VHW or VBW water speed; needs "
                        "--nmea-utc-start) or the --refs layout with speed_log rows")
    p.add_argument("--dvl", metavar="FILE",
                   help="DVL bottom-track velocities used in navigation (over ground, in the DVL's own axes, "
                        "m/s): the --refs layout with dvl rows; the DVL's mounting from the scenario or "
                        "--dvl-align, --dvl-lever")
    p.add_argument("--dvl-align", type=float, nargs=3, metavar=("X", "Y", "Z"),
                   help="the DVL's mounting: the rotation vector from the ship's axes to the DVL's [deg] "
                        "(C_d^b = exp([m x]); default 0, aligned, or the scenario's)")
    p.add_argument("--dvl-lever", type=float, nargs=3, metavar=("X", "Y", "Z"),
                   help="the DVL's position from the reference point in the ship's axes, x starboard, y bow, "
                        "z up [m] (default 0, or the scenario's)")
    p.add_argument("--gnss-lever", type=float, nargs=3, metavar=("X", "Y", "Z"),
                   help="the GNSS antenna's position from the reference point in the ship's axes, x "
                        "starboard, y bow, z up [m]: the fixes are the antenna's (default 0, or the scenario's)")
    p.add_argument("--nmea-utc-start", metavar="UTC",
                   help="the UTC date and time of the log's start (tick 0), e.g. 2026-12-05T10:00:00.00: "
                        "maps the NMEA files' UTC times onto the log's ticks")
    p.add_argument("--gnss-sigma", metavar="SIGMA",
                   help="position sigma (east, north, up) of an NMEA fix without a GST of its epoch, e.g. "
                        f"'3 m' (default '{nmea_files.DEFAULT_POS_SIGMA_M:g} m', assumed: said in a warning)")
    p.add_argument("--gnss-vel-sigma", metavar="SIGMA",
                   help="sigma per axis of an NMEA velocity (RMC, VTG carry none), e.g. '0.05 m/s' "
                        f"(default '{nmea_files.DEFAULT_VEL_SIGMA_MPS:g} m/s', assumed: said in a warning)")
    p.add_argument("--speed-log-sigma", metavar="SIGMA",
                   help="sigma of an NMEA speed-log speed (VHW, VBW carry none), e.g. '0.05 m/s' "
                        f"(default '{nmea_files.DEFAULT_LOG_SIGMA_MPS:g} m/s', assumed: said in a warning)")
    p.add_argument("--zero-velocity", nargs="?", const="0.01 m/s", metavar="SIGMA",
                   help="the vehicle or ship at rest after its alignment: a zero-velocity reference every "
                        "second of navigation, SIGMA per axis (default '0.01 m/s')")
    p.add_argument("--out", help="output directory (default runs/replay)")
    p.add_argument("--engine", choices=engine.ENGINES, default="native",
                   help="the firmware: native (compiled, default) or reference (NumPy mirror)")


#: the reader's words for its Python arguments, as the command line says them
_CLI_WORDS = (("pass fmt= one of", "give --format, one of"), ("fmt='binary'", "--format binary"),
              ("fmt='csv'", "--format csv"), ("fmt='text'", "--format text"), ("fmt='psins'", "--format psins"),
              ("fmt='npz'", "--format npz"), ("fmt ", "--format "),
              ("time_col='none'", "--time-col none"), ("time_col='first'", "--time-col first"),
              ("time_col='last'", "--time-col last"), ("pass dt", "give --rate HZ (or --dt S)"),
              ("differs from dt=", "differs from --dt "), ("table_angle given", "--table-angle given"),
              ("table_angle does not apply", "--table-angle does not apply"),
              ("or pass the names", "or name them with --columns"),
              ("columns= names CSV header columns or npz arrays; it does not apply to ",
               "--columns names CSV header columns or npz arrays; it does not apply to --format "),
              ("unit, axis, scale and column options", "--kind, --gyro-unit, --accel-unit, --axes, "
                                                      "--gyro-scale, --accel-scale and --columns"))


def _cli_words(msg):
    msg = re.sub(r"columns=\{'(\w+)': (?:NAME|\.\.\.)\}", r"--columns \1=NAME", msg)
    for python, cli in _CLI_WORDS:
        msg = msg.replace(python, cli)
    # the reader's keyword names: gyro_unit 'x' ... kind='increments', axes: ...
    msg = re.sub(r"\b(gyro_unit|accel_unit)='([^']*)'", lambda m: f"--{m.group(1).replace('_', '-')} {m.group(2)}", msg)
    msg = msg.replace(" and kind", " and --kind").replace(
        " (plausibility=False for a log without gravity)", " (the check needs gravity in the log)")
    msg = re.sub(r"\b(gyro_unit|accel_unit|gyro_scale|accel_scale|time_col|table_angle)\b(?!')",
                 lambda m: "--" + m.group(1).replace("_", "-"), msg)
    msg = re.sub(r"\bkind='(\w+)'", r"--kind \1", msg)
    msg = re.sub(r"(^|: )axes\b", r"\1--axes", msg)
    # the reader's option names in a list ("options ['time_col'] do not apply")
    return re.sub(r"options \[([^\]]*)\]", lambda m: "options " + ", ".join(
        "--" + k.strip(" '").replace("_", "-") for k in m.group(1).split(",")), msg)


def _positive(option, value, what):
    if value is not None and not (np.isfinite(value) and value > 0):
        raise InputError(f"{option}: {value:g} must be {what}")


def _check_reader_options(args):
    """The reader's numeric options, refused when they cannot be right (one line each)."""
    _positive("--dt", args.dt, "a positive sample interval [s]")
    _positive("--gyro-scale", args.gyro_scale, "a positive unit per count")
    _positive("--accel-scale", args.accel_scale, "a positive unit per count")
    if args.table_angle is not None and not np.isfinite(args.table_angle):
        raise InputError(f"--table-angle: {args.table_angle:g} deg is not an angle")
    for option, value in (("--lat", args.lat), ("--lon", args.lon), ("--height", args.height)):
        if value is not None and not np.isfinite(value):
            raise InputError(f"{option}: {value:g} is not a number")
    if args.attitude is not None:
        pitch, roll, yaw = args.attitude
        if not (np.all(np.isfinite(args.attitude)) and abs(pitch) <= 90.0 and abs(roll) <= 360.0
                and abs(yaw) <= 360.0):
            raise InputError(f"--attitude {pitch:g} {roll:g} {yaw:g}: pitch must lie within +-90 deg, "
                             "roll and yaw within +-360 deg")
    if args.table_angle is not None and not abs(args.table_angle) <= 360.0:
        raise InputError(f"--table-angle: {args.table_angle:g} deg is not within +-360 deg")
    if args.every is not None and not 1 <= args.every <= replay_options.MAX_TICKS:
        raise InputError(f"--every {args.every}: keep one record every 1 to {replay_options.MAX_TICKS} samples")


def _spool(log, fmt):
    """A log read from a pipe or standard input ('-') is read once: copied to
    a temporary file, whose path is returned with the format (told by the
    name the user gave; a pipe with no extension needs --format). A plain
    file is returned as it is (None: nothing to remove)."""
    if log != "-":
        try:
            mode = os.stat(log).st_mode
        except OSError as exc:
            raise InputError(f"{log}: {exc.strerror}") from None
        if stat.S_ISREG(mode) or stat.S_ISDIR(mode):
            if stat.S_ISDIR(mode):
                raise InputError(f"{log}: a directory, not a log file")
            return log, fmt, None
    if fmt is None:
        try:
            fmt = logs.format_of(log) if log != "-" else None
        except ValueError:
            fmt = None
        if fmt is None:
            raise InputError(f"{'standard input' if log == '-' else log}: a pipe has no extension to tell "
                             f"the format by: give --format ({', '.join(logs.FORMATS)})")
    fd, tmp = tempfile.mkstemp(prefix="pyins-replay-", suffix=".log")
    try:
        with os.fdopen(fd, "wb") as dst:
            src = sys.stdin.buffer if log == "-" else open(log, "rb")
            try:
                shutil.copyfileobj(src, dst, 1 << 22)
            finally:
                if log != "-":
                    src.close()
    except BaseException:
        os.remove(tmp)
        raise
    return tmp, fmt, tmp


#: the sigma options of the NMEA files: (option, attribute, dimension, unit, the file's option)
_SIGMAS = (("--gnss-sigma", "gnss_sigma", "length", "m", "--gnss"),
           ("--gnss-vel-sigma", "gnss_vel_sigma", "velocity", "m/s", "--gnss"),
           ("--speed-log-sigma", "speed_log_sigma", "velocity", "m/s", "--speed-log"))


def _check_reference_options(args):
    """The options of the reference files, refused when they cannot be
    right or apply to nothing given (one line each); the sigmas in SI and
    the start in ns are kept on ``args`` (``_sigmas``, ``_utc_start``)."""
    files = {"--gnss": args.gnss, "--speed-log": args.speed_log}
    args._sigmas = {}
    for option, attr, dimension, unit, owner in _SIGMAS:
        text = getattr(args, attr)
        if text is None:
            continue
        if files[owner] is None:
            raise InputError(f"{option}: applies to the NMEA file of {owner} FILE, which is not given")
        try:
            value = replay_options.quantity(option, text, dimension)
        except ValueError as exc:
            raise InputError(str(exc)) from None
        if not (np.isfinite(value) and value > 0.0):
            raise InputError(f"{option} {text!r}: a sigma must be more than 0 {unit}")
        args._sigmas[option] = value
    args._utc_start = None
    if args.nmea_utc_start is not None:
        if args.gnss is None and args.speed_log is None:
            raise InputError("--nmea-utc-start: applies to the NMEA files of --gnss or --speed-log; neither "
                             "is given")
        try:
            args._utc_start = nmea_files.parse_utc(args.nmea_utc_start)
        except ValueError as exc:
            raise InputError(f"--nmea-utc-start: {exc}") from None


def cmd_replay(args):
    _check_reader_options(args)
    _check_reference_options(args)
    path, fmt, spooled = _spool(args.log, args.format)
    try:
        return _replay(args, path, fmt)
    except (ValueError, InputError, EOFError, zipfile.BadZipFile) as exc:
        msg = _cli_words(str(exc))
        if isinstance(exc, (EOFError, zipfile.BadZipFile)):      # an npz cut in a member
            msg = f"{args.log}: not a complete file ({msg}): cut or damaged"
        if spooled is not None:
            msg = msg.replace(spooled, "standard input" if args.log == "-" else args.log)
        raise InputError(msg) from exc
    finally:
        if spooled is not None:
            os.remove(spooled)


def _refs_csv(option, path):
    """A file of the reference text layout (`load_refs_csv`) holding at
    least one reference, or InputError naming ``option``."""
    try:
        refs = reference_files.load_refs_csv(path)
    except OSError as exc:
        raise InputError(f"{option} {path}: {exc.strerror or exc}") from None
    except UnicodeDecodeError:
        raise InputError(f"{option} {path}: not a text file of references (bytes that are not "
                         "ASCII); the layout is in docs/log-formats.md, \"Reference files\"") from None
    except ValueError as exc:
        raise InputError(f"{option} {exc}") from None
    if not len(refs):
        raise InputError(f"{option} {path}: holds no reference (only its header)")
    return refs


def _row_line(path, index):
    """The line number of the ``index``-th record of a reference text file
    (its header is line 1; blank lines are skipped)."""
    with open(path, encoding="ascii") as f:
        n = -1
        for lineno, line in enumerate(f, 1):
            if lineno == 1 or not line.strip():
                continue
            n += 1
            if n == index:
                return lineno
    return None


#: the kinds each file option takes, and the option for the others
_FILE_KINDS = {"--gnss": ("gnss_pos", "gnss_vel"), "--speed-log": ("speed_log",), "--dvl": ("dvl",)}


def _reference_file(args, option, path, hz):
    """The references of ``--gnss FILE``, ``--speed-log FILE`` (NMEA 0183
    or the reference text layout) or ``--dvl FILE`` (the reference text
    layout), restricted to the option's kinds: (records, what the file
    gave, warnings); InputError when refused."""
    kinds = _FILE_KINDS[option]
    try:
        if os.path.isdir(path):
            raise InputError(f"{option} {path}: a directory, not a file of references")
        if os.path.getsize(path) == 0:
            raise InputError(f"{option} {path}: an empty file")
        nmea = nmea_files.is_nmea(path)
    except OSError as exc:
        raise InputError(f"{option} {path}: {exc.strerror or exc}") from None
    if nmea and option == "--dvl":
        raise InputError(f"{option} {path}: an NMEA 0183 file: a DVL's sentences (VBW's two ground-speed "
                         "axes) are not read; give its readings in the reference text layout, dvl rows of "
                         "the three axes (docs/log-formats.md, \"Reference files\")")
    if nmea:
        if args._utc_start is None:
            raise InputError(f"{option} {path}: an NMEA 0183 file, whose times are UTC: give --nmea-utc-start, "
                             "the UTC date and time of the log's start (tick 0), e.g. "
                             "--nmea-utc-start 2026-12-05T10:00:00.00")
        sig = args._sigmas
        try:
            got = nmea_files.read_nmea(
                path, args._utc_start, hz, kinds, pos_sigma_m=sig.get("--gnss-sigma"),
                vel_sigma_mps=sig.get("--gnss-vel-sigma"), log_sigma_mps=sig.get("--speed-log-sigma"),
                name=f"{option} {path}",
                option_names=dict(utc_start="--nmea-utc-start", pos_sigma="--gnss-sigma",
                                  vel_sigma="--gnss-vel-sigma", log_sigma="--speed-log-sigma"))
        except OSError as exc:
            raise InputError(f"{option} {path}: {exc.strerror or exc}") from None
        except nmea_files.NmeaError as exc:
            raise InputError(str(exc)) from None
        return got.refs, dict(option=option, file=path, **got.facts), got.warnings
    for sigma_option, _, _, _, owner in _SIGMAS:
        if owner == option and sigma_option in args._sigmas:
            raise InputError(f"{sigma_option}: {option} {path} is in the reference text layout, whose rows hold "
                             f"their sigmas (only an NMEA file takes {sigma_option}): drop it")
    try:
        with open(path, encoding="ascii") as f:
            head = f.readline().strip()
    except UnicodeDecodeError:
        head = None
    except OSError as exc:
        raise InputError(f"{option} {path}: {exc.strerror or exc}") from None
    if head != reference_files.CSV_HEADER:
        comp = logs.compression_of(path)
        what = (f"a {comp}-compressed file whose text is not NMEA 0183 (the reference text layout is read "
                "uncompressed)" if comp else "bytes that are not ASCII text" if head is None else None)
        raise InputError(f"{option} {path}:1: neither NMEA 0183 (sentences beginning with $ or !) nor the "
                         f"reference text layout (its header {reference_files.CSV_HEADER!r}; docs/log-formats.md, "
                         "\"Reference files\")" + (f": {what}" if what else ""))
    refs = _refs_csv(option, path)
    codes = {k: contract.REF_KINDS[k] for k in kinds}
    wrong = np.flatnonzero(~np.isin(refs["kind"], list(codes.values())))
    if len(wrong):
        i = int(wrong[0])
        name = reference_files.KIND_NAMES.get(int(refs["kind"][i]), "?")
        other = {"speed_log": "--speed-log or --refs", "gnss_pos": "--gnss or --refs",
                 "gnss_vel": "--gnss or --refs", "dvl": "--dvl or --refs"}.get(name, "--refs")
        raise InputError(f"{option} {path}:{_row_line(path, i)}: a {name} reference; {option} takes "
                         f"{' and '.join(kinds)} ({len(wrong)} rows are not): give the file to {other}")
    counts = {k: n for k, n in ((k, int(np.count_nonzero(refs["kind"] == c))) for k, c in codes.items()) if n}
    return refs, dict(option=option, file=path, format="reference text", references=counts), []


def _feed(args, cfg, hz):
    """The external references of --refs, --gnss, --speed-log, --dvl and
    --zero-velocity (a `pyins.aiding.BlockFeed`), or None; refused before
    the log runs when they cannot be used. The files' records are merged
    by tick (stable: --refs, --gnss, --speed-log, --dvl at one tick). The
    DVL's mounting (--dvl-align, --dvl-lever) goes into ``cfg``."""
    given = [o for o, v in (("--refs", args.refs), ("--gnss", args.gnss), ("--speed-log", args.speed_log),
                            ("--dvl", args.dvl), ("--zero-velocity", args.zero_velocity)) if v is not None]
    mounting = [o for o, v in (("--dvl-align", args.dvl_align), ("--dvl-lever", args.dvl_lever)) if v is not None]
    if not given:
        _dvl_mounting(args, cfg, mounting, None)     # refused: there is nothing they apply to
        _gnss_lever(args, cfg, None)
        _underway_refs(cfg, hz, None)
        return None
    if cfg.get("nav_mode") == abi.PYINS_NAV_UNDAMPED:
        raise InputError(f"{'/'.join(given)}: the scenario sets firmware.nav_mode = \"undamped\", "
                         "which takes no references")
    refs = zv = None
    parts, sources, notes = [], [], []
    if args.refs is not None:
        try:
            nmea = nmea_files.is_nmea(args.refs)
        except OSError:
            nmea = False         # said below, as load_refs_csv finds it
        if nmea:
            raise InputError(f"--refs {args.refs}: an NMEA 0183 file: give it to --gnss (GGA, RMC, VTG) or "
                             "--speed-log (VHW, VBW), with --nmea-utc-start")
        refs = _refs_csv("--refs", args.refs)
        parts.append(refs)
    for option, path in (("--gnss", args.gnss), ("--speed-log", args.speed_log), ("--dvl", args.dvl)):
        if path is not None:
            r, source, said = _reference_file(args, option, path, hz)
            parts.append(r)
            sources.append(source)
            notes.extend(said)
    if args._utc_start is not None and not any(s.get("format") == "NMEA 0183" for s in sources):
        raise InputError("--nmea-utc-start: applies to NMEA files; "
                         + " and ".join(f"{s['option']} {s['file']}" for s in sources)
                         + " " + ("is" if len(sources) == 1 else "are") + " in the reference text layout, "
                         "whose ticks are on the log's clock already: drop it")
    if parts:
        refs = np.concatenate(parts) if len(parts) > 1 else parts[0]
        refs = refs[np.argsort(refs["tick"], kind="stable")]
        pos = refs["kind"] == contract.REF_KINDS["gnss_pos"]
        if cfg.get("nav_mode") == abi.PYINS_NAV_DAMPED and np.any(pos):
            raise InputError(f"{'/'.join(given)}: {np.count_nonzero(pos)} GNSS position fixes, and the "
                             "scenario sets firmware.nav_mode = \"damped\", which takes none (its position "
                             "is dead reckoning): give velocity fixes alone (--refs with gnss_vel rows) or "
                             "another nav_mode")
    _dvl_mounting(args, cfg, mounting, refs)
    _gnss_lever(args, cfg, refs)
    _underway_refs(cfg, hz, refs)
    if args.zero_velocity is not None:
        zv = replay_options.quantity("--zero-velocity", args.zero_velocity, "velocity")
        if not (np.isfinite(zv) and zv > 0.0):
            raise InputError(f"--zero-velocity {args.zero_velocity!r}: a sigma must be more than 0 m/s")
    zv_from = cfg.get("coarse_ticks", 0) + cfg.get("fine_ticks", 0)
    return aiding.BlockFeed(refs, zv, zv_from, hz, sources=sources, notes=notes)


def _underway_refs(cfg, hz, refs):
    """A coarse alignment under way (fit_vel) refused before the log runs
    when no GNSS velocity reaches its first seconds: the firmware would
    only fault it at its end (the longest gap it takes: kCoarseRefGapS)."""
    if cfg.get("coarse_method") != abi.PYINS_COARSE_FIT_VEL or cfg.get("coarse_ticks", 0) <= 0:
        return
    gap = fw_config.COARSE_REF_GAP_S * hz
    vel = np.zeros(0, dtype=np.int64) if refs is None else \
        refs["tick"][refs["kind"] == contract.REF_KINDS["gnss_vel"]]
    if not np.any(vel <= gap):
        first = f"the first is at {vel.min() / hz:g} s" if vel.size else "none is given"
        raise InputError(f"--coarse-method fit_vel: the alignment under way takes the ship's motion from GNSS "
                         f"velocities from its first {fw_config.COARSE_REF_GAP_S} s on ({first}): give --gnss "
                         "(RMC or VTG) or --refs with gnss_vel rows")


def _gnss_lever(args, cfg, refs):
    """--gnss-lever into the firmware's gnss_lever_b_m (over the scenario's),
    refused when no GNSS fix is given or the firmware would refuse it."""
    if args.gnss_lever is None:
        return
    gnss = (contract.REF_KINDS["gnss_pos"], contract.REF_KINDS["gnss_vel"])
    if refs is None or not np.any(np.isin(refs["kind"], gnss)):
        raise InputError("--gnss-lever: applies to GNSS fixes (--gnss FILE or --refs FILE with gnss_pos or "
                         "gnss_vel rows), none is given")
    r = np.asarray(args.gnss_lever, dtype=float)
    if not (np.all(np.isfinite(r)) and np.sqrt(np.sum(r * r)) <= fw_config.MAX_LEVER_M):
        raise InputError("--gnss-lever {:g} {:g} {:g}: a lever arm at most {:g} m long".format(
            *args.gnss_lever, fw_config.MAX_LEVER_M))
    cfg["gnss_lever_b_m"] = r


def _dvl_mounting(args, cfg, mounting, refs):
    """--dvl-align, --dvl-lever into the firmware's dvl_align_rad,
    dvl_lever_b_m (over the scenario's), refused when no DVL reading is
    given or the firmware would refuse them."""
    if not mounting:
        return
    if refs is None or not np.any(refs["kind"] == contract.REF_KINDS["dvl"]):
        raise InputError(f"{mounting[0]}: applies to a DVL's readings (--dvl FILE or --refs FILE with dvl "
                         "rows), none is given")
    if args.dvl_align is not None:
        m = np.radians(np.asarray(args.dvl_align, dtype=float))
        if not (np.all(np.isfinite(m)) and np.sqrt(np.sum(m * m)) <= np.pi):
            raise InputError("--dvl-align {:g} {:g} {:g}: a rotation vector at most 180 deg long".format(
                *args.dvl_align))
        cfg["dvl_align_rad"] = m
    if args.dvl_lever is not None:
        r = np.asarray(args.dvl_lever, dtype=float)
        if not (np.all(np.isfinite(r)) and np.sqrt(np.sum(r * r)) <= fw_config.MAX_LEVER_M):
            raise InputError("--dvl-lever {:g} {:g} {:g}: a lever arm at most {:g} m long".format(
                *args.dvl_lever, fw_config.MAX_LEVER_M))
        cfg["dvl_lever_b_m"] = r


def _replay(args, path, fmt):
    dt = args.dt
    if args.time_col == "none" and dt is None and args.rate is not None:
        dt = 1.0 / args.rate      # --rate states the interval of a log without time (its --help)
    read_kw = dict(dt=dt, kind=args.kind, gyro_unit=args.gyro_unit, accel_unit=args.accel_unit,
                   axes=args.axes, time_col=args.time_col, gyro_scale=args.gyro_scale,
                   accel_scale=args.accel_scale)
    if args.table_angle is not None:
        read_kw["table_angle"] = np.radians(args.table_angle)
    if args.columns is not None:
        read_kw["columns"] = logs.parse_columns(args.columns, "--columns")
    # the log in blocks (bounded memory); opening it reads the probe: the rate, the header, the unit checks
    data = logs.LogReader(path, fmt, strict=not args.allow_gaps, name=args.log if path != args.log else None,
                          strict_hint="--allow-gaps replays it, bridging the gaps",
                          **{k: v for k, v in read_kw.items() if v is not None})
    blocks, bridge = data.blocks(), None
    if args.allow_gaps:     # the gaps, and the bridge, said when the log has been read
        bridge = logs.GapBridge(how="--allow-gaps")
        blocks = bridge.blocks(blocks)
    scn = None
    if args.scenario:
        scn = scenario.load(args.scenario)
    elif data.metadata.get("scenario"):
        scn = scenario.loads(data.metadata["scenario"], source=f"{args.log} (metadata)",
                             name=data.metadata.get("scenario_name"))
    cfg, spec = {}, None
    if scn is not None:
        specs = list(scn.runs())
        spec = specs[int(data.metadata.get("variant", 0)) if not args.scenario else 0]
        cfg = replay.replay_config(spec)

    # 1. the rate, the initial state and the firmware options, each as the user gave it;
    # 2. what the firmware cannot be right without, refused before it runs
    cfg, hz = replay_options.config(args, data, spec, cfg, say=lambda text: say(args, text))

    feed = _feed(args, cfg, hz)

    # 3. the log through the firmware
    out_dir = args.out or default_out("replay")
    every = args.every if args.every is not None else hz
    if args.reference is not None and spec is not None:
        raise InputError("--reference: the log's scenario is its reference already (drop --reference)")
    reference, truth_of = args.reference, spec
    if args.truth is not None:        # the errors against the track, not the scenario's truth
        if args.reference is not None:
            raise InputError("--truth: one reference at a time (--reference or --truth)")
        reference, truth_of = truth_track.read_track(args.truth), None
    def notes():        # the log's warnings (gaps), and the bridge's, kept in the summary
        return [*(data.warnings or ()), *([bridge.note()] if bridge is not None and bridge.note() else [])]

    bar = progress_bars(args)
    bar = bar(f"replaying {args.log}") if bar is not None and data.n else None
    try:
        summary = replay.replay(blocks, cfg, out_dir, every=every, spec=truth_of, engine=args.engine,
                                log_path=args.log, reference=reference,
                                t_first=data.metadata.get("t_first"), notes=notes, feed=feed,
                                progress=None if bar is None else (lambda done: bar(min(done, data.n), data.n)))
    except KeyboardInterrupt:
        if os.path.exists(os.path.join(out_dir, "summary.json")):
            print(f"\npyins replay: interrupted; the records so far are in {out_dir} (summary.json says "
                  f"\"interrupted\"): `pyins report {out_dir}` renders them", file=sys.stderr)
        else:
            print("\npyins replay: interrupted before the first record: nothing written", file=sys.stderr)
        return EXIT_INTERRUPTED
    page = report.render(out_dir)
    say(args, f"pyins replay {'standard input' if args.log == '-' else args.log}: {summary['samples']} samples at {hz} Hz "
               f"-> {out_dir}/navigation.npz")
    if "aligned" in summary:
        al = summary["aligned"]
        say(args, f"  aligned at {al['time_s']:g} s: pitch {al['pitch_deg']:.4f} deg, roll "
                   f"{al['roll_deg']:.4f} deg, heading {al['heading_deg']:.4f} deg")
    fa = summary.get("fine_alignment") or {}
    if "r_vrw_ug_sqrt_hz" in fa:
        measured = fa["measured_vrw_ug_sqrt_hz"]
        say(args, f"  fine alignment: R from {fa['r_vrw_ug_sqrt_hz']:.1f} ug/sqrt(Hz) ("
                   + ("measured in the coarse phase" if measured > 0.0 and measured == fa["r_vrw_ug_sqrt_hz"]
                      else "configured") + f"), heading sigma {fa['sigma_heading_arcmin']:.2f}', NIS {fa['nis']:.2f}")
    fin = summary["final"]
    faults = abi.fault_names(fin["fault_flags"])
    mode = report_replay.MODES.get(fin["mode"], f"mode {fin['mode']}")
    say(args, f"  final position {fin['lat_deg']:.6f} N {fin['lon_deg']:.6f} E, {mode}, "
               f"faults {', '.join(faults) or 'none'}")
    for src in summary.get("references", {}).get("sources", ()):
        say(args, "  " + report_replay.source_text(src))
    for name, k in summary.get("references", {}).get("kinds", {}).items():
        say(args, f"  references {name}: {k['given']} given, {k['used']} used, {k['rejected']} rejected by "
                   f"the gate" + (f", {k['stale']} repeats unused" if k["stale"] else "")
                   + (f", {k['skipped']} before navigation" if k["skipped"] else ""))
    for w in summary.get("warnings", ()):
        print(f"  WARNING: {w}", file=sys.stderr, flush=True)
    if "errors" in summary:
        er = summary["errors"]
        extra = (f", final heading {er['heading_final_arcmin']:.3f}'" if "heading_final_arcmin" in er
                 else f", max speed {er['speed_max_mps']:.3f} m/s" if "speed_max_mps" in er else "")
        if summary.get("navigating_records") == 0:
            say(args, f"  against {er['reference']}: nothing compared: no record is of navigation (the "
                       "alignment, which holds the site, covered the whole log)")
        else:
            say(args, f"  against {er['reference']}: max horizontal {er['horizontal_max_m']:.2f} m{extra}")
    say(args, f"  report: {page}")
    emit_json(args, summary)
    if "errors_missing" in summary:
        # the errors the user asked for do not exist: not a success
        raise InputError(f"--truth: {summary['errors_missing']} (the records are in {out_dir})")
    return EXIT_OK
