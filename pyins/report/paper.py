"""The paper's figures beside a run's: which can be judged, and how ours
compare (``pyins run``'s lines and the run report's table), from a
summary.json alone."""
from pyins import scenario

__all__ = ["paper_rows", "not_judged", "span"]

def span(seconds):
    """A duration as a report writes it: 6 h, 12 min, 150 s."""
    if seconds >= 3600:
        return f"{seconds / 3600:.3g} h"
    if seconds >= 60:
        return f"{seconds / 60:.3g} min"
    return f"{seconds:.3g} s"


def not_judged(variants):
    """Why the paper's figures cannot be judged on these summary entries
    (one variant, or all of a group metric), or "" when they can: a variant
    that stopped (its metrics cover part of the run), or one run for another
    length than the scenario file gives it (``--hours``, ``--set duration``):
    the paper's figures are for the run as written (a final error at 6 h is
    not the error at 72 h, nor the largest over 6 h the largest over 72 h)."""
    for v in variants:
        dur = v.get("duration_s")
        if not v.get("complete"):
            if dur and v.get("ticks"):
                return (f"not judged: the run stopped at {span(dur * v.get('ticks_done', 0) / v['ticks'])}"
                        f" of {span(dur)}")
            return "not judged: the run stopped before its end"
        written = v.get("written_duration_s")
        if dur is not None and written is not None and abs(dur - written) > 1e-6 * max(written, 1.0):
            how = "shortened" if dur < written else "lengthened"
            return (f"not judged: run {how} to {span(dur)}; the paper's figure is for the "
                    f"{span(written)} the scenario runs")
    return ""


def paper_rows(summary):
    """The paper's figures beside ours, a dict per row: metric, variant,
    relation, paper (value), unit, ours (our value in the paper's unit, None
    if none), verdict ("within"/"above" a bound, "xR" the ratio to a value,
    or "not judged: why" for a partial or re-timed run: `not_judged`),
    judged (bool), note. For the report and the CLI."""
    rows = []
    paper = summary.get("paper") or {}
    for fig in paper.get("figures", []):
        metric = fig["metric"]
        targets = [v for v in summary["variants"] if fig.get("variant") in (None, v["label"])]
        if metric in summary.get("group_metrics", {}):
            ours = [("all", summary["group_metrics"][metric], summary["variants"])]
        else:
            ours = [(v["label"], v["metrics"].get(metric), [v]) for v in targets]
        for label, val, over in ours:
            mine = None if val is None else scenario.in_figure_unit(val, fig)
            why = not_judged(over)
            verdict = why
            if why or mine is None:
                pass
            elif fig["relation"] == "<":
                verdict = "within" if mine < fig["value"] else "above"
            elif fig["value"]:
                verdict = f"x{mine / fig['value']:.2f}"
            rows.append(dict(metric=metric, variant=label, relation=fig["relation"], paper=fig["value"],
                             unit=fig["unit"], ours=mine, verdict=verdict, judged=not why and mine is not None,
                             note=fig.get("note", "")))
    return rows
