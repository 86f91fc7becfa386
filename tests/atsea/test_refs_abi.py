"""pyins_push_ref's front door, both engines: every refusal has its own
status and changes nothing (the snapshot after it is the snapshot before
it); a reference pushed ahead waits for its tick, one pushed late is
carried forward; a snapshot carries the queue; an UNDAMPED firmware takes
none. Nothing here needs a long run: a static IMU for a few seconds."""
import numpy as np
import pytest

from pyins import contract, engine
from pyins.reference import abi, earth

LAT = 0.5
G = 9.7946          # near normal gravity at 28.6 deg [m/s^2]: a static IMU, tilt-free


def _fw(eng, **cfg):
    return engine.firmware(eng, {"lat_rad": LAT, **cfg})


def _static(n):
    return contract.make_samples(np.zeros((n, 3)), np.tile([0.0, 0.0, G * 0.01], (n, 1)))


def _pos(tick, lat=LAT, lon=None, sigma=3.0):
    # a distinct longitude per tick (a repeated fix is a frozen receiver's: not used)
    lon = tick * 1e-12 if lon is None else lon
    return contract.make_refs("gnss_pos", [tick], [[lat, lon, 0.0]], [[sigma, sigma, 5.0]])


def _water_track():
    # a DVL reading marked as water track (reserved != 0): not used by this firmware
    r = contract.make_refs("dvl", [50], [[5.0, 0, 0]], [[0.1, 0.1, 0.1]])
    r["reserved"] = 1
    return r


def _state(fw):
    # the reference engine's snapshot holds its own state; the C one the instance's bytes
    return fw.snapshot()


@pytest.mark.parametrize("eng", ["native", "reference"])
@pytest.mark.parametrize("ref, status", [
    (_water_track(), "PYINS_E_REF_KIND"),
    (contract.make_refs("dvl", [50], [[5.0, 0, 0]], [[0.1, 0.1, 0.0]]), "PYINS_E_REF_VALUE"),
    (contract.make_refs("speed_log", [50], [[5.0, 0, 0]], [[0.0, 0.1, 0.1]]), "PYINS_E_REF_VALUE"),
    (contract.make_refs(9, [50], [[0.0, 0, 0]], [[0.1, 0.1, 0.1]]), "PYINS_E_REF_KIND"),
    (contract.make_refs("gnss_pos", [50], [[np.nan, 0, 0]], [[3, 3, 5]]), "PYINS_E_REF_VALUE"),
    (contract.make_refs("gnss_pos", [50], [[2.0, 0, 0]], [[3, 3, 5]]), "PYINS_E_REF_VALUE"),
    (contract.make_refs("gnss_vel", [50], [[0.0, 0, 0]], [[0.0, 0.1, 0.1]]), "PYINS_E_REF_VALUE"),
    (contract.make_refs("gnss_vel", [50], [[0.0, 0, 0]], [[0.1, -1.0, 0.1]]), "PYINS_E_REF_VALUE"),
    (contract.make_refs("zero_velocity", [50], [[0.0, 0, 0]], [[np.inf, 0.1, 0.1]]), "PYINS_E_REF_VALUE"),
    (contract.make_refs("gnss_pos", [200 + 1001], [[LAT, 0, 0]], [[3, 3, 5]]), "PYINS_E_REF_FUTURE"),
    (contract.make_refs("gnss_pos", [200 - 101], [[LAT, 0, 0]], [[3, 3, 5]]), "PYINS_E_REF_ORDER"),
])
def test_a_refused_reference_changes_nothing(eng, ref, status):
    fw = _fw(eng)
    fw.run(_static(200))
    before = _state(fw)
    with pytest.raises(contract.RefError) as e:
        fw.push_ref(ref)
    assert e.value.status_name == status and e.value.index == 0
    assert _state(fw) == before


@pytest.mark.parametrize("eng", ["native", "reference"])
def test_order_queue_and_undamped(eng):
    fw = _fw(eng)
    fw.run(_static(100))
    fw.push_ref(_pos(150))
    with pytest.raises(contract.RefError) as e:       # older than the last pushed
        fw.push_ref(_pos(140))
    assert e.value.status_name == "PYINS_E_REF_ORDER"
    for k in range(7):                                 # 8 in the queue
        fw.push_ref(_pos(160 + k))
    before = _state(fw)
    with pytest.raises(contract.RefError) as e:
        fw.push_ref(_pos(170))
    assert e.value.status_name == "PYINS_E_REF_FULL" and _state(fw) == before
    out = fw.run(_static(100))
    # each applied at its own tick (record k is after tick 101 + k): 150, then 160..166
    used = out["n_ref_used"][:, 0]
    assert used[149 - 101] == 0 and used[150 - 101] == 1 and used[159 - 101] == 1
    assert used[160 - 101] == 2 and used[166 - 101] == 8
    undamped = _fw(eng, nav_mode=abi.PYINS_NAV_UNDAMPED)
    undamped.run(_static(10))
    with pytest.raises(contract.RefError) as e:
        undamped.push_ref(_pos(20))
    assert e.value.status_name == "PYINS_E_REF_UNUSED"
    assert undamped.output()["nav_mode"] == abi.PYINS_NAV_UNDAMPED


@pytest.mark.parametrize("eng", ["native", "reference"])
def test_late_reference_is_carried_forward_and_a_snapshot_keeps_the_queue(eng):
    # A ship moving north at 5 m/s: a fix of where it was 50 ticks ago, pushed
    # now, fits (NIS ~ 0) only because it is carried forward by v * 0.5 s = 2.5 m.
    rm = earth.principal_radii(np.sin(LAT))[0]
    fw = _fw(eng, vel_n_mps=[0.0, 5.0, 0.0])
    fw.run(_static(300))
    now = fw.output()
    fix_lat = now["lat_rad"] - 2.5 / rm
    fw.push_ref(_pos(250, lat=fix_lat, lon=now["lon_rad"], sigma=0.1))
    rec = fw.output()
    assert rec["n_ref_used"][0] == 1
    # 2.5 m uncompensated would be a NIS of (2.5 / 0.1)^2 / 2 ~ 300 against the gate's 13.8:
    # carried forward the miss is the radius mismatch (< 1 mm)
    assert rec["nav_nis"][0] < 1e-3
    # the queue rides in the snapshot: a restored copy applies the same reference at its tick
    fw.push_ref(_pos(340, lat=fix_lat + 45 * 5.0 * 0.01 / rm, lon=now["lon_rad"]))
    blob = fw.snapshot()
    twin = type(fw).from_snapshot(blob)
    a, b = fw.run(_static(100)), twin.run(_static(100))
    assert a.tobytes() == b.tobytes() and a["n_ref_used"][-1, 0] == 2
