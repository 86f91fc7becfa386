"""The two engines behind one contract: ``pyins.native.Firmware`` (the C++
core) and ``pyins.reference.Firmware`` (the NumPy mirror), driven through
the same public calls over a short stream that passes coarse alignment,
fine alignment and navigation with a two-position indexing cycle.

Both give records of the same dtype (``native.OUTPUT_DTYPE``); every integer
field (tick, mode, flags, counters, indexing state) is equal, every float
field equal to a few ulps (portable vs libm sin/cos, Eigen vs NumPy
summation order: see test_xcheck_run). Rejections raise the same exception
type at the same index with the same records before it; notices land in
``last_status``; the decimated run gives the records of the full run at the
multiples of ``every``. Each engine is deterministic: its own records are
the same bit for bit run after run and across a snapshot.
"""
import numpy as np
import pytest

from pyins import engine, native
from pyins import reference
from pyins.reference import abi, earth
from pyins import units

ENGINES = {"native": native.Firmware, "reference": reference.Firmware}
N = 2600
LAT = 30.0 * units.DEG_TO_RAD
CFG = dict(lat_rad=LAT, euler_b_rad=[0.0, 0.0, 0.4], coarse_ticks=1000, coarse_first_output_ticks=500,
           coarse_output_every_ticks=100, fine_ticks=1000, index_scheme=abi.PYINS_INDEX_TWO_POSITION,
           seq_mode=abi.PYINS_SEQ_CHECK)
INTEGER = [n for n in native.OUTPUT_DTYPE.names if native.OUTPUT_DTYPE[n].base.kind in "iu"]
FLOAT = [n for n in native.OUTPUT_DTYPE.names if native.OUTPUT_DTYPE[n].base.kind == "f"]


def stream(n=N, seed=1):
    """A ship at rest at LAT with a little sway, the table turning 0.1 rad/s."""
    rng = np.random.default_rng(seed)
    dt = 1.0 / 100.0
    w_ie = np.array([0.0, earth.OMEGA_IE * np.cos(LAT), earth.OMEGA_IE * np.sin(LAT)])
    t = np.arange(n) * dt
    dtheta = (np.tile(w_ie * dt, (n, 1)) + 1e-4 * dt * np.sin(0.5 * t)[:, None] * [1.0, 0.5, 0.2]
              + rng.normal(0.0, 1e-7, (n, 3)))
    dv = np.tile([0.0, 0.0, 9.79 * dt], (n, 1)) + rng.normal(0.0, 1e-5, (n, 3))
    alpha = (0.3 + 0.1 * t) % (2.0 * np.pi)
    return native.make_samples(dtheta, dv, alpha, seq=np.arange(n))


def assert_same_records(a, b):
    assert a.dtype == b.dtype == native.OUTPUT_DTYPE
    assert a.shape == b.shape
    for name in INTEGER:
        np.testing.assert_array_equal(a[name], b[name], err_msg=name)
    for name in FLOAT:
        np.testing.assert_allclose(a[name], b[name], rtol=1e-12, atol=1e-12, err_msg=name)


def test_run_through_every_mode_gives_the_same_records():
    s = stream()
    out = {e: cls(CFG).run(s) for e, cls in ENGINES.items()}
    assert set(np.unique(out["native"]["mode"])) == {abi.PYINS_MODE_COARSE_ALIGN, abi.PYINS_MODE_FINE_ALIGN,
                                                     abi.PYINS_MODE_NAVIGATE}
    assert_same_records(out["native"], out["reference"])
    again = reference.Firmware(CFG).run(s)
    assert again.tobytes() == out["reference"].tobytes()    # the reference is deterministic


def test_step_by_step_equals_run_and_output_is_the_last_record():
    s = stream(1200)
    for cls in ENGINES.values():
        whole = cls(CFG).run(s)
        fw = cls(dict(CFG, fine_ticks=500), fine_ticks=1000)     # keywords override the dict
        steps = np.array([fw.step(x["dtheta_p_rad"], x["dv_p_mps"], x["table_angle_rad"], x["seq"])
                          for x in s])
        assert steps.tobytes() == whole.tobytes()
        assert fw.output().tobytes() == whole[-1].tobytes()
        assert fw.config["coarse_ticks"] == 1000 and fw.config["fine_ticks"] == 1000


def test_decimated_run_gives_the_records_at_the_multiples():
    s = stream(1500)
    for name, cls in ENGINES.items():
        whole = cls(CFG).run(s)
        every = cls(CFG).run(s, every=100)
        assert every.tobytes() == whole[99::100].tobytes(), name


def test_compact_records_agree_between_engines_and_with_the_full_ones():
    """run_nav (pyins_run_nav and its mirror): each engine's compact records
    are its own full records' fields bit for bit, and the engines agree as
    the full records do (integers equal, floats to 1e-12: a few ulps)."""
    s = stream(1500)
    compact = {}
    for name, cls in ENGINES.items():
        whole = cls(CFG).run(s)
        fw = cls(CFG)
        compact[name] = np.concatenate([fw.run_nav(s[:700]), fw.run_nav(s[700:], every=1)])
        assert compact[name].dtype == native.NAV_DTYPE
        for field in native.NAV_DTYPE.names:
            assert np.ascontiguousarray(compact[name][field]).tobytes() == \
                np.ascontiguousarray(whole[field]).tobytes(), (name, field)
        assert fw.nav().tobytes() == compact[name][-1].tobytes()
        every = cls(CFG).run_nav(s, every=100)
        assert every.tobytes() == compact[name][99::100].tobytes(), name
    for field in native.NAV_DTYPE.names:
        if native.NAV_DTYPE[field].base.kind in "iu":
            np.testing.assert_array_equal(compact["native"][field], compact["reference"][field], err_msg=field)
        else:
            np.testing.assert_allclose(compact["native"][field], compact["reference"][field], rtol=1e-12,
                                       atol=1e-12, err_msg=field)


def test_rejected_sample_and_notice():
    s = stream(900)
    s["dv_p_mps"][700, 1] = np.nan
    s["seq"][300:] += 1        # one tick missing before sample 300: a notice, alignment restarts
    got = {}
    for name, cls in ENGINES.items():
        fw = cls(CFG)
        with pytest.raises(native.SampleError) as exc:
            fw.run(s)
        assert exc.value.code == abi.PYINS_E_SAMPLE_NONFINITE and exc.value.index == 700
        got[name] = exc.value.outputs
        assert got[name]["align_restarts"][-1] == 1
        fw2 = cls(CFG)
        fw2.run(s[:300])
        fw2.step(s["dtheta_p_rad"][300], s["dv_p_mps"][300], s["table_angle_rad"][300], s["seq"][300])
        assert fw2.last_status == abi.PYINS_W_SEQ_GAP
        with pytest.raises(native.SampleError):
            fw2.step([np.inf, 0.0, 0.0], [0.0, 0.0, 0.1])
        assert fw2.last_status == abi.PYINS_E_SAMPLE_NONFINITE
    assert_same_records(got["native"], got["reference"])


def test_refused_configuration_raises_the_same_status():
    for cls in ENGINES.values():
        with pytest.raises(native.ConfigError) as exc:
            cls(CFG, lat_rad=2.0)
        assert exc.value.code == abi.PYINS_E_CONFIG_LAT
        with pytest.raises(ValueError):
            cls(CFG, no_such_field=1)


def test_snapshot_and_index_reset():
    s = stream(1500)
    for cls in ENGINES.values():
        whole = cls(CFG).run(s)
        fw = cls(CFG)
        fw.run(s[:800])
        blob = fw.snapshot()
        rest = cls.from_snapshot(blob).run(s[800:])
        assert rest.tobytes() == whole[800:].tobytes()
        fw.index_reset()      # not in FAULT: nothing changes
        assert fw.run(s[800:]).tobytes() == whole[800:].tobytes()
        with pytest.raises(native.SnapshotError):
            fw.restore(blob[:-1] + bytes([blob[-1] ^ 1]))


def test_engine_choice_and_a_missing_native_engine(monkeypatch):
    """pyins.engine picks the class by name; without pyins.native (no
    library: engine.native is None) the reference engine still runs and the
    native one raises ImportError saying why (tests/reference/test_no_library.py
    does it with the library really absent)."""
    assert type(engine.firmware("native", CFG)) is native.Firmware
    assert type(engine.firmware("reference", CFG)) is reference.Firmware
    with pytest.raises(ValueError, match="is not one of native, reference"):
        engine.firmware("numba", CFG)
    monkeypatch.setattr(engine, "native", None)
    monkeypatch.setattr(engine, "_NATIVE_ERROR", "pyins: no library here")
    assert type(engine.firmware("reference", CFG)) is reference.Firmware
    with pytest.raises(ImportError, match=r"engine 'native' is not available \(pyins: no library here\)"):
        engine.firmware("native", CFG)
    with pytest.raises(ImportError, match="not available"):
        engine.plant("native", None, None, None)


@pytest.mark.parametrize("fields", [{}, CFG, dict(lat_rad=2.0), dict(tick_hz=-1), dict(fine_states=6),
                                    dict(index_scheme=abi.PYINS_INDEX_CUSTOM), dict(seq_max_gap_ticks=101)])
def test_config_check_is_the_cores_with_or_without_the_library(fields, monkeypatch):
    want = native.lib.pyins_config_check(native.make_config(fields))
    assert engine.config_check(fields) == want
    monkeypatch.setattr(engine, "native", None)
    assert engine.config_check(fields) == want
