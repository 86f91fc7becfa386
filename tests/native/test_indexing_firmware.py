"""The indexing machine inside the firmware: C++ against the NumPy reference
in a closed loop with an ideal table, and the encoder faults."""
import numpy as np
import pytest

from pyins import native, scenario, sim
from pyins.reference import firmware as ref_firmware
from pyins import units

DEG = units.DEG_TO_RAD


def closed_loop(fw_step, n, dtheta, dv, follow):
    """Step n ticks; the encoder reads follow(k, previous record)."""
    enc = 0.0
    recs = []
    for k in range(n):
        rec = fw_step(dtheta[k], dv[k], enc % (2 * np.pi))
        recs.append(rec)
        enc = follow(k, rec, enc)
    return recs


@pytest.mark.parametrize("scheme, sums", [(1, 0), (2, 0), (3, 0), (4, 0), (6, 0), (4, 1), (6, 1)])
def test_cpp_equals_reference_in_closed_loop(scheme, sums):
    m = sim.HeadingSwing.experiment(1)
    n = 4000
    dtheta, dv, _ = sim.exact_increments(m, n)
    cfg = scenario.initial_config(m, None, index_scheme=scheme, index_stop_ticks=400, index_sums=sums)
    fw = native.Firmware(cfg)
    ref = ref_firmware.Firmware(cfg)

    def ideal(k, rec, enc):          # the table is where it was commanded
        return rec["table_angle_cmd_rad"]

    c = closed_loop(lambda a, b, e: fw.step(a, b, e), n, dtheta, dv, ideal)
    r = closed_loop(lambda a, b, e: ref.step(a, b, e)[1], n, dtheta, dv, ideal)
    moves = 0
    for k, (x, y) in enumerate(zip(c, r)):
        for f in ("index_state", "index_step", "index_fault", "index_fallbacks"):
            assert x[f] == y[f], (k, f)
        for f in ("table_angle_cmd_rad", "motor_rate_cmd_rad_s", "index_a_c", "index_a_s"):
            assert abs(x[f] - y[f]) <= 1e-9 * max(1.0, abs(y[f])), (k, f)
        moves += x["index_state"] == 2
    assert moves > 100                                  # the table really turned
    # the sums over the turns too (index_sums = 1) or only over the stops
    a_c = np.array([x["index_a_c"] for x in c])
    # a tick is a turn's when the machine was turning before it (a record shows
    # the state after its tick: the last stopped tick already reads MOVE)
    turning = np.concatenate([[False], [x["index_state"] == 2 for x in c[:-1]]])
    changed = np.concatenate([[False], np.diff(a_c) != 0.0])
    assert np.any(changed & turning) == (sums == 1)


def _faulting(follow, n=3000):
    m = sim.Static(0.6, 0.0, 0.0)
    dtheta, dv, _ = sim.exact_increments(m, n)
    cfg = scenario.initial_config(m, None, index_scheme=2, index_stop_ticks=300)
    fw = native.Firmware(cfg)
    recs = closed_loop(lambda a, b, e: fw.step(a, b, e), n, dtheta, dv, follow)
    return fw, np.array(recs, dtype=native.OUTPUT_DTYPE)


@pytest.mark.parametrize("name, follow, fault", [
    ("stalled", lambda k, rec, enc: enc, 1),
    ("reversed", lambda k, rec, enc: -rec["table_angle_cmd_rad"], 1),
    ("jumping", lambda k, rec, enc: rec["table_angle_cmd_rad"] + (0.3 if k == 1000 else 0.0), 2),
])
def test_encoder_faults_detected_and_navigation_goes_on(name, follow, fault):
    fw, recs = _faulting(follow)
    state = recs["index_state"]
    assert state[-1] == 3 and recs["index_fault"][-1] == fault, name
    first_move = int(np.argmax(state == 2))
    first_fault = int(np.argmax(state == 3))
    if fault == 1:
        # detected within the configured time (2 s, 200 ticks) after the lag
        # passes the 0.5 deg tolerance: at 30 deg/s^2 that takes sqrt(2 0.5 / 30) s
        build_up = int(np.ceil(np.sqrt(2 * 0.5 / 30.0) * 100))
        assert first_fault - first_move <= 200 + build_up + 2, name
    else:
        assert first_fault == 1001, name
    after = recs[first_fault:]
    assert np.all(after["mode"] == 3) and np.all(np.isfinite(after["lat_rad"]))
    assert np.all(after["motor_rate_cmd_rad_s"] == 0.0)   # the motor is stopped
    fw.index_reset()
    assert fw.output()["index_state"] == 1 and fw.output()["index_fault"] == 0


def test_custom_scheme_and_config_errors():
    fw = native.Firmware(index_scheme=5, index_n_steps=2, index_rate_rad_s=0.2, index_accel_rad_s2=1.0,
                         index_steps=[(50, 1, np.pi / 2), (50, 1, -np.pi / 2)])
    assert fw.output()["index_state"] == 0               # idle until the first sample
    with pytest.raises(native.ConfigError) as info:
        native.Firmware(index_scheme=5, index_n_steps=0)
    assert info.value.status_name == "PYINS_E_CONFIG_INDEX_EMPTY"
    with pytest.raises(native.ConfigError) as info:
        native.Firmware(index_scheme=5, index_n_steps=1, index_rate_rad_s=0.0, index_accel_rad_s2=1.0,
                        index_steps=[(50, 1, 1.0)])
    assert info.value.status_name == "PYINS_E_CONFIG_INDEX_RATE"
    with pytest.raises(native.ConfigError) as info:
        native.Firmware(index_scheme=5, index_n_steps=1, index_rate_rad_s=0.1, index_accel_rad_s2=1.0,
                        index_delta=0.0, index_steps=[(50, 2, 1.0)])
    assert info.value.status_name == "PYINS_E_CONFIG_INDEX_DELTA"
    with pytest.raises(native.ConfigError) as info:
        native.Firmware(index_scheme=6, index_sums=2)
    assert info.value.status_name == "PYINS_E_CONFIG_INDEX_SUMS"
    with pytest.raises(ValueError, match=r"index_steps\[0\]"):
        native.Firmware(index_steps=[(1, 2)])
