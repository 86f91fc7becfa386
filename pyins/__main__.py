"""Command line entry point: ``pyins`` / ``python -m pyins``.

Commands (``pyins COMMAND --help`` shows an example for each; docs/cli.md):

    run SCENARIO       run a built-in scenario or a TOML file into a run directory
    simulate SCENARIO  write the IMU log of a scenario (open loop, table fixed)
    replay LOG         run a recorded IMU log through the firmware
    report RUNDIR      (re)render the plots and report.html of a run directory
    campaign           grids and Monte-Carlo sets, local process pool or Dask
    budget SCENARIO    each sensor error's share of the position error (linear model)
    list               built-in scenarios, campaigns, presets, schemes, formats
    bench              benchmark figures (C++ vs the NumPy reference)
    demo               the main job of tools/setup.sh (2 h seed-002 swing)
    version            package and core versions

Exit codes: 0 success, 1 a run failed (firmware error), 2 bad input (usage,
scenario file, log file: one line naming the file, key and reason), 130
interrupted by Ctrl-C (a valid partial result is left). ``--debug`` shows
the traceback of an error.
"""
import json
import os
import sys
import time

import numpy as np

from pyins import (__version__, bench, budget, campaign, contract, engine, logs, metrics, open_loop, replay,
                   replay_options, report, run_scenario, rundir, scenario, sim, truth_track)
from pyins.cli_parser import build_parser
from pyins.progress import Phases, TextProgress, phase
from pyins.report.paper import paper_rows
from pyins.units import ARCMIN_TO_RAD, ARCSEC_TO_RAD, NMI_TO_M, TICK_HZ

_TICKS_PER_HOUR = 3600 * TICK_HZ


def _demo(args):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    motion = sim.HeadingSwing.experiment(1)
    sensors = sim.SensorModel(sim.preset(args.sensors), seed=args.seed)
    ticks = int(round(args.hours * _TICKS_PER_HOUR))
    t0 = time.perf_counter()

    def progress(done, total):
        if not args.quiet and sys.stdout.isatty():
            print(f"\r  {done / _TICKS_PER_HOUR:6.2f} h of {total / _TICKS_PER_HOUR:.2f} h ship time", end="",
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
    fig.savefig(plot, dpi=100)
    with open(os.path.join(args.out, "summary.json"), "w") as f:
        json.dump(summary, f, indent=2)
    print(f"pyins demo: {args.hours:g} h of ship time through the C++ firmware in {wall:.1f} s wall")
    print(f"  max horizontal position error {summary['max_horizontal_error_m']:.1f} m "
          f"({summary['max_horizontal_error_nmi']:.3f} nmi), final {summary['final_horizontal_error_m']:.1f} m")
    print(f"  max level error {summary['max_level_error_arcsec']:.2f} arcsec, "
          f"max heading error {summary['max_heading_error_arcmin']:.3f} arcmin, "
          f"max velocity error {summary['max_velocity_error_mps']:.4f} m/s")
    print(f"  plot: {plot}  figures: {os.path.join(args.out, 'summary.json')}")
    return 0


EXIT_OK, EXIT_FAILED, EXIT_INPUT, EXIT_INTERRUPTED = 0, 1, 2, 130
EXIT_BROKEN_PIPE = 141          #: 128 + SIGPIPE, as a shell reports a command its reader left


class InputError(Exception):
    """Bad input from the user: printed as one line, exit code 2."""


def _say(args, text):
    if not getattr(args, "quiet", False) and not getattr(args, "json", False):
        print(text, flush=True)


def _progress(args):
    if getattr(args, "quiet", False) or getattr(args, "json", False):
        return None

    def make(label):
        print(f"  {label}", file=sys.stderr, flush=True)
        return TextProgress()
    return make


def _phases(args):
    """A line on stderr per phase after the firmware (reading the records, the figures), or None."""
    return None if getattr(args, "quiet", False) or getattr(args, "json", False) else Phases()


def _emit_json(args, obj):
    if getattr(args, "json", False):
        print(json.dumps(obj, indent=2, default=float))


def _summary_lines(summary):
    out = []
    for v in summary["variants"]:
        m = v["metrics"]
        if not m:
            out.append(f"  {v['label']}: no records")
            continue
        out.append(f"  {v['label']}: max horizontal {m['horizontal_error_max']:.1f} m "
                   f"({m['horizontal_error_max'] / NMI_TO_M:.3f} nmi), "
                   f"final level {m['level_error_final'] / ARCSEC_TO_RAD:.2f}\", "
                   f"final heading {m['heading_error_final'] / ARCMIN_TO_RAD:.3f}'"
                   + ("" if v["complete"] else f"  [partial: {v['ticks_done']} of {v['ticks']} ticks]"))
    for r in paper_rows(summary):
        ours = "-" if r["ours"] is None else f"{r['ours']:.4g}"
        out.append(f"  paper {r['metric']} [{r['variant']}]: {r['relation']} {r['paper']:g} {r['unit']}"
                   f"; ours {ours} {r['unit']} {r['verdict']}")
    return out


def _default_out(name):
    return os.path.join("runs", name)


def _set_overrides(args):
    """The scenario overrides of --set KEY=VALUE (repeatable) and --hours."""
    overrides = {}
    for item in args.set or []:
        if "=" not in item:
            raise InputError(f"--set {item!r}: expected KEY=VALUE, e.g. --set duration=\"2 h\"")
        k, v = item.split("=", 1)
        overrides[k.strip()] = _toml_value(v.strip(), f"--set {k.strip()}")
    if args.hours is not None:
        overrides["duration"] = f"{args.hours} h"
    return overrides


def cmd_run(args):
    scn = scenario.load(args.scenario)
    overrides = _set_overrides(args)
    if args.seed is not None:
        overrides["seed"] = args.seed
    if overrides:
        scn = scn.with_overrides(overrides)
    out = args.out or _default_out(scn.name)
    _say(args, f"pyins run {scn.name}: {scn.title}\n  -> {out}")
    try:
        summary = run_scenario.execute(scn, out, progress=_progress(args), resume=args.resume,
                               log=None if args.quiet or args.json else print, engine=args.engine,
                               force=getattr(args, "force", False),
                               notice=lambda text: print(f"pyins run: note: {text}", file=sys.stderr))
    except KeyboardInterrupt:
        # no metrics or plots now (they can take longer than the user waits): the report reads the records
        print(f"\npyins run: interrupted; the partial result is in {out}: `pyins report {out}` renders "
              f"it, `pyins run ... --out {out} --resume` continues it", file=sys.stderr)
        return EXIT_INTERRUPTED
    path = report.render(out, progress=_phases(args))
    for line in _summary_lines(summary):
        _say(args, line)
    _say(args, f"  report: {path}")
    _emit_json(args, summary)
    return EXIT_OK


def _toml_value(text, where):
    """A --set value: TOML syntax if it parses ("2 h" with quotes, 3, [..]),
    else the bare text as a string (so --set duration=2h needs no quotes)."""
    import tomllib
    try:
        return tomllib.loads(f"v = {text}")["v"]
    except tomllib.TOMLDecodeError:
        return text


def cmd_simulate(args):
    scn = scenario.load(args.scenario)
    if args.hours is not None:
        scn = scn.with_overrides({"duration": f"{args.hours} h"})
    specs = list(scn.runs())
    if not 0 <= args.variant < len(specs):
        raise InputError(f"--variant {args.variant}: {scn.name} has {len(specs)} variant(s) (0..{len(specs) - 1})")
    spec = specs[args.variant]
    if spec.config.get("index_scheme", 0) != 0:
        _say(args, f"  note: the indexing scheme of {spec.label!r} is closed loop (the firmware commands the "
                   "table); the log is written with the table fixed at its initial angle. "
                   "Use `pyins run` for closed-loop runs.")
    alpha0 = float(spec.config.get("table_angle_rad", 0.0))
    sensors = sim.SensorModel(spec.errors, seed=spec.seed)
    fmt = logs.format_of(args.log, args.format)
    metadata = dict(scenario=scn.text, scenario_name=scn.name, variant=args.variant, digest=scn.digest())
    # written as the chunks come (bounded memory); the file appears under its name when complete
    n = 0
    with logs.LogWriter(args.log, fmt, dt=spec.dt, metadata=metadata) as log:
        for chunk in sim.generate(spec.motion, spec.duration_ticks, chunk_ticks=200_000,
                                  dt=spec.dt, table=sim.Fixed(alpha0), sensors=sensors, with_truth=False):
            log.write(sim.io.ImuData(tick=chunk.tick.astype(np.int64), dtheta_p=chunk.dtheta_p,
                                     dv_p=chunk.dv_p, table_angle_rad=chunk.table_angle, dt=spec.dt,
                                     metadata=metadata))
            n += len(chunk.tick)
    _say(args, f"pyins simulate {scn.name} [{spec.label}]: {n} samples "
               f"({n * spec.dt / 3600:.3g} h) -> {args.log} ({fmt})")
    _emit_json(args, dict(log=args.log, format=fmt, samples=n, scenario=scn.name,
                          variant=spec.label))
    return EXIT_OK


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
    cfg, hz = replay_options.config(args, data, spec, cfg, say=lambda text: _say(args, text))

    # 3. the log through the firmware
    out_dir = args.out or _default_out("replay")
    every = args.every if args.every is not None else hz
    if args.reference is not None and spec is not None:
        raise InputError("--reference: the log's scenario is its reference already (drop --reference)")
    reference, truth_of = args.reference, spec
    if args.truth is not None:        # the errors against the track, not the scenario's truth
        if args.reference is not None:
            raise InputError("--truth: one reference at a time (--reference or --truth)")
        reference, truth_of = truth_track.read_track(args.truth), None
    bar = _progress(args)
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
    _say(args, f"pyins replay {args.log}: {summary['samples']} samples at {hz} Hz "
               f"-> {out_dir}/navigation.npz")
    if "aligned" in summary:
        al = summary["aligned"]
        _say(args, f"  aligned at {al['time_s']:g} s: pitch {al['pitch_deg']:.4f} deg, roll "
                   f"{al['roll_deg']:.4f} deg, heading {al['heading_deg']:.4f} deg")
    fa = summary.get("fine_alignment") or {}
    if "r_vrw_ug_sqrt_hz" in fa:
        measured = fa["measured_vrw_ug_sqrt_hz"]
        _say(args, f"  fine alignment: R from {fa['r_vrw_ug_sqrt_hz']:.1f} ug/sqrt(Hz) ("
                   + ("measured in the coarse phase" if measured > 0.0 and measured == fa["r_vrw_ug_sqrt_hz"]
                      else "configured") + f"), heading sigma {fa['sigma_heading_arcmin']:.2f}', NIS {fa['nis']:.2f}")
    fin = summary["final"]
    _say(args, f"  final position {fin['lat_deg']:.6f} N {fin['lon_deg']:.6f} E, mode {fin['mode']}, "
               f"faults {fin['fault_flags']}")
    for w in summary.get("warnings", ()):
        print(f"  WARNING: {w}", file=sys.stderr, flush=True)
    if "errors" in summary:
        er = summary["errors"]
        extra = (f", final heading {er['heading_final_arcmin']:.3f}'" if "heading_final_arcmin" in er
                 else f", max speed {er['speed_max_mps']:.3f} m/s" if "speed_max_mps" in er else "")
        _say(args, f"  against {er['reference']}: max horizontal {er['horizontal_max_m']:.2f} m{extra}")
    _say(args, f"  report: {page}")
    _emit_json(args, summary)
    if "errors_missing" in summary:
        # the errors the user asked for do not exist: not a success
        raise InputError(f"--truth: {summary['errors_missing']} (the records are in {out_dir})")
    return EXIT_OK


def cmd_report(args):
    if report.is_replay_dir(args.rundir):      # pyins replay's directory: its own page
        path = report.render(args.rundir)
        _say(args, f"report: {path}")
        _emit_json(args, dict(report=path, complete=True))
        return EXIT_OK
    if rundir.read_summary(args.rundir) is None:
        what = ("the run stopped before it wrote its summary" if os.path.exists(
            os.path.join(args.rundir, "resolved_scenario.json")) else "not a run directory")
        raise InputError(f"{args.rundir}: {what} (no readable summary.json)")
    with phase(_phases(args), "report: reading the records"):
        summary, series = report.run.load(args.rundir)
    path = report.render(args.rundir, loaded=(summary, series), progress=_phases(args))
    partial = not summary.get("complete")
    _say(args, f"report: {path}" + (f"  [PARTIAL, {summary.get('stopped', 'interrupted')}: the figures "
                                    "cover the ticks done]" if partial else ""))
    _emit_json(args, dict(report=path, complete=not partial, stopped=summary.get("stopped"),
                          variants=summary["variants"]))
    return EXIT_OK


def cmd_list(args):
    items = dict(scenarios=scenario.list_builtin(), sensor_presets=sorted(sim.PRESETS),
                 index_schemes=sorted(scenario.INDEX_SCHEMES))
    items["campaigns"] = campaign.list_builtin()
    items["log_formats"] = list(logs.FORMATS)
    if args.json:
        _emit_json(args, items)
        return EXIT_OK
    print("built-in scenarios (pyins run NAME; the files: pyins list --paths):")
    for name, title in items["scenarios"]:
        extra = f"  [{scenario.builtin_path(name)}]" if args.paths else ""
        print(f"  {name:18s} {title}{extra}")
    if "campaigns" in items:
        print("built-in campaigns (pyins campaign NAME):")
        for name, title in items["campaigns"]:
            extra = f"  [{campaign.builtin_path(name)}]" if args.paths else ""
            print(f"  {name:18s} {title}{extra}")
    print("sensor presets:", ", ".join(items["sensor_presets"]))
    print("indexing schemes:", ", ".join(items["index_schemes"]))
    print("log formats:", ", ".join(items["log_formats"]))
    return EXIT_OK


def cmd_bench(args):
    fig = bench.run(seconds=args.seconds)
    if args.json:
        _emit_json(args, fig)
    else:
        for line in bench.lines(fig):
            print(line)
    return EXIT_OK


def cmd_campaign(args):
    if args.campaign and (args.grid or args.scenario):
        raise InputError("campaign: give a campaign (NAME or FILE) or --scenario with --grid, not both")
    if args.campaign:
        camp = campaign.load_campaign(args.campaign)
    elif args.scenario:
        camp = campaign.from_args(args.scenario, args.grid or [], args.seeds, args.group_by)
    else:
        raise InputError("campaign: give a campaign NAME or FILE, or --scenario with --grid (see --help)")
    out = args.out or campaign.default_out_dir(camp)
    _say(args, f"pyins campaign {camp.name} -> {out}")

    def progress(done, total, skipped=0):
        if not args.quiet and not args.json and sys.stderr.isatty():
            print(f"\r  {done}/{total} runs ({skipped} already done)", end="", file=sys.stderr, flush=True)
    try:
        result = campaign.run_campaign(camp, out, workers=args.workers, scheduler=args.scheduler,
                                       progress=progress,
                                       notice=lambda text: print(f"pyins campaign: note: {text}",
                                                                 file=sys.stderr))
    except KeyboardInterrupt as exc:
        ex = (getattr(exc, "result", None) or {}).get("execution", {})
        done = f"{ex['computed'] + ex['skipped']} of {ex['runs']} runs finished, " if ex else ""
        print(f"\npyins campaign: interrupted; {done}kept in {out}/runs; partial aggregates in "
              f"{os.path.join(out, 'aggregate.md')} (rerun the same command to resume)", file=sys.stderr)
        return EXIT_INTERRUPTED
    if not args.quiet and not args.json and sys.stderr.isatty():
        print(file=sys.stderr)
    _say(args, f"  aggregates: {os.path.join(out, 'aggregate.md')}")
    _emit_json(args, result)
    return EXIT_OK


def cmd_budget(args):
    """Each sensor error's signed share of a scenario's errors: the linear model of
    pyins.budget.run_budget on one closed-loop run per variant; --check runs every
    source alone through the firmware too (docs/concepts.md, "The error budget")."""
    scn = scenario.load(args.scenario)
    overrides = _set_overrides(args)
    if overrides:
        scn = scn.with_overrides(overrides)
    specs = list(scn.runs())
    if args.variant is not None:
        if not 0 <= args.variant < len(specs):
            raise InputError(f"--variant {args.variant}: the scenario has {len(specs)} variant(s), "
                             f"0 to {len(specs) - 1}")
        specs = [specs[args.variant]]
    result = []
    for spec in specs:
        _say(args, f"pyins budget {scn.name} [{spec.label}], {spec.duration_ticks / _TICKS_PER_HOUR:g} h"
                   + (", every source alone too" if args.check else ""))
        rows, shares = budget.run_budget(spec, check=args.check)
        for r in rows:
            line = (f"  {r['source']:19s} model N {r['model_north_m'] / NMI_TO_M:+8.3f}  "
                    f"E {r['model_east_m'] / NMI_TO_M:+8.3f}  final {r['model_final_m'] / NMI_TO_M:7.3f} nmi")
            if "fil_final_m" in r:
                line += (f"   FIL N {r['fil_north_m'] / NMI_TO_M:+8.3f}  E {r['fil_east_m'] / NMI_TO_M:+8.3f}"
                         f"  final {r['fil_final_m'] / NMI_TO_M:7.3f} nmi  rel. diff. "
                         f"{budget.budget_verdict(r)[1]}")
            _say(args, line)
        result.append(dict(label=spec.label, rows=rows,
                           eps_n_mean_rad_s={n: shares.eps_n_mean[i].tolist() for i, n in enumerate(shares.names)}))
    _emit_json(args, dict(scenario=scn.name, variants=result))
    return EXIT_OK


def main(argv=None):
    ap = build_parser(__doc__.split("\n\n")[1])
    args = ap.parse_args(argv)
    if getattr(args, "json", False):
        args.quiet = True
    handlers = dict(run=cmd_run, simulate=cmd_simulate, replay=cmd_replay, report=cmd_report,
                    campaign=cmd_campaign, list=cmd_list, bench=cmd_bench, budget=cmd_budget)
    try:
        if args.command == "demo":
            if args.sensors not in sim.PRESETS:
                ap.error(f"--sensors: unknown preset {args.sensors!r} (known: {', '.join(sim.PRESETS)})")
            if not args.hours > 0:
                ap.error("--hours: must be positive")
            return _demo(args)
        if args.command == "version":
            print(f"pyins {__version__}, core {engine.core_version()}" + (f" (ABI {engine.core_abi()})" if engine.core_abi() else ""))
            return EXIT_OK
        return handlers[args.command](args)
    except KeyboardInterrupt:
        print("pyins: interrupted", file=sys.stderr)
        return EXIT_INTERRUPTED
    except BrokenPipeError:
        # the reader closed the pipe (`pyins list | head`): not an error of
        # ours; stop writing, silence the interpreter's flush at exit
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
        return EXIT_BROKEN_PIPE
    except Exception as exc:   # one line for the user; --debug for the traceback
        if args.debug:
            raise
        if isinstance(exc, contract.CoreError):
            print(f"pyins {args.command}: firmware error: {exc}", file=sys.stderr)
            return EXIT_FAILED
        if isinstance(exc, (InputError, ValueError, OSError, ImportError)):
            msg = str(exc) if not isinstance(exc, OSError) or not exc.filename else \
                f"{exc.filename}: {exc.strerror}"
            print(f"pyins {args.command}: {msg.splitlines()[0] if msg else type(exc).__name__}",
                  file=sys.stderr)
            return EXIT_INPUT
        print(f"pyins {args.command}: internal error {type(exc).__name__}: {exc} (rerun with --debug)",
              file=sys.stderr)
        return EXIT_FAILED


if __name__ == "__main__":
    sys.exit(main())
