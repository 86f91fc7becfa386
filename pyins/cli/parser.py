"""The command line's grammar: every subcommand in the order ``pyins --help``
lists them, each with the options and examples its own module gives
(`add_<command>`, ``EXAMPLES``). What the commands take, refuse and leave
after Ctrl-C is in docs/cli.md."""
import argparse
from argparse import RawDescriptionHelpFormatter as Raw

from . import info, replay, run, simulate, study

#: (module, command) in the order of ``pyins --help``.
COMMANDS = ((run, "run"), (simulate, "simulate"), (replay, "replay"), (run, "report"), (study, "campaign"),
            (info, "list"), (info, "bench"), (run, "demo"), (info, "version"), (study, "budget"))


def build_parser(description):
    """The ``pyins`` parser; ``description`` heads its --help."""
    ap = argparse.ArgumentParser(prog="pyins", description=description, formatter_class=Raw)
    ap.add_argument("--debug", action="store_true", help="show tracebacks")
    sub = ap.add_subparsers(dest="command", required=True, metavar="COMMAND")

    def cmd(name, help_, module):
        p = sub.add_parser(name, help=help_, description=help_, epilog=module.EXAMPLES[name], formatter_class=Raw)
        p.add_argument("--quiet", action="store_true", help="no progress or summary lines")
        p.add_argument("--json", action="store_true", help="print the result as JSON (implies --quiet)")
        p.add_argument("--debug", action="store_true", default=argparse.SUPPRESS, help="show tracebacks")
        return p

    for module, name in COMMANDS:
        getattr(module, f"add_{name}")(lambda name_, help_, m=module: cmd(name_, help_, m))
    return ap


def handler(command):
    """The function that runs ``command`` (``cmd_<command>`` of its module)."""
    module = dict((name, m) for m, name in COMMANDS)[command]
    return getattr(module, f"cmd_{command}")
