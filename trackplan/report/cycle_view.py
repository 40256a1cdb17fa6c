"""The 3D view of a plan whose seams are joined by moves: each seam and each move drawn
on its own, and every seam's nominal path.

:func:`cycle_view_spec` takes the view of :func:`~trackplan.report.robot_view.robot_view_spec`
(the robot following the whole trajectory) and replaces its one planned path and its first
seam's nominal path by one trace per seam (in the colours of ``cycle.png``), the approach,
retract and air moves (dashed, one trace per kind) and one nominal path per seam; the
animated traces and their frames stay as they are. With a positioner the part, its path
and its seams move with the flange (:mod:`~trackplan.report.machine_view`) and the view
is left unchanged.
"""

from __future__ import annotations

import numpy as np

from trackplan.case import Case
from trackplan.frames import placement_transform
from trackplan.paths.nominal import NominalPath
from trackplan.planning.result import MOVE_KINDS, SEAM, PlanResult
from trackplan.report.cycle import has_moves
from trackplan.report.machine_view import moves_the_part
from trackplan.report.robot_view import NOMINAL_TRACE, PATH_TRACE
from trackplan.report.scene import DRAWING_STEP, plotly_xyz, transform_points

SEAM_COLORS = (
    "#1f77b4",
    "#ff7f0e",
    "#2ca02c",
    "#d62728",
    "#9467bd",
    "#8c564b",
    "#e377c2",
    "#7f7f7f",
    "#bcbd22",
    "#17becf",
)
"""matplotlib's ``C0``–``C9``: a seam has the same colour here as in ``cycle.png``."""
MOVE_LINE = {"approach": "#737373", "retract": "#a6a6a6", "air": "#333333"}
"""The grey of each move kind (``cycle.MOVE_COLORS`` as hex)."""
MOST_POINTS = 2000
"""Most points drawn per trace (longer spans are thinned evenly)."""


def _thin(points: np.ndarray, n_points: int = MOST_POINTS) -> np.ndarray:
    """Every k-th point of ``points`` and its last, at most about ``n_points``."""
    step = max(1, len(points) // n_points)
    return points if step == 1 else np.vstack([points[::step], points[-1:]])


def _joined(pieces: list[np.ndarray]) -> np.ndarray:
    """Polylines as one, with a NaN row (a gap in plotly) between them."""
    gap = np.full((1, 3), np.nan)
    rows: list[np.ndarray] = []
    for piece in pieces:
        rows += [piece, gap]
    return np.vstack(rows[:-1]) if rows else np.zeros((0, 3))


def cycle_traces(result: PlanResult, case: Case) -> list[dict]:
    """The static traces of a cycle: per seam its planned path (``name`` the seam's, with
    ``(reversed)`` when welded end to start) and its nominal path, and per move kind its
    spans (``approach``, ``retract``, ``air`` moves, dashed), base frame, m."""
    position = result.trajectory.tool_position
    T_base_part = placement_transform(result.placement)
    names = case.seam_names
    traces: list[dict] = []
    moves: dict[str, list[np.ndarray]] = {kind: [] for kind in MOVE_KINDS}
    for span in result.spans:
        points = _thin(position[span.first : span.last + 1])
        if span.kind != SEAM:
            moves[span.kind].append(points)
            continue
        index = names.index(span.label)
        color = SEAM_COLORS[index % len(SEAM_COLORS)]
        seam = case.seams[index]
        nominal = NominalPath.from_specs(seam.start, seam.segments).polyline(DRAWING_STEP)
        direction = " (reversed)" if span.reversed else ""
        traces.append(
            {
                "type": "scatter3d",
                **plotly_xyz(points),
                "mode": "lines",
                "name": f"seam {span.label}{direction}",
                "legendgroup": span.label,
                "line": {"color": color, "width": 6},
                "hovertext": span.label,
                "hoverinfo": "text",
            }
        )
        traces.append(
            {
                "type": "scatter3d",
                **plotly_xyz(_thin(transform_points(T_base_part, nominal))),
                "mode": "lines",
                "name": f"{NOMINAL_TRACE}: {span.label}",
                "legendgroup": span.label,
                "showlegend": False,
                "line": {"color": color, "width": 2, "dash": "dash"},
                "hoverinfo": "skip",
            }
        )
    for kind, pieces in moves.items():
        if pieces:
            traces.append(
                {
                    "type": "scatter3d",
                    **plotly_xyz(_joined(pieces)),
                    "mode": "lines",
                    "name": f"{kind} moves",
                    "line": {"color": MOVE_LINE[kind], "width": 3, "dash": "dash"},
                    "hoverinfo": "name",
                }
            )
    return traces


def cycle_view_spec(spec: dict, result: PlanResult, case: Case) -> dict:
    """``spec`` (:func:`~trackplan.report.robot_view.robot_view_spec`) with the traces of
    :func:`cycle_traces` in place of its planned and nominal paths, for a plan whose seams
    are joined by moves and whose part stands still; ``spec`` unchanged otherwise.

    The replaced traces are static (before every animated trace), so the animated traces
    move down by the difference and their frames' ``traces`` indices with them.
    """
    if not has_moves(result, case) or moves_the_part(case) or not result.spans:
        return spec
    frames = spec["frames"]
    animated = set(frames[0]["traces"]) if frames else set()
    data = spec["data"]
    static = [trace for i, trace in enumerate(data) if i not in animated]
    moving = [trace for i, trace in enumerate(data) if i in animated]
    kept = [t for t in static if t.get("name") not in (PATH_TRACE, NOMINAL_TRACE)]
    new_static = kept + cycle_traces(result, case)
    first = len(new_static)
    index = {old: first + k for k, old in enumerate(sorted(animated))}
    return {
        **spec,
        "data": new_static + moving,
        "frames": [{**f, "traces": [index[i] for i in f["traces"]]} for f in frames],
    }


__all__ = ["MOVE_LINE", "SEAM_COLORS", "cycle_traces", "cycle_view_spec"]
