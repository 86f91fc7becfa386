"""A recorded IMU log through the firmware (what ``pyins replay`` does).

`replay` is a guarded prefix, then named steps:

1. the log through the firmware in blocks (a `pyins.logs.LogReader`'s, or
   an ImuData split into `BLOCK` samples), one firmware call a block, one
   record every ``every`` samples, written as they come (navigation.npz is
   assembled from them at the end): memory does not grow with the log, and
   Ctrl-C between blocks leaves the records so far with a summary saying
   ``"state": "interrupted"``;
2. what the run says: the final state, the attitude at the end of the
   alignment, the fine alignment's sigmas and drift estimates, and the
   warnings for anything its figures cannot be trusted for (`warnings`);
3. the errors against a reference when there is one: the truth of the
   scenario the log was simulated from, or ``reference="parked"`` (the
   configured site and zero velocity: a vehicle or a ship at the pier that
   did not move), north and east apart (errors.npz);
4. summary.json (the figures of step 2 and 3 gathered block by block: a
   record, a maximum or a last value each, the same as from all records at
   once); the page and figures are `pyins.report.replay`.

The CLI checks the user's options before any of this (the rate, an
attitude someone gave, the firmware's limits: `pyins.__main__`,
`pyins.limits`).
"""
import json
import os

import numpy as np

from pyins import engine as engines
from pyins import contract, logs, metrics, open_loop, records, scenario, sim
from pyins.reference import abi
from pyins.reference.config import DEFAULT_NAV_GATE
from pyins.reference.fine_align import PHI
from pyins.reference.firmware import VALID_HEADING_SIGMA, VALID_NAV_HEADING_SIGMA
from pyins.report.replay import alignment_figures
from pyins.truth_track import TruthTrack
from pyins.rundir import hold_interrupts
from pyins.units import ARCMIN_TO_RAD, ARCSEC_TO_RAD, TICK_HZ

__all__ = ["replay", "replay_config", "warnings", "REFERENCES"]

#: the references a log's errors can be taken against without a scenario
REFERENCES = ("parked",)
#: samples per firmware call (`pyins.logs.DEFAULT_BLOCK`): 655 s at 100 Hz, ~0.1 s of work
BLOCK = logs.DEFAULT_BLOCK

def replay_config(spec):
    """The firmware configuration replaying a log of ``spec`` (a RunSpec)
    starts from: its initial state and settings, without indexing (a log's
    table angles are recorded: the firmware commands nothing)."""
    cfg = scenario.initial_config(spec.motion, None, **spec.config)
    cfg["index_scheme"] = 0
    return cfg


def warnings(recs, aligning, hz):
    """What a replay's figures cannot be trusted for, in words: a log that
    ended before the alignment did, an attitude the firmware does not call
    valid (and why), fault bits."""
    out = []
    last = recs[-1]
    t = float(last["tick"] / hz)
    if aligning and last["mode"] != abi.PYINS_MODE_NAVIGATE:
        phase = {abi.PYINS_MODE_COARSE_ALIGN: "coarse", abi.PYINS_MODE_FINE_ALIGN: "fine"}.get(
            int(last["mode"]), "the")
        out.append(f"the log ended during {phase} alignment (at {t:g} s): no aligned attitude")
    if not last["state_flags"] & abi.PYINS_STATE_ATT_VALID:
        integrity = abi.PYINS_FAULT_ALIGN_INCONSISTENT | abi.PYINS_FAULT_COARSE_UNSETTLED
        heading_sigma = float(last["kf_sigma"][PHI][2]) if last["kf_states"] else 0.0
        if int(last["fault_flags"]) & integrity:
            why = "an integrity test failed: the measurements do not fit the alignment's model"
        elif heading_sigma > VALID_HEADING_SIGMA:
            why = (f"the fine alignment left a heading sigma of {heading_sigma / ARCMIN_TO_RAD:.2f}', above "
                   f"{VALID_HEADING_SIGMA / ARCMIN_TO_RAD:g}': align longer")
        elif (last["mode"] == abi.PYINS_MODE_NAVIGATE and not last["kf_states"]
              and last["nav_sigma_heading_rad"] > VALID_NAV_HEADING_SIGMA):
            nav_sigma = float(last["nav_sigma_heading_rad"]) / ARCMIN_TO_RAD
            why = (f"the navigation filter aligning on the coarse attitude has a heading sigma of "
                   f"{nav_sigma:.2f}': three times it is above {VALID_HEADING_SIGMA / ARCMIN_TO_RAD:g}'; "
                   "aid it longer")
        elif aligning:
            why = "the alignment had not ended"
        else:
            why = "it is the configured guess"
        out.append(f"the attitude at the end ({t:g} s) is not valid (ATT_VALID unset): {why}")
    faults = abi.fault_names(last["fault_flags"])
    if faults:
        out.append("fault bits set: " + ", ".join(faults))
    state = np.concatenate([np.ravel(last[k]) for k in ("lat_rad", "lon_rad", "euler_b_rad")])
    if not np.all(np.isfinite(state)):
        out.append(f"the navigation state at the end ({t:g} s) is not a number (NaN): the log's "
                   "values or its declared units cannot be right")
    return out


def _parked_errors(recs, cfg, hz):
    """Errors against the configured site and zero velocity (a parked
    vehicle): `pyins.metrics.nav_errors` against a static truth at the site
    (its attitude errors mean nothing here and are not kept)."""
    site = sim.Static(cfg["lat_rad"], cfg["lon_rad"], cfg.get("height_m", 0.0))
    dt = 1.0 / hz
    e = metrics.nav_errors(open_loop.RunResult(outputs=recs, truth=sim.truth_at(site, recs["tick"], dt=dt), dt=dt))
    return dict(time_s=e.time_s, north_m=e.north_m, east_m=e.east_m, vel_n_mps=e.vel_n_mps)


class _Summary:
    """What the summary needs of the records, gathered block by block: the
    first and last record, the first record in navigation, the last of the
    fine alignment, and the errors' maxima and last values (the errors
    themselves go to errors.npz as they come). The same figures as from all
    the records at once: each is a record, a max or a last value, and the
    errors are record by record (`metrics.nav_errors`, `sim.truth_at`)."""

    def __init__(self, cfg, hz, spec, reference, errors, t_first=None):
        self.cfg, self.hz, self.spec, self.reference, self.errors = cfg, hz, spec, reference, errors
        self.t_first = t_first
        self.outside = 0          # records outside a truth track's time span
        self.records = 0
        self.navigating = 0       # records in navigation (an alignment holds the site: nothing to compare)
        self.last = self.first_nav = self.last_fine = None
        self.horizontal_max = self.level_max = self.speed_max = -np.inf
        self.e_last = None
        self.t_span = None        # the records' times on a truth track's clock [s]

    def add(self, recs):
        self.records += len(recs)
        self.navigating += int(np.count_nonzero(recs["mode"] == abi.PYINS_MODE_NAVIGATE))
        self.last = recs[-1:].copy()
        if self.first_nav is None:
            nav = np.flatnonzero(recs["mode"] == abi.PYINS_MODE_NAVIGATE)
            if len(nav):
                self.first_nav = recs[nav[0]:nav[0] + 1].copy()
        fine = np.flatnonzero(recs["mode"] == abi.PYINS_MODE_FINE_ALIGN)
        if len(fine):
            self.last_fine = recs[fine[-1]:fine[-1] + 1].copy()
        if self.spec is not None:
            truth = sim.truth_at(self.spec.motion, recs["tick"], dt=self.spec.dt)
            e = metrics.nav_errors(open_loop.RunResult(outputs=recs, truth=truth, dt=self.spec.dt))
            err = dict(time_s=e.time_s, north_m=e.north_m, east_m=e.east_m, vel_n_mps=e.vel_n_mps)
            self.horizontal_max = max(self.horizontal_max, float(e.horizontal_m.max()))
            self.level_max = max(self.level_max, float(np.abs(e.att_n_rad[:, :2]).max()))
            self.e_last = dict(horizontal=float(e.horizontal_m[-1]), heading=float(e.att_n_rad[-1, 2]))
        elif self.reference == "parked":
            err = _parked_errors(recs, self.cfg, self.hz)
            horizontal = np.hypot(err["north_m"], err["east_m"])
            speed = np.linalg.norm(err["vel_n_mps"][:, :2], axis=1)
            self.horizontal_max = max(self.horizontal_max, float(horizontal.max()))
            self.speed_max = max(self.speed_max, float(speed.max()))
            self.e_last = dict(horizontal=float(horizontal[-1]), north=float(err["north_m"][-1]),
                               east=float(err["east_m"][-1]))
        elif isinstance(self.reference, TruthTrack):
            # the records' times on the log's clock: the time stamp of their sample
            ticks = recs["tick"].astype(float)
            t = ticks / self.hz if self.t_first is None else self.t_first + (ticks - 1.0) / self.hz
            inside, err = self.reference.errors(t, recs["lat_rad"], recs["lon_rad"], recs["heading_b_rad"])
            self.outside += int(np.count_nonzero(~inside))
            lo, hi = float(t.min()), float(t.max())
            self.t_span = (lo, hi) if self.t_span is None else (min(self.t_span[0], lo), max(self.t_span[1], hi))
            if not inside.any():
                return
            err["time_s"] = ticks[inside] / self.hz           # since the log's start, as the others
            horizontal = np.hypot(err["north_m"], err["east_m"])
            self.horizontal_max = max(self.horizontal_max, float(horizontal.max()))
            self.e_last = dict(horizontal=float(horizontal[-1]), north=float(err["north_m"][-1]),
                               east=float(err["east_m"][-1]))
            if "heading_rad" in err:
                self.e_last["heading"] = float(err["heading_rad"][-1])
        else:
            return
        for key, value in err.items():
            self.errors.append(key, value)

    def summary(self, log_path, samples, every):
        cfg, hz, recs = self.cfg, self.hz, self.last
        log = "standard input" if log_path == "-" else os.path.abspath(log_path) if log_path else None
        summary = dict(log=log, samples=int(samples),
                       rate_hz=int(hz), every=every,
                       final=dict(lat_deg=float(np.degrees(recs["lat_rad"][-1])),
                                  lon_deg=float(np.degrees(recs["lon_rad"][-1])),
                                  euler_deg=np.degrees(recs["euler_b_rad"][-1]).tolist(),
                                  mode=int(recs["mode"][-1]), fault_flags=int(recs["fault_flags"][-1])))
        aligning = cfg.get("coarse_ticks", 0) > 0 or cfg.get("fine_ticks", 0) > 0
        if aligning and self.first_nav is not None:
            first = self.first_nav
            pitch, roll, yaw = np.degrees(first["euler_b_rad"][0])
            summary["aligned"] = dict(time_s=float(first["tick"][0] / hz), pitch_deg=float(pitch),
                                      roll_deg=float(roll), heading_deg=float(np.mod(-yaw, 360.0)),
                                      method=metrics.alignment_method(cfg, hz),
                                      heading_sigma_arcmin=metrics.alignment_heading_sigma(first[0]))
        # the filter's state at the end of the fine alignment: the first record of navigation
        # holds it (the last fine record is up to a record interval before the end)
        end = None if self.first_nav is None else self.first_nav[0]
        fine = alignment_figures(self.last_fine, end) if self.last_fine is not None else None
        if fine is not None:
            summary["fine_alignment"] = fine
        summary["warnings"] = warnings(recs, aligning, hz)
        if "aligned" in summary and abs(summary["aligned"]["roll_deg"]) > 90.0:
            # gravity came out along the IMU's +z: an upside-down mounting, or axes declared wrong
            summary["warnings"].append(
                f"the alignment found the IMU upside down (roll {summary['aligned']['roll_deg']:.1f} deg): "
                "if it was mounted upright, the log's axes are not the ones declared (--axes)")
        summary["navigating_records"] = self.navigating
        if self.spec is not None:
            summary["errors"] = dict(reference=f"the truth of {self.spec.scenario}",
                                     horizontal_max_m=self.horizontal_max,
                                     horizontal_final_m=self.e_last["horizontal"],
                                     heading_final_arcmin=self.e_last["heading"] / ARCMIN_TO_RAD,
                                     level_max_arcsec=self.level_max / ARCSEC_TO_RAD)
        elif isinstance(self.reference, str) and self.reference == "parked":
            summary["errors"] = dict(reference="the site, parked (zero velocity)",
                                     horizontal_max_m=self.horizontal_max,
                                     horizontal_final_m=self.e_last["horizontal"],
                                     north_final_m=self.e_last["north"], east_final_m=self.e_last["east"],
                                     speed_max_mps=self.speed_max)
        elif isinstance(self.reference, TruthTrack):
            track = self.reference
            if self.e_last is None:
                span = "" if self.t_span is None else f"; the records span {self.t_span[0]:g} .. {self.t_span[1]:g} s"
                summary["errors_missing"] = (f"no record lies within the time span of {track.path} "
                                             f"({track.t[0]:g} .. {track.t[-1]:g} s{span}): no errors computed")
                summary["warnings"].append(summary["errors_missing"])
            else:
                summary["errors"] = dict(reference=f"the track in {os.path.basename(track.path)}",
                                         horizontal_max_m=self.horizontal_max,
                                         horizontal_final_m=self.e_last["horizontal"],
                                         north_final_m=self.e_last["north"], east_final_m=self.e_last["east"],
                                         compared=self.records - self.outside)
                if "heading" in self.e_last:
                    summary["errors"]["heading_final_arcmin"] = self.e_last["heading"] / ARCMIN_TO_RAD
                if self.outside:
                    summary["warnings"].append(
                        f"{self.outside} of {self.records} records lie outside the time span of "
                        f"{track.path} ({track.t[0]:g} .. {track.t[-1]:g} s) and were not compared")
        return summary


def _json_safe(obj):
    """``obj`` with every NaN or infinity as None (null): summary.json is JSON
    (a NaN end state is said in the warnings, not written as NaN)."""
    if isinstance(obj, dict):
        return {k: _json_safe(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [_json_safe(v) for v in obj]
    if isinstance(obj, float) and not np.isfinite(obj):
        return None
    return obj


def _blocks(data, block):
    """``data`` in blocks: an ImuData split (`pyins.logs.split_blocks`), or
    the blocks of an iterable (a `pyins.logs.LogReader`) as they come."""
    if hasattr(data, "tick"):
        return logs.split_blocks(data, block)
    return iter(data)


#: the files a replay writes into its directory (and their temporary names: NAME.*)
OWN_FILES = ("navigation.npz", "errors.npz", "summary.json", "report.html", "attitude.png",
             "alignment.png", "errors.png", "references.png")


def _own(name):
    return name in OWN_FILES or any(name.startswith(f + ".") for f in OWN_FILES)


def claim_dir(out_dir, keep=None):
    """Make ``out_dir`` the new replay's: an earlier replay's files there
    (`OWN_FILES`, and the temporary files a killed one left) are removed, so
    that nothing of it (an errors.npz the new replay has no reference for)
    is read as the new one's; a directory holding anything else (a `pyins
    run`, files of the user's) is refused (ValueError), never mixed into.
    Returns True when the directory was made here."""
    if not os.path.isdir(out_dir):
        if os.path.exists(out_dir):
            raise ValueError(f"--out {out_dir}: not a directory")
        os.makedirs(out_dir)
        return True
    names = os.listdir(out_dir)
    other = sorted(n for n in names if not _own(n))
    if other:
        shown = ", ".join(other[:3]) + (f" and {len(other) - 3} more" if len(other) > 3 else "")
        raise ValueError(f"--out {out_dir}: holds files that are not a replay's ({shown}): give an "
                         "empty or new directory, or one an earlier replay wrote (it is replaced)")
    for n in names:
        path = os.path.join(out_dir, n)
        if keep is not None and os.path.exists(keep) and os.path.samefile(path, keep):
            raise ValueError(f"--out {out_dir}: holds the log being replayed ({n}), which a replay there "
                             "would replace: give another --out")
    for n in names:
        os.remove(os.path.join(out_dir, n))
    return False


def replay(data, cfg, out_dir, every=TICK_HZ, spec=None, engine="native", log_path=None, reference=None,
           block=BLOCK, progress=None, t_first=None, notes=None, feed=None):
    """Run a recorded IMU log through the firmware configured by ``cfg`` into
    ``out_dir`` and return the summary dict (also summary.json). ``data``: a
    pyins.sim.io.ImuData, or an iterable of them in order (the blocks of a
    `pyins.logs.LogReader`): each block is one firmware call (``every`` is in
    phase across calls), its records and errors written as they come, so the
    memory does not grow with the log. ``spec``: the RunSpec the log was
    simulated from (its truth is the reference); ``reference="parked"``: the
    site and zero velocity; ``reference`` a `pyins.truth_track.TruthTrack`:
    a trajectory on the log's clock, ``t_first`` the time stamp of the log's
    first sample on it (None: the log has no time column; a sample's time is
    then its tick x dt). ``progress(samples_done)`` after each block.
    ``notes()``: the warnings of the log itself (its gaps, their bridge),
    asked for when the blocks are out and kept first in the summary's.
    ``feed``: a `pyins.aiding.BlockFeed` of external references (a file's,
    zero velocity at rest), pushed block by block at their ticks; what was
    used, rejected and not covered goes to the summary's ``references`` and
    its warnings.
    ``out_dir`` is the replay's (`claim_dir`: an earlier replay there is
    replaced, anything else refused).

    Ctrl-C (KeyboardInterrupt) between blocks, or in one (a block is at most
    ``block`` samples: well under a second): the records so far are written
    with a summary that says ``"state": "interrupted"``, ``"complete":
    false`` (`pyins report` renders it), and the interrupt is raised again.
    A log refused part way (`pyins.logs.LogError`) or a firmware error
    leaves no navigation.npz or summary.json."""
    # the guarded prefix
    engines.check(engine)
    if not every >= 1:
        raise ValueError(f"--every {every}: keep one record every 1 or more samples")
    every = int(every)
    if reference is not None and not isinstance(reference, TruthTrack) and reference not in REFERENCES:
        raise ValueError(f"reference: {reference!r} is not one of {', '.join(REFERENCES)}")
    hz = cfg.get("tick_hz") or TICK_HZ

    # 1. the log through the firmware, block by block, the records written as they come
    fw = engines.firmware(engine, cfg)
    made = claim_dir(out_dir, keep=log_path if log_path and log_path != "-" else None)
    nav = logs.NpzWriter(os.path.join(out_dir, "navigation.npz"))
    err = logs.NpzWriter(os.path.join(out_dir, "errors.npz"))
    acc = _Summary(cfg, hz, spec, reference, err, t_first=t_first)
    samples, interrupted = 0, False
    try:
        try:
            for piece in _blocks(data, block):
                chunk = contract.make_samples(piece.dtheta_p, piece.dv_p, piece.table_angle_rad)
                recs = fw.run(chunk, every=every) if feed is None else feed.run(fw, chunk, every)
                samples += len(chunk)
                if len(recs):
                    # the records and what the summary counts of them go
                    # together: a Ctrl-C between the two left records on disk
                    # that the summary never saw (seen under load: a replay
                    # "interrupted before the first record" with its records
                    # half written)
                    with hold_interrupts(defer=True):
                        nav.append("outputs", recs)
                        acc.add(recs)
                if progress is not None:
                    progress(samples)
        except KeyboardInterrupt:
            interrupted = True
        # 2. what the run says; 3. the errors against a reference; 4. summary.json
        with hold_interrupts(defer=not interrupted):
            if not acc.records:
                if interrupted:
                    raise KeyboardInterrupt
                raise ValueError(f"{log_path or 'the log'}: {samples} samples, fewer than one record "
                                 f"interval ({every} samples): nothing to report (a smaller --every, or a "
                                 f"longer log)")
            summary = acc.summary(log_path, samples, every)
            summary["warnings"][:0] = list(notes() if notes is not None else ())
            if feed is not None:
                last = acc.last[0]
                nav_from = (cfg.get("coarse_ticks", 0) + cfg.get("fine_ticks", 0)
                            if last["mode"] == abi.PYINS_MODE_NAVIGATE else None)
                summary["references"], said = feed.summary(last, nav_from)
                summary["references"]["gate"] = float(cfg.get("nav_gate") or DEFAULT_NAV_GATE)
                summary["warnings"].extend(said)
            if interrupted:
                t = float(acc.last["tick"][0] / hz)
                summary.update(complete=False, state="interrupted")
                summary["warnings"].insert(0, f"interrupted (Ctrl-C) at {t:g} s after {samples} samples: "
                                              "the log was not replayed to its end")
            nav.close()
            if err.rows("time_s"):
                err.close()
            else:
                err.abort()
            records.write_atomic(os.path.join(out_dir, "summary.json"),
                                 json.dumps(_json_safe(summary), indent=2, allow_nan=False), sync=False)
    except BaseException:
        nav.abort()
        err.abort()
        if made and not os.listdir(out_dir):
            os.rmdir(out_dir)
        raise
    if interrupted:
        raise KeyboardInterrupt
    return summary
