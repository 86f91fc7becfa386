"""The progress line of a long run on a terminal."""
import sys
import time

from pyins.units import DT


class TextProgress:
    """A one-line progress bar on stderr: ship time done, ticks per second,
    time left. Silent when stderr is not a terminal (CI, pipes). Called as
    ``progress(done_ticks, total_ticks)``."""

    def __init__(self, dt=DT, stream=None, width=30):
        self.dt, self.width = dt, width
        self.stream = stream if stream is not None else sys.stderr
        self.t0 = time.perf_counter()
        self.active = hasattr(self.stream, "isatty") and self.stream.isatty()

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
