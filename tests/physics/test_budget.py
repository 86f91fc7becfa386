"""The error budget (pyins.budget): the linear error model extended with
scale-factor and misalignment errors under the run's table angle and ship
attitude history (pyins.budget.error_budget), each source against a run of
the firmware with that error alone, the misalignment-times-tilt case among
them; the noise's 1 sigma against Monte Carlo runs; `pyins budget`."""
import json
from dataclasses import replace

import numpy as np
import pytest

from pyins import analysis, contract, fil, metrics, scenario, sim
from pyins.budget import (INITIAL, NOISE, SOURCES, budget_verdict, compare_with_run, error_budget, error_drive,
                          run_budget)
from pyins.reference import attitude, earth
from pyins import units

DEG = units.DEG_TO_RAD
LAT = 34.0 * DEG


def _spec(name, hours, overrides=None):
    sc = scenario.load(name).with_overrides({"duration": f"{hours * 3600:g} s", "compare": None, "paper": None,
                                             **(overrides or {})})
    (spec,) = sc.runs()
    return spec


def test_drive_of_a_bias_on_a_fixed_ship_is_its_projection():
    """A gyro bias on a ship at rest with the table fixed at 30 deg: the mean eps^n
    over every interval is C_b^n Rz(30 deg) b (to rounding), and a scale factor
    sees the Earth's rate only (|eps| = 10 ppm x 15 deg/h)."""
    euler = np.array([1.0, -2.0, -15.0]) * DEG
    m = sim.Static(LAT, 0.0, 0.0, *euler)
    b = np.array([1.0, -2.0, 3.0]) * 0.001 * units.DPH_TO_RPS
    tab = analysis.table_history(np.arange(1.0, 11.0), np.full(10, 30 * DEG), np.zeros(10), alpha0=30 * DEG)
    eps, nab = error_drive(m, tab, [sim.SensorErrors(gyro_bias=b),
                                    sim.SensorErrors(gyro_scale=np.full(3, 10e-6))])
    want = attitude.euler_to_mat(euler) @ attitude.rot_z(30 * DEG) @ b
    assert np.abs(eps[0] - want).max() <= 1e-15 * np.abs(want).max() * 10
    assert np.allclose(np.linalg.norm(eps[1], axis=1), 10e-6 * earth.OMEGA_IE, rtol=1e-9)
    assert np.all(nab == 0.0)


def test_misalignment_times_tilt_times_swing():
    """Seed 002 exp. 2, the traditional two-position scheme, the six gyro
    misalignments (+10") as the only error, 12 h: the deck's tilt times the
    misalignment times the 6 deg/s yaw swing, locked to the table's turns,
    rectifies into a mean up drift (~0.005 deg/h, more than the up gyro's
    0.003 deg/h) that no vertical-axis table modulates. The model (driven
    by the run's table history and the analytic swing) follows the firmware
    within 2 % of the run's largest error over the whole run: measured
    0.05 % at 72 h; the model's own approximations (first order in the
    errors, the interval's forcing held constant) are below 0.1 %, while
    leaving out the tilt term changes the result by more than 10 % (checked
    below), so 2 % tells a right model from one that misses it. The model
    that knows constant drifts only (what pyins.analysis had before) predicts
    nothing here."""
    mis = sim.preset("seed002").gyro_misalignment
    out = {}
    for deck, over in (("tilted", {}), ("level", {"motion.pitch": "0 deg", "motion.roll": "0 deg"})):
        spec = _spec("seed002_exp2", 12, {"initial_errors": None, "indexing.scheme": "two_position", **over})
        errors = sim.SensorErrors(gyro_misalignment=mis)
        res = fil.run_fil(spec.motion, spec.duration_ticks, config=spec.config, errors=errors, table=spec.table,
                          every=100)
        nav = metrics.nav_errors(res)
        budget = error_budget(spec.motion, res, errors, spec.config, keep_every=10)
        cmp = compare_with_run(budget.errors("gyro_misalignment"), nav)
        print(deck, cmp, budget.eps_n_mean / units.DPH_TO_RPS)
        assert cmp["rel_max"] <= 0.02, deck
        out[deck] = (budget, nav)
    eps_u = out["tilted"][0].eps_n_mean[0, 2] / units.DPH_TO_RPS
    assert 0.004 <= eps_u <= 0.006                  # the rectified up drift [deg/h]
    assert abs(out["level"][0].eps_n_mean[0, 2] / units.DPH_TO_RPS) < 0.0002
    tilted, level = (out[d][1].horizontal_m[-1] for d in ("tilted", "level"))
    assert tilted > 1.1 * level                     # the tilt term is more than 10 % of the result at 12 h
    assert tilted > 0.5 * units.NMI_TO_M


def test_records_only_drive_is_close():
    """Without the motion (the firmware's 1-s attitude records alone) the same case
    comes within 2 % (measured 0.7 % at 72 h): one sample per interval misses the
    turns' corners and the swing's curvature inside it."""
    mis = sim.preset("seed002").gyro_misalignment
    spec = _spec("seed002_exp2", 6, {"initial_errors": None, "indexing.scheme": "two_position"})
    errors = sim.SensorErrors(gyro_misalignment=mis)
    res = fil.run_fil(spec.motion, spec.duration_ticks, config=spec.config, errors=errors, table=spec.table, every=100)
    budget = error_budget(spec.motion, res, errors, spec.config, from_records=True, keep_every=10)
    cmp = compare_with_run(budget.errors("gyro_misalignment"), metrics.nav_errors(res))
    assert cmp["rel_max"] <= 0.02


@pytest.mark.parametrize("name, scheme", [("seed002_exp1", "flexible"), ("seed003", "single_position")])
def test_every_source_alone_and_their_sum(name, scheme):
    """Every source of the scenario's sensor set (gyro and accelerometer bias,
    scale factor, misalignment) and its initial errors, each alone through the
    firmware (6 h), and all together: the model within 10 % of each run's
    largest horizontal error (the budget's acceptance line; measured <= 0.05 %). A source
    whose run stays below 1 m (seed 002's uniform accelerometer scale factor acts
    along the held vertical only: exactly nothing horizontal) is held in
    absolute terms: within 0.1 m."""
    spec = _spec(name, 6, {"indexing.scheme": scheme})
    rows, budget = run_budget(spec, check=True)
    names = {r["source"] for r in rows}
    assert set(SOURCES) <= names and "sum" in names
    assert (INITIAL in names) == name.startswith("seed002")
    assert rows[-1]["source"] == NOISE and rows[-1]["one_sigma"]     # not checked here
    for r in rows[:-1]:
        print(r["source"], r["rel_max"], r["diff_max_m"], r["run_max_m"], r["rel_level"], r["rel_heading"],
              r["rel_velocity"])
        if r["run_max_m"] >= 1.0:
            assert r["rel_max"] <= 0.10, r["source"]
            # the attitude and velocity errors too (measured <= 0.3 %)
            assert max(r["rel_level"], r["rel_heading"], r["rel_velocity"]) <= 0.10, r["source"]
        else:
            assert r["diff_max_m"] <= 0.1, r["source"]
    # the budget's sum (all sources on the all-errors run's table history) is the sum of its rows
    total = budget.errors()
    parts = [budget.errors(n) for n in budget.names]
    assert np.abs(total.north_m - sum(p.north_m for p in parts)).max() <= 1e-9 * np.abs(total.north_m).max()
    assert np.abs(total.att_n_rad - sum(p.att_n_rad for p in parts)).max() <= 1e-9 * np.abs(total.att_n_rad).max()


def test_budget_command(capsys):
    """`pyins budget SCENARIO --check --json`: one entry per variant, every source, the
    sum and the noise, each checked row within 10 % (or the 1 m floor: budget_verdict); a
    scenario with an alignment phase is refused with exit code 2 (the model starts
    navigating at t = 0)."""
    from pyins.__main__ import main
    assert main(["budget", "seed003", "--hours", "0.5", "--check", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert [v["label"] for v in out["variants"]] == ["no rotation", "single-position fwd/rev (seed 003)"]
    for v in out["variants"]:
        # seed 003's ARW: the noise's 1 sigma comes last, outside the sum and not checked
        assert [r["source"] for r in v["rows"]] == list(SOURCES) + ["sum", NOISE]
        assert v["rows"][-1]["one_sigma"] and v["rows"][-1]["model_final_m"] > 0.0
        assert all(budget_verdict(r)[0] for r in v["rows"][:-1])
    assert main(["budget", "seed000_static", "--hours", "0.1"]) == 2
    assert "alignment" in capsys.readouterr().err


def test_noise_sigma_matches_monte_carlo():
    """The noise's row: the 1 sigma of the (north, east) error that seed 002's ARW
    (0.0005 deg/sqrt(h)) and VRW (5 ug/sqrt(Hz)) drive, by covariance, against 12
    noise-only firmware runs (seeds 0-11, 2 h, exp. 2, traditional scheme). The sum of
    the final errors' squared Mahalanobis distances is chi-square with 24 degrees of
    freedom if the sigma is right: it must lie inside the two-sided 99 % bounds. The
    test has the power to see a sigma wrong by a factor 2: a variance 4 times smaller
    or larger puts the same draws outside them."""
    from scipy.stats import chi2
    spec = _spec("seed002_exp2", 2, {"initial_errors": None, "indexing.scheme": "two_position"})
    e = spec.errors
    noise = sim.SensorErrors(gyro_arw=e.gyro_arw, accel_vrw=e.accel_vrw)
    total, budget, n = 0.0, None, 12
    for seed in range(n):
        res = fil.run_fil(spec.motion, spec.duration_ticks, config=spec.config, errors=noise, table=spec.table,
                          every=100, seed=seed)
        nav = metrics.nav_errors(res)
        if budget is None:
            budget = error_budget(spec.motion, res, {}, spec.config, keep_every=600,
                                  noise=(e.gyro_arw, e.accel_vrw))
            assert budget.names == [] and budget.time_s[-1] == nav.time_s[-1]
        x = np.array([nav.north_m[-1], nav.east_m[-1]])
        total += x @ np.linalg.solve(budget.noise_position_cov()[-1], x)
    lo, hi = chi2.ppf([0.005, 0.995], 2 * n)
    print(f"chi2({2 * n}) = {total:.1f}, 99 % bounds [{lo:.1f}, {hi:.1f}]")
    assert lo <= total <= hi
    assert not lo <= total / 4 <= hi and not lo <= total * 4 <= hi


@pytest.mark.parametrize("preset", ["seed002", "seed003"])
def test_a_draw_is_the_sum_of_its_elements(preset):
    """The budget's Monte Carlo (tools/papers/budget_montecarlo.py) places a
    draw as the element responses times its coefficients: the basis times
    the coefficients gives the drawn errors back (to one rounding), and on a
    2 h run the budget of the draw itself equals the combination of the
    element budgets (the model is linear in each element) to 1e-9 of its
    size; an element outside the basis is refused."""
    from pyins.budget import element_coefficients, element_sources
    basis = element_sources(sim.sensors.PRESETS[preset])
    for d in (0, 3):
        drawn = sim.sensors.draw_random_constants(preset, d)
        c = element_coefficients(basis, drawn)
        for name in SOURCES:
            rebuilt = sum(ci * getattr(e, name) for ci, e in zip(c, basis.values()))
            np.testing.assert_allclose(rebuilt, getattr(drawn, name), rtol=1e-15, atol=1e-30, err_msg=name)
    spec = _spec("seed002_exp1", 2, {"indexing.scheme": "flexible", "record_every": "1 s"})
    res = fil.run_fil(spec.motion, spec.duration_ticks, config=spec.config, errors=sim.SensorErrors(),
                      table=spec.table, every=spec.every)
    whole = error_budget(spec.motion, res, sim.sensors.draw_random_constants(preset, 3), spec.config,
                         keep_every=10)
    parts = error_budget(spec.motion, res, basis, spec.config, keep_every=10)
    c = element_coefficients(basis, sim.sensors.draw_random_constants(preset, 3))
    x_whole = whole.states.sum(axis=0)
    x_parts = np.tensordot(c, parts.states[:len(basis)], axes=1) + parts.states[len(basis)]
    assert parts.names[-1] == INITIAL and whole.names[-1] == INITIAL
    assert np.abs(x_parts - x_whole).max() <= 1e-9 * np.abs(x_whole).max()
    with pytest.raises(ValueError, match="not in the basis"):
        element_coefficients(element_sources(sim.SensorErrors(gyro_bias=np.array([1e-9, 0.0, 0.0]))),
                             sim.SensorErrors(gyro_bias=np.array([1e-9, 1e-9, 0.0])))


def test_the_model_refuses_what_it_does_not_model():
    """outside_model names the reason for an alignment phase, a free
    vertical channel, external references, a damped or integrated mode and
    a moving ship; a fixed ship navigating unaided passes."""
    from pyins.budget import outside_model
    assert outside_model(_spec("seed002_exp1", 1)) is None
    cases = {"alignment phase": {"firmware.coarse_time": "60 s"},
             "vertical channel": {"firmware.vertical_mode": "free"},
             "undamped navigation": {"firmware.nav_mode": "damped"}}
    for words, over in cases.items():
        assert words in outside_model(_spec("seed002_exp1", 1, over)), words
    spec = _spec("seed002_exp1", 1)
    assert "fixed position" in outside_model(replace(spec, motion=sim.default_voyage()))
    refs = np.zeros(1, dtype=contract.REF_DTYPE)
    assert "external" in outside_model(replace(spec, refs=refs))
