"""What every figure of pyins shares: matplotlib for files, and margins.

matplotlib is imported when a figure is first drawn (not with pyins), on its
Agg backend: files only, no display.
"""
import math

from pyins.units import UNITS

__all__ = ["pyplot", "margins", "time_axis"]


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
