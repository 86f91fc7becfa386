"""`pyins simulate`: a scenario's IMU log written as a field log would be."""
import os
import sys

import numpy as np

from pyins import logs, scenario, sim
from pyins.sim import references

from .common import EXIT_OK, InputError, check_hours, emit_json, progress_hook, say


#: The examples each subcommand's --help ends with.
EXAMPLES = {
    'simulate': 'example:\n  pyins simulate demo imu.npz --hours 0.5\n  pyins simulate seed000_static imu.txt',
}


def add_simulate(cmd):
    """`pyins simulate`: its subparser (``cmd(name, help)`` makes one) and options."""
    p = cmd("simulate", "write the IMU log of a scenario (open loop, table fixed)")
    p.add_argument("scenario")
    p.add_argument("log", help="output file: .npz, .csv, .txt, .bin")
    p.add_argument("--format", help="npz, csv, text, binary (default: from the extension)")
    p.add_argument("--hours", type=float)
    p.add_argument("--variant", type=int, default=0, help="which [compare] variant (default 0)")
    p.add_argument("--refs", metavar="FILE",
                   help="also write the scenario's external references ([references]: GNSS fixes, "
                        "zero velocity) to FILE on the log's clock, for `pyins replay --refs FILE` "
                        "(docs/log-formats.md, \"Reference files\")")


def _load_for_a_log(name, hours):
    """The scenario, with --hours; a [firmware] key the loader refuses (an
    alignment longer than the run, ...) is left out, as the log does not use
    the firmware: (Scenario, [notes on what was ignored])."""
    import tomllib
    text, path = scenario.read_toml_source(name, scenario.builtin_path)
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError:
        return scenario.load(name), []          # its own one-line error
    if hours is not None:
        data["duration"] = f"{hours} h"
    notes = []
    for _ in range(len(data.get("firmware", {})) + 1):
        try:
            return scenario.Scenario(text, data, str(path), path.stem), notes
        except scenario.ScenarioError as exc:
            section, _, key = exc.key.partition(".")
            if section != "firmware" or key not in data.get("firmware", {}):
                raise
            del data["firmware"][key]
            notes.append(f"{exc.key} ignored: the IMU log does not use the firmware ({exc.reason})")
    return scenario.Scenario(text, data, str(path), path.stem), notes


def cmd_simulate(args):
    check_hours(args.hours)
    if args.format is not None and args.format not in logs.FORMATS:
        raise InputError(f"--format {args.format}: not one of {', '.join(logs.FORMATS)}")
    try:
        logs.format_of(args.log, args.format)
    except ValueError:
        raise InputError(f"{args.log}: cannot tell the format from the extension: give --format "
                         f"({', '.join(logs.FORMATS)}) or a known extension ({', '.join(logs.EXTENSIONS)})") from None
    scn, notes = _load_for_a_log(args.scenario, args.hours)
    for note in notes:
        print(f"pyins simulate: note: {note}", file=sys.stderr)
    specs = list(scn.runs())
    if not 0 <= args.variant < len(specs):
        raise InputError(f"--variant {args.variant}: {scn.name} has {len(specs)} variant(s) (0..{len(specs) - 1})")
    spec = specs[args.variant]
    if spec.config.get("index_scheme", 0) != 0:
        say(args, f"  note: the indexing scheme of {spec.label!r} is closed loop (the firmware commands the "
                   "table); the log is written with the table fixed at its initial angle. "
                   "Use `pyins run` for closed-loop runs.")
    if args.refs is not None and spec.refs is None:
        raise InputError(f"--refs {args.refs}: the scenario {scn.name} has no [references] to write")
    alpha0 = float(spec.config.get("table_angle_rad", 0.0))
    sensors = sim.SensorModel(spec.errors, seed=spec.seed)
    fmt = logs.format_of(args.log, args.format)
    metadata = dict(scenario=scn.text, notes=notes, scenario_name=scn.name, variant=args.variant, digest=scn.digest())
    # written as the chunks come (bounded memory); the file appears under its name when complete
    n = 0
    bar = progress_hook(args, f"simulating {spec.duration_ticks * spec.dt / 3600:.3g} h of {scn.name} [{spec.label}]")
    with logs.LogWriter(args.log, fmt, dt=spec.dt, metadata=metadata) as log:
        for chunk in sim.generate(spec.motion, spec.duration_ticks, chunk_ticks=200_000,
                                  dt=spec.dt, table=sim.Fixed(alpha0), sensors=sensors, with_truth=False):
            log.write(sim.io.ImuData(tick=chunk.tick.astype(np.int64), dtheta_p=chunk.dtheta_p,
                                     dv_p=chunk.dv_p, table_angle_rad=chunk.table_angle, dt=spec.dt,
                                     metadata=metadata))
            n += len(chunk.tick)
            if bar is not None:
                bar(n, spec.duration_ticks)
    say(args, f"pyins simulate {scn.name} [{spec.label}]: {n} samples "
               f"({n * spec.dt / 3600:.3g} h) -> {args.log} ({fmt})")
    done = dict(log=args.log, format=fmt, samples=n, scenario=scn.name, variant=spec.label, notes=notes)
    if args.refs is not None:
        # whole or not at all, as the log (a temporary name renamed)
        part = f"{args.refs}.part{os.getpid()}"
        try:
            references.save_refs_csv(part, spec.refs)
            os.replace(part, args.refs)
        except OSError as exc:
            raise InputError(f"--refs {args.refs}: {exc.strerror or exc}") from None
        finally:
            if os.path.exists(part):
                os.remove(part)
        say(args, f"  {len(spec.refs)} references ({', '.join(sorted({references.KIND_NAMES[int(k)] for k in spec.refs['kind']}))}) "
                   f"-> {args.refs}")
        done["refs"] = args.refs
    emit_json(args, done)
    return EXIT_OK
