"""`pyins replay`: a recorded IMU log through the firmware, its errors
against a reference, its page."""
import os
import sys

import numpy as np

from pyins import engine, logs, replay, replay_options, report, scenario, truth_track

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


def cmd_replay(args):
    read_kw = dict(dt=args.dt, kind=args.kind, gyro_unit=args.gyro_unit, accel_unit=args.accel_unit,
                   axes=args.axes, time_col=args.time_col, gyro_scale=args.gyro_scale,
                   accel_scale=args.accel_scale)
    if args.table_angle is not None:
        read_kw["table_angle"] = np.radians(args.table_angle)
    if args.columns is not None:
        read_kw["columns"] = logs.parse_columns(args.columns, "--columns")
    # the log in blocks (bounded memory); opening it reads the probe: the rate, the header, the unit checks
    data = logs.LogReader(args.log, args.format, strict=not args.allow_gaps,
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
    bar = progress_bars(args)
    bar = bar(f"replaying {args.log}") if bar is not None and data.n else None
    try:
        summary = replay.replay(blocks, cfg, out_dir, every=every, spec=truth_of, engine=args.engine,
                                log_path=args.log, reference=reference, t_first=data.metadata.get("t_first"),
                                progress=None if bar is None else (lambda done: bar(min(done, data.n), data.n)))
    except KeyboardInterrupt:
        if os.path.exists(os.path.join(out_dir, "summary.json")):
            print(f"\npyins replay: interrupted; the records so far are in {out_dir} (summary.json says "
                  f"\"interrupted\"): `pyins report {out_dir}` renders them", file=sys.stderr)
        else:
            print("\npyins replay: interrupted before the first record: nothing written", file=sys.stderr)
        return EXIT_INTERRUPTED
    for w in data.warnings + ([bridge.note()] if bridge is not None and bridge.note() else []):
        print(f"  WARNING: {w}", file=sys.stderr, flush=True)
    page = report.render(out_dir)
    say(args, f"pyins replay {args.log}: {summary['samples']} samples at {hz} Hz "
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
    say(args, f"  final position {fin['lat_deg']:.6f} N {fin['lon_deg']:.6f} E, mode {fin['mode']}, "
               f"faults {fin['fault_flags']}")
    for w in summary.get("warnings", ()):
        print(f"  WARNING: {w}", file=sys.stderr, flush=True)
    if "errors" in summary:
        er = summary["errors"]
        extra = (f", final heading {er['heading_final_arcmin']:.3f}'" if "heading_final_arcmin" in er
                 else f", max speed {er['speed_max_mps']:.3f} m/s" if "speed_max_mps" in er else "")
        say(args, f"  against {er['reference']}: max horizontal {er['horizontal_max_m']:.2f} m{extra}")
    say(args, f"  report: {page}")
    emit_json(args, summary)
    if "errors_missing" in summary:
        # the errors the user asked for do not exist: not a success
        raise InputError(f"--truth: {summary['errors_missing']} (the records are in {out_dir})")
    return EXIT_OK
