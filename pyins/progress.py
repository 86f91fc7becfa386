"""Progress on stderr: the bar of a long firmware run (`TextProgress`) and a
line for each phase after it (`Phases`: the metrics and time series of a
variant, reading the records, each figure, the page), so no step of
``pyins run`` or ``pyins report`` that takes seconds passes without a word.

The bar redraws itself with ``\\r`` and is drawn only on a terminal; a phase
line is one plain line (``  plots: errors.png ... 0.4 s``) written on a
terminal and to a pipe or a CI log alike. Both are quiet when the command
is (``--quiet``, ``--json``: the CLI then passes no progress at all).
"""
import sys
import time

from pyins.units import DT

__all__ = ["TextProgress", "Phases", "phase"]


class _Phase:
    """One phase line: its name when it starts, its duration when it ends
    (the same line), "stopped" when an exception (Ctrl-C) ends it."""

    def __init__(self, stream, text):
        self.stream, self.text, self.t0 = stream, text, None

    def __enter__(self):
        self.t0 = time.perf_counter()
        self.stream.write(f"{self.text} ... ")
        self.stream.flush()
        return self

    def __exit__(self, exc_type, *exc):
        self.stream.write("stopped\n" if exc_type is not None else f"{time.perf_counter() - self.t0:.1f} s\n")
        self.stream.flush()
        return False


class _Nothing:
    def __enter__(self):
        return self

    def __exit__(self, *exc):
        return False


class Phases:
    """``with phases("plots: errors.png"): ...`` writes ``  plots:
    errors.png ... 0.4 s`` on ``stream`` (default stderr), each line
    prefixed with ``indent``."""

    def __init__(self, stream=None, indent="  "):
        self.stream = stream if stream is not None else sys.stderr
        self.indent = indent

    def __call__(self, text):
        return _Phase(self.stream, f"{self.indent}{text}")


def phase(progress, text):
    """The context of a phase for ``progress`` (a `Phases`, an object with
    a ``phase`` method such as `TextProgress`, or None: nothing)."""
    if progress is None:
        return _Nothing()
    if callable(getattr(progress, "phase", None)):
        return progress.phase(text)
    if isinstance(progress, Phases):
        return progress(text)
    return _Nothing()


class TextProgress:
    """A one-line progress bar on stderr: ship time done, ticks per second,
    time left. The bar is silent when stderr is not a terminal (CI, pipes).
    Called as ``progress(done_ticks, total_ticks)``; ``phase(text)`` gives
    the line of a phase after the run (`Phases`), written to a terminal and
    a pipe alike."""

    def __init__(self, dt=DT, stream=None, width=30):
        self.dt, self.width = dt, width
        self.stream = stream if stream is not None else sys.stderr
        self.t0 = time.perf_counter()
        self.active = hasattr(self.stream, "isatty") and self.stream.isatty()
        self._phases = Phases(self.stream, indent="    ")

    def phase(self, text):
        """The context of one phase of this run's work after the firmware."""
        return self._phases(text)

    def __call__(self, done, total):
        if not self.active:
            return
        el = time.perf_counter() - self.t0
        rate = done / el if el > 0 else 0.0
        left = (total - done) / rate if rate > 0 else float("nan")
        n = int(self.width * done / total)
        self.stream.write(f"\r[{'#' * n}{'.' * (self.width - n)}] {done * self.dt / 3600:.2f}/"
                          f"{total * self.dt / 3600:.2f} h ship time, {rate / 1e6:.2f} M ticks/s, "
                          f"{left:.0f} s left ")
        if done >= total:
            self.stream.write("\n")
        self.stream.flush()
