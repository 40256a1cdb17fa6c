"""The plot and report of a plan whose seams are joined by moves: the cycle seen from above
and its timeline.

``cycle.png``: left, the tool point's path in the robot base frame seen from above, every
seam in its own colour (an arrow half-way shows the welding direction) and the
approach, retract and air moves dashed; right, a Gantt-like timeline of the cycle, one row
per seam plus one for the moves. ``report.html`` embeds it with the per-seam figures.
"""

from __future__ import annotations

import base64
from pathlib import Path
from typing import TYPE_CHECKING

from trackplan.case import Case
from trackplan.planning.result import AIR, APPROACH, RETRACT, PlanResult
from trackplan.report.figures import _new_figure
from trackplan.report.html import _esc, _grid, html_page
from trackplan.run_files import REPORT_FILE

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
    figure = _new_figure(11.0, 4.6)
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
    case of several seams, an approach or a home, planned or not): its report is the
    cycle's (:func:`write_seams_report`)."""
    sequencing = case.sequencing
    joined = len(case.seams) > 1 or sequencing.approach > 0 or sequencing.home is not None
    return joined or any(span.kind in MOVE_COLORS for span in result.spans)


def write_seams_report(
    result: PlanResult, case: Case, out_dir: Path, info: dict | None = None
) -> list[Path]:
    """Write ``cycle.png`` and ``report.html`` (self-contained: the plot as a data URI).

    Parameters
    ----------
    result
        The cycle.
    case
        Its case.
    out_dir
        Directory to write into.
    info
        The ``result.json`` content, for the tables (seams, moves, search).

    Returns
    -------
    list of pathlib.Path
        The files written.
    """
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    written: list[Path] = []
    plot = ""
    if result.trajectory.n_samples:
        figure = cycle_figure(result, case)
        path = out_dir / CYCLE_PLOT
        figure.savefig(path)
        written.append(path)
        data = base64.b64encode(path.read_bytes()).decode("ascii")
        plot = (
            f'<figure id="plot-cycle"><img alt="the cycle" src="data:image/png;base64,{data}">'
            "<figcaption>Left: the tool point from above, each seam in its colour (the arrow "
            "half-way shows the welding direction), approach, retract and air moves dashed. "
            f"Right: the cycle's timeline. (file: {CYCLE_PLOT})</figcaption></figure>"
        )
    info = info or {}
    seams = [
        [
            _esc(row["name"]),
            "reversed" if row["reversed"] else "forward",
            f"{row['t_start']:.3f}",
            f"{row['duration']:.3f}",
            f"{row['objective']:.4f}",
            f"{1e3 * row['max_tracking_error']:.3f}",
            f"{100 * row['rated_speed_fraction']:.1f}",
            str(len(row["slowdowns"])),
        ]
        for row in info.get("seams", [])
    ]
    seam_table = _grid(
        [
            "seam",
            "direction",
            "start s",
            "duration s",
            "J",
            "tracking mm",
            "at rated speed %",
            "slow-downs",
        ],
        seams,
    )
    figures = _grid(
        ["figure", "value"],
        [
            ["cycle time", f"{result.duration:.3f} s"],
            ["welding", f"{result.seam_time:.3f} s"],
            ["approach, retract and air", f"{result.air_time:.3f} s"],
            ["J (Eq. 8, whole cycle)", f"{result.objective:.4f}"],
            ["placement", ", ".join(f"{v:.4f}" for v in result.placement)],
            ["sequence", _esc(_sequence_text(info))],
        ],
    )
    violations = "".join(f"<li>{_esc(v.message)}</li>" for v in result.check.violations[:20])
    verdict = "feasible" if result.feasible else "infeasible"
    body = (
        f"<h1>{_esc(case.name)}: {verdict}</h1><p>{_esc(result.message)}</p>"
        f'<section id="result"><h2>Cycle</h2>{figures}{plot}'
        f"<h2>Seams</h2>{seam_table}"
        + (f"<h2>Violations</h2><ul>{violations}</ul>" if violations else "")
        + "</section>"
    )
    page = html_page(f"trackplan report: {case.name}", body)
    report = out_dir / REPORT_FILE
    report.write_text(page, encoding="utf-8")
    written.append(report)
    return written


def _sequence_text(info: dict) -> str:
    """``rib-left ← , rib-right →`` from the ``sequence`` of result.json."""
    steps = info.get("sequence", [])
    return ", ".join(f"{s['seam']} {'←' if s['reversed'] else '→'}" for s in steps) or "-"


__all__ = ["CYCLE_PLOT", "cycle_figure", "has_moves", "write_seams_report"]
