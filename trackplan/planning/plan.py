"""Plan or check a case at one placement: the one pipeline for every case.

``case → seam stage (every seam planned at X: path geometry, joint path, time law,
trajectory, check) → sequence stage (order and directions) → assembly (approach, retract
and air moves, one trajectory) → whole-trajectory check``.

A case is a set of seams; a single-path case is one seam, and with the given sequence, no
approach and no home its plan is that seam's plan (:mod:`~trackplan.planning.seam_plan`).
Several seams, an approach or a home add the moves (:mod:`~trackplan.planning.assembly`,
``docs/seams.md``).
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from trackplan.case import Case
from trackplan.errors import CaseError
from trackplan.frames import as_placement
from trackplan.planning.assembly import join_seams, unplanned
from trackplan.planning.ordering import order_seams
from trackplan.planning.result import SEAM, CheckReport, PlanResult, Span
from trackplan.planning.seam_plan import (
    CELL_KINDS,
    case_geometry,
    cell_geometry,
    check_task_values,
    make_trajectory,
    motion_trajectory,
    tracking_reference,
)
from trackplan.planning.seams import (
    SeamGeometries,
    SeamSpin,
    check_sequence,
    directions,
    plan_seams,
)
from trackplan.planning.sequence import Sequence
from trackplan.planning.trajectory_check import (
    check_spans,
    spans_from_segments,
    uncovered_seams,
)
from trackplan.tool import SpinProfile


def plan(
    case: Case,
    X: np.ndarray,
    *,
    timing: str | None = None,
    sequence: Sequence | None = None,
    geometries: SeamGeometries | None = None,
    branches: tuple[int, ...] | None = None,
    spins: tuple[SeamSpin, ...] | None = None,
    branch: int | None = None,
    spin: np.ndarray | SpinProfile | None = None,
) -> PlanResult:
    """Plan every seam of the case at placement X, sequence them, join them and check.

    Parameters
    ----------
    case
        The case (one seam or several).
    X
        Placement (x, y, z, roll, pitch, yaw), shape (6,), metres and radians.
    timing
        A time law of :data:`trackplan.timing.TIME_LAWS` (``smooth`` or ``paper``);
        default: each seam's ``task.timing``.
    sequence
        Force this order and these directions; default the case's
        ``sequencing.sequence`` (``optimize``: the best sequence; ``given``: as written,
        forward).
    geometries
        The seams' paths when already built for this law, by ``(seam, reversed)``
        (:func:`~trackplan.planning.seams.seam_geometries`); a geometry of another path
        mode is rebuilt.
    branches
        The IK branch of each seam (as written), both directions; default: per seam the
        one with the largest joint-limit margin.
    spins
        The spin of each seam (as written, :data:`~trackplan.planning.seams.SeamSpin`;
        see :func:`~trackplan.planning.seams.seam_spin`); default: each free spin in the
        middle of its range.
    branch
        One IK branch for every seam (``branches`` with the same value for each).
    spin
        The spin of a single-seam case: spin variables of its tool spec, shape (n_spin,)
        (:meth:`~trackplan.tool.ToolSpec.profile`), or a given
        :class:`~trackplan.tool.SpinProfile`. To choose them, see
        :func:`trackplan.search.spin.optimize_spin`.

    Returns
    -------
    PlanResult
        Feasible or not, with the trajectory (empty when some seam is unreachable) and the
        checker's report.

    Raises
    ------
    CaseError
        When X is not 6 finite numbers, the timing names no law, a task value is not a
        finite number > 0, a forced sequence names a seam twice or reverses a seam that
        may not be reversed, ``spins`` does not give one spin per seam, ``spin`` is given
        for several seams, ``branch`` and ``branches`` are both given, or a given spin
        leaves its tool's range or rate.
    """
    X = as_placement(X)
    seams = case.seams
    m = len(seams)
    for index, seam in enumerate(seams):
        check_task_values(seam.task, "task" if m == 1 else f"paths[{index}].task")
    if sequence is not None:
        check_sequence(case, sequence)
    if spins is not None and len(spins) != m:
        raise CaseError(f"give one spin per seam ({m}), got {len(spins)}", key="spin")
    if spin is not None and m > 1:
        raise CaseError(
            f"case {case.name} has {m} seams: give one spin per seam (spins=...)", key="spin"
        )
    if branch is not None:
        if branches is not None:
            raise CaseError("give branch (every seam) or branches (per seam), not both")
        branches = (branch,) * m
    with_cell = m == 1 and case.sequencing.approach == 0.0 and case.sequencing.home is None
    stage = plan_seams(
        case,
        X,
        directions(case, case.sequencing.sequence, sequence),
        timing=timing,
        geometries=geometries,
        branches=branches,
        spins=spins,
        spin=spin,
        with_cell=with_cell,
    )
    if stage.failed:
        return unplanned(case, X, stage.failed)
    return join_seams(case, X, stage, sequence or order_seams(case, stage))


def check(
    case: Case,
    X: np.ndarray,
    q: np.ndarray,
    sample_time: float,
    *,
    timing: str | None = None,
    segment: np.ndarray | None = None,
) -> CheckReport:
    """Check any joint trajectory against a case with the workpiece at placement X.

    The one call behind ``trackplan check``: the joint limits of every sample, the
    tracking, speed, orientation and coverage of every seam on its own samples, and the
    case's cell.

    Parameters
    ----------
    case
        The case.
    X
        Placement, shape (6,), metres and radians.
    q
        Joint positions at every sample, shape (N, n), rad.
    sample_time
        Ts, s.
    timing
        The time law whose planned paths the speeds refer to; default each seam's.
    segment
        The ``segment`` label of every sample, shape (N,) (trajectory.csv's column: a
        seam's name or ``approach``, ``retract``, ``air``); default every sample on the
        case's one seam, welded the way the samples run when the seam is reversible.

    Returns
    -------
    CheckReport
        A seam of the case that no sample welds is a ``coverage`` violation.

    Raises
    ------
    CaseError
        When a task value is not a finite number > 0, a label is neither a seam of the
        case nor a move, or ``segment`` is missing for a case with several seams.
    """
    q = np.asarray(q, dtype=float)
    seams = case.seams
    for index, seam in enumerate(seams):
        check_task_values(seam.task, "task" if len(seams) == 1 else f"paths[{index}].task")
    if segment is None:
        if len(seams) > 1:
            raise CaseError(
                f"case {case.name} has {len(seams)} seams: the trajectory needs its "
                "segment column (the seam or move of every sample)",
                key="segment",
            )
        spans: tuple[Span, ...] = (
            Span(kind=SEAM, label=seams[0].name, first=0, last=len(q) - 1, seam=0),
        )
        if seams[0].reversible and len(q):  # welded either way: the samples say which
            spans = spans_from_segments(case, X, q, np.full(len(q), seams[0].name, dtype=object))
    else:
        spans = spans_from_segments(case, X, q, segment)
    report, _ = check_spans(case, X, q, sample_time, spans, timing=timing)
    missing = uncovered_seams(case, spans)
    if not missing:
        return report
    return replace(report, success=False, violations=report.violations + missing)


__all__ = [
    "CELL_KINDS",
    "case_geometry",
    "cell_geometry",
    "check",
    "check_task_values",
    "make_trajectory",
    "motion_trajectory",
    "plan",
    "tracking_reference",
]
