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

__all__ = ["Aider", "run_with_refs"]

#: How far ahead of its tick a reference is pushed when no availability is
#: given [ticks at 100 Hz]: half the firmware's 10 s horizon.
_AHEAD_S = 5


def _tick(fw):
    return int(fw.nav()["tick"])


class Aider:
    """References for one firmware instance, pushed as the run reaches
    their availability: `run` steps a block of samples (call it block after
    block: the references carry over).

    ``refs`` REF_DTYPE sorted by tick; ``avail_tick`` (N,) the tick at which
    each reaches the firmware (>= its tick: the latency), None to push each
    up to 5 s ahead of its tick (the firmware then applies it at exactly
    its tick). A reference the firmware refuses raises contract.RefError
    with its index in ``refs``.
    """

    def __init__(self, refs, avail_tick=None, tick_hz=100):
        self.refs = contract.check_refs(refs)
        if self.refs.shape[0] and np.any(np.diff(self.refs["tick"]) < 0):
            raise ValueError("refs: ticks must not decrease")
        if avail_tick is None:
            self.push_at = self.refs["tick"] - _AHEAD_S * tick_hz
        else:
            self.push_at = np.asarray(avail_tick, dtype=np.int64)
            if self.push_at.shape != self.refs.shape or np.any(self.push_at < self.refs["tick"]):
                raise ValueError("avail_tick: one tick per reference, none before the reference's own tick")
            if np.any(np.diff(self.push_at) < 0):
                raise ValueError("avail_tick: must not decrease")
        self.j = 0           # the next reference to push
        self.queued = []     # ticks of references pushed ahead and not yet due

    def _push_due(self, fw, now):
        self.queued = [t for t in self.queued if t > now]
        refs, push_at = self.refs, self.push_at
        while self.j < len(refs) and push_at[self.j] <= now:
            j = self.j
            if refs["tick"][j] > now and len(self.queued) == 8:
                break
            try:
                fw.push_ref(refs[j:j + 1])
            except contract.RefError as e:
                raise contract.RefError(e.code, j) from None
            if refs["tick"][j] > now:
                self.queued.append(int(refs["tick"][j]))
            self.j += 1

    def run(self, fw, samples, every=100, compact=False):
        """Step ``samples`` (one per tick from the firmware's current tick
        on; no seq gaps) through ``fw`` (either engine), pushing the
        references that come due; the records after each step whose tick is
        a multiple of ``every`` (OUTPUT_DTYPE, or NAV_DTYPE with ``compact``)."""
        samples = contract.check_samples(samples)
        call = fw.run_nav if compact else (lambda s, every: fw.run(s, every=every))
        t0 = _tick(fw)
        n = samples.shape[0]
        parts, i = [], 0
        while True:
            self._push_due(fw, t0 + i)
            if i >= n:
                break
            stop = n
            if len(self.queued) == 8:       # full: the next push waits for the oldest to be due
                stop = min(stop, max(self.queued[0] - t0, i + 1))
            elif self.j < len(self.refs):
                stop = min(stop, max(int(self.push_at[self.j]) - t0, i + 1))
            parts.append(call(samples[i:stop], every))
            i = stop
        dtype = contract.NAV_DTYPE if compact else contract.OUTPUT_DTYPE
        return np.concatenate(parts) if parts else np.zeros(0, dtype=dtype)


def run_with_refs(fw, samples, refs, every=100, avail_tick=None, compact=False, tick_hz=100):
    """`Aider` (refs, avail_tick) over one block of samples: the records."""
    return Aider(refs, avail_tick, tick_hz).run(fw, samples, every, compact)
