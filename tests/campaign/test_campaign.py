"""Campaigns: the 30-run seed 000 grid locally and on a Dask cluster give the
same aggregates; a campaign killed mid-way resumes without recomputing what
finished; campaign-file mistakes are one line naming file, key and reason."""
import json
import os
import signal
import subprocess
import sys
import textwrap
import time
from pathlib import Path

import pytest

from pyins import campaign, scenario
from pyins.campaign import execute as campaign_execute
from pyins.scenario import ScenarioError

HEADINGS = "motion.heading=0 deg,60 deg,120 deg,180 deg,240 deg,300 deg"


def _without_execution(path):
    with open(path) as f:
        d = json.load(f)
    d.pop("execution")
    return d


def _summary_mtimes(out_dir):
    """run dir -> mtime (ns) of its summary.json, for the finished runs."""
    out = {}
    for d in sorted((Path(out_dir) / "runs").iterdir()):
        s = d / "summary.json"
        if s.exists() and json.loads(s.read_text()).get("complete"):
            out[d.name] = s.stat().st_mtime_ns
    return out


@pytest.fixture(scope="module")
def local_run(tmp_path_factory):
    """The built-in seed000_static campaign (30 runs of 150 s) on the local pool."""
    out = tmp_path_factory.mktemp("local")
    camp = campaign.load_campaign("seed000_static")
    calls = []
    t0 = time.perf_counter()
    result = campaign.run_campaign(camp, out, workers=2, progress=lambda *a: calls.append(a))
    return camp, out, result, calls, time.perf_counter() - t0


# ---------------------------------------------------------------------------
# Built-ins and the campaign's expansion
# ---------------------------------------------------------------------------
def test_builtin_campaigns_load():
    names = [n for n, _ in campaign.list_builtin()]
    assert names == ["moored_heave_lever", "seed000_static", "seed000_swing", "seed002_montecarlo",
                     "seed002_schemes", "seed003_montecarlo"]
    sizes = {n: len(campaign.load_campaign(n).points) for n in names}
    assert sizes == {"moored_heave_lever": 120, "seed000_static": 30, "seed000_swing": 90,
                     "seed002_montecarlo": 800, "seed002_schemes": 40, "seed003_montecarlo": 200}
    swing = campaign.load_campaign("seed000_swing")
    assert len(swing.groups) == 18 and swing.compare == "drop"
    assert campaign.load_campaign("seed002_schemes").base.with_overrides(
        campaign.load_campaign("seed002_schemes").points[0].overrides).duration_s == 12 * 3600


def test_seed000_static_points_match_the_tool():
    """6 headings x 5 runs, seeds 1000 * heading + run as
    tools/papers/reproduce_seed000.py, the base's [compare] over seeds dropped."""
    camp = campaign.load_campaign("seed000_static")
    assert [p.seed for p in camp.points[:6]] == [0, 1, 2, 3, 4, 60000]
    assert camp.points[-1].seed == 300004
    assert camp.compare == "drop" and camp.variants is None
    assert [g["label"] for g in camp.groups][:2] == ["heading = 0 deg", "heading = 60 deg"]
    p = camp.points[7]
    scn = scenario.load("seed000_static").with_overrides(
        {"compare": None, "paper": None, "motion.heading": "60 deg", "seed": 60002})
    assert p.digest == scn.digest() and p.dir == f"runs/{scn.digest()[:16]}"
    assert len({q.digest for q in camp.points}) == 30
    # the same campaign from command-line arguments
    same = campaign.from_args("seed000_static", [HEADINGS], 5, ["motion.heading"],
                              seed_formula="1000 * heading + run")
    assert [q.digest for q in same.points] == [q.digest for q in camp.points]


def test_parse_grid_and_values():
    g = campaign.parse_grid(["motion.heading=0 deg, 60 deg", "seed=1,2", "indexing.delta=0.01,2e-2",
                             'sensors.gyro_bias=["0.003 deg/h", 0, 0],0.001 deg/h',
                             "outputs.plots=true,false"])
    assert g == {"motion.heading": ["0 deg", "60 deg"], "seed": [1, 2], "indexing.delta": [0.01, 0.02],
                 "sensors.gyro_bias": [["0.003 deg/h", 0, 0], "0.001 deg/h"],
                 "outputs.plots": [True, False]}
    with pytest.raises(ScenarioError, match="KEY=VALUE"):
        campaign.parse_grid(["motion.heading"])


def test_compare_auto_keep_and_drop():
    # seeds given and the base compares seeds: dropped
    assert campaign.from_args("seed000_static", [HEADINGS], 2).compare == "drop"
    # a grid over the heading only: the base's sea states run at every point
    camp = campaign.from_args("seed000_swing", ["motion.heading=0 deg,60 deg"])
    assert camp.compare == "keep" and camp.variants == ["ideal sea", "general sea", "bad sea"]
    assert len(camp.points) == 2
    with pytest.raises(ScenarioError, match="campaign.compare: the base scenario's \\[compare\\] varies 'seed'"):
        campaign.from_args("seed000_static", [HEADINGS], 2, compare="keep")


def test_kept_compare_aggregates_per_variant(tmp_path):
    camp = campaign.from_args("seed000_swing", ["motion.heading=0 deg,60 deg"],
                              overrides=["duration=30 s", "firmware.coarse_time=30 s"])
    res = campaign.run_campaign(camp, tmp_path, workers=1, plots=False)
    assert res["complete"] and res["execution"]["computed"] == 2
    rows = [a for a in res["aggregates"] if a["metric"] == "level_error_final_rad"]
    assert [(a["group"], a["variant"]) for a in rows] == [
        (g, v) for g in (0, 1) for v in ("ideal sea", "general sea", "bad sea")]
    assert all(a["count"] == 1 and a["std"] is None for a in rows)
    assert set(res["points"][0]["metrics"]) == {"ideal sea", "general sea", "bad sea"}


# ---------------------------------------------------------------------------
# Local pool and Dask: identical aggregates
# ---------------------------------------------------------------------------
def test_local_campaign_outputs(local_run):
    camp, out, res, calls, wall = local_run
    print(f"\n30-run seed000_static campaign, local pool of 2: {wall:.1f} s")
    assert res["complete"] and not res["missing_points"]
    assert res["execution"]["computed"] == 30 and res["execution"]["skipped"] == 0
    assert calls[0] == (0, 30, 0) and calls[-1] == (30, 30, 0) and len(calls) == 31
    assert len(res["groups"]) == 6 and all(len(g["points"]) == 5 for g in res["groups"])
    for name in ("campaign.json", "aggregate.csv", "aggregate.md", "runs.csv",
                 "plots/level_error_final.png", "plots/group_std.png"):
        assert (out / name).is_file(), name
    agg = {(a["group"], a["metric"]): a for a in res["aggregates"]}
    a = agg[(0, "level_error_final_rad")]
    assert a["count"] == 5 and a["min"] <= a["p5"] <= a["p50"] <= a["p95"] <= a["max"]
    # the aggregate is the statistics of the runs' own summaries
    import numpy as np
    vals = [json.loads((out / camp.points[i].dir / "summary.json").read_text())["variants"][0]
            ["metrics"]["level_error_final"] for i in range(5)]
    assert a["mean"] == float(np.mean(vals)) and a["std"] == float(np.std(vals, ddof=1))
    gm = {(g["group"], g["metric"]): g["value"] for g in res["group_metrics"]}
    assert set(m for _, m in gm) == {"level_error_std_rad", "heading_error_std_rad"}
    assert "level_error_std" in (out / "aggregate.md").read_text()
    header = (out / "aggregate.csv").read_text().splitlines()[0]
    assert header == "group,motion.heading,variant,metric,count,mean,std,min,p5,p50,p95,max,value"


def test_dask_cluster_gives_identical_aggregates(local_run, tmp_path):
    distributed = pytest.importorskip("distributed")
    camp, out_local, _, _, _ = local_run
    t_start = time.perf_counter()
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                  dashboard_address=None) as cluster:
        print(f"\nDask LocalCluster up in {time.perf_counter() - t_start:.1f} s")
        t0 = time.perf_counter()
        res = campaign.run_campaign(camp, tmp_path, scheduler=cluster.scheduler_address, plots=False)
        print(f"30-run seed000_static campaign, Dask LocalCluster of 2: "
              f"{time.perf_counter() - t0:.1f} s")
    print(f"cluster closed after {time.perf_counter() - t_start:.1f} s in all")
    assert res["execution"]["scheduler"].startswith("dask tcp://")
    assert res["execution"]["computed"] == 30
    assert _without_execution(tmp_path / "campaign.json") == _without_execution(out_local / "campaign.json")
    assert (tmp_path / "aggregate.csv").read_bytes() == (out_local / "aggregate.csv").read_bytes()
    assert (tmp_path / "runs.csv").read_bytes() == (out_local / "runs.csv").read_bytes()


def test_dask_needs_a_reachable_scheduler(tmp_path, monkeypatch):
    pytest.importorskip("distributed")
    monkeypatch.setattr(campaign_execute, "DASK_CONNECT_TIMEOUT", "1s")
    camp = campaign.from_args("seed000_static", ["motion.heading=0 deg"], 1)
    with pytest.raises(campaign.CampaignError, match="cannot connect to the Dask scheduler"):
        campaign.run_campaign(camp, tmp_path, scheduler="tcp://127.0.0.1:9", plots=False)


@pytest.mark.parametrize("address", ["0", "host", "tcp://h:0", "h:99999", "http://h:8786", "tcp://:8786"])
def test_a_scheduler_address_that_names_none_is_refused_before_anything_is_written(address, tmp_path):
    # refused by its form, before dask is imported: "0" once went to dask's import (seconds on a
    # fresh clone) and a host with no port to the connection timeout
    camp = campaign.from_args("seed000_static", ["motion.heading=0 deg"], 1)
    out = tmp_path / "out"
    with pytest.raises(campaign.CampaignError, match=f"--scheduler {address}: "):
        campaign.run_campaign(camp, out, scheduler=address, plots=False)
    assert not out.exists()


@pytest.mark.parametrize("address", ["tcp://127.0.0.1:8786", "127.0.0.1:8786", "tls://host.example:8786",
                                     "inproc://10.0.0.1/123/1", "tcp://[::1]:8786"])
def test_a_scheduler_address_of_every_form_dask_takes_passes_the_check(address):
    campaign_execute.check_scheduler_address(address)


# ---------------------------------------------------------------------------
# Kill and resume
# ---------------------------------------------------------------------------
KILL_ARGS = dict(grid=[HEADINGS], seeds=5, overrides={"duration": "10 min"},
                 seed_formula="1000 * heading + run")


def _kill_campaign():
    return campaign.from_args("seed000_static", KILL_ARGS["grid"], KILL_ARGS["seeds"],
                              overrides=KILL_ARGS["overrides"], seed_formula=KILL_ARGS["seed_formula"])


def test_resume_after_kill(tmp_path):
    out = tmp_path / "killed"
    script = textwrap.dedent(f"""
        from pyins import campaign
        camp = campaign.from_args("seed000_static", {KILL_ARGS['grid']!r}, {KILL_ARGS['seeds']!r},
                                  overrides={KILL_ARGS['overrides']!r},
                                  seed_formula={KILL_ARGS['seed_formula']!r})
        campaign.run_campaign(camp, {str(out)!r}, workers=2, plots=False)
    """)
    proc = subprocess.Popen([sys.executable, "-c", script], start_new_session=True,
                            stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    try:
        deadline = time.monotonic() + 120
        while len(_summary_mtimes(out) if (out / "runs").exists() else {}) < 6:
            assert proc.poll() is None, proc.stderr.read().decode()
            assert time.monotonic() < deadline, "the campaign did not start"
            time.sleep(0.02)
    finally:
        os.killpg(proc.pid, signal.SIGKILL)       # the campaign and its pool workers
        proc.wait()
    time.sleep(0.2)
    done = _summary_mtimes(out)
    assert 6 <= len(done) < 30, f"{len(done)} runs finished before the kill"
    assert not (out / "aggregate.csv").exists()

    camp = _kill_campaign()
    assert len(campaign.pending(camp, out)[0]) == 30 - len(done)
    res = campaign.run_campaign(camp, out, workers=2, plots=False)
    ex = res["execution"]
    assert (ex["skipped"], ex["computed"]) == (len(done), 30 - len(done))
    after = _summary_mtimes(out)
    assert len(after) == 30
    assert {k: after[k] for k in done} == done          # finished runs were not recomputed

    ref = tmp_path / "uninterrupted"
    campaign.run_campaign(_kill_campaign(), ref, workers=2, plots=False)
    assert _without_execution(out / "campaign.json") == _without_execution(ref / "campaign.json")
    assert (out / "aggregate.csv").read_bytes() == (ref / "aggregate.csv").read_bytes()

    # a third time: nothing to do
    res = campaign.run_campaign(camp, out, workers=2, plots=False)
    assert res["execution"]["computed"] == 0 and res["execution"]["skipped"] == 30


# ---------------------------------------------------------------------------
# Mistakes in campaign files: one line, FILE: key: reason
# ---------------------------------------------------------------------------
GOOD = """
[campaign]
scenario = "seed000_static"
seeds = 2
group_by = ["motion.heading"]

[campaign.grid]
"motion.heading" = ["0 deg", "60 deg"]
"""


@pytest.mark.parametrize("old,new,key,reason", [
    ('seeds = 2', 'sedes = 2', "campaign.sedes", "unknown key; did you mean 'seeds'?"),
    ('"motion.heading" = [', '"motion.headng" = [', 'campaign.grid."motion.headng"',
     "is not a key; did you mean 'motion.heading'?"),
    ('"60 deg"]', '"400 deg"]', 'campaign.grid."motion.heading"[1]',
     "out of range: '400 deg' must be >= -360 deg and <= 360 deg"),
    ('"60 deg"]', '"60 m"]', 'campaign.grid."motion.heading"[1]', "wrong unit 'm'"),
    ('"60 deg"]', '"0 deg"]', 'campaign.grid."motion.heading"', "the value '0 deg' is given twice"),
    ('"seed000_static"', '"seed000_statc"', "campaign.scenario",
     "'seed000_statc': no such file or built-in scenario; did you mean 'seed000_static'?"),
    ('seeds = 2', 'seeds = 0', "campaign.seeds", "out of range: a count of seeds must be >= 1"),
    ('seeds = 2', 'seeds = "two"', "campaign.seeds", "must be a count or an array of seeds"),
    ('seeds = 2', 'seeds = 2\nseed_formula = "1000 * headin + run"', "campaign.seed_formula",
     "unknown name 'headin'; did you mean 'heading'?"),
    ('seeds = 2', 'seeds = 2\nseed_formula = "run - 5"', "campaign.seed_formula",
     "gives -5 for motion.heading = 0 deg, run 0: a seed must be an integer >= 0"),
    ('group_by = ["motion.heading"]', 'group_by = ["motion.yaw"]', "campaign.group_by",
     "'motion.yaw' is not a grid key"),
    ('seeds = 2', 'seeds = 2\ncompare = "maybe"', "campaign.compare", "unknown value 'maybe'"),
    ('[campaign.grid]', '[campaign.set]\nduration = "5 s"\n[campaign.grid]', "campaign.set",
     "firmware.coarse_time: out of range: the alignment (150 s) is longer than the duration (5 s)"),
    ('[campaign.grid]', '[campaign.set]\nduration = "5 parsecs"\n[campaign.grid]',
     "campaign.set.duration", "unknown unit"),
    ('[campaign.grid]', '[campaign.set]\nseed = 3\n[campaign.grid]', "campaign.set.seed",
     "the seed is set both here and by campaign.seeds"),
    ('[campaign.grid]', '[campaign.grd]', "campaign.grd", "unknown key; did you mean 'grid'?"),
    ('[campaign]\n', '[campain]\n', "campain", "unknown key; did you mean 'campaign'?"),
    ('scenario = "seed000_static"', 'scenario = "seed000_static"\nx = ', "",
     "malformed TOML"),
])
def test_campaign_file_errors(tmp_path, old, new, key, reason):
    path = tmp_path / "my_campaign.toml"
    assert old in GOOD
    path.write_text(GOOD.replace(old, new, 1))
    with pytest.raises(ScenarioError) as info:
        campaign.load_campaign(str(path))
    msg = str(info.value)
    assert "\n" not in msg
    assert msg.startswith(f"{path}: {key + ': ' if key else ''}"), msg
    assert reason in msg, msg


def test_good_file_and_scenario_file_given_as_campaign(tmp_path):
    path = tmp_path / "ok.toml"
    path.write_text(GOOD)
    camp = campaign.load_campaign(str(path))
    assert len(camp.points) == 4 and camp.name == "ok" and camp.compare == "drop"
    # unquoted dotted keys are tables in TOML: read the same
    path.write_text(GOOD.replace('"motion.heading" = [', 'motion.heading = ['))
    assert [p.digest for p in campaign.load_campaign(str(path)).points] == [p.digest for p in camp.points]
    with pytest.raises(ScenarioError, match="this is a scenario file, not a campaign"):
        campaign.load_campaign(str(scenario.builtin_path("demo")))
    with pytest.raises(ScenarioError, match="no such file or built-in campaign; did you mean 'seed000_swing'"):
        campaign.load_campaign("seed000_swig")


def test_base_scenario_relative_to_the_campaign_file(tmp_path):
    (tmp_path / "sub").mkdir()
    text = scenario.builtin_path("seed000_static").read_text()
    (tmp_path / "sub" / "mine.toml").write_text(text.replace('lat = "34.246 deg"', 'lat = "95 deg"'))
    path = tmp_path / "sub" / "c.toml"
    path.write_text(GOOD.replace('"seed000_static"', '"mine.toml"'))
    with pytest.raises(ScenarioError) as info:
        campaign.load_campaign(str(path))
    msg = str(info.value)
    assert msg.startswith(f"{path}: campaign.scenario: the base scenario 'mine.toml' is invalid: ")
    assert "motion.lat: out of range" in msg and "\n" not in msg
