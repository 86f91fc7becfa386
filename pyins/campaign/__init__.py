"""Campaigns: grids and Monte-Carlo sets of scenario runs, aggregated per group.

A campaign is a base scenario (a built-in name or a TOML path), a grid of
overrides (dotted scenario keys -> lists of values, as
`pyins.scenario.Scenario.with_overrides` takes them), optional fixed
overrides applied to every run, noise seeds (a count or a list, optionally
turned into the scenario's ``seed`` by a formula) and the keys to group the
runs by. Every combination of grid values times every seed is one *point*;
each point is one scenario, validated when the campaign is built, and run
with `pyins.run_scenario.execute` into ``OUT/runs/<digest[:16]>`` where ``digest``
is `Scenario.digest` of the overridden scenario: runs are content
addressed, so a campaign that is run again (after a kill, a Ctrl-C, or with
more seeds) runs only what has no complete summary.json of that digest.

    >>> camp = load_campaign("seed000_static")       # a built-in, or a campaign .toml
    >>> camp = from_args("seed000_static", ["motion.heading=0 deg,60 deg"], 5)
    >>> result = run_campaign(camp, "runs/campaigns/x")   # doctest: +SKIP
    >>> run_campaign(camp, "runs/campaigns/x", scheduler="tcp://10.0.0.5:8786")  # doctest: +SKIP

The rooms:

- `pyins.campaign.grid`: values, grid strings, seeds and seed formulas as
  written (the command line, a campaign file);
- `pyins.campaign.spec`: the campaign itself (`Campaign`, `Point`),
  validated and expanded into points and groups; loading campaign files and
  the built-ins of pyins/builtin/campaigns/;
- `pyins.campaign.execute`: running the missing runs on a local process
  pool or a Dask cluster (`run_campaign`, `pending`);
- `pyins.campaign.aggregate`: the statistics over the runs of each group in
  data form, campaign.json, aggregate.csv and runs.csv (SI); aggregate.md
  and plots/ (the papers' units) are written by `pyins.report.campaign`.

The base scenario's [compare] (e.g. seed000_static compares five seeds):
``compare = "drop"`` removes it (and the base's [paper], whose figures may
name its variants: campaign.json keeps it), so each point is one run;
``"keep"`` runs every variant at every point and aggregates each variant
separately (keyed by its label); ``"auto"`` (default) drops it when the
campaign itself sets the compared key (a grid key, a fixed override, or
``seed`` when it has seeds), and keeps it otherwise. docs/campaigns.md is
the guide.
"""
from pyins.campaign.aggregate import STATS, aggregate
from pyins.campaign.execute import CampaignError, CampaignInterrupted, pending, run_campaign
from pyins.campaign.grid import parse_grid, parse_value
from pyins.campaign.spec import (Campaign, Point, builtin_path, default_out_dir, from_args, list_builtin,
                                 load_campaign, loads_campaign)
from pyins.units import ScenarioError

__all__ = ["Campaign", "Point", "CampaignError", "ScenarioError", "load_campaign", "loads_campaign",
           "from_args", "parse_grid", "parse_value", "run_campaign", "CampaignInterrupted", "aggregate", "pending",
           "list_builtin", "builtin_path", "default_out_dir", "STATS"]
