"""The self-contained HTML report of one run (``report.html``).

One page that works offline: plotly.js is embedded once, the PNG plots are embedded as
base64 data URIs, and no resource is fetched from the network. The page holds the case
summary, the result tables, the plots and the interactive 3D view of the robot.
"""

from __future__ import annotations

import base64
import html
import math
from collections.abc import Iterable, Mapping, Sequence
from pathlib import Path

import numpy as np

from trackplan.case import Case
from trackplan.paths.specs import ArcSpec, LineSpec, PointsSpec, SegmentSpec
from trackplan.planning.result import LIMIT_KINDS, PlanResult
from trackplan.report.figures import history_columns
from trackplan.report.plotly_html import plotly_div
from trackplan.report.robot_view import VIEW_ID, robot_view_spec
from trackplan.report.scene import JOINT_QUANTITIES
from trackplan.robots.families import ik_family
from trackplan.run_files import REPORT_FILE

Cell = str | tuple[str, str]
"""A table cell: escaped HTML, or (escaped HTML, css class)."""

_PLOT_CAPTIONS = {
    "joints.png": (
        "Joint trajectories",
        "Rows: position, velocity, acceleration and jerk (backward differences at Ts, robot "
        "at rest before the first sample); one column per joint. Dashed lines are the limits; "
        "red markers are samples beyond a limit and red bands the violation windows the "
        "checker reported. Each panel gives its margin (unused fraction of the limit) above it.",
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
        "from the nominal path (sharp corners kept) against the tolerance ρ.",
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

_CSS = """
body { font-family: system-ui, -apple-system, "Segoe UI", Helvetica, Arial, sans-serif;
       margin: 0 auto; max-width: 1400px; padding: 0 1.5rem 3rem; color: #222; }
h1 { margin: 1.2rem 0 0.3rem; font-size: 1.6rem; }
h2 { border-bottom: 2px solid #ddd; padding-bottom: 0.2rem; margin-top: 2.2rem; }
h3 { margin: 1.2rem 0 0.4rem; font-size: 1.05rem; }
h4 { margin: 0.9rem 0 0.3rem; font-size: 0.95rem; }
nav a { margin-right: 1rem; }
.verdict { display: inline-block; padding: 0.2rem 0.7rem; border-radius: 4px; font-weight: 600; }
.ok { background: #e3f4e1; color: #1d6b16; }
.bad { background: #fbe3e3; color: #a31515; }
.low { background: #fff3d6; color: #8a5a00; }
table { border-collapse: collapse; margin: 0.3rem 0 0.8rem; font-size: 0.9rem; }
th, td { border: 1px solid #ddd; padding: 0.25rem 0.6rem; text-align: right; }
th { background: #f5f5f5; }
td.text, th.text { text-align: left; }
.cols { display: flex; flex-wrap: wrap; gap: 0 2.5rem; align-items: flex-start; }
figure { margin: 1rem 0 2rem; }
figure img { max-width: 100%; border: 1px solid #eee; }
figcaption { color: #555; font-size: 0.9rem; max-width: 70rem; }
.muted { color: #777; }
"""


# Plotly.animate rejects the promise of an animation that a newer one interrupts (pause, or
# the slider moved during play) without a reason, and its buttons leave that unhandled: the
# browser would log "Uncaught (in promise) undefined" at every pause.
_QUIET_INTERRUPTS = (
    "window.addEventListener('unhandledrejection', function (event) {"
    " if (event.reason === undefined) { event.preventDefault(); } });"
)


def _esc(value: object) -> str:
    return html.escape(str(value))


def _num(value: float | None, digits: int = 4, scale: float = 1.0, unit: str = "") -> str:
    """A number with ``digits`` significant digits, or an en dash when missing."""
    if value is None or not math.isfinite(float(value)):
        return "–"
    text = f"{float(value) * scale:.{digits}g}"
    return f"{text} {unit}".rstrip()


def _percent(fraction: float) -> str:
    return "–" if not math.isfinite(float(fraction)) else f"{100 * float(fraction):.1f} %"


def _margin_class(fraction: float) -> str:
    if not math.isfinite(float(fraction)) or fraction < 0:
        return "bad"
    return "low" if fraction < 0.1 else "ok"


def _vector(values: Iterable[float], digits: int = 4) -> str:
    return "(" + ", ".join(_num(v, digits) for v in values) + ")"


def _key_values(rows: Iterable[tuple[str, str]]) -> str:
    """A two-column table; values are already-escaped HTML."""
    body = "".join(
        f'<tr><th class="text">{_esc(k)}</th><td class="text">{v}</td></tr>' for k, v in rows
    )
    return f"<table>{body}</table>"


def _grid(header: Sequence[str], rows: Iterable[Sequence[Cell]], row_header: bool = True) -> str:
    """A table with a header row.

    Cells are escaped HTML, or ``(html, css class)`` pairs for coloured cells; the first
    cell of a row is a row header unless ``row_header`` is False.
    """
    head = "".join(
        f'<th class="{"text" if i == 0 else ""}">{_esc(h)}</th>' for i, h in enumerate(header)
    )
    body = ""
    for row in rows:
        cells = []
        for i, cell in enumerate(row):
            content, css = cell if isinstance(cell, tuple) else (cell, "text" if i == 0 else "")
            tag = "th" if (i == 0 and row_header) else "td"
            cells.append(f'<{tag} class="{css}">{content}</{tag}>')
        body += "<tr>" + "".join(cells) + "</tr>"
    return f"<table><thead><tr>{head}</tr></thead><tbody>{body}</tbody></table>"


def _verdict_badge(result: PlanResult) -> str:
    css = "ok" if result.feasible else "bad"
    return f'<span class="verdict {css}">{_esc(result.status.value)}</span>'


def _describe_segment(segment: SegmentSpec) -> tuple[str, str]:
    if isinstance(segment, LineSpec):
        return "line", f"to {_vector(segment.to)} m"
    if isinstance(segment, ArcSpec):
        return "arc", (
            f"centre {_vector(segment.center)} m, normal {_vector(segment.normal)}, "
            f"angle {_num(segment.angle)} rad ({_num(np.degrees(segment.angle))}°)"
        )
    if isinstance(segment, PointsSpec):
        return "points", f"{len(segment.points)} sampled points"
    return type(segment).__name__, ""


def _case_section(result: PlanResult, case: Case) -> str:
    robot, task, bounds = case.robot, case.task, case.bounds
    joint_rows = [
        [
            f"{j + 1} ({robot.joint_names[j]})",
            _vector(robot.origins[j][:3, 3]),
            _vector(robot.axes[j]),
            f"[{_num(robot.q_min[j])}, {_num(robot.q_max[j])}]",
            _num(robot.v_max[j]),
            _num(robot.a_max[j]),
            _num(robot.j_max[j]),
            _num(case.objective.weights[j]) if j < len(case.objective.weights) else "–",
        ]
        for j in range(robot.n_dof)
    ]
    robot_html = _key_values(
        [
            ("name", _esc(robot.name)),
            ("joints", str(robot.n_dof)),
            ("IK family", _esc(ik_family(robot).name)),
            ("tool offset", "yes" if robot.has_tool else "none (tool = flange)"),
            *(("assumption", _esc(note)) for note in robot.assumptions),
            ("source", _esc(robot.source or "–")),
        ]
    ) + _grid(
        [
            "joint",
            "origin xyz [m]",
            "axis",
            "q range [rad]",
            "q̇ max [rad/s]",
            "q̈ max [rad/s²]",
            "q⃛ max [rad/s³]",
            "weight C_i",
        ],
        joint_rows,
    )
    segments: list[list[Cell]] = [
        [str(i + 1), *((_esc(text), "text") for text in _describe_segment(s))]
        for i, s in enumerate(case.segments)
    ]
    path_html = _key_values(
        [
            ("start", f"{_vector(case.start)} m"),
            ("segments", str(len(case.segments))),
            ("nominal length", _num(result.path_length, unit="m")),
        ]
    ) + _grid(["#", "kind", "geometry (definition frame)"], segments)
    task_html = _key_values(
        [
            ("rated speed v_r", _num(task.rated_speed, scale=1e3, unit="mm/s")),
            ("corner speed cap v_t^max", _num(task.corner_speed, scale=1e3, unit="mm/s")),
            ("tolerance ρ", _num(task.tolerance, scale=1e3, unit="mm")),
            ("sample time Ts", _num(task.sample_time, scale=1e3, unit="ms")),
            ("tool orientation", _tool_text(task.tool)),
            ("time law", _esc(task.timing)),
        ]
    )
    search_html = _key_values(
        [
            ("lower bound X", _vector(bounds.lower)),
            ("upper bound X", _vector(bounds.upper)),
            ("reach of (x, y, z)", f"{_num(bounds.reach[0])} – {_num(bounds.reach[1])} m"),
            (
                "objective",
                f"Eq. 8, time weight {_num(case.objective.time_weight)} per s, "
                f"{_esc(case.objective.penalty)} penalty",
            ),
            (
                "optimizer",
                f"{_esc(case.optimizer.method)}, population {case.optimizer.population}, "
                f"seed {case.optimizer.seed}, "
                f"budget {_esc(case.optimizer.budget or 'method default')}",
            ),
            ("case file", _esc(case.source or "–")),
        ]
    )
    return (
        '<section id="case"><h2>Case</h2>'
        f'<div class="cols"><div><h3>Robot</h3>{robot_html}</div></div>'
        f'<div class="cols"><div><h3>Path</h3>{path_html}</div><div><h3>Task</h3>{task_html}</div>'
        f"<div><h3>Placement search</h3>{search_html}</div></div></section>"
    )


def _figures_table(result: PlanResult, case: Case) -> str:
    check = result.check
    task = case.task
    ideal = result.path_length / task.rated_speed if task.rated_speed > 0 else float("nan")
    x = result.placement
    rows = [
        ("verdict", _verdict_badge(result)),
        ("message", _esc(result.message)),
        (
            "placement X",
            f"({_num(x[0])}, {_num(x[1])}, {_num(x[2])}) m, "
            f"rpy ({_num(x[3])}, {_num(x[4])}, {_num(x[5])}) rad",
        ),
        ("objective J (Eq. 8)", _num(result.objective, 6)),
        ("duration", _num(result.duration, unit="s")),
        ("path length", _num(result.path_length, unit="m")),
        (
            "L / v_r (no ramps, no corners)",
            f"{_num(ideal, unit='s')}; duration is "
            f"{_num(result.duration / ideal if ideal else float('nan'))} × that",
        ),
        _rated_speed_row(result, task.rated_speed),
        ("min corner speed", _num(result.min_corner_speed, scale=1e3, unit="mm/s")),
        (
            "max tracking error",
            f"{_num(check.max_tracking_error, scale=1e3, unit='mm')} "
            f"(ρ = {_num(task.tolerance, scale=1e3, unit='mm')})",
        ),
        (
            "max orientation error",
            f"{_num(check.max_orientation_error, unit='rad')} "
            f"({_num(np.degrees(check.max_orientation_error))}°)",
        ),
        (
            "worst margin",
            _percent(check.worst_margin()) if check.joint_margins or check.task_margins else "–",
        ),
        *_energy_rows(result),
        ("time law, IK branch", f"{_esc(result.timing)}, branch {result.branch}"),
        (
            "samples",
            f"{result.trajectory.n_samples} at "
            f"Ts = {_num(result.trajectory.sample_time, scale=1e3, unit='ms')}",
        ),
    ]
    return _key_values(rows)


def _rated_speed_row(result: PlanResult, rated_speed: float) -> tuple[str, str]:
    """The share of the path run at the rated speed, or the top speed when that share
    would read 0.0 % (a curve cruising just below the rated speed; ``docs/results.md``)."""
    share = _percent(result.rated_speed_fraction)
    if share != "0.0 %":
        return "rated speed fraction", share
    top = float(np.max(result.trajectory.speed, initial=0.0))
    of_rated = f" ({_percent(top / rated_speed)} of v_r)" if rated_speed > 0 else ""
    return "top speed", _num(top, scale=1e3, unit="mm/s") + of_rated


def _energy_rows(result: PlanResult) -> list[tuple[str, str]]:
    """Energy figures of a robot with dynamics (``docs/dynamics.md``), else none."""
    energy = result.energy
    if energy is None:
        return []
    return [
        ("mechanical energy", _num(energy.mechanical_energy, unit="J")),
        ("copper loss", f"{_num(energy.copper_loss)} {_esc(energy.copper_loss_unit)}"),
        (
            "peak torque ratio",
            f"{_num(energy.peak_torque_ratio)} (joint {energy.peak_torque_joint})",
        ),
    ]


def _margins_table(result: PlanResult, case: Case) -> str:
    check = result.check
    n = case.robot.n_dof
    rows = []
    for kind in (*LIMIT_KINDS, "torque"):
        margins = check.joint_margins.get(kind)
        if margins is None:
            continue
        name, unit = JOINT_QUANTITIES[kind]
        cells: list[Cell] = [f"{name} [{unit}]"]
        for j in range(n):
            cells.append((_percent(margins[j]), _margin_class(margins[j])))
        binding = check.binding.get(kind)
        cells.append(f"joint {binding[0]} at t = {_num(binding[1])} s" if binding else "–")
        rows.append(cells)
    joints = _grid(["limit", *[f"joint {j + 1}" for j in range(n)], "closest to binding"], rows)
    tasks = _grid(
        ["task bound", "margin"],
        [[_esc(k), (_percent(v), _margin_class(v))] for k, v in check.task_margins.items()],
    )
    return (
        '<h3>Margins</h3><p class="muted">Unused fraction of each limit over all samples '
        "(1 − |x| / limit; negative = exceeded).</p>" + joints + tasks
    )


def _violations_table(result: PlanResult, limit: int = 60) -> str:
    violations = result.check.violations
    if not violations:
        return "<h3>Violations</h3><p>None.</p>"
    rows: list[list[Cell]] = [
        [
            _esc(v.limit),
            "–" if v.joint is None else str(v.joint),
            _num(v.t_first, unit="s"),
            _num(v.t_last, unit="s"),
            _num(v.worst),
            _num(v.bound),
            (_esc(v.message), "text"),
        ]
        for v in violations[:limit]
    ]
    more = f"<p>… and {len(violations) - limit} more.</p>" if len(violations) > limit else ""
    header = ["limit", "joint", "first", "last", "worst", "bound", "message"]
    return f"<h3>Violations ({len(violations)})</h3>" + _grid(header, rows) + more


def _slowdowns_table(result: PlanResult) -> str:
    if not result.slowdowns:
        return "<h3>Slow-downs</h3><p>None: every straight piece runs at the rated speed.</p>"
    rows: list[list[Cell]] = [
        [
            str(k + 1),  # the number speed.png labels it with
            _num(s.s_start, unit="m"),
            _num(s.s_end, unit="m"),
            _num(s.speed, scale=1e3, unit="mm/s"),
            _num(s.rated_speed, scale=1e3, unit="mm/s"),
            (_esc(s.limit), "text"),
        ]
        for k, s in enumerate(result.slowdowns)
    ]
    return "<h3>Slow-downs</h3>" + _grid(
        ["#", "from s", "to s", "speed", "rated", "forced by"], rows
    )


def _references_table(result: PlanResult) -> str:
    if not result.references:
        return "<h3>Reference durations</h3><p>Not computed.</p>"
    rows = [
        [
            _esc(name.removesuffix("_duration")),
            _num(value, unit="s"),
            _num(result.duration / value if value else float("nan")),
        ]
        for name, value in result.references.items()
    ]
    return "<h3>Reference durations</h3>" + _grid(
        ["reference", "duration", "ours / reference"], rows
    )


def _format_value(value: object) -> str:
    if isinstance(value, bool):
        return "yes" if value else "no"
    if isinstance(value, float | np.floating):
        return _num(float(value), 6)
    if isinstance(value, np.ndarray | list | tuple):
        items = np.asarray(value).ravel().tolist()
        return (
            "("
            + ", ".join(_format_value(v) for v in items[:12])
            + (", …)" if len(items) > 12 else ")")
        )
    if isinstance(value, Mapping):
        return _key_values((str(k), _format_value(v)) for k, v in value.items())
    return _esc(value)


PLACEMENT_KEYS = ("x", "y", "z", "roll", "pitch", "yaw")
PLACEMENT_HEADER = ["x [m]", "y [m]", "z [m]", "roll [rad]", "pitch [rad]", "yaw [rad]"]
"""Columns of a placement X in the report's tables."""

_SEARCH_KEYS = ("optimizer", "initial", "robot", "status", "plan_status", "interrupted")
"""Keys of ``optimizer_info`` (the ``result.json`` blocks of a run) that the placement
search section lays out as tables, or leaves out (``robot``: in the Case section)."""


def _search_tables(info: Mapping[str, object], result: PlanResult) -> str:
    """The search (method, budget, time, stop) and the placements before, after and
    rejected, as tables with named columns, from the ``optimizer`` and ``initial`` blocks
    of ``result.json`` (:func:`trackplan.io.history.optimizer_summary`)."""
    parts = []
    optimizer = info.get("optimizer")
    if isinstance(optimizer, Mapping):
        header = [
            "method",
            "seed",
            "runs",
            "generations",
            "evaluations",
            "wall time [s]",
            "best fitness",
            "stopped",
        ]
        row: list[Cell] = [
            _esc(optimizer.get("method", "–")),
            *(
                _esc(optimizer.get(key, "–"))
                for key in ("seed", "runs", "generations", "evaluations")
            ),
            _num(optimizer.get("wall_time_s")),
            _num(optimizer.get("fitness"), 6),
            (_esc(optimizer.get("stop_reason", "–")), "text"),
        ]
        parts.append(_grid(header, [row]))
    interrupted = info.get("interrupted")
    if isinstance(interrupted, Mapping) and "message" in interrupted:
        parts.append(f'<p class="bad">{_esc(interrupted["message"])}</p>')
    rows: list[list[Cell]] = []
    initial = info.get("initial")
    if isinstance(initial, Mapping) and isinstance(initial.get("placement"), Mapping):
        placement = initial["placement"]
        verdict = initial.get("status", "feasible" if initial.get("feasible") else "infeasible")
        rows.append(
            [
                "before (centre of the bounds)",
                *(_num(placement.get(key)) for key in PLACEMENT_KEYS),
                (_esc(verdict), "text"),
                _num(initial.get("objective"), 6),
            ]
        )
    rows.append(
        [
            "after (best found)",
            *(_num(v) for v in result.placement),
            (_esc(result.status.value), "text"),
            _num(result.objective, 6),
        ]
    )
    rejected = optimizer.get("rejected_candidates", []) if isinstance(optimizer, Mapping) else []
    for k, X in enumerate(rejected or []):  # type: ignore[union-attr]
        rows.append(
            [
                f"rejected {k + 1} (failed the final check)",
                *(_num(v) for v in X),
                ("rejected", "text"),
                "–",
            ]
        )
    parts.append(
        "<h4>Placements</h4>" + _grid(["placement", *PLACEMENT_HEADER, "verdict", "J"], rows)
    )
    return "".join(parts)


def _optimizer_section(
    optimizer_info: Mapping[str, object] | None,
    history: Mapping[str, Mapping[str, np.ndarray]] | None,
    result: PlanResult,
) -> str:
    info = optimizer_info or {}
    searched = "optimizer" in info or "initial" in info
    others = [(str(k), v) for k, v in info.items() if k not in _SEARCH_KEYS]
    if not searched and not others and not history:
        return ""
    parts = ["<h3>Placement search</h3>"]
    if searched:
        parts.append(_search_tables(info, result))
    if others:
        parts.append(_key_values((k, _format_value(v)) for k, v in others))
    if history:
        rows = [
            [
                _esc(method),
                str(len(c["generation"])),
                _num(c["evaluations"][-1], 6),
                _num(c["best"][-1], 6),
                _num(c["mean"][-1], 4),
                _percent(c["feasible_share"][-1]),
                _num(c["wall_time"][-1], 4),
            ]
            for method, c in history_columns(history).items()
        ]
        header = [
            "method",
            "generations",
            "evaluations",
            "best",
            "last mean",
            "last feasible share",
            "wall time [s]",
        ]
        parts.append("<h4>History</h4>" + _grid(header, rows))
    return "".join(parts)


def _plots_section(paths: Sequence[Path]) -> str:
    items = []
    for path in paths:
        title, caption = _PLOT_CAPTIONS.get(path.name, (path.stem, ""))
        data = base64.b64encode(path.read_bytes()).decode("ascii")
        items.append(
            f'<figure id="plot-{_esc(path.stem)}"><h3>{_esc(title)}</h3>'
            f'<img alt="{_esc(title)}" src="data:image/png;base64,{data}">'
            f"<figcaption>{_esc(caption)} (file: {_esc(path.name)})</figcaption></figure>"
        )
    return '<section id="plots"><h2>Plots</h2>' + "".join(items) + "</section>"


def view_section(result: PlanResult, case: Case, n_frames: int = 150) -> str:
    """The report's 3D view section: the robot following the path (plotly.js embedded), or
    a note when there is no trajectory. ``n_frames`` animation frames."""
    if result.trajectory.n_samples == 0:
        return (
            '<section id="view"><h2>3D view</h2><p>No trajectory to show: '
            f"{_esc(result.message)}</p></section>"
        )
    div = plotly_div(
        robot_view_spec(result, case, n_frames=n_frames),
        VIEW_ID,
        config={"displaylogo": False, "responsive": True},
        post_script=_QUIET_INTERRUPTS,
    )
    return (
        '<section id="view"><h2>3D view</h2><p class="muted">The robot drawn from its DH chain '
        "(links between frame origins, a marker per joint) follows the placed path. Drag to "
        "rotate, scroll to zoom, ▶ play or move the time slider; click legend entries to show "
        f"or hide the path, frames and reach shell.</p>{div}</section>"
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
            f"<h1>{_esc(case.name)}: {verdict}</h1>",
            f"<p>{_verdict_badge(result)} {_esc(result.message)}</p>",
            _bounds_line(optimizer_info),
            '<nav><a href="#case">Case</a><a href="#result">Result</a><a href="#plots">Plots</a>'
            '<a href="#view">3D view</a></nav>',
            _case_section(result, case),
            '<section id="result"><h2>Result</h2>',
            '<div class="cols"><div><h3>Key figures</h3>',
            _figures_table(result, case),
            "</div><div>",
            _references_table(result),
            _slowdowns_table(result),
            _optimizer_section(optimizer_info, history, result),
            "</div></div>",
            _margins_table(result, case),
            _violations_table(result),
            "</section>",
            _plots_section(plots),
            view,
        ]
    )
    return html_page(f"trackplan report: {case.name}", body)


def html_page(title: str, body: str) -> str:
    """A self-contained page in the report's look: ``title`` (text) and ``body`` (HTML)
    with the report's style sheet. ``report.html``, a cycle's report and ``map.html`` are
    all built with it."""
    return (
        '<!DOCTYPE html>\n<html lang="en"><head><meta charset="utf-8">'
        '<meta name="viewport" content="width=device-width, initial-scale=1">'
        f"<title>{_esc(title)}</title><style>{_CSS}</style></head>"
        f"<body>{body}</body></html>\n"
    )


def _bounds_line(optimizer_info: Mapping[str, object] | None) -> str:
    """A line under the verdict when the search's placement lies on a bound of its box
    (``optimizer.on_bounds`` of result.json); '' otherwise."""
    search = (optimizer_info or {}).get("optimizer")
    hits = search.get("on_bounds") if isinstance(search, Mapping) else None
    if not hits:
        return ""
    from trackplan.search.space import BoundHit, bounds_note

    note = bounds_note([BoundHit(**hit) for hit in hits])
    return f'<p id="on-bounds">Note: {_esc(note)}</p>'


def _tool_text(tool) -> str:  # type: ignore[no-untyped-def]
    """The tool spec in one line (docs/tool.md)."""
    if str(tool.frame) == "part":
        where = f"part frame, roll/pitch/yaw {_vector(tool.rpy)} rad"
    else:
        normal = (
            f"normal {_vector(tool.normal)}"
            if tool.normals is None
            else "normals " + " ".join(_vector(n) for n in tool.normals)
        )
        where = (
            f"seam frame, {normal}, work {tool.work_angle:.4g} rad, "
            f"travel {tool.travel_angle:.4g} rad"
        )
    return f"{where}; spin {tool.spin}"
