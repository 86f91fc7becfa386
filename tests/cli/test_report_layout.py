"""report.html and its figures read right (docs/cli.md, "pyins report
RUNDIR"): a stopped
run and a run shortened with ``--hours`` are labelled and not judged
against the paper's full-length figures; the A_c/A_s panel only for a
scheme that steers by the flexible sums; the position error split north /
east and latitude / longitude; the page without horizontal scrolling at
1200 and 1400 px (in a real browser); every curve of a long run decimated
to a bounded number of points that keeps its peaks, with a zoom on a few
turntable cycles; a progress line for the phases after the firmware.

The figures are inspected as matplotlib draws them: `Figure.savefig` is
wrapped to note every axes' labels and every line's points."""
import html
import os
import re
import shutil
import subprocess

import matplotlib.figure
import numpy as np
import pytest

from pyins import __main__ as cli
from pyins import fil, report, run_scenario, rundir, scenario, units
from pyins.report.paper import paper_rows, span
from pyins.progress import Phases
from pyins.report import plotting
from pyins.report import run as run_report

#: three variants side by side; many short turntable cycles (a 5 s stop and
#: 20 deg/s: ~60 s a two-position cycle, 20 in the run) and records every
#: 0.1 s (12,000 a variant: more than a figure draws)
LAYOUT = """
name = "layout"
title = "report layout: a fixed IMU, two-position and flexible indexing"
duration = "1200 s"
seed = 1
record_every = "0.1 s"
[motion]
kind = "static"
lat = "34 deg"
lon = "108 deg"
height = "0 m"
heading = "30 deg"
[sensors]
preset = "seed003"
[indexing]
scheme = "none"
stop = "5 s"
rate = "20 deg/s"
[compare]
key = "indexing.scheme"
values = ["none", "two_position", "flexible"]
labels = ["fixed", "two-position", "flexible"]
[paper]
citation = "a bound made up for the test"
[[paper.figures]]
metric = "horizontal_error_max"
relation = "<"
value = "50 nmi"
variant = "flexible"
"""

#: one 1 h run (two 30 min firmware chunks: a stop after the first leaves a
#: partial run) with a bound it meets by far when it runs in full
BOUND = """
name = "bound"
title = "a static hour against a generous bound"
duration = "1 h"
seed = 2
record_every = "1 s"
[motion]
kind = "static"
lat = "34 deg"
lon = "108 deg"
height = "0 m"
heading = "0 deg"
[sensors]
preset = "seed003"
[paper]
citation = "a bound made up for the test"
[[paper.figures]]
metric = "horizontal_error_max"
relation = "<"
value = "50 nmi"
"""


@pytest.fixture
def drawn(monkeypatch):
    """file name -> [one dict per axes: title, ylabel, xlim, lines: [(label, x, y)]]
    of every figure saved while the test runs."""
    seen = {}
    save = matplotlib.figure.Figure.savefig

    def spy(fig, path, *args, **kwargs):
        seen[os.path.basename(str(path))] = [
            dict(title=a.get_title(), ylabel=a.get_ylabel(), xlim=a.get_xlim(),
                 lines=[(ln.get_label(), np.asarray(ln.get_xdata(), float), np.asarray(ln.get_ydata(), float))
                        for ln in a.get_lines()])
            for a in fig.axes]
        return save(fig, path, *args, **kwargs)
    monkeypatch.setattr(matplotlib.figure.Figure, "savefig", spy)
    return seen


def _run(tmp_path, text, name="run", overrides=None):
    scn = scenario.loads(text, source=str(tmp_path / "s.toml"))
    if overrides:
        scn = scn.with_overrides(overrides)
    out = tmp_path / name
    run_scenario.execute(scn, str(out))
    return out


def _paper_cells(page):
    """[(variant, ours, verdict)] of the rows of the 'Beside the paper' table."""
    table = page.split("Beside the paper", 1)[1].split("</table>", 1)[0]
    rows = re.findall(r"<tr><td>horizontal_error_max</td>(.*?)</tr>", html.unescape(table))
    return [tuple(re.findall(r"<td[^>]*>(.*?)</td>", r)[i] for i in (0, 2, 3)) for r in rows]


# ---------------------------------------------------------------------------
# Partial and shortened runs are not judged
# ---------------------------------------------------------------------------
def test_a_full_run_is_judged_and_a_stopped_one_is_labelled_not_judged(tmp_path):
    full = _run(tmp_path, BOUND, "full")
    page = open(report.render(str(full))).read()
    assert [c[2] for c in _paper_cells(page)] == ["within"]

    def stop_after_the_first_chunk(label):
        def progress(done, total):
            if done < total:
                raise KeyboardInterrupt
        return progress
    out = tmp_path / "stopped"
    with pytest.raises(KeyboardInterrupt):
        run_scenario.execute(scenario.loads(BOUND), str(out), progress=stop_after_the_first_chunk)
    page = open(report.render(str(out))).read()
    (variant, ours, verdict), = _paper_cells(page)
    assert ours.endswith(" nmi")                   # our figure is shown ...
    assert verdict not in ("within", "above") and verdict.startswith("not judged")
    # ... and why it is not judged: stopped after the first chunk (run_scenario's, the
    # smaller of fil.CHUNK_TICKS and the checkpoint interval: 16.7 min since 2026-12-06)
    first = min(fil.CHUNK_TICKS, int(round(run_scenario.CHECKPOINT_S / units.DT))) * units.DT
    assert f"stopped at {span(first)} of 1 h" in verdict
    assert "PARTIAL" in page


def test_a_shortened_run_is_labelled_and_not_judged_against_the_full_length_figure(tmp_path, capsys):
    path = tmp_path / "bound.toml"
    path.write_text(BOUND)
    out = tmp_path / "short"
    assert cli.main(["run", str(path), "--hours", "0.5", "--out", str(out)]) == 0
    said = capsys.readouterr().out
    line = next(ln for ln in said.splitlines() if "paper horizontal_error_max" in ln)
    assert "within" not in line and "above" not in line
    assert "not judged: run shortened to 30 min; the paper's figure is for the 1 h the scenario runs" in line
    page = (out / "report.html").read_text()
    (variant, ours, verdict), = _paper_cells(page)
    assert verdict.startswith("not judged: run shortened")
    assert "Run for 30 min; the scenario as written runs 1 h" in html.unescape(page)
    # --seed changes no length: judged as before
    summary = rundir.read_summary(str(_run(tmp_path, BOUND, "seeded", {"seed": 7})))
    assert [r["verdict"] for r in paper_rows(summary)] == ["within"]


# ---------------------------------------------------------------------------
# Panels where they mean something; north/east and latitude/longitude
# ---------------------------------------------------------------------------
def _sums_axes(figure):
    return [a for a in figure if a["ylabel"].startswith("A_c, A_s")]


def test_the_flexible_sums_panel_only_for_the_flexible_scheme(tmp_path, drawn):
    out = _run(tmp_path, LAYOUT)
    report.render(str(out))
    panel, = _sums_axes(drawn["table.png"])
    labels = {lab for lab, _, _ in panel["lines"]}
    assert labels == {"flexible: A_c", "flexible: A_s"}
    # the same run without the flexible scheme: no A_c/A_s panel at all
    drawn.clear()
    fixed_only = LAYOUT.replace('values = ["none", "two_position", "flexible"]', 'values = ["none", "two_position"]')
    fixed_only = fixed_only.replace('labels = ["fixed", "two-position", "flexible"]', 'labels = ["fixed", "flexible"]')
    out = _run(tmp_path, fixed_only, "two")   # a two-position scheme, labelled "flexible" to mislead
    page = open(report.render(str(out))).read()
    assert _sums_axes(drawn["table.png"]) == []
    assert "A_c" not in page
    ylabels = " ".join(a["ylabel"] for a in drawn["table.png"])
    assert "table angle" in ylabels and "IMU yaw" in ylabels


def test_north_east_latitude_longitude_errors_in_the_table_and_the_figure(tmp_path, drawn):
    out = _run(tmp_path, LAYOUT)
    page = html.unescape(open(report.render(str(out))).read())
    summary, series = run_report.load(str(out))
    for name, key in (("north error", "north_m"), ("east error", "east_m")):
        row = re.search(rf"<code>{name}</code></td>(.*?)</tr>", page).group(1)
        cells = re.findall(r"<td>(.*?)</td>", row)
        assert len(cells) == 3
        # final / largest |value|, in m here, equal to the series
        s = series["fixed"][key]
        assert cells[0] == f"{s[-1]:.4g} / {np.abs(s).max():.4g} m"
    for name in ("latitude error", "longitude error"):
        row = re.search(rf"<code>{name}</code></td>(.*?)</tr>", page).group(1)
        assert all(c.endswith("arcsec") for c in re.findall(r"<td>(.*?)</td>", row))
    ylabels = [a["ylabel"] for a in drawn["errors.png"]]
    for word in ("north position", "east position", "latitude", "longitude"):
        assert any(word in y for y in ylabels), (word, ylabels)
    # the latitude error is the north error over the meridian radius
    dlat, _ = run_report.latlon_errors(series["fixed"])
    assert np.allclose(dlat * 6.3e6, series["fixed"]["north_m"], rtol=0.01)


def test_an_alignment_only_run_has_no_position_panels(tmp_path, drawn):
    """The fine alignment holds the site and zero velocity: position and
    velocity panels would be flat lines at zero."""
    scn = scenario.load("seed001_fine5").with_overrides({"duration": "120 s", "firmware.fine_time": "120 s"})
    out = tmp_path / "fine"
    run_scenario.execute(scn, str(out))
    page = html.unescape(open(report.render(str(out))).read())
    ylabels = [a["ylabel"] for a in drawn["errors.png"]]
    assert len(ylabels) == 2 and "level" in ylabels[0] and "heading" in ylabels[1]
    assert "<code>north error</code>" not in page and "<code>level_error_final</code>" in page
    assert "alignment.png" in drawn


# ---------------------------------------------------------------------------
# The page reads at 1200-1400 px
# ---------------------------------------------------------------------------
#: seven variants with long labels and a paper figure with a long note: the
#: old single-row results table needed ~1900 px
WIDE = """
name = "wide"
title = "seven seeds <script>alert(1)</script> & a 'quote'"
duration = "60 s"
record_every = "1 s"
[motion]
kind = "static"
lat = "34 deg"
lon = "108 deg"
height = "0 m"
heading = "0 deg"
[sensors]
preset = "seed003"
[compare]
key = "seed"
values = [1, 2, 3, 4, 5, 6, 7]
labels = ["seed one, a long label", "seed two, a long label", "seed three, a long label",
          "seed four, a long label", "seed five, a long label", "seed six, a long label",
          "seed_seven_with_a_label_that_has_no_space_to_break_at_anywhere"]
[paper]
citation = "made up"
[[paper.figures]]
metric = "level_error_vs_limit_final"
value = "1 arcsec"
note = "a_long_note_without_spaces_/docs/results/seed002.md#section-with-a-very-long-anchor-name-that-never-ends"
"""

PROBE = """
<script>
window.addEventListener("load", function () {
  var d = document.documentElement;
  document.body.setAttribute("data-width", d.scrollWidth + "/" + d.clientWidth);
});
</script>
</body>"""


def test_results_tables_fit_the_page(tmp_path):
    out = _run(tmp_path, WIDE)
    page = open(report.render(str(out))).read()
    assert "<script" not in page and "&lt;script&gt;alert(1)&lt;/script&gt; &amp; a" in page   # escaped
    style = page.split("<style>", 1)[1].split("</style>", 1)[0]
    # the page is at most 1400 px wide and no rule asks for more
    assert max(int(v) for v in re.findall(r"(\d+)px", style)) <= 1400
    assert re.search(r"table\.fit \{[^}]*width: 100%;[^}]*table-layout: fixed;", style)
    assert "overflow-wrap: anywhere" in style
    # every table fits; the results split into tables of at most VARIANTS_PER_TABLE variants
    tables = re.findall(r"<table class='([^']*)'>(.*?)</table>", page, re.S)
    assert tables and all("fit" in cls.split() for cls, _ in tables)
    results = [body for cls, body in tables if "results" in cls]
    assert len(results) == 2
    for body in results:
        head = re.search(r"<tr>(.*?)</tr>", body).group(1)
        assert len(re.findall(r"<th>", head)) <= 1 + run_report.VARIANTS_PER_TABLE


@pytest.mark.parametrize("width", [1200, 1400])
def test_the_page_does_not_scroll_sideways_in_a_browser(tmp_path, width):
    browser = shutil.which("chromium") or shutil.which("chromium-browser")
    if browser is None:
        pytest.fail("no chromium: tools/setup.sh installs Debian's chromium for this test")
    out = _run(tmp_path, WIDE)
    check = out / "report_check.html"
    check.write_text(open(report.render(str(out))).read().replace("</body>", PROBE))
    proc = subprocess.run([browser, "--headless=new", "--no-sandbox", "--disable-gpu",
                           f"--window-size={width},900", "--hide-scrollbars", "--virtual-time-budget=5000",
                           "--dump-dom", check.as_uri()], capture_output=True, text=True, timeout=120)
    assert proc.returncode == 0, proc.stderr[-2000:]
    scroll, client = map(int, re.search(r'data-width="(\d+)/(\d+)"', proc.stdout).groups())
    assert client == width and scroll <= client, (scroll, client)


# ---------------------------------------------------------------------------
# Long runs: decimated curves that keep their peaks, a zoom on a few cycles
# ---------------------------------------------------------------------------
def test_envelope_bounds_the_points_and_keeps_every_peak():
    t = np.arange(1_000_003) * 0.01
    y = np.mod(t, 120.0) * 3.0            # a 120 s sawtooth: a stride of any size aliases it
    y[777_777] = 1e4                       # one spike
    y[5] = np.nan
    x2, y2 = plotting.envelope(t, y, 4000)
    assert len(y2) <= 4000
    assert np.nanmax(y2) == 1e4 and np.nanmin(y2) == 0.0
    assert np.all(np.diff(x2) > 0) and x2[0] == t[0] and x2[-1] == t[-1]
    # every stretch of a period reaches the sawtooth's top and bottom: no slow wave that is not there
    k = 13_000                              # one period (12,000 samples) and a bucket (~500)
    for i in range(0, len(t) - k, 37_000):
        part = y2[(x2 >= t[i]) & (x2 < t[i + k])]
        assert part.max() > 355 and part.min() < 5, i
    short = np.arange(10.0)                 # within the bound: every point, as given
    assert np.array_equal(plotting.envelope(short, short)[1], short)


def test_a_long_rotation_runs_figures_are_decimated_with_a_zoom_on_a_few_cycles(tmp_path, drawn):
    out = _run(tmp_path, LAYOUT)
    report.render(str(out))
    summary, series = run_report.load(str(out))
    n = len(series["two-position"]["time_s"])
    assert n > plotting.MAX_POINTS          # the bound is exercised
    for name in ("errors.png", "table.png"):
        for ax in drawn[name]:
            for label, x, y in ax["lines"]:
                assert len(x) <= plotting.MAX_POINTS, (name, ax["ylabel"], label, len(x))
    table = drawn["table.png"]
    whole = next(a for a in table if a["ylabel"].startswith("table angle"))
    angle = np.degrees(series["two-position"]["outputs"]["table_angle_rad"])
    _, x, y = next(ln for ln in whole["lines"] if ln[0] == "two-position")
    assert y.max() == pytest.approx(angle.max()) and y.min() == pytest.approx(angle.min())
    zooms = [a for a in table if a["title"].startswith("zoom")]
    assert len(zooms) == 1
    zoom = zooms[0]["xlim"]                  # seconds: the run is 20 min
    o = series["two-position"]["outputs"]
    t = series["two-position"]["time_s"]
    inside = (t >= zoom[0]) & (t <= zoom[1])
    cycles = np.count_nonzero(np.diff(o["index_state"][inside]) != 0) / (2 * (o["index_step"].max() + 1))
    assert 2 <= cycles <= 5, cycles
    assert zoom[1] - zoom[0] < 0.25 * t[-1]


# ---------------------------------------------------------------------------
# Progress
# ---------------------------------------------------------------------------
def test_pyins_run_prints_a_line_for_the_metrics_and_the_figures(tmp_path, capsys):
    path = tmp_path / "layout.toml"
    path.write_text(LAYOUT)
    out = tmp_path / "run"
    assert cli.main(["run", str(path), "--out", str(out)]) == 0
    err = capsys.readouterr().err
    assert len(re.findall(r"^    metrics and time series \.\.\. \d+\.\d s$", err, re.M)) == 3, err
    assert re.search(r"^  report: figures \.\.\. \d+\.\d s$", err, re.M), err
    assert cli.main(["report", str(out)]) == 0
    err = capsys.readouterr().err
    assert re.search(r"^  report: figures \.\.\. \d+\.\d s$", err, re.M), err
    # --quiet: no progress at all
    assert cli.main(["run", str(path), "--out", str(out), "--quiet"]) == 0
    assert capsys.readouterr().err == ""


def test_a_phase_line_says_stopped_when_ctrl_c_ends_it():
    import io
    buf = io.StringIO()
    with pytest.raises(KeyboardInterrupt):
        with Phases(buf)("report: figures"):
            raise KeyboardInterrupt
    assert buf.getvalue() == "  report: figures ... stopped\n"


def test_a_long_replays_figures_keep_every_peak(tmp_path, drawn):
    """Before: the replay page thinned its records by a stride (one in 25
    here), so a one-record excursion drew only if it fell on the stride and
    a rotation cycle near the stride drew as a slow wave. Now each curve is
    its min/max envelope, read block by block: every peak is drawn, within
    MAX_POINTS points a line."""
    import json

    from pyins import native
    from pyins.reference import abi

    n = 100_003                                    # 11 blocks of records; a stride would be 25
    rec = np.zeros(n, dtype=native.OUTPUT_DTYPE)
    rec["tick"] = np.arange(1, n + 1)
    rec["mode"] = abi.PYINS_MODE_NAVIGATE
    rec["mode"][:3000] = abi.PYINS_MODE_COARSE_ALIGN
    i = np.arange(n)
    rec["euler_b_rad"][:, 0] = np.radians(2.0) * np.sin(2 * np.pi * i / 25.02)  # aliases at stride 25
    rec["euler_b_rad"][:, 1] = np.radians(1.0) * np.cos(2 * np.pi * i / 900.0)
    rec["heading_b_rad"] = np.radians(90.0)
    spikes = {0: (50_001, np.radians(7.0)), 1: (77_777, np.radians(-6.0))}
    for axis, (k, v) in spikes.items():
        rec["euler_b_rad"][k, axis] = v
    rec["heading_b_rad"][33_333] = np.radians(100.0)
    out = tmp_path / "replay"
    out.mkdir()
    np.savez(out / "navigation.npz", outputs=rec)
    t = rec["tick"] / 100.0
    north = np.zeros(n)
    north[61_111] = 42.0
    np.savez(out / "errors.npz", time_s=t, north_m=north, east_m=np.zeros(n), vel_n_mps=np.zeros((n, 3)))
    summary = dict(log="synthetic.imu", samples=n, rate_hz=100, complete=True,
                   final=dict(mode=3, lat_deg=34.0, lon_deg=108.0, fault_flags=0),
                   errors=dict(reference="parked", horizontal_max_m=42.0, horizontal_final_m=0.0))
    (out / "summary.json").write_text(json.dumps(summary))
    report.render(str(out))
    att = drawn["attitude.png"]
    for ax in att + drawn["errors.png"]:
        for label, x, y in ax["lines"]:
            assert len(x) <= plotting.MAX_POINTS, (ax["ylabel"], label, len(x))
    pitch, roll, heading = (ax["lines"][0][2] for ax in att)
    assert pitch.max() == pytest.approx(7.0) and roll.min() == pytest.approx(-6.0)
    assert heading.max() == pytest.approx(100.0)
    # the fast pitch wave keeps its full swing in every stretch of 2,000 records (a stride
    # of 25 draws it as a wave of ~0.6 of its amplitude there, then of 2 deg, slowly)
    x = att[0]["lines"][0][1] * 100.0          # the time axis in seconds (1,000 s), as ticks
    for a in range(3000, n - 2000, 9000):
        part = pitch[(x >= a) & (x < a + 2000)]
        assert part.max() > 1.99 and part.min() < -1.99, a
    assert drawn["errors.png"][0]["lines"][0][2].max() == 42.0


# ---------------------------------------------------------------------------
# Which alignment ran: the summary and the report say it
# ---------------------------------------------------------------------------
ALIGNED = """
name = "aligned"
title = "a static IMU aligned by FIT, then the 8-state filter, then navigating"
duration = "300 s"
seed = 3
record_every = "1 s"
[motion]
kind = "static"
lat = "34 deg"
lon = "108 deg"
height = "0 m"
heading = "30 deg"
[sensors]
preset = "seed000"
[firmware]
initial_attitude = "zero"
coarse_time = "60 s"
coarse_method = "fit"
fine_time = "120 s"
fine_states = 8
[compare]
key = "firmware.fine_time"
values = ["120 s", "0 s"]
labels = ["fine", "coarse only"]
"""


def test_a_run_names_its_alignment_in_the_summary_and_the_report(tmp_path):
    out = _run(tmp_path, ALIGNED)
    summary = rundir.read_summary(str(out))
    fine, coarse = summary["variants"]
    # the method as configured, the time navigation began and the sigma then: the
    # 8-state filter's heading sigma after 120 s (tens of arc-minutes on a static
    # base: well above 0, well below its 600' prior); the coarse alignment alone
    # has no filter to say it
    assert fine["aligned"]["method"] == ("coarse FIT 60 s, then fine 8-state filter 120 s, then the "
                                         "navigation filter while a reference aids it")
    assert fine["aligned"]["time_s"] == 180.0
    assert 0.0 < fine["aligned"]["heading_sigma_arcmin"] < 600.0
    assert coarse["aligned"]["method"].startswith("coarse FIT 60 s, then the navigation filter")
    assert coarse["aligned"]["time_s"] == 60.0
    page = html.unescape(open(report.render(str(out))).read())
    row = page.split("<code>alignment</code>", 1)[1].split("</tr>", 1)[0]
    assert "coarse FIT 60 s, then fine 8-state filter 120 s" in row and "navigating at 180 s" in row
    assert f"heading sigma {fine['aligned']['heading_sigma_arcmin']:.3g}'" in row


def test_a_damaged_aligned_entry_is_named(tmp_path):
    out = _run(tmp_path, ALIGNED)
    summary = rundir.read_summary(str(out))
    summary["variants"][0]["aligned"] = "FIT"
    rundir.write_summary(str(out), summary)
    with pytest.raises(rundir.RunDirError, match="damaged entry for variant 'fine' \\(aligned\\)"):
        rundir.summary_for_report(str(out))
