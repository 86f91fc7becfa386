"""Alignment below the static limit by indexing the table (the built-in
scenarios `pier_indexed` and `moored_indexed`, tools/indexed_alignment.py): coarse 120 s, then the
navigation filter aided by zero velocity with the table indexed between two
positions, against the static limit eps_E / (Omega cos L) of each draw of
seed 000's errors; and the same filter with the table fixed, which cannot
beat it (the indexing is what separates the drift from the heading)."""

import numpy as np
from scipy.stats import chi2

from pyins.units import ARCMIN_TO_RAD
from tools_loader import load_tool

DRAWS = range(12)           # two of each heading 0, 60, ... 300 deg


def _tool():
    return load_tool("indexed_alignment.py")


def test_indexing_beats_the_static_limit():
    tool = _tool()
    err, sig, lim = [], [], []
    for d in DRAWS:
        t, h, s, limit = tool.one(d, 60.0, static=False)
        k = int(np.searchsorted(t, 599.0))
        err.append(h[k])
        sig.append(s[k])
        lim.append(limit)
    err, sig, lim = map(np.abs, (err, sig, lim))
    print(f"\nmedian |heading| at 600 s: indexed {np.median(err) / ARCMIN_TO_RAD:.3f}', static limit "
          f"{np.median(lim) / ARCMIN_TO_RAD:.3f}'; NEES {np.mean((err / sig) ** 2):.2f}")
    # the bar: at most half the static limit (median over the draws);
    # measured 0.13 of it over 30 draws (docs/results/indexed_alignment.md)
    assert np.median(err) <= 0.5 * np.median(lim)
    # the filter's sigma says how sure it is: the NEES inside chi-square(n) / n's 95 % bounds
    n = len(err)
    assert chi2.ppf(0.025, n) / n <= np.mean((err / sig) ** 2) <= chi2.ppf(0.975, n) / n


def test_a_fixed_table_stays_at_the_static_limit():
    """The same filter and zero velocity, the table never moved: the heading
    error is pinned by the drift as the static limit says (the same sign, at
    least 0.7 of it: a fixed IMU converges towards the limit from the coarse
    start, 0.82 of it at worst over these draws when the test was written),
    nowhere near the indexed alignment's 0.13."""
    tool = _tool()
    from pyins import metrics, scenario
    from pyins.run_scenario import run
    from pyins.sim.sensors import random_constant_overrides
    for d in (0, 1, 3):
        _, _, _, limit = tool.one(d, 60.0, static=False)
        over = dict(random_constant_overrides("seed000", d), seed=d,
                    **{"motion.heading": f"{60 * (d % 6)} deg", "indexing.scheme": "none"})
        res = run(next(iter(scenario.load("pier_indexed").with_overrides(over).runs())))
        e = metrics.nav_errors(res)
        k = int(np.searchsorted(e.time_s, 599.0))
        assert e.att_n_rad[k, 2] / limit >= 0.7, (d, e.att_n_rad[k, 2], limit)


def test_a_moored_ship_with_gnss_beats_the_static_limit():
    """moored_indexed: the heaving, surging, swaying ship with its lever arm,
    FIT coarse 120 s, then the filter aided by GNSS (3 m, 0.05 m/s; the
    receiver's noise drawn per draw) with the table indexed: at most half
    the static limit (median over twelve draws: measured 0.27 of it; 0.38
    over 30, docs/results/indexed_alignment_moored_3m.md; over the first six
    alone 0.72: with a sigma of 1.37' against a limit of ~2.4', six draws
    are too few for a median), and the NEES inside chi-square(12) / 12's
    95 % bounds (measured 1.18; 1.14 over 30). Before the receiver's noise
    was drawn per draw every draw had the same noise and the NEES read 0.22:
    one noise draw's, not the filter's."""
    tool = _tool()
    err, sig, lim = [], [], []
    for d in range(12):
        t, h, s, limit = tool.one(d, 60.0, static=False, site="moored")
        k = int(np.searchsorted(t, 599.0))
        err.append(h[k])
        sig.append(s[k])
        lim.append(limit)
    err, sig, lim = map(np.abs, (err, sig, lim))
    assert np.median(err) <= 0.5 * np.median(lim)
    n = len(err)
    assert chi2.ppf(0.025, n) / n <= np.mean((err / sig) ** 2) <= chi2.ppf(0.975, n) / n


def test_the_mirror_aligns_alike():
    """The indexed alignments through the C++ core and through the NumPy
    mirror (firmware and plant), each of its 600 s: every decision
    identical (modes, indexing, references used and rejected), the floats
    within tests/engines.py's bounds (the NIS of the pier's zero velocity,
    0.001 m/s, to 1e-6 absolute: engines.py says why)."""
    from engines import assert_engines_agree
    from pyins import scenario
    from pyins.run_scenario import run
    for name in ("pier_indexed", "moored_indexed"):
        spec = next(iter(scenario.load(name).runs()))
        a = run(spec).outputs
        b = run(spec, engine="reference").outputs
        assert len(a) == len(b) and np.any(a["index_state"] != a["index_state"][0]), name
        assert_engines_agree(a, b, nis_abs=1e-6)
