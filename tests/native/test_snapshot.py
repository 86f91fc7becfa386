"""Snapshot and restore: a run stopped at any tick and restored continues
bit-identically, in every mode; bad blobs are refused, state untouched."""
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from pyins import native, scenario, sim

M = sim.sea_state("general", 0.6, 0.1, 0.0, yaw0=0.5)
N = 9000
_DTH, _DV, _AL = sim.exact_increments(M, N)
_DTH, _DV = sim.SensorModel(sim.preset("seed001"), seed=4).apply(_DTH, _DV)
SAMPLES = native.make_samples(_DTH, _DV, _AL)
# coarse 0-2999, fine 3000-5999, navigation with indexing after
CFG = scenario.initial_config(M, None, coarse_ticks=3000, fine_ticks=3000, index_scheme=4, index_stop_ticks=500,
                            euler_b_rad=[0.0, 0.0, 0.0])
FULL = native.Firmware(CFG).run(SAMPLES)


@settings(max_examples=25, deadline=None)
@given(cut=st.integers(0, N - 1))
def test_restore_at_any_tick_continues_bit_identically(cut):
    fw = native.Firmware(CFG)
    fw.run(SAMPLES[:cut])
    blob = fw.snapshot()
    restored = native.Firmware.from_snapshot(blob)
    rest = restored.run(SAMPLES[cut:])
    assert rest.tobytes() == FULL[cut:].tobytes()


def test_every_mode_is_covered():
    assert set(FULL["mode"]) == {1, 2, 3} and 2 in set(FULL["index_state"])


@pytest.mark.parametrize("damage, status", [
    (lambda b: b[:-1], "PYINS_E_SNAPSHOT_SIZE"),
    (lambda b: b + b"\0", "PYINS_E_SNAPSHOT_SIZE"),
    (lambda b: b[:10], "PYINS_E_SNAPSHOT_SIZE"),
    (lambda b: b[:8] + bytes([b[8] ^ 1]) + b[9:], "PYINS_E_SNAPSHOT_VERSION"),
    (lambda b: b[:500] + bytes([b[500] ^ 0x10]) + b[501:], "PYINS_E_SNAPSHOT_CORRUPT"),
    (lambda b: b"XYSN" + b[4:], "PYINS_E_SNAPSHOT_CORRUPT"),
])
def test_bad_blobs_refused_state_untouched(damage, status):
    fw = native.Firmware(CFG)
    fw.run(SAMPLES[:4000])
    blob = fw.snapshot()
    other = native.Firmware(CFG)
    other.run(SAMPLES[:100])
    before = other.output().tobytes()
    with pytest.raises(native.SnapshotError) as info:
        other.restore(damage(blob))
    assert info.value.status_name == status
    assert other.output().tobytes() == before
    with pytest.raises(ValueError, match="snapshot: expected bytes"):
        other.restore("not bytes")
