"""The whole-trajectory check of :func:`trackplan.planning.plan.plan` and ``check``.

Every sample's joint limits and, with a cell, clearance; every seam's tracking,
orientation, speed and coverage on its own samples (:func:`check_spans`). A trajectory
that is one seam from end to end is checked in one call against that seam, the cell
included. A trajectory read back is cut into spans by its ``segment`` labels
(:func:`spans_from_segments`).
"""

from __future__ import annotations

from dataclasses import replace
from typing import TYPE_CHECKING

import numpy as np

from trackplan.case import Case
from trackplan.check_report import DownhandFigures
from trackplan.errors import CaseError
from trackplan.frames import as_placement, placement_transform
from trackplan.paths.nominal import NominalPath
from trackplan.planning.checker import check_trajectory
from trackplan.planning.result import MOVE_KINDS, SEAM, CheckReport, Span, Violation
from trackplan.planning.seam_plan import case_geometry, cell_geometry, tracking_reference
from trackplan.planning.seams import SeamGeometries, reversed_segments, seam_direction_case
from trackplan.robots.machine import carrier_tool
from trackplan.timing import time_law

if TYPE_CHECKING:  # the cell's compiled screening only for cases with a cell
    from trackplan.cell.screening import CellGeometry


def check_spans(
    case: Case,
    X: np.ndarray,
    q: np.ndarray,
    sample_time: float,
    spans: list[Span] | tuple[Span, ...],
    geometries: SeamGeometries | None = None,
    seam_reports: dict[int, CheckReport] | None = None,
    timing: str | None = None,
) -> tuple[CheckReport, tuple[CheckReport, ...]]:
    """Check a whole trajectory: every sample's joint limits and clearance, every seam's task.

    Parameters
    ----------
    case
        The case.
    X
        Placement, shape (6,), metres and radians.
    q
        The whole trajectory, shape (N, n), rad.
    sample_time
        Ts, s.
    spans
        Where each seam lies in ``q`` (and in which direction).
    geometries
        The seams' paths when already built (:func:`seam_geometries`).
    seam_reports
        Each seam's own report by span index, when already made on exactly its samples
        (a seam plan's check: the same call on the same samples).
    timing
        The time law whose planned paths the speeds refer to; default each seam's.

    Returns
    -------
    tuple
        The whole report (joint limits and clearance of every sample, plus each seam's
        task violations, named and timed in the trajectory) and each seam's own task report
        in the order of ``spans``.
    """
    X = as_placement(X)
    q = np.asarray(q, dtype=float)
    if len(spans) == 1 and spans[0].kind == SEAM and spans[0].last - spans[0].first + 1 == len(q):
        # the trajectory is one seam: its own check, the cell included
        known = (seam_reports or {}).get(0)
        if known is None:
            cell = cell_geometry(case)
            known = _seam_report(case, X, q, sample_time, spans[0], geometries, timing, cell)
        return known, (known,)
    whole = check_trajectory(case.machine, q, sample_time)
    cell = cell_geometry(case)
    cell_report = None
    violations = list(whole.violations)
    task_margins: dict[str, float] = {}
    if cell is not None:  # the cell's exact check (coal) only for a case with a cell
        from trackplan.cell.check import check_cell

        cell_report = check_cell(cell, case.machine, q, sample_time, placement_transform(X))
        violations += list(cell_report.violations)
        task_margins["clearance"] = cell_report.margin
    seam_checks: list[CheckReport] = []
    tracking = 0.0
    orientation = 0.0
    for k, span in enumerate(spans):
        if span.kind != SEAM or span.seam is None:
            continue
        known = (seam_reports or {}).get(k)
        if known is not None:
            own = known
        else:
            own = _seam_report(case, X, q, sample_time, span, geometries, timing)
        seam_checks.append(own)
        tracking = max(tracking, own.max_tracking_error)
        orientation = max(orientation, own.max_orientation_error)
        for kind, value in own.task_margins.items():
            task_margins[kind] = min(task_margins.get(kind, np.inf), value)
        offset = span.first * sample_time
        violations += [
            replace(
                v,
                t_first=v.t_first + offset,
                t_last=v.t_last + offset,
                message=f"seam {span.label}: {v.message} (seam time; it starts at "
                f"t = {offset:.3f} s)",
            )
            for v in own.violations
            if v.joint is None
        ]
    report = CheckReport(
        success=not violations,
        joint_margins=whole.joint_margins,
        task_margins=task_margins,
        violations=tuple(violations),
        max_tracking_error=tracking,
        max_orientation_error=orientation,
        binding=whole.binding,
        cell=cell_report,
        downhand=merged_downhand([own.downhand for own in seam_checks]),
    )
    return report, tuple(seam_checks)


def merged_downhand(figures: list[DownhandFigures | None]) -> DownhandFigures | None:
    """The seams' downhand figures as one: the largest angles, the share over every seam
    (each seam's share weighted alike); None when no seam has the rule."""
    found = [f for f in figures if f is not None]
    if not found:
        return None
    return DownhandFigures(
        max_slope=max(f.max_slope for f in found),
        max_rotation=max(f.max_rotation for f in found),
        slope=found[0].slope,
        rotation=found[0].rotation,
        share=float(np.mean([f.share for f in found])),
    )


def spans_from_segments(
    case: Case, X: np.ndarray, q: np.ndarray, segment: np.ndarray
) -> tuple[Span, ...]:
    """The spans of a trajectory from its ``segment`` labels (a trajectory.csv read
    back): runs of one label; a seam's direction is the one whose start lies nearer the
    tool point at the run's first sample (for a closed seam, the way the tool runs along it).

    Parameters
    ----------
    case
        The case.
    X
        Placement, shape (6,).
    q
        Joint positions, shape (N, n), rad.
    segment
        Label per sample, shape (N,), str.

    Raises
    ------
    CaseError
        When a label is neither a seam of the case nor a move kind.
    """
    names = [seam.name for seam in case.seams]
    labels = np.asarray(segment).astype(str)
    change = np.flatnonzero(labels[1:] != labels[:-1]) + 1
    starts = np.r_[0, change]
    ends = np.r_[change - 1, len(labels) - 1]
    T_base_part = placement_transform(as_placement(X))
    spans = []
    for begin, end in zip(starts, ends, strict=True):
        label = str(labels[begin])
        first = max(int(begin) - 1, 0)  # the shared sample carries the earlier label
        if label in MOVE_KINDS:
            spans.append(Span(kind=label, label=label, first=first, last=int(end)))
            continue
        if label not in names:
            raise CaseError(
                f"segment {label!r} is neither a seam of the case ({', '.join(names)}) "
                f"nor one of {', '.join(MOVE_KINDS)}",
                key="segment",
            )
        i = names.index(label)
        seam = case.seams[i]
        tool = carrier_tool(case.machine, q[first])[:3, 3]
        forward = T_base_part[:3, :3] @ seam.start + T_base_part[:3, 3]
        backward_start, _ = reversed_segments(seam.start, seam.segments)
        backward = T_base_part[:3, :3] @ backward_start + T_base_part[:3, 3]
        if np.linalg.norm(forward - backward) > seam.task.tolerance:
            reverse = bool(np.linalg.norm(tool - backward) < np.linalg.norm(tool - forward))
        else:  # a closed seam: the way it runs
            reverse = _runs_backwards(case, i, q[first : int(end) + 1], T_base_part)
        spans.append(
            Span(kind=SEAM, label=label, first=first, last=int(end), seam=i, reversed=reverse)
        )
    return tuple(spans)


def _runs_backwards(case: Case, index: int, q: np.ndarray, T_base_part: np.ndarray) -> bool:
    """Whether the samples q (K, n) of a closed seam run it end to start: the tool's
    projections on the seam as written at a quarter and at half of the run go backwards."""
    seam = case.seams[index]
    quarter, half = len(q) // 4, len(q) // 2
    frames = carrier_tool(case.machine, q[[quarter, half]])
    points = (frames[:, :3, 3] - T_base_part[:3, 3]) @ T_base_part[:3, :3]  # part frame
    s, _ = NominalPath.from_specs(seam.start, seam.segments).project(points)
    return bool(s[1] < s[0])


def uncovered_seams(case: Case, spans: tuple[Span, ...]) -> tuple[Violation, ...]:
    """A ``coverage`` violation for every seam of the case that no span welds."""
    welded = {span.seam for span in spans if span.kind == SEAM}
    return tuple(
        Violation(
            limit="coverage",
            joint=None,
            t_first=0.0,
            t_last=0.0,
            worst=float("nan"),
            bound=0.0,
            message=f"seam {seam.name} is not welded: no sample carries its name",
        )
        for i, seam in enumerate(case.seams)
        if i not in welded
    )


def _seam_report(
    case: Case,
    X: np.ndarray,
    q: np.ndarray,
    sample_time: float,
    span: Span,
    geometries: SeamGeometries | None,
    timing: str | None,
    cell: CellGeometry | None = None,
) -> CheckReport:
    """One seam's samples checked against its task (tracking, orientation, speed, coverage)."""
    assert span.seam is not None
    seam_case = seam_direction_case(case, span.seam, span.reversed)
    geometry = (geometries or {}).get((span.seam, span.reversed))
    mode = time_law(timing or seam_case.task.timing).path_mode
    if geometry is None or geometry.mode != mode:
        geometry = case_geometry(seam_case, mode)
    reference = tracking_reference(seam_case, geometry, X)
    samples = q[span.first : span.last + 1]
    return check_trajectory(case.machine, samples, sample_time, reference, cell)


__all__ = ["check_spans", "spans_from_segments", "uncovered_seams"]
