"""The command line's grammar: every subcommand, its options and their
help, and the examples its --help ends with (`build_parser`). What each
subcommand does is in `pyins.__main__`; what it takes, refuses and leaves
after Ctrl-C is in docs/cli.md."""
import argparse
import os
from argparse import RawDescriptionHelpFormatter as Raw

from pyins import engine, logs, replay, scenario

EXAMPLES = {
    "run": "examples:\n  pyins run seed003\n  pyins run my_ship.toml --out runs/my_ship\n"
           "  pyins run seed002_exp1 --hours 6 --set indexing.stop=\"120 s\"\n"
           "  pyins run seed002_exp1 --out runs/exp1 --resume   # continue after Ctrl-C or a kill\n"
           "  pyins run seed003 --hours 0.02 --engine reference  # through the NumPy mirror",
    "simulate": "example:\n  pyins simulate demo imu.npz --hours 0.5\n  pyins simulate seed000_static imu.txt",
    "replay": "examples:\n  pyins replay imu.npz                       # initial state from the log's scenario\n"
              "  pyins replay field.txt --kind rates --gyro-unit deg/s --accel-unit g --axes frd \\\n"
              "      --lat 34.246 --lon 108.91 --height 380 --coarse 150 --fine 600\n"
              "  pyins replay log200.txt --time-col first --axes frd --lat 34.246 --lon 108.91 \\\n"
              "      --height 0 --coarse 300 --coarse-method fit   # the rate (200 Hz) from the time column",
    "report": "example:\n  pyins report runs/seed003",
    "campaign": "examples:\n  pyins campaign seed000_static\n"
                "  pyins campaign --scenario seed000_static --grid motion.heading=\"0 deg,60 deg\" --seeds 5\n"
                "  pyins campaign seed000_static --scheduler tcp://127.0.0.1:8786",
    "list": "example:\n  pyins list --paths",
    "bench": "example:\n  pyins bench --seconds 5 --json",
    "demo": "example:\n  pyins demo --hours 2 --sensors seed002",
    "version": "example:\n  pyins version",
    "budget": "examples:\n  pyins budget seed002_exp2 --variant 1   # the traditional two-position scheme\n"
              "  pyins budget seed003 --hours 6 --check   # every source alone through the firmware too",
}


def build_parser(description):
    """The ``pyins`` parser; ``description`` heads its --help."""
    ap = argparse.ArgumentParser(prog="pyins", description=description, formatter_class=Raw)
    ap.add_argument("--debug", action="store_true", help="show tracebacks")
    sub = ap.add_subparsers(dest="command", required=True, metavar="COMMAND")

    def cmd(name, help_):
        p = sub.add_parser(name, help=help_, description=help_, epilog=EXAMPLES[name], formatter_class=Raw)
        p.add_argument("--quiet", action="store_true", help="no progress or summary lines")
        p.add_argument("--json", action="store_true", help="print the result as JSON (implies --quiet)")
        p.add_argument("--debug", action="store_true", default=argparse.SUPPRESS, help="show tracebacks")
        return p

    p = cmd("run", "run a built-in scenario or a TOML file into a run directory")
    p.add_argument("scenario", help="built-in name (pyins list) or a .toml file")
    p.add_argument("--out", help="run directory (default runs/NAME)")
    p.add_argument("--hours", type=float, help="override the duration [h]")
    p.add_argument("--seed", type=int, help="override the noise seed")
    p.add_argument("--set", action="append", metavar="KEY=VALUE", help="override a scenario key (repeatable)")
    p.add_argument("--resume", action="store_true", help="continue an interrupted run in --out")
    p.add_argument("--force", action="store_true", help="replace a run of another scenario in --out")
    p.add_argument("--engine", choices=engine.ENGINES, default="native",
                   help="the firmware and plant: native (compiled, default) or reference (NumPy mirror)")
    p = cmd("simulate", "write the IMU log of a scenario (open loop, table fixed)")
    p.add_argument("scenario")
    p.add_argument("log", help="output file: .npz, .csv, .txt, .bin")
    p.add_argument("--format", help="npz, csv, text, binary (default: from the extension)")
    p.add_argument("--hours", type=float)
    p.add_argument("--variant", type=int, default=0, help="which [compare] variant (default 0)")
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
    p.add_argument("--every", type=int, help="record every N samples (default: one a second)")
    p.add_argument("--reference", choices=replay.REFERENCES,
                   help="errors against: parked = the site (--lat/--lon/--height) and zero velocity")
    p.add_argument("--truth", metavar="FILE",
                   help="errors against a reference trajectory: a text file with a header line naming "
                        "t, lat_deg, lon_deg [, height_m, heading_deg], t on the log's clock "
                        "(docs/cli.md, \"pyins replay\")")
    p.add_argument("--out", help="output directory (default runs/replay)")
    p.add_argument("--engine", choices=engine.ENGINES, default="native",
                   help="the firmware: native (compiled, default) or reference (NumPy mirror)")
    p = cmd("report", "(re)render the plots and report.html of a run directory")
    p.add_argument("rundir")
    p = cmd("campaign", "grids and Monte-Carlo sets on a local process pool or a Dask cluster")
    p.add_argument("campaign", nargs="?", help="built-in campaign name or a campaign .toml file")
    p.add_argument("--scenario", help="base scenario for --grid")
    p.add_argument("--grid", action="append", metavar="KEY=V1,V2,...")
    p.add_argument("--seeds", help="a count N (0..N-1), a list 0,3,7 or a range 2..6 (default: the scenario's)")
    p.add_argument("--group-by", action="append", help="grid keys to group by (default: all but seed)")
    p.add_argument("--workers", type=int, help="local processes (default: every core)")
    p.add_argument("--scheduler", help="Dask scheduler address, e.g. tcp://host:8786")
    p.add_argument("--out", help="campaign directory (default runs/campaign_NAME)")
    p = cmd("list", "list built-in scenarios, campaigns, presets, schemes and log formats")
    p.add_argument("--paths", action="store_true", help="show where the built-in files are")
    p = cmd("bench", "print benchmark figures (C++ firmware vs the NumPy reference)")
    p.add_argument("--seconds", type=float, default=3.0, help="time budget per figure [s]")
    demo = cmd("demo", "the main job of tools/setup.sh: 2 h of seed 002's swing, errors and a plot")
    demo.add_argument("--hours", type=float, default=2.0, help="ship time [h] (default 2)")
    demo.add_argument("--sensors", default="seed002",
                      help="sensor error preset: error_free, seed000, seed001, seed002, seed003")
    demo.add_argument("--seed", type=int, default=1, help="noise seed")
    demo.add_argument("--out", default=os.path.join("runs", "demo"), help="output directory")
    cmd("version", "print the package and core versions")
    p = cmd("budget", "each sensor error's share of a scenario's errors (linear model, one FIL run per variant)")
    p.add_argument("scenario", help="built-in name (pyins list) or a .toml file")
    p.add_argument("--hours", type=float, help="override the duration [h]")
    p.add_argument("--set", action="append", metavar="KEY=VALUE", help="override a scenario key (repeatable)")
    p.add_argument("--variant", type=int, help="only this [compare] variant (0, 1, ...; default all)")
    p.add_argument("--check", action="store_true", help="run every source alone through the firmware too")
    return ap
