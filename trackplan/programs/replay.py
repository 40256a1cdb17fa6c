"""A run replayed: its case re-planned where and as the run was, and proven equal to it.

A run folder holds the trajectory (``trajectory.csv``) and its summary (``result.json``)
but not the plan's geometry (the placed path, the tool poses, the seams' spans) that a
program needs. :func:`replay_run` re-plans the run's case with everything the summary
records (placement, time law, sequence, per-seam IK branch and spin) and checks that the
re-plan reproduces ``trajectory.csv`` before anything is built on it;
:func:`replay_plan` wraps a plan held in memory the same way (notebooks, tests).
"""

from __future__ import annotations

import json
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from trackplan.case import PLACEMENT_KEYS, Case
from trackplan.errors import CaseError
from trackplan.io.export import TrajectoryTable, read_trajectory_table
from trackplan.io.results import plan_summary, recorded_positioner
from trackplan.io.run_folder import verified_trajectory
from trackplan.planning.result import PlanResult
from trackplan.planning.seams import SeamSpin
from trackplan.planning.sequence import Sequence, Visit
from trackplan.run_files import RESULT_FILE, TRAJECTORY_FILE
from trackplan.tool import SpinProfile

JOINT_TOLERANCE = 1e-6
"""Largest joint difference, rad, between a re-plan and the run's ``trajectory.csv``.

The CSV holds each float as its shortest round-trip text, so it reads back bit for bit;
a re-plan with the same code and library versions reproduces the run to rounding (the
summation order of a few reductions may differ between processes), far below 1e-6 rad
(a 0.2 arcsecond). A larger difference means another case, another robot or another
version of the planner: a program built on it would not be the verified run."""

NO_CASE = "the run does not say which case it was planned from: give --case CASE"


@dataclass(frozen=True, eq=False, kw_only=True)
class ReplayedRun:
    """A verified run with its re-planned geometry.

    Attributes
    ----------
    folder
        The run folder, or None for a plan held in memory (:func:`replay_plan`).
    summary
        The run's ``result.json`` content (for a plan in memory: the same keys, composed).
    case
        The case the run was planned from.
    plan
        The case re-planned at the run's placement; its trajectory equals ``table``'s
        joints within :data:`JOINT_TOLERANCE`.
    table
        ``trajectory.csv`` as read: times (N,) s, joints (N, n) rad, with the joint names.
    """

    folder: Path | None
    summary: dict
    case: Case
    plan: PlanResult
    table: TrajectoryTable


def replay_run(run: Path | str, case: Case | Path | str | None = None) -> ReplayedRun:
    """Re-plan a run folder's case where the run was planned, and check it reproduces the run.

    The re-plan uses ``result.json``'s placement (and ``positioner_pose``), time law
    (``timing``), sequence (order and
    directions), and each seam's IK branch and spin (``seams[].branch``, ``seams[].spin``:
    a spin the run chose, such as a free spin optimised for its placement, is given back
    as written). It must reproduce ``trajectory.csv``: the same number of samples, and
    every joint of every sample within :data:`JOINT_TOLERANCE` (1e-6 rad; the CSV holds
    shortest round-trip floats, and a re-plan with the same versions reproduces it to
    rounding).

    Parameters
    ----------
    run
        The run folder (or its ``trajectory.csv``), read through
        :func:`~trackplan.io.run_folder.verified_trajectory` (its hash is checked).
    case
        The case: a :class:`~trackplan.case.Case`, or a case file to load; default the
        case file ``result.json`` records (``case_file``).

    Returns
    -------
    ReplayedRun

    Raises
    ------
    CaseError
        When the folder is not a consistent run, ``result.json`` lacks a key the re-plan
        needs, no case is given and the run records none (key ``--case``), the case file
        cannot be read, or the re-plan does not reproduce the run (key ``--case``: which
        joint differs, by how much and when).
    """
    folder = _run_folder(Path(run))
    csv_file = verified_trajectory(folder)
    summary = _read_summary(folder / RESULT_FILE)
    where = str(folder / RESULT_FILE)
    loaded = recorded_positioner(_the_case(case, summary), summary, where)
    table = read_trajectory_table(csv_file)
    plan = _replan(loaded, summary, where)
    _check_reproduces(plan, table)
    return ReplayedRun(folder=folder, summary=summary, case=loaded, plan=plan, table=table)


def replay_plan(plan: PlanResult, case: Case) -> ReplayedRun:
    """A plan held in memory as a :class:`ReplayedRun` (no folder; nothing re-planned).

    Parameters
    ----------
    plan
        A plan of ``case`` (:func:`trackplan.planning.plan.plan`).
    case
        Its case.

    Returns
    -------
    ReplayedRun
        ``summary`` is the ``result.json`` content the run would have; ``table`` the
        plan's trajectory with the robot's joint names.

    Raises
    ------
    CaseError
        When the plan has no trajectory (an unreachable placement).
    """
    if plan.trajectory.n_samples == 0:
        raise CaseError(f"the plan has no trajectory: {plan.message}", key="trajectory")
    table = TrajectoryTable.from_trajectory(plan.trajectory, case.machine.joint_names)
    return ReplayedRun(
        folder=None, summary=plan_summary(plan, case), case=case, plan=plan, table=table
    )


def _run_folder(run: Path) -> Path:
    """The run folder of ``run`` (a folder, or the ``trajectory.csv`` in one)."""
    if run.is_file() and run.name == TRAJECTORY_FILE and (run.parent / RESULT_FILE).is_file():
        return run.parent
    if not run.is_dir():
        raise CaseError(
            "a program needs a run folder (trajectory.csv with its result.json), not a "
            "bare CSV file",
            file=str(run),
        )
    return run


def _read_summary(file: Path) -> dict:
    """``result.json`` as a dict (:func:`verified_trajectory` has read it once already)."""
    try:
        summary = json.loads(file.read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError, ValueError) as error:
        raise CaseError(
            f"unreadable {RESULT_FILE}: {error}".splitlines()[0], file=str(file)
        ) from None
    if not isinstance(summary, dict):
        raise CaseError(f"{RESULT_FILE} is not a mapping", file=str(file))
    return summary


def _the_case(case: Case | Path | str | None, summary: dict) -> Case:
    """The given case, the given case file loaded, or the case file the run records."""
    if isinstance(case, Case):
        return case
    from trackplan.io.case_file import load_case

    file = case if case is not None else summary.get("case_file")
    if not isinstance(file, str | Path) or not str(file):
        raise CaseError(NO_CASE, key="--case")
    if case is None and not Path(file).exists():
        raise CaseError(
            f"the run was planned from {str(file)!r}, which is no longer there: give --case CASE",
            key="--case",
        )
    robot = summary.get("robot")
    assumed = isinstance(robot, dict) and bool(robot.get("assumptions"))
    return load_case(file, assume_limits=assumed)


def _replan(case: Case, summary: dict, where: str) -> PlanResult:
    """The case planned with everything ``result.json`` records of the run."""
    from trackplan.planning.plan import plan

    try:
        X = np.array([float(summary["placement"][key]) for key in PLACEMENT_KEYS])
        timing = str(summary["timing"])
        recorded_seams = {seam["name"]: seam for seam in summary["seams"]}
        visits = [(str(v["seam"]), bool(v["reversed"])) for v in summary["sequence"]]
    except (KeyError, TypeError, ValueError) as error:
        raise CaseError(
            f"{RESULT_FILE} lacks the run's placement, timing, seams or sequence ({error}): "
            "plan the case again",
            file=where,
        ) from None
    names = case.seam_names
    unknown = [name for name in (*recorded_seams, *(n for n, _ in visits)) if name not in names]
    if unknown or len(recorded_seams) != len(names):
        raise CaseError(
            f"the case's seams ({', '.join(names)}) are not the run's "
            f"({', '.join(recorded_seams)}): give the case the run was planned from",
            key="--case",
        )
    reversed_ = {name: rev for name, rev in visits}
    branches = tuple(int(recorded_seams[name]["branch"]) for name in names)
    spins = tuple(
        _seam_spin(recorded_seams[name].get("spin"), reversed_.get(name, False)) for name in names
    )
    sequence = Sequence(
        visits=tuple(Visit(names.index(name), rev) for name, rev in visits),
        cost=float("nan"),
        exact=False,
    )
    return plan(case, X, timing=timing, sequence=sequence, branches=branches, spins=spins)


def _seam_spin(recorded: Any, reversed_: bool) -> SeamSpin:
    """The spin ``result.json`` records for a seam, as :func:`plan` takes it (over the seam
    as written: a reversed seam's profile, written in welding order, is turned back)."""
    if not isinstance(recorded, dict):
        return None
    if "value" in recorded:
        return SpinProfile(np.array([float(recorded["value"])]), 0.0)
    coefficients = np.array(recorded["coefficients"], dtype=float)
    length = float(recorded["knots"][-1])
    if reversed_:
        coefficients = coefficients[::-1].copy()
    return SpinProfile(coefficients, length)


def _check_reproduces(plan: PlanResult, table: TrajectoryTable) -> None:
    """Refuse a re-plan that is not the run (sample count, then the worst joint)."""
    hint = "give the case the run was planned from, or plan again"
    q = plan.trajectory.q
    if q.shape != table.q.shape:
        raise CaseError(
            f"the case does not reproduce the run ({q.shape[0]} samples of {q.shape[1]} joints "
            f"against {table.q.shape[0]} of {table.q.shape[1]} in {TRAJECTORY_FILE}): {hint}",
            key="--case",
        )
    difference = np.abs(q - table.q)
    k, j = np.unravel_index(int(np.argmax(difference)), difference.shape)
    if difference[k, j] > JOINT_TOLERANCE:
        raise CaseError(
            f"the case does not reproduce the run (joint {j + 1} differs by "
            f"{difference[k, j]:.1e} rad at t = {table.t[k]:.3f} s): {hint}",
            key="--case",
        )


__all__ = ["JOINT_TOLERANCE", "ReplayedRun", "replay_plan", "replay_run"]
