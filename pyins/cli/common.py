"""What every subcommand shares: the exit codes, the one error class for
bad input, the progress and summary lines, --json, --set and the default
output directory."""
import json
import math
import os
import sys
import time

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


def finite_json(obj, reasons=None, path=""):
    """``obj`` with every NaN and infinity made None (JSON has no such
    numbers): ``reasons`` (a dict, filled in) gets ``path: "not finite
    (inf)"`` for each one a caller did not explain itself."""
    if isinstance(obj, dict):
        return {k: finite_json(v, reasons, f"{path}.{k}" if path else str(k)) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [finite_json(v, reasons, f"{path}[{i}]") for i, v in enumerate(obj)]
    if isinstance(obj, float) or type(obj).__module__ == "numpy" and hasattr(obj, "dtype") and obj.ndim == 0:
        try:
            x = float(obj)
        except (TypeError, ValueError):
            return obj
        if math.isfinite(x):
            return x if isinstance(obj, float) or obj.dtype.kind == "f" else obj.item()
        if reasons is not None:
            reasons.setdefault(path, f"not finite ({x})")
        return None
    if type(obj).__module__ == "numpy" and hasattr(obj, "tolist"):
        return finite_json(obj.tolist(), reasons, path)
    return obj


def emit_json(args, obj):
    """``obj`` as JSON on stdout (with --json): always valid JSON, a NaN or an
    infinity is null and listed with its reason under "null_values" (callers
    that know why put their own reason there first)."""
    if getattr(args, "json", False):
        reasons = {}
        clean = finite_json(obj, reasons)
        if reasons and isinstance(clean, dict):
            clean["null_values"] = dict(clean.get("null_values") or {}, **reasons)
        print(json.dumps(clean, indent=2, allow_nan=False, default=str))


#: The longest run a scenario takes (its duration's limit, 30 d)
MAX_HOURS = 720.0


def check_hours(hours, option="--hours"):
    """--hours checked: a finite ship time, > 0 and at most MAX_HOURS (InputError naming the option)."""
    if hours is not None and not (math.isfinite(hours) and 0 < hours <= MAX_HOURS):
        raise InputError(f"{option} {hours:g}: must be a ship time in hours, > 0 and at most {MAX_HOURS:g} (30 d)")
    return hours


def progress_hook(args, label):
    """A progress callable ``progress(done, total)`` (ticks) for a long step
    of a subcommand (``pyins simulate``, a budget's runs): prints ``label``,
    then a bar with the time left on a terminal; None with --quiet/--json.
    Any subcommand may call it."""
    if getattr(args, "quiet", False) or getattr(args, "json", False):
        return None
    print(f"  {label}", file=sys.stderr, flush=True)
    return TextProgress()


class CountProgress:
    """``progress(done, total, skipped=0)`` over a count of items (a
    campaign's runs, a budget's runs): on a terminal one line redrawn with
    the count and the time left (ETA from the items done here, not the
    ones found already done); elsewhere (a pipe, a CI log) a plain line at
    most every ``every_s`` seconds and at the end. ``end()`` closes it."""

    def __init__(self, what, enabled=True, stream=None, every_s=10.0):
        self.what, self.enabled, self.every_s = what, enabled, every_s
        self.stream = stream if stream is not None else sys.stderr
        self.tty = hasattr(self.stream, "isatty") and self.stream.isatty()
        self.t0, self.first, self.last_print, self.drawn = time.perf_counter(), None, 0.0, False

    def line(self, done, total, skipped=0):
        el = time.perf_counter() - self.t0
        here = done - (self.first if self.first is not None else done)
        left = total - done
        eta = f", about {el / here * left:.0f} s left" if here > 0 and left > 0 else ""
        already = f" ({skipped} already done)" if skipped else ""
        return f"  {done}/{total} {self.what}{already}, {el:.0f} s{eta}"

    def __call__(self, done, total, skipped=0):
        if not self.enabled:
            return
        if self.first is None:
            self.first, self.t0 = done, time.perf_counter()
        now = time.perf_counter()
        text = self.line(done, total, skipped)
        if self.tty:
            self.stream.write(f"\r{text}   ")
            self.drawn = True
        elif done >= total or now - self.last_print >= self.every_s:
            self.stream.write(text + "\n")
            self.last_print = now
        self.stream.flush()

    def end(self):
        if self.enabled and self.tty and self.drawn:
            self.stream.write("\n")
            self.stream.flush()
            self.drawn = False


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
