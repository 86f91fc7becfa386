"""FIL runs checkpoint to disk and resume after being killed (docs/cli.md,
"pyins run SCENARIO": checkpoints and --resume).

A run with noise, indexing and alignment-free navigation is killed with
SIGKILL in a subprocess once it has checkpointed, then resumed in this
process: its records must be bit-identical to an uninterrupted run (the
firmware snapshot, the plant state and the noise generator all resume), and
nothing written before the kill is lost."""

import numpy as np
import pytest

import killing
from pyins import fil, records, sim

TICKS = 240_000                  # 40 min of ship time: 12 chunks of 20,000
CHUNK = 20_000
RUN = f"""
import sys, numpy as np
from pyins import fil, sim
m = sim.HeadingSwing.experiment(1)
fil.run_fil(m, {TICKS}, config=dict(index_scheme=4), errors=sim.preset("seed002"), seed=5,
            every=100, chunk_ticks={CHUNK}, record_dir=sys.argv[1], checkpoint_ticks={2 * CHUNK},
            resume=True, progress=lambda d, t: __import__("time").sleep(0.05))
"""


def _run(record_dir, **kw):
    return fil.run_fil(sim.HeadingSwing.experiment(1), TICKS, config=dict(index_scheme=4),
                       errors=sim.preset("seed002"), seed=5, every=100, chunk_ticks=CHUNK,
                       record_dir=record_dir, **kw)




def test_killed_run_resumes_bit_identical(tmp_path):
    whole = _run(str(tmp_path / "whole"))
    cut = tmp_path / "cut"
    killing.kill_after_checkpoint(RUN, cut, cut / records.CHECKPOINT, 4 * CHUNK, 0.08)   # let it write a chunk past the checkpoint
    # what was written before the kill is readable and is the start of the whole run
    part_out, part_plant, info = records.load_records(str(cut))
    assert not info["complete"] and 0 < len(part_out) < len(whole.outputs)
    assert part_out.tobytes() == np.asarray(whole.outputs[:len(part_out)]).tobytes()
    resumed = _run(str(cut), checkpoint_ticks=2 * CHUNK, resume=True)
    assert len(resumed.outputs) == len(whole.outputs) == TICKS // 100
    assert np.asarray(resumed.outputs).tobytes() == np.asarray(whole.outputs).tobytes()
    assert np.asarray(resumed.plant).tobytes() == np.asarray(whole.plant).tobytes()
    _, _, info = records.load_records(str(cut))
    assert info["complete"] and info["ticks_done"] == TICKS


def test_resume_refuses_another_runs_checkpoint(tmp_path):
    d = str(tmp_path / "r")
    fil.run_fil(sim.Static(0.6, 0.0, 0.0), 4 * CHUNK, chunk_ticks=CHUNK, record_dir=d,
                checkpoint_ticks=CHUNK)
    with pytest.raises(ValueError, match="belongs to another run"):
        fil.run_fil(sim.Static(0.6, 0.0, 0.0), 4 * CHUNK, chunk_ticks=CHUNK, record_dir=d,
                    checkpoint_ticks=CHUNK, resume=True, seed=1)


def test_resume_of_a_finished_run_recomputes_nothing(tmp_path):
    d = str(tmp_path / "r")
    a = fil.run_fil(sim.Static(0.6, 0.0, 0.0), 2 * CHUNK, chunk_ticks=CHUNK, record_dir=d,
                    checkpoint_ticks=CHUNK)
    calls = []
    b = fil.run_fil(sim.Static(0.6, 0.0, 0.0), 2 * CHUNK, chunk_ticks=CHUNK, record_dir=d,
                    checkpoint_ticks=CHUNK, resume=True, progress=lambda d, t: calls.append(d))
    assert calls == [] and np.asarray(a.outputs).tobytes() == np.asarray(b.outputs).tobytes()


def test_checkpoint_arguments_are_checked():
    with pytest.raises(ValueError, match="need record_dir"):
        fil.run_fil(sim.Static(0.6, 0.0, 0.0), 10, checkpoint_ticks=5)
    with pytest.raises(ValueError, match="checkpoint_ticks must be > 0"):
        fil.run_fil(sim.Static(0.6, 0.0, 0.0), 10, record_dir="/tmp/x", checkpoint_ticks=0)


@pytest.mark.parametrize("wall_s, expected", [(None, TICKS // (2 * CHUNK)), (0.0, TICKS // (2 * CHUNK)),
                                              (1e9, 1)])
def test_checkpoints_at_most_one_per_wall_interval(tmp_path, monkeypatch, wall_s, expected):
    """checkpoint_wall_s spaces the checkpoints in wall time too (what a
    run directory uses: a 72 h run took 130 of them in 3 s); the last one,
    at the end, is always written; the records are the same."""
    written = []
    real = records.write_checkpoint

    def counting(path, digest, done, *a, **k):
        written.append(done)
        return real(path, digest, done, *a, **k)
    monkeypatch.setattr(records, "write_checkpoint", counting)
    res = _run(str(tmp_path / "r"), checkpoint_ticks=2 * CHUNK, checkpoint_wall_s=wall_s)
    assert len(written) == expected and written[-1] == TICKS
    ref = _run(None)
    assert res.outputs.tobytes() == ref.outputs.tobytes()
    with pytest.raises(ValueError, match="checkpoint_wall_s"):
        _run(str(tmp_path / "bad"), checkpoint_ticks=2 * CHUNK, checkpoint_wall_s=-1.0)
