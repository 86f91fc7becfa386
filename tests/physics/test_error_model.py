"""The simulation agrees with error theory: static FIL runs with constant
gyro drifts only (0.01 deg/h on each gyro, no other error), without and
with modulation (seed 003's single-position scheme), against the linear
static-INS error model of pyins.analysis driven by the same drifts
projected through the recorded table angle. At 6, 12 and 24 h the heading,
level and position errors agree within 10 % of each quantity's scale (its
largest model value over the day: a relative test at a zero crossing would
say nothing).

The error budget (issue 16, below): the model extended with scale-factor
and misalignment errors under the run's table angle and ship attitude
history (pyins.analysis.error_budget), each source against a run of the
firmware with that error alone, the misalignment-times-tilt case among them."""
import json

import numpy as np
import pytest

from pyins import analysis, fil, metrics, sim
from pyins.reference import attitude, earth
from pyins import units

DEG = units.DEG_TO_RAD
LAT = 34.0 * DEG
YAW = -30.0 * DEG
HOURS = np.array([6.0, 12.0, 24.0])


@pytest.mark.parametrize("scheme", [0, 1])
def test_static_run_matches_linear_error_model(scheme):
    m = sim.Static(LAT, 0.0, 0.0, 0.0, 0.0, YAW)
    errors = sim.SensorErrors(gyro_bias=np.full(3, 0.01 * units.DPH_TO_RPS))
    res = fil.run_fil(m, 24 * 360_000, config=dict(index_scheme=scheme), errors=errors, every=100)
    e = metrics.nav_errors(res)
    eps_n = analysis.table_projected(errors.gyro_bias, [0.0, 0.0, YAW], res.plant["tick"] * 0.01,
                                     res.plant["alpha_rad"])
    grid = np.arange(1, 25) * 3600.0
    model = analysis.static_error_model(LAT, grid, eps_n, step_s=0.5)
    k_sim = (HOURS * 3600).astype(int) - 1      # records every 1 s from t = 1 s
    k_mod = (HOURS - 1).astype(int)
    quantities = {
        "heading": (e.att_n_rad[:, 2], model.att_n_rad[:, 2]),
        "level E": (e.att_n_rad[:, 0], model.att_n_rad[:, 0]),
        "level N": (e.att_n_rad[:, 1], model.att_n_rad[:, 1]),
        "north": (e.north_m, model.north_m),
        "east": (e.east_m, model.east_m),
    }
    for name, (sim_q, mod_q) in quantities.items():
        scale = np.abs(mod_q).max()
        diff = np.abs(sim_q[k_sim] - mod_q[k_mod])
        print(f"scheme {scheme} {name}: sim {sim_q[k_sim]}, model {mod_q[k_mod]}, scale {scale:.3g}")
        assert np.all(diff <= 0.1 * scale), name
    if scheme == 1:
        # what modulation cannot remove: the up gyro's drift, i.e. the part of
        # the drift along the Earth's axis that feeds the longitude error
        assert model.horizontal_m[-1] > 1000.0


@pytest.mark.parametrize("label", ["traditional two-position", "flexible two-position"])
def test_drift_surviving_at_the_full_rate_equals_every_tick(label):
    """The proxy integrated over the swing and the table's history between
    1-s plant records (analysis.drift_surviving_of_run) equals the proxy of
    every 100 Hz record's IMU yaw (the same run recorded every tick), whole,
    stopped and turning, on seed 002 exp. 2 for 1 h. 2e-5 because the
    tick-sampled mean is itself a rectangle rule on 0.01 s steps of a 6 deg/s
    turn (measured 1e-5 at 1 h and 6 h; 1 Hz records differ from every tick
    by up to 2.7e-4 at 1 h: the test fails on a sampled proxy)."""
    from pyins import runs, scenario
    sc = scenario.load("seed002_exp2")
    got = {}
    for every in ("1 s", "0.01 s"):
        spec = next(s for s in sc.with_overrides({"duration": "1 h", "record_every": every}).runs()
                    if s.label == label)
        got[every] = (spec, runs.run(spec))
    spec, res = got["1 s"]
    cont = analysis.drift_surviving_of_run(spec.motion, res, spec.config)
    out = got["0.01 s"][1].outputs
    psi, stopped = out["yaw_p_rad"], np.asarray(out["index_state"]) != 2
    every_tick = (analysis.drift_surviving(psi), analysis.drift_surviving(psi, stopped),
                  analysis.drift_surviving(psi, ~stopped))
    np.testing.assert_allclose(cont, every_tick, rtol=0, atol=2e-5)


def test_drift_surviving_proxy():
    """The proxy of docs/papers.md, seed 002 §10: a fixed IMU keeps all of a
    constant drift (1), a uniform full turn cancels it (0 to rounding), and the masked parts add
    up as vectors to the whole."""
    assert analysis.drift_surviving(np.full(100, 0.3)) == pytest.approx(1.0, abs=1e-15)
    turn = np.linspace(0.0, 2 * np.pi, 3600, endpoint=False)
    assert analysis.drift_surviving(turn) < 1e-15
    # the first half turn alone leaves |sum of [cos, sin]| = 1/sin(pi/3600) of 3600 samples
    half = turn < np.pi
    assert analysis.drift_surviving(turn, half) == pytest.approx(1.0 / np.sin(np.pi / 3600) / 3600, rel=1e-9)
    assert analysis.drift_surviving(turn, half) == pytest.approx(analysis.drift_surviving(turn, ~half), rel=1e-9)


# ---------------------------------------------------------------------------
# The error budget (issue 16): scale factors and misalignments under the
# actual table angle and ship attitude history, each source alone
# ---------------------------------------------------------------------------
from pyins import scenario  # noqa: E402


def _spec(name, hours, overrides=None):
    sc = scenario.load(name).with_overrides({"duration": f"{hours * 3600:g} s", "compare": None, "paper": None,
                                             **(overrides or {})})
    (spec,) = sc.runs()
    return spec


def test_discretization_matches_scipy_expm():
    """Phi and Gamma of the stepped model against scipy's expm of the augmented
    matrix (Van Loan): both are exact to rounding, 1e-12 relative leaves room for
    the series' and the squarings' roundings only."""
    from scipy.linalg import expm
    f, gg, ga = analysis.error_matrix(LAT, 380.0)
    g = np.hstack([gg, ga])
    for h in (0.01, 1.0, 600.0):            # 600 s: the scaling and squaring branch
        phi, gam = analysis.discretize(f, g, h)
        aug = np.zeros((13, 13))
        aug[:7, :7], aug[:7, 7:] = f * h, g * h
        ref = expm(aug)
        assert np.abs(phi - ref[:7, :7]).max() <= 1e-12 * np.abs(ref[:7, :7]).max()
        assert np.abs(gam - ref[:7, 7:]).max() <= 1e-12 * np.abs(ref[:7, 7:]).max()


def test_stepped_model_equals_rk4_static_model():
    """Constant eps^n and nabla^n: the exactly stepped model (1 s steps) and the
    RK4 static model (0.5 s) integrate the same equations; at 6 h they agree to
    1e-6 of each quantity's scale (RK4's error ~ (omega_s h)^4 per step)."""
    eps = np.array([0.002, -0.003, 0.004]) * units.DPH_TO_RPS
    nab = np.array([30.0, -20.0, 0.0]) * units.UG_TO_MPS2
    k = 6 * 3600
    times, states = analysis.propagate_errors(LAT, 0.0, 1.0, np.tile(eps, (1, k, 1)), np.tile(nab, (1, k, 1)))
    ref = analysis.static_error_model(LAT, np.array([3600.0, 6 * 3600.0]), eps, nab, step_s=0.5)
    for i, t in enumerate((3600, 6 * 3600)):
        x = states[0, t - 1]
        assert times[t - 1] == t
        assert np.abs(x[:3] - ref.att_n_rad[i]).max() <= 1e-6 * np.abs(ref.att_n_rad).max()
        assert np.abs(x[3:5] - ref.vel_n_mps[i]).max() <= 1e-6 * np.abs(ref.vel_n_mps).max()


def test_table_history_places_the_turns_start():
    """A table at rest that starts turning at 6 deg/s 0.37 s into a 1-s record
    interval (a motor that reaches its rate within a tick): the kinked
    reconstruction gives the angle exactly (1e-12 rad), straight lines between
    the records are off by 6 deg/s x 0.37 x 0.63 s = 1.4 deg there."""
    r = 6.0 * DEG
    t_rec = np.arange(1.0, 6.0)
    true = lambda t: r * np.maximum(0.0, t - 2.37)          # noqa: E731
    rate = np.where(t_rec > 2.37, r, 0.0)
    fine = np.linspace(0.0, 5.0, 5001)
    for kinks, bound in ((True, 1e-12), (False, 1.5 * DEG)):
        tab = analysis.table_history(t_rec, true(t_rec), rate, kinks=kinks)
        k = np.minimum((fine // 1.0).astype(int), 4)
        tt = fine - tab.t0[k]
        tau = tab.t_kink[k] - tab.t0[k]
        alpha = tab.alpha0[k] + tab.rate0[k] * np.minimum(tt, tau) + tab.rate1[k] * np.maximum(0.0, tt - tau)
        err = np.abs(alpha - true(fine)).max()
        assert err <= bound
        if not kinks:
            assert err > 1.0 * DEG          # the reconstruction is what makes the difference


def test_drive_of_a_bias_on_a_fixed_ship_is_its_projection():
    """A gyro bias on a ship at rest with the table fixed at 30 deg: the mean eps^n
    over every interval is C_b^n Rz(30 deg) b (to rounding), and a scale factor
    sees the Earth's rate only (|eps| = 10 ppm x 15 deg/h)."""
    euler = np.array([1.0, -2.0, -15.0]) * DEG
    m = sim.Static(LAT, 0.0, 0.0, *euler)
    b = np.array([1.0, -2.0, 3.0]) * 0.001 * units.DPH_TO_RPS
    tab = analysis.table_history(np.arange(1.0, 11.0), np.full(10, 30 * DEG), np.zeros(10), alpha0=30 * DEG)
    eps, nab = analysis.error_drive(m, tab, [sim.SensorErrors(gyro_bias=b),
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
    that knows constant drifts only (what analysis had before) predicts
    nothing here."""
    mis = sim.preset("seed002").gyro_misalignment
    out = {}
    for deck, over in (("tilted", {}), ("level", {"motion.pitch": "0 deg", "motion.roll": "0 deg"})):
        spec = _spec("seed002_exp2", 12, {"initial_errors": None, "indexing.scheme": "two_position", **over})
        errors = sim.SensorErrors(gyro_misalignment=mis)
        res = fil.run_fil(spec.motion, spec.duration_ticks, config=spec.config, errors=errors, table=spec.table,
                          every=100)
        nav = metrics.nav_errors(res)
        budget = analysis.error_budget(spec.motion, res, errors, spec.config, keep_every=10)
        cmp = analysis.compare_with_run(budget.errors("gyro_misalignment"), nav)
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
    budget = analysis.error_budget(spec.motion, res, errors, spec.config, from_records=True, keep_every=10)
    cmp = analysis.compare_with_run(budget.errors("gyro_misalignment"), metrics.nav_errors(res))
    assert cmp["rel_max"] <= 0.02


@pytest.mark.parametrize("name, scheme", [("seed002_exp1", "flexible"), ("seed003", "single_position")])
def test_every_source_alone_and_their_sum(name, scheme):
    """Every source of the scenario's sensor set (gyro and accelerometer bias,
    scale factor, misalignment) and its initial errors, each alone through the
    firmware (6 h), and all together: the model within 10 % of each run's
    largest horizontal error (issue 16's line; measured <= 0.05 %). A source
    whose run stays below 1 m (seed 002's uniform accelerometer scale factor acts
    along the held vertical only: exactly nothing horizontal) is held in
    absolute terms: within 0.1 m."""
    spec = _spec(name, 6, {"indexing.scheme": scheme})
    rows, budget = analysis.run_budget(spec, check=True)
    names = {r["source"] for r in rows}
    assert set(analysis.SOURCES) <= names and "sum" in names
    assert (analysis.INITIAL in names) == name.startswith("seed002")
    assert rows[-1]["source"] == analysis.NOISE and rows[-1]["one_sigma"]     # not checked here
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
        assert [r["source"] for r in v["rows"]] == list(analysis.SOURCES) + ["sum", analysis.NOISE]
        assert v["rows"][-1]["one_sigma"] and v["rows"][-1]["model_final_m"] > 0.0
        assert all(analysis.budget_verdict(r)[0] for r in v["rows"][:-1])
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
            budget = analysis.error_budget(spec.motion, res, {}, spec.config, keep_every=600,
                                           noise=(e.gyro_arw, e.accel_vrw))
            assert budget.names == [] and budget.time_s[-1] == nav.time_s[-1]
        x = np.array([nav.north_m[-1], nav.east_m[-1]])
        total += x @ np.linalg.solve(budget.noise_position_cov()[-1], x)
    lo, hi = chi2.ppf([0.005, 0.995], 2 * n)
    print(f"chi2({2 * n}) = {total:.1f}, 99 % bounds [{lo:.1f}, {hi:.1f}]")
    assert lo <= total <= hi
    assert not lo <= total / 4 <= hi and not lo <= total * 4 <= hi
