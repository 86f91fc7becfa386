"""NMEA 0183 files as external references of a replay (``pyins replay
--gnss FILE``, ``--speed-log FILE``): a ship's GNSS receiver's fixes and
its EM speed log as `pyins.sim.references.REF_DTYPE` records on the IMU
log's clock (`read_nmea`), and the other way (`write_nmea`).

Sentences read (layouts of NMEA 0183 v4.11, National Marine Electronics
Association, 2018; each field is comma-separated, ``$`` or ``!`` first,
``*hh`` last: the XOR of the characters between them, two hex digits):

- ``$--GGA,hhmmss.ss,llll.ll,a,yyyyy.yy,a,q,nn,h.h,alt,M,sep,M,age,stn``
  (global positioning system fix data) -> gnss_pos: latitude, longitude,
  height = alt + sep (altitude above the geoid + geoid separation: the
  height above the WGS 84 ellipsoid). Quality q 0 (no fix) is skipped,
  and so are 6 (estimated, dead reckoning), 7 (manual input) and 8
  (simulator): not measurements.
- ``$--RMC,hhmmss.ss,A,llll.ll,a,yyyyy.yy,a,sog,cog,ddmmyy,var,a[,m[,s]]``
  (recommended minimum specific GNSS data) -> gnss_vel: speed over ground
  (knots) and course over ground (deg true) as east, north (up 0, its
  sigma 0: not measured, which the firmware's alignment under way reads
  as no vertical velocity); status
  A only, mode (v2.3 on) not N (not valid), E (estimated), M (manual) or
  S (simulator). Its date dates the file. Its position is not read
  (GGA's has the height and the fix quality).
- ``$--VTG,cog,T,cmag,M,sog,N,kmh,K[,m]`` (course and speed over ground)
  -> gnss_vel, when the file has no usable RMC (the same velocity twice
  otherwise). Knots, else km/h.
- ``$--GST,hhmmss.ss,rms,smaj,smin,orient,slat,slon,salt`` (pseudorange
  error statistics) -> the 1-sigma east (slon) and north (slat) errors
  [m] of the GGA fix of the same time; up: salt.
- ``$--ZDA,hhmmss.ss,dd,mm,yyyy,zh,zm`` (time and date) -> the date.
- ``$--VHW,hdgT,T,hdgM,M,spd,N,kmh,K`` (water speed and heading) ->
  speed_log (knots, else km/h).
- ``$--VBW,lw,tw,A,lg,tg,A[,...]`` (dual ground/water speed) -> speed_log:
  the longitudinal water speed lw (knots, negative astern), status A only.

VTG, VHW and VBW carry no time: each takes the time of the last timed
sentence (GGA, RMC, GST, ZDA) before it, and a warning says so.

Time: NMEA times are UTC times of day; RMC and ZDA give the date. The IMU
log runs on its own clock: ``utc_start`` is the UTC time of its tick 0
(the log's start; tick T is T / tick_hz later), and a time t maps to tick
floor((t - utc_start) tick_hz + 1/2), in exact integer arithmetic
(nanoseconds). Before the file's first date, a time of day is put on the
day that brings it within 12 h of the first dated sentence (of
``utc_start`` when the file has no date); after it, on the day of the
time before it, the next day when the time of day goes back by more than
12 h (midnight) and the day before when it jumps ahead by more than 12 h.
Fixes before tick 0 are dropped with a warning (all of them: refused).

Refused (`NmeaError`, a ValueError naming the file): a file that is not
text, a file with no usable sentence of the kinds asked for, every fix
before the log's start, a sigma that is not finite and > 0. Skipped,
counted and warned about (the count and the first line): sentences whose
checksum does not match, lines that are not sentences, sentences whose
fields do not parse, fixes that are not measurements (above), the same
epoch twice. Unknown sentence types are counted and ignored.

The parser is this module's, not pynmea2's (1.19): pynmea2 verifies the
checksum, but returns a field it cannot convert as its raw text (an
altitude "abc" comes back as the string 'abc') and reads a hemisphere
other than N/S or E/W as 0 deg: silent wrong values this reader refuses
field by field (tests/logs/test_nmea.py).
"""
import datetime
import lzma
import math
import os
import re
from dataclasses import dataclass, field

import numpy as np

from pyins.logs.files import _opener, _read_bytes
from pyins.logs.issues import LogError
from pyins.sim.references import (KIND_GNSS_POS, KIND_GNSS_VEL, KIND_NAMES, KIND_SPEED_LOG, REF_DTYPE)
from pyins.units import DEG_TO_RAD, NMI_TO_M

__all__ = ["read_nmea", "write_nmea", "is_nmea", "looks_like_nmea", "checksum", "sentence", "parse_utc",
           "format_utc", "NmeaError", "NmeaRefs", "KNOT_MPS", "DEFAULT_POS_SIGMA_M",
           "DEFAULT_VEL_SIGMA_MPS", "DEFAULT_LOG_SIGMA_MPS", "SENTENCES"]

KNOT_MPS = NMI_TO_M / 3600.0        #: one knot [m/s] (1852 m an hour, exactly)
KMH_MPS = 1.0 / 3.6                 #: one km/h [m/s]

#: The sigmas assumed when the file gives none and the user states none;
#: each use is said in a warning ("assumed, not measured").
#: Position: the GPS SPS performance standard (4th ed., 2008) bounds the
#: horizontal error at 9 m 95 %, global average (a circular normal's 95 %
#: radius is 2.45 sigma: ~3.7 m 1-sigma per axis) for a standalone receiver;
#: 5 m leaves room for a poorer antenna or sky (an overstated sigma weights
#: the fixes less and fails the gate less; an understated one does both wrong).
DEFAULT_POS_SIGMA_M = 5.0
#: Velocity: a receiver's Doppler velocity is good to a few cm/s, and NMEA
#: rounds the speed to 0.1 kn (0.05 m/s) in many receivers: 0.1 m/s per axis.
DEFAULT_VEL_SIGMA_MPS = 0.1
#: Speed log: IMO resolution A.824(19) allows 2 % of the speed or 0.2 kn
#: (0.1 m/s), whichever is more: 0.1 m/s, the bound up to 10 kn.
DEFAULT_LOG_SIGMA_MPS = 0.1

#: The sentence types read, per kind of reference.
SENTENCES = {"gnss_pos": ("GGA", "GST"), "gnss_vel": ("RMC", "VTG"), "speed_log": ("VHW", "VBW")}
_TIMED = ("GGA", "RMC", "GST", "ZDA")
_READ = ("GGA", "RMC", "VTG", "GST", "ZDA", "VHW", "VBW")
_DATE_OF = ("RMC", "ZDA")

_NS = 10 ** 9
_DAY_NS = 86400 * _NS
_HALF_DAY_NS = _DAY_NS // 2
_HEAD_LINES = 10         #: non-blank lines a file's NMEA is told by

_NUMBER = re.compile(r"[+-]?(?:\d+(?:\.\d*)?|\.\d+)")
_TIME = re.compile(r"(\d\d)(\d\d)(\d\d)(?:\.(\d{0,9}))?")
_ANGLE = re.compile(r"(\d{1,3})(\d\d(?:\.\d*)?)")
_ADDRESS = re.compile(r"[A-Z0-9]{2}[A-Z]{3}")
_HEX2 = re.compile(r"[0-9A-Fa-f]{2}")
_UTC = re.compile(r"(\d{4})-(\d\d)-(\d\d)[T ](\d\d):(\d\d):(\d\d)(?:\.(\d{1,9}))?"
                  r"(Z|[+-]\d\d:\d\d)?")


class NmeaError(ValueError):
    """A file that cannot give references: one line naming it."""


class _Bad(Exception):
    """A sentence whose fields do not parse (the reason)."""


@dataclass
class NmeaRefs:
    """What `read_nmea` read: ``refs`` (REF_DTYPE, sorted by tick, stable),
    ``warnings`` (one line each, naming the file) and ``facts`` (counts:
    sentences by type, records by kind, what was skipped and why, the
    sigmas' sources, the UTC span)."""
    refs: np.ndarray
    warnings: list = field(default_factory=list)
    facts: dict = field(default_factory=dict)


# ---------------------------------------------------------------------------
# Sentences, times
# ---------------------------------------------------------------------------
def checksum(body):
    """The NMEA checksum of ``body`` (the characters between ``$`` or ``!``
    and ``*``): their XOR, an int 0..255; -1 for a body that is not ASCII
    (no checksum matches it)."""
    if not body.isascii():
        return -1
    b = body.encode("ascii")
    x, n = int.from_bytes(b, "little"), len(b)
    while n > 1:                 # fold the halves: the XOR of all bytes in log2(n) steps
        h = (n + 1) // 2
        x = (x & ((1 << (8 * h)) - 1)) ^ (x >> (8 * h))
        n = h
    return x


def sentence(body, start="$"):
    """``body`` framed as a sentence: ``$body*hh`` (two upper-case hex digits)."""
    return f"{start}{body}*{checksum(body):02X}"


def parse_utc(text):
    """``"2026-12-05T10:00:00.00"`` (a space for the T; a trailing ``Z`` or
    ``+hh:mm``/``-hh:mm`` offset; up to 9 decimals) -> nanoseconds since
    0001-01-01T00:00:00 UTC (proleptic Gregorian), exact. ValueError saying
    what is wrong."""
    m = _UTC.fullmatch(text.strip()) if isinstance(text, str) else None
    if m is None:
        raise ValueError(f"{text!r} is not a UTC date and time: write it as YYYY-MM-DDThh:mm:ss[.sss] "
                         "(e.g. 2026-12-05T10:00:00.00)")
    y, mo, d, hh, mm, ss = (int(g) for g in m.groups()[:6])
    try:
        day = datetime.date(y, mo, d).toordinal() - 1
    except ValueError as exc:
        raise ValueError(f"{text!r}: {exc}") from None
    if hh > 23 or mm > 59 or ss > 60:
        raise ValueError(f"{text!r}: the time of day {hh:02d}:{mm:02d}:{ss:02d} is not one")
    frac = m.group(7) or ""
    ns = (day * 86400 + hh * 3600 + mm * 60 + ss) * _NS + int(frac.ljust(9, "0") or 0)
    zone = m.group(8)
    if zone and zone != "Z":
        zh, zm = int(zone[1:3]), int(zone[4:6])
        if zh > 14 or zm > 59:
            raise ValueError(f"{text!r}: {zone} is not a time zone offset")
        ns -= (1 if zone[0] == "+" else -1) * (zh * 3600 + zm * 60) * _NS
    return ns


def format_utc(ns, decimals=2):
    """Nanoseconds of `parse_utc` -> ``"YYYY-MM-DDThh:mm:ss.ss"`` (``decimals``
    of a second, truncated)."""
    day, rest = divmod(int(ns), _DAY_NS)
    date = datetime.date.fromordinal(day + 1)
    s, frac = divmod(rest, _NS)
    text = f"{date.isoformat()}T{s // 3600:02d}:{s % 3600 // 60:02d}:{s % 60:02d}"
    if decimals:
        text += "." + f"{frac:09d}"[:decimals]
    return text


def looks_like_nmea(text):
    """Whether text is NMEA 0183: one of its first non-blank lines begins
    with ``$`` or ``!`` (a logger started mid-sentence leaves a partial
    first line)."""
    n = 0
    for line in text.splitlines():
        s = line.strip()
        if not s:
            continue
        if s[0] in "$!":
            return True
        n += 1
        if n >= _HEAD_LINES:
            break
    return False


def _read_text(path, name):
    """The file's text (decompressed when gzip/xz/bzip2, as the logs'
    `_read_bytes`), or NmeaError."""
    try:
        raw = _read_bytes(path, name)
    except LogError as exc:             # a broken compressed stream
        raise NmeaError(str(exc)) from None
    if b"\x00" in raw[:1 << 16]:
        raise NmeaError(f"{name}: not a text file (NUL bytes): NMEA 0183 is lines of ASCII text")
    return raw.removeprefix(b"\xef\xbb\xbf").decode("ascii", errors="replace")    # a UTF-8 BOM: not a byte of it


def is_nmea(path):
    """Whether the file at ``path`` (compressed or not) `looks_like_nmea`,
    told by its first 64 KiB. OSError when it cannot be read."""
    comp, opener = _opener(path)
    with opener(path, "rb") as f:
        try:
            head = f.read(1 << 16)
        except (EOFError, ValueError, lzma.LZMAError):       # a broken stream: read_nmea names it
            return comp is not None
    return b"\x00" not in head and looks_like_nmea(head.removeprefix(b"\xef\xbb\xbf").decode("ascii", errors="replace"))


# ---------------------------------------------------------------------------
# Fields
# ---------------------------------------------------------------------------
def _num(text, what):
    if not _NUMBER.fullmatch(text):
        raise _Bad(f"{what} {text!r} is not a number")
    return float(text)


def _tod(text):
    """hhmmss[.s...] -> nanoseconds of the day."""
    m = _TIME.fullmatch(text)
    if m is None:
        raise _Bad(f"time {text!r} is not hhmmss.ss")
    hh, mm, ss = int(m.group(1)), int(m.group(2)), int(m.group(3))
    if hh > 23 or mm > 59 or ss > 60:      # 60: a leap second
        raise _Bad(f"time {text!r} is not a time of day")
    return (hh * 3600 + mm * 60 + ss) * _NS + int((m.group(4) or "").ljust(9, "0") or 0)


def _angle(text, hemi, lat):
    """(d)ddmm.mmmm with its hemisphere -> rad."""
    what = "latitude" if lat else "longitude"
    m = _ANGLE.fullmatch(text)
    if m is None:
        raise _Bad(f"{what} {text!r} is not {'ddmm.mmmm' if lat else 'dddmm.mmmm'}")
    deg, minutes = int(m.group(1)), float(m.group(2))
    if minutes >= 60.0 or deg + minutes / 60.0 > (90.0 if lat else 180.0):
        raise _Bad(f"{what} {text!r} is not an angle (minutes below 60, within +-{90 if lat else 180} deg)")
    signs = ("N", "S") if lat else ("E", "W")
    if hemi not in signs:
        raise _Bad(f"{what} hemisphere {hemi!r} is not {signs[0]} or {signs[1]}")
    x = (deg + minutes / 60.0) * DEG_TO_RAD
    return x if hemi == signs[0] else -x


def _date_ddmmyy(text):
    if not re.fullmatch(r"\d{6}", text):
        raise _Bad(f"date {text!r} is not ddmmyy")
    d, mo, yy = int(text[:2]), int(text[2:4]), int(text[4:])
    try:   # a two-digit year: 1980 (GPS time's start) to 2079
        return datetime.date(2000 + yy if yy < 80 else 1900 + yy, mo, d).toordinal() - 1
    except ValueError:
        raise _Bad(f"date {text!r} is not a date") from None


def _need(f, n, kind):
    if len(f) < n:
        raise _Bad(f"{len(f)} fields, {kind} has {n}")


def _speed(kn, kn_unit, kmh, kmh_unit, what):
    """The speed of a knots / km/h field pair [m/s], or None when both are empty."""
    if kn != "":
        if kn_unit != "N":
            raise _Bad(f"{what} unit {kn_unit!r} is not N (knots)")
        return _num(kn, what) * KNOT_MPS
    if kmh != "":
        if kmh_unit != "K":
            raise _Bad(f"{what} unit {kmh_unit!r} is not K (km/h)")
        return _num(kmh, what) * KMH_MPS
    return None


def _course_velocity(sog, cog_text):
    """(east, north) [m/s] of a speed [m/s] and a course over ground text
    [deg true]; None when the course is empty at a speed that is not 0."""
    if cog_text == "":
        return (0.0, 0.0) if sog == 0.0 else None
    cog = _num(cog_text, "course") * DEG_TO_RAD
    return sog * math.sin(cog), sog * math.cos(cog)


_NOT_MEASURED = {"0": "no fix (quality 0)", "6": "estimated (quality 6)", "7": "manual input (quality 7)",
                 "8": "simulated (quality 8)"}
_MODE_NOT_MEASURED = {"N": "not valid (mode N)", "E": "estimated (mode E)", "M": "manual input (mode M)",
                      "S": "simulated (mode S)"}


# ---------------------------------------------------------------------------
# Reading
# ---------------------------------------------------------------------------
class _Lines:
    """Counts of lines of one category with the first line number."""

    def __init__(self):
        self.n, self.first, self.why = 0, None, None

    def add(self, lineno, why=None):
        self.n += 1
        if self.first is None:
            self.first, self.why = lineno, why


def _plural(n, one, many=None):
    return f"{n} {one if n == 1 else (many or one + 's')}"


def read_nmea(path, utc_start, tick_hz, kinds=("gnss_pos", "gnss_vel", "speed_log"), pos_sigma_m=None,
              vel_sigma_mps=None, log_sigma_mps=None, name=None, option_names=None):
    """The references of an NMEA 0183 file (module docstring) on the IMU
    log's clock -> `NmeaRefs`.

    ``utc_start``: the UTC time of the log's tick 0 (`parse_utc` text or
    its nanoseconds); ``tick_hz`` the log's rate (an int). ``kinds``: the
    kinds to read (others' sentences are counted, not used).
    ``pos_sigma_m``: the position sigma of a fix without a GST of its epoch
    (E, N, U alike); ``vel_sigma_mps``: per axis of a velocity;
    ``log_sigma_mps``: of a speed-log speed. None: the DEFAULT_* value,
    said in a warning as assumed. ``name``: the file as messages name it
    (default the path); ``option_names``: how messages name the arguments
    (a dict of utc_start, pos_sigma, vel_sigma, log_sigma: a command line's
    option names). NmeaError for what is refused."""
    name = name or os.fspath(path)
    opt = dict(utc_start="utc_start", pos_sigma="pos_sigma_m", vel_sigma="vel_sigma_mps",
               log_sigma="log_sigma_mps")
    opt.update(option_names or {})
    kinds = tuple(kinds)
    for k in kinds:
        if k not in SENTENCES:
            raise ValueError(f"kinds: {k!r} is not one of {', '.join(SENTENCES)}")
    start = parse_utc(utc_start) if isinstance(utc_start, str) else int(utc_start)
    if not (isinstance(tick_hz, (int, np.integer)) and tick_hz > 0):
        raise ValueError(f"tick_hz: {tick_hz!r} must be a whole number of Hz above 0")
    sig = {}
    for key, value, default, unit in (("pos_sigma", pos_sigma_m, DEFAULT_POS_SIGMA_M, "m"),
                                      ("vel_sigma", vel_sigma_mps, DEFAULT_VEL_SIGMA_MPS, "m/s"),
                                      ("log_sigma", log_sigma_mps, DEFAULT_LOG_SIGMA_MPS, "m/s")):
        if value is not None and not (math.isfinite(value) and value > 0.0):
            raise NmeaError(f"{opt[key]}: {value!r} {unit}: a sigma must be finite and more than 0 {unit}")
        sig[key] = (float(value), True) if value is not None else (default, False)

    text = _read_text(path, name)
    if not looks_like_nmea(text):
        raise NmeaError(f"{name}: not NMEA 0183 (none of its first lines begins with $ or !)")

    counts, ignored = {}, {}
    bad_sum, not_sentence, malformed = _Lines(), _Lines(), _Lines()
    skipped = {}                       # reason -> _Lines (fixes that are not measurements)
    no_checksum = 0
    pos, gst, rmc, vtg, speed = [], {}, [], [], []
    before_time = _Lines()
    no_geoid, no_course = _Lines(), _Lines()
    timed_epochs = []

    lines = text.splitlines()
    timeline = _Timeline(start, _first_dated(lines))
    for lineno, raw in enumerate(lines, 1):
        line = raw.strip()
        if not line:
            continue
        what, addr, f = _frame(line)
        if what == "not a sentence":
            not_sentence.add(lineno)
            continue
        if what == "bad checksum":
            bad_sum.add(lineno)
            continue
        no_checksum += what == "no checksum"
        if line[0] == "!" or addr.startswith("P"):        # encapsulated (AIS) or proprietary
            key = addr[2:] if line[0] == "!" and len(addr) == 5 else addr
            ignored[key or "?"] = ignored.get(key or "?", 0) + 1
            continue
        if not _ADDRESS.fullmatch(addr):
            not_sentence.add(lineno)
            continue
        talker, kind = addr[:2], addr[2:]
        if kind not in _READ:
            ignored[kind] = ignored.get(kind, 0) + 1
            continue
        counts[kind] = counts.get(kind, 0) + 1
        try:
            if kind == "GGA":
                _need(f, 14, kind)
                q = f[5]
                if q == "" or q in _NOT_MEASURED:
                    why = _NOT_MEASURED.get(q, "no fix (quality empty)")
                    skipped.setdefault(f"GGA {why}", _Lines()).add(lineno)
                    _keep_time(timeline, timed_epochs, f[0], None, lineno)
                    continue
                if len(q) != 1 or q not in "0123456789":
                    raise _Bad(f"fix quality {q!r} is not a digit")
                tod = _tod(f[0])
                lat, lon = _angle(f[1], f[2], True), _angle(f[3], f[4], False)
                alt = _num(f[8], "altitude")
                if f[9] != "M":
                    raise _Bad(f"altitude unit {f[9]!r} is not M")
                if f[10] == "":
                    no_geoid.add(lineno)
                    sep = 0.0
                else:
                    sep = _num(f[10], "geoid separation")
                    if f[11] != "M":
                        raise _Bad(f"geoid separation unit {f[11]!r} is not M")
                t = timeline.at(tod, None, lineno)
                timed_epochs.append(t)
                pos.append((t, lat, lon, alt + sep, lineno, talker))
            elif kind == "RMC":
                _need(f, 11, kind)
                why = _rmc_not_measured(f)
                if why is not None:
                    skipped.setdefault(why, _Lines()).add(lineno)
                    _keep_time(timeline, timed_epochs, f[0], None, lineno)
                    continue
                tod = _tod(f[0])
                date = _date_ddmmyy(f[8])
                sog = _num(f[6], "speed over ground") * KNOT_MPS
                v = _course_velocity(sog, f[7])
                t = timeline.at(tod, date, lineno)
                timed_epochs.append(t)
                if v is None:
                    no_course.add(lineno)
                    continue
                rmc.append((t, v[0], v[1], lineno, talker))
            elif kind == "VTG":
                _need(f, 8, kind)
                if len(f) > 8 and f[8] in _MODE_NOT_MEASURED:
                    skipped.setdefault(f"VTG {_MODE_NOT_MEASURED[f[8]]}", _Lines()).add(lineno)
                    continue
                if f[0] != "" and f[1] != "T":
                    raise _Bad(f"course reference {f[1]!r} is not T (true)")
                sog = _speed(f[4], f[5], f[6], f[7], "speed over ground")
                if sog is None:
                    raise _Bad("no speed")
                v = _course_velocity(sog, f[0])
                if v is None:
                    no_course.add(lineno)
                    continue
                if timeline.last is None:
                    before_time.add(lineno)
                    continue
                vtg.append((timeline.last, v[0], v[1], lineno, talker))
            elif kind == "GST":
                _need(f, 8, kind)
                tod = _tod(f[0])
                t = timeline.at(tod, None, lineno)
                timed_epochs.append(t)
                if f[5] == "" or f[6] == "":
                    skipped.setdefault("GST without latitude and longitude sigmas", _Lines()).add(lineno)
                    continue
                s_n, s_e = _num(f[5], "latitude sigma"), _num(f[6], "longitude sigma")
                s_u = _num(f[7], "altitude sigma") if f[7] != "" else None
                if not (s_n > 0.0 and s_e > 0.0 and (s_u is None or s_u > 0.0)):
                    raise _Bad(f"sigmas {f[5]}, {f[6]}, {f[7]} must be more than 0")
                gst.setdefault(t, (s_e, s_n, s_u))
            elif kind == "ZDA":
                _need(f, 4, kind)
                timed_epochs.append(timeline.at(_tod(f[0]), _zda_date(f), lineno))
            elif kind in ("VHW", "VBW"):
                if kind == "VHW":
                    _need(f, 8, kind)
                    v = _speed(f[4], f[5], f[6], f[7], "water speed")
                    if v is None:
                        raise _Bad("no water speed")
                else:
                    _need(f, 6, kind)
                    if f[2] != "A":
                        skipped.setdefault("VBW water speed not valid (status V)", _Lines()).add(lineno)
                        continue
                    v = _num(f[0], "longitudinal water speed") * KNOT_MPS
                if timeline.last is None:
                    before_time.add(lineno)
                    continue
                speed.append((timeline.last, v, lineno, kind))
        except _Bad as exc:
            malformed.add(lineno, f"{kind}: {exc}")
            continue

    # the references of the kinds asked for: (kind, times, values, sigmas, sigma sources)
    warn, facts = [], dict(format="NMEA 0183", sentences=counts, ignored=ignored)
    parts, taken, late = [], {}, []           # late: warnings after those of the drop
    if "gnss_pos" in kinds and pos:
        rows, dup = _first_per_epoch(pos)
        s_user, given = sig["pos_sigma"]
        value, sigma, src = [], [], []
        for t, lat, lon, h, _, _ in rows:
            g = gst.get(t)
            if g is not None:
                sigma.append((g[0], g[1], g[2] if g[2] is not None else max(g[0], g[1])))
                src.append("GST")
            else:
                sigma.append((s_user, s_user, s_user))
                src.append(opt["pos_sigma"] if given else "assumed")
            value.append((lat, lon, h))
        parts.append((KIND_GNSS_POS, [r[0] for r in rows], value, sigma, src))
        taken["gnss_pos"] = "GGA"
        _dup_warning(late, name, "GGA", dup)
    if "gnss_vel" in kinds and (rmc or vtg):
        what, rows = ("RMC", rmc) if rmc else ("VTG", vtg)
        rows, dup = _first_per_epoch(rows)
        s, given = sig["vel_sigma"]
        parts.append((KIND_GNSS_VEL, [r[0] for r in rows], [(r[1], r[2], 0.0) for r in rows],
                      [(s, s, 0.0)] * len(rows), [opt["vel_sigma"] if given else "assumed"] * len(rows)))
        taken["gnss_vel"] = what
        if rmc and vtg:
            facts["vtg_not_used"] = len(vtg)
        _dup_warning(late, name, what, dup)
        if what == "VTG":
            _untimed_warning(late, name, "VTG", len(vtg), timed_epochs)
    if "speed_log" in kinds and speed:
        rows, dup = _first_per_epoch(speed)
        s, given = sig["log_sigma"]
        z = 0.0
        parts.append((KIND_SPEED_LOG, [r[0] for r in rows], [(r[1], z, z) for r in rows],
                      [(s, z, z)] * len(rows), [opt["log_sigma"] if given else "assumed"] * len(rows)))
        what = "/".join(sorted({r[3] for r in speed}))
        taken["speed_log"] = what
        if dup.n:
            late.append(f"{name}: {_plural(dup.n, 'speed')} of the same epoch as the one before (more "
                        f"{what} than timed sentences; the first at line {dup.first}): the first of each "
                        "epoch used")
        _untimed_warning(late, name, what, len(speed), timed_epochs)

    for key, kind_name, what in (("pos_sigma", "gnss_pos", "GGA fix"), ("vel_sigma", "gnss_vel", "RMC or VTG velocity"),
                                 ("log_sigma", "speed_log", "VHW or VBW speed")):
        if sig[key][1] and kind_name in kinds and kind_name not in taken:
            late.append(f"{name}: {opt[key]} not used: the file has no usable {what}")

    if not parts:
        want = sorted({s for k in kinds for s in SENTENCES[k] if s != "GST"})
        found = ", ".join(f"{n} {k}" for k, n in sorted({**counts, **ignored}.items())) or "none"
        why = []
        if bad_sum.n:
            why.append(f"{_plural(bad_sum.n, 'sentence')} with a bad checksum")
        if malformed.n:
            why.append(f"{_plural(malformed.n, 'sentence')} whose fields do not parse (line {malformed.first}: "
                       f"{malformed.why})")
        for reason, lines_ in skipped.items():
            why.append(f"{lines_.n} {reason}")
        if before_time.n:
            why.append(f"{before_time.n} without a time (no GGA, RMC, GST or ZDA before them)")
        if no_course.n:
            why.append(f"{no_course.n} without a course")
        raise NmeaError(f"{name}: no usable {', '.join(want[:-1])}{' or ' if len(want) > 1 else ''}{want[-1]} "
                        f"sentence (sentences found: {found}"
                        + (f"; skipped: {'; '.join(why)}" if why else "") + ")")

    # ticks on the log's clock, sorted (stable), those before the log dropped
    kind_arr, tick, value, sigma, src = [], [], [], [], []
    for k, ts, v, sg, sr in parts:
        kind_arr.append(np.full(len(ts), k, np.int32))
        tick.append(np.array([(2 * (t - start) * tick_hz + _NS) // (2 * _NS) for t in ts], dtype=np.int64))
        value.append(np.array(v, float).reshape(-1, 3))
        sigma.append(np.array(sg, float).reshape(-1, 3))
        src.append(np.array(sr, dtype=object))
    kind_arr, tick, value, sigma, src = (np.concatenate(a) for a in (kind_arr, tick, value, sigma, src))
    t_all = np.concatenate([np.array(p[1], dtype=object) for p in parts])   # Python ints: ns overflow int64
    order = np.argsort(tick, kind="stable")
    kind_arr, tick, value, sigma, src, t_all = (a[order] for a in (kind_arr, tick, value, sigma, src, t_all))
    facts["utc_span"] = [format_utc(min(t_all)), format_utc(max(t_all))]
    before = tick < 0
    n_before = int(np.count_nonzero(before))
    if n_before == len(tick):
        raise NmeaError(f"{name}: all its {len(tick)} references (UTC {facts['utc_span'][0]} .. "
                        f"{facts['utc_span'][1]}) lie before the log's start ({opt['utc_start']} "
                        f"{format_utc(start)}): nothing to use; check the date and time of {opt['utc_start']}")
    if n_before:
        warn.append(f"{name} covers only part of the log: {n_before} of its {len(tick)} references "
                    f"(UTC {format_utc(min(t_all))} .. {format_utc(max(t_all[before]))}) lie before the log's "
                    f"start ({format_utc(start)}) and were dropped")
    keep = ~before
    kind_arr, tick, value, sigma, src = (a[keep] for a in (kind_arr, tick, value, sigma, src))
    refs = np.zeros(len(tick), dtype=REF_DTYPE)
    refs["kind"], refs["tick"], refs["value"], refs["sigma"] = kind_arr, tick, value, sigma

    # where the sigmas of the references kept come from; the assumed said
    sigma_src = {}
    for k, key, unit, what in ((KIND_GNSS_POS, "pos_sigma", "m", "position"),
                               (KIND_GNSS_VEL, "vel_sigma", "m/s", "velocity"),
                               (KIND_SPEED_LOG, "log_sigma", "m/s", "speed-log")):
        mine = src[kind_arr == k]
        if not len(mine):
            continue
        name_k = KIND_NAMES[k]
        other = opt[key] if sig[key][1] else "assumed"        # the user's sigma, or the default
        sigma_src[name_k] = {w: int(np.count_nonzero(mine == w))
                             for w in (("GST", other) if k == KIND_GNSS_POS else (other,))}
        n_assumed = int(np.count_nonzero(mine == "assumed"))
        s_value = sig[key][0]
        if n_assumed and k == KIND_GNSS_POS:
            warn.append(f"{name}: position sigma {s_value:g} m assumed, not measured, for {n_assumed} of the "
                        f"{len(mine)} fixes (no GST of their epoch; give {opt[key]} to state it)")
        elif n_assumed:
            warn.append(f"{name}: {what} sigma {s_value:g} {unit} assumed, not measured ({taken[name_k]} "
                        f"carries none; give {opt[key]} to state it)")
        if k == KIND_GNSS_POS and sig[key][1] and not np.any(mine == opt[key]):
            warn.append(f"{name}: {opt[key]} {s_value:g} m not used: every fix had the sigmas of its GST")
    warn.extend(late)

    # what was skipped, in the warnings with the first line
    if bad_sum.n:
        warn.append(f"{name}: {_plural(bad_sum.n, 'sentence')} with a bad checksum skipped (the first at line "
                    f"{bad_sum.first})")
    if malformed.n:
        warn.append(f"{name}: {_plural(malformed.n, 'sentence')} whose fields do not parse skipped (the first "
                    f"at line {malformed.first}: {malformed.why})")
    if not_sentence.n:
        warn.append(f"{name}: {_plural(not_sentence.n, 'line')} that {'is' if not_sentence.n == 1 else 'are'} "
                    f"not an NMEA sentence skipped (the first at line {not_sentence.first})")
    for reason, lines_ in skipped.items():
        if reason.split()[0] in {s for k in kinds for s in SENTENCES[k]}:
            warn.append(f"{name}: {lines_.n} {reason} skipped (the first at line {lines_.first})")
    if before_time.n:
        warn.append(f"{name}: {before_time.n} untimed sentences before the first timed one (GGA, RMC, "
                    f"GST, ZDA) skipped (the first at line {before_time.first})")
    if no_course.n and "gnss_vel" in kinds:
        warn.append(f"{name}: {no_course.n} velocities without a course over ground at a speed above 0 "
                    f"skipped (the first at line {no_course.first})")
    if no_geoid.n and "gnss_pos" in kinds:
        warn.append(f"{name}: {no_geoid.n} GGA without the geoid separation (the first at line "
                    f"{no_geoid.first}): their height is above the geoid, not the ellipsoid (the firmware "
                    "holds its vertical: the height is not used)")
    if timeline.back.n:
        warn.append(f"{name}: the time goes back {_plural(timeline.back.n, 'time')} (the first at line "
                    f"{timeline.back.first}): the references were sorted by time")

    used = {KIND_NAMES[k]: int(np.count_nonzero(refs["kind"] == k)) for k in np.unique(refs["kind"])}
    facts.update(references=used, sentences_used=taken, sigmas=sigma_src, before_log=n_before,
                 midnights=timeline.midnights,
                 skipped={**({"bad checksum": bad_sum.n} if bad_sum.n else {}),
                          **({"fields do not parse": malformed.n} if malformed.n else {}),
                          **({"not a sentence": not_sentence.n} if not_sentence.n else {}),
                          **{k: v.n for k, v in skipped.items()}},
                 without_checksum=no_checksum)
    return NmeaRefs(refs, warn, facts)


def _frame(line):
    """(what, address, fields) of a line: what is "ok", "no checksum",
    "bad checksum" or "not a sentence" (then address and fields None)."""
    if line[0] not in "$!":
        return "not a sentence", None, None
    star = line.rfind("*")
    what = "ok"
    if star >= 0:
        body, cs = line[1:star], line[star + 1:]
        if not _HEX2.fullmatch(cs) or int(cs, 16) != checksum(body):
            return "bad checksum", None, None
    else:
        body, what = line[1:], "no checksum"
    f = body.split(",")
    return what, f[0], f[1:]


def _rmc_not_measured(f):
    """Why an RMC is not a measurement (status V; mode N, E, M, S), or None."""
    if f[1] != "A":
        if f[1] != "V":
            raise _Bad(f"status {f[1]!r} is not A or V")
        return "RMC not valid (status V)"
    if len(f) > 11 and f[11] in _MODE_NOT_MEASURED:
        return f"RMC {_MODE_NOT_MEASURED[f[11]]}"
    return None


def _zda_date(f):
    try:
        return datetime.date(int(f[3]), int(f[2]), int(f[1])).toordinal() - 1
    except ValueError:
        raise _Bad(f"date {f[1]!r}, {f[2]!r}, {f[3]!r} is not a day, month and year") from None


def _first_dated(lines):
    """The time [ns] of the file's first dated sentence (a valid RMC, a
    ZDA), or None: the undated times before it are put within 12 h of it."""
    for raw in lines:
        line = raw.strip()
        if line[3:6] not in ("RMC", "ZDA"):
            continue
        what, addr, f = _frame(line)
        if what in ("bad checksum", "not a sentence") or line[0] != "$" or not _ADDRESS.fullmatch(addr):
            continue
        try:
            if addr[2:] == "RMC":
                _need(f, 11, "RMC")
                if _rmc_not_measured(f) is None:
                    return _date_ddmmyy(f[8]) * _DAY_NS + _tod(f[0])
            else:
                _need(f, 4, "ZDA")
                return _zda_date(f) * _DAY_NS + _tod(f[0])
        except _Bad:
            continue
    return None


def _keep_time(timeline, epochs, text, date, lineno):
    """The time of a sentence that gives no reference (no fix, not valid)
    still times the untimed sentences after it, when it parses."""
    if text:
        try:
            epochs.append(timeline.at(_tod(text), date, lineno))
        except _Bad:
            pass


class _Timeline:
    """UTC times of day -> nanoseconds since 0001-01-01 (module docstring)."""

    def __init__(self, start, anchor=None):
        self.start, self.last, self.midnights, self.back = start, None, 0, _Lines()
        self.anchor = start if anchor is None else anchor       # the undated before the first date: near it

    def at(self, tod, date, lineno):
        if date is not None:
            t = date * _DAY_NS + tod
        else:
            ref = self.anchor if self.last is None else self.last
            t = (ref // _DAY_NS) * _DAY_NS + tod
            if ref - t > _HALF_DAY_NS:
                t += _DAY_NS
                self.midnights += self.last is not None
            elif t - ref > _HALF_DAY_NS:
                t -= _DAY_NS
        if self.last is not None and t < self.last:
            self.back.add(lineno)
        self.last = t
        return t


def _first_per_epoch(rows):
    """The first row of each epoch (row[0]); the rest counted (a _Lines with
    the talkers met)."""
    seen, out, dup = set(), [], _Lines()
    dup.talkers = set()
    for r in rows:
        if r[0] in seen:
            dup.add(r[-2])            # the line number; r[-1] the talker (or the sentence type)
            dup.talkers.add(r[-1])
            continue
        seen.add(r[0])
        out.append(r)
    return out, dup


def _dup_warning(warn, name, what, dup):
    if dup.n:
        warn.append(f"{name}: {_plural(dup.n, what)} of an epoch already given (talker "
                    f"{', '.join(sorted(dup.talkers))}; the first at line {dup.first}): two receivers in "
                    "one file? the first of each epoch used")


def _untimed_warning(warn, name, what, n, timed_epochs):
    ep = sorted(set(timed_epochs))          # Python ints: ns since year 1 overflow int64
    gap = max(b - a for a, b in zip(ep, ep[1:])) / _NS if len(ep) > 1 else None
    warn.append(f"{name}: {n} {what} carry no time: each took the time of the last timed sentence (GGA, RMC, "
                f"GST, ZDA) before it" + (f", up to {gap:g} s earlier (the longest interval between the file's "
                                          "timed epochs)" if gap is not None else ""))


# ---------------------------------------------------------------------------
# Writing
# ---------------------------------------------------------------------------
def _dm(x_rad, lat, decimals):
    """An angle [rad] as (d)ddmm.mmmm with ``decimals`` of a minute, and its hemisphere."""
    deg = abs(float(x_rad)) / DEG_TO_RAD
    scale = 10 ** decimals
    units = round(deg * 60.0 * scale)           # of 10^-decimals minute: the carry into degrees exact
    d, m = divmod(units, 60 * scale)
    mi, mf = divmod(m, scale)
    width = 2 if lat else 3
    text = f"{d:0{width}d}{mi:02d}" + (f".{mf:0{decimals}d}" if decimals else "")
    hemi = ("N" if x_rad >= 0 else "S") if lat else ("E" if x_rad >= 0 else "W")
    return text, hemi


def _fixed(x, decimals):
    text = f"{x:.{decimals}f}"
    return text[1:] if text.startswith("-") and float(text) == 0.0 else text


def write_nmea(path, refs, utc_start, tick_hz=100, talker="GP", log_talker="VM", minute_decimals=5,
               time_decimals=2, speed_decimals=3, course_decimals=2, sigma_decimals=3, height_decimals=3,
               geoid_separation_m=0.0):
    """Write reference records as NMEA 0183 (a receiver's file, as
    `read_nmea` reads it): per tick, in tick order, a GNSS_POS -> GGA
    (quality 1) and GST (its E, N, U sigmas as the longitude, latitude and
    altitude sigmas), a GNSS_VEL -> RMC (status A, mode A; the speed over
    ground and the course of its east and north components: up is lost;
    its position that of the GGA of the tick, or empty), a SPEED_LOG ->
    VHW (knots and km/h; a ZDA before it when no timed sentence has that
    tick's time). Lines end CR LF. ``utc_start`` as in `read_nmea`;
    ``geoid_separation_m`` the GGA's separation (the altitude written is
    the height less it). ``*_decimals``: digits written (minutes of arc,
    seconds, knots, degrees, metres). ``talker``: the GNSS sentences'
    (GP); ``log_talker``: the VHW's (VM: speed log, water, magnetic, an EM
    log). Other kinds, and a tick whose time is not a whole number of
    10^-time_decimals s, raise ValueError."""
    start = parse_utc(utc_start) if isinstance(utc_start, str) else int(utc_start)
    refs = np.asarray(getattr(refs, "refs", refs))
    if refs.dtype != REF_DTYPE:
        raise ValueError(f"write_nmea: expected REF_DTYPE records, got {refs.dtype}")
    refs = refs[np.argsort(refs["tick"], kind="stable")]
    other = sorted({KIND_NAMES.get(int(k), str(k)) for k in refs["kind"]}
                   - {"gnss_pos", "gnss_vel", "speed_log"})
    if other:
        raise ValueError(f"write_nmea: {', '.join(other)} references have no NMEA sentence here")
    step = 10 ** (9 - time_decimals)
    lines = []
    ticks = refs["tick"]
    bounds = np.flatnonzero(np.diff(ticks)) + 1
    for group in np.split(np.arange(len(refs)), bounds):
        if not len(group):
            continue
        tk = int(ticks[group[0]])
        num = tk * _NS
        if num % tick_hz:
            raise ValueError(f"write_nmea: tick {tk} at {tick_hz} Hz is not a whole number of ns")
        t = start + num // tick_hz
        if t % step:
            raise ValueError(f"write_nmea: tick {tk} at {tick_hz} Hz ({format_utc(t, 9)}) is not a whole "
                             f"number of 10^-{time_decimals} s: more time_decimals")
        day, tod = divmod(t, _DAY_NS)
        s, frac = divmod(tod, _NS)
        hms = f"{s // 3600:02d}{s % 3600 // 60:02d}{s % 60:02d}" + (
            f".{frac // step:0{time_decimals}d}" if time_decimals else "")
        date = datetime.date.fromordinal(day + 1)
        rs = refs[group]
        pos = rs[rs["kind"] == KIND_GNSS_POS]
        vel = rs[rs["kind"] == KIND_GNSS_VEL]
        log = rs[rs["kind"] == KIND_SPEED_LOG]
        for kind, rows in ((KIND_GNSS_POS, pos), (KIND_GNSS_VEL, vel), (KIND_SPEED_LOG, log)):
            if len(rows) > 1:
                raise ValueError(f"write_nmea: {len(rows)} {KIND_NAMES[kind]} references at tick {tk}: "
                                 "one a tick")
        latlon = ",,,"
        timed = False
        for p in pos[:1]:
            lat, ns = _dm(p["value"][0], True, minute_decimals)
            lon, ew = _dm(p["value"][1], False, minute_decimals)
            latlon = f"{lat},{ns},{lon},{ew}"
            alt = _fixed(float(p["value"][2]) - geoid_separation_m, height_decimals)
            lines.append(sentence(f"{talker}GGA,{hms},{latlon},1,08,1.0,{alt},M,"
                                  f"{_fixed(geoid_separation_m, height_decimals)},M,,"))
            se, sn, su = (_fixed(float(x), sigma_decimals) for x in p["sigma"])
            major, minor = (se, sn) if p["sigma"][0] >= p["sigma"][1] else (sn, se)
            orient = "90.0" if p["sigma"][0] > p["sigma"][1] else "0.0"
            lines.append(sentence(f"{talker}GST,{hms},,{major},{minor},{orient},{sn},{se},{su}"))
            timed = True
        for v in vel[:1]:
            ve, vn = float(v["value"][0]), float(v["value"][1])
            sog = math.hypot(ve, vn) / KNOT_MPS
            cog = math.degrees(math.atan2(ve, vn)) % 360.0
            cog_text = _fixed(cog, course_decimals)
            if float(cog_text) >= 360.0:
                cog_text = _fixed(0.0, course_decimals)
            lines.append(sentence(f"{talker}RMC,{hms},A,{latlon},{_fixed(sog, speed_decimals)},{cog_text},"
                                  f"{date.day:02d}{date.month:02d}{date.year % 100:02d},,,A"))
            timed = True
        for lg in log[:1]:
            if not timed:
                lines.append(sentence(f"{talker}ZDA,{hms},{date.day:02d},{date.month:02d},{date.year:04d},00,00"))
            kn = float(lg["value"][0]) / KNOT_MPS
            kmh = float(lg["value"][0]) / KMH_MPS
            lines.append(sentence(f"{log_talker}VHW,,T,,M,{_fixed(kn, speed_decimals)},N,"
                                  f"{_fixed(kmh, speed_decimals)},K"))
    with open(path, "w", encoding="ascii", newline="") as f:
        f.write("".join(line + "\r\n" for line in lines))
