"""A reference trajectory a replayed log is compared with (``pyins replay
--truth FILE``): a post-processed GNSS/INS solution, a survey of the pier, a
peer's output.

The file is text: an optional run of ``#`` or ``%`` comment lines, then a
header line naming the columns (comma- or whitespace-separated, in any
order), then one row per epoch, times strictly increasing::

    # t [s], on the log's clock
    t, lat_deg, lon_deg, height_m, heading_deg
    369300.00, 34.2460480, 108.9096640, 380.00, 90.80
    ...

``t`` (seconds, on the clock of the log's time column; for a log without
one, seconds from the start of its first sample), ``lat_deg`` and
``lon_deg`` are required; ``height_m`` and ``heading_deg`` (clockwise from
north) are optional. gzip/xz/bzip2-compressed files are read as they are.
Between epochs the track is interpolated linearly (longitude and heading
unwrapped first, so a track across 180 deg E or through north interpolates
the short way); records outside its time span are not compared, and the
replay says how many.
"""
from dataclasses import dataclass

import numpy as np

from pyins import logs, metrics
from pyins.sim.imu import wrap_pi_mod
from pyins.units import DEG_TO_RAD

__all__ = ["TruthTrack", "read_track", "COLUMNS"]

#: the columns a track may have: name -> (required, scale to SI)
COLUMNS = {"t": (True, 1.0), "lat_deg": (True, DEG_TO_RAD), "lon_deg": (True, DEG_TO_RAD),
           "height_m": (False, 1.0), "heading_deg": (False, DEG_TO_RAD)}


class TrackError(ValueError):
    """A track file that cannot be read, with the file and line named."""


@dataclass
class TruthTrack:
    path: str
    t: np.ndarray                 #: (N,) [s], strictly increasing
    lat_rad: np.ndarray           #: (N,)
    lon_rad: np.ndarray           #: (N,) unwrapped
    height_m: np.ndarray = None   #: (N,) or None
    heading_rad: np.ndarray = None  #: (N,) unwrapped, clockwise from north, or None

    def errors(self, t, lat_rad, lon_rad, heading_rad=None):
        """Errors of the positions (and headings) at times ``t`` against the
        track, for the times inside its span: (mask of those times, dict of
        time_s, north_m, east_m [, heading_rad]). North and east are the
        latitude and longitude differences on the track's radii of curvature
        (WGS-84, at its height, 0 when it gives none)."""
        t = np.asarray(t, dtype=float)
        inside = (t >= self.t[0]) & (t <= self.t[-1])
        ti = t[inside]
        lat_t = np.interp(ti, self.t, self.lat_rad)
        lon_t = np.interp(ti, self.t, self.lon_rad)
        h_t = np.interp(ti, self.t, self.height_m) if self.height_m is not None else np.zeros_like(ti)
        north, east = metrics.position_errors(np.asarray(lat_rad)[inside], np.asarray(lon_rad)[inside],
                                              lat_t, lon_t, h_t)
        out = dict(time_s=ti, north_m=north, east_m=east)
        if self.heading_rad is not None and heading_rad is not None:
            hd_t = np.interp(ti, self.t, self.heading_rad)
            out["heading_rad"] = wrap_pi_mod(np.asarray(heading_rad)[inside] - hd_t)
        return inside, out


def _split(line):
    return [x for x in line.replace(",", " ").split() if x]


def read_track(path):
    """The TruthTrack in ``path`` (see the module's docstring); TrackError
    naming the file and line for anything it cannot take."""
    name = str(path)
    header, rows, lines = None, [], []
    try:
        text = logs._read_bytes(path, name).decode("utf-8")
    except UnicodeDecodeError:
        raise TrackError(f"{name}: not UTF-8 text (a track is a text file with a header line)") from None
    for lineno, raw in enumerate(text.splitlines(), start=1):
        line = raw.strip()
        if not line or line[0] in "#%":
            continue
        tokens = _split(line)
        if header is None:
            header = tokens
            unknown = [c for c in header if c not in COLUMNS]
            missing = [c for c, (req, _) in COLUMNS.items() if req and c not in header]
            if unknown or missing or len(set(header)) != len(header):
                raise TrackError(
                    f"{name}: line {lineno}: the header names the columns, from {', '.join(COLUMNS)} "
                    f"(t, lat_deg and lon_deg required)"
                    + (f"; unknown: {', '.join(unknown)}" if unknown else "")
                    + (f"; missing: {', '.join(missing)}" if missing else "")
                    + ("; a column named twice" if len(set(header)) != len(header) else ""))
            continue
        if len(tokens) != len(header):
            raise TrackError(f"{name}: line {lineno}: {len(tokens)} values for {len(header)} columns")
        try:
            values = [float(x) for x in tokens]
        except ValueError:
            raise TrackError(f"{name}: line {lineno}: not a number in {line!r}") from None
        if not all(np.isfinite(values)):
            raise TrackError(f"{name}: line {lineno}: a value that is not finite")
        rows.append(values)
        lines.append(lineno)
    if header is None or len(rows) < 2:
        raise TrackError(f"{name}: a track needs a header line and at least two epochs "
                         f"({len(rows)} found)")
    a = np.array(rows)
    col = {c: a[:, header.index(c)] * COLUMNS[c][1] for c in header}
    steps = np.diff(col["t"])
    if np.any(steps <= 0.0):
        k = int(np.flatnonzero(steps <= 0.0)[0]) + 1
        raise TrackError(f"{name}: line {lines[k]}: time {col['t'][k]:g} s does not increase "
                         f"(after {col['t'][k - 1]:g} s)")
    lat = col["lat_deg"]
    if np.any(np.abs(lat) >= 0.5 * np.pi):
        k = int(np.flatnonzero(np.abs(lat) >= 0.5 * np.pi)[0])
        raise TrackError(f"{name}: line {lines[k]}: latitude {np.degrees(lat[k]):g} deg is not within (-90, 90)")
    return TruthTrack(path=name, t=col["t"], lat_rad=lat, lon_rad=np.unwrap(col["lon_deg"]),
                      height_m=col.get("height_m"),
                      heading_rad=np.unwrap(col["heading_deg"]) if "heading_deg" in col else None)
