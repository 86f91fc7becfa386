"""The built-in moored_heave_lever campaign: its grid (heave, lever-arm length,
lever known or not) over moored_general with FIT; a tiny version of it runs,
and with two or more group keys the report has a table of each metric by
the first key (rows) and the others (columns) and a plot against each of the
first two keys."""
import json

import numpy as np
import pytest

from pyins import campaign, sim
from pyins.report import campaign as campaign_report
from pyins.units import ARCMIN_TO_RAD as ARCMIN

TINY = """
[campaign]
title = "tiny moored_heave_lever"
scenario = "moored_general"
seeds = 1
seed_formula = "240007 + run"
group_by = ["motion.heave", "motion.lever_b"]
compare = "drop"

[campaign.set]
duration = "100 s"
"firmware.coarse_time" = "100 s"
"firmware.coarse_method" = "fit"

[campaign.grid]
"motion.heave" = [{ amplitude = "0 m", period = "8 s" }, { amplitude = "3 m", period = "8 s" }]
"motion.lever_b" = [["0 m", "0 m", "0 m"], ["1.2595 m", "3.7784 m", "3.0228 m"]]

[campaign.labels]
"motion.heave" = ["heave 0 m", "heave 3 m"]
"motion.lever_b" = ["lever 0 m", "lever 5 m"]
"""


def test_builtin_moored_heave_lever_grid():
    camp = campaign.load_campaign("moored_heave_lever")
    assert camp.base.name == "moored_general" and camp.compare == "drop"
    assert camp.group_by == ["motion.heave", "motion.lever_b", "firmware.lever"]
    assert len(camp.points) == 120 and len(camp.groups) == 40
    assert camp.seeds == [0, 1, 2] and {p.seed for p in camp.points} == {240007, 240008, 240009}
    assert [g["label"] for g in camp.groups[:2]] == ["heave 0 m, lever 0 m, lever known",
                                                     "heave 0 m, lever 0 m, lever unknown"]
    amps, lengths = set(), set()
    for p in camp.points:
        run = next(camp.base.with_overrides(p.overrides).runs())
        assert run.config["coarse_method"] == 1 and run.duration_ticks == 30_000
        assert isinstance(run.motion, sim.ShipAtSea)
        assert run.motion.linear.surge == sim.MOORED_SHIP["surge"]
        (a, period, _), = run.motion.linear.heave
        amps.add(a)
        assert period == 8.0
        r = run.motion.lever_b
        lengths.add(round(float(np.linalg.norm(r)), 3))
        if np.any(r):
            assert np.allclose(r / np.linalg.norm(r), np.array([0.5, 1.5, 1.2]) / np.linalg.norm([0.5, 1.5, 1.2]),
                               atol=1e-4)
        unknown = p.values["firmware.lever"] == "unknown"
        assert ("lever_b_m" in run.config) == unknown
    assert amps == {0.0, 0.5, 1.0, 2.0, 3.0} and lengths == {0.0, 1.0, 2.0, 5.0}


@pytest.fixture(scope="module")
def tiny(tmp_path_factory):
    out = tmp_path_factory.mktemp("moored")
    camp = campaign.loads_campaign(TINY, source="tiny.toml")
    return camp, out, campaign.run_campaign(camp, out, workers=1)


def test_tiny_moored_campaign_runs(tiny):
    camp, out, res = tiny
    builtin = campaign.load_campaign("moored_heave_lever")
    for key in camp.grid:            # a corner of the built-in grid
        assert all(v in builtin.grid[key] for v in camp.grid[key])
    assert res["complete"] and res["execution"]["computed"] == 4 and len(res["groups"]) == 4
    heading = {a["group"]: a for a in res["aggregates"] if a["metric"] == "heading_error_vs_limit_final_rad"}
    assert len(heading) == 4 and all(a["count"] == 1 for a in heading.values())
    # FIT after 100 s on the moored ship: a few arc-minutes (after the built-in's 300 s: < 1')
    assert all(0.0 <= a["mean"] < 15.0 * ARCMIN for a in heading.values())
    # heave and lever arm change the runs (the truth and the IMU's increments differ)
    finals = {json.dumps(p["values"], sort_keys=True): p["metrics"][""]["phi_u_final_rad"] for p in res["points"]}
    assert len(set(finals.values())) == 4


def test_two_group_keys_give_a_table_and_plots_by_key(tiny):
    camp, out, res = tiny
    md = (out / "aggregate.md").read_text()
    section = md[md.index("### heading_error_final [arcmin]"):]
    section = section[:section.index("\n### ", 1)]
    assert ("Mean over the runs of each group, by motion.heave (rows) and motion.lever_b (columns):"
            in section)
    assert "|  | lever 0 m | lever 5 m |" in section
    mean = {a["group"]: a["mean"] for a in res["aggregates"] if a["metric"] == "heading_error_final_rad"}
    for gi, row in ((0, "heave 0 m"), (2, "heave 3 m")):
        want = f"| {row} | {mean[gi] / ARCMIN:.4g} | {mean[gi + 1] / ARCMIN:.4g} |"
        assert want in section, want
    for name in ("heading_error_final_by_keys.png", "heading_error_vs_limit_final_by_keys.png",
                 "heading_error_final.png"):
        assert (out / "plots" / name).is_file(), name
    # one group key: no table by key, no plot by key
    single = campaign.from_args(camp.base, {"motion.heave": camp.grid["motion.heave"]},
                                overrides=dict(camp.overrides))
    assert campaign_report.pivot_lines(single, [], 1.0) == []
