"""What every figure of pyins shares: matplotlib for files, margins, the
time axis, and the two things that keep a long run's figure readable and
cheap: a min/max envelope of each curve (`envelope`: at most `MAX_POINTS`
points a line, every peak kept) and the window of a few turntable cycles a
zoom panel shows (`cycle_window`).

matplotlib is imported when a figure is first drawn (not with pyins), on its
Agg backend: files only, no display.
"""
import math

import numpy as np

from pyins.units import UNITS

__all__ = ["pyplot", "margins", "time_axis", "envelope", "line", "cycle_window", "MAX_POINTS"]

#: at most this many points per plotted line: a 72 h run at 1 Hz has 259,200
#: records, and a figure is 800-1100 px wide
MAX_POINTS = 4000


def pyplot():
    """matplotlib.pyplot on the Agg backend."""
    import matplotlib
    matplotlib.use("Agg")              # files only, no display
    import matplotlib.pyplot as plt
    return plt


def margins(fig, labels, rot, wspace=0.06):
    """Margins from the length of the tick labels (tight_layout costs as much
    as drawing the figure twice): 8-pt text is about 6 px a character at 90 dpi."""
    w_px, h_px = fig.get_size_inches() * 90
    n = max((len(s) for s in labels), default=0) * 6.0
    bottom = (n * math.sin(math.radians(rot)) + 12 if rot else 14) + 30
    left = max(60.0, n * math.cos(math.radians(rot)) - 0.5 * (w_px / 2) / max(len(labels), 1)
               if rot else 60.0)
    fig.subplots_adjust(left=min(left / w_px, 0.3), right=0.985, top=0.86,
                        bottom=min(bottom / h_px, 0.5), wspace=wspace)


def time_axis(t_s):
    """Times [s] in the unit that reads best over their span, and its label:
    hours beyond 3 h, minutes beyond 20 min, else seconds."""
    span = t_s[-1] if len(t_s) else 0.0
    if span > 3 * UNITS["time"]["h"]:
        return t_s / UNITS["time"]["h"], "time [h]"
    if span > 20 * UNITS["time"]["min"]:
        return t_s / UNITS["time"]["min"], "time [min]"
    return t_s, "time [s]"


def envelope(x, y, max_points=MAX_POINTS):
    """(x, y) of one curve with at most ``max_points`` points: the samples
    split into equal buckets, the smallest and the largest of each kept in
    their order (and the first and last sample), so the line drawn through
    them covers what the whole curve covers at any width the figure has.
    A stride would alias: a 120 s rotation cycle sampled every 65 s draws a
    slow wave that is not there. NaN samples are skipped within a bucket."""
    x, y = np.asarray(x), np.asarray(y, dtype=float)
    n = len(y)
    if n <= max_points:
        return x, y
    m = max(1, max_points // 2 - 2)            # buckets of k samples; 2 per bucket + the ends + a tail
    k = -(-n // m)
    m = n // k
    blk = y[:m * k].reshape(m, k)
    nan = np.isnan(blk)
    lo = np.argmin(np.where(nan, np.inf, blk), axis=1)
    hi = np.argmax(np.where(nan, -np.inf, blk), axis=1)
    base = np.arange(m) * k
    parts = [base + lo, base + hi, [0, n - 1]]
    if m * k < n:
        tail = y[m * k:]
        parts.append(m * k + np.array([np.nanargmin(tail), np.nanargmax(tail)]
                                      if not np.isnan(tail).all() else [0]))
    idx = np.unique(np.concatenate(parts).astype(np.int64))
    return x[idx], y[idx]


def line(ax, t, y, *args, log=False, **kw):
    """One curve drawn through its min/max envelope (`envelope`), on a
    logarithmic y axis when ``log``; ``args``, ``kw`` as for ax.plot."""
    x, y = envelope(t, y)
    return (ax.semilogy if log else ax.plot)(x, y, *args, **kw)


def cycle_window(index_step, index_state, cycles=3, min_cycles=8):
    """The record slice of ``cycles`` turntable cycles (from the first
    stop-or-move change on), for a zoom panel; None when the run has fewer
    than ``min_cycles`` (the whole run then reads without one). A cycle is
    every step of the scheme once (``index_step`` 0..n-1), each a stop and a
    move: 2 n changes of ``index_state``."""
    index_state = np.asarray(index_state)
    n_steps = int(np.max(index_step)) + 1 if len(index_step) else 1
    changes = np.flatnonzero(np.diff(index_state) != 0) + 1
    per_cycle = 2 * n_steps
    if len(changes) < min_cycles * per_cycle:
        return None
    start = changes[0]
    stop = changes[cycles * per_cycle]
    margin = max(1, (stop - start) // 40)
    return slice(max(0, start - margin), min(len(index_state), stop + margin))
