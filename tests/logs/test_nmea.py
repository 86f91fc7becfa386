"""`pyins.logs.nmea`: NMEA 0183 sentences -> reference records, and back.

Sentence layouts: NMEA 0183 v4.11. The checksums here are computed by the
test's own XOR (`_cs`), or are the published ones of sentences quoted in
many references (gpsinformation.org's GGA and RMC examples); field values
are checked against hand arithmetic. Tolerances are in metres (m/s) with
the reason: float arithmetic where the text is exact, half the last
written digit where the writer rounds."""
import functools
import math
import operator

import numpy as np
import pytest

from pyins import contract
from pyins.logs import nmea as N
from pyins.reference import earth
from pyins.units import DEG_TO_RAD

KN = 1852.0 / 3600.0          # one knot [m/s], by definition
#: float arithmetic on exact decimal text: ~1e-16 relative of an angle of
#: ~1 rad, 1e-12 rad (6 um on the ground) is far above it and far below
#: any NMEA resolution (1e-5 minute of arc = 1.9 cm)
ANGLE_TOL = 1e-12


def _cs(body):
    return functools.reduce(operator.xor, body.encode("ascii"), 0)


def _s(body):
    """A sentence with its correct checksum (the test's own XOR)."""
    return f"${body}*{_cs(body):02X}"


def _write(tmp_path, lines, name="f.nmea"):
    p = tmp_path / name
    p.write_text("".join(line + "\r\n" for line in lines), encoding="ascii")
    return p


def _read(path, start="2026-12-05T10:00:00", **kw):
    return N.read_nmea(path, start, 100, **kw)


def _kind(r, name):
    return r.refs[r.refs["kind"] == {"gnss_pos": 1, "gnss_vel": 2, "speed_log": 3}[name]]


# -- checksums and fields ---------------------------------------------------
PUBLISHED = [
    # gpsinformation.org (D. DePriest, "NMEA data"): 12:35:19 UTC, 48 07.038' N 11 31.000' E,
    # quality 1, 545.4 m above the geoid, geoid 46.9 m above the ellipsoid
    "$GPGGA,123519,4807.038,N,01131.000,E,1,08,0.9,545.4,M,46.9,M,,*47",
    # the same page's RMC: 22.4 kn over ground at 84.4 deg true, 23 March 1994
    "$GPRMC,123519,A,4807.038,N,01131.000,E,022.4,084.4,230394,003.1,W*6A",
]


def test_published_sentences_pass_their_checksums_and_give_their_fields(tmp_path):
    for line in PUBLISHED:             # the module's checksum agrees with the published one
        body, hh = line[1:].split("*")
        assert N.checksum(body) == int(hh, 16) == _cs(body)
    r = _read(_write(tmp_path, PUBLISHED), start="1994-03-23T12:35:00")
    assert r.warnings[0].startswith(f"{tmp_path / 'f.nmea'}: position sigma 5 m assumed, not measured, "
                                    "for 1 of the 1 fixes (no GST of their epoch")
    pos, vel = _kind(r, "gnss_pos"), _kind(r, "gnss_vel")
    # 19 s after the start at 100 Hz; the RMC's date 230394 read as 1994 (a wrong century or
    # day would put it 100 years or a day away)
    assert pos["tick"].tolist() == vel["tick"].tolist() == [1900]
    lat, lon, h = pos["value"][0]
    assert abs(lat - (48 + 7.038 / 60) * DEG_TO_RAD) < ANGLE_TOL
    assert abs(lon - (11 + 31.0 / 60) * DEG_TO_RAD) < ANGLE_TOL
    assert abs(h - (545.4 + 46.9)) < 1e-9          # ellipsoidal: altitude + separation (float sum)
    assert pos["sigma"][0].tolist() == [5.0, 5.0, 5.0]
    v = 22.4 * KN
    c = math.radians(84.4)
    assert np.allclose(vel["value"][0], [v * math.sin(c), v * math.cos(c), 0.0], rtol=0, atol=1e-12)
    # RMC gives no vertical velocity: its sigma 0 says so (the alignment under way reads
    # the vertical only where its sigma is > 0)
    assert vel["sigma"][0].tolist() == [0.1, 0.1, 0.0]
    assert r.facts["sigmas"] == {"gnss_pos": {"GST": 0, "assumed": 1}, "gnss_vel": {"assumed": 1}}


def test_south_west_hemispheres_and_a_negative_geoid_separation(tmp_path):
    body = "GPGGA,184353.07,1929.045,S,02410.506,W,1,04,2.6,100.00,M,-33.9,M,,0000"
    r = _read(_write(tmp_path, [_s(body)]), start="2026-12-05T18:43:53.00")
    (lat, lon, h), = _kind(r, "gnss_pos")["value"]
    assert abs(lat + (19 + 29.045 / 60) * DEG_TO_RAD) < ANGLE_TOL
    assert abs(lon + (24 + 10.506 / 60) * DEG_TO_RAD) < ANGLE_TOL
    assert abs(h - 66.1) < 1e-9
    assert _kind(r, "gnss_pos")["tick"].tolist() == [7]          # 0.07 s at 100 Hz


def test_a_bad_checksum_is_skipped_counted_and_never_used(tmp_path):
    good = "GPGGA,100001.00,3414.76288,N,10854.57984,E,1,08,1.0,380.0,M,0.0,M,,"
    bad = good.replace("100001", "100002")
    tampered = bad.replace("3414.76288", "3414.86288") + f"*{_cs(bad):02X}"    # the digits changed in transit
    lines = [_s(good), "$" + tampered,
             "$" + good.replace("100001", "100003") + "*G1",                    # not two hex digits
             "$" + good.replace("100001", "100004") + f"*{_cs(good.replace('100001', '100004')):02x}",  # lower case
             "$" + good.replace("100001", "100005")]                            # no checksum: taken
    r = _read(_write(tmp_path, lines))
    pos = _kind(r, "gnss_pos")
    assert pos["tick"].tolist() == [100, 400, 500]
    assert np.all(pos["value"][:, 0] == pos["value"][0, 0])     # the tampered latitude is nowhere
    assert f"{tmp_path / 'f.nmea'}: 2 sentences with a bad checksum skipped (the first at line 2)" in r.warnings
    assert r.facts["skipped"]["bad checksum"] == 2 and r.facts["without_checksum"] == 1


AIS = "AIVDM,1,1,,B,15M67FC000G?ufbE`FepT@3n00Sa,0"       # an AIS message, encapsulated (!)


def test_talker_ids_are_any_and_unknown_sentences_are_counted_and_ignored(tmp_path):
    lines = [_s("GNGGA,100001.00,3414.76288,N,10854.57984,E,2,12,0.8,380.0,M,0.0,M,1.0,0001"),
             _s("GLRMC,100001.00,A,3414.76288,N,10854.57984,E,10.0,90.0,051226,,,D"),
             _s("GAGST,100001.00,1.0,2.0,1.0,90.0,1.0,2.0,3.0"),
             _s("IIVHW,,T,,M,9.5,N,,K"),
             _s("GPGSV,3,1,11,03,03,111,00,04,15,270,00,06,01,010,00,13,06,292,00"),
             _s("GPGSA,A,3,04,05,,09,12,,,24,,,,,2.5,1.3,2.1"),
             _s("PUBX,00,081350.00,4717.113210,N,00833.915187,E,546.589,G3,2.1,2.0,0.007,77.52,0.007,,0.92,"
                "1.19,0.77,9,0,0"),
             "!" + AIS + f"*{_cs(AIS):02X}",
             _s("VDVBW,-1.5,0.1,A,,,V")]
    r = _read(_write(tmp_path, lines), pos_sigma_m=3.0, vel_sigma_mps=0.05, log_sigma_mps=0.05)
    assert r.facts["ignored"] == {"GSV": 1, "GSA": 1, "PUBX": 1, "VDM": 1}
    assert r.facts["references"] == {"gnss_pos": 1, "gnss_vel": 1, "speed_log": 1}    # GN, GL, GA, II: taken
    assert _kind(r, "gnss_pos")["sigma"][0].tolist() == [2.0, 1.0, 3.0]   # GST: lon (E), lat (N), alt
    assert np.allclose(_kind(r, "gnss_vel")["value"][0], [10 * KN, 0.0, 0.0], atol=1e-12)
    # one speed an epoch: the VHW (the first); the VBW of the same epoch counted
    assert _kind(r, "speed_log")["value"][0].tolist() == [9.5 * KN, 0.0, 0.0]
    assert any("1 speed of the same epoch" in w for w in r.warnings)


def test_fixes_that_are_not_measurements_are_skipped_and_counted(tmp_path):
    fix = "GPGGA,{t},3414.76288,N,10854.57984,E,{q},08,1.0,380.0,M,0.0,M,,"
    rmc = "GPRMC,{t},{s},3414.76288,N,10854.57984,E,1.0,45.0,051226,,,{m}"
    lines = [_s(fix.format(t="100001.00", q=1)), _s("GPGGA,100002.00,,,,,0,00,99.9,,,,,,"),
             _s(fix.format(t="100003.00", q=6)), _s(fix.format(t="100004.00", q=4)),
             _s(rmc.format(t="100001.00", s="A", m="A")), _s(rmc.format(t="100002.00", s="V", m="N")),
             _s(rmc.format(t="100003.00", s="A", m="N")), _s(rmc.format(t="100004.00", s="A", m="E"))]
    r = _read(_write(tmp_path, lines), pos_sigma_m=3.0, vel_sigma_mps=0.05)
    assert _kind(r, "gnss_pos")["tick"].tolist() == [100, 400]      # quality 1 and 4 (RTK fixed)
    assert _kind(r, "gnss_vel")["tick"].tolist() == [100]
    assert r.facts["skipped"] == {"GGA no fix (quality 0)": 1, "GGA estimated (quality 6)": 1,
                                  "RMC not valid (status V)": 1, "RMC not valid (mode N)": 1,
                                  "RMC estimated (mode E)": 1}
    w = " | ".join(r.warnings)
    assert "1 GGA no fix (quality 0) skipped (the first at line 2)" in w
    assert "1 RMC estimated (mode E) skipped (the first at line 8)" in w


@pytest.mark.parametrize("field, text, why", [
    ("hemisphere", "3414.76288,X", "latitude hemisphere 'X' is not N or S"),   # not read as 0 deg
    ("minutes", "3460.50000,N", "latitude '3460.50000' is not an angle"),
    ("degrees", "9100.00000,N", "latitude '9100.00000' is not an angle"),
    ("number", "34l4.76288,N", "latitude '34l4.76288' is not ddmm.mmmm"),
])
def test_fields_that_do_not_parse_skip_the_sentence_with_its_line(tmp_path, field, text, why):
    body = f"GPGGA,100002.00,{text},10854.57984,E,1,08,1.0,380.0,M,0.0,M,,"
    lines = [_s("GPGGA,100001.00,3414.76288,N,10854.57984,E,1,08,1.0,380.0,M,0.0,M,,"), _s(body)]
    r = _read(_write(tmp_path, lines), pos_sigma_m=3.0)
    assert _kind(r, "gnss_pos")["tick"].tolist() == [100]
    assert r.warnings[0].startswith(f"{tmp_path / 'f.nmea'}: 1 sentence whose fields do not parse skipped "
                                    f"(the first at line 2: GGA: {why}")


@pytest.mark.parametrize("body, why", [
    ("GPGGA,256001.00,3414.76288,N,10854.57984,E,1,08,1.0,380.0,M,0.0,M,,", "time '256001.00' is not a time of day"),
    ("GPGGA,100001.00,3414.76288,N,10854.57984,E,1,08,1.0,abc,M,0.0,M,,", "altitude 'abc' is not a number"),
    ("GPGGA,100001.00,3414.76288,N,10854.57984,E,1,08,1.0,nan,M,0.0,M,,", "altitude 'nan' is not a number"),
    ("GPGGA,100001.00,3414.76288,N,10854.57984,E,1,08,1.0,380.0", "9 fields, GGA has 14"),     # cut
    ("GPRMC,100001.00,A,3414.76288,N,10854.57984,E,1.0,45.0,311326,,,A", "date '311326' is not a date"),
    ("GPGST,100001.00,1.0,2.0,1.0,90.0,0.0,2.0,3.0", "sigmas 0.0, 2.0, 3.0 must be more than 0"),
])
def test_more_fields_that_do_not_parse(tmp_path, body, why):
    good = _s("GPGGA,100009.00,3414.76288,N,10854.57984,E,1,08,1.0,380.0,M,0.0,M,,")
    r = _read(_write(tmp_path, [_s(body), good]), pos_sigma_m=3.0)
    assert len(_kind(r, "gnss_pos")) == 1
    assert any(f"(the first at line 1: {body[2:5]}: {why})" in w for w in r.warnings), r.warnings


def test_gst_gives_the_sigmas_of_its_epoch_else_the_users(tmp_path):
    lines = [_s("GPGST,100001.00,0.9,2.0,1.0,10.0,1.5,2.5,4.0"),      # before its GGA: matched by time
             _s("GPGGA,100001.00,3414.76288,N,10854.57984,E,1,08,1.0,380.0,M,0.0,M,,"),
             _s("GPGGA,100002.00,3414.76288,N,10854.57984,E,1,08,1.0,380.0,M,0.0,M,,"),
             _s("GPGST,100003.00,0.9,2.0,1.0,10.0,1.5,2.5,"),           # no altitude sigma: the larger
             _s("GPGGA,100003.00,3414.76288,N,10854.57984,E,1,08,1.0,380.0,M,0.0,M,,")]
    r = _read(_write(tmp_path, lines), pos_sigma_m=3.0)
    assert _kind(r, "gnss_pos")["sigma"].tolist() == [[2.5, 1.5, 4.0], [3.0, 3.0, 3.0], [2.5, 1.5, 2.5]]
    assert r.facts["sigmas"]["gnss_pos"] == {"GST": 2, "pos_sigma_m": 1}
    assert not any("assumed" in w for w in r.warnings)         # stated, not assumed
    # every fix with its GST: the user's value is not used, and said so
    r = _read(_write(tmp_path, lines[:2]), pos_sigma_m=3.0)
    assert any("pos_sigma_m 3 m not used: every fix had the sigmas of its GST" in w for w in r.warnings)


# -- time -----------------------------------------------------------------
def _gga(t):
    return _s(f"GPGGA,{t},3414.76288,N,10854.57984,E,1,08,1.0,380.0,M,0.0,M,,")


def test_midnight_rolls_over_without_a_date(tmp_path):
    # the log starts 2 s before midnight; times of day without a date: 23:59:59, then 00:00:00 ...
    r = _read(_write(tmp_path, [_gga("235959.00"), _gga("000000.00"), _gga("000001.00")]),
              start="2026-12-05T23:59:58", pos_sigma_m=3.0)
    assert _kind(r, "gnss_pos")["tick"].tolist() == [100, 200, 300]
    assert r.facts["midnights"] == 1 and r.facts["utc_span"] == ["2026-12-05T23:59:59.00", "2026-12-06T00:00:01.00"]
    # a file that begins after midnight is put on the day within 12 h of the start: the next one
    r = _read(_write(tmp_path, [_gga("000001.00")]), start="2026-12-05T23:59:58", pos_sigma_m=3.0)
    assert _kind(r, "gnss_pos")["tick"].tolist() == [300]
    # and one that begins before a start just after midnight: the day before
    r = _read(_write(tmp_path, [_gga("235959.00"), _gga("000001.00")]), start="2026-12-06T00:00:00",
              pos_sigma_m=3.0)
    assert _kind(r, "gnss_pos")["tick"].tolist() == [100]
    assert "1 of its 2 references (UTC 2026-12-05T23:59:59.00 .. 2026-12-05T23:59:59.00) lie before" in r.warnings[0]


def test_dates_of_rmc_and_zda_date_the_undated(tmp_path):
    lines = [_s("GPRMC,235959.00,A,3414.76288,N,10854.57984,E,1.0,45.0,051226,,,A"),
             _gga("000000.00"),                                        # undated, after midnight: 6 Dec
             _s("GPRMC,000001.00,A,3414.76288,N,10854.57984,E,1.0,45.0,061226,,,A"),
             _s("GPZDA,000002.00,06,12,2026,00,00"), _gga("000002.00")]
    r = _read(_write(tmp_path, lines), start="2026-12-05T23:59:58", pos_sigma_m=3.0, vel_sigma_mps=0.05)
    assert _kind(r, "gnss_pos")["tick"].tolist() == [200, 400]
    assert _kind(r, "gnss_vel")["tick"].tolist() == [100, 300]
    # the same file a day later by its dates: every fix 24 h before the start: refused
    with pytest.raises(N.NmeaError, match=r"all its 4 references \(UTC 2026-12-05T23:59:59.00 .. "
                                          r"2026-12-06T00:00:02.00\) lie before the log's start \(utc_start "
                                          r"2026-12-06T23:59:58.00\): nothing to use; check the date"):
        _read(_write(tmp_path, lines), start="2026-12-06T23:59:58", pos_sigma_m=3.0, vel_sigma_mps=0.05)


def test_time_going_back_is_warned_about_and_sorted(tmp_path):
    r = _read(_write(tmp_path, [_gga("100010.00"), _gga("100005.00"), _gga("100011.00")]), pos_sigma_m=3.0)
    assert _kind(r, "gnss_pos")["tick"].tolist() == [500, 1000, 1100]
    assert any("the time goes back 1 time (the first at line 2)" in w for w in r.warnings)


def test_ticks_round_half_up_in_exact_arithmetic(tmp_path):
    # 0.4, 0.5, 1.5 and 1.49999999 ticks at 100 Hz: floor(x + 1/2) of the exact decimal. In floats
    # 0.015 s x 100 is 1.4999999999999998 and would round to 1
    lines = [_gga("100000.004"), _gga("100000.005"), _gga("100000.015"), _gga("100000.014999999")]
    r = _read(_write(tmp_path, lines), pos_sigma_m=3.0)
    assert _kind(r, "gnss_pos")["tick"].tolist() == [0, 1, 1, 2]      # sorted by tick, stable


def test_fixes_before_the_log_are_dropped_with_a_warning(tmp_path):
    lines = [_gga(f"1000{s:02d}.00") for s in range(0, 11)]
    r = _read(_write(tmp_path, lines), start="2026-12-05T10:00:05", pos_sigma_m=3.0)
    assert _kind(r, "gnss_pos")["tick"].tolist() == [0, 100, 200, 300, 400, 500]
    assert r.warnings[0] == (f"{tmp_path / 'f.nmea'} covers only part of the log: 5 of its 11 references (UTC "
                             "2026-12-05T10:00:00.00 .. 2026-12-05T10:00:04.00) lie before the log's start "
                             "(2026-12-05T10:00:05.00) and were dropped")
    assert r.facts["before_log"] == 5


# -- speeds ---------------------------------------------------------------
def test_speed_log_sentences(tmp_path):
    lines = [_s("IIVHW,,T,,M,10.0,N,18.52,K"),                 # before any time: skipped
             _s("GPZDA,100001.00,05,12,2026,00,00"), _s("IIVHW,,T,,M,10.0,N,18.52,K"),
             _s("GPZDA,100002.00,05,12,2026,00,00"), _s("IIVHW,,T,,M,,N,18.0,K"),         # km/h only
             _s("GPZDA,100003.00,05,12,2026,00,00"), _s("VWVBW,-1.5,0.2,A,,,V"),          # astern
             _s("GPZDA,100004.00,05,12,2026,00,00"), _s("VWVBW,3.0,0.2,V,,,V")]           # not valid
    r = _read(_write(tmp_path, lines), kinds=("speed_log",), log_sigma_mps=0.05)
    log = r.refs
    assert log["tick"].tolist() == [100, 200, 300]
    assert np.allclose(log["value"][:, 0], [10.0 * KN, 5.0, -1.5 * KN], rtol=0, atol=1e-12)
    assert np.all(log["value"][:, 1:] == 0) and log["sigma"].tolist() == [[0.05, 0, 0]] * 3
    w = " | ".join(r.warnings)
    assert "1 untimed sentences before the first timed one (GGA, RMC, GST, ZDA) skipped (the first at line 1)" in w
    assert "1 VBW water speed not valid (status V) skipped (the first at line 9)" in w
    assert "3 VBW/VHW carry no time: each took the time of the last timed sentence" in w
    assert "up to 1 s earlier" in w


def test_vtg_gives_the_velocity_only_without_rmc(tmp_path):
    vtg = _s("GPVTG,90.0,T,,M,10.0,N,18.52,K,A")
    r = _read(_write(tmp_path, [_gga("100001.00"), vtg]), pos_sigma_m=3.0, vel_sigma_mps=0.05)
    vel = _kind(r, "gnss_vel")
    assert vel["tick"].tolist() == [100] and np.allclose(vel["value"][0], [10 * KN, 0, 0], atol=1e-12)
    assert any("1 VTG carry no time" in w for w in r.warnings)
    rmc = _s("GPRMC,100001.00,A,3414.76288,N,10854.57984,E,10.0,0.0,051226,,,A")
    r = _read(_write(tmp_path, [_gga("100001.00"), rmc, vtg]), pos_sigma_m=3.0, vel_sigma_mps=0.05)
    vel = _kind(r, "gnss_vel")
    assert len(vel) == 1 and np.allclose(vel["value"][0], [0, 10 * KN, 0], atol=1e-12)   # the RMC's
    assert r.facts["vtg_not_used"] == 1


# -- refusals -------------------------------------------------------------
def test_a_file_with_no_usable_sentence_is_refused_naming_it(tmp_path):
    p = _write(tmp_path, [_s("GPGSV,1,1,01,03,03,111,00"), _s("GPGGA,100002.00,,,,,0,00,99.9,,,,,,")])
    with pytest.raises(N.NmeaError, match=rf"^{tmp_path / 'f.nmea'}: no usable GGA, RMC or VTG sentence "
                                          r"\(sentences found: 1 GGA, 1 GSV; skipped: 1 GGA no fix \(quality 0\)\)"):
        _read(p, kinds=("gnss_pos", "gnss_vel"))
    p = _write(tmp_path, [_gga("100001.00")])
    with pytest.raises(N.NmeaError, match=r"no usable VBW or VHW sentence \(sentences found: 1 GGA\)"):
        _read(p, kinds=("speed_log",))
    p = _write(tmp_path, ["tick,kind,v0,v1,v2,s0,s1,s2", "100,gnss_vel,0,0,0,1,1,1"])
    with pytest.raises(N.NmeaError, match=r"not NMEA 0183"):
        _read(p)
    p = tmp_path / "bin.nmea"
    p.write_bytes(b"$GPGGA\x00\x01\x02")
    with pytest.raises(N.NmeaError, match=r"not a text file"):
        _read(p)


@pytest.mark.parametrize("kw", [dict(pos_sigma_m=0.0), dict(vel_sigma_mps=-1.0), dict(log_sigma_mps=float("nan"))])
def test_a_sigma_must_be_finite_and_positive(tmp_path, kw):
    with pytest.raises(N.NmeaError, match=r"a sigma must be finite and more than 0"):
        _read(_write(tmp_path, [_gga("100001.00")]), **kw)


@pytest.mark.parametrize("text", ["2026-12-05", "10:00:00", "2026-13-05T10:00:00", "2026-02-30T10:00:00",
                                  "2026-12-05T24:00:00", "2026-12-05T10:00:00+25:00", "yesterday"])
def test_bad_utc_times_are_refused(text):
    with pytest.raises(ValueError):
        N.parse_utc(text)


def test_utc_times():
    base = N.parse_utc("2026-12-05T10:00:00")
    assert N.parse_utc("2026-12-05 10:00:00.5Z") - base == 500_000_000
    assert N.parse_utc("2026-12-05T12:00:00+02:00") == base
    assert N.parse_utc("2026-12-05T10:00:00.000000001") - base == 1
    assert N.format_utc(base + 250_000_000) == "2026-12-05T10:00:00.25"


# -- writing and reading back ---------------------------------------------
def _random_refs(rng, n, tick_hz=100):
    ticks = np.arange(1, n + 1, dtype=np.int64) * tick_hz
    lat = rng.uniform(-80, 80, n) * DEG_TO_RAD
    lon = rng.uniform(-180, 180, n) * DEG_TO_RAD
    pos = np.column_stack([lat, lon, rng.uniform(-50, 3000, n)])
    sig = np.column_stack([rng.uniform(0.01, 9.0, n), rng.uniform(0.01, 9.0, n), rng.uniform(0.01, 9, n)])
    vel = np.column_stack([rng.uniform(-15, 15, n), rng.uniform(-15, 15, n), np.zeros(n)])
    z = np.zeros(n)
    log = np.column_stack([rng.uniform(-3, 15, n), z, z])
    parts = [contract.make_refs("gnss_pos", ticks, pos, sig),
             contract.make_refs("gnss_vel", ticks, vel, np.full((n, 3), 0.05)),
             contract.make_refs("speed_log", ticks, log, np.column_stack([np.full(n, 0.05), z, z]))]
    refs = np.concatenate(parts)
    return refs[np.argsort(refs["tick"], kind="stable")]


@pytest.mark.parametrize("decimals", [4, 5])
def test_written_and_read_back_within_the_nmea_resolution(tmp_path, decimals):
    """GGA + GST + RMC + VHW written, read back: the same ticks and kinds;
    each value within half the last digit written. Across midnight (the
    RMC's date changes, the GGA's time of day goes back)."""
    rng = np.random.default_rng(7)
    refs = _random_refs(rng, 400)
    p = tmp_path / "rt.nmea"
    start = "2026-12-05T23:55:00.00"                  # 400 s: midnight at 300 s
    N.write_nmea(p, refs, start, minute_decimals=decimals)
    r = N.read_nmea(p, start, 100, vel_sigma_mps=0.05, log_sigma_mps=0.05)
    assert r.refs["tick"].tolist() == refs["tick"].tolist()
    assert r.refs["kind"].tolist() == refs["kind"].tolist()
    a, b = refs, r.refs
    pos = a["kind"] == 1
    lat = a["value"][pos, 0]
    rm, rn = earth.principal_radii(np.sin(lat))
    h = a["value"][pos, 2]
    dn = (b["value"][pos, 0] - lat) * (rm + h)
    de = (b["value"][pos, 1] - a["value"][pos, 1]) * (rn + h) * np.cos(lat)
    # half the last digit of a minute of arc: 4 decimals -> 0.5e-4' = 0.093 m of latitude,
    # 5 -> 0.0093 m (one minute of latitude is 1843-1862 m); east the same times cos(lat);
    # 1e-6 relative for the float arithmetic of the check itself
    half = 0.5 * 10.0 ** -decimals / 60.0 * DEG_TO_RAD
    assert np.all(np.abs(dn) <= half * (rm + h) * (1 + 1e-6))
    assert np.all(np.abs(de) <= half * (rn + h) * np.cos(lat) * (1 + 1e-6))
    # the bound is met by rounding, not truncation: errors fill it (a truncating writer
    # reaches twice the bound and fails above)
    assert np.max(np.abs(dn) / (half * (rm + h))) > 0.9
    # heights to the mm written: half of it, 0.5 mm; sigmas likewise
    assert np.all(np.abs(b["value"][pos, 2] - h) <= 0.0005 + 1e-9)
    assert np.all(np.abs(b["sigma"][pos] - a["sigma"][pos]) <= 0.0005 + 1e-12)
    vel = a["kind"] == 2
    va, vb = a["value"][vel, :2], b["value"][vel, :2]
    sog = np.hypot(va[:, 0], va[:, 1])
    # speed to 0.001 kn (half: 0.26 mm/s) and course to 0.01 deg (half: 8.7e-5 rad, across the
    # track: sog x that, 1.3 mm/s at 15 m/s)
    bound = 0.5e-3 * KN + sog * math.radians(0.005) + 1e-9
    assert np.all(np.hypot(*(vb - va).T) <= bound)
    assert np.all(b["value"][vel, 2] == 0)                  # up: not in RMC
    log = a["kind"] == 3
    assert np.all(np.abs(b["value"][log, 0] - a["value"][log, 0]) <= 0.5e-3 * KN + 1e-9)
    # the GGA of 00:00:00 comes before its RMC: undated, it rolled over to the day the RMC then gave
    assert r.facts["midnights"] == 1
    assert not [w for w in r.warnings if "assumed" in w or "skipped" in w]


def test_the_writer_refuses_what_nmea_cannot_say(tmp_path):
    zv = contract.make_refs("zero_velocity", [100], np.zeros((1, 3)), np.full((1, 3), 0.01))
    with pytest.raises(ValueError, match="zero_velocity references have no NMEA sentence"):
        N.write_nmea(tmp_path / "x.nmea", zv, "2026-12-05T10:00:00")
    pos = contract.make_refs("gnss_pos", [1], [[0.5, 1.0, 0.0]], [[3.0, 3.0, 5.0]])
    with pytest.raises(ValueError, match=r"not a whole number of 10\^-2 s"):   # 5 ms
        N.write_nmea(tmp_path / "x.nmea", pos, "2026-12-05T10:00:00", tick_hz=200)
    N.write_nmea(tmp_path / "x.nmea", pos, "2026-12-05T10:00:00", tick_hz=200, time_decimals=3)
    r = N.read_nmea(tmp_path / "x.nmea", "2026-12-05T10:00:00", 200)
    assert r.refs["tick"].tolist() == [1]


def test_the_documented_example_sentences_are_valid(tmp_path):
    """docs/log-formats.md, "NMEA 0183": its example lines pass their
    checksums (the test's own XOR) and read as the table says."""
    import pathlib
    doc = (pathlib.Path(__file__).resolve().parents[2] / "docs/log-formats.md").read_text()
    section = doc.split("### NMEA 0183", 1)[1]
    lines = [line.strip() for line in section.splitlines() if line.startswith("    $")]
    assert [line[3:6] for line in lines] == ["GGA", "GST", "RMC", "ZDA", "VHW"]
    for line in lines:
        body, hh = line[1:].split("*")
        assert _cs(body) == int(hh, 16), line
    r = N.read_nmea(_write(tmp_path, lines), "2026-12-05T23:58:00", 100, vel_sigma_mps=0.05, log_sigma_mps=0.05)
    assert r.facts["references"] == {"gnss_pos": 1, "gnss_vel": 1, "speed_log": 1}
    assert r.refs["tick"].tolist() == [100, 100, 200]      # the VHW after the ZDA of 23:58:02
    assert r.refs["sigma"][0].tolist() == [3.606, 3.606, 5.385]
