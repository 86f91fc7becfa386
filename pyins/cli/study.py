"""`pyins campaign` and `pyins budget`: many runs of a scenario (grids,
Monte Carlo, local or on Dask), and each sensor error's share of one."""
import os
import sys

from pyins import budget, campaign, scenario
from pyins.units import NMI_TO_M

from .common import EXIT_INTERRUPTED, EXIT_OK, InputError, TICKS_PER_HOUR, emit_json, say, set_overrides


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
    p.add_argument("--seeds", help="a count N (0..N-1), a list 0,3,7 or a range 2..6 (default: the scenario's)")
    p.add_argument("--group-by", action="append", help="grid keys to group by (default: all but seed)")
    p.add_argument("--workers", type=int, help="local processes (default: every core)")
    p.add_argument("--scheduler", help="Dask scheduler address, e.g. tcp://host:8786")
    p.add_argument("--out", help="campaign directory (default runs/campaign_NAME)")


def add_budget(cmd):
    """`pyins budget`: its subparser (``cmd(name, help)`` makes one) and options."""
    p = cmd("budget", "each sensor error's share of a scenario's errors (linear model, one FIL run per variant)")
    p.add_argument("scenario", help="built-in name (pyins list) or a .toml file")
    p.add_argument("--hours", type=float, help="override the duration [h]")
    p.add_argument("--set", action="append", metavar="KEY=VALUE", help="override a scenario key (repeatable)")
    p.add_argument("--variant", type=int, help="only this [compare] variant (0, 1, ...; default all)")
    p.add_argument("--check", action="store_true", help="run every source alone through the firmware too")


def cmd_campaign(args):
    if args.campaign and (args.grid or args.scenario):
        raise InputError("campaign: give a campaign (NAME or FILE) or --scenario with --grid, not both")
    if args.campaign:
        camp = campaign.load_campaign(args.campaign)
    elif args.scenario:
        camp = campaign.from_args(args.scenario, args.grid or [], args.seeds, args.group_by)
    else:
        raise InputError("campaign: give a campaign NAME or FILE, or --scenario with --grid (see --help)")
    out = args.out or campaign.default_out_dir(camp)
    say(args, f"pyins campaign {camp.name} -> {out}")

    def progress(done, total, skipped=0):
        if not args.quiet and not args.json and sys.stderr.isatty():
            print(f"\r  {done}/{total} runs ({skipped} already done)", end="", file=sys.stderr, flush=True)
    try:
        result = campaign.run_campaign(camp, out, workers=args.workers, scheduler=args.scheduler,
                                       progress=progress,
                                       notice=lambda text: print(f"pyins campaign: note: {text}",
                                                                 file=sys.stderr))
    except KeyboardInterrupt as exc:
        ex = (getattr(exc, "result", None) or {}).get("execution", {})
        done = f"{ex['computed'] + ex['skipped']} of {ex['runs']} runs finished, " if ex else ""
        print(f"\npyins campaign: interrupted; {done}kept in {out}/runs; partial aggregates in "
              f"{os.path.join(out, 'aggregate.md')} (rerun the same command to resume)", file=sys.stderr)
        return EXIT_INTERRUPTED
    if not args.quiet and not args.json and sys.stderr.isatty():
        print(file=sys.stderr)
    say(args, f"  aggregates: {os.path.join(out, 'aggregate.md')}")
    emit_json(args, result)
    return EXIT_OK


def cmd_budget(args):
    """Each sensor error's signed share of a scenario's errors: the linear model of
    pyins.budget.run_budget on one closed-loop run per variant; --check runs every
    source alone through the firmware too (docs/concepts.md, "The error budget")."""
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
    for spec in specs:
        say(args, f"pyins budget {scn.name} [{spec.label}], {spec.duration_ticks / TICKS_PER_HOUR:g} h"
                   + (", every source alone too" if args.check else ""))
        rows, shares = budget.run_budget(spec, check=args.check)
        for r in rows:
            line = (f"  {r['source']:19s} model N {r['model_north_m'] / NMI_TO_M:+8.3f}  "
                    f"E {r['model_east_m'] / NMI_TO_M:+8.3f}  final {r['model_final_m'] / NMI_TO_M:7.3f} nmi")
            if "fil_final_m" in r:
                line += (f"   FIL N {r['fil_north_m'] / NMI_TO_M:+8.3f}  E {r['fil_east_m'] / NMI_TO_M:+8.3f}"
                         f"  final {r['fil_final_m'] / NMI_TO_M:7.3f} nmi  rel. diff. "
                         f"{budget.budget_verdict(r)[1]}")
            say(args, line)
        result.append(dict(label=spec.label, rows=rows,
                           eps_n_mean_rad_s={n: shares.eps_n_mean[i].tolist() for i, n in enumerate(shares.names)}))
    emit_json(args, dict(scenario=scn.name, variants=result))
    return EXIT_OK
