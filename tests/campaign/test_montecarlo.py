"""Monte Carlo over the papers' random constants (docs/campaigns.md, "Campaign
files": random constants): the draw is
N(0, sigma^2) per non-zero preset term with a fixed stream per draw; a
campaign with ``random_constants`` gives every scheme of one draw the same
constants (paired) and a new draw new ones; its mistakes are one line; the
small Monte-Carlo campaign gives identical aggregates locally and on a Dask
LocalCluster; the report's statistics (percentile, Clopper-Pearson)."""
import json
import math

import numpy as np
import pytest

from pyins import campaign, scenario
from pyins.scenario import ScenarioError
from pyins.sim import sensors
from pyins.units import ARCSEC_TO_RAD, DPH_TO_RPS, UG_TO_MPS2
from budget_campaign import BUDGET_CAMPAIGN
from tools_loader import load_tool



def _driver():
    return load_tool("papers/montecarlo.py")


# ---------------------------------------------------------------------------
# The draw
# ---------------------------------------------------------------------------
@pytest.mark.parametrize("name", ["seed002", "seed003"])
def test_draws_are_zero_mean_with_the_preset_sigma(name):
    """2000 draws: per term, mean 0 and std = |preset value| (the stated 1
    sigma); zero preset terms stay zero. With n = 2000 the sample std of a
    normal scatters by sigma / sqrt(2 n) = 1.6 % and the mean by sigma /
    sqrt(n) = 2.2 % of sigma: 6 % and 9 % are about 4 of those, so a draw
    with a wrong sigma (e.g. the preset's +1 sigma times 0.9, or a uniform
    of the same range, std 0.58 sigma) fails."""
    n = 2000
    p = sensors.PRESETS[name]
    factors = {t: f for t, _, f in sensors.RANDOM_CONSTANT_TERMS}
    samples = {t: np.array([sensors.random_constant_values(name, d)[t][0] for d in range(n)]) * factors[t]
               for t in factors}
    for term, s in samples.items():
        sigma = np.abs(getattr(p, term))
        zero = sigma == 0.0
        assert np.all(s[:, zero] == 0.0), term
        if np.all(zero):
            continue
        std = s[:, ~zero].std(axis=0, ddof=1)
        mean = s[:, ~zero].mean(axis=0)
        np.testing.assert_allclose(std, sigma[~zero], rtol=0.06, err_msg=term)
        assert np.all(np.abs(mean) < 0.09 * sigma[~zero]), term
        assert np.all((s[:, ~zero] > 0).mean(axis=0) > 0.45), f"{term}: both signs are drawn"


def test_seed003_draws_one_common_rotation_of_both_triads():
    """Seed 003 prints one skew-symmetric installation matrix for both
    triads (a common rotation of the IMU, [phi x] with phi = (2", 2", 2")):
    a draw is one rotation, phi_i = 2" z_i from the gyro terms' normals at
    (2, 1), (0, 2), (1, 0), and both triads get the same [phi x] (exactly:
    a drawn unit's triads stay orthogonal and agree with each other). Seed
    002's matrices (all six gyro terms, three accelerometer terms) are not
    one rotation, and stay drawn term by term."""
    for d in (0, 1, 5):
        v = sensors.random_constant_values("seed003", d)
        g, a = v["gyro_misalignment"][0], v["accel_misalignment"][0]
        assert np.array_equal(g, a)
        assert np.array_equal(g, -g.T)
        z = sensors.random_constant_normals(d)[6:15].reshape(3, 3)
        phi = np.array([g[2, 1], g[0, 2], g[1, 0]])
        np.testing.assert_allclose(phi, 2.0 * np.array([z[2, 1], z[0, 2], z[1, 0]]), rtol=1e-15, atol=0)
    v2 = sensors.random_constant_values("seed002", 0)
    assert not np.array_equal(v2["gyro_misalignment"][0], -v2["gyro_misalignment"][0].T)
    assert np.count_nonzero(v2["accel_misalignment"][0]) == 3


def test_a_draw_is_reproducible_and_its_stream_fixed():
    """Draw 0 of seed002 is pinned (a change of the salt, order or generator
    changes every Monte-Carlo run and its digest); the up gyro of draw 0 is
    pinned to 1e-15 deg/h, far below any change of stream (O(sigma))."""
    v = sensors.random_constant_values("seed002", 0)
    assert v["gyro_bias"][1] == "deg/h"
    np.testing.assert_allclose(v["gyro_bias"][0], [0.0028437713168923528, 0.000382623415782682,
                                                   0.005642530789345591], rtol=0, atol=1e-15)
    again = sensors.random_constant_values("seed002", 0)
    assert all(np.array_equal(again[t][0], v[t][0]) for t in v)
    other = sensors.random_constant_values("seed002", 1)
    assert not np.array_equal(other["gyro_bias"][0], v["gyro_bias"][0])
    # the same normals under both presets: seed 003's draw 0 is seed 002's scaled by the sigmas
    v3 = sensors.random_constant_values("seed003", 0)
    np.testing.assert_allclose(v3["gyro_bias"][0], v["gyro_bias"][0], rtol=1e-12)   # both 0.003 deg/h
    np.testing.assert_allclose(v3["accel_bias"][0], v["accel_bias"][0] * 20.0 / 30.0, rtol=1e-12)
    with pytest.raises(ValueError, match="integer >= 0"):
        sensors.random_constant_values("seed002", -1)
    with pytest.raises(ValueError, match="unknown sensor preset"):
        sensors.random_constant_values("seed009", 0)


@pytest.mark.parametrize("draw", [0, 7])
def test_overrides_give_the_drawn_errors(draw):
    """The overrides written as text give, once resolved by the scenario, the
    SensorErrors of draw_random_constants: to 1e-15 relative (one rounding
    of the unit conversion), the noise terms kept as the preset's."""
    sc = scenario.load("seed002_exp1").with_overrides(
        {"compare": None, "paper": None, **sensors.random_constant_overrides("seed002", draw)})
    spec = next(sc.runs())
    want = sensors.draw_random_constants("seed002", draw)
    got = spec.errors
    for t, _, _ in sensors.RANDOM_CONSTANT_TERMS:
        np.testing.assert_allclose(getattr(got, t), getattr(want, t), rtol=1e-15, atol=0, err_msg=t)
    assert got.gyro_arw == sensors.PRESETS["seed002"].gyro_arw
    assert got.accel_vrw == sensors.PRESETS["seed002"].accel_vrw
    # the drawn up-gyro drift in SI: N(0, (0.003 deg/h)^2) times the normal
    z = sensors.random_constant_normals(draw)
    assert got.gyro_bias[2] == pytest.approx(z[2] * 0.003 * DPH_TO_RPS, rel=1e-12)
    assert got.accel_bias[0] == pytest.approx(z[15] * 30.0 * UG_TO_MPS2, rel=1e-12)
    assert got.gyro_misalignment[1, 0] == pytest.approx(z[9] * 10.0 * ARCSEC_TO_RAD, rel=1e-12)


# ---------------------------------------------------------------------------
# The campaign
# ---------------------------------------------------------------------------
def test_builtin_montecarlo_campaigns_are_paired():
    """seed002_montecarlo: 4 schemes x 2 swings x 100 draws; every point of
    draw d carries draw d's constants and noise seed d, whatever its scheme
    and experiment; two draws differ; the definition names the preset."""
    camp = campaign.load_campaign("seed002_montecarlo")
    assert len(camp.points) == 800 and len(camp.groups) == 8
    assert camp.describe()["random_constants"] == "seed002"
    by_run = {}
    for p in camp.points:
        drawn = {k: v for k, v in p.overrides.items() if k.startswith("sensors.")}
        assert drawn["sensors.preset"] == "seed002"
        assert p.seed == p.run
        by_run.setdefault(p.run, []).append(json.dumps(drawn, sort_keys=True))
    assert all(len(set(v)) == 1 and len(v) == 8 for v in by_run.values())
    assert len({v[0] for v in by_run.values()}) == 100
    c3 = campaign.load_campaign("seed003_montecarlo")
    assert len(c3.points) == 200
    assert c3.points[0].overrides["sensors.gyro_bias"] == c3.points[100].overrides["sensors.gyro_bias"]


def test_random_constants_mistakes_are_one_line(tmp_path):
    base = """[campaign]\nscenario = "seed003"\ncompare = "drop"\n"""
    cases = [
        (base + 'random_constants = "seed002"\n[campaign.grid]\n"indexing.scheme" = ["none"]\n',
         "campaign.random_constants: needs campaign.seeds"),
        (base + 'seeds = 2\nrandom_constants = "sed003"\n',
         "'sed003' is not a sensor preset; did you mean 'seed003'?"),
        (base + 'seeds = 2\nrandom_constants = "error_free"\n', "has no random constants"),
        (base + 'seeds = 2\nrandom_constants = "seed003"\n[campaign.grid]\n'
                '"sensors.gyro_bias" = ["0.001 deg/h", "0.002 deg/h"]\n',
         'campaign.grid."sensors.gyro_bias": drawn by campaign.random_constants'),
    ]
    for text, msg in cases:
        with pytest.raises(ScenarioError) as exc:
            campaign.loads_campaign(text, source="mc.toml")
        line = str(exc.value)
        assert "\n" not in line and line.startswith("mc.toml: ") and msg in line, line


def test_without_random_constants_nothing_changes():
    """A campaign without the key keeps its points' overrides and digests:
    seed002_schemes draws nothing and its definition has no such entry."""
    camp = campaign.load_campaign("seed002_schemes")
    assert "random_constants" not in camp.describe()
    assert not any(k.startswith("sensors.") for p in camp.points for k in p.overrides)


def test_local_and_dask_give_identical_montecarlo_aggregates(tmp_path):
    """3 draws x 2 schemes x 1 h (seed 002 exp. 1) on a local pool and on a
    Dask LocalCluster of 2 processes: campaign.json (every point's metrics
    and the aggregates) is identical but for ``execution``. Also: the two
    schemes of one draw differ (the runs are real), and two draws differ."""
    pytest.importorskip("distributed")
    mc = _driver()
    same, local, dask, _ = mc.dask_identity(str(tmp_path), draws=3, hours=1, workers=2)
    assert local["execution"]["computed"] == 6 and dask["execution"]["computed"] == 6
    assert dask["execution"]["scheduler"].startswith("dask tcp://")
    assert same
    h = [p["metrics"][""]["horizontal_error_final_m"] for p in local["points"]]
    assert len(set(h)) == 6


# ---------------------------------------------------------------------------
# The report's statistics
# ---------------------------------------------------------------------------
def test_report_statistics():
    """Clopper-Pearson 90 %: 0 of 10 gives [0, 0.259] (1 - 0.05^(1/10)), 10
    of 10 [0.741, 1]; 50 of 100 about [0.413, 0.587] (to 1e-3: the exact
    beta quantiles). The paper's percentile: the share of draws below it,
    ties counted half."""
    mc = _driver()
    lo, hi = mc.clopper_pearson(0, 10)
    assert lo == 0.0 and hi == pytest.approx(1 - 0.05 ** 0.1, abs=1e-9)
    lo, hi = mc.clopper_pearson(10, 10)
    assert hi == 1.0 and lo == pytest.approx(0.05 ** 0.1, abs=1e-9)
    lo, hi = mc.clopper_pearson(50, 100)
    assert lo == pytest.approx(0.413, abs=1e-3) and hi == pytest.approx(0.587, abs=1e-3)
    assert mc.percentile_of([1, 2, 3, 4], 2.5) == 50.0
    assert mc.percentile_of([1, 2, 3, 4], 2) == pytest.approx(37.5)
    assert mc.percentile_of([1, 2, 3, 4], 0.5) == 0.0 and mc.percentile_of([1, 2, 3, 4], 9) == 100.0
    assert math.isclose(mc.percentile_of(np.arange(100), 89.5), 90.0)


def test_first_draws_shares_the_runs():
    """The driver's blocks: the first n draws of the campaign (and a scheme
    subset) keep the whole campaign's digests, so the blocks resume into
    the same run directories."""
    mc = _driver()
    camp = campaign.load_campaign("seed002_montecarlo")
    sub = mc.first_draws(camp, 3, ["none", "flexible"])
    assert len(sub.points) == 3 * 2 * 2
    assert [p.index for p in sub.points] == list(range(12))
    whole = {(p.run, p.values["indexing.scheme"], p.values["motion.period"]): p.digest for p in camp.points}
    for p in sub.points:
        assert whole[(p.run, p.values["indexing.scheme"], p.values["motion.period"])] == p.digest


def test_statistics_pair_the_draws():
    """statistics() on a made-up seed 002 result: 10 draws, flexible smaller
    than traditional in draws 0-6 of exp. 1 (P = 0.7, paired by draw, not by
    rank); the paper's 2.97 nmi (flexible, exp. 1) sits above 3 of the
    flexible draws' 1..10 nmi (30th percentile); a draw missing from one
    scheme drops out of the pair only."""
    mc = _driver()
    nmi = 1852.0
    points = []
    for d in range(10):
        trad = (d + 1) * nmi
        flex = (d + 0.5) * nmi if d < 7 else (d + 1.5) * nmi     # 1..10 nmi over the draws, shifted
        for scheme, h in (("two_position", trad), ("flexible", flex)):
            points.append({"values": {"indexing.scheme": scheme, "motion.period": "120 s"}, "run": d,
                           "metrics": {"": {"horizontal_error_final_m": h, "horizontal_error_max_m": h}}})
    points.append({"values": {"indexing.scheme": "two_position", "motion.period": "120 s"}, "run": 10,
                   "metrics": {"": {"horizontal_error_final_m": nmi, "horizontal_error_max_m": nmi}}})
    result = {"points": points, "campaign": {"grid": {"indexing.scheme": ["two_position", "flexible"]},
                                             "labels": {"indexing.scheme": ["trad", "flex"]}}}
    st = mc.statistics("seed002", result)
    pair = next(p for p in st["pairs"] if p["metric"] == "horizontal_error_final")
    assert (pair["better"], pair["worse"], pair["n"], pair["wins"]) == ("flexible", "two_position", 10, 7)
    assert pair["ci90"] == pytest.approx(list(mc.clopper_pearson(7, 10)))
    flex = next(r for r in st["rows"] if r["scheme"] == "flexible" and r["metric"] == "horizontal_error_final")
    assert flex["paper"] == pytest.approx(2.97, abs=1e-9) and flex["paper_percentile"] == 30.0
    trad = next(r for r in st["rows"] if r["scheme"] == "two_position" and r["metric"] == "horizontal_error_final")
    assert trad["n"] == 11 and trad["paper"] == pytest.approx(3.70, abs=1e-9)


def test_one_seeds_report_keeps_the_others_figures(tmp_path):
    """`montecarlo.py seed003` alone rewrites montecarlo.json: seed 002's
    figures already there are kept, not dropped (they took an hour of runs)."""
    mc = _driver()
    report_dir = tmp_path / "report"
    report_dir.mkdir()
    kept = {"seed002": {"draws": 100, "rows": [{"median": 3.99}]}}
    (report_dir / "montecarlo.json").write_text(json.dumps(kept))
    text = mc.report(["seed003"], str(tmp_path / "runs"), str(report_dir))
    assert "seed003: no complete run" in text
    assert json.loads((report_dir / "montecarlo.json").read_text()) == kept


# ---------------------------------------------------------------------------
# The draws through the error budget (`pyins campaign --budget`)
# ---------------------------------------------------------------------------
def _seed002_budget_campaign(schemes, duration):
    """BUDGET_CAMPAIGN on seed 002's experiment 1 and its draws, over the
    schemes (a TOML list) for the duration."""
    return (BUDGET_CAMPAIGN.replace('scenario = "seed003"', 'scenario = "seed002_exp1"')
            .replace('random_constants = "seed003"', 'random_constants = "seed002"')
            .replace('["none", "single_position"]', schemes).replace('"2 h"', f'"{duration}"'))


def test_campaign_budget_places_draws_held_to_the_closed_loop(tmp_path, capsys):
    """`pyins campaign FILE --budget 300 --checks 3`: 300 draws per grid
    point through the budget, and three closed-loop runs of drawn units (no
    noise) within 1 % of the budget's value for the same draw. 1 %: the
    budget steps the linear error equations every 10 s from one error-free
    run's table history; on the fixed schedules it was measured within
    0.1 % on 24 h runs (2026-12-06), and a wrong coefficient (a term's
    element or sign mixed up) moves a draw by tens of percent."""
    from pyins import __main__ as cli
    f = tmp_path / "c.toml"
    f.write_text(BUDGET_CAMPAIGN)
    out = tmp_path / "out"
    rc = cli.main(["campaign", str(f), "--budget", "300", "--checks", "3", "--workers", "2", "--out", str(out)])
    text, err = capsys.readouterr()
    assert rc == 0, err
    res = json.loads((out / "budget.json").read_text())
    assert [p["draws"] for p in res["points"]] == [300, 300]
    assert all(len(p["final_m"]) == 300 and p["p5_m"] < p["median_m"] < p["p95_m"] for p in res["points"])
    assert len(res["checks"]) == 3 and res["warnings"] == []
    assert len({(tuple(sorted(c["values"].items())), c["draw"]) for c in res["checks"]}) == 3   # distinct
    for c in res["checks"]:
        assert abs(c["rel"]) <= 0.01, c
        # a fixed schedule: every unit turns its table as the error-free unit does, bit for bit
        assert c["same_table"] is True and c["table_differs_from_s"] is None, c
    assert "through the budget" in text and (out / "budget.md").exists()
    # every phase says how far it is, with the time left until its last step
    assert "budget 1/2:" in text and "budget 2/2:" in text and "check 3/3:" in text
    assert text.count("s left") == 3, text       # after budget 1/2 and checks 1/3, 2/3


@pytest.mark.parametrize("argv, words", [
    (["--budget", "0"], "--budget 0: the number of draws must be 1 or more"),
    (["--checks", "2"], "--checks is for --budget"),
    (["--budget", "10", "--checks", "-1"], "--checks -1: must be 0 or more"),
    (["--budget", "10", "--scheduler", "tcp://127.0.0.1:8786"], "--budget runs on the local pool"),
])
def test_campaign_budget_refuses_bad_options(tmp_path, capsys, argv, words):
    from pyins import __main__ as cli
    f = tmp_path / "c.toml"
    f.write_text(BUDGET_CAMPAIGN)
    assert cli.main(["campaign", str(f), *argv, "--out", str(tmp_path / "o")]) == 2
    assert words in capsys.readouterr().err
    assert not (tmp_path / "o").exists()


def test_campaign_budget_refuses_more_checks_than_units(tmp_path, capsys):
    """Checks are distinct (grid point, draw) pairs: 2 grid points x 4
    seeds give 8, and a ninth is refused rather than run twice."""
    from pyins import __main__ as cli
    f = tmp_path / "c.toml"
    f.write_text(BUDGET_CAMPAIGN)
    assert cli.main(["campaign", str(f), "--budget", "300", "--checks", "9", "--out", str(tmp_path / "o")]) == 2
    assert "9 checks asked, but there are only 8 (grid point, draw) pairs" in capsys.readouterr().err
    assert not (tmp_path / "o").exists()


def test_same_table_compares_angles_and_counts():
    """by_budget.same_table: equal histories are the same; an angle that
    differs at a record both keep names its time; counts that differ at the
    end (a move between records) make it differ without a time."""
    from pyins.campaign.by_budget import same_table
    model = {"tick": np.arange(0, 1000, 100), "alpha": np.linspace(0.0, 3.0, 10), "starts": 4, "travel": 6.28}
    check = {"tick": model["tick"][::2].copy(), "alpha": model["alpha"][::2].copy(), "starts": 4, "travel": 6.28}
    assert same_table(model, check, 0.01) == (True, None)
    moved = dict(check, alpha=check["alpha"].copy())
    moved["alpha"][3] = np.nextafter(moved["alpha"][3], 9.0)        # one ulp at tick 600
    assert same_table(model, moved, 0.01) == (False, 6.0)
    assert same_table(model, dict(check, starts=5), 0.01) == (False, None)
    assert same_table(model, dict(check, travel=6.28 + 1e-15), 0.01) == (False, None)


def test_campaign_budget_checks_say_where_the_units_stops_moved(tmp_path, capsys):
    """The derivation form of the flexible scheme steers every stop from
    the unit's own heading: over 6 h some checked unit's table turns
    otherwise than the error-free unit's (seed 002's draws, measured
    2026-12-06: from 0.37-1.72 h on), and budget.md and the terminal say from
    when; a check that misses by more than 1 % is put down to that."""
    from pyins import __main__ as cli
    f = tmp_path / "c.toml"
    f.write_text(_seed002_budget_campaign('["flexible_derived"]', "6 h"))
    out = tmp_path / "out"
    assert cli.main(["campaign", str(f), "--budget", "20", "--checks", "4", "--workers", "2",
                     "--out", str(out)]) == 0
    text, err = capsys.readouterr()
    res = json.loads((out / "budget.json").read_text())
    moved = [c for c in res["checks"] if not c["same_table"]]
    assert moved, res["checks"]
    for c in moved:
        assert c["table_differs_from_s"] is None or 0.0 < c["table_differs_from_s"] <= 6 * 3600.0
    assert "turned otherwise than the error-free unit's" in text
    assert "| no" in (out / "budget.md").read_text()
    for c in res["checks"]:
        if abs(c["rel"]) > 0.01:
            assert not c["same_table"], c
    if any(abs(c["rel"]) > 0.01 for c in res["checks"]):
        assert "in all of them the unit's table turned otherwise" in err


def test_campaign_budget_refuses_what_it_cannot_place(tmp_path, capsys):
    """No random constants: nothing to place; an alignment phase: outside
    the budget's model (named)."""
    from pyins import __main__ as cli
    f = tmp_path / "c.toml"
    f.write_text(BUDGET_CAMPAIGN.replace('random_constants = "seed003"\n', ""))
    assert cli.main(["campaign", str(f), "--budget", "10", "--out", str(tmp_path / "o")]) == 2
    assert "draws no random constants" in capsys.readouterr().err
    f.write_text(BUDGET_CAMPAIGN + '"firmware.coarse_time" = "60 s"\n')
    assert cli.main(["campaign", str(f), "--budget", "10", "--out", str(tmp_path / "o")]) == 2
    assert "alignment phase" in capsys.readouterr().err


def test_campaign_budget_warns_where_the_table_is_steered(tmp_path, capsys):
    """The flexible scheme stops where the unit's own heading says: the
    budget takes every unit's stops from the error-free unit's, so the grid
    point is marked steered and the warning is printed and kept in
    budget.json and budget.md; no check at all is a warning too."""
    from pyins import __main__ as cli
    from pyins.budget import steered_table
    f = tmp_path / "c.toml"
    f.write_text(_seed002_budget_campaign('["two_position", "flexible"]', "1 h"))
    out = tmp_path / "out"
    assert cli.main(["campaign", str(f), "--budget", "20", "--checks", "0", "--out", str(out)]) == 0
    err = capsys.readouterr().err
    res = json.loads((out / "budget.json").read_text())
    assert [p["steered"] for p in res["points"]] == [False, True]
    assert any("steered by the unit's own heading" in w for w in res["warnings"])
    assert any("no closed-loop check" in w for w in res["warnings"])
    assert "steered by the unit's own heading" in err and "(steered)" in (out / "budget.md").read_text()
    spec = next(scenario.load("seed003").with_overrides({"compare": None, "paper": None}).runs())
    assert not steered_table(spec)
