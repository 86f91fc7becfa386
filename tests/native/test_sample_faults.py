"""Sample-level faults through the C ABI (docs/core.md, "Sample-level
faults"): what each fault does to the state, its status, its sticky bit and
its counter. GIVEN a stream with a fault, WHEN it runs, THEN the documented
behaviour holds."""
import numpy as np
import pytest

from pyins import native, scenario, sim
from pyins.reference import attitude, earth
from pyins.units import ARCSEC_TO_RAD, G0, TICK_HZ
from pyins import units

lib = native.lib
DEG = units.DEG_TO_RAD
ARCSEC = ARCSEC_TO_RAD
BOOKKEEPING = ("fault_flags", "n_nonfinite", "n_saturated", "n_seq_gaps", "n_seq_bridged", "n_seq_repeats",
               "n_seq_lost", "n_encoder_jumps", "seq")


def nav_part(rec):
    """A record without the sample-level fault bookkeeping, as bytes."""
    r = np.array(rec, dtype=native.OUTPUT_DTYPE).copy()
    for f in BOOKKEEPING:
        r[f] = 0
    return r.tobytes()


def static(n, lat=0.5):
    """Error-free increments of a level IMU at yaw 0 on a static base: uniform motion."""
    g = earth.normal_gravity(np.sin(lat), 0.0)
    w = earth.OMEGA_IE
    dth = np.tile([0.0, w * np.cos(lat) * 0.01, w * np.sin(lat) * 0.01], (n, 1))
    dv = np.tile([0.0, 0.0, g * 0.01], (n, 1))
    return native.make_samples(dth, dv, np.zeros(n), seq=np.arange(1, n + 1))


def att_err(a, b):
    q = attitude.quat_mul(a["quat_np"], attitude.quat_conj(b["quat_np"]))
    return np.linalg.norm(attitude.quat_to_rotvec(attitude.quat_normalize(q)))


SEQ = dict(lat_rad=0.5, seq_mode=1)


# ---- skipped ticks -----------------------------------------------------------

@pytest.mark.parametrize("gap", [1, 2])
def test_skipped_ticks_on_uniform_motion_give_the_full_data_result(gap):
    """GIVEN uniform motion (static base) WHEN `gap` ticks are lost (up to the
    default maximum of 2) THEN the bridged run ends bit-identical to the run
    with every sample (interpolating equal increments is exact), with time
    right, and the gap counted."""
    s = static(3000)
    full = native.Firmware(SEQ).run(s)
    keep = np.ones(3000, bool)
    for at in (10, 1000, 2500):
        keep[at:at + gap] = False
    out = native.Firmware(SEQ).run(s[keep].copy())
    assert out[-1]["tick"] == 3000
    assert nav_part(out[-1]) == nav_part(full[-1])
    assert out[-1]["n_seq_gaps"] == 3 and out[-1]["n_seq_bridged"] == 3 * gap
    assert out[-1]["fault_flags"] == lib.PYINS_FAULT_SEQ_GAP
    # the record after each gap shows the state the full run had at that tick
    after = np.flatnonzero(~keep[1:] & keep[:-1])   # last kept sample before a gap
    for i in np.searchsorted(np.flatnonzero(keep), after + gap + 1):
        assert nav_part(out[i]) == nav_part(full[out[i]["tick"] - 1])


def test_bridging_on_a_bad_sea_interpolates_far_better_than_repeating():
    """GIVEN seed 000's bad sea state (23 deg/s peaks) WHEN one or two ticks
    are lost in navigation THEN the attitude right after the gap is within
    0.3" (one tick) / 1" (two) of the full-data run (docs/core.md: 0.19",
    0.75" measured), where repeating the last increments would leave 20" /
    60"."""
    m = sim.sea_state("bad", 34.246 * DEG, 108.91 * DEG, 0.0, yaw0=0.3)
    n = 1500
    dth, dv, al = sim.exact_increments(m, n)
    cfg = scenario.initial_config(m, None, seq_mode=1)
    seq = np.arange(1, n + 1)
    full = native.Firmware(cfg).run(native.make_samples(dth, dv, al, seq))
    for gap, bound in ((1, 0.3 * ARCSEC), (2, 1.0 * ARCSEC)):
        worst = worst_repeat = 0.0
        for at in range(300, 1300, 97):
            keep = np.ones(n, bool)
            keep[at:at + gap] = False
            s = native.make_samples(dth[keep].copy(), dv[keep].copy(), al[keep].copy(), seq[keep])
            fw = native.Firmware(cfg)
            out = fw.run(s[:at + 1])            # up to the sample after the gap
            assert out[-1]["tick"] == at + gap + 1 and out[-1]["n_seq_bridged"] == gap
            worst = max(worst, att_err(out[-1], full[at + gap]))
            d2, v2 = dth[:at + gap + 1].copy(), dv[:at + gap + 1].copy()
            d2[at:at + gap], v2[at:at + gap] = dth[at - 1], dv[at - 1]
            rep = native.Firmware(cfg).run(native.make_samples(d2, v2, al[:at + gap + 1], seq[:at + gap + 1]))
            worst_repeat = max(worst_repeat, att_err(rep[-1], full[at + gap]))
        assert worst < bound, (gap, worst / ARCSEC)
        assert worst_repeat > 30 * worst, (gap, worst_repeat / ARCSEC, worst / ARCSEC)


def test_gap_beyond_the_maximum_is_taken_without_bridging():
    """GIVEN seq jumping by more than seq_max_gap_ticks + 1 THEN the sample is
    taken as the next tick of the navigation (nothing bridged: the motion of
    the outage is lost), tick moves on by the whole outage, SEQ_LOST is set
    and counted; a backward jump beyond the window (an IMU restart) also
    resynchronises, adding one tick."""
    s = static(100)
    fw = native.Firmware(SEQ)
    fw.run(s[:50])
    lost = s[50:51].copy()
    lost["seq"] = 50 + 4            # 3 missing > 2
    rec = fw.step(lost["dtheta_p_rad"][0], lost["dv_p_mps"][0], 0.0, seq=54)
    assert fw.last_status == lib.PYINS_W_SEQ_LOST
    assert rec["tick"] == 54 and rec["n_seq_lost"] == 1 and rec["n_seq_bridged"] == 0
    assert rec["fault_flags"] == lib.PYINS_FAULT_SEQ_LOST
    # only one tick of motion was integrated: the state equals 51 samples' run
    ref = native.Firmware(SEQ).run(s[:51])[-1].copy()
    ref["tick"] = 54
    assert nav_part(rec) == nav_part(ref)
    # IMU restart: far behind
    rec = fw.step(s["dtheta_p_rad"][0], s["dv_p_mps"][0], 0.0, seq=7)
    assert fw.last_status == lib.PYINS_W_SEQ_LOST and rec["tick"] == 55 and rec["seq"] == 7
    rec = fw.step(s["dtheta_p_rad"][0], s["dv_p_mps"][0], 0.0, seq=8)
    assert fw.last_status == lib.PYINS_OK and rec["n_seq_lost"] == 2


def test_seq_wraps_at_two_to_the_32():
    s = static(20)
    s["seq"] = (np.arange(20, dtype=np.int64) + 2**32 - 10) & 0xFFFFFFFF
    out = native.Firmware(SEQ).run(s)
    assert np.all(out["fault_flags"] == 0) and out[-1]["seq"] == 9


def test_seq_off_ignores_the_counter():
    """Old logs without a counter: seq_mode 0 (the default) reads nothing of seq."""
    s = static(500)
    a = native.Firmware(lat_rad=0.5).run(s)
    s["seq"] = np.random.default_rng(1).integers(0, 2**32, 500)
    b = native.Firmware(lat_rad=0.5).run(s)
    assert np.all(b["fault_flags"] == 0)
    for x, y in zip(a, b):
        assert nav_part(x) == nav_part(y)


def test_gap_during_alignment_restarts_it():
    """Alignment cannot bridge (docs/core.md): a gap restarts it at the
    sample after the gap, time kept right, nothing bridged."""
    s = static(400)
    keep = np.ones(400, bool)
    keep[150] = False
    cfg = dict(SEQ, fine_ticks=300)
    out = native.Firmware(cfg).run(s[keep].copy())
    i = 150                                 # the record of the sample after the gap
    assert out[i]["tick"] == 152 and out[i]["align_restarts"] == 1
    assert out[i]["fault_flags"] == lib.PYINS_FAULT_SEQ_GAP | lib.PYINS_FAULT_ALIGN_RESTARTED
    assert out[i]["n_seq_bridged"] == 0 and out[-1]["mode"] == lib.PYINS_MODE_FINE_ALIGN


# ---- duplicates ----------------------------------------------------------------

def test_duplicates_leave_the_state_bit_identical():
    """GIVEN a swinging, turning run with indexing, alignment included, WHEN
    some samples arrive twice (or a sample up to the maximum gap behind comes
    again) THEN each copy is dropped with PYINS_W_SEQ_REPEAT, its record is
    the previous one but for the counter, and every later record equals the
    clean run's."""
    m = sim.sea_state("general", 0.6, 0.1, 0.0, yaw0=0.5)
    n = 2500
    dth, dv, al = sim.exact_increments(m, n, table=sim.ConstantRate(6 * DEG))
    cfg = scenario.initial_config(m, None, seq_mode=1, fine_ticks=800)
    s = native.make_samples(dth, dv, al, np.arange(1, n + 1))
    clean = native.Firmware(cfg).run(s)
    dup_at = [0, 5, 799, 800, 1500, 2400]
    idx = []
    for k in range(n):
        idx.append(k)
        if k in dup_at:
            idx.append(k)
        if k == 2000:
            idx.append(1999)                   # one behind: stale, dropped
    noisy = native.Firmware(cfg).run(s[np.array(idx)].copy())
    j = 0
    for k in range(n):
        assert nav_part(noisy[j]) == nav_part(clean[k])
        j += 1
        if k in dup_at or k == 2000:
            assert nav_part(noisy[j]) == nav_part(clean[k])
            j += 1
    assert noisy[-1]["n_seq_repeats"] == len(dup_at) + 1
    assert noisy[-1]["fault_flags"] == lib.PYINS_FAULT_SEQ_REPEAT
    fw = native.Firmware(cfg)
    fw.run(s[:10])
    fw.step(s[9]["dtheta_p_rad"], s[9]["dv_p_mps"], s[9]["table_angle_rad"], seq=10)
    assert fw.last_status == lib.PYINS_W_SEQ_REPEAT


# ---- saturation ------------------------------------------------------------------

def test_saturated_sample_rejected_and_held_then_bridged():
    """GIVEN the default limits (400 deg/s, 20 g per tick) WHEN an increment
    reaches one THEN the sample is rejected (SampleError, state held but for
    the bit and counter); with seq checking the next good sample bridges the
    hole, so on uniform motion the run ends as if nothing happened."""
    s = static(1000)
    full = native.Firmware(SEQ).run(s)
    bad = s.copy()
    bad["dtheta_p_rad"][300, 0] = 400.0 * DEG / 100.0          # exactly at the limit
    bad["dv_p_mps"][600, 2] = -20.0 * G0 / TICK_HZ * 1.5
    fw = native.Firmware(SEQ)
    with pytest.raises(native.SampleError) as info:
        fw.run(bad)
    assert info.value.index == 300 and info.value.status_name == "PYINS_E_SAMPLE_SATURATED"
    held = fw.output()
    assert held["n_saturated"] == 1 and held["fault_flags"] == lib.PYINS_FAULT_SAMPLE_SATURATED
    assert nav_part(held) == nav_part(full[299])
    with pytest.raises(native.SampleError) as info:
        fw.run(bad[301:])
    assert info.value.index == 299
    out = fw.run(bad[601:])
    assert out[0]["n_seq_bridged"] == 2 and out[-1]["n_saturated"] == 2
    assert nav_part(out[-1]) == nav_part(full[-1])


def test_saturation_limits_are_configurable():
    s = static(10)
    fw = native.Firmware(lat_rad=0.5, sat_gyro_rad=1e-6)          # 0.1 deg/s at 100 Hz
    fw.run(s[:5])
    fw.step([0.0, 0.99e-6, 0.0], [0.0, 0.0, 0.098])
    with pytest.raises(native.SampleError, match="saturation"):
        fw.step([0.0, -1e-6, 0.0], [0.0, 0.0, 0.098])
    fw = native.Firmware(lat_rad=0.5, sat_accel_mps=0.1)
    with pytest.raises(native.SampleError):
        fw.step([0.0, 0.0, 0.0], [0.0, 0.0, 0.1])


def test_saturation_during_alignment_restarts_it():
    s = static(300)
    s["dv_p_mps"][100, 0] = 5.0
    fw = native.Firmware(lat_rad=0.5, fine_ticks=250)
    with pytest.raises(native.SampleError):
        fw.run(s)
    out = fw.run(s[101:])
    assert out[0]["align_restarts"] == 1 and out[0]["fault_flags"] == (
        lib.PYINS_FAULT_SAMPLE_SATURATED | lib.PYINS_FAULT_ALIGN_RESTARTED)


# ---- NaN / Inf -------------------------------------------------------------------

def test_nonfinite_sample_bit_and_counter():
    s = static(20)
    s["table_angle_rad"][7] = np.inf
    fw = native.Firmware(lat_rad=0.5)
    with pytest.raises(native.SampleError) as info:
        fw.run(s)
    assert info.value.status_name == "PYINS_E_SAMPLE_NONFINITE"
    rec = fw.output()
    assert rec["n_nonfinite"] == 1 and rec["fault_flags"] == lib.PYINS_FAULT_SAMPLE_NONFINITE
    assert rec["tick"] == 7


# ---- encoder jumps -----------------------------------------------------------------

def test_encoder_jump_flagged_and_indexing_faults():
    """GIVEN navigation with the two-position scheme on an ideal table WHEN
    the encoder jumps by 10 deg THEN the sample is taken (the table angle
    follows the reading), PYINS_W_ENCODER_JUMP, bit and counter are set, and
    the indexing machine is in FAULT with fault 2 (encoder jump)."""
    s = static(400)
    fw = native.Firmware(lat_rad=0.5, index_scheme=2, index_stop_ticks=100)
    enc = 0.0
    for k in range(300):
        rec = fw.step(s["dtheta_p_rad"][k], s["dv_p_mps"][k], np.mod(enc, 2 * np.pi))
        enc = rec["table_angle_cmd_rad"]
    rec = fw.step(s["dtheta_p_rad"][300], s["dv_p_mps"][300], np.mod(enc + 10 * DEG, 2 * np.pi))
    assert fw.last_status == lib.PYINS_W_ENCODER_JUMP
    assert rec["n_encoder_jumps"] == 1 and rec["fault_flags"] == lib.PYINS_FAULT_ENCODER_JUMP
    assert rec["index_state"] == lib.PYINS_INDEX_FAULT and rec["index_fault"] == 2
    assert abs(rec["table_angle_rad"] - (enc + 10 * DEG)) < 1e-12


def test_encoder_jump_seen_without_indexing_but_not_on_the_first_sample():
    s = static(10)
    s["table_angle_rad"][:] = 1.0               # the configured angle (0) was a guess
    s["table_angle_rad"][6] = 1.3
    out = native.Firmware(lat_rad=0.5).run(s)
    assert list(out["n_encoder_jumps"]) == [0] * 6 + [1, 2, 2, 2]


# ---- batch calls, snapshots ----------------------------------------------------------

def test_decimated_records_with_gaps_past_multiples():
    """Records come after each step reaching or passing a multiple of every;
    gaps passing more multiples than the buffer holds are continued by
    Firmware.run (the C call stops before an overflow)."""
    s = static(400)
    cfg = dict(SEQ, seq_max_gap_ticks=100)
    full = native.Firmware(cfg).run(s)
    sparse = s[::40].copy()                       # 39 ticks missing each time
    dec = native.Firmware(cfg).run(sparse, every=10)
    assert list(dec["tick"]) == list(range(1, 400, 40))[1:]
    for r in dec:
        assert nav_part(r) == nav_part(full[r["tick"] - 1])
    fw = native.Firmware(cfg)
    parts = [fw.run(s[a:b], every=25) for a, b in ((0, 33), (33, 290), (290, 400))]
    assert np.concatenate(parts).tobytes() == full[24::25].tobytes()


def test_compact_records_with_gaps_past_multiples():
    """pyins_run_nav keeps pyins_run_decimated's rules: the same ticks, the
    same fields, across gaps that pass more multiples than the buffer holds."""
    s = static(400)
    cfg = dict(SEQ, seq_max_gap_ticks=100)
    sparse = s[::40].copy()
    full = native.Firmware(cfg).run(sparse, every=10)
    compact = native.Firmware(cfg).run_nav(sparse, every=10)
    assert list(compact["tick"]) == list(full["tick"])
    for field in native.NAV_DTYPE.names:
        assert np.ascontiguousarray(compact[field]).tobytes() == np.ascontiguousarray(full[field]).tobytes()
    with pytest.raises(ValueError, match="every: must be a positive"):
        native.Firmware(cfg).run_nav(s, every=0)


def test_snapshot_carries_the_sequence_state():
    """A snapshot taken before a gap, restored, bridges it exactly as the
    uninterrupted instance does (seq, last increments and counters are in it)."""
    s = static(200)
    keep = np.ones(200, bool)
    keep[120:122] = False
    cut = s[keep].copy()
    fw = native.Firmware(SEQ)
    fw.run(cut[:60])
    blob = fw.snapshot()
    assert int.from_bytes(blob[4:8], "little") == 9      # snapshot format 9 (the coarse alignment under way, ABI 0.20)
    rest = native.Firmware.from_snapshot(blob).run(cut[60:])
    whole = native.Firmware(SEQ).run(cut)
    assert rest.tobytes() == whole[60:].tobytes()
    assert rest[-1]["n_seq_bridged"] == 2


# ---- configuration -----------------------------------------------------------------

@pytest.mark.parametrize("fields, status", [
    (dict(seq_mode=2), "PYINS_E_CONFIG_SEQ"),
    (dict(seq_max_gap_ticks=-1), "PYINS_E_CONFIG_SEQ"),
    (dict(seq_max_gap_ticks=101), "PYINS_E_CONFIG_SEQ"),
    (dict(sat_gyro_rad=-1e-3), "PYINS_E_CONFIG_SATURATION"),
    (dict(sat_gyro_rad=float("nan")), "PYINS_E_CONFIG_SATURATION"),
    (dict(sat_accel_mps=float("inf")), "PYINS_E_CONFIG_SATURATION"),
])
def test_sample_fault_config_errors(fields, status):
    with pytest.raises(native.ConfigError) as info:
        native.Firmware(**fields)
    assert info.value.status_name == status


def test_notice_statuses_are_named():
    for code in (1, 2, 3, 4):
        assert native.status_str(code).startswith("PYINS_W_")
    assert native.status_str(-31).startswith("PYINS_E_SAMPLE_SATURATED")
