"""The moving-base fine alignment (fine_states = 12: position matching on a
moored ship) after 120 s of FIT coarse alignment, against the truth and the
theoretical limit, error-free and with seed 000's sensor errors; and its
integrity test when the waves exceed what the filter was told."""
import os
import sys

import numpy as np
import pytest

from pyins import native, scenario, sim
from pyins import units

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "..", "tools", "papers"))
from reproduce_seed000 import limit_euler, sensors  # noqa: E402

DEG = units.DEG_TO_RAD
ARCMIN = units.ARCMIN_TO_RAD
ARCSEC = units.ARCSEC_TO_RAD
LAT, LON = 34.246 * DEG, 108.910 * DEG


def align(m, seed=None, **extra):
    n = 60000
    dtheta, dv, _ = sim.exact_increments(m, n)
    errs = None
    if seed is not None:
        model, errs = sensors(seed=seed)
        dtheta, dv = model.apply(dtheta, dv)
    cfg = scenario.initial_config(m, None, coarse_ticks=12000, coarse_method=1, fine_ticks=48000,
                                fine_states=12, euler_b_rad=[0.0, 0.0, 0.0], **extra)
    rec = native.Firmware(cfg).run(native.make_samples(dtheta, dv), every=1000)
    truth = sim.truth_at(m, rec["tick"][-1:])
    d = rec["euler_b_rad"][-1] - truth.euler[0]
    d = (d + np.pi) % (2 * np.pi) - np.pi
    err = np.array([d[0], d[1], -d[2]])          # pitch, roll, marine heading
    lim = limit_euler(m, errs, 600.0) * ARCSEC if errs is not None else np.zeros(3)
    return rec, err - lim


@pytest.mark.parametrize("state", ["ideal", "general", "bad"])
@pytest.mark.parametrize("heading", [0, 240])
def test_error_free_moored_ship(state, heading):
    # Measured 0.01-0.21' heading and 0.18" level at 600 s: what the waves
    # (taken as white position noise) leave after 480 s. Bounds 0.5' / 0.5".
    # The static filters on the same data are 16-2400' off (test_integrity).
    rec, e = align(sim.moored(state, LAT, LON, 0.0, -heading * DEG))
    assert abs(e[2]) < 0.5 * ARCMIN and np.max(np.abs(e[:2])) < 0.5 * ARCSEC
    assert rec["fault_flags"][-1] == 0 and rec["state_flags"][-1] & 1
    assert 0.1 < rec["align_nis"][-1] < 2.0        # measured 0.36: R (0.5 m) above the waves' 0.2 m
    assert rec["kf_states"][-1] == 12


def test_with_sensor_errors_near_the_static_limit():
    # Seed 000's errors, general sea state, heading 60, 3 seeds: against the
    # limit 0.4-0.5' heading and 1.3" level (measured); the static 5-state
    # filter on the pure swing (its own model) reaches 0.1-0.7'. Bounds 1.5'
    # and 3" (the acceptance asks 1' and 3" for the median over 10 seeds;
    # tools/papers/moored_alignment.py measures it).
    for seed in range(3):
        rec, e = align(sim.moored("general", LAT, LON, 0.0, -60 * DEG), seed=seed)
        assert abs(e[2]) < 1.5 * ARCMIN, (seed, e / ARCMIN)
        assert np.max(np.abs(e[:2])) < 3.0 * ARCSEC, (seed, e / ARCSEC)
        assert rec["fault_flags"][-1] == 0


def test_waves_beyond_the_configured_displacement_are_flagged():
    # Told 2 cm of surge and sway where the ship moves 0.3 m: the position
    # innovations are ~100 sigma, the NIS window mean ~1e3: inconsistent.
    rec, _ = align(sim.moored("general", LAT, LON, 0.0, -60 * DEG), fine_pos_sigma_m=0.02)
    assert rec["fault_flags"][-1] & native.lib.PYINS_FAULT_ALIGN_INCONSISTENT
    assert not rec["state_flags"][-1] & 1
