"""Every built-in scenario runs from the CLI, in full (72 h for seed 002:
about a minute each on this machine), and its report shows each of the
paper's figures beside ours. What the figures are is the business of the
reproduction reports (docs/results); here: they are there and computed."""
import html
import json
import re

import pytest

from pyins import __main__ as cli
from pyins import scenario

NAMES = [name for name, _ in scenario.list_builtin()]


@pytest.mark.parametrize("name", NAMES)
def test_builtin_scenario_runs_and_reports_the_papers_figures(tmp_path, name):
    out = tmp_path / name
    assert cli.main(["run", name, "--out", str(out), "--quiet"]) == 0
    summary = json.loads((out / "summary.json").read_text())
    assert summary["complete"]
    page = html.unescape((out / "report.html").read_text())
    figures = (summary.get("paper") or {}).get("figures", [])
    if name.startswith("seed"):
        assert figures or name == "seed001_fine8", "a paper scenario without the paper's figures"
    for fig in figures:
        variant = re.escape(fig["variant"]) if fig.get("variant") else ".*?"
        rows = re.findall(rf"<tr><td>{fig['metric']}</td><td>{variant}</td>.*?</tr>", page)
        assert rows, f"{fig['metric']} missing from the report"
        for row in rows:
            cells = re.findall(r"<td>(.*?)</td>", row)
            # metric, variant, the paper's value, ours (a number with the paper's unit), verdict
            assert f"{fig['value']:g}" in cells[2]
            assert re.match(r"-?[0-9.]+(e[-+]?[0-9]+)? ", cells[3]), row
