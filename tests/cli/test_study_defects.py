"""`pyins campaign` and `pyins budget` as a careful user tries them: an option
given is honoured or refused (never ignored), a wrong value is refused
naming the option, --json is valid JSON whatever the numbers, long steps
say how far they are, and --help tells the truth about defaults."""
import json
import math

import pytest

from pyins import __main__ as cli


def _run(capsys, *argv):
    rc = cli.main([str(a) for a in argv])
    out, err = capsys.readouterr()
    return rc, out, err


TINY_CAMPAIGN = """
[campaign]
scenario = "seed003"
seeds = 3
group_by = ["indexing.scheme"]
compare = "drop"
[campaign.grid]
"indexing.scheme" = ["single_position"]
[campaign.set]
duration = "0.01 h"
"""


def test_seeds_given_with_a_campaign_name_is_honoured(tmp_path, capsys):
    """Before: `pyins campaign NAME --seeds 1` ran the campaign's own seeds
    (120 runs, not 40), silently; --group-by was dropped the same way."""
    f = tmp_path / "tiny.toml"
    f.write_text(TINY_CAMPAIGN)
    rc, out, err = _run(capsys, "campaign", f, "--seeds", "1", "--out", tmp_path / "c", "--json")
    assert rc == 0, err
    res = json.loads(out)
    assert res["execution"]["runs"] == 1 and len(res["points"]) == 1
    rc, out, err = _run(capsys, "campaign", f, "--seeds", "2", "--group-by", "seed",
                        "--out", tmp_path / "c", "--json")
    assert rc == 0, err
    res = json.loads(out)
    assert res["execution"]["runs"] == 2 and res["execution"]["skipped"] == 1
    assert res["campaign"]["group_by"] == ["seed"] and len(res["groups"]) == 2


def test_seeds_and_group_by_of_a_campaign_name_are_checked_naming_the_option(tmp_path, capsys):
    f = tmp_path / "tiny.toml"
    f.write_text(TINY_CAMPAIGN)
    rc, out, err = _run(capsys, "campaign", f, "--seeds", "0", "--out", tmp_path / "c")
    assert rc == 2 and "--seeds 0" in err and "Traceback" not in err
    rc, out, err = _run(capsys, "campaign", f, "--group-by", "nope", "--out", tmp_path / "c")
    assert rc == 2 and "--group-by nope" in err and "not a grid key" in err


@pytest.mark.parametrize("argv, option", [
    (["--scenario", "seed003", "--seeds", "-1"], "--seeds -1"),
    (["--scenario", "seed003", "--seeds", "abc"], "--seeds abc"),
    (["--scenario", "seed003", "--seeds", "2", "--group-by", "foo"], "--group-by foo"),
])
def test_a_wrong_command_line_value_is_refused_naming_the_option(tmp_path, capsys, argv, option):
    """Before: 'command line: campaign.seeds: ...' (the campaign file's key, not the option)."""
    rc, out, err = _run(capsys, "campaign", *argv, "--out", tmp_path / "c")
    assert rc == 2 and option in err and "campaign.seeds" not in err and "campaign.group_by" not in err


@pytest.mark.parametrize("workers", ["0", "-1"])
def test_workers_below_one_is_refused_not_replaced(tmp_path, capsys, workers):
    """Before: --workers 0 ran on every core (0 taken as 'not given'), -1 on one."""
    rc, out, err = _run(capsys, "campaign", "--scenario", "seed003", "--seeds", "1",
                        "--workers", workers, "--out", tmp_path / "c")
    assert rc == 2 and f"--workers {workers}" in err
    assert not (tmp_path / "c").exists()


def test_campaign_help_gives_the_real_default_out(capsys):
    """Before: --help said runs/campaign_NAME; the campaign goes to runs/campaigns/NAME."""
    with pytest.raises(SystemExit):
        cli.main(["campaign", "--help"])
    out = " ".join(capsys.readouterr().out.split())
    assert "runs/campaigns/NAME" in out and "runs/campaign_NAME" not in out


def test_campaign_prints_its_headline_figures(tmp_path, capsys):
    """Before: the campaign ended with the aggregate's path and no figure."""
    f = tmp_path / "tiny.toml"
    f.write_text(TINY_CAMPAIGN)
    rc, out, err = _run(capsys, "campaign", f, "--seeds", "2", "--out", tmp_path / "c", "--workers", "1")
    assert rc == 0, err
    assert "2 run(s): 2 computed, 0 already done" in out
    assert "horizontal_error_final" in out and "+-" in out and "heading_error_final" in out
    # the progress (with the count) goes to stderr, also on a pipe
    assert "2/2 runs" in err


def test_budget_json_is_valid_json_when_a_run_has_no_error(capsys):
    """Before: 'Infinity' (rel. differences over a run whose error is zero),
    which no JSON reader takes."""
    rc, out, err = _run(capsys, "budget", "seed003", "--hours", "0.01", "--variant", "0", "--check", "--json")
    assert rc == 0, err
    assert "Infinity" not in out and "NaN" not in out
    res = json.loads(out, parse_constant=lambda c: pytest.fail(f"not JSON: {c}"))
    rows = res["variants"][0]["rows"]
    nulls = [r for r in rows if "rel_max" in r and (r["rel_max"] is None or r["rel_final"] is None)]
    assert nulls and all("rel_null" in r and r["rel_null"] for r in nulls)


def test_emit_json_never_writes_nan_or_infinity(capsys):
    """Every --json goes through common.emit_json: NaN and inf become null,
    each listed under null_values with its reason."""
    from argparse import Namespace

    from pyins.cli.common import emit_json
    emit_json(Namespace(json=True), {"a": math.inf, "b": [1.0, math.nan], "c": {"d": -math.inf}})
    out = capsys.readouterr().out
    res = json.loads(out, parse_constant=lambda c: pytest.fail(f"not JSON: {c}"))
    assert res["a"] is None and res["b"] == [1.0, None] and res["c"]["d"] is None
    assert set(res["null_values"]) == {"a", "b[1]", "c.d"}


def test_budget_prints_a_line_per_firmware_run_and_rows_as_they_come(capsys):
    """Before: silent for the whole --check (24 s at 24 h), then every row at once."""
    import io
    import sys
    lines = []

    class Tee(io.StringIO):
        def write(self, s):
            lines.append(("err", s))
            return len(s)
    rc = None
    real_err = sys.stderr
    sys.stderr = Tee()
    try:
        import builtins
        real_print = builtins.print

        def tracking_print(*a, file=None, **k):
            if file is None or file is sys.stdout:
                lines.append(("out", " ".join(map(str, a))))
            real_print(*a, file=file, **k)
        builtins.print = tracking_print
        try:
            rc = cli.main(["budget", "seed003", "--hours", "0.01", "--variant", "1", "--check"])
        finally:
            builtins.print = real_print
    finally:
        sys.stderr = real_err
    capsys.readouterr()
    assert rc == 0
    kinds = [(k, t) for k, t in lines if t.strip()]
    runs = [i for i, (k, t) in enumerate(kinds) if k == "err" and "firmware run" in t]
    rows = [i for i, (k, t) in enumerate(kinds) if k == "out" and "model N" in t]
    assert len(runs) >= 3 and "s left" in kinds[runs[2]][1]
    # a row comes before the next firmware run starts
    assert rows and rows[0] < runs[-1]


def test_budget_too_short_is_refused_naming_the_duration(capsys):
    """Before: --hours 0.001 stopped with 'internal error IndexError'."""
    rc, out, err = _run(capsys, "budget", "seed003", "--hours", "0.001")
    assert rc == 2 and "duration" in err and "--hours" in err and "internal error" not in err


def test_budget_of_an_aligning_scenario_names_the_scenario_keys(capsys):
    """Before: 'run_budget: the linear model starts navigating at t = 0' (a
    Python function, no key of the scenario)."""
    rc, out, err = _run(capsys, "budget", "seed000_static", "--hours", "1")
    assert rc == 2 and "run_budget" not in err
    assert "firmware.coarse_time" in err and "firmware.fine_time" in err


def test_group_std_bars_are_labelled(tmp_path, capsys, monkeypatch):
    """Before: plots/group_std.png's bars had no label and no value (the
    legend showed only the paper's line)."""
    import matplotlib.figure
    texts = {}
    save = matplotlib.figure.Figure.savefig

    def keep(fig, path, *a, **k):
        texts[str(path)] = ([t.get_text() for ax in fig.axes for t in ax.texts],
                            [h for ax in fig.axes for h in ax.get_legend_handles_labels()[1]])
        return save(fig, path, *a, **k)
    monkeypatch.setattr(matplotlib.figure.Figure, "savefig", keep)
    rc, out, err = _run(capsys, "campaign", "--scenario", "seed000_static", "--grid", "duration=0.05 h",
                        "--seeds", "2", "--workers", "1", "--out", tmp_path / "c")
    assert rc == 0, err
    values, legend = next(v for p, v in texts.items() if p.endswith("group_std.png"))
    assert values and all(v for v in values)
    assert any("std" in h for h in legend)


def test_seed002_experiments_say_they_run_four_variants():
    """Before: their title and description named three schemes; they run four."""
    from pyins import scenario
    for name in ("seed002_exp1", "seed002_exp2"):
        scn = scenario.load(name)
        assert len(list(scn.runs())) == 4
        assert "four variants" in " ".join(scn.data["description"].split())
        assert "literal and derived" in scn.title


def test_a_campaign_whose_runs_fail_says_so_without_internal_error(tmp_path, capsys, monkeypatch):
    """Before: CampaignError (a RuntimeError) reached main as 'internal
    error CampaignError: ... (rerun with --debug)'."""
    from pyins.campaign import execute

    def failing(task):
        raise ValueError("the firmware stopped")
    monkeypatch.setattr(execute, "_run_point", failing)
    rc, out, err = _run(capsys, "campaign", "--scenario", "seed003", "--seeds", "2", "--workers", "1",
                        "--out", tmp_path / "c")
    assert rc == 1 and "internal error" not in err
    assert "2 of 2 runs failed" in err and "the firmware stopped" in err
    camp = json.loads((tmp_path / "c" / "campaign.json").read_text())
    assert len(camp["execution"]["failed"]) == 2 and camp["execution"]["notes"] == []


@pytest.mark.parametrize("hours", ["nan", "0", "-1", "1e12"])
def test_budget_hours_out_of_range_names_the_option(capsys, hours):
    """Before: 'seed003.toml (with overrides): duration: 'nan h' does not start
    with a number' (the scenario's key for a value given as --hours)."""
    rc, out, err = _run(capsys, "budget", "seed003", "--hours", hours)
    assert rc == 2 and err.startswith(f"pyins budget: --hours ") and "duration:" not in err


def test_progress_hook_for_long_steps(capsys):
    """common.progress_hook(args, label): the label on stderr and a
    progress(done, total) callable (a bar with the time left on a terminal);
    None with --quiet or --json (for pyins simulate's long writes)."""
    from argparse import Namespace

    from pyins.cli.common import progress_hook
    assert progress_hook(Namespace(quiet=True, json=False), "x") is None
    assert progress_hook(Namespace(quiet=False, json=True), "x") is None
    bar = progress_hook(Namespace(quiet=False, json=False), "writing x.bin")
    bar(10, 100)
    bar(100, 100)
    assert "writing x.bin" in capsys.readouterr().err
