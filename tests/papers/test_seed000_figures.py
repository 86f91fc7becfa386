"""Seed 000's Figs. 1 and 2 as tools/papers/reproduce_seed000.py computes them: the coarse
methods it accepts, the heading error against the truth (Fig. 1's way) and against the limit
(the ratio study), and the vectorised Euler-angle errors. Noise-free 250-s alignments at
heading 0 (a run takes a few hundredths of a second)."""
import os
import sys

import numpy as np
import pytest

from pyins import scenario
from pyins.reference import earth
from pyins.units import ARCMIN_TO_RAD as ARCMIN
from pyins.units import DPH_TO_RPS as DPH
from pyins.units import G0, UG_TO_MPS2

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "..", "tools", "papers"))
import reproduce_seed000 as tool  # noqa: E402


def test_methods_are_those_the_core_offers():
    assert tool.check_methods("triad") == ["triad"]
    with pytest.raises(SystemExit, match="not offered by this core"):
        tool.check_methods("triad,nonesuch")
    if "eq8" not in scenario.COARSE_METHODS:
        # seed 000's eq. 8 as printed: not in the core yet, and the message says so
        with pytest.raises(SystemExit, match="eq. 8 as printed is not offered yet"):
            tool.check_methods("triad,eq8")
    else:
        assert tool.check_methods("triad,eq8") == ["triad", "eq8"]


def test_fig1_against_truth_settles_on_each_drifts_limit():
    """Fig. 1 is plotted against the truth: without noise the heading error at 150 s is the
    limit of its drift (-eps_E / (W cos L) + tan L nabla_E / g, seed 001's limit, which
    seed 000's TRIAD shares), which moves by 5.5' from 0.01 to 0.05 deg/h; against the
    limit the two runs agree. 0.1': twice the largest noise-free distance from the limit
    measured at 100-200 s over the six biases (0.055'), 2 % of the 5.5' the limit moves."""
    out = {}
    for dph in (0.01, 0.05):
        o = {"sensors.gyro_bias": f"{dph} deg/h"}
        t, truth = tool.heading_series(o, [0], noise=False, vs_limit=False)
        _, vs_lim = tool.heading_series(o, [0], noise=False)
        k = tool.at(t, 150)
        out[dph] = truth[0, k], vs_lim[0, k]
        lim = truth[0, k] - vs_lim[0, k]
        assert abs(vs_lim[0, k]) < 0.1
        # the limit (seed 001 sec. 3.2) with the IMU's x axis east at heading 0 (levelled to
        # 0.5 deg: the projections are within 1 %): eps_E = the drift, nabla_E = 100 ug
        w_n = earth.OMEGA_IE * np.cos(tool.LAT)
        want = (-dph * DPH / w_n + np.tan(tool.LAT) * 100 * UG_TO_MPS2 / G0) / ARCMIN
        assert lim == pytest.approx(want, rel=0.02)
    assert out[0.05][0] - out[0.01][0] < -5.0
    assert abs(out[0.05][1] - out[0.01][1]) < 0.1


def test_euler_errors_of_a_slice_are_those_of_each_record():
    spec = tool.run_spec("static", 0, 0, {"duration": "30 s", "firmware.coarse_time": "30 s"})
    res, _ = tool.navigate(spec)
    k = np.arange(20, 30)
    rows = tool.euler_errors(res, k)
    assert rows.shape == (10, 3)
    for i, j in enumerate(k):
        assert np.array_equal(rows[i], tool.euler_errors(res, j))
