"""``pyins replay LOG --gnss FILE --speed-log FILE`` with NMEA 0183 files
(docs/log-formats.md, "NMEA 0183"; docs/cli.md, "pyins replay LOG"),
through the command line as a user runs it.

The NMEA files are written by `pyins.logs.nmea.write_nmea` from the same
records a reference text file (``--refs``) holds, so a replay with the
NMEA file and one with the text file must navigate alike: the records
differ only by the NMEA rounding (5 decimals of a minute of arc: at most
0.93 cm north, 0.77 cm east at 34 deg; speed 0.001 kn: 0.26 mm/s; course
0.01 deg: 0.09 mm/s a m/s of speed). The filter weighs each fix by the
same sigma (GST to the mm) and its gain on a position is below 1: its
track cannot move by more than the fixes did, plus what the velocity
rounding integrates to over the filter's memory (~1 mm/s x a few tens of
s, a few cm if it were all one way; it is not: it alternates). TRACK_TOL
= 3 cm holds that with room (measured on the voyage: 0.62 cm), and fails
what is wrong by more than the rounding: the same file with
--nmea-utc-start one tick (10 ms) late measured 4.7 m (each fix a tick
late: the first one's correction lands after a record), written with 4
decimals of a minute (9.3 cm of rounding) 3.7 cm.
"""
import json
import lzma
import pathlib

import numpy as np
import parked_site
import pytest

from pyins import __main__ as cli
from pyins import contract
from pyins.logs import nmea as N
from pyins.reference import earth
from pyins.sim import references as R


#: After 180 s of aided navigation on the coarse attitude (a 300-s slice of
#: the log) the heading is not yet valid: three times the navigation
#: filter's heading sigma (4.8' on the zero-velocity replay) is above 10'
#: (firmware.hpp's kValidNavHeadingSigma, 2026-12-06). The replay says so;
#: the checks below that nothing else is said keep their meaning.
NAV_NOT_YET = "the navigation filter aligning on the coarse attitude"


def _others(warnings):
    """The warnings beside the navigation filter's not-yet-valid heading."""
    return [w for w in warnings if NAV_NOT_YET not in w]

ROOT = pathlib.Path(__file__).resolve().parents[2]
LOG = str(ROOT / "tests/data/lasergyro_300s.imu.gz")
LAT, LON, H = parked_site.LAT, parked_site.LON, parked_site.H
SITE = ["--lat", str(LAT), "--lon", str(LON), "--height", str(H), "--coarse", "120"]
#: the log's start in UTC: midnight falls at 180 s, inside the navigation (120 .. 300 s)
START = "2026-12-05T23:57:00.00"
TRACK_TOL = 0.03       #: [m] the module docstring's bound for two replays whose fixes differ by the NMEA rounding


def _replay(tmp_path, *extra, name="out", log=LOG, site=True):
    out = tmp_path / name
    argv = ["replay", log, *(SITE + ["--reference", "parked"] if site else []), "--out", str(out), "--quiet",
            *extra]
    rc = cli.main(argv)
    summary = json.loads((out / "summary.json").read_text()) if rc == 0 else None
    return rc, summary, out


def _fixes(ticks, noise_m, seed=0):
    return parked_site.fixes(ticks, noise_m, seed, up_velocity=False)


def _track_gap(a, b):
    """The largest horizontal distance [m] between two replays' positions, record by record."""
    oa = np.load(a / "navigation.npz")["outputs"]
    ob = np.load(b / "navigation.npz")["outputs"]
    assert oa["tick"].tolist() == ob["tick"].tolist()
    lat = oa["lat_rad"]
    rm, rn = earth.principal_radii(np.sin(lat))
    dn = (ob["lat_rad"] - lat) * (rm + oa["height_m"])
    de = (ob["lon_rad"] - oa["lon_rad"]) * (rn + oa["height_m"]) * np.cos(lat)
    return float(np.max(np.hypot(dn, de)))


def test_nmea_fixes_navigate_as_the_same_fixes_in_the_text_layout(tmp_path):
    refs = _fixes(np.arange(12_000, 30_001, 100), 3.0)
    R.save_refs_csv(str(tmp_path / "gnss.csv"), refs)
    N.write_nmea(tmp_path / "gnss.nmea", refs, START)      # GGA + GST + RMC, across midnight
    rc, csv, out_csv = _replay(tmp_path, "--refs", str(tmp_path / "gnss.csv"), name="csv")
    assert rc == 0
    rc, s, out = _replay(tmp_path, "--gnss", str(tmp_path / "gnss.nmea"), "--nmea-utc-start", START,
                         "--gnss-vel-sigma", "0.05 m/s", name="nmea")
    assert rc == 0
    k, kc = s["references"]["kinds"], csv["references"]["kinds"]
    assert k["gnss_pos"]["given"] == k["gnss_vel"]["given"] == 181
    assert [k[n]["used"] for n in k] == [kc[n]["used"] for n in kc]
    assert s["references"]["file_span_s"] == [120.0, 300.0]          # midnight crossed, ticks the same
    src, = s["references"]["sources"]
    assert src["option"] == "--gnss" and src["format"] == "NMEA 0183"
    assert src["sigmas"] == {"gnss_pos": {"GST": 181, "assumed": 0}, "gnss_vel": {"--gnss-vel-sigma": 181}}
    assert src["utc_span"] == ["2026-12-05T23:59:00.00", "2026-12-06T00:02:00.00"]
    assert _others(s["warnings"]) == []          # every sigma measured (GST) or stated: nothing assumed
    assert abs(s["errors"]["horizontal_max_m"] - csv["errors"]["horizontal_max_m"]) < TRACK_TOL
    assert _track_gap(out_csv, out) < TRACK_TOL


def test_what_the_file_does_not_give_is_warned_about_and_kept(tmp_path, capsys):
    """A receiver's file from 30 s before the log to 200 s into it (the log
    ends at 300 s), GST for every other fix, a sentence garbled in transit,
    satellites in view: the fixes before the log dropped, the sigmas
    assumed, the bad sentence skipped, the end uncovered: each a warning,
    in summary.json and on the page."""
    refs = _fixes(np.arange(-3_000, 20_001, 100), 0.5)
    path = tmp_path / "rx.nmea"
    N.write_nmea(path, refs, "2026-12-05T10:00:00", tick_hz=100)
    # (write_nmea takes the negative ticks: 30 s before the start)
    lines = path.read_text().splitlines()
    out_lines, n_gst = [], 0
    for line in lines:
        if "GST" in line:
            n_gst += 1
            if n_gst % 2 == 0:
                continue
        out_lines.append(line)
    i = next(j for j, line in enumerate(out_lines) if line.startswith("$GPGGA,100300"))   # 180 s
    out_lines[i] = out_lines[i].replace("$GPGGA,100300.00,3414", "$GPGGA,100300.00,3415")  # checksum now wrong
    out_lines.insert(3, N.sentence("GPGSV,1,1,01,03,03,111,00"))
    path.write_text("\r\n".join(out_lines) + "\r\n")
    rc, s, out = _replay(tmp_path, "--gnss", str(path), "--nmea-utc-start", "2026-12-05T10:00:00",
                         "--gnss-sigma", "0.5 m")
    assert rc == 0, capsys.readouterr().err
    w = s["warnings"]
    name = f"--gnss {path}"
    expect = [f"{name} covers only part of the log: 60 of its 461 references (UTC 2026-12-05T09:59:30.00 .. "
              "2026-12-05T09:59:59.00) lie before the log's start (2026-12-05T10:00:00.00) and were dropped",
              f"{name}: velocity sigma 0.1 m/s assumed, not measured (RMC carries none; give --gnss-vel-sigma "
              "to state it)",
              f"{name}: 1 sentence with a bad checksum skipped (the first at line {i + 2})",
              "the references end 100 s before the log does: unaided from 200 to 300 s"]
    for e in expect:
        assert e in w, (e, w)
    assert f"{name}: position sigma" not in " ".join(w)      # --gnss-sigma given: stated, not assumed
    src, = s["references"]["sources"]
    assert src["ignored"] == {"GSV": 1} and src["before_log"] == 60
    assert src["sigmas"]["gnss_pos"] == {"GST": 100, "--gnss-sigma": 100}
    assert s["references"]["kinds"]["gnss_pos"]["given"] == 200      # 0 .. 200 s, less the garbled one
    page = (out / "report.html").read_text()
    assert "covers only part of the log" in page and "unaided from 200 to 300 s" in page
    assert "201 gnss_vel from RMC (sigma: 201 assumed)" in page           # the file's row
    assert "200 gnss_pos from GGA (sigma: 100 GST, 100 --gnss-sigma)" in page
    err = capsys.readouterr().err
    assert "WARNING: --gnss" in err and "bad checksum" in err


def test_files_merge_with_refs_and_zero_velocity_either_way(tmp_path):
    """GNSS and speed log, each as NMEA in one run and as text in the
    other, with --zero-velocity: merged by tick; the two runs navigate
    alike (TRACK_TOL; the speed to 0.001 kn)."""
    ticks = np.arange(12_000, 30_001, 100)
    gnss = _fixes(ticks, 3.0)
    z = np.zeros(len(ticks))
    log = contract.make_refs("speed_log", ticks,
                             np.column_stack([np.random.default_rng(3).normal(0, 0.05, len(ticks)), z, z]),
                             np.column_stack([np.full(len(ticks), 0.05), z, z]))
    R.save_refs_csv(str(tmp_path / "gnss.csv"), gnss)
    R.save_refs_csv(str(tmp_path / "log.csv"), log)
    N.write_nmea(tmp_path / "gnss.nmea", gnss, START)
    N.write_nmea(tmp_path / "log.nmea", log, START)             # ZDA + VHW a second
    rc, a, out_a = _replay(tmp_path, "--gnss", str(tmp_path / "gnss.nmea"), "--speed-log",
                           str(tmp_path / "log.csv"), "--zero-velocity", "--nmea-utc-start", START,
                           "--gnss-vel-sigma", "0.05 m/s", name="a")
    assert rc == 0
    rc, b, out_b = _replay(tmp_path, "--refs", str(tmp_path / "gnss.csv"), "--speed-log",
                           str(tmp_path / "log.nmea"), "--zero-velocity", "--nmea-utc-start", START,
                           "--speed-log-sigma", "0.05 m/s", name="b")
    assert rc == 0
    for s in (a, b):
        k = s["references"]["kinds"]
        assert {n: k[n]["given"] for n in k} == {"gnss_pos": 181, "gnss_vel": 181, "speed_log": 181,
                                                  "zero_velocity": 181}
    assert [src["option"] for src in a["references"]["sources"]] == ["--gnss", "--speed-log"]
    assert a["references"]["sources"][1] == {"option": "--speed-log", "file": str(tmp_path / "log.csv"),
                                             "format": "reference text", "references": {"speed_log": 181}}
    # a speed log has no time in NMEA: said (the only warning of either run)
    assert _others(b["warnings"]) == [f"--speed-log {tmp_path / 'log.nmea'}: 181 VHW carry no time: each took the time "
                             "of the last timed sentence (GGA, RMC, GST, ZDA) before it, up to 1 s earlier "
                             "(the longest interval between the file's timed epochs)"]
    assert _others(a["warnings"]) == []
    assert _track_gap(out_a, out_b) < TRACK_TOL


@pytest.fixture(scope="module")
def voyage(tmp_path_factory):
    """The built-in voyage_gnss (a ship under way at 5-20 kn, 1 Hz GNSS of
    3 m noise and a 2 m Gauss-Markov bias) cut to 5 minutes: its 2 h
    track costs ~8 s to build each time a replay loads the scenario from
    the log; 5 min costs ~0.5 s and holds a course change of its route."""
    tmp = tmp_path_factory.mktemp("voyage")
    text = (ROOT / "pyins/builtin/scenarios/voyage_gnss.toml").read_text()
    assert '\nduration = "2 h"\n' in text
    (tmp / "voyage.toml").write_text(text.replace('\nduration = "2 h"\n', '\nduration = "5 min"\n'))
    rc = cli.main(["simulate", str(tmp / "voyage.toml"), str(tmp / "voyage.npz"), "--refs",
                   str(tmp / "refs.csv"), "--quiet"])
    assert rc == 0
    return tmp


def test_a_simulated_voyage_replays_from_nmea_as_from_its_reference_file(voyage, tmp_path):
    refs = R.load_refs_csv(str(voyage / "refs.csv"))
    N.write_nmea(tmp_path / "voyage.nmea", refs, "2026-12-05T10:00:00.00")
    log = str(voyage / "voyage.npz")
    rc, csv, out_csv = _replay(tmp_path, "--refs", str(voyage / "refs.csv"), name="csv", log=log, site=False)
    assert rc == 0
    rc, s, out = _replay(tmp_path, "--gnss", str(tmp_path / "voyage.nmea"), "--nmea-utc-start",
                         "2026-12-05T10:00:00.00", "--gnss-vel-sigma", "0.05 m/s", name="nmea", log=log,
                         site=False)
    assert rc == 0
    k = s["references"]["kinds"]
    assert k["gnss_pos"]["given"] == k["gnss_vel"]["given"] == 300
    assert k["gnss_pos"]["used"] == csv["references"]["kinds"]["gnss_pos"]["used"]
    assert s["warnings"] == csv["warnings"]
    # against the voyage's truth: the same within the NMEA rounding (measured: 4.67 m both,
    # the tracks 0.6 cm apart)
    assert abs(s["errors"]["horizontal_max_m"] - csv["errors"]["horizontal_max_m"]) < TRACK_TOL
    assert _track_gap(out_csv, out) < TRACK_TOL


# -- refusals ---------------------------------------------------------------
def _nmea_file(tmp):
    p = tmp / "rx.nmea"
    N.write_nmea(p, _fixes(np.arange(12_000, 12_501, 100), 3.0), "2026-12-05T10:00:00")
    return p


def _damaged_xz(text):
    """``text`` xz-compressed, its middle bytes flipped (the header and the
    stream's end intact: lzma says "Corrupt input data")."""
    b = bytearray(lzma.compress(text.encode()))
    for i in range(20, len(b) - 20):
        b[i] ^= 0x55
    return bytes(b)


CASES = [
    # (files to make, argv, words of the one-line error)
    ({}, ["--gnss", "{tmp}/missing.nmea", "--nmea-utc-start", "2026-12-05T10:00:00"],
     "--gnss {tmp}/missing.nmea: No such file or directory"),
    ({}, ["--gnss", "{tmp}"], "--gnss {tmp}: a directory, not a file of references"),
    ({"empty.nmea": ""}, ["--speed-log", "{tmp}/empty.nmea"], "--speed-log {tmp}/empty.nmea: an empty file"),
    ({"x.txt": "hello\nworld\n"}, ["--gnss", "{tmp}/x.txt"],
     "--gnss {tmp}/x.txt:1: neither NMEA 0183 (sentences beginning with $ or !) nor the reference text layout"),
    ({"x.bin": b"\x00\x01\xff\xfe" * 8}, ["--gnss", "{tmp}/x.bin"],
     "--gnss {tmp}/x.bin:1: neither NMEA 0183"),
    ("nmea", ["--gnss", "{tmp}/rx.nmea"],
     "--gnss {tmp}/rx.nmea: an NMEA 0183 file, whose times are UTC: give --nmea-utc-start"),
    ("nmea", ["--speed-log", "{tmp}/rx.nmea", "--nmea-utc-start", "2026-12-05T10:00:00"],
     "--speed-log {tmp}/rx.nmea: no usable VBW or VHW sentence (sentences found: 6 GGA, 6 GST, 6 RMC)"),
    ({"gsv.nmea": N.sentence("GPGSV,1,1,01,03,03,111,00") + "\n"}, ["--gnss", "{tmp}/gsv.nmea", "--nmea-utc-start",
                                                         "2026-12-05T10:00:00"],
     "--gnss {tmp}/gsv.nmea: no usable GGA, RMC or VTG sentence (sentences found: 1 GSV)"),
    ("nmea", ["--gnss", "{tmp}/rx.nmea", "--nmea-utc-start", "2026-12-06T10:00:00"],
     "--gnss {tmp}/rx.nmea: all its 12 references (UTC 2026-12-05T10:02:00.00 .. 2026-12-05T10:02:05.00) lie "
     "before the log's start (--nmea-utc-start 2026-12-06T10:00:00.00): nothing to use"),
    ("nmea", ["--gnss", "{tmp}/rx.nmea", "--nmea-utc-start", "10:00:00"],
     "--nmea-utc-start: '10:00:00' is not a UTC date and time: write it as YYYY-MM-DDThh:mm:ss[.sss]"),
    ("nmea", ["--gnss", "{tmp}/rx.nmea", "--nmea-utc-start", "2026-12-05T10:00:00", "--gnss-sigma", "0 m"],
     "--gnss-sigma '0 m': a sigma must be more than 0 m"),
    ("nmea", ["--gnss", "{tmp}/rx.nmea", "--nmea-utc-start", "2026-12-05T10:00:00", "--gnss-sigma", "-3 m"],
     "--gnss-sigma '-3 m': a sigma must be more than 0 m"),
    ("nmea", ["--gnss", "{tmp}/rx.nmea", "--nmea-utc-start", "2026-12-05T10:00:00", "--gnss-sigma", "inf m"],
     "--gnss-sigma 'inf m'"),
    ("nmea", ["--gnss", "{tmp}/rx.nmea", "--nmea-utc-start", "2026-12-05T10:00:00", "--gnss-vel-sigma", "3 m"],
     "--gnss-vel-sigma '3 m': wrong unit 'm'"),
    ("nmea", ["--speed-log", "{tmp}/rx.nmea", "--speed-log-sigma", "nan m/s"], "--speed-log-sigma 'nan m/s'"),
    ({}, ["--gnss-sigma", "3 m"], "--gnss-sigma: applies to the NMEA file of --gnss FILE, which is not given"),
    ({}, ["--speed-log-sigma", "0.05 m/s"],
     "--speed-log-sigma: applies to the NMEA file of --speed-log FILE, which is not given"),
    ({}, ["--nmea-utc-start", "2026-12-05T10:00:00"],
     "--nmea-utc-start: applies to the NMEA files of --gnss or --speed-log; neither is given"),
    ("csv", ["--gnss", "{tmp}/r.csv", "--nmea-utc-start", "2026-12-05T10:00:00"],
     "--nmea-utc-start: applies to NMEA files; --gnss {tmp}/r.csv is in the reference text layout"),
    ("csv", ["--gnss", "{tmp}/r.csv", "--gnss-sigma", "3 m"],
     "--gnss-sigma: --gnss {tmp}/r.csv is in the reference text layout, whose rows hold their sigmas"),
    ("csv", ["--speed-log", "{tmp}/r.csv"],
     "--speed-log {tmp}/r.csv:2: a gnss_pos reference; --speed-log takes speed_log (12 rows are not): give "
     "the file to --gnss or --refs"),
    ({"r.csv": "tick,kind,v0,v1,v2,s0,s1,s2\n\n12000,zero_velocity,0,0,0,0.01,0.01,0.01\n"},
     ["--gnss", "{tmp}/r.csv"], "--gnss {tmp}/r.csv:3: a zero_velocity reference; --gnss takes gnss_pos and "
                                "gnss_vel (1 rows are not): give the file to --refs"),
    ({"r.csv": "tick,kind,v0,v1,v2,s0,s1,s2\n12000,speed_log,1,0,0,0,0,0\n"}, ["--speed-log", "{tmp}/r.csv"],
     "--speed-log {tmp}/r.csv:2: sigma [0.0] must be > 0"),
    ("nmea", ["--refs", "{tmp}/rx.nmea"],
     "--refs {tmp}/rx.nmea: an NMEA 0183 file: give it to --gnss (GGA, RMC, VTG) or --speed-log (VHW, VBW)"),
    # a compressed file damaged inside (lzma's own error, not an EOF): it was an internal error
    ({"bad.nmea.xz": _damaged_xz(N.sentence("GPGGA,100000.00,3414.7629,N,10854.5798,E,1,08,0.9,380.0,M,0.0,M,,")
                                 + "\n")},
     ["--gnss", "{tmp}/bad.nmea.xz", "--nmea-utc-start", "2026-12-05T10:00:00"],
     "--gnss {tmp}/bad.nmea.xz: not a complete xz stream"),
]


@pytest.mark.parametrize("files, argv, words", CASES, ids=[f"{i}-{c[1][0]}" for i, c in enumerate(CASES)])
def test_bad_reference_files_are_refused_in_one_line_naming_the_option(tmp_path, capsys, files, argv, words):
    if files == "nmea":
        _nmea_file(tmp_path)
    elif files == "csv":
        R.save_refs_csv(str(tmp_path / "r.csv"), _fixes(np.arange(12_000, 12_501, 100), 3.0))
    else:
        for name, content in files.items():
            (tmp_path / name).write_bytes(content if isinstance(content, bytes) else content.encode())
    args = [a.replace("{tmp}", str(tmp_path)) for a in argv]
    rc, _, out = _replay(tmp_path, *args)
    err = capsys.readouterr().err
    assert rc == 2, err
    assert words.replace("{tmp}", str(tmp_path)) in err, err
    lines = [line for line in err.splitlines() if line.strip()]
    assert len(lines) == 1 and "Traceback" not in err and "internal error" not in err, err
    assert "pos_sigma" not in err and "utc_start" not in err and "_mps" not in err     # the CLI's words
    assert not (out / "summary.json").exists()       # refused before the log runs
