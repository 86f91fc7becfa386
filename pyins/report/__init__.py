"""Every page and figure pyins writes from results it already has.

- `pyins.report.run`: a run directory's plots and report.html
  (``pyins report RUNDIR``; `render`);
- `pyins.report.replay`: a replayed log's plots and report.html
  (``pyins replay``, and `render` of a replay directory);
- `pyins.report.campaign`: a campaign's aggregate.md and plots/
  (`pyins.campaign.aggregate` calls it);
- `pyins.report.plotting`: what the figures share (matplotlib on Agg, margins).

Both read only what was written or computed before (summary.json, the
variants' timeseries.npz, a campaign's aggregates): a report is re-rendered
without running anything. Units follow the papers, through `pyins.metrics`.
"""
import json
import os

from pyins.report import replay as _replay
from pyins.report import run as _run
from pyins.report.run import plot_alignment, plot_comparison, plot_errors, plot_table

__all__ = ["render", "is_replay_dir", "plot_errors", "plot_alignment", "plot_table", "plot_comparison"]


def is_replay_dir(run_dir):
    """True when ``run_dir`` was written by ``pyins replay``."""
    path = os.path.join(run_dir, "summary.json")
    try:
        with open(path, encoding="utf-8") as f:
            summary = json.load(f)
    except (OSError, ValueError):
        return False
    return isinstance(summary, dict) and _replay.is_replay(summary)


def render(run_dir, **kwargs):
    """The page and figures of a run directory (``pyins run``; ``kwargs`` go
    to `pyins.report.run.render`) or of a replay directory (``pyins
    replay``); returns the page's path."""
    if is_replay_dir(run_dir):
        return _replay.render(run_dir)
    return _run.render(run_dir, **kwargs)
