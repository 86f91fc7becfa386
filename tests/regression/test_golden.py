"""The golden regression suite: every firmware mode and indexing scheme on
short stored input streams must give the stored output records bit for bit
(tests/regression/cases.py says what each case runs). A failure names the
first tick and field that moved. If the change of bits is meant, regenerate
with tools/regenerate_golden.py and say why in the commit."""
import hashlib
import json
import os
import sys

import numpy as np
import pytest

from pyins import native

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
import cases  # noqa: E402

DATA = os.path.join(HERE, "data")


def _first_difference(got, want):
    for k in range(len(want)):
        if got[k].tobytes() != want[k].tobytes():
            for name in native.OUTPUT_DTYPE.names:
                if np.asarray(got[k][name]).tobytes() != np.asarray(want[k][name]).tobytes():
                    return f"record {k}: field {name}: got {got[k][name]!r}, stored {want[k][name]!r}"
    return "records equal, digest differs (a tick between the stored ones)"


@pytest.mark.parametrize("name", sorted(cases.CASES))
def test_golden_records(name):
    path = os.path.join(DATA, f"{name}.npz")
    assert os.path.exists(path), f"{path} missing: run tools/regenerate_golden.py {name}"
    d = np.load(path)
    assert tuple(d["abi"]) == tuple(native.abi_version()), "golden records of another ABI: regenerate them"
    cfg = json.loads(str(d["config"]))
    rec = cases.run(cfg, d["dtheta"], d["dv"], d["seq"], turn=name in cases.TURNS)
    want = d["records"].view(native.OUTPUT_DTYPE)
    got = np.ascontiguousarray(rec[cases.EVERY - 1::cases.EVERY])
    if hashlib.sha256(rec.tobytes()).hexdigest() != str(d["sha256"]):
        pytest.fail(f"{name}: the firmware's bits moved: {_first_difference(got, want)}")


@pytest.mark.parametrize("name", sorted(cases.CASES))
def test_compact_records_are_the_full_records_fields(name):
    """pyins_run_nav's record is pyins_output's fields of the same names,
    bit for bit, on every tick of every case: each mode, scheme, lever arm
    and sample fault (the compact record must not be a second
    navigation solution)."""
    d = np.load(os.path.join(DATA, f"{name}.npz"))
    cfg = json.loads(str(d["config"]))
    turn = name in cases.TURNS
    full = cases.run(cfg, d["dtheta"], d["dv"], d["seq"], turn=turn)
    compact = cases.run_compact(cfg, d["dtheta"], d["dv"], d["seq"], turn=turn)
    for field in native.NAV_DTYPE.names:
        got = np.ascontiguousarray(compact[field])
        want = np.ascontiguousarray(full[field])
        if got.tobytes() != want.tobytes():
            k = next(i for i in range(len(got)) if got[i].tobytes() != want[i].tobytes())
            pytest.fail(f"{name}: tick record {k}: field {field}: compact {got[k]!r}, full {want[k]!r}")


def test_every_mode_and_scheme_is_covered():
    # the suite must reach every mode, every preset scheme and the custom one,
    # every coarse method (TRIAD, FIT, eq. 8) and all three fine filters
    seen_modes, schemes, methods, states = set(), set(), set(), set()
    for name in cases.CASES:
        d = np.load(os.path.join(DATA, f"{name}.npz"))
        cfg = json.loads(str(d["config"]))
        seen_modes |= set(int(m) for m in d["records"].view(native.OUTPUT_DTYPE)["mode"])
        schemes.add(cfg.get("index_scheme", 0))
        methods.add(cfg.get("coarse_method", 0) if cfg.get("coarse_ticks", 0) else None)
        if cfg.get("fine_ticks", 0):
            states.add(cfg.get("fine_states", 5))
    assert {1, 2, 3} <= seen_modes
    # heading isolation (7) with the increments turned by the commanded table (cases.TURNS)
    assert schemes == {0, 1, 2, 3, 4, 5, 6, 7}
    assert {0, 1, 2} <= methods and states == {5, 8, 12}


@pytest.mark.parametrize("name", sorted(set(cases.CASES) - cases.TURNS))
def test_compact_records_of_one_batch_are_the_single_steps(name):
    """pyins_run_nav with a record every tick over a whole case in one call
    (Firmware::run_plain's loop writes the records of the plain samples,
    step() takes the others: alignment, seq gaps, the rejected sample) gives
    the records of one sample at a time, bit for bit: one record per sample
    that advanced the tick. The encoder reads what the single steps' harness
    fed back (the last commanded angle), so the inputs are the same."""
    d = np.load(os.path.join(DATA, f"{name}.npz"))
    cfg = json.loads(str(d["config"]))
    one = cases.run_compact(cfg, d["dtheta"], d["dv"], d["seq"])
    n = len(one)
    enc = np.empty(n)
    enc[0] = float(cfg.get("table_angle_rad", 0.0))
    enc[1:] = np.mod(one["table_angle_cmd_rad"][:-1], 2.0 * np.pi)
    s = native.make_samples(d["dtheta"], d["dv"], enc, np.asarray(d["seq"]) & 0xFFFFFFFF)
    fw = native.Firmware(cfg)
    parts, start = [], 0
    while start < n:
        try:
            parts.append(fw.run_nav(s[start:], every=1))
            break
        except native.SampleError as e:     # faults_seq_nan_gap's NaN: rejected, the run goes on after it
            parts.append(e.outputs)
            start += e.index + 1
    batch = np.concatenate(parts)
    advanced = [k for k in range(n) if one["tick"][k] > (one["tick"][k - 1] if k else 0)]
    assert len(batch) == len(advanced) > 2000
    if batch.tobytes() != one[advanced].tobytes():
        k = next(i for i in range(len(batch)) if batch[i].tobytes() != one[advanced][i].tobytes())
        pytest.fail(f"{name}: record {k} (tick {one[advanced][k]['tick']}) differs from the single steps'")
