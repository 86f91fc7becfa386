"""`pyins campaign` and `pyins budget`: many runs of a scenario (grids,
Monte Carlo, local or on Dask), and each sensor error's share of one."""
import json
import math
import os
import sys
import time

import numpy as np

from pyins import budget, campaign, records, scenario
from pyins.campaign.by_budget import CHECK_SEED, BudgetInterrupted, by_budget
from pyins.metrics import display
from pyins.units import NMI_TO_M

from .common import (EXIT_FAILED, EXIT_INTERRUPTED, EXIT_OK, CountProgress, InputError, TICKS_PER_HOUR, check_hours,
                     emit_json, say, set_overrides)


#: The examples each subcommand's --help ends with.
EXAMPLES = {
    'campaign': 'examples:\n  pyins campaign seed000_static\n  pyins campaign --scenario seed000_static --grid motion.heading="0 deg,60 deg" --seeds 5\n  pyins campaign seed000_static --scheduler tcp://127.0.0.1:8786',
    'budget': 'examples:\n  pyins budget seed002_exp2 --variant 1   # the traditional two-position scheme\n  pyins budget seed003 --hours 6 --check   # every source alone through the firmware too',
}


def add_campaign(cmd):
    """`pyins campaign`: its subparser (``cmd(name, help)`` makes one) and options."""
    p = cmd("campaign", "grids and Monte-Carlo sets on a local process pool or a Dask cluster")
    p.add_argument("campaign", nargs="?", help="built-in campaign name or a campaign .toml file")
    p.add_argument("--scenario", help="base scenario for --grid")
    p.add_argument("--grid", action="append", metavar="KEY=V1,V2,...")
    p.add_argument("--seeds", help="a count N (0..N-1), a list 0,3,7 or a range 2..6 (default: the campaign's own, "
                   "else the scenario's seed)")
    p.add_argument("--group-by", action="append", help="grid keys to group by, repeatable or a,b (default: the campaign's own, else every grid key)")
    p.add_argument("--workers", type=int, help="local processes (default: every core)")
    p.add_argument("--scheduler", help="Dask scheduler address, e.g. tcp://host:8786")
    p.add_argument("--out", help="campaign directory (default runs/campaigns/NAME)")
    p.add_argument("--budget", type=int, metavar="N",
                   help="place N draws of the campaign's random constants through the error budget "
                        "(one closed-loop run per grid point) instead of a closed-loop run per draw; "
                        "writes OUT/budget.md and budget.json")
    p.add_argument("--checks", type=int, metavar="M",
                   help="with --budget: M closed-loop runs of distinct (grid point, draw) pairs picked "
                        "at random, held against the budget (default 10, or every pair if fewer)")


def add_budget(cmd):
    """`pyins budget`: its subparser (``cmd(name, help)`` makes one) and options."""
    p = cmd("budget", "each sensor error's share of a scenario's errors (linear model, one FIL run per variant)")
    p.add_argument("scenario", help="built-in name (pyins list) or a .toml file")
    p.add_argument("--hours", type=float, help="override the duration [h]")
    p.add_argument("--set", action="append", metavar="KEY=VALUE", help="override a scenario key (repeatable)")
    p.add_argument("--variant", type=int, help="only this [compare] variant (0, 1, ...; default all)")
    p.add_argument("--check", action="store_true", help="run every source alone through the firmware too")


def _campaign_option_error(exc, args):
    """A ScenarioError about what the command line gave (--seeds, --group-by,
    --grid, --scenario) said in the option's name rather than the campaign
    file's key."""
    key = getattr(exc, "key", "") or ""
    given = {"campaign.seeds": ("--seeds", args.seeds), "campaign.group_by": ("--group-by", args.group_by),
             "campaign.scenario": ("--scenario", args.scenario)}
    for k, (opt, value) in given.items():
        if key == k and value is not None and (exc.source == "command line" or opt != "--scenario"):
            shown = ",".join(value) if isinstance(value, list) else value
            return InputError(f"{opt} {shown}: {exc.reason}")
    if exc.source == "command line" and key.startswith("campaign.grid"):
        return InputError(f"--grid {key[len('campaign.grid.'):]}: {exc.reason}")
    if exc.source == "command line":
        return InputError(f"{key + ': ' if key else ''}{exc.reason}")
    return exc


def _headline(result):
    """The headline lines of a campaign's aggregate: per group (and variant),
    the mean, std and max of its main metrics, in the report's units."""
    main = ("horizontal_error_final", "horizontal_error_max", "heading_error_final")
    lines = []
    groups = {g["index"]: g["label"] for g in result.get("groups", [])}
    keyed = {}
    for a in result.get("aggregates", []):
        name = next((m for m in main if a["metric"].startswith(m + "_") or a["metric"] == m), None)
        if name is not None:
            keyed.setdefault((a["group"], a["variant"]), []).append((main.index(name), name, a))
    for (gi, v), items in keyed.items():
        parts = []
        for _, name, a in sorted(items, key=lambda t: t[0]):
            unit, scale = display(name, [a["max"]])
            if a["mean"] is None:
                parts.append(f"{name} none (no finite value)")
                continue
            std = "" if a["std"] is None else f" +- {a['std'] / scale:.3g}"
            mx = "" if a["max"] is None else f" (max {a['max'] / scale:.3g})"
            parts.append(f"{name} {a['mean'] / scale:.3g}{std}{mx} {unit}")
        label = groups.get(gi, str(gi)) + (f" [{v}]" if v else "")
        lines.append(f"  {label}: {a['count']} run(s); " + "; ".join(parts))
    return lines


def cmd_campaign(args):
    if args.checks is not None and args.budget is None:
        raise InputError("--checks is for --budget (the closed-loop checks of the budget's draws)")
    if args.budget is not None:
        if args.budget < 1:
            raise InputError(f"--budget {args.budget}: the number of draws must be 1 or more")
        if args.checks is not None and args.checks < 0:
            raise InputError(f"--checks {args.checks}: must be 0 or more")
        if args.scheduler:
            raise InputError("--budget runs on the local pool (--workers), not on --scheduler")
    if args.campaign and (args.grid or args.scenario):
        raise InputError("campaign: give a campaign (NAME or FILE) or --scenario with --grid, not both")
    if args.workers is not None and args.workers < 1:
        raise InputError(f"--workers {args.workers}: must be 1 or more (default: every core)")
    group_by = ",".join(args.group_by) if args.group_by else None
    try:
        if args.campaign:
            # --seeds, --group-by stand for the campaign file's own (never ignored)
            camp = campaign.load_campaign(args.campaign, seeds=args.seeds, group_by=group_by)
        elif args.scenario:
            camp = campaign.from_args(args.scenario, args.grid or [], args.seeds, group_by)
        else:
            raise InputError("campaign: give a campaign NAME or FILE, or --scenario with --grid (see --help)")
    except scenario.ScenarioError as exc:
        raise _campaign_option_error(exc, args) from None
    out = args.out or campaign.default_out_dir(camp)
    if args.budget is not None:
        return _campaign_by_budget(args, camp, out)
    n_runs = len({p.digest for p in camp.points})
    given = [f"{o} {v}" for o, v in (("--seeds", args.seeds), ("--group-by", group_by))
             if v is not None and args.campaign]
    say(args, f"pyins campaign {camp.name} -> {out}: {n_runs} run(s)"
              + (f" ({', '.join(given)} in place of the campaign's own)" if given else ""))
    bar = CountProgress("runs", enabled=not args.quiet and not args.json)

    def progress(done, total, skipped=0):
        bar(done, total, skipped)
    try:
        result = campaign.run_campaign(camp, out, workers=args.workers, scheduler=args.scheduler,
                                       progress=progress,
                                       notice=lambda text: print(f"pyins campaign: note: {text}",
                                                                 file=sys.stderr))
    except campaign.CampaignError as exc:
        bar.end()
        if exc.result is None:          # it could not run (no dask, no scheduler): the input's
            raise InputError(str(exc)) from None
        # runs failed: every other result is written; one line naming the first failure
        print(f"pyins campaign: {exc}", file=sys.stderr)
        print(f"  aggregates of the others: {os.path.join(out, 'aggregate.md')}", file=sys.stderr)
        emit_json(args, exc.result)
        return EXIT_FAILED
    except KeyboardInterrupt as exc:
        bar.end()
        ex = (getattr(exc, "result", None) or {}).get("execution", {})
        done = f"{ex['computed'] + ex['skipped']} of {ex['runs']} runs finished, " if ex else ""
        print(f"\npyins campaign: interrupted; {done}kept in {out}/runs; partial aggregates in "
              f"{os.path.join(out, 'aggregate.md')} (rerun the same command to resume)", file=sys.stderr)
        return EXIT_INTERRUPTED
    bar.end()
    ex = result.get("execution", {})
    say(args, f"  {ex.get('runs', n_runs)} run(s): {ex.get('computed', 0)} computed, "
              f"{ex.get('skipped', 0)} already done, {ex.get('wall_s', 0.0):.1f} s")
    for line in _headline(result):
        say(args, line)
    say(args, f"  aggregates: {os.path.join(out, 'aggregate.md')}")
    emit_json(args, result)
    return EXIT_OK


#: The checks of `pyins campaign --budget` done so far (a stopped run's, for the next to resume).
BUDGET_CHECKS = "budget_checks.json"


def _campaign_by_budget(args, camp, out):
    """`pyins campaign --budget N`: the draws through the error budget
    (`pyins.campaign.by_budget`), OUT/budget.json and budget.md."""
    checks = args.checks       # None: by_budget's default (10, or every unit if fewer)
    if not camp.random_constants:
        raise InputError(f"campaign --budget: campaign {camp.name!r} draws no random constants "
                         f"(campaign.random_constants): the budget has nothing to place")
    say(args, f"pyins campaign {camp.name} --budget {args.budget} -> {out}: {args.budget:,} draws through the "
              f"error budget, {'10 (or every unit if fewer)' if checks is None else checks} closed-loop "
              f"check(s)")
    # the checks done by a run of the same campaign and draws that was stopped (Ctrl-C, a kill):
    # OUT/budget_checks.json, written after every check, removed once all are done
    done_path = os.path.join(out, BUDGET_CHECKS)
    identity = {"campaign_digest": camp.digest(), "draws": args.budget, "check_seed": CHECK_SEED}
    kept = None
    try:
        with open(done_path) as f:
            done = json.load(f)
        if all(done.get(k) == v for k, v in identity.items()):
            kept = (done["checks_planned"], done["checks"])
    except (OSError, ValueError, KeyError, TypeError):
        kept = None                     # none, unreadable or another run's: the checks start over

    def save(checks_done, planned):
        os.makedirs(out, exist_ok=True)
        records.write_atomic(done_path, json.dumps({**identity, "checks_planned": planned, "checks": [
            {k: v for k, v in c.items() if k != "point"} for c in checks_done]}))
    try:
        res = by_budget(camp, args.budget, checks, args.workers, log=lambda text: say(args, text), kept=kept,
                        on_check=save)
    except ValueError as exc:
        raise InputError(f"campaign --budget: {exc}") from None
    except BudgetInterrupted as stop:       # Ctrl-C in the checks: the draws and the checks done are kept
        res = stop.result
        save(res["checks"], res["checks_planned"])  # (the Ctrl-C may have come between a check and its save)
    warnings = []
    if res["interrupted"]:
        warnings.append(f"interrupted (Ctrl-C) after {len(res['checks'])} of {res['checks_planned']} closed-loop "
                        f"checks: the draws are all placed, the checks are incomplete; the same command "
                        f"again runs the others (the checks done are kept in {BUDGET_CHECKS})")
    elif os.path.exists(done_path):
        os.remove(done_path)
    if not res["checks"]:
        warnings.append("no closed-loop check: the budget's figures are not held to the firmware in this run")
    steered = [", ".join(f"{k}={x}" for k, x in pt["values"].items()) for pt in res["points"] if pt["steered"]]
    if steered:
        warnings.append(f"the table is steered by the unit's own heading at {len(steered)} grid point(s) "
                        f"({'; '.join(steered)}): the budget takes every unit's stops from the error-free "
                        f"unit's, an approximation; the checks measure its error there")
    bad = [c for c in res["checks"] if abs(c["rel"]) > 0.01]
    if bad:
        own = [c for c in bad if c["same_table"]]
        worst = max(bad, key=lambda c: abs(c["rel"]))
        warnings.append(f"{len(bad)} of {len(res['checks'])} check(s) differ from the closed loop by more than "
                        f"1 % (largest {100 * abs(worst['rel']):.2f} %, "
                        f"{abs(worst['budget_m'] - worst['closed_loop_m']):.1f} m on {worst['closed_loop_m']:.1f} m): "
                        + (f"in all of them the unit's table turned otherwise than the error-free unit's, "
                           f"whose stops the budget takes (a table steered by the unit's own heading)"
                           if not own else
                           f"{len(own)} of them with the error-free unit's table history, so the budget's "
                           f"own model misses there"))
    lines = [f"# {camp.name}: {args.budget:,} draws through the error budget", "",
             *([f"**Incomplete:** interrupted after {len(res['checks'])} of {res['checks_planned']} "
                f"closed-loop checks.", ""] if res["interrupted"] else []),
             f"Final horizontal error; the budget's draws with the noise drawn from its covariance "
             f"(`pyins.campaign.by_budget`). {res['seconds_budget']:.0f} s for the budget, "
             f"{res['seconds_checks']:.0f} s for {len(res['checks'])} closed-loop check(s), "
             f"{res['workers']} worker(s).", "",
             "| grid point | draws | median | 5 % | 95 % | checks | largest abs(difference) |", "|---|---|---|---|---|---|---|"]
    points = []
    for i, pt in enumerate(res["points"]):
        v = pt["final_m"]
        mine = [c for c in res["checks"] if c["point"] == i]
        worst = max((abs(c["rel"]) for c in mine), default=None)
        label = ", ".join(f"{k}={x}" for k, x in pt["values"].items()) + (" (steered)" if pt["steered"] else "")
        lines.append(f"| {label} | {pt['draws']} | {np.median(v) / NMI_TO_M:.3f} nmi | "
                     f"{np.percentile(v, 5) / NMI_TO_M:.3f} | {np.percentile(v, 95) / NMI_TO_M:.3f} | "
                     f"{len(mine)} | {'' if worst is None else f'{100 * worst:.2f} %'} |")
        say(args, f"  {label}: median {np.median(v) / NMI_TO_M:.3f} nmi (5-95 %: {np.percentile(v, 5) / NMI_TO_M:.3f}"
                  f"-{np.percentile(v, 95) / NMI_TO_M:.3f}) over {pt['draws']:,} draws")
        points.append({"values": pt["values"], "draws": pt["draws"], "steered": pt["steered"],
                       "median_m": float(np.median(v)),
                       "p5_m": float(np.percentile(v, 5)), "p95_m": float(np.percentile(v, 95)),
                       "final_m": [float(x) for x in v]})
    lines += ["", "| grid point | draw | closed loop (no noise) | budget (no noise) | difference | "
              "table turned as the error-free unit's |", "|---|---|---|---|---|---|"]
    for c in res["checks"]:
        label = ", ".join(f"{k}={x}" for k, x in c["values"].items())
        table = ("yes" if c["same_table"] else "no" if c["table_differs_from_s"] is None
                 else f"no, from {c['table_differs_from_s'] / 3600:.2f} h")
        lines.append(f"| {label} | {c['draw']} | {c['closed_loop_m']:.1f} m | {c['budget_m']:.1f} m | "
                     f"{100 * c['rel']:+.3f} % ({c['budget_m'] - c['closed_loop_m']:+.1f} m) | {table} |")
    if warnings:
        lines += ["", *[f"**Warning:** {w}" for w in warnings]]
    os.makedirs(out, exist_ok=True)
    records.write_atomic(os.path.join(out, "budget.md"), "\n".join(lines) + "\n")
    blob = {"campaign": camp.name, "draws": args.budget, "complete": not res["interrupted"],
            "checks_planned": res["checks_planned"], "points": points,
            "checks": [{k: v for k, v in c.items() if k != "point"} for c in res["checks"]],
            "seconds_budget": res["seconds_budget"], "seconds_checks": res["seconds_checks"],
            "workers": res["workers"], "warnings": warnings}
    records.write_atomic(os.path.join(out, "budget.json"), json.dumps(blob, indent=1))
    for w in warnings:
        print(f"pyins campaign: warning: {w}", file=sys.stderr)
    say(args, f"  report: {os.path.join(out, 'budget.md')}")
    emit_json(args, blob)
    return EXIT_INTERRUPTED if res["interrupted"] else EXIT_OK


def cmd_budget(args):
    """Each sensor error's signed share of a scenario's errors: the linear model of
    pyins.budget.run_budget on one closed-loop run per variant; --check runs every
    source alone through the firmware too (docs/concepts.md, "The error budget")."""
    check_hours(args.hours)                     # as pyins run: one line naming --hours
    scn = scenario.load(args.scenario)
    overrides = set_overrides(args)
    if overrides:
        scn = scn.with_overrides(overrides)
    specs = list(scn.runs())
    if args.variant is not None:
        if not 0 <= args.variant < len(specs):
            raise InputError(f"--variant {args.variant}: the scenario has {len(specs)} variant(s), "
                             f"0 to {len(specs) - 1}")
        specs = [specs[args.variant]]
    result = []
    quiet = args.quiet or args.json
    for spec in specs:
        say(args, f"pyins budget {scn.name} [{spec.label}], {spec.duration_ticks / TICKS_PER_HOUR:g} h"
                   + (", every source alone too" if args.check else ""))
        t0 = time.perf_counter()

        def phase(i, n, text, t0=t0):
            # a line per firmware run (the rows follow as they are known), with the time left
            if quiet:
                return
            el = time.perf_counter() - t0
            eta = f", about {el / i * (n - i):.0f} s left" if i else ""
            print(f"  firmware run {i + 1}/{n}: {text} ({el:.0f} s{eta})", file=sys.stderr, flush=True)
        rows, shares = budget.run_budget(spec, check=args.check, phase=phase,
                                         on_row=None if quiet else _budget_line)
        result.append(dict(label=spec.label, rows=[_budget_json_row(r) for r in rows],
                           eps_n_mean_rad_s={n: shares.eps_n_mean[i].tolist() for i, n in enumerate(shares.names)}))
    emit_json(args, dict(scenario=scn.name, variants=result))
    return EXIT_OK


def _budget_line(r):
    line = (f"  {r['source']:19s} model N {r['model_north_m'] / NMI_TO_M:+8.3f}  "
            f"E {r['model_east_m'] / NMI_TO_M:+8.3f}  final {r['model_final_m'] / NMI_TO_M:7.3f} nmi")
    if "fil_final_m" in r:
        line += (f"   FIL N {r['fil_north_m'] / NMI_TO_M:+8.3f}  E {r['fil_east_m'] / NMI_TO_M:+8.3f}"
                 f"  final {r['fil_final_m'] / NMI_TO_M:7.3f} nmi  rel. diff. "
                 f"{budget.budget_verdict(r)[1]}")
    print(line, flush=True)


#: The relative differences of a checked row (model against its firmware run).
_REL_KEYS = ("rel_max", "rel_24h", "rel_final", "rel_level", "rel_heading", "rel_velocity")


def _budget_json_row(row):
    """A budget row for --json: a relative difference that has no value (the
    run's own error is zero there: infinity in pyins.budget) is null, and
    ``rel_null`` says why."""
    out = dict(row)
    empty = [k for k in _REL_KEYS if isinstance(out.get(k), float) and not math.isfinite(out[k])]
    for k in empty:
        out[k] = None
    if empty:
        out["rel_null"] = {k: "the firmware run's own error is zero there: no relative difference "
                              "(diff_max_m holds the absolute one)" for k in empty}
    return out
