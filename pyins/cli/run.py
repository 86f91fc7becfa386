"""`pyins run`, `pyins report` and `pyins demo`: a scenario into a run
directory, a run directory's page, and the set-up's main job."""
import json
import os
import shlex
import sys
import time

import numpy as np

from pyins import engine, metrics, open_loop, records, report, run_scenario, rundir, scenario, sim
from pyins.progress import phase
from pyins.report.paper import paper_rows
from pyins.units import ARCMIN_TO_RAD, ARCSEC_TO_RAD, NMI_TO_M

from .common import (EXIT_INTERRUPTED, EXIT_OK, InputError, TICKS_PER_HOUR, check_hours, default_out, emit_json,
                     phases, progress_bars, say, set_overrides)


#: The examples each subcommand's --help ends with.
EXAMPLES = {
    'run': 'examples:\n  pyins run seed003\n  pyins run my_ship.toml --out runs/my_ship\n  pyins run seed002_exp1 --hours 6 --set indexing.stop="120 s"\n  pyins run seed002_exp1 --out runs/exp1 --resume   # continue after Ctrl-C or a kill\n  pyins run seed003 --hours 0.02 --engine reference  # through the NumPy mirror',
    'report': 'example:\n  pyins report runs/seed003',
    'demo': 'example:\n  pyins demo --hours 2 --sensors seed002',
}


def add_run(cmd):
    """`pyins run`: its subparser (``cmd(name, help)`` makes one) and options."""
    p = cmd("run", "run a built-in scenario or a TOML file into a run directory")
    p.add_argument("scenario", help="built-in name (pyins list) or a .toml file")
    p.add_argument("--out", help="run directory (default runs/NAME)")
    p.add_argument("--hours", type=float, help="override the duration [h]")
    p.add_argument("--seed", type=int, help="override the noise seed")
    p.add_argument("--set", action="append", metavar="KEY=VALUE", help="override a scenario key (repeatable)")
    p.add_argument("--variant", type=int, metavar="N",
                   help="run only [compare] variant N (0 = the first; default: every variant)")
    p.add_argument("--resume", action="store_true", help="continue an interrupted run in --out")
    p.add_argument("--force", action="store_true", help="replace a run of another scenario in --out")
    p.add_argument("--engine", choices=engine.ENGINES, default="native",
                   help="the firmware and plant: native (compiled, default) or reference (NumPy mirror)")


def add_report(cmd):
    """`pyins report`: its subparser (``cmd(name, help)`` makes one) and options."""
    p = cmd("report", "(re)render the plots and report.html of a run directory")
    p.add_argument("rundir")


def add_demo(cmd):
    """`pyins demo`: its subparser (``cmd(name, help)`` makes one) and options."""
    p = cmd("demo", "the main job of tools/setup.sh: 2 h of seed 002's swing, errors and a plot")
    p.add_argument("--hours", type=float, default=2.0, help="ship time [h] (default 2)")
    p.add_argument("--sensors", default="seed002",
                      help="sensor error preset: error_free, seed000, seed001, seed002, seed003")
    p.add_argument("--seed", type=int, default=1, help="noise seed")
    p.add_argument("--out", default=os.path.join("runs", "setup_demo"),
                   help="output directory (default runs/setup_demo: `pyins run demo` writes runs/demo)")


def check_out(out):
    """--out checked: a directory or nothing yet (InputError naming it)."""
    if os.path.exists(out) and not os.path.isdir(out):
        raise InputError(f"--out {out}: a file, not a directory: give a directory (new or a run's)")
    return out


def _summary_lines(summary):
    out = []
    for v in summary["variants"]:
        m = v["metrics"]
        if not m:
            out.append(f"  {v['label']}: no records")
            continue
        where = (f"max horizontal {m['horizontal_error_max']:.1f} m "
                 f"({m['horizontal_error_max'] / NMI_TO_M:.3f} nmi), " if "horizontal_error_max" in m
                 else "alignment only (the site is held: no position error), ")
        out.append(f"  {v['label']}: {where}"
                   f"final level {m['level_error_final'] / ARCSEC_TO_RAD:.2f}\", "
                   f"final heading {m['heading_error_final'] / ARCMIN_TO_RAD:.3f}'"
                   + ("" if v["complete"] else f"  [partial: {v['ticks_done']} of {v['ticks']} ticks]"))
    for r in paper_rows(summary):
        ours = "-" if r["ours"] is None else f"{r['ours']:.4g}"
        out.append(f"  paper {r['metric']} [{r['variant']}]: {r['relation']} {r['paper']:g} {r['unit']}"
                   f"; ours {ours} {r['unit']} {r['verdict']}")
    return out


def _resume_command(args, out):
    """The command that continues this run: the same scenario and overrides, --out, --resume."""
    words = ["pyins", "run", args.scenario, "--out", out]
    if args.hours is not None:
        words += ["--hours", f"{args.hours:g}"]
    if args.seed is not None:
        words += ["--seed", str(args.seed)]
    for item in args.set or []:
        words += ["--set", item]
    if getattr(args, "variant", None) is not None:
        words += ["--variant", str(args.variant)]
    if args.engine != "native":
        words += ["--engine", args.engine]
    return " ".join(shlex.quote(w) for w in words + ["--resume"])


def cmd_run(args):
    check_hours(args.hours)
    if args.out is not None:
        check_out(args.out)
    scn = scenario.load(args.scenario)
    overrides = set_overrides(args)
    if args.seed is not None:
        overrides["seed"] = args.seed
    if overrides:
        scn = scn.with_overrides(overrides)
    if args.variant is not None:
        scn = scn.only_variant(args.variant)
    out = check_out(args.out or default_out(scn.name))

    def started():
        say(args, f"pyins run {scn.name}: {scn.title}\n  -> {out}")
        for note in scn.notes:
            print(f"pyins run: note: {note}", file=sys.stderr)
    try:
        summary = run_scenario.execute(scn, out, progress=progress_bars(args), resume=args.resume,
                               log=None if args.quiet or args.json else print, engine=args.engine,
                               force=getattr(args, "force", False),
                               notice=lambda text: print(f"pyins run: note: {text}", file=sys.stderr),
                               started=started)
    except KeyboardInterrupt:
        # no metrics or plots now (they can take longer than the user waits): the report reads the records
        print(f"\npyins run: interrupted; the partial result is in {out}: `pyins report {shlex.quote(out)}` "
              f"renders it, `{_resume_command(args, out)}` continues it", file=sys.stderr)
        return EXIT_INTERRUPTED
    path = report.render(out, progress=phases(args))
    for line in _summary_lines(summary):
        say(args, line)
    say(args, f"  report: {path}")
    emit_json(args, summary)
    return EXIT_OK


def cmd_report(args):
    if report.is_replay_dir(args.rundir):      # pyins replay's directory: its own page
        summary = rundir.read_summary(args.rundir)
        path = report.render(args.rundir)
        complete = summary.get("complete") is not False
        stopped = None if complete else (summary.get("warnings") or ["interrupted"])[0]
        say(args, f"report: {path}" + ("" if complete else f"  [PARTIAL, {stopped}]"))
        emit_json(args, dict(report=path, complete=complete, stopped=stopped, state=summary.get("state"),
                             warnings=summary.get("warnings", [])))
        return EXIT_OK
    rundir.summary_for_report(args.rundir)       # a damaged summary: one line naming it, before any phase
    with phase(phases(args), "report: reading the records"):
        summary, series = report.run.load(args.rundir)
    path = report.render(args.rundir, loaded=(summary, series), progress=phases(args))
    partial = not summary.get("complete")
    for w in summary.get("report_warnings", []):
        print(f"pyins report: WARNING: {w}", file=sys.stderr)
    say(args, f"report: {path}" + (f"  [PARTIAL, {summary.get('stopped', 'interrupted')}: the figures "
                                    "cover the ticks done]" if partial else ""))
    emit_json(args, dict(report=path, complete=not partial, stopped=summary.get("stopped"),
                          warnings=summary.get("report_warnings", []), variants=summary["variants"]))
    return EXIT_OK


def cmd_demo(args):
    check_hours(args.hours)
    if args.seed < 0:
        raise InputError(f"--seed {args.seed}: must be >= 0")
    check_out(args.out)
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    held = rundir.read_summary(args.out)
    if isinstance(held, dict) and "variants" in held:
        raise InputError(f"--out {args.out}: holds a `pyins run` of {held.get('scenario')!r}; the demo "
                         "would overwrite its summary.json: give another --out")
    motion = sim.HeadingSwing.experiment(1)
    sensors = sim.SensorModel(sim.preset(args.sensors), seed=args.seed)
    ticks = int(round(args.hours * TICKS_PER_HOUR))
    t0 = time.perf_counter()

    def progress(done, total):
        if not args.quiet and sys.stdout.isatty():
            print(f"\r  {done / TICKS_PER_HOUR:6.2f} h of {total / TICKS_PER_HOUR:.2f} h ship time", end="",
                  flush=True)

    result = open_loop.navigate(motion, ticks, every=100, sensors=sensors, progress=progress)
    wall = time.perf_counter() - t0
    if not args.quiet and sys.stdout.isatty():
        print()
    e = metrics.nav_errors(result)
    arcsec, arcmin = ARCSEC_TO_RAD, ARCMIN_TO_RAD
    summary = {
        "scenario": "seed 002 experiment 1 heading swing, IMU fixed to the ship",
        "sensors": args.sensors,
        "ship_time_h": args.hours,
        "wall_time_s": wall,
        "final_horizontal_error_m": float(e.horizontal_m[-1]),
        "max_horizontal_error_m": float(e.horizontal_m.max()),
        "max_horizontal_error_nmi": float(e.horizontal_m.max() / NMI_TO_M),
        "max_level_error_arcsec": float(np.abs(e.att_n_rad[:, :2]).max() / arcsec),
        "max_heading_error_arcmin": float(np.abs(e.att_n_rad[:, 2]).max() / arcmin),
        "max_velocity_error_mps": float(np.abs(e.vel_n_mps[:, :2]).max()),
        "core_version": engine.core_version(),
    }
    os.makedirs(args.out, exist_ok=True)
    th = e.time_s / 3600.0
    fig, ax = plt.subplots(3, 1, figsize=(8, 9), sharex=True)
    ax[0].plot(th, e.north_m, label="north")
    ax[0].plot(th, e.east_m, label="east")
    ax[0].plot(th, e.horizontal_m, "k", label="horizontal")
    ax[0].set_ylabel("position error [m]")
    ax[0].legend()
    ax[1].plot(th, e.att_n_rad[:, 0] / arcsec, label="phi_E")
    ax[1].plot(th, e.att_n_rad[:, 1] / arcsec, label="phi_N")
    ax[1].set_ylabel("level error [arcsec]")
    ax[1].legend()
    ax[2].plot(th, e.att_n_rad[:, 2] / arcmin, label="phi_U (heading)")
    ax[2].set_ylabel("heading error [arcmin]")
    ax[2].set_xlabel("ship time [h]")
    ax[2].legend()
    fig.suptitle(f"pyins demo: {summary['scenario']}, sensors {args.sensors}")
    fig.tight_layout()
    plot = os.path.join(args.out, "navigation_errors.png")
    records.write_atomic(plot, write=lambda f: fig.savefig(f, format="png", dpi=100), sync=False)
    records.write_atomic(os.path.join(args.out, "summary.json"), json.dumps(summary, indent=2))
    say(args, f"pyins demo: {args.hours:g} h of ship time through the C++ firmware in {wall:.1f} s wall")
    say(args, f"  max horizontal position error {summary['max_horizontal_error_m']:.1f} m "
              f"({summary['max_horizontal_error_nmi']:.3f} nmi), final {summary['final_horizontal_error_m']:.1f} m")
    say(args, f"  max level error {summary['max_level_error_arcsec']:.2f} arcsec, "
              f"max heading error {summary['max_heading_error_arcmin']:.3f} arcmin, "
              f"max velocity error {summary['max_velocity_error_mps']:.4f} m/s")
    say(args, f"  plot: {plot}  figures: {os.path.join(args.out, 'summary.json')}")
    emit_json(args, summary)
    return EXIT_OK
