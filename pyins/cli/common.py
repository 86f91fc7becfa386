"""What every subcommand shares: the exit codes, the one error class for
bad input, the progress and summary lines, --json, --set and the default
output directory."""
import json
import os
import sys

from pyins.progress import Phases, TextProgress
from pyins.units import TICK_HZ


TICKS_PER_HOUR = 3600 * TICK_HZ

EXIT_OK, EXIT_FAILED, EXIT_INPUT, EXIT_INTERRUPTED = 0, 1, 2, 130
EXIT_BROKEN_PIPE = 141          #: 128 + SIGPIPE, as a shell reports a command its reader left


class InputError(Exception):
    """Bad input from the user: printed as one line, exit code 2."""


def say(args, text):
    if not getattr(args, "quiet", False) and not getattr(args, "json", False):
        print(text, flush=True)


def progress_bars(args):
    if getattr(args, "quiet", False) or getattr(args, "json", False):
        return None

    def make(label):
        print(f"  {label}", file=sys.stderr, flush=True)
        return TextProgress()
    return make


def phases(args):
    """A line on stderr per phase after the firmware (reading the records, the figures), or None."""
    return None if getattr(args, "quiet", False) or getattr(args, "json", False) else Phases()


def emit_json(args, obj):
    if getattr(args, "json", False):
        print(json.dumps(obj, indent=2, default=float))


def default_out(name):
    return os.path.join("runs", name)


def set_overrides(args):
    """The scenario overrides of --set KEY=VALUE (repeatable) and --hours."""
    overrides = {}
    for item in args.set or []:
        if "=" not in item:
            raise InputError(f"--set {item!r}: expected KEY=VALUE, e.g. --set duration=\"2 h\"")
        k, v = item.split("=", 1)
        overrides[k.strip()] = toml_value(v.strip(), f"--set {k.strip()}")
    if args.hours is not None:
        overrides["duration"] = f"{args.hours} h"
    return overrides


def toml_value(text, where):
    """A --set value: TOML syntax if it parses ("2 h" with quotes, 3, [..]),
    else the bare text as a string (so --set duration=2h needs no quotes)."""
    import tomllib
    try:
        return tomllib.loads(f"v = {text}")["v"]
    except tomllib.TOMLDecodeError:
        return text
