"""`pyins simulate`: a scenario's IMU log written as a field log would be."""
import numpy as np

from pyins import logs, scenario, sim

from .common import EXIT_OK, InputError, emit_json, say


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


def cmd_simulate(args):
    scn = scenario.load(args.scenario)
    if args.hours is not None:
        scn = scn.with_overrides({"duration": f"{args.hours} h"})
    specs = list(scn.runs())
    if not 0 <= args.variant < len(specs):
        raise InputError(f"--variant {args.variant}: {scn.name} has {len(specs)} variant(s) (0..{len(specs) - 1})")
    spec = specs[args.variant]
    if spec.config.get("index_scheme", 0) != 0:
        say(args, f"  note: the indexing scheme of {spec.label!r} is closed loop (the firmware commands the "
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
    say(args, f"pyins simulate {scn.name} [{spec.label}]: {n} samples "
               f"({n * spec.dt / 3600:.3g} h) -> {args.log} ({fmt})")
    emit_json(args, dict(log=args.log, format=fmt, samples=n, scenario=scn.name,
                          variant=spec.label))
    return EXIT_OK
