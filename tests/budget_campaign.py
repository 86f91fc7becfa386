"""The small campaign the tests of `pyins campaign --budget` share: seed
003's two schemes (no rotation, single-position), 4 units each, drawn from
seed 003's random constants, 2 h, records every 60 s."""

BUDGET_CAMPAIGN = """
[campaign]
scenario = "seed003"
seeds = 4
random_constants = "seed003"
group_by = ["indexing.scheme"]
compare = "drop"
[campaign.grid]
"indexing.scheme" = ["none", "single_position"]
[campaign.set]
duration = "2 h"
record_every = "60 s"
"""
