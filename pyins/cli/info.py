"""`pyins list`, `pyins bench` and `pyins version`: what is built in, how
fast the core runs here, which core is loaded."""
from pyins import __version__, bench, campaign, engine, logs, scenario, sim

from .common import EXIT_OK, InputError, emit_json


#: The examples each subcommand's --help ends with.
EXAMPLES = {
    'list': 'example:\n  pyins list --paths',
    'bench': 'example:\n  pyins bench --seconds 5 --json',
    'version': 'example:\n  pyins version',
}


def add_list(cmd):
    """`pyins list`: its subparser (``cmd(name, help)`` makes one) and options."""
    p = cmd("list", "list built-in scenarios, campaigns, presets, schemes and log formats")
    p.add_argument("--paths", action="store_true", help="show where the built-in files are")


def add_bench(cmd):
    """`pyins bench`: its subparser (``cmd(name, help)`` makes one) and options."""
    p = cmd("bench", "print benchmark figures (C++ firmware vs the NumPy reference)")
    p.add_argument("--seconds", type=float, default=3.0, help="time budget per figure [s]")


def add_version(cmd):
    """`pyins version`: its subparser (``cmd(name, help)`` makes one) and options."""
    cmd("version", "print the package and core versions")


def cmd_list(args):
    items = dict(scenarios=scenario.list_builtin(), sensor_presets=sorted(sim.PRESETS),
                 index_schemes=sorted(scenario.INDEX_SCHEMES))
    items["campaigns"] = campaign.list_builtin()
    items["log_formats"] = list(logs.FORMATS)
    if args.json:
        emit_json(args, items)
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


#: The longest --seconds of pyins bench (each of its figures takes about that long)
BENCH_MAX_S = 600.0


def cmd_bench(args):
    if not 0 < args.seconds <= BENCH_MAX_S:       # NaN too
        raise InputError(f"--seconds {args.seconds:g}: must be more than 0 and at most {BENCH_MAX_S:g} "
                         f"(the time budget of each figure)")
    fig = bench.run(seconds=args.seconds)
    if args.json:
        emit_json(args, fig)
    else:
        for line in bench.lines(fig):
            print(line)
    return EXIT_OK


def cmd_version(args):
    print(f"pyins {__version__}, core {engine.core_version()}"
          + (f" (ABI {engine.core_abi()})" if engine.core_abi() else ""))
    return EXIT_OK
