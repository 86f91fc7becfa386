"""tools/papers/montecarlo.py's per-unit analysis (docs/results/montecarlo.md, "The paper's six
figures at once, and the schemes beside the shared up-gyro floor") on made-up units whose
answers are known: the nearest unit to the paper's six figures, the counts within 25 % and of
the paper's order, and the comparison once each unit's up-gyro share is taken out. No run."""
import os
import sys

import numpy as np
import pytest

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "..", "tools", "papers"))
import montecarlo as mc  # noqa: E402

PERIODS = list(mc.SEED002_EXPERIMENTS)
PAPER = {("none", PERIODS[0]): 8.57, ("two_position", PERIODS[0]): 3.70, ("flexible", PERIODS[0]): 2.97,
         ("none", PERIODS[1]): 16.13, ("two_position", PERIODS[1]): 12.90, ("flexible", PERIODS[1]): 1.98}
#: the up drift's response per 0.003 deg/h (north, east nmi): the same for every scheme
UP = {PERIODS[0]: [0.0, 6.0], PERIODS[1]: [0.0, 5.9]}


def papers():
    from pyins.units import NMI_TO_M
    return {k: {"horizontal_error_final": {"value_si": v * NMI_TO_M}} for k, v in PAPER.items()}


def units(n=40):
    """Made-up units: each scheme's own error along north (the up share along east, the
    drawn eps_U's), flexible's own error 1 nmi against traditional's 2 in the even units and
    3 against 2 in the odd ones; unit 7's six final magnitudes are the paper's figures."""
    vec = {}
    for d in range(n):
        k = mc.up_gyro_dph("seed002", d) / 0.003
        own = {"none": 4.0, "two_position": 2.0, "flexible": 1.0 if d % 2 == 0 else 3.0}
        vec[d] = {f"{s}|{p}": [own[s], k * UP[p][1], 0.0] for s in mc.PAPER_SCHEMES for p in PERIODS}
    # unit 7: its final magnitudes are the paper's figures
    k = mc.up_gyro_dph("seed002", 7) / 0.003
    for (s, p), v in PAPER.items():
        e = k * UP[p][1]
        vec[7][f"{s}|{p}"] = [float(np.sqrt(max(v * v - e * e, 0.0))), e, 0.0]
    return vec


def test_nearest_unit_and_counts():
    j = mc.joint(units(), papers(), UP)
    assert j["nearest"]["draw"] == 7
    # its up share (0.14 x 5.9-6.0 nmi) is below every figure, so its magnitudes are the paper's
    assert j["nearest"]["rms_nmi"] < 1e-9
    assert j["all_six_within_25pct"]["count"] >= 1


def test_the_shared_up_share_is_taken_out():
    vec = units()
    del vec[7]
    j = mc.joint(vec, papers(), UP)
    fl_tr = [p for p in j["beyond_floor"] if p["better"] == "flexible" and p["worse"] == "two_position"]
    # flexible's own error is the smaller exactly in the even units, whatever their eps_U
    evens = sum(1 for d in vec if d % 2 == 0)
    for p in fl_tr:
        assert p["wins_beyond_floor"] == evens and p["n"] == len(vec)
    # the traditional scheme's own error (2) is below no rotation's (4) in every unit
    for p in j["beyond_floor"]:
        if p["better"] == "two_position":
            assert p["wins_beyond_floor"] == len(vec)


def test_paper_set_distance():
    j = mc.joint(units(), papers(), UP, paper_set=[PAPER[(s, p)] + 1.0 for p in PERIODS for s in mc.PAPER_SCHEMES])
    assert j["paper_set"]["rms_nmi"] == pytest.approx(1.0, abs=1e-12)
    assert j["paper_set"]["draws_nearer"] >= 1      # unit 7, at 0 nmi
