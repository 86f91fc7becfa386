"""Firmware in the loop with external references: `pyins.fil.run_fil(refs=,
avail_tick=)`. The compiled plant steps the firmware tick by tick inside C,
so the references are pushed between plant calls, each chunk split where
the next must be pushed (`pyins.aiding.Aider`, shared with the open loop).

A 15-min voyage under way (a course change, 5-20 kn, the sea's swing),
seed-002 sensor errors, two-position indexing, GNSS fixes at 1 Hz: the
integrated navigation holds the position to decimetres where the unaided
run drifts by a hundred metres; the NumPy mirror agrees over two minutes;
a killed run resumes bit-identical, its position among the references
derived from the tick; a checkpoint of other references is refused."""
import functools
import time

import numpy as np
import pytest

import killing
from pyins import aiding, contract, fil, metrics, records, sim
from pyins.reference import attitude
from pyins.sim import references

TICKS = 90_000                       # the whole 15-min voyage
CFG = dict(index_scheme=2)           # two-position indexing (table 0 / 180 deg)
KW = dict(config=CFG, errors=sim.preset("seed002"), seed=5, every=100, chunk_ticks=20_000)
GNSS_POS, GNSS_VEL = contract.REF_KINDS["gnss_pos"], contract.REF_KINDS["gnss_vel"]


@functools.lru_cache(maxsize=None)
def _voyage():
    # one object for the module: its track's positions are integrated once
    # (a cache the run digest does not read)
    return sim.default_voyage(0.25, seed=1)


def _gnss(motion, seconds, seed=1, **kw):
    # white position noise only (3 m per axis, 0.05 m/s): the receiver's
    # Gauss-Markov bias (2 m, 300 s by default) is common to every fix and no
    # filter can average it out, so it would set the floor of the error, not
    # the closed loop's pushing of the fixes
    return references.gnss(motion, seconds, pos_noise_m=3.0, vel_noise_mps=0.05, bias_sigma_m=0.0,
                           seed=seed, **kw)


def _counting_plants(monkeypatch):
    """Count the plant's run calls of the runs that follow."""
    calls = []
    make = fil.engines.plant

    def plant(*a, **k):
        p = make(*a, **k)
        run = p.run

        def counted(*ra, **rk):
            calls.append(ra[-3])          # n
            return run(*ra, **rk)
        p.run = counted
        return p
    monkeypatch.setattr(fil.engines, "plant", plant)
    return calls


# ---------------------------------------------------------------------------
# 1. GNSS aiding in the loop
# ---------------------------------------------------------------------------
def test_gnss_aided_fil_voyage(monkeypatch):
    m = _voyage()
    g = _gnss(m, TICKS / 100)
    calls = _counting_plants(monkeypatch)
    t0 = time.perf_counter()
    aided = fil.run_fil(m, TICKS, refs=g.refs, **KW)
    t_aided = time.perf_counter() - t0
    n_calls = len(calls)
    t0 = time.perf_counter()
    free = fil.run_fil(m, TICKS, **KW)
    t_free = time.perf_counter() - t0
    ea, ef = metrics.nav_errors(aided), metrics.nav_errors(free)
    late = ea.time_s >= 300.0                      # after the first 5 min
    rms = float(np.sqrt(np.mean(ea.horizontal_m[late] ** 2)))
    rms_free = float(np.sqrt(np.mean(ef.horizontal_m[late] ** 2)))
    o = aided.outputs
    print(f"\nFIL voyage 15 min, seed 002, 2-position indexing, GNSS 1 Hz (3 m, 0.05 m/s): horizontal "
          f"after 5 min RMS {rms:.3f} m, max {ea.horizontal_m[late].max():.3f} m; unaided RMS "
          f"{rms_free:.1f} m, min {ef.horizontal_m[late].min():.1f} m; {n_calls} plant calls "
          f"({len(g.refs)} refs); {t_aided:.2f} s aided, {t_free:.2f} s unaided")
    # Theory: position fixes of white noise sigma_p = 3 m per axis beside
    # velocity fixes of sigma_v = 0.05 m/s each T = 1 s are a random walk of
    # steps sigma_v T watched through white noise sigma_p; its steady-state
    # filter holds sigma ~ sqrt(sigma_p sigma_v T) = 0.39 m per axis, 0.55 m
    # horizontally (RMS). Measured 0.38-0.54 m over GNSS seeds 1-11 (max
    # 0.8-1.3 m): 1 m RMS and 2.5 m at most leave a factor ~2 of margin and
    # still fail an aiding that works at the wrong tick or misses fixes
    # (3 m: the fixes' own noise).
    assert rms < 1.0
    assert ea.horizontal_m[late].max() < 2.5
    # unaided: seed 002's biases drift the free inertial position by 20-220 m
    assert rms < rms_free / 50.0 and ea.horizontal_m[late].max() < ef.horizontal_m[late].min() / 5.0
    assert np.all(o["nav_mode"] == 3)     # PYINS_NAV_INTEGRATED from the first record (the first fix's tick)
    assert np.all(free.outputs["nav_mode"] == 1)      # AUTO without references: undamped
    assert np.count_nonzero(o["index_state"] == 2) > 0  # the table really indexes meanwhile
    # every fix whose tick has been stepped was applied at its tick or
    # rejected by the gate: used + rejected = the fixes up to the record's tick
    for kind in (GNSS_POS, GNSS_VEL):
        ticks = g.refs["tick"][g.refs["kind"] == kind]
        due = np.searchsorted(ticks, o["tick"], side="right")
        used, rejected = o["n_ref_used"][:, kind - 1], o["n_ref_rejected"][:, kind - 1]
        assert np.array_equal(used + rejected, due), kind
        assert used[-1] == len(ticks) - rejected[-1] and rejected[-1] <= 5
        assert np.all(o["n_ref_skipped"][:, kind - 1] == 0)
    # one plant call per refill of the queue (a fix per second), not per tick
    assert n_calls <= len(g.refs) // 2 + TICKS // KW["chunk_ticks"] + 2
    assert sum(calls[:n_calls]) == TICKS


def test_latency_and_queue_rule_match_the_open_loop_aider():
    """The pushes of a chunked FIL run are those of Aider.run: with a
    latency (pushed late, carried forward) and at 10 Hz (the queue full), the
    records do not depend on the chunking."""
    m = _voyage()
    n = 12_000
    for g, avail in ((_gnss(m, n / 100), None),
                     (_gnss(m, n / 100, latency_s=0.37), "lat"),
                     (_gnss(m, n / 100, rate_hz=10.0), None)):
        avail_tick = g.avail_tick if avail else None
        runs = [fil.run_fil(m, n, refs=g.refs, avail_tick=avail_tick, config=CFG,
                            errors=sim.preset("seed002"), seed=5, every=10, chunk_ticks=c)
                for c in (n, 1_234)]
        a, b = (np.asarray(r.outputs) for r in runs)
        assert a.tobytes() == b.tobytes()
        per = (a["n_ref_used"] + a["n_ref_rejected"])[:, :2].sum(axis=1)
        due = np.searchsorted(g.avail_tick if avail else g.refs["tick"], a["tick"], side="right")
        assert np.array_equal(per, due)              # each one applied when it came


def test_aider_seek_is_the_position_of_a_run():
    """Aider.seek(start, t) is where push_due / next_stop leave the Aider at
    t, wherever the run was cut (a fake firmware that only counts)."""
    class Fake:
        def __init__(self):
            self.pushed = 0

        def push_ref(self, r):
            self.pushed += 1
    m = _voyage()
    rng = np.random.default_rng(0)
    for g, avail in ((_gnss(m, 60.0, rate_hz=10.0), None), (_gnss(m, 60.0, latency_s=0.5), True),
                     (_gnss(m, 60.0), None)):
        live = aiding.Aider(g.refs, g.avail_tick if avail else None)
        fw, now = Fake(), 0
        cuts = set(rng.integers(1, 6_000, 40).tolist())
        while now < 6_000:
            live.push_due(fw, now)
            if now in cuts or rng.random() < 0.05:
                got = aiding.Aider(g.refs, g.avail_tick if avail else None).seek(0, now)
                assert (got.j, got.queued) == (live.j, live.queued) and got.j == fw.pushed, now
            nxt = live.next_stop(now)
            nxt = 6_000 if nxt is None else min(nxt, 6_000)
            inside = [c for c in cuts if now < c < nxt]
            now = min(inside) if inside else nxt     # a chunk's end between two stops


def test_a_refused_reference_stops_the_run():
    m = _voyage()
    g = _gnss(m, 30.0)
    with pytest.raises(contract.RefError) as e:       # UNDAMPED takes no references
        fil.run_fil(m, 3_000, refs=g.refs, config=dict(CFG, nav_mode=1))
    assert e.value.status_name == "PYINS_E_REF_UNUSED" and e.value.index == 0
    with pytest.raises(ValueError, match="avail_tick"):
        fil.run_fil(m, 3_000, refs=g.refs, avail_tick=g.avail_tick[:-1])


def test_a_rejected_sample_in_a_split_chunk_is_the_chunks(tmp_path):
    """A sample rejected in the middle of a chunk split by the references:
    PlantError as without them (the same tick, ticks done and records
    before it, in the error and on disk)."""
    m = _voyage()
    g = _gnss(m, 300.0)
    omega = sim.node_rates(m, np.arange(30_000))[0]
    inc = np.abs(omega).max(axis=(1, 2)) * 0.01      # the largest gyro increment per tick
    sat = 0.5 * (inc[:1000].max() + inc.max())       # saturated in a turn, not at the start
    errs = []
    for i, refs in enumerate((None, g.refs)):
        with pytest.raises(contract.PlantError) as e:
            fil.run_fil(m, 30_000, refs=refs, config=dict(CFG, sat_gyro_rad=sat), errors=sim.preset("seed002"),
                        chunk_ticks=20_000, record_dir=str(tmp_path / str(i)))
        errs.append(e.value)
        written, _ = records.load_written(str(tmp_path / str(i)))
        assert len(written) == len(e.value.outputs) and np.array_equal(written["tick"], e.value.outputs["tick"])
    a, b = errs
    assert str(a) == str(b) and a.n_done == b.n_done > 1_000 and a.status_name == "PYINS_E_SAMPLE_SATURATED"
    assert np.array_equal(a.outputs["tick"], b.outputs["tick"]) and np.all(b.outputs["nav_mode"] == 3)


# ---------------------------------------------------------------------------
# 2. The NumPy mirror in the loop
# ---------------------------------------------------------------------------
def test_gnss_aided_fil_reference_engine_agrees():
    """Two minutes of the same run through the NumPy firmware and plant:
    within the FIL crosscheck's bounds (attitude and table angle 1e-10 rad,
    the indexing decisions identical), the filter's position to 1e-12 rad
    (6 um), its velocity to 1e-9 m/s, every reference counted alike."""
    m = _voyage()
    n = 12_000
    g = _gnss(m, n / 100)
    # the table indexed after each 30-s stop and the filter told the gyros'
    # scale factors and misalignments as states (ABI 0.19) and a bias random
    # walk: the states the moves and the Earth's rate excite run in both
    # engines (seed 002's grade: 10 ppm, 10", 0.0007 deg/h/sqrt(h))
    cfg = dict(CFG, index_stop_ticks=3_000, nav_table_scale_sigma=10e-6, nav_table_mis_sigma=4.85e-5,
               nav_level_scale_sigma=10e-6, nav_level_mis_sigma=4.85e-5, nav_gyro_bias_rw=5.66e-11)
    kw = dict(KW, every=1, chunk_ticks=5_000, config=cfg)
    t0 = time.perf_counter()
    a = fil.run_fil(m, n, refs=g.refs, **kw)
    t_native = time.perf_counter() - t0
    t0 = time.perf_counter()
    b = fil.run_fil(m, n, refs=g.refs, engine="reference", **kw)
    t_ref = time.perf_counter() - t0
    A, B = a.outputs, b.outputs
    q = attitude.quat_mul(np.asarray(A["quat_np"]).T, attitude.quat_conj(np.asarray(B["quat_np"]).T))
    ang = 2.0 * np.arcsin(np.minimum(1.0, np.linalg.norm(q[1:], axis=0)))
    print(f"\nFIL + GNSS, native vs reference over {n // 100} s: attitude {ang.max():.1e} rad, "
          f"lat {np.abs(A['lat_rad'] - B['lat_rad']).max():.1e} rad, vel "
          f"{np.abs(A['vel_n_mps'] - B['vel_n_mps']).max():.1e} m/s; {t_native:.2f} s vs {t_ref:.2f} s")
    assert ang.max() < 1e-10
    assert np.abs(a.plant["alpha_rad"] - b.plant["alpha_rad"]).max() < 1e-10
    assert np.abs(A["lat_rad"] - B["lat_rad"]).max() < 1e-12
    assert np.abs(A["lon_rad"] - B["lon_rad"]).max() < 1e-12
    assert np.abs(A["vel_n_mps"] - B["vel_n_mps"]).max() < 1e-9
    np.testing.assert_allclose(A["nav_nis"], B["nav_nis"], rtol=1e-9, atol=1e-12)
    np.testing.assert_allclose(A["nav_sigma_heading_rad"], B["nav_sigma_heading_rad"], rtol=1e-9)
    assert np.ptp(np.unwrap(a.plant["alpha_rad"])) > 3.0, "the table did not move in the 2 min"
    for f in ("tick", "seq", "index_state", "index_step", "nav_mode", "ref_in_use", "n_ref_used",
              "n_ref_rejected", "n_ref_skipped"):
        assert np.array_equal(A[f], B[f]), f
    assert A["n_ref_used"][-1][GNSS_POS - 1] >= n // 100 - 3
    aided = A["tick"] >= g.refs["tick"][0]           # AUTO: undamped until the first fix
    assert np.all(A["nav_mode"][aided] == 3) and np.all(A["nav_mode"][~aided] == 1)


# ---------------------------------------------------------------------------
# 3. Checkpoints: kill and resume
# ---------------------------------------------------------------------------
CK_CHUNK = 7_777                     # chunk ends fall between fixes, with fixes queued
RUN = f"""
import sys, time
from pyins import fil, sim
from pyins.sim import references
m = sim.default_voyage(0.25, seed=1)
g = references.gnss(m, {TICKS} / 100, pos_noise_m=3.0, vel_noise_mps=0.05, bias_sigma_m=0.0, seed=1)
fil.run_fil(m, {TICKS}, refs=g.refs, config=dict(index_scheme=2), errors=sim.preset("seed002"), seed=5,
            every=100, chunk_ticks={CK_CHUNK}, record_dir=sys.argv[1], checkpoint_ticks={2 * CK_CHUNK},
            resume=True, progress=lambda d, t: time.sleep(0.1))
"""


def _ck_run(record_dir, refs, avail_tick=None, **kw):
    return fil.run_fil(_voyage(), TICKS, refs=refs, avail_tick=avail_tick, config=CFG,
                       errors=sim.preset("seed002"), seed=5, every=100, chunk_ticks=CK_CHUNK,
                       record_dir=record_dir, **kw)




def test_killed_run_with_refs_resumes_bit_identical(tmp_path):
    g = _gnss(_voyage(), TICKS / 100)
    whole = _ck_run(str(tmp_path / "whole"), g.refs)
    cut = tmp_path / "cut"
    killing.kill_after_checkpoint(RUN, cut, cut / records.CHECKPOINT, 4 * CK_CHUNK, 0.15)   # a chunk past the checkpoint
    part_out, _, info = records.load_records(str(cut))
    assert not info["complete"] and 0 < len(part_out) < len(whole.outputs)
    assert part_out.tobytes() == np.asarray(whole.outputs[:len(part_out)]).tobytes()
    resumed = _ck_run(str(cut), g.refs, checkpoint_ticks=2 * CK_CHUNK, resume=True)
    assert np.asarray(resumed.outputs).tobytes() == np.asarray(whole.outputs).tobytes()
    assert np.asarray(resumed.plant).tobytes() == np.asarray(whole.plant).tobytes()
    assert np.all(resumed.outputs["nav_mode"] == 3)


class _Stop(Exception):
    pass


def _interrupted(record_dir, refs, avail_tick, after):
    def progress(done, total):
        if done >= after:
            raise _Stop
    with pytest.raises(_Stop):
        _ck_run(record_dir, refs, avail_tick, checkpoint_ticks=CK_CHUNK, resume=True, progress=progress)


@pytest.mark.parametrize("rate_hz, latency_s", [(10.0, 0.0), (1.0, 0.43)])
def test_interrupted_run_resumes_bit_identical_queue_full_or_late(tmp_path, rate_hz, latency_s):
    """Resumed at every checkpoint in turn: with 10 Hz fixes (the firmware's
    queue full at each chunk end) and with fixes pushed late."""
    g = _gnss(_voyage(), TICKS / 100, rate_hz=rate_hz, latency_s=latency_s)
    avail = g.avail_tick if latency_s else None
    whole = _ck_run(str(tmp_path / "whole"), g.refs, avail)
    d = str(tmp_path / "cut")
    for k in range(1, TICKS // CK_CHUNK + 1, 3):
        _interrupted(d, g.refs, avail, k * CK_CHUNK)
    resumed = _ck_run(d, g.refs, avail, checkpoint_ticks=CK_CHUNK, resume=True)
    assert np.asarray(resumed.outputs).tobytes() == np.asarray(whole.outputs).tobytes()
    assert np.asarray(resumed.plant).tobytes() == np.asarray(whole.plant).tobytes()


# ---------------------------------------------------------------------------
# 4. A checkpoint of other references is another run's
# ---------------------------------------------------------------------------
def test_checkpoint_of_other_refs_is_refused(tmp_path):
    m = _voyage()
    g = _gnss(m, TICKS / 100)
    other = g.refs.copy()
    other["value"][100, 0] += 1e-9                   # one fix 6 mm further north
    variants = [dict(refs=other), dict(refs=None), dict(refs=g.refs, avail_tick=g.avail_tick + 1),
                dict(refs=g.refs[:-1])]
    for i, v in enumerate(variants):
        d = str(tmp_path / f"r{i}")
        _interrupted(d, g.refs, None, 2 * CK_CHUNK)
        with pytest.raises(ValueError, match="belongs to another run"):
            _ck_run(d, v["refs"], v.get("avail_tick"), checkpoint_ticks=CK_CHUNK, resume=True)
    # and the same references resume (the run of r0 goes on)
    _ck_run(str(tmp_path / "r0"), g.refs, checkpoint_ticks=CK_CHUNK, resume=True)
    d = str(tmp_path / "plain")                      # a run without references: not one with them
    with pytest.raises(_Stop):
        fil.run_fil(m, TICKS, config=CFG, errors=sim.preset("seed002"), seed=5, every=100,
                    chunk_ticks=CK_CHUNK, record_dir=d, checkpoint_ticks=CK_CHUNK, resume=True,
                    progress=lambda done, total: (_ for _ in ()).throw(_Stop()))
    with pytest.raises(ValueError, match="belongs to another run"):
        _ck_run(d, g.refs, checkpoint_ticks=CK_CHUNK, resume=True)
