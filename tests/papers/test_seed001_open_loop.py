"""Seed 001 open loop, as the paper's Fig. 2 ran it, beside feedback: the gap statistics of
tools/papers/reproduce_seed001.py are computed as docs/results/seed001.md says, and the open
loop's extra gaps are the second-order terms of the 60' initial heading error.

One noise seed, the reduced 5-state filter, the built-in scenario seed001_fine5 (1200 s: a
run takes well under a second)."""
import os
import sys

import numpy as np
import pytest

from pyins import analysis
from pyins.reference import earth
from pyins.units import ARCMIN_TO_RAD as ARCMIN
from pyins.units import DPH_TO_RPS as DPH

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "..", "tools", "papers"))
import reproduce_seed001 as tool  # noqa: E402


@pytest.fixture(scope="module")
def both():
    return {corr: tool.run(5, 0, corr) for corr in tool.CORRECTIONS}


def test_gap_is_reduced_truth_minus_estimate(both):
    """The documented gap, (true - estimate) - limit, is for the 5-state filter the
    transformed truth of seed 001 eq. 21 (analysis.reduced_truth) minus the filter's estimate:
    the driver's sign conventions (NavErrors, alignment_limits, the eps estimates) agree."""
    for corr, (res, e, lim) in both.items():
        out = res.outputs[-1]
        # the last record follows the end-of-alignment correction: the phi estimate is 0
        # and the reported attitude's error is the residual phi (either correction mode)
        assert np.all(out["kf_x"][:3] == 0.0)
        want = analysis.reduced_truth(lim, e.att_n_rad[-1]) - np.r_[0.0, 0.0, 0.0, out["kf_x"][3:5]]
        got = tool.gaps(res, e, lim, 5) * tool._SCALE
        # 1e-12 rad, 1e-18 rad/s: rounding of the two orders of the same sums
        np.testing.assert_allclose(got[:3], want[:3], rtol=0, atol=1e-12)
        np.testing.assert_allclose(got[3:], want[3:], rtol=0, atol=1e-18)


def test_open_loop_gap_is_the_second_order_term(both):
    """Open loop the filter reads the (phi x)^2 / 2 part of the attitude error as tilt
    (docs/results/seed001.md): its phi_E gap lies below the feedback one by phi_U phi_N / 2,
    60' x 10' / 2 = 0.087' for the paper's initial error, and its eps_N gap above by
    w_N phi_U^2 / 2 = 0.0019 deg/h. Both runs draw the same noise, so their difference is
    the deterministic term; the driver predicts it from the run's uncorrected phi."""
    go, gf = (tool.gaps(*both[c], 5) for c in ("open_loop", "feedback"))
    pred = tool.second_order(both["open_loop"][0], both["open_loop"][1], tool.LAT)
    # physical margin: 2/3 of the 0.087' term; with feedback phi falls to the limit (< 1')
    # and the term to 1e-5', so a driver that ran feedback twice fails here
    assert go[0] - gf[0] < -0.06
    # 0.01': 4x the largest residual seen over 30 seeds (0.0022'), 12 % of the term
    assert abs((go[0] - gf[0]) - pred[0]) < 0.01
    # 0.0004 deg/h: 4x the largest residual over 30 seeds (1e-4 deg/h), 20 % of the term
    assert abs((go[3] - gf[3]) - pred[2]) < 4e-4
    # and the prediction itself is the paper's set-up's size (60' heading, 10' level, 34.246 N)
    w_n = earth.OMEGA_IE * np.cos(tool.LAT)
    assert pred[0] == pytest.approx(-(60 * ARCMIN) * (10 * ARCMIN) / 2 / ARCMIN, rel=0.1)
    assert pred[2] == pytest.approx(w_n * (60 * ARCMIN) ** 2 / 2 / DPH, rel=0.1)


def test_statistics_are_median_and_5_95_percentiles():
    """statistics() is (median, 5 %, 95 %) per state over the seeds (numpy's linear
    interpolation): on 0 .. 20 the 5 % point is 1.0 and the 95 % point 19.0."""
    g = np.column_stack([np.arange(21.0), -np.arange(21.0)])
    med, p5, p95 = tool.statistics(g)
    assert med.tolist() == [10.0, -10.0]
    assert p5.tolist() == [1.0, -19.0] and p95.tolist() == [19.0, -1.0]
