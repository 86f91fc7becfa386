"""The Python side of the C ABI contract: layout, configuration errors,
rejected samples, input checking, determinism."""
import numpy as np
import pytest

from pyins import native
from pyins.reference import earth


def static_samples(n, lat=0.5):
    """Error-free increments of a level IMU at yaw 0 on a static base."""
    g = earth.normal_gravity(np.sin(lat), 0.0)
    w = earth.OMEGA_IE
    dth = np.tile([0.0, w * np.cos(lat) * 0.01, w * np.sin(lat) * 0.01], (n, 1))
    dv = np.tile([0.0, 0.0, g * 0.01], (n, 1))
    return native.make_samples(dth, dv)


def test_layout_matches_library():
    assert native.SAMPLE_DTYPE.itemsize == native.lib.pyins_sizeof_sample() == 64
    assert native.SAMPLE_DTYPE.fields["seq"][1] == 56
    assert native.OUTPUT_DTYPE.itemsize == native.lib.pyins_sizeof_output() == 696   # + navigation at sea (ABI 0.15), + the gyros' scale factors and misalignments (0.19)
    assert native.OUTPUT_DTYPE.itemsize % 8 == 0
    assert native.NAV_DTYPE.itemsize == native.lib.pyins_sizeof_nav() == 168   # the compact record (ABI 0.12), + nav_mode, ref_in_use (0.15)
    assert set(native.NAV_DTYPE.names) < set(native.OUTPUT_DTYPE.names)
    assert native.abi_version() == native.EXPECTED_ABI
    assert native.version() == "0.1.0"


@pytest.mark.parametrize("field, value, status", [
    ("lat_rad", np.deg2rad(91.0), "PYINS_E_CONFIG_LAT"),
    ("lat_rad", float("nan"), "PYINS_E_CONFIG_LAT"),
    ("tick_hz", -1, "PYINS_E_CONFIG_RATE"),
    ("lon_rad", float("inf"), "PYINS_E_CONFIG_LON"),
    ("height_m", 2e5, "PYINS_E_CONFIG_HEIGHT"),
    ("vel_n_mps", [0.0, float("nan"), 0.0], "PYINS_E_CONFIG_VEL"),
    ("euler_b_rad", [0.0, 0.0, float("inf")], "PYINS_E_CONFIG_ATT"),
    ("vertical_mode", 5, "PYINS_E_CONFIG_MODE"),
    ({"coarse_ticks": 15000, "coarse_ratio": 1.2}, None, "PYINS_E_CONFIG_ALIGN_RATIO"),
    ({"coarse_ticks": 15000, "coarse_first_output_ticks": 100}, None, "PYINS_E_CONFIG_ALIGN_EARLY"),
    ({"coarse_ticks": 60000}, None, "PYINS_E_CONFIG_ALIGN_LONG"),
    ({"fine_ticks": 1000, "fine_states": 7}, None, "PYINS_E_CONFIG_FINE"),
    ({"fine_ticks": 1000, "fine_gyro_arw": -1e-7}, None, "PYINS_E_CONFIG_NOISE"),
])
def test_config_errors_are_distinct_and_named(field, value, status):
    with pytest.raises(native.ConfigError) as info:
        native.Firmware(**(field if isinstance(field, dict) else {field: value}))
    assert info.value.status_name == status
    assert isinstance(info.value, ValueError)


def test_config_key_errors():
    with pytest.raises(ValueError, match="unknown key 'latitude'"):
        native.Firmware(latitude=0.5)
    with pytest.raises(ValueError, match="euler_b_rad needs 3 values"):
        native.Firmware(euler_b_rad=[0.0, 1.0])
    with pytest.raises(ValueError, match="vertical_mode 'up'"):
        native.Firmware(vertical_mode="up")


def test_rejected_sample_leaves_state_unchanged():
    fw = native.Firmware(lat_rad=0.5)
    samples = static_samples(10)
    fw.run(samples[:5])
    before = fw.output()
    bad = samples[5:].copy()
    bad["dv_p_mps"][2, 1] = np.nan
    with pytest.raises(native.SampleError) as info:
        fw.run(bad)
    assert info.value.index == 2 and len(info.value.outputs) == 2
    assert info.value.status_name == "PYINS_E_SAMPLE_NONFINITE"
    # the two good samples were taken, the bad one not: only its fault bit
    # and counter tell it was there
    after = fw.output()
    assert after["tick"] == before["tick"] + 2
    assert after["fault_flags"] == native.lib.PYINS_FAULT_SAMPLE_NONFINITE and after["n_nonfinite"] == 1
    fw2 = native.Firmware(lat_rad=0.5)
    fw2.run(samples[:7])
    ref = fw2.output()
    ref["fault_flags"], ref["n_nonfinite"] = after["fault_flags"], after["n_nonfinite"]
    assert ref.tobytes() == after.tobytes()
    with pytest.raises(native.SampleError):
        fw.step([np.inf, 0, 0], [0, 0, 0.1])
    again = fw.output()
    assert again["n_nonfinite"] == 2
    again["n_nonfinite"] = 1
    assert again.tobytes() == after.tobytes()


@pytest.mark.parametrize("field", ["dtheta_p_rad", "dv_p_mps", "table_angle_rad"])
def test_wrong_arrays_raise_value_error_naming_the_field(field):
    n = 8
    good = {"dtheta_p_rad": np.zeros((n, 3)), "dv_p_mps": np.zeros((n, 3)),
            "table_angle_rad": np.zeros(n)}
    wrong_dtype = dict(good, **{field: good[field].astype(np.float32)})
    with pytest.raises(ValueError, match=f"{field}: dtype is float32"):
        native.make_samples(**wrong_dtype)
    wrong_int = dict(good, **{field: good[field].astype(np.int32)})
    with pytest.raises(ValueError, match=f"{field}: dtype is int32"):
        native.make_samples(**wrong_int)
    wrong_shape = dict(good, **{field: np.zeros((n, 4)) if good[field].ndim == 2 else np.zeros((n, 1))})
    with pytest.raises(ValueError, match=f"{field}: shape"):
        native.make_samples(**wrong_shape)
    # a view (every other row, a column slice of a log) is copied, not refused:
    # the documented path make_samples(d.dtheta_p, ...) gets such views (a log read by pyins.logs)
    big = np.random.default_rng(1).normal(size=(2 * n, 3) if good[field].ndim == 2 else 2 * n)
    view = dict(good, **{field: big[::2]})
    copy = dict(good, **{field: np.ascontiguousarray(big[::2])})
    assert not view[field].flags.c_contiguous
    assert native.make_samples(**view).tobytes() == native.make_samples(**copy).tobytes()


def test_run_checks_the_sample_array():
    fw = native.Firmware()
    with pytest.raises(ValueError, match="samples: expected an array of pyins.native.SAMPLE_DTYPE"):
        fw.run(np.zeros((4, 7)))
    s = static_samples(8)
    with pytest.raises(ValueError, match="samples: array is not C-contiguous"):
        fw.run(s[::2])
    with pytest.raises(ValueError, match="outputs:"):
        fw.run(s, outputs=np.zeros(3, dtype=native.OUTPUT_DTYPE))
    assert fw.output()["tick"] == 0      # nothing ran


def test_determinism_and_batch_equals_steps():
    rng = np.random.default_rng(7)
    n = 3000
    s = static_samples(n, lat=0.7)
    s["dtheta_p_rad"] += 1e-5 * rng.standard_normal((n, 3))
    s["dv_p_mps"] += 1e-3 * rng.standard_normal((n, 3))
    s["table_angle_rad"] = np.mod(0.001 * np.arange(n), 2 * np.pi)
    cfg = dict(lat_rad=0.7, euler_b_rad=[0.01, -0.02, 2.0], vel_n_mps=[1.0, 2.0, 0.0])
    a = native.Firmware(cfg).run(s)
    b = native.Firmware(cfg).run(s)
    assert a.tobytes() == b.tobytes()
    fw = native.Firmware(cfg)
    steps = [fw.step(x["dtheta_p_rad"], x["dv_p_mps"], x["table_angle_rad"]) for x in s]
    assert np.array(steps, dtype=native.OUTPUT_DTYPE).tobytes() == a.tobytes()
    # chunked runs equal one run
    fw = native.Firmware(cfg)
    chunks = np.concatenate([fw.run(s[i:i + 700]) for i in range(0, n, 700)])
    assert chunks.tobytes() == a.tobytes()


def test_decimated_run_matches_full_run_in_phase():
    s = static_samples(1050, lat=0.3)
    full = native.Firmware(lat_rad=0.3).run(s)
    fw = native.Firmware(lat_rad=0.3)
    parts = [fw.run(s[a:b], every=100) for a, b in ((0, 37), (37, 620), (620, 1050))]
    dec = np.concatenate(parts)
    assert list(dec["tick"]) == list(range(100, 1001, 100))
    assert dec.tobytes() == full[99:1000:100].tobytes()
    with pytest.raises(ValueError, match="every: must be a positive"):
        fw.run(s, every=0)


def test_runs_without_records_are_single_steps_bit_for_bit():
    """Ticks without a record, and compact records every tick, go through
    Firmware::run_plain (a loop over the plain samples: NAVIGATE, the next
    seq, the encoder within its jump limit), the others through step(): a
    stream that mixes both (seq gaps bridged, duplicates, a lost sequence,
    an encoder jump, a turning table under the two-position scheme, a
    moving ship) must leave the same instance bytes and the same records as
    single steps."""
    rng = np.random.default_rng(11)
    n = 2400
    s = static_samples(n, lat=0.6)
    s["dtheta_p_rad"] += 2e-5 * rng.standard_normal((n, 3))
    s["dv_p_mps"] += 3e-3 * rng.standard_normal((n, 3))
    s["table_angle_rad"] = np.mod(np.where(np.arange(n) > 300, 0.002 * (np.arange(n) - 300), 0.0), 2 * np.pi)
    seq = np.arange(n, dtype=np.int64) + 10
    seq[500:] += 2          # a gap of two ticks, bridged
    seq[900] = seq[899]     # a duplicate, dropped
    seq[1400:] += 1000      # beyond seq_max_gap_ticks: the sequence is lost
    s["seq"] = seq.astype(np.uint32)
    s["table_angle_rad"][1800:] += 0.5   # an encoder jump: taken, flagged
    cfg = dict(lat_rad=0.6, euler_b_rad=[0.01, -0.02, 1.0], vel_n_mps=[3.0, 4.0, 0.0],
               seq_mode=1, index_scheme=2, index_stop_ticks=200)
    one = native.Firmware(cfg)
    full = np.array([one.step(x["dtheta_p_rad"], x["dv_p_mps"], x["table_angle_rad"], seq=int(x["seq"]))
                     for x in s], dtype=native.OUTPUT_DTYPE)
    assert np.any(full["fault_flags"] != 0) and full["tick"][-1] > n   # the faults happened
    batch = native.Firmware(cfg)
    dec = np.concatenate([batch.run(s[a:b], every=7) for a, b in ((0, 450), (450, 1700), (1700, n))])
    assert batch.snapshot() == one.snapshot()
    kept = [k for k in range(n) if full["tick"][k] // 7 > (full["tick"][k - 1] // 7 if k else 0)]
    assert dec.tobytes() == full[kept].tobytes()
    # a compact record every tick: run_plain writes them in its loop, step()
    # the ones of the samples that stop it (one record per sample that
    # advanced the tick, a bridged gap's at its sample)
    compact = native.Firmware(cfg)
    nav = np.concatenate([compact.run_nav(s[a:b], every=1) for a, b in ((0, 450), (450, 1700), (1700, n))])
    assert compact.snapshot() == one.snapshot()
    advanced = [k for k in range(n) if full["tick"][k] > (full["tick"][k - 1] if k else 0)]
    assert len(advanced) < n and len(nav) == len(advanced)
    for field in native.NAV_DTYPE.names:
        assert np.ascontiguousarray(nav[field]).tobytes() == \
            np.ascontiguousarray(full[advanced][field]).tobytes(), field


@pytest.mark.parametrize("lib_path, message", [
    ("/nonexistent/libpyins_core.so", "was not found"),
    ("libm", "is not a pyins core library"),
])
def test_import_fails_with_one_clear_message(tmp_path, lib_path, message):
    """A missing or wrong library makes `import pyins.native` fail with a
    message that says what to run, not with a cffi traceback later."""
    import ctypes.util
    import os
    import subprocess
    import sys
    if lib_path == "libm":
        libm = ctypes.util.find_library("m")
        libm = next((os.path.join(d, "libm.so.6") for d in ("/lib/x86_64-linux-gnu", "/lib/aarch64-linux-gnu",
                                                             "/usr/lib64", "/lib64")
                     if os.path.exists(os.path.join(d, "libm.so.6"))), libm)
        (tmp_path / "lib.so").symlink_to(libm)
        for h in ("pyins_core.h", "pyins_core_testing.h"):   # headers beside it, as installed
            (tmp_path / h).write_text((native.LIBRARY_PATH.parent / h).read_text())
        lib_path = str(tmp_path / "lib.so")
    env = dict(os.environ, PYINS_CORE_LIB=lib_path)
    res = subprocess.run([sys.executable, "-c", "import pyins.native"], env=env,
                         capture_output=True, text=True)
    assert res.returncode != 0
    last = res.stderr.strip().splitlines()[-1]
    assert last.startswith("ImportError: pyins:") and message in last
    assert "pip install ." in last
