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
import os
import sys

from pyins import contract, sim
from pyins.cli import parser
from pyins.cli.common import EXIT_BROKEN_PIPE, EXIT_FAILED, EXIT_INPUT, EXIT_INTERRUPTED, EXIT_OK, InputError

#: The entry point and the exit codes (callers and tests read them here).
__all__ = ["main", "EXIT_OK", "EXIT_FAILED", "EXIT_INPUT", "EXIT_INTERRUPTED", "EXIT_BROKEN_PIPE", "InputError"]


def main(argv=None):
    ap = parser.build_parser(__doc__.split("\n\n")[1])
    args = ap.parse_args(argv)
    if getattr(args, "json", False):
        args.quiet = True
    try:
        if args.command == "demo":
            if args.sensors not in sim.PRESETS:
                ap.error(f"--sensors: unknown preset {args.sensors!r} (known: {', '.join(sim.PRESETS)})")
            if not args.hours > 0:
                ap.error("--hours: must be positive")
        return parser.handler(args.command)(args)
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
