"""The engine choice end to end: a built-in scenario, shortened to 30 s of
ship time, through ``pyins run --engine native`` and ``--engine reference``
(the same code path: pyins.run_scenario.execute -> pyins.fil.run_fil, with the
compiled firmware and plant or their NumPy mirrors), and a log through
``pyins replay --engine``."""
import numpy as np
import pytest

from pyins import __main__ as cli
from pyins import records, rundir, scenario

#: seed 002's flexible scheme with a 5 s stop: the table turns within 30 s,
#: so the firmware's motor commands close the loop through the plant.
ARGS = ["seed002_exp1", "--hours", str(30 / 3600), "--set", 'indexing.stop="5 s"', "--set",
        'record_every="0.5 s"', "--quiet"]


def _records(run_dir, engine):
    out = run_dir / engine
    assert cli.main(["run", *ARGS, "--out", str(out), "--engine", engine]) == cli.EXIT_OK
    scn = scenario.load("seed002_exp1")
    got = {}
    for spec in scn.runs():
        outputs, plant, info = records.load_records(str(out / rundir.slug(spec.label) / "records"))
        assert info["complete"] and len(outputs) == 60
        got[spec.label] = (np.array(outputs), np.array(plant))
    return got


@pytest.fixture(scope="module")
def both(tmp_path_factory):
    d = tmp_path_factory.mktemp("engines")
    return _records(d, "native"), _records(d, "reference")


def test_both_engines_run_the_same_loop(both):
    """The plant's records bit for bit, the firmware's decisions identical, its
    navigation within the cross-check bounds (tests/crosscheck)."""
    native, reference = both
    assert native.keys() == reference.keys()
    for label in native:
        (out_n, plant_n), (out_r, plant_r) = native[label], reference[label]
        assert plant_n.tobytes() == plant_r.tobytes(), label
        for f in ("tick", "mode", "index_state", "index_step", "fault_flags", "seq"):
            assert np.array_equal(out_n[f], out_r[f]), (label, f)
        # The engines are not bit-identical in the floats (portable vs libm
        # sin/cos, Eigen vs NumPy summation order: ulps from the first tick),
        # so these bounds are far above that and far below anything an INS
        # engineer would see: a quaternion component 1e-10 is ~4e-5 arcsec,
        # 1e-12 rad of latitude ~6 um, 1e-9 m/s of velocity.
        np.testing.assert_allclose(out_r["quat_np"], out_n["quat_np"], rtol=0, atol=1e-10)
        np.testing.assert_allclose(out_r["lat_rad"], out_n["lat_rad"], rtol=0, atol=1e-12)
        np.testing.assert_allclose(out_r["vel_n_mps"], out_n["vel_n_mps"], rtol=0, atol=1e-9)


def test_replay_through_both_engines(tmp_path):
    log = tmp_path / "imu.npz"
    assert cli.main(["simulate", "seed003", str(log), "--hours", str(20 / 3600), "--quiet"]) == 0
    got = {}
    for engine in ("native", "reference"):
        out = tmp_path / engine
        assert cli.main(["replay", str(log), "--out", str(out), "--engine", engine, "--every", "50",
                         "--quiet"]) == 0
        got[engine] = np.load(out / "navigation.npz")["outputs"]
    assert len(got["native"]) == len(got["reference"]) == 40
    for f in ("tick", "mode", "fault_flags"):
        assert np.array_equal(got["native"][f], got["reference"][f])
    # ~4e-5 arcsec: as above
    np.testing.assert_allclose(got["reference"]["quat_np"], got["native"]["quat_np"], rtol=0, atol=1e-10)


def test_an_unknown_engine_is_refused(capsys):
    with pytest.raises(SystemExit):
        cli.main(["run", "seed003", "--engine", "fortran"])
    assert "invalid choice" in capsys.readouterr().err
