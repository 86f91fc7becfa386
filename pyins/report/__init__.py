"""Every page and figure pyins writes from results it already has.

- `pyins.report.run`: a run directory's plots and report.html
  (``pyins report RUNDIR``; `render`);
- `pyins.report.campaign`: a campaign's aggregate.md and plots/
  (`pyins.campaign.aggregate` calls it);
- `pyins.report.plotting`: what the figures share (matplotlib on Agg, margins).

Both read only what was written or computed before (summary.json, the
variants' timeseries.npz, a campaign's aggregates): a report is re-rendered
without running anything. Units follow the papers, through `pyins.metrics`.
"""
from pyins.report.run import plot_alignment, plot_comparison, plot_errors, plot_table, render

__all__ = ["render", "plot_errors", "plot_alignment", "plot_table", "plot_comparison"]
