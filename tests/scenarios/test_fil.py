"""Firmware-in-the-loop scenarios through the compiled plant."""
import numpy as np
import pytest

from pyins import fil, runner, sim
from pyins.reference import earth
from pyins.sim import turntable

DEG = earth.DEG_TO_RAD


def test_error_free_24h_flexible_scheme_on_heading_swing():
    """Error-free sensors, 24 h, flexible scheme, seed 002 experiment 1:
    horizontal error < 10 m (100 times below the effects under study). Also
    the machine really indexes: moves happen, no fault, no fallback."""
    m = sim.HeadingSwing.experiment(1)
    res = fil.run_fil(m, 24 * 360_000, config=dict(index_scheme=4), every=100)
    e = runner.nav_errors(res)
    o = res.outputs
    print(f"\nerror-free 24 h FIL flexible: max horizontal {e.horizontal_m.max():.3e} m, "
          f"max attitude {np.abs(e.att_n_rad).max() / earth.ARCSEC_TO_RAD:.2e} arcsec, "
          f"max velocity {np.abs(e.vel_n_mps).max():.2e} m/s, table travelled {np.abs(np.diff(res.plant['alpha_rad'])).sum() / DEG:.0f} deg")
    assert e.horizontal_m.max() < 10.0
    # the table really turns the IMU: a frame or sign error in the plant or
    # the firmware would show here at once (degrees, m/s)
    assert np.abs(e.att_n_rad).max() < 0.01 * earth.ARCSEC_TO_RAD
    assert np.abs(e.vel_n_mps).max() < 1e-6
    assert np.all(o["index_fault"] == 0) and o["index_fallbacks"][-1] == 0
    assert np.count_nonzero(o["index_state"] == 2) > 100


@pytest.mark.parametrize("fault, code", [(turntable.TABLE_STALL, 1), (turntable.TABLE_REVERSE, 1),
                                         (turntable.TABLE_JUMP, 2)])
def test_table_faults_detected_within_configured_time(fault, code):
    m = sim.Static(0.6, 0.0, 0.0)
    table = turntable.TableConfig(fault=fault, fault_tick=29_000, jump_rad=10.0 * DEG)
    res = fil.run_fil(m, 40_000, config=dict(index_scheme=2, index_timeout_ticks=150), table=table, every=1)
    o = res.outputs
    first_fault = int(np.argmax(o["index_state"] == 3))
    assert o["index_fault"][-1] == code and first_fault > 0
    if fault == turntable.TABLE_JUMP:
        assert first_fault == 29_000                   # the tick the reading jumps
    else:
        # the first move starts at 30 000 (stop 300 s); detected within the
        # 150-tick timeout after the lag exceeds 0.5 deg (under 0.2 s)
        assert 30_000 <= first_fault <= 30_000 + 150 + 25
    assert np.all(o["mode"][first_fault:] == 3) and np.all(np.isfinite(o["lat_rad"]))


def test_records_streamed_to_disk_equal_in_memory(tmp_path):
    m = sim.HeadingSwing.experiment(2)
    a = fil.run_fil(m, 50_000, config=dict(index_scheme=4, index_stop_ticks=1000), every=10,
                    chunk_ticks=7_000)
    b = fil.run_fil(m, 50_000, config=dict(index_scheme=4, index_stop_ticks=1000), every=10,
                    chunk_ticks=7_000, record_dir=tmp_path)
    assert isinstance(b.outputs, np.memmap)
    assert np.asarray(b.outputs).tobytes() == a.outputs.tobytes()
    assert np.asarray(b.plant).tobytes() == a.plant.tobytes()
    assert (tmp_path / "records.json").exists()
    # chunking does not change the run: one chunk gives the same bits
    c = fil.run_fil(m, 50_000, config=dict(index_scheme=4, index_stop_ticks=1000), every=10)
    assert c.outputs.tobytes() == a.outputs.tobytes()


def test_text_progress_draws_on_a_terminal():
    import io

    class Tty(io.StringIO):
        def isatty(self):
            return True

    s = Tty()
    p = fil.TextProgress(stream=s)
    p(180_000, 360_000)
    p(360_000, 360_000)
    text = s.getvalue()
    assert "0.50/1.00 h ship time" in text and text.endswith("\n")
    quiet = io.StringIO()
    fil.TextProgress(stream=quiet)(1, 2)
    assert quiet.getvalue() == ""



@pytest.fixture(scope="module")
def isolated_runs():
    """Seed 002 experiment 1, 72 h, the horizontal gyro drifts (0.003 deg/h)
    the only error: max horizontal error [m] per scheme."""
    m = sim.HeadingSwing.experiment(1)
    errors = sim.SensorErrors(gyro_bias=np.array([1.0, 1.0, 0.0]) * 0.003 * earth.DPH_TO_RPS)
    worst = {}
    for s in (0, 2, 4, 6):
        res = fil.run_fil(m, 72 * 360_000, config=dict(index_scheme=s), errors=errors, every=100)
        worst[s] = runner.nav_errors(res).horizontal_m.max()
    print("\nmax horizontal error, nmi: " + ", ".join(f"scheme {k} {v / 1852:.3f}" for k, v in worst.items()))
    return worst


@pytest.mark.parametrize("scheme, beats_traditional", [(4, False), (6, True)])
def test_isolated_horizontal_drifts_scheme_order(isolated_runs, scheme, beats_traditional):
    """No rotation > traditional always. The literal flexible scheme (with its
    fixed 180-deg moves, the default) does NOT beat the traditional one on
    the constant drifts alone; the derivation form (scheme 6) does, by more
    than 20 %. This pins the measured behaviour (docs/indexing.md)."""
    worst = isolated_runs
    assert worst[0] > worst[2]
    if beats_traditional:
        assert worst[scheme] < 0.8 * worst[2]
    else:
        assert worst[scheme] > worst[2]
