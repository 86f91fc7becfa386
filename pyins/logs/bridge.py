"""Gap bridging: every skipped tick of a log filled in by the firmware's
rule (`bridge_gaps` whole, `GapBridge` in blocks)."""
import numpy as np

from pyins.logs.issues import _plural
from pyins.logs.project import ImuData


def _bridged(data, how, warnings):
    """(bridged ImuData, ticks added) of one piece of a log: see `bridge_gaps`."""
    tick = np.asarray(data.tick, dtype=np.int64)
    steps = np.diff(tick)
    gaps = np.nonzero(steps > 1)[0]
    if gaps.size == 0:
        return data, 0
    pieces = {"tick": [], "dtheta_p": [], "dv_p": [], "table_angle_rad": []}
    start = 0
    for k in gaps:
        m = int(steps[k] - 1)
        j = np.arange(1, m + 1)
        w = (j / (m + 1.0))[:, None]
        for key in ("dtheta_p", "dv_p"):
            a = getattr(data, key)
            pieces[key] += [a[start:k + 1], a[k] + (a[k + 1] - a[k]) * w]
        ang = data.table_angle_rad
        turn = np.mod(ang[k + 1] - ang[k] + np.pi, 2.0 * np.pi) - np.pi
        pieces["table_angle_rad"] += [ang[start:k + 1], ang[k] + turn * w[:, 0]]
        pieces["tick"] += [tick[start:k + 1], tick[k] + j]
        start = k + 1
    for key in pieces:
        pieces[key].append((tick if key == "tick" else getattr(data, key))[start:])
    return ImuData(np.concatenate(pieces["tick"]), np.concatenate(pieces["dtheta_p"]),
                   np.concatenate(pieces["dv_p"]), np.concatenate(pieces["table_angle_rad"]),
                   data.dt, data.metadata), int(np.sum(steps[gaps] - 1))


def _bridge_note(source, added, how):
    return (f"{source}: {_plural(added, 'missing tick')} bridged by linear interpolation "
            f"of the neighbouring samples ({how}); the motion in them is not in the log")


def bridge_gaps(data, how="bridge_gaps"):
    """``data`` with every skipped tick filled in, and the number of ticks added.

    The rule is the firmware's own for a sequence gap in navigation
    (docs/core.md, "skipped ticks"): the increments of the j-th of m missing
    ticks are interpolated linearly between the sample before the gap and the
    one after it, ``x_prev + (x_next - x_prev) * j / (m + 1)``, the table angle
    along the shorter turn between its two readings. What moved during the
    gap is not in the log, so the bridge is a guess that keeps the clock right
    (each sample is one tick to the firmware): callers say that they used it.
    `GapBridge` does the same to a log in blocks.

    The result's ``metadata["warnings"]`` is the input's (the gaps as
    `read_log` found them) and, when ticks were added, a last line saying how
    many and that ``how`` bridged them.
    """
    warnings = list(data.metadata.get("warnings", ()))
    out, added = _bridged(data, how, warnings)
    if not added:
        data.metadata["warnings"] = warnings
        return data, 0
    source = data.metadata.get("source", "the log")
    warnings.append(_bridge_note(source, added, how))
    out.metadata = dict(data.metadata, bridged_ticks=added, warnings=warnings)
    return out, added


class GapBridge:
    """`bridge_gaps` over a log in blocks: ``GapBridge(how).blocks(reader.blocks())``
    yields the blocks with every skipped tick filled in, the same samples,
    bit for bit, as `bridge_gaps` on the whole log (a gap across a block
    boundary is bridged from the last sample of the block before, kept for
    it). ``added``: the ticks added so far; `note`: the line `bridge_gaps`
    appends to the warnings, once the blocks are out (None when none was
    added)."""

    def __init__(self, how="bridge_gaps"):
        self.how, self.added, self.source = how, 0, "the log"

    def blocks(self, blocks):
        prev = None
        for data in blocks:
            self.source = data.metadata.get("source", "the log")
            if prev is not None and len(data.tick) and data.tick[0] - prev.tick[-1] > 1:
                ext = ImuData(np.concatenate((prev.tick[-1:], data.tick)),
                              np.concatenate((prev.dtheta_p[-1:], data.dtheta_p)),
                              np.concatenate((prev.dv_p[-1:], data.dv_p)),
                              np.concatenate((prev.table_angle_rad[-1:], data.table_angle_rad)),
                              data.dt, data.metadata)
                out, added = _bridged(ext, self.how, None)
                out = ImuData(out.tick[1:], out.dtheta_p[1:], out.dv_p[1:],
                              out.table_angle_rad[1:], out.dt, out.metadata)
            else:
                out, added = _bridged(data, self.how, None)
            self.added += added
            if len(data.tick):
                prev = data
            yield out

    def note(self):
        return _bridge_note(self.source, self.added, self.how) if self.added else None
