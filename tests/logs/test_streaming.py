"""Logs in blocks (docs/log-formats.md, "Reading and writing in blocks"):
`pyins.logs.LogReader` gives what `read_log` gives, bit for bit, whatever the
block size, with the same errors naming the same lines across block
boundaries; `LogWriter` writes the file `write_log` writes, and a kill leaves
no file that looks complete; `pyins replay` in small blocks writes the
records of one firmware call; Ctrl-C between blocks leaves a summary that
says so; the memory of a streamed replay does not grow with the log."""
import gzip
import json
import os
import signal
import subprocess
import sys
import time
import tracemalloc

import numpy as np
import pytest

from pyins import __main__ as cli
from pyins import logs, replay, scenario
from pyins.logs import ImuData
from pyins.units import DEG_TO_RAD

from test_logs import assert_same_data, static_log

#: block sizes: one sample, a prime that splits every layout at odd places,
#: one bigger than the test logs, and whole
BLOCKS = (1, 7, 64, 5000, None)

#: (fmt, file name, write_log options, read options)
LAYOUTS = [
    ("text", "psins.txt", {}, {}),
    ("text", "kfgins.txt.gz", dict(time_col="first", axes="frd", kind="rates", header=False),
     dict(time_col="first", axes="frd", kind="rates")),
    ("text", "table.txt.xz", dict(table=True), {}),
    ("binary", "log.bin", {}, {}),
    ("binary", "table.bin.bz2", dict(table=True), dict(table=True)),
    ("csv", "project.csv", {}, {}),
    ("npz", "project.npz", {}, {}),
]


def _same(a, b):
    assert_same_data(a, b)
    assert a.dt == b.dt
    assert a.metadata == b.metadata


def _write(tmp_path, fname, data, **kw):
    path = tmp_path / fname
    logs.write_log(str(path), data, **kw)
    return path


@pytest.fixture(scope="module")
def data():
    return static_log(n=300, table=True)


@pytest.mark.parametrize("fmt, fname, wkw, rkw", LAYOUTS, ids=[x[1] for x in LAYOUTS])
def test_the_blocks_are_read_log_bit_for_bit(tmp_path, data, fmt, fname, wkw, rkw):
    d = data if wkw.get("table") or fmt in ("csv", "npz") else ImuData(
        data.tick, data.dtheta_p, data.dv_p, np.zeros_like(data.table_angle_rad), data.dt, {})
    path = _write(tmp_path, fname, d, **wkw)
    whole = logs.read_log(str(path), **rkw)
    for block in BLOCKS:
        for probe in (logs.PROBE, 5):
            r = logs.LogReader(str(path), block=block, probe=probe, **rkw)
            assert r.dt == whole.dt
            blocks = list(r.blocks())
            assert all(len(b.tick) <= (block or len(whole.tick)) for b in blocks)
            if block == 1:
                assert len(blocks) == len(whole.tick)
            got = logs.ImuData(np.concatenate([b.tick for b in blocks]),
                               np.concatenate([b.dtheta_p for b in blocks]),
                               np.concatenate([b.dv_p for b in blocks]),
                               np.concatenate([b.table_angle_rad for b in blocks]), r.dt, r.metadata)
            _same(got, whole)
            assert r.warnings == whole.metadata["warnings"] == []


def test_a_psins_log_streams(tmp_path):
    """The real laser-gyro excerpt (PSINS .imu, gzip): its header facts before the
    first block, its samples in blocks as read_log reads them."""
    path = os.path.join(os.path.dirname(__file__), "..", "data", "lasergyro_300s.imu.gz")
    whole = logs.read_log(path)
    r = logs.LogReader(path, block=4999, probe=1000)
    assert r.dt == whole.dt == 0.01 and r.metadata["psins_header"]["lat0_deg"] == pytest.approx(34.246048)
    got = r.read()
    _same(got, whole)


def _text(tmp_path, lines, name="log.txt"):
    path = tmp_path / name
    path.write_text("".join(line + "\n" for line in lines))
    return str(path)


def _rows(n, dt=0.01, start=1, skip=(), repeat=(), back=(), nan_at=None, fast=None):
    """Text lines "g(3) a(3) t" of a level IMU at ``dt``: a comment on line 1,
    sample k on line k + 2 (0-based k); ticks in ``skip`` missing (gaps);
    the time of samples in ``repeat`` repeats the one before, in ``back``
    goes back; ``nan_at`` a NaN gyro; ``fast`` a gyro of 20 rad/s there."""
    lines = ["% a test log"]
    tick = start
    for k in range(n):
        while tick in skip:
            tick += 1
        t = tick * dt
        if k in repeat:
            t = (tick - 1) * dt
        if k in back:
            t = (tick - 5) * dt
        g = "nan" if k == nan_at else ("0.2" if k == fast else "1e-7")
        lines.append(f"{g} 2e-7 3e-7 1e-5 -2e-5 {9.8 * dt!r} {t!r}")
        tick += 1
    return lines


FAULTS = {
    "a bad token": lambda: _rows(40)[:23] + ["1e-7 x 3e-7 1e-5 -2e-5 0.098 0.22"] + _rows(40)[24:],
    "a short line": lambda: _rows(40)[:30] + ["1e-7 3e-7 1e-5 -2e-5 0.098 0.22"] + _rows(40)[31:],
    "a repeated time": lambda: _rows(40, repeat={21, 30}),
    "time going back": lambda: _rows(40, back={17}),
    "a NaN late": lambda: _rows(40, nan_at=33),
    "a NaN and a time error": lambda: _rows(40, repeat={5}, nan_at=38),
    "one gap": lambda: _rows(40, skip={22}),
    "twelve gaps": lambda: _rows(60, skip={7, 9, 11, 14, 19, 23, 27, 30, 35, 38, 44, 49}),
    "a gap then a fast gyro": lambda: _rows(40, skip={9}, fast=31),
    "an irregular step": lambda: _rows(40)[:20] + ["1e-7 2e-7 3e-7 1e-5 -2e-5 0.098 0.1905"] + _rows(40)[21:],
}


@pytest.mark.parametrize("fault", FAULTS)
@pytest.mark.parametrize("strict", (True, False))
def test_errors_across_block_boundaries_name_the_line_read_log_names(tmp_path, fault, strict):
    """Each fault at a block boundary (blocks of 1 and 7, a probe of 3: every
    check runs across boundaries): the same error, word for word, or the same
    data and warnings."""
    path = _text(tmp_path, FAULTS[fault]())

    def outcome(fn):
        try:
            return "data", fn()
        except logs.LogError as exc:
            return "error", str(exc)

    want = outcome(lambda: logs.read_log(path, strict=strict))
    for block in (1, 7, 8):
        got = outcome(lambda: logs.LogReader(path, block=block, probe=3, strict=strict).read())
        assert got[0] == want[0], (got, want)
        if want[0] == "error":
            assert got[1] == want[1]
        else:
            _same(got[1], want[1])
    if fault == "a bad token":
        assert "line 24, column 2 (gyro_y)" in want[1]
    if fault == "a repeated time":
        assert "line 23: time 0.21 repeats" in want[1] and "2 such steps in all" in want[1]
    if fault == "a NaN and a time error":       # the NaN first, as read_log always said
        assert "line 40, column 1 (gyro_x): nan is not finite" in want[1]
    if fault == "twelve gaps" and strict is False:
        assert "and 2 more gaps; 12 gaps, 12 missing ticks in all" in want[1].metadata["warnings"][-1]
    if fault == "a gap then a fast gyro":
        assert "line 33: gyro rate" in want[1]


def test_a_refusal_found_after_the_probe_comes_when_its_block_is_reached(tmp_path):
    """The blocks before it are out (a caller keeps its results under a temporary
    name); the error is read_log's."""
    path = _text(tmp_path, _rows(50, back={40}))
    r = logs.LogReader(path, block=10, probe=10)
    seen = []
    with pytest.raises(logs.LogError, match="line 42: time 0.36 goes back"):
        for b in r.blocks():
            seen.append(len(b.tick))
    assert seen == [10, 10, 10, 10]


def test_gaps_are_bridged_in_blocks_as_on_the_whole_log(tmp_path):
    path = _text(tmp_path, _rows(60, skip={7, 8, 20, 21, 22, 35}))
    whole, added = logs.bridge_gaps(logs.read_log(path, strict=False), how="--allow-gaps")
    assert added == 6
    for block in (1, 6, 7, 14):
        r = logs.LogReader(path, block=block, probe=4, strict=False)
        bridge = logs.GapBridge(how="--allow-gaps")
        blocks = list(bridge.blocks(r.blocks()))
        got = ImuData(np.concatenate([b.tick for b in blocks]), np.concatenate([b.dtheta_p for b in blocks]),
                      np.concatenate([b.dv_p for b in blocks]),
                      np.concatenate([b.table_angle_rad for b in blocks]), r.dt, {})
        assert_same_data(got, whole)
        assert bridge.added == 6
        assert r.warnings + [bridge.note()] == whole.metadata["warnings"]


# ---------------------------------------------------------------------------
# Writing
# ---------------------------------------------------------------------------
WRITES = [("a.txt", {}), ("b.txt", dict(header=False, time_col="first")), ("c.bin", dict(table=True)),
          ("d.csv", {}), ("e.txt.gz", dict(kind="rates", axes="frd"))]


@pytest.mark.parametrize("fname, kw", WRITES, ids=[w[0] for w in WRITES])
def test_the_writer_writes_write_logs_file(tmp_path, fname, kw):
    """Blocks of 7 (the table angle becoming non-zero in the third: the text
    lines before it get the column) give the bytes of one write_log call."""
    d = static_log(n=60, table=False)
    d.table_angle_rad[17:] = 0.25
    ref = tmp_path / ("ref_" + fname)
    logs.write_log(str(ref), d, **kw)
    out = tmp_path / fname
    with logs.LogWriter(str(out), **kw) as w:
        for b in logs.split_blocks(d, 7):
            w.write(b)
    read = gzip.open if fname.endswith(".gz") else open
    with read(ref, "rb") as f1, read(out, "rb") as f2:
        assert f1.read() == f2.read()
    assert sorted(os.listdir(tmp_path)) == sorted([fname, "ref_" + fname])     # no temporary left


def test_an_npz_written_in_blocks_reads_back(tmp_path):
    d = static_log(n=50, table=True)
    with logs.LogWriter(str(tmp_path / "x.npz"), metadata={"k": 1}) as w:
        for b in logs.split_blocks(d, 9):
            w.write(b)
    got = logs.read_log(str(tmp_path / "x.npz"))
    assert_same_data(got, d)
    assert got.dt == d.dt and got.metadata["k"] == 1
    assert os.listdir(tmp_path) == ["x.npz"]


def test_an_error_or_a_kill_mid_write_leaves_no_file_that_looks_complete(tmp_path):
    d = static_log(n=40)
    target = tmp_path / "log.bin"
    target.write_bytes(b"the user's old file")
    with pytest.raises(RuntimeError):
        with logs.LogWriter(str(target)) as w:
            w.write(d)
            raise RuntimeError("stop")
    assert target.read_bytes() == b"the user's old file" and os.listdir(tmp_path) == ["log.bin"]
    # a kill (os._exit: no cleanup at all) after a block: the name is not written
    code = ("import numpy as np, os; from pyins import logs; from pyins.logs import ImuData; "
            "d = ImuData(np.arange(1, 11), np.zeros((10, 3)), np.zeros((10, 3)), np.zeros(10), 0.01, {}); "
            f"w = logs.LogWriter({str(tmp_path / 'new.txt')!r}); w.write(d); os._exit(9)")
    assert subprocess.run([sys.executable, "-c", code]).returncode == 9
    assert not (tmp_path / "new.txt").exists()


# ---------------------------------------------------------------------------
# Replay
# ---------------------------------------------------------------------------
@pytest.fixture(scope="module")
def demo_log(tmp_path_factory):
    """Nine minutes of the demo scenario, simulated as a binary log."""
    path = tmp_path_factory.mktemp("demo") / "demo.bin"
    assert cli.main(["simulate", "demo", str(path), "--hours", "0.15", "--quiet"]) == 0
    spec = list(scenario.load("demo").runs())[0]
    cfg = replay.replay_config(spec)
    cfg["tick_hz"] = 100
    return str(path), spec, cfg


def _outputs(out):
    with np.load(os.path.join(out, "navigation.npz")) as z:
        nav = z["outputs"]
    with np.load(os.path.join(out, "errors.npz")) as z:
        err = {k: z[k] for k in z.files}
    with open(os.path.join(out, "summary.json")) as f:
        summary = json.load(f)
    return nav, err, summary


@pytest.mark.parametrize("every", (100, 7))
def test_a_replay_in_small_blocks_is_the_replay_of_one_call(tmp_path, demo_log, every):
    path, spec, cfg = demo_log
    whole = replay.replay(logs.read_log(path), dict(cfg), str(tmp_path / "whole"), every=every, spec=spec,
                          log_path=path, block=None)
    small = replay.replay(logs.LogReader(path, block=997, probe=500), dict(cfg), str(tmp_path / "small"),
                          every=every, spec=spec, log_path=path)
    assert small == whole
    nav_w, err_w, _ = _outputs(str(tmp_path / "whole"))
    nav_s, err_s, _ = _outputs(str(tmp_path / "small"))
    assert nav_w.dtype == nav_s.dtype and nav_w.tobytes() == nav_s.tobytes()
    # read back in blocks (what a report of a long replay can decimate from)
    rows = list(logs.iter_npz(str(tmp_path / "small" / "navigation.npz"), "outputs", block=13))
    assert np.concatenate(rows).tobytes() == nav_w.tobytes()
    assert set(err_w) == set(err_s) and all(err_w[k].tobytes() == err_s[k].tobytes() for k in err_w)


def test_the_reference_engine_runs_in_blocks_in_phase(tmp_path, demo_log):
    """The NumPy mirror behind --engine reference: the records of blocks of 13
    with every=7 (never a multiple) are those of one call."""
    path, spec, cfg = demo_log
    d = logs.read_log(path)
    d = ImuData(d.tick[:300], d.dtheta_p[:300], d.dv_p[:300], d.table_angle_rad[:300], d.dt, d.metadata)
    replay.replay(d, dict(cfg), str(tmp_path / "w"), every=7, spec=spec, engine="reference", block=None)
    replay.replay(logs.split_blocks(d, 13), dict(cfg), str(tmp_path / "s"), every=7, spec=spec,
                  engine="reference")
    assert _outputs(str(tmp_path / "w"))[0].tobytes() == _outputs(str(tmp_path / "s"))[0].tobytes()


def test_ctrl_c_between_blocks_leaves_a_summary_that_says_interrupted(tmp_path, demo_log):
    path, spec, cfg = demo_log
    r = logs.LogReader(path, block=2000)

    def blocks():
        for k, b in enumerate(r.blocks()):
            if k == 3:
                raise KeyboardInterrupt
            yield b

    out = tmp_path / "out"
    with pytest.raises(KeyboardInterrupt):
        replay.replay(blocks(), dict(cfg), str(out), spec=spec, log_path=path)
    nav, err, s = _outputs(str(out))
    assert s["state"] == "interrupted" and s["complete"] is False and s["samples"] == 6000
    assert len(nav) == 60 and nav["tick"][-1] == 6000 and len(err["time_s"]) == 60
    assert s["warnings"][0].startswith("interrupted (Ctrl-C) at 60 s")
    assert [f for f in os.listdir(out) if "part" in f or "tmp" in f] == []
    assert cli.main(["report", str(out), "--quiet"]) == 0
    assert "PARTIAL: interrupted" in (out / "report.html").read_text()     # the page says so first


def test_ctrl_c_stops_pyins_replay_within_seconds(tmp_path):
    """A real SIGINT to ``python -m pyins replay`` of a text log (parsed at a
    few hundred thousand lines a second: it runs for seconds): exit 130 within
    STOP_S of the signal, a summary that says interrupted. STOP_S as in
    tests/cli/test_interrupts.py: the stop is one block (~0.1-0.3 s) and a
    summary write; 5 s leaves room for a busy machine."""
    stop_s = 5.0
    log = tmp_path / "long.txt"
    n = 400_000
    d = ImuData(np.arange(1, n + 1, dtype=np.int64), np.full((n, 3), 1e-7), np.tile([0.0, 0.0, 0.098], (n, 1)),
                np.zeros(n), 0.01, {})
    logs.write_log(str(log), d, header=False)
    out = tmp_path / "out"
    proc = subprocess.Popen([sys.executable, "-m", "pyins", "replay", str(log), "--lat", "34", "--lon", "108",
                             "--attitude", "0", "0", "0", "--out", str(out), "--quiet"],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, start_new_session=True,
                            preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL))
    t0 = time.monotonic()
    while not (out.exists() and any("part" in f for f in os.listdir(out))):
        assert proc.poll() is None, proc.stderr.read()
        assert time.monotonic() - t0 < 60, "no records after 60 s"
        time.sleep(0.01)
    t1 = time.monotonic()
    os.killpg(proc.pid, signal.SIGINT)
    rc = proc.wait(timeout=60)
    took = time.monotonic() - t1
    err = proc.stderr.read()
    assert rc == cli.EXIT_INTERRUPTED, err
    assert took < stop_s
    s = json.loads((out / "summary.json").read_text())
    assert s["state"] == "interrupted" and 0 < s["samples"] < n
    assert "interrupted" in err


def test_the_memory_of_a_streamed_replay_does_not_grow_with_the_log(tmp_path, demo_log):
    """tracemalloc peak (NumPy's buffers included) of replaying the first N and
    the first 4N samples in blocks of 1000, a record every 1000 samples. Whole,
    the log alone is >= 120 B a sample (a 56-B record read, a 64-B firmware
    sample; measured: 167 B), so 3N = 36,000 more samples add >= 4.3 MB.
    Streamed, nothing a sample is kept (the records go to a file as they come);
    the one thing that grows is the final copy of that file into
    navigation.npz, read up to `logs.COPY_BYTES` (4 MiB) at a time: 432 B a
    record, 0.4 B a sample here. So the peak may grow by less than 8 B a
    sample (288 kB: twenty times that copy, room for allocator noise) and the
    whole-log path fails this by a factor of 15."""
    path, spec, cfg = demo_log
    d = logs.read_log(path)
    peaks = {}
    for n in (12_000, 48_000):
        part = tmp_path / f"p{n}.bin"
        logs.write_log(str(part), next(logs.split_blocks(d, n)))
        tracemalloc.start()
        replay.replay(logs.LogReader(str(part), block=1000, probe=1000), dict(cfg), str(tmp_path / f"o{n}"),
                      every=1000, spec=spec, log_path=str(part))
        peaks[n] = tracemalloc.get_traced_memory()[1]
        tracemalloc.stop()
    growth = peaks[48_000] - peaks[12_000]
    assert growth < 8 * 36_000, peaks
