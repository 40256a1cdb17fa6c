"""The 3D view of a plan whose seams are joined by moves: each seam and each move drawn
on its own, and every seam's nominal path.

:func:`cycle_view_spec` takes the view of :func:`~trackplan.report.robot_view.robot_view_spec`
(the robot following the whole trajectory) and replaces its one planned path and its first
seam's nominal path by one trace per seam (in the colours of ``cycle.png``), the approach,
retract and air moves (dashed, one trace per kind) and one nominal path per seam; the
animated traces and their frames stay as they are. With a positioner the part rides on its
flange (:mod:`~trackplan.report.machine_view`), so the same seams, nominal paths and moves
are animated traces instead, carried by the flange in every frame (the positioner's links,
the workpiece and the track's carriage are machine_view's, drawn over the whole cycle).
"""

from __future__ import annotations

import numpy as np

from trackplan.case import Case
from trackplan.frames import placement_transform
from trackplan.paths.nominal import NominalPath
from trackplan.planning.result import MOVE_KINDS, SEAM, PlanResult
from trackplan.report.cycle import has_moves
from trackplan.report.machine_view import (
    PART_POINTS,
    TraceBuilder,
    moves_the_part,
    moving_line_builder,
    moving_points,
    part_transforms,
    thin_polyline,
)
from trackplan.report.robot_view import NOMINAL_TRACE, PATH_TRACE
from trackplan.report.scene import DRAWING_STEP, frame_indices, plotly_xyz, transform_points
from trackplan.robots.machine import Machine

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


def _cycle_lines(result: PlanResult, case: Case) -> list[tuple[dict, np.ndarray, str]]:
    """The polylines of a cycle, each as (style, points (M, 3), frame): per seam its
    planned path (``frame`` ``"tool"``: the frame of ``trajectory.tool_position``) and its
    nominal path (``"part"``: the definition frame), per move kind its spans (``"tool"``)."""
    position = result.trajectory.tool_position
    names = case.seam_names
    lines: list[tuple[dict, np.ndarray, str]] = []
    moves: dict[str, list[np.ndarray]] = {kind: [] for kind in MOVE_KINDS}
    for span in result.spans:
        points = position[span.first : span.last + 1]
        if span.kind != SEAM:
            moves[span.kind].append(points)
            continue
        index = names.index(span.label)
        color = SEAM_COLORS[index % len(SEAM_COLORS)]
        seam = case.seams[index]
        nominal = NominalPath.from_specs(seam.start, seam.segments).polyline(DRAWING_STEP)
        direction = " (reversed)" if span.reversed else ""
        seam_style = {
            "name": f"seam {span.label}{direction}",
            "legendgroup": span.label,
            "line": {"color": color, "width": 6},
            "hovertext": span.label,
            "hoverinfo": "text",
        }
        nominal_style = {
            "name": f"{NOMINAL_TRACE}: {span.label}",
            "legendgroup": span.label,
            "showlegend": False,
            "line": {"color": color, "width": 2, "dash": "dash"},
            "hoverinfo": "skip",
        }
        lines += [(seam_style, points, "tool"), (nominal_style, nominal, "part")]
    for kind, pieces in moves.items():
        if pieces:
            style = {
                "name": f"{kind} moves",
                "line": {"color": MOVE_LINE[kind], "width": 3, "dash": "dash"},
                "hoverinfo": "name",
            }
            lines.append((style, _joined(pieces), "tool"))
    return lines


def cycle_traces(result: PlanResult, case: Case) -> list[dict]:
    """The static traces of a cycle whose part stands still: per seam its planned path
    (``name`` the seam's, with ``(reversed)`` when welded end to start) and its nominal
    path, and per move kind its spans (``approach``, ``retract``, ``air`` moves, dashed),
    base frame, m."""
    T_base_part = placement_transform(result.placement)
    traces = []
    for style, points, frame in _cycle_lines(result, case):
        placed = transform_points(T_base_part, points) if frame == "part" else points
        traces.append({"type": "scatter3d", **plotly_xyz(_thin(placed)), "mode": "lines", **style})
    return traces


def moving_cycle_builders(
    result: PlanResult, case: Case, idx: np.ndarray, n_points: int = 2 * PART_POINTS
) -> list[TraceBuilder]:
    """The animated traces of a cycle whose part rides on a positioner: the lines of
    :func:`cycle_traces`, each carried by the flange at the samples ``idx`` (F,).

    The planned paths and the moves are the tool's positions relative to the flange
    (``trajectory.tool_position``), placed with ``T_cell_carrier(q)``; the nominal paths
    are in the part's definition frame, placed with ``T_cell_carrier(q) · T(X)``
    (:func:`~trackplan.report.machine_view.part_transforms`). They are sent in every
    frame, so they share ``n_points`` points per frame (each line's share in proportion
    to its points, at least 2), as many as the one seam's nominal and planned paths.
    """
    machine = case.machine
    assert isinstance(machine, Machine)
    q = result.trajectory.q[idx]
    T = {"tool": machine.T_cell_carrier(q), "part": part_transforms(result, case, q)}
    lines = _cycle_lines(result, case)
    total = sum(len(points) for _, points, _ in lines)
    builders = []
    for style, points, frame in lines:
        share = max(2, n_points * len(points) // max(1, total))
        moving = moving_points(T[frame], thin_polyline(points, share))
        builders.append(moving_line_builder(moving, style))
    return builders


def cycle_view_spec(spec: dict, result: PlanResult, case: Case) -> dict:
    """``spec`` (:func:`~trackplan.report.robot_view.robot_view_spec`) with the traces of a
    cycle in place of its planned and nominal paths, for a plan whose seams are joined by
    moves; ``spec`` unchanged otherwise.

    When the part stands still the cycle's lines are static (:func:`cycle_traces`) and the
    replaced traces are static too (before every animated trace), so the animated traces
    move down by the difference and their frames' ``traces`` indices with them. With a
    positioner the replaced traces are animated: the cycle's lines
    (:func:`moving_cycle_builders`) take their place after the other animated traces, in
    the first frame's data and in every frame.
    """
    if not has_moves(result, case) or not result.spans:
        return spec
    frames = spec["frames"]
    if moves_the_part(case):
        if not frames:
            return spec
        idx = frame_indices(result.trajectory.n_samples, len(frames))
        return _with_animated(spec, moving_cycle_builders(result, case, idx))
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


def _with_animated(spec: dict, builders: list[TraceBuilder]) -> dict:
    """``spec`` without its animated planned and nominal paths, with the traces of
    ``builders`` animated after its other animated traces (their order kept: the robot's
    joints stay each frame's first)."""
    data, frames = spec["data"], spec["frames"]
    animated = frames[0]["traces"]
    static = [trace for i, trace in enumerate(data) if i not in set(animated)]
    kept = [i for i in animated if data[i].get("name") not in (PATH_TRACE, NOMINAL_TRACE)]
    ids = list(range(len(static), len(static) + len(kept) + len(builders)))
    new_frames = []
    for k, frame in enumerate(frames):
        by_id = dict(zip(frame["traces"], frame["data"], strict=True))
        frame_data = [by_id[i] for i in kept] + [build(k) for build in builders]
        new_frames.append({**frame, "data": frame_data, "traces": ids})
    first = [data[i] for i in kept] + [build(0) for build in builders]
    return {**spec, "data": static + first, "frames": new_frames}


__all__ = [
    "MOVE_LINE",
    "SEAM_COLORS",
    "cycle_traces",
    "cycle_view_spec",
    "moving_cycle_builders",
]
