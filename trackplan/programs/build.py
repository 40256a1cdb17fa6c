"""From a verified run to a :class:`~trackplan.programs.model.Program` (``docs/export.md``).

:func:`build_program` reads a run (its case and its plan, replayed from the run folder)
and makes the program every writer prints: in the Cartesian form the seams as path moves
(:mod:`trackplan.programs.cartesian`), in the joint form the planned joint trajectory
itself (:mod:`trackplan.programs.joint_form`). The frames are those of the run: the base is
the placement (the part frame) in the controller's world (with a positioner: the part
frame on the positioner's flange), the tool the robot's TCP in the flange; the external
axes (track, positioner) ride along on every joint move and target.
"""

from __future__ import annotations

import pathlib
from collections.abc import Mapping
from typing import Any, Protocol

import numpy as np

from trackplan.case import Case
from trackplan.errors import CaseError
from trackplan.frames import placement_transform
from trackplan.planning.result import PlanResult
from trackplan.programs.cartesian import cartesian_sections
from trackplan.programs.external import external_axes
from trackplan.programs.header import header_lines
from trackplan.programs.joint_form import joint_sections, sample_step
from trackplan.programs.model import MOTION_FORMS, Budget, Program, Section


class Run(Protocol):
    """What :func:`build_program` reads of a run (a replayed run folder, or a plan made
    in code)."""

    @property
    def folder(self) -> pathlib.Path | None:
        """The run folder, or None for a plan made in code."""
        ...

    @property
    def summary(self) -> Mapping[str, Any]:
        """The run's ``result.json`` (empty for a plan made in code)."""
        ...

    @property
    def case(self) -> Case:
        """The run's case."""
        ...

    @property
    def plan(self) -> PlanResult:
        """The run's plan at its placement."""
        ...


def build_program(
    replayed: Run,
    *,
    motion: str = "cartesian",
    name: str | None = None,
    period: float | None = None,
    force: bool = False,
) -> Program:
    """The program of a run, in no language.

    Parameters
    ----------
    replayed
        The run: its case and plan (:class:`Run`).
    motion
        ``cartesian``: the seams as the controller's path moves (linear, circular, spline)
        within the task tolerance, the moves between seams as joint moves; ``joint``: the
        planned joint trajectory, one timed joint move per ``period``.
    name
        The program's name; default the case name (each writer makes it an identifier).
    period
        Joint form: time per move, s, a positive multiple of the sample time; default the
        sample time (every sample).
    force
        Export a run that is not feasible (its verdict goes into the header).

    Returns
    -------
    Program
        Its first section is the joint move to the planned start.

    Raises
    ------
    CaseError
        A run that is not feasible without ``force`` (key ``--force``), a run without a
        trajectory, an unknown form or the Cartesian form of a weaving seam
        (``--motion``) or a period that is no multiple of the
        sample time (``--period``).
    """
    case, plan = replayed.case, replayed.plan
    if motion not in MOTION_FORMS:
        raise CaseError(f"must be one of {', '.join(MOTION_FORMS)}, got {motion!r}", key="--motion")
    if motion == "cartesian" and any(seam.task.weave is not None for seam in case.seams):
        raise CaseError(
            "a weaving seam is not written as path moves (they follow the centre line; "
            "the controller's weave function is not written): export --motion joint, the "
            "planned joints with the weave",
            key="--motion",
        )
    if not plan.success and not force:
        raise CaseError(
            f"the run is not feasible ({plan.message}): exporting it needs --force",
            key="--force",
        )
    if plan.trajectory.n_samples < 2 or not plan.spans:
        raise CaseError(
            f"the run has no trajectory ({plan.message}): there is nothing to export",
            key="run",
        )
    robot = case.robot
    convention = robot.convention
    external = external_axes(case)
    coordinated = any(axis.kind == "positioner" for axis in external)
    # with a positioner the placement puts the part on its flange (the carrier frame):
    # the base is the part there, and the controller moves it with the positioner
    part = placement_transform(plan.placement)
    base = part if coordinated else convention.world_from_base(part)
    tool = np.array(robot.T_flange_tool, dtype=float)
    sample_time = float(plan.trajectory.sample_time)
    sections: tuple[Section, ...]
    budget: Budget | None = None
    written_period: float | None = None
    if motion == "cartesian":
        sections, budget = cartesian_sections(case, plan)
    else:
        step = sample_step(period, sample_time)
        written_period = step * sample_time
        sections = joint_sections(case, plan, step)
    header = header_lines(
        case,
        plan,
        base=base,
        tool=tool,
        form=motion,
        budget=budget,
        period=written_period,
        external=external,
    )
    return Program(
        name=name or case.name,
        motion="cartesian" if motion == "cartesian" else "joint",
        robot=robot.name,
        vendor=convention.vendor,
        n_dof=robot.n_dof,
        base=base,
        tool=tool,
        sections=sections,
        header=header,
        sample_time=sample_time,
        period=written_period,
        budget=budget,
        feasible=bool(plan.success),
        v_max=np.array(robot.v_max, dtype=float),
        external_axes=external,
    )


__all__ = ["Run", "build_program"]
