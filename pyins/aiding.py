"""Runs with external references: samples and time-tagged references
through either engine, each reference pushed when it is available.

The firmware takes a reference ahead of its tick (it waits in the
instance's queue, 8 deep, up to 10 s ahead) or after it (up to
``ref_max_latency_ticks``, the position carried forward by the velocity).
`run_with_refs` plays a log or a simulation the way a ship's computer would
see it: each reference is pushed at its availability tick (its tick plus
the receiver's latency, when given), else as early as the queue allows, so
the firmware applies it at exactly its own tick.
"""
import numpy as np

from . import contract

__all__ = ["run_with_refs"]

#: How far ahead of its tick a reference is pushed when no availability is
#: given [ticks at 100 Hz]: half the firmware's 10 s horizon.
_AHEAD_S = 5


def _tick(fw):
    return int(fw.nav()["tick"])


def run_with_refs(fw, samples, refs, every=100, avail_tick=None, compact=False, tick_hz=100):
    """Step ``samples`` (SAMPLE_DTYPE, one per tick from the firmware's
    current tick on) through ``fw`` (either engine), pushing ``refs``
    (REF_DTYPE, sorted by tick) as they become available.

    ``avail_tick`` (N,) the tick at which each reference reaches the
    firmware (>= its tick: latency); None pushes each up to 5 s ahead of its
    tick. Returns the records after each step whose tick is a multiple of
    ``every`` (OUTPUT_DTYPE, or NAV_DTYPE with ``compact``). A reference the
    firmware refuses raises contract.RefError (its index in ``refs``).
    Assumes one tick per sample (no seq gaps): a log with gaps is the
    replay's to split.
    """
    samples = contract.check_samples(samples)
    refs = contract.check_refs(refs)
    if refs.shape[0] and np.any(np.diff(refs["tick"]) < 0):
        raise ValueError("refs: ticks must not decrease")
    if avail_tick is None:
        push_at = refs["tick"] - _AHEAD_S * tick_hz
    else:
        push_at = np.asarray(avail_tick, dtype=np.int64)
        if push_at.shape != refs.shape or np.any(push_at < refs["tick"]):
            raise ValueError("avail_tick: one tick per reference, none before the reference's own tick")
        if np.any(np.diff(push_at) < 0):
            raise ValueError("avail_tick: must not decrease")
    run = fw.run_nav if compact else (lambda s, every: fw.run(s, every=every))
    t0 = _tick(fw)
    n = samples.shape[0]
    parts, i, j = [], 0, 0
    queued = []          # ticks of references pushed ahead and not yet due
    while True:
        now = t0 + i
        queued = [t for t in queued if t > now]
        while j < len(refs) and push_at[j] <= now:
            if refs["tick"][j] > now and len(queued) == 8:
                break
            try:
                fw.push_ref(refs[j:j + 1])
            except contract.RefError as e:
                raise contract.RefError(e.code, j) from None
            if refs["tick"][j] > now:
                queued.append(int(refs["tick"][j]))
            j += 1
        if i >= n:
            break
        stop = n
        if j < len(refs):
            nxt = int(push_at[j]) if not (queued and len(queued) == 8) else queued[0]
            stop = min(stop, max(nxt - t0, i + 1))
        if len(queued) == 8:
            stop = min(stop, max(queued[0] - t0, i + 1))
        parts.append(run(samples[i:stop], every))
        i = stop
    dtype = contract.NAV_DTYPE if compact else contract.OUTPUT_DTYPE
    return np.concatenate(parts) if parts else np.zeros(0, dtype=dtype)
