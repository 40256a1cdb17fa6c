"""The self-contained HTML report of one run (``report.html``).

One page that works offline: plotly.js is embedded once, the PNG plots are embedded as
base64 data URIs, and no resource is fetched from the network. The page holds the case
summary, the result tables, the plots and the interactive 3D view of the robot.
"""

from __future__ import annotations

import base64
from collections.abc import Mapping, Sequence
from pathlib import Path

import numpy as np

from trackplan.case import Case
from trackplan.planning.result import PlanResult
from trackplan.report.cycle import has_moves, sequence_section
from trackplan.report.cycle_view import cycle_view_spec
from trackplan.report.html_case import case_section
from trackplan.report.html_markup import esc, grid, html_page
from trackplan.report.html_result import (
    external_axes_table,
    figures_table,
    margins_table,
    references_table,
    slowdowns_table,
    verdict_badge,
    violations_table,
)
from trackplan.report.html_search import bounds_line, optimizer_section
from trackplan.report.plotly_html import plotly_div
from trackplan.report.robot_view import VIEW_ID, robot_view_spec
from trackplan.run_files import REPORT_FILE

_esc, _grid = esc, grid  # moved to html_markup; importers outside this package keep working

_PLOT_CAPTIONS = {
    "cycle.png": (
        "Cycle",
        "Left: the tool point from above, each seam in its colour (the arrow half-way shows "
        "the welding direction), approach, retract and air moves dashed. Right: the cycle's "
        "timeline, one row per seam and one for the moves.",
    ),
    "joints.png": (
        "Joint trajectories",
        "Rows: position, velocity, acceleration and jerk (backward differences at Ts, robot "
        "at rest before the first sample); one column per joint. Dashed lines are the limits; "
        "red markers are samples beyond a limit and red bands the violation windows the "
        "checker reported. Each panel gives its margin (unused fraction of the limit) above it; "
        "grey bands, for seams joined by moves, are the approach, retract and air moves.",
    ),
    "path.png": (
        "Path and placement",
        "Left: the path in its definition frame (dashed) and placed (solid) in the robot base "
        "frame, with the base frame (dark, solid) and the part frame (light, dashed), the "
        "reach shell allowed for the placement origin and the robot at t = 0. Right: the "
        "placed path close up with tool frames (x red, y green, z blue) and the samples "
        "inside violation windows.",
    ),
    "speed.png": (
        "Tool speed and tracking error",
        "Top: Cartesian tool speed against the rated speed and the corner speed cap, slow-downs "
        "shaded and numbered as in the slow-down table (neighbours too close to label apart "
        "share a label, 3–5), their reasons in the legend. Bottom: distance of the tool point "
        "from the nominal path (sharp corners kept) against the tolerance ρ. For seams joined by "
        "moves: each seam named over its span with its own rated speed, cap and tolerance, the "
        "moves shaded grey.",
    ),
    "clearance.png": (
        "Clearance",
        "Least distance between the robot (link and tool capsules) and the cell (obstacles, "
        "workpiece, non-adjacent links) at each sample, against the required clearance; the "
        "closest approach is marked with the pair it occurs between.",
    ),
    "tool.png": (
        "Tool orientation",
        "Left: the spin about the tool axis along the planned path, with the spin range when "
        "the spin is free. Right: tool frames along the placed path (x red, y green, z blue; "
        "z is the tool axis).",
    ),
    "convergence.png": (
        "Placement search",
        "Best and mean fitness and the share of feasible candidates per generation, placed at "
        "the cumulative number of evaluations; one colour per method.",
    ),
}


# Plotly.animate rejects the promise of an animation that a newer one interrupts (pause, or
# the slider moved during play) without a reason, and its buttons leave that unhandled: the
# browser would log "Uncaught (in promise) undefined" at every pause.
_QUIET_INTERRUPTS = (
    "window.addEventListener('unhandledrejection', function (event) {"
    " if (event.reason === undefined) { event.preventDefault(); } });"
)


def _plots_section(paths: Sequence[Path]) -> str:
    items = []
    for path in paths:
        title, caption = _PLOT_CAPTIONS.get(path.name, (path.stem, ""))
        data = base64.b64encode(path.read_bytes()).decode("ascii")
        items.append(
            f'<figure id="plot-{esc(path.stem)}"><h3>{esc(title)}</h3>'
            f'<img alt="{esc(title)}" src="data:image/png;base64,{data}">'
            f"<figcaption>{esc(caption)} (file: {esc(path.name)})</figcaption></figure>"
        )
    return '<section id="plots"><h2>Plots</h2>' + "".join(items) + "</section>"


def _external_note(case: Case) -> str:
    """What the 3D view shows of a track and a positioner (escaped HTML), else nothing."""
    notes = []
    if case.track is not None:
        notes.append(" The robot's base rides the track, drawn as a line over its range.")
    if case.positioner is not None:
        notes.append(
            " The positioner (lines between its axes' frames) turns the part: the seam, the "
            "planned path, the part frame and the workpiece move with its flange."
        )
    return esc("".join(notes))


def _cycle_note(result: PlanResult, case: Case) -> str:
    """What the 3D view shows of seams joined by moves (escaped HTML), else nothing."""
    if not has_moves(result, case) or not result.spans:  # cycle_view_spec's condition
        return ""
    return esc(
        " The robot runs the whole cycle: each seam in its colour of the cycle plot, its "
        "nominal path dashed in the same colour, the approach, retract and air moves dashed grey."
    )


def view_figure(result: PlanResult, case: Case, n_frames: int = 150) -> dict:
    """The 3D view's figure as plotly.js takes it (``data``, ``layout``, ``frames``): the
    robot view (:func:`~trackplan.report.robot_view.robot_view_spec`) with the cycle's
    seams and moves (:func:`~trackplan.report.cycle_view.cycle_view_spec`). The report and
    the still images (:mod:`trackplan.report.images`) draw this one figure."""
    return cycle_view_spec(robot_view_spec(result, case, n_frames=n_frames), result, case)


def view_section(result: PlanResult, case: Case, n_frames: int = 150) -> str:
    """The report's 3D view section: the robot following the path (plotly.js embedded), or
    a note when there is no trajectory. ``n_frames`` animation frames."""
    if result.trajectory.n_samples == 0:
        return (
            '<section id="view"><h2>3D view</h2><p>No trajectory to show: '
            f"{esc(result.message)}</p></section>"
        )
    div = plotly_div(
        view_figure(result, case, n_frames),
        VIEW_ID,
        config={"displaylogo": False, "responsive": True},
        post_script=_QUIET_INTERRUPTS,
    )
    return (
        '<section id="view"><h2>3D view</h2><p class="muted">The robot, drawn with its URDF '
        "meshes or as solids of its collision capsules, follows the placed path. Drag to "
        "rotate, scroll to zoom, ▶ play or move the time slider; click legend entries to show "
        f"or hide the path, frames and reach shell.{_external_note(case)}"
        f"{_cycle_note(result, case)}</p>{div}</section>"
    )


def write_report(
    result: PlanResult,
    case: Case,
    out_dir: Path,
    plots: Sequence[Path],
    history: Mapping[str, Mapping[str, np.ndarray]] | None = None,
    optimizer_info: Mapping[str, object] | None = None,
    n_frames: int = 150,
) -> Path:
    """Write ``report.html``, one self-contained page that works offline.

    The PNG plots (written by :func:`trackplan.report.figures.write_plots`) are embedded
    as data URIs; plotly.js is embedded once for the interactive 3D view (div id
    ``robot-view``).

    Parameters
    ----------
    result
        The planned placement.
    case
        The case it was planned for.
    out_dir
        Directory to write into (created when missing).
    plots
        The PNG files to embed, in report order.
    history
        Optimizer history ``{method: {"generation", "evaluations", "best", "mean",
        "feasible_share", "wall_time"}}`` with arrays of shape (G,), for ``optimize`` runs.
    optimizer_info
        Figures of the search shown as a table (method, evaluations, wall time, …).
    n_frames
        Number of animation frames of the 3D view.

    Returns
    -------
    pathlib.Path
        The report file.
    """
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    page = report_page(
        result, case, plots, view_section(result, case, n_frames), history, optimizer_info
    )
    path = out_dir / REPORT_FILE
    path.write_text(page, encoding="utf-8")
    return path


def report_page(
    result: PlanResult,
    case: Case,
    plots: Sequence[Path],
    view: str,
    history: Mapping[str, Mapping[str, np.ndarray]] | None = None,
    optimizer_info: Mapping[str, object] | None = None,
) -> str:
    """The HTML of ``report.html`` (see :func:`write_report`) around the 3D view section
    ``view`` (:func:`view_section`)."""
    verdict = "feasible" if result.feasible else "infeasible"
    body = "".join(
        [
            f"<h1>{esc(case.name)}: {verdict}</h1>",
            f"<p>{verdict_badge(result)} {esc(result.message)}</p>",
            bounds_line(optimizer_info),
            '<nav><a href="#case">Case</a><a href="#result">Result</a>'
            + ('<a href="#sequence">Sequence</a>' if has_moves(result, case) else "")
            + '<a href="#plots">Plots</a><a href="#view">3D view</a></nav>',
            case_section(result, case),
            '<section id="result"><h2>Result</h2>',
            '<div class="cols"><div><h3>Key figures</h3>',
            figures_table(result, case),
            external_axes_table(result, case),
            "</div><div>",
            references_table(result),
            slowdowns_table(result),
            optimizer_section(optimizer_info, history, result),
            "</div></div>",
            margins_table(result, case),
            violations_table(result),
            "</section>",
            sequence_section(result, case),
            _plots_section(plots),
            view,
        ]
    )
    return html_page(f"trackplan report: {case.name}", body)
