"""What the report adds for a plan whose seams are joined by moves: the cycle's plot and
the sequence.

``cycle.png``: left, the tool point's path in the robot base frame seen from above, every
seam in its own colour (an arrow half-way shows the welding direction) and the
approach, retract and air moves dashed; right, a Gantt-like timeline of the cycle, one row
per seam plus one for the moves. :func:`sequence_section` is the report's sequence table.
The rest of such a run's report is every run's (``docs/results.md``).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from trackplan.case import Case
from trackplan.planning.result import AIR, APPROACH, MOVE_KINDS, RETRACT, SEAM, PlanResult
from trackplan.report.figure_style import new_figure
from trackplan.report.html_markup import Cell, esc, grid, key_values, margin_class, num, percent

if TYPE_CHECKING:
    from matplotlib.figure import Figure

CYCLE_PLOT = "cycle.png"
"""File name of the cycle plot."""
MOVE_COLORS = {APPROACH: "0.45", RETRACT: "0.65", AIR: "0.2"}
"""Grey levels of the moves between seams."""


def cycle_figure(result: PlanResult, case: Case) -> Figure:
    """The cycle from above (seams colour-coded, moves dashed) and its timeline.

    Parameters
    ----------
    result
        The planned cycle; positions in m (robot base frame), times in s.
    case
        Its case.

    Returns
    -------
    matplotlib.figure.Figure
        Two axes: the top view (``gid="seam"`` lines per seam, ``gid="move"`` dashed lines)
        and the timeline (``gid="bar"`` bars).
    """
    figure = new_figure(11.0, 4.6)
    top, gantt = figure.subplots(1, 2, width_ratios=[1.0, 1.4])
    position = result.trajectory.tool_position
    sample_time = result.trajectory.sample_time
    names = [seam.name for seam in case.seams]
    colors = {name: f"C{k % 10}" for k, name in enumerate(names)}
    for piece in result.spans:
        xy = position[piece.first : piece.last + 1, :2]
        t0, t1 = piece.first * sample_time, piece.last * sample_time
        if piece.kind == "seam":
            color = colors[piece.label]
            direction = " (reversed)" if piece.reversed else ""
            top.plot(*xy.T, color=color, lw=2.0, label=piece.label + direction, gid="seam")
            middle = len(xy) // 2
            ahead = min(len(xy) - 1, middle + max(1, len(xy) // 50))
            top.annotate(
                "",
                xy=tuple(xy[ahead]),
                xytext=tuple(xy[middle]),
                arrowprops={"arrowstyle": "-|>", "color": color, "lw": 1.5, "mutation_scale": 18},
            )
            row = names.index(piece.label)
        else:
            color = MOVE_COLORS[piece.kind]
            top.plot(*xy.T, color=color, lw=1.0, ls="--", gid="move")
            row = len(names)
        gantt.barh(row, t1 - t0, left=t0, color=color, edgecolor="white", lw=0.3, gid="bar")
    top.plot([], [], color="0.3", ls="--", lw=1.0, label="approach, retract, air")
    top.set_aspect("equal", adjustable="datalim")
    top.set_xlabel("x (m, robot base frame)")
    top.set_ylabel("y (m)")
    top.set_title("tool path from above")
    top.legend(fontsize=8, loc="best")
    gantt.set_yticks(range(len(names) + 1), [*names, "moves"])
    gantt.invert_yaxis()
    gantt.set_xlabel("t (s)")
    gantt.set_title(
        f"cycle {result.duration:.2f} s: seams {result.seam_time:.2f} s, "
        f"moves {result.air_time:.2f} s"
    )
    gantt.grid(axis="x", alpha=0.3)
    return figure


def has_moves(result: PlanResult, case: Case) -> bool:
    """Whether the plan joins its seams with moves (approach, retract or air spans, or a
    case of several seams, an approach or a home, planned or not): its report adds the
    cycle's plot and the sequence."""
    sequencing = case.sequencing
    joined = len(case.seams) > 1 or sequencing.approach > 0 or sequencing.home is not None
    return joined or any(span.kind in MOVE_COLORS for span in result.spans)


def sequence_section(result: PlanResult, case: Case) -> str:
    """The sequence of a plan whose seams are joined by moves (:func:`has_moves`), or
    nothing for one seam alone: per seam in welding order its order, direction, IK
    branch, start, duration, length, largest tracking error, share run at the rated speed,
    verdict and worst margin (its own plan's joint limits and its task checks); then the
    totals (welding, approach, retract and air, cycle).

    Returns
    -------
    str
        HTML: ``<section id="sequence">`` with two tables.
    """
    if not has_moves(result, case):
        return ""
    sample_time = result.trajectory.sample_time
    rows: list[list[Cell]] = []
    for order, (seam, own) in enumerate(zip(result.seams, result.seam_checks, strict=True)):
        span = next(p for p in result.spans if p.kind == SEAM and p.seam == seam.index)
        plan = seam.plan
        margins = [m for m in (plan.check.worst_margin(), own.worst_margin()) if m == m]
        margin = min(margins, default=float("nan"))  # NaN: no margin counts
        passed = own.success and plan.check.success
        verdict = "feasible" if passed else "infeasible"
        rows.append(
            [
                str(order + 1),
                esc(seam.name),
                "reversed" if seam.reversed else "forward",
                str(plan.branch),
                num(span.first * sample_time, unit="s"),
                num((span.last - span.first) * sample_time, unit="s"),
                num(plan.path_length, scale=1e3, unit="mm"),
                num(own.max_tracking_error, scale=1e3, unit="mm"),
                percent(plan.rated_speed_fraction),
                (verdict, "ok" if passed else "bad"),
                (percent(margin), margin_class(margin)),
            ]
        )
    header = [
        "#",
        "seam",
        "direction",
        "branch",
        "start",
        "duration",
        "length",
        "max tracking error",
        "at rated speed",
        "verdict",
        "worst margin",
    ]
    moves = [span for span in result.spans if span.kind in MOVE_KINDS]
    totals = key_values(
        [
            ("welding (seam time)", num(result.seam_time, unit="s")),
            (
                "approach, retract and air",
                f"{num(result.air_time, unit='s')} in {len(moves)} moves",
            ),
            ("cycle time", num(result.duration, unit="s")),
            ("sequence", esc(_sequence_text(result, case))),
        ]
    )
    unplanned = "".join(
        f"<li>{esc(name)}: {esc(plan.message)}</li>" for name, plan in result.unplanned.items()
    )
    return (
        '<section id="sequence"><h2>Sequence</h2><p class="muted">The seams in the order '
        "welded; the margin is the least unused fraction of a joint limit or a task bound "
        "over the seam's own plan. Times in the whole cycle.</p>"
        + grid(header, rows)
        + "<h3>Total</h3>"
        + totals
        + (f"<h3>Not planned</h3><ul>{unplanned}</ul>" if unplanned else "")
        + "</section>"
    )


def _sequence_text(result: PlanResult, case: Case) -> str:
    """``rib-left ←, rib-right →``: the seams in welding order and their directions."""
    names = case.seam_names
    steps = result.sequence.visits
    return ", ".join(f"{names[v.seam]} {'←' if v.reversed else '→'}" for v in steps) or "–"


__all__ = ["CYCLE_PLOT", "MOVE_COLORS", "cycle_figure", "has_moves", "sequence_section"]
