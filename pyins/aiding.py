"""Runs with external references: samples and time-tagged references
through either engine, each reference pushed when it is available.

The firmware takes a reference ahead of its tick (it waits in the
instance's queue, 8 deep, up to 10 s ahead) or after it (up to
``ref_max_latency_ticks``, the position carried forward by the velocity).
`run_with_refs` plays a log or a simulation the way a ship's computer would
see it: each reference is pushed at its availability tick (its tick plus
the receiver's latency, when given), else as early as the queue allows, so
the firmware applies it at exactly its own tick. `Aider` is the one
implementation, for the open loop (`pyins.open_loop`) and the closed one
(`pyins.fil`).
"""
import hashlib

import numpy as np

from . import contract

__all__ = ["Aider", "BlockFeed", "concat", "run_with_refs"]

#: How far ahead of its tick a reference is pushed when no availability is
#: given [ticks at 100 Hz]: half the firmware's 10 s horizon.
_AHEAD_S = 5


def _tick(fw):
    return int(fw.nav()["tick"])


def concat(parts, dtype):
    """The record arrays ``parts`` end to end (``dtype`` when there are
    none): one array, the same bytes as np.concatenate, without its field
    promotion, which costs ~25 us a part for a structured dtype (a 72 h run
    with a 1 Hz GNSS joins ~260,000 parts)."""
    if len(parts) == 1:
        return parts[0]
    out = np.empty(sum(len(p) for p in parts), dtype=parts[0].dtype if parts else dtype)
    i = 0
    for p in parts:
        out[i:i + len(p)] = p
        i += len(p)
    return out


class Aider:
    """References for one firmware instance, pushed as the run reaches
    their availability: `run` steps a block of samples (call it block after
    block: the references carry over). A loop that steps the firmware
    itself (`pyins.fil`, whose plant steps it inside C) calls `push_due` at
    its current tick and steps up to `next_stop`, the same pushes at the
    same ticks; `seek` recovers the position of a resumed run.

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

    def push_due(self, fw, now):
        """Push to ``fw`` (its current tick ``now``) every reference due by
        ``now`` that the queue has room for, in order. Calling it again at
        the same tick, or at any tick before `next_stop`, pushes nothing."""
        self._advance(now, fw.push_ref)

    def next_stop(self, now):
        """The first tick after ``now`` at which `push_due` will have
        something to push (call it after ``push_due(fw, now)``): the oldest
        queued reference's tick when the queue is full (its slot frees
        then), else the next reference's push tick; None when every
        reference is pushed. Stepping the firmware up to this tick, then
        calling `push_due`, pushes each reference at the tick `run` does."""
        if len(self.queued) == 8:       # full: the next push waits for the oldest to be due
            return max(self.queued[0], now + 1)
        if self.j < len(self.refs):
            return max(int(self.push_at[self.j]), now + 1)
        return None

    def seek(self, start, now):
        """Put the Aider where it stands after ``push_due(fw, now)`` in a run
        that began at tick ``start`` (the firmware's tick when it was made)
        and called `push_due` at every `next_stop` since: which references
        were pushed by a tick is a function of the tick, the push ticks and
        the queue rule alone, so a resumed run (its firmware restored from
        a snapshot, queue included) needs no stored position."""
        self.j, self.queued = 0, []
        t = start
        while True:
            self._advance(t, None)
            nxt = self.next_stop(t)
            if nxt is None or nxt > now:
                break
            t = nxt
        self._advance(now, None)        # pushes nothing: drops the queued ticks now passed
        return self

    def identity(self):
        """SHA-256 (hex) of the references and their push ticks: what a
        checkpoint of a run with these references must match."""
        h = hashlib.sha256(b"pyins-refs-1")
        h.update(self.refs.tobytes())
        h.update(np.ascontiguousarray(self.push_at, dtype="<i8").tobytes())
        return h.hexdigest()

    def _advance(self, now, push):
        """`push_due` with ``push`` the firmware's push_ref (None: the
        bookkeeping alone)."""
        self.queued = [t for t in self.queued if t > now]
        refs, push_at = self.refs, self.push_at
        while self.j < len(refs) and push_at[self.j] <= now:
            j = self.j
            if refs["tick"][j] > now and len(self.queued) == 8:
                break
            if push is not None:
                try:
                    push(refs[j:j + 1])
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
            self.push_due(fw, t0 + i)
            if i >= n:
                break
            nxt = self.next_stop(t0 + i)
            stop = n if nxt is None else min(n, nxt - t0)
            parts.append(call(samples[i:stop], every))
            i = stop
        dtype = contract.NAV_DTYPE if compact else contract.OUTPUT_DTYPE
        return concat(parts, dtype)


def run_with_refs(fw, samples, refs, every=100, avail_tick=None, compact=False, tick_hz=100):
    """`Aider` (refs, avail_tick) over one block of samples: the records."""
    return Aider(refs, avail_tick, tick_hz).run(fw, samples, every, compact)


class BlockFeed:
    """The references of a replay, block by block: a file's (REF_DTYPE,
    ticks on the log's clock: tick T is the end of its T-th sample) and, when
    ``zero_velocity_mps`` is given, a zero-velocity declaration every second
    from ``zv_from_tick`` on (a vehicle or a ship at rest after its
    alignment). The log's length need not be known: `run` steps one block
    (samples from the firmware's current tick on) with the references whose
    ticks fall in it, each pushed as `Aider` pushes it; `summary` says what
    was given, used, rejected and not used, and what the references do not
    cover. ``sources``: what each file gave (dicts, kept in the summary's
    ``sources``); ``notes``: what reading them found (warnings, kept first
    in the summary's)."""

    def __init__(self, refs=None, zero_velocity_mps=None, zv_from_tick=0, tick_hz=100, sources=(), notes=()):
        self.refs = contract.check_refs(refs) if refs is not None else np.zeros(0, dtype=contract.REF_DTYPE)
        if self.refs.shape[0] and np.any(np.diff(self.refs["tick"]) < 0):
            raise ValueError("refs: ticks must not decrease")
        if zero_velocity_mps is not None and not (np.isfinite(zero_velocity_mps) and zero_velocity_mps > 0):
            raise ValueError(f"zero_velocity_mps: {zero_velocity_mps!r} must be a sigma > 0 [m/s]")
        self.zv_sigma, self.zv_from, self.hz = zero_velocity_mps, int(zv_from_tick), int(tick_hz)
        self.sources, self.notes = [dict(s) for s in sources], [str(n) for n in notes]
        self.pushed = 0        # references handed to the firmware
        self.zv_given = 0
        self.end_tick = 0      # the firmware's tick after the last block

    def _zero_velocity(self, lo, hi):
        """Declarations at whole seconds in [lo, hi], from zv_from_tick on."""
        if self.zv_sigma is None:
            return np.zeros(0, dtype=contract.REF_DTYPE)
        first = max(lo, self.zv_from, 1)
        first = -(-first // self.hz) * self.hz
        ticks = np.arange(first, hi + 1, self.hz, dtype=np.int64)
        s = self.zv_sigma
        return contract.make_refs("zero_velocity", ticks, np.zeros((len(ticks), 3)),
                                  np.tile([s, s, s], (len(ticks), 1)))

    def run(self, fw, samples, every=100):
        """Step ``samples`` through ``fw`` with the references of their ticks;
        the records (`Aider.run`)."""
        t0 = _tick(fw)
        n = len(samples)
        lo = t0 if t0 == 0 else t0 + 1       # a tick on a block's edge belongs to the earlier block
        tick = self.refs["tick"]
        part = self.refs[np.searchsorted(tick, lo, "left"):np.searchsorted(tick, t0 + n, "right")]
        zv = self._zero_velocity(lo, t0 + n)
        if len(zv):
            part = np.concatenate([part, zv])
            part = part[np.argsort(part["tick"], kind="stable")]
        self.zv_given += len(zv)
        self.pushed += len(part)
        self.end_tick = t0 + n
        if not len(part):
            return fw.run(samples, every=every)
        return Aider(part, tick_hz=self.hz).run(fw, samples, every)

    def summary(self, last, nav_from_tick):
        """(facts, warnings) after the last block: per kind the references
        given, used, rejected by the gate, stale (a frozen receiver's
        repeats), skipped (before navigation) and after the log's end; what
        of the navigation the file does not cover (gaps of more than 10 s at
        its start or end). ``last``: the last record; ``nav_from_tick``: the
        tick navigation began (None: it never did)."""
        from_names = {v: k for k, v in contract.REF_KINDS.items()}
        given = {int(k): int(np.count_nonzero(self.refs["kind"] == k)) for k in np.unique(self.refs["kind"])}
        if self.zv_given:
            given[contract.REF_KINDS["zero_velocity"]] = given.get(contract.REF_KINDS["zero_velocity"], 0) \
                + self.zv_given
        kinds, warn = {}, list(self.notes)
        for k, n in sorted(given.items()):
            s = k - 1
            kinds[from_names[k]] = dict(given=n, used=int(last["n_ref_used"][s]),
                                        rejected=int(last["n_ref_rejected"][s]),
                                        stale=int(last["n_ref_stale"][s]), skipped=int(last["n_ref_skipped"][s]),
                                        after_end=int(np.count_nonzero((self.refs["kind"] == k)
                                                                       & (self.refs["tick"] > self.end_tick))))
        facts = dict(kinds=kinds)
        if self.sources:
            facts["sources"] = self.sources
        if self.zv_sigma is not None:
            facts["zero_velocity_mps"] = self.zv_sigma
        file_refs = len(self.refs)
        if file_refs:
            t = self.refs["tick"] / self.hz
            facts["file_span_s"] = [float(t[0]), float(t[-1])]
            after = int(np.count_nonzero(self.refs["tick"] > self.end_tick))
            if after:
                warn.append(f"{after} of the {file_refs} references lie after the log's end "
                            f"({self.end_tick / self.hz:g} s) and were not used")
            if nav_from_tick is None:
                warn.append("the log ended before navigation: no reference was used")
            else:
                start, end = nav_from_tick / self.hz, self.end_tick / self.hz
                inside = t[(t >= start) & (t <= end)]
                if not len(inside):
                    warn.append(f"no reference lies in the navigation ({start:g} .. {end:g} s): the "
                                f"references span {t[0]:g} .. {t[-1]:g} s; the navigation was unaided")
                else:
                    if inside[0] - start > 10.0:
                        warn.append(f"the references begin {inside[0] - start:g} s after the navigation "
                                    f"did ({start:g} s): unaided until {inside[0]:g} s")
                    if end - inside[-1] > 10.0:
                        warn.append(f"the references end {end - inside[-1]:g} s before the log does: "
                                    f"unaided from {inside[-1]:g} to {end:g} s")
        # the gate (chi-square, 2 degrees of freedom, 0.999) rejects 1 in 1000 good references by
        # chance: more than 1 % is the references or the filter's model being off
        for name, k in kinds.items():
            tested = k["used"] + k["rejected"]
            if k["rejected"] > max(1, 0.01 * tested):
                warn.append(f"{k['rejected']} of the {tested} {name} references tested failed the "
                            "innovation gate and were not used (more than 1 %: the gate alone rejects "
                            "0.1 % by chance): the references, their sigmas or the navigation are off")
        return facts, warn
