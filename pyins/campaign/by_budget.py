"""A campaign's draws placed through the error budget instead of the closed
loop: thousands of production units for the cost of one closed-loop run per
grid point, held to the closed loop by a few runs drawn at random.

A campaign with ``random_constants`` (a sensor preset whose random constants
each seeds entry draws, docs/campaigns.md) spreads its units over the draws
0 .. seeds - 1, one closed-loop run each. The error budget
(`pyins.budget`) is linear in every element of the sensor errors, so per
grid point (a group of the campaign's points that differ only in the draw):

1. one closed-loop run of an error-free unit with the point's initial
   errors, records every 1 s: the table's history. Where the table follows
   a fixed schedule (no rotation, the fixed two- and four-position schemes)
   it is every unit's; where the firmware steers the stops from its own
   heading (the flexible schemes), a unit's heading error can move a stop,
   and the checks below measure what that costs;
2. the budget of that run with one source per non-zero element of the
   preset (`pyins.budget.element_sources`) and the initial errors, and the
   covariance the noise (ARW, VRW) drives;
3. draw d's final (north, east) error: the element responses times draw d's
   elements over the basis's (`pyins.budget.element_coefficients`), plus
   the initial errors' response, plus one draw of the noise from its final
   covariance (a generator seeded with (NOISE_SALT, d)), for any number of
   draws (beyond the campaign's seeds too: the draws are
   `pyins.sim.sensors.draw_random_constants`).

A grid point whose table is steered by the firmware's heading
(`pyins.budget.steered_table`) is marked ``steered``: there the budget
uses the error-free unit's stops for every unit, an approximation whose
error the checks measure (on seed 002's campaign, docs/results/
budget_montecarlo.md: every checked unit there turned its table otherwise,
and differed by up to 8.0 % for the literal flexible scheme, up to 131 %
for the derivation form).

The checks: ``checks`` distinct (grid point, draw) pairs picked at random
without replacement (a fixed seed), each run in the closed loop with that
draw's constants and no noise, against the budget's noise-free value
(saved as they finish, so a run stopped part-way resumes: ``kept``,
``on_check``). The figure is the final horizontal
error; the budget gives no maximum over time with noise (the noise is a
process, its covariance gives the final spread only). Each check also says
whether its table turned as the error-free unit's (the same true table
angle at every record tick both runs keep, the same motor starts and
commanded travel at the end), and if not, from when: where it did, the
budget used the unit's own table history and the difference is the
model's; where it did not, the difference is the steering's.

Refused (ValueError) where the budget's model does not hold
(`pyins.budget.outside_model`: an alignment phase, external references,
damping, a free vertical channel, a moving ship) or the campaign draws no
random constants.
"""
import concurrent.futures
import os
import signal
import time

import numpy as np

from pyins import budget, fil, metrics
from pyins.sim import sensors

__all__ = ["by_budget", "BudgetInterrupted", "NOISE_SALT"]

#: The noise draws' generator: seed (NOISE_SALT, draw), apart from every other stream.
NOISE_SALT = 0xB0D6E7
#: The seed of the checks' choice of (grid point, draw).
CHECK_SEED = 20261206
#: Checks when none are asked for (fewer if the campaign has fewer units to check).
DEFAULT_CHECKS = 10


class BudgetInterrupted(KeyboardInterrupt):
    """Ctrl-C (SIGINT) during the checks: ``.result`` is what `by_budget`
    returns, with every draw placed and the checks that had finished, and
    ``"interrupted": True``."""

    def __init__(self, result):
        super().__init__(f"interrupted after {len(result['checks'])} of {result['checks_planned']} checks")
        self.result = result


def _worker_init():
    """A pool worker leaves SIGINT to the parent, which stops the pool and
    keeps what has finished (a Ctrl-C at the terminal reaches the workers too)."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)


def grid_points(camp):
    """[(values as a sorted tuple, [points by draw])] in the campaign's order."""
    out = {}
    for p in camp.points:
        out.setdefault(tuple(sorted(p.values.items())), []).append(p)
    return [(k, sorted(v, key=lambda p: p.run)) for k, v in out.items()]


def _scenario(camp, point, every=None):
    over = dict(point.overrides)
    if every is not None:
        over["record_every"] = every
    return camp.base.with_overrides(over)


def _table_history(res):
    """What says whether two runs turned their tables alike: the plant's
    record ticks and true table angles, and the final record's motor
    starts and commanded travel (which count every move, between records
    too)."""
    last = res.outputs[-1]
    return {"tick": np.asarray(res.plant["tick"]), "alpha": np.asarray(res.plant["alpha_rad"]),
            "starts": int(last["index_motor_starts"]), "travel": float(last["index_travel_rad"])}


def same_table(model, check, dt):
    """(same, first_s): whether a check's table turned as the error-free
    unit's, bit for bit at every record tick both runs keep and in motor
    starts and travel at the end; first_s, the first such tick's time [s]
    where the angles differ (None if none does, or if only the end's counts
    differ)."""
    common, i, j = np.intersect1d(model["tick"], check["tick"], assume_unique=True, return_indices=True)
    differ = model["alpha"][i] != check["alpha"][j]
    first = float(common[np.argmax(differ)]) * dt if differ.any() else None
    same = first is None and model["starts"] == check["starts"] and model["travel"] == check["travel"]
    return same, first


def _model(task):
    """Steps 1 and 2 for one grid point (a worker's task): the final states
    and the error-free unit's table history."""
    scn, preset = task
    t0 = time.perf_counter()
    (spec,) = list(scn.runs())
    res = fil.run_fil(spec.motion, spec.duration_ticks, config=spec.config, errors=sensors.SensorErrors(),
                      table=spec.table, every=spec.every)
    basis = budget.element_sources(sensors.PRESETS[preset])
    b = budget.error_budget(spec.motion, res, basis, spec.config, keep_every=10,
                            noise=(spec.errors.gyro_arw, spec.errors.accel_vrw))
    final = b.states[:, -1, :]
    init = final[len(basis)] if b.names[-1] == budget.INITIAL else np.zeros(7)
    cov = b.noise_position_cov()[-1] if b.noise_cov is not None else np.zeros((2, 2))
    return {"final": final[:len(basis)], "initial": init, "noise_cov": cov, "scale": b.position_scale(),
            "table": _table_history(res), "dt": spec.dt, "seconds": time.perf_counter() - t0}


def _check(task):
    """One closed-loop check (a worker's task): final horizontal error [m]
    without noise, its table history (`_table_history`) and its seconds."""
    scn = task
    t0 = time.perf_counter()
    (spec,) = list(scn.runs())
    res = fil.run_fil(spec.motion, spec.duration_ticks, config=spec.config,
                      errors=budget.deterministic(spec.errors), table=spec.table, every=spec.every)
    return float(metrics.nav_errors(res).horizontal_m[-1]), _table_history(res), time.perf_counter() - t0


def coefficients(preset, draws):
    """(draws, S): every draw's elements over the basis of ``preset``."""
    basis = budget.element_sources(sensors.PRESETS[preset])
    return np.array([budget.element_coefficients(basis, sensors.draw_random_constants(preset, d))
                     for d in range(draws)])


def final_errors(model, coef, noise=True, first_draw=0):
    """(draws, 2) final (north, east) [m]: the budget's, with one noise draw each if ``noise``."""
    x = coef @ model["final"] + model["initial"]
    kn, ke = model["scale"]
    ne = np.column_stack([x[:, 5] * kn, x[:, 6] * ke])
    if noise and np.any(model["noise_cov"]):
        chol = np.linalg.cholesky(model["noise_cov"])
        z = np.array([np.random.default_rng([NOISE_SALT, first_draw + d]).standard_normal(2)
                      for d in range(len(coef))])
        ne = ne + z @ chol.T
    return ne


def by_budget(camp, draws, checks=0, workers=None, log=None, kept=None, on_check=None):
    """Place ``draws`` draws of ``camp``'s random constants through the
    budget at every grid point, and run ``checks`` closed-loop checks
    (None: `DEFAULT_CHECKS`, or every (grid point, draw) pair if fewer;
    more than there are pairs is refused). ``kept``: (checks planned, the
    checks done) of an earlier call on the same campaign and draws, stopped
    part-way: those that are the first of this call's picks (the same
    count planned, the same pairs in the same order: the picks are seeded)
    are taken as done, not run again. ``on_check(checks, planned)`` is
    called after every check that finishes (to save them as they come).
    Returns {"points": [{values, draws, final_m (draws,), final_clean_m,
    seconds_model}], "checks": [{values, draw, closed_loop_m, budget_m, rel,
    same_table, table_differs_from_s, seconds}], "seconds_budget",
    "seconds_checks", "workers"}: ``same_table`` says whether the check's
    table turned as the error-free unit's whose history the budget took
    (`same_table`), ``table_differs_from_s`` from when it did not."""
    preset = camp.random_constants
    if not preset:
        raise ValueError(f"campaign {camp.name!r} draws no random constants (campaign.random_constants): "
                         "the budget has nothing to place")
    if draws < 1 or (checks is not None and checks < 0):
        raise ValueError(f"draws must be >= 1 and checks >= 0, got {draws} and {checks}")
    workers = workers or os.cpu_count()
    say = log or (lambda text: None)
    pts = grid_points(camp)
    steered = []
    for values, group in pts:
        (spec,) = list(_scenario(camp, group[0]).runs())
        refusal = budget.outside_model(spec)
        if refusal is not None:
            raise ValueError(f"{dict(values)}: {refusal}")
        steered.append(budget.steered_table(spec))
    pairs = [(i, p) for i, (_, group) in enumerate(pts) for p in group[:min(draws, len(group))]]
    if checks is None:
        checks = min(DEFAULT_CHECKS, len(pairs))
    elif checks > len(pairs):
        raise ValueError(f"{checks} checks asked, but there are only {len(pairs)} (grid point, draw) pairs to "
                         f"check (the campaign's units among the first {draws} draws at its {len(pts)} grid "
                         f"point(s)): ask for {len(pairs)} or fewer")
    t0 = time.perf_counter()
    say(f"the budget: {len(pts)} grid point(s), one error-free closed-loop run and one budget each")
    tasks = [(_scenario(camp, group[0], every="1 s"), preset) for _, group in pts]
    models = [None] * len(tasks)
    with concurrent.futures.ProcessPoolExecutor(min(workers, len(tasks)), initializer=_worker_init) as ex:
        futures = {ex.submit(_model, task): i for i, task in enumerate(tasks)}
        for done, fut in enumerate(concurrent.futures.as_completed(futures), start=1):
            i = futures[fut]
            models[i] = fut.result()
            el = time.perf_counter() - t0
            say(f"  budget {done}/{len(tasks)}: {dict(pts[i][0])} ({models[i]['seconds']:.0f} s)"
                + (f"; about {el / done * (len(tasks) - done):.0f} s left" if done < len(tasks) else ""))
    coef = coefficients(preset, draws)
    out_points = []
    for (values, _), model in zip(pts, models):
        out_points.append({"values": dict(values), "draws": draws, "steered": steered[len(out_points)],
                           "final_m": np.hypot(*final_errors(model, coef).T),
                           "final_clean_m": np.hypot(*final_errors(model, coef, noise=False).T),
                           "seconds_model": model["seconds"]})
    t_budget = time.perf_counter() - t0
    say(f"  {draws:,} draws x {len(pts)} grid point(s) through the budget in {t_budget:.0f} s")
    # the checks: distinct (grid point, draw) pairs, picked at random without replacement
    picks = [pairs[k] for k in np.random.default_rng(CHECK_SEED).choice(len(pairs), size=checks, replace=False)]
    t1 = time.perf_counter()
    out_checks = []
    if kept is not None and kept[0] == len(picks):
        for c, (i, p) in zip(kept[1], picks):
            if c.get("draw") != p.run or c.get("values") != out_points[i]["values"]:
                break
            bud = float(out_points[i]["final_clean_m"][p.run])   # the budget's, as it is now (the same bits)
            out_checks.append({**c, "point": i, "budget_m": bud,
                               "rel": (bud - c["closed_loop_m"]) / c["closed_loop_m"]})
        if out_checks:
            say(f"  {len(out_checks)} of {len(picks)} check(s) kept from the run that stopped")

    def result(interrupted=False):
        return {"points": out_points, "checks": out_checks, "seconds_budget": t_budget,
                "seconds_checks": time.perf_counter() - t1, "workers": workers, "preset": preset,
                "checks_planned": len(picks), "interrupted": interrupted}
    if len(out_checks) < len(picks):
        try:
            _run_checks(camp, picks, models, out_points, out_checks, t1, say, workers, on_check)
        except KeyboardInterrupt:
            raise BudgetInterrupted(result(interrupted=True)) from None
    return result()


def _run_checks(camp, picks, models, out_points, out_checks, t1, say, workers, on_check):
    """The closed-loop checks not yet in ``out_checks``, appended as they
    finish (in the picks' order; ``on_check`` after each). Ctrl-C: no
    further check starts, the ones running end, KeyboardInterrupt."""
    first = len(out_checks)
    todo = picks[first:]
    with concurrent.futures.ProcessPoolExecutor(min(workers, len(todo)), initializer=_worker_init) as ex:
        try:
            for (i, p), (loop, table, sec) in zip(todo, ex.map(_check, [_scenario(camp, p) for _, p in todo])):
                values = out_points[i]["values"]
                bud = float(out_points[i]["final_clean_m"][p.run])
                same, since = same_table(models[i]["table"], table, models[i]["dt"])
                out_checks.append({"values": dict(values), "point": i, "draw": p.run, "closed_loop_m": loop,
                                   "budget_m": bud, "rel": (bud - loop) / loop, "same_table": same,
                                   "table_differs_from_s": since, "seconds": sec})
                if on_check is not None:
                    on_check(out_checks, len(picks))
                left = (time.perf_counter() - t1) / (len(out_checks) - first) * (len(picks) - len(out_checks))
                say(f"  check {len(out_checks)}/{len(picks)}: {values}, draw {p.run}: closed loop "
                    f"{loop:.1f} m, budget {bud:.1f} m ({100 * (bud - loop) / loop:+.3f} %)"
                    + ("" if same else f"; its table turned otherwise than the error-free unit's"
                       + ("" if since is None else f" from {since / 3600:.2f} h"))
                    + (f"; about {left:.0f} s left" if len(out_checks) < len(picks) else ""))
        except KeyboardInterrupt:
            ex.shutdown(wait=True, cancel_futures=True)
            raise
