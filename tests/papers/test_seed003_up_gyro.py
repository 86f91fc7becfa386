"""Seed 003's < 1.1 nmi and its up gyro (docs/results/seed003.md, "The up gyro the paper's bound
needs"): on the single-position scheme's 24-h table history, with the horizontal drifts and the
accelerometer biases as stated, no up drift of the stated sign (not even zero) keeps the
linear model's maximum below 1.1 nmi; only an up drift of the opposite sign does. One 24-h
closed-loop run of the rotating scheme with the constant errors only (a few seconds)."""
import os
import sys

import numpy as np
import pytest

from pyins import analysis, run_scenario

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "..", "tools", "papers"))
import reproduce_seed003 as tool  # noqa: E402


@pytest.fixture(scope="module")
def scan():
    sc = tool.load(24.0, 1).with_overrides(tool.BIASES_ONLY)
    spec = next(s for s in sc.runs() if s.config["index_scheme"])
    res = run_scenario.run(spec)
    lat, e = spec.motion.lat, spec.errors
    grid = np.arange(1, 24 * 12 + 1) * 300.0
    up = analysis.predict_static_fil(res, lat, np.zeros(3), np.array([0.0, 0.0, e.gyro_bias[2]]),
                                     np.zeros(3), grid)
    return tool.up_gyro_scan(res, lat, e, up, grid)


def test_without_the_up_gyro_the_bound_is_not_met(scan):
    # measured 1.56 nmi: held above 1.3 nmi (0.2 nmi of margin over the bound, more than the
    # noise's 1 sigma, 0.18 nmi, that the model leaves out)
    assert scan["scan_without_up_max_nmi"] > 1.3


def test_only_an_up_drift_of_the_opposite_sign_meets_it(scan):
    lo, hi = scan["scan_up_dph_meeting_1.1nmi"]
    # measured -0.0016 .. -0.0007 deg/h: the whole range below zero
    assert lo < hi < 0.0
    # the stated +0.003 deg/h gives 3.57 nmi (the firmware run with the constant errors: 3.573)
    assert scan["scan_stated_max_nmi"] == pytest.approx(3.573, abs=0.01)
