"""Compare a program read back by a language's test parser with the plan it was built from.

Every language's round-trip test calls :func:`assert_matches_plan` on the
:class:`~tests.programs.parsed.ParsedProgram` its parser returns: the frames, every
Cartesian target against the program's and against the forward kinematics of the planned
joints there, every joint target against the planned joints, and the number and kinds of
targets (:func:`assert_matches_program` leaves the forward kinematics out, for a program
whose targets are not the FK of their joints). What one language adds (configuration
fields, speeds, zones, times) it checks on top, over :func:`target_pairs` and with
:func:`assert_joint_timing`; the tolerances are this module's.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

import trackplan
from tests.conftest import CASES
from tests.programs.parsed import ParsedProgram, ParsedTarget
from trackplan.case import Case
from trackplan.planning.result import PlanResult
from trackplan.programs.model import (
    CircularMove,
    JointMove,
    LinearMove,
    Program,
    SplineMove,
    Target,
)
from trackplan.robots.kinematics import forward_kinematics
from trackplan.robots.model import Robot

POSITION_TOLERANCE = 1e-5
"""Largest position difference of a frame or target, m (0.01 mm)."""

ANGLE_TOLERANCE = np.radians(1e-3)
"""Largest rotation between two frames or targets, rad (0.001°)."""

JOINT_TOLERANCE = 1e-6
"""Largest joint difference, rad (1e-4° is 1.7e-6 rad: the languages in degrees print
to 1e-4° and better)."""

DURATION_TOLERANCE = 1e-6
"""Largest difference of a timed move's duration, s."""


SHIPPED_PLACEMENTS: dict[str, tuple[float, ...]] = {
    "paper-corner-cell": (0.0902, 0.209, 0.202, 0.3263, 0.3016, -0.2522),
    "seam-weld-fixed": (0.5241, 0.2063, 0.0498, -0.2943, 0.2999, 2.4350),
    "seam-weld-free": (0.342, -0.238, 0.4, -0.132, -0.009, 3.019),
    "ur5-bead": (0.5961, -0.2199, -0.2935, -0.0136, -0.4994, -0.1238),
}
"""Placements of the shipped cases without a ``placement.example`` (from optimize runs:
tests/cell/test_robot_bodies.py, tests/planning/test_plan_golden.py)."""


@dataclass(frozen=True, eq=False)
class PlannedRun:
    """A run made in code: what :func:`trackplan.programs.build_program` reads of a
    replayed run folder."""

    case: Case
    plan: PlanResult
    summary: dict[str, Any] = field(default_factory=dict)
    folder: Path | None = None


@functools.cache
def planned_run(case_name: str, X: tuple[float, ...] | None = None) -> PlannedRun:
    """The shipped case ``cases/<case_name>.yaml`` planned at ``X`` (default its example
    placement, or :data:`SHIPPED_PLACEMENTS`), kept for the session."""
    case = trackplan.load_case(CASES / f"{case_name}.yaml")
    if X is None:
        example = case.bounds.example
        X = tuple(example) if example is not None else SHIPPED_PLACEMENTS[case_name]
    return PlannedRun(case=case, plan=trackplan.plan(case, np.asarray(X, dtype=float)))


@dataclass(frozen=True)
class ExpectedTarget:
    """One target of a program, in the order a parser returns them.

    Attributes
    ----------
    kind
        ``joint``, ``linear``, ``circular_via``, ``circular_end`` or ``spline``.
    joints
        The planned joints there in the controller's convention, shape (n,), rad.
    model_joints
        The same in the model's convention, shape (n,), rad.
    pose
        The TCP in the part frame, shape (4, 4), m; None for a joint target.
    duration
        A timed joint move's duration, s, else None.
    speed
        The move's speed: m/s for a Cartesian move, share of the joint rates for a joint
        move.
    external
        The external axes there (the program's, SI units), shape (e,).
    """

    kind: str
    joints: np.ndarray
    model_joints: np.ndarray
    pose: np.ndarray | None = None
    duration: float | None = None
    speed: float | None = None
    external: np.ndarray = field(default_factory=lambda: np.zeros(0))


def expected_targets(program: Program) -> list[ExpectedTarget]:
    """The program's targets in execution order (a circular move gives its via, then its
    end; a spline each of its points)."""
    out: list[ExpectedTarget] = []

    def cartesian(kind: str, target: Target, speed: float) -> ExpectedTarget:
        return ExpectedTarget(
            kind=kind,
            joints=target.joints,
            model_joints=target.model_joints,
            pose=target.pose,
            speed=speed,
            external=target.external,
        )

    for move in program.moves():
        if isinstance(move, JointMove):
            out.append(
                ExpectedTarget(
                    kind="joint",
                    joints=move.joints,
                    model_joints=move.model_joints,
                    duration=move.duration,
                    speed=move.speed,
                    external=move.external,
                )
            )
        elif isinstance(move, LinearMove):
            out.append(cartesian("linear", move.target, move.speed))
        elif isinstance(move, CircularMove):
            out.append(cartesian("circular_via", move.via, move.speed))
            out.append(cartesian("circular_end", move.target, move.speed))
        elif isinstance(move, SplineMove):
            out.extend(cartesian("spline", target, move.speed) for target in move.targets)
        else:  # pragma: no cover - a move kind this helper does not know
            raise TypeError(f"unknown move {move!r}")
    return out


def rotation_angle(a: np.ndarray, b: np.ndarray) -> float:
    """The angle of the rotation between two rotations, rad.

    ``a`` and ``b`` are rotation matrices (3, 3) or frames (4, 4) (their rotation part is
    used). The angle is ``2 asin(‖Ra − Rb‖_F / 2√2)``, exact near 0 (unlike an arccos of
    the trace).
    """
    chord = float(np.linalg.norm(a[:3, :3] - b[:3, :3])) / (2.0 * np.sqrt(2.0))
    return 2.0 * float(np.arcsin(min(chord, 1.0)))


def frame_difference(a: np.ndarray, b: np.ndarray) -> tuple[float, float]:
    """Distance (m) and rotation angle (rad, :func:`rotation_angle`) between two frames
    (4, 4)."""
    return float(np.linalg.norm(a[:3, 3] - b[:3, 3])), rotation_angle(a, b)


def _assert_frame(actual: np.ndarray, expected: np.ndarray, what: str, whose: str) -> None:
    distance, angle = frame_difference(actual, expected)
    assert distance <= POSITION_TOLERANCE, (
        f"{what}: {distance * 1e3:.6f} mm from the {whose} (at most {POSITION_TOLERANCE * 1e3} mm)"
    )
    assert angle <= ANGLE_TOLERANCE, (
        f"{what}: {np.degrees(angle):.6f} deg from the {whose} (at most 0.001 deg)"
    )


def _kinds_agree(parsed: ParsedTarget, expected: ExpectedTarget, spline_as: str | None) -> bool:
    """A spline point reads back as ``spline_as``; as a spline or a linear move when it is
    None (a language without a spline writes lines)."""
    if expected.kind == "spline":
        return parsed.kind == spline_as if spline_as else parsed.kind in ("spline", "linear")
    return parsed.kind == expected.kind


def target_pairs(
    parsed: ParsedProgram, program: Program
) -> list[tuple[ParsedTarget, ExpectedTarget]]:
    """Every target read back with the program's target it stands for, in order; asserts
    that they are as many."""
    expected = expected_targets(program)
    assert len(parsed.targets) == len(expected), (
        f"{len(parsed.targets)} targets read back, the program has {len(expected)}"
    )
    return list(zip(parsed.targets, expected, strict=True))


def _assert_targets(
    parsed: ParsedProgram, program: Program, robot: Robot | None, spline_as: str | None
) -> None:
    _assert_frame(parsed.base, program.base, "base frame", "program")
    _assert_frame(parsed.tool, program.tool, "tool frame", "program")
    pairs = target_pairs(parsed, program)
    world_poses = None
    if robot is not None and pairs:
        world_poses = robot.convention.world_from_base(
            forward_kinematics(robot, np.array([want.model_joints for _, want in pairs]))
        )
    for k, (got, want) in enumerate(pairs):
        where = f"target {k} ({want.kind}, {got.part or 'main'})"
        assert _kinds_agree(got, want, spline_as), f"{where}: read back as {got.kind}"
        if want.pose is not None:
            assert got.pose is not None, f"{where}: no pose read back"
            if world_poses is not None:
                _assert_frame(parsed.base @ got.pose, world_poses[k], where, "plan")
            _assert_frame(got.pose, want.pose, where, "program")
        if want.kind == "joint" or got.joints is not None:
            assert got.joints is not None, f"{where}: no joints read back"
            error = float(np.max(np.abs(np.asarray(got.joints) - want.joints)))
            assert error <= JOINT_TOLERANCE, f"{where}: joints {error:.3g} rad from the plan"
        if want.duration is not None and got.duration is not None:
            assert abs(got.duration - want.duration) <= DURATION_TOLERANCE, (
                f"{where}: duration {got.duration} s, the plan's {want.duration} s"
            )


def assert_matches_plan(
    parsed: ParsedProgram, program: Program, robot: Robot, *, spline_as: str | None = None
) -> None:
    """Assert that a program read back is the plan's, target by target.

    - The parsed base and tool equal the program's (0.01 mm, 0.001°).
    - The parsed targets are as many as the program's, of the same kinds, in the same
      order; a spline's points read back as ``spline_as`` (``spline`` or ``linear``; either
      when None).
    - Every Cartesian target equals the program's (TCP in the part frame) and, put through
      the parsed base, is the controller-world forward kinematics of the planned joints
      there (model joints → ``forward_kinematics`` → ``convention.world_from_base``), both
      within 0.01 mm and 0.001°.
    - Every joint target (and a Cartesian target that states joints) equals the program's
      controller joints within 1e-6 rad; a timed move's duration, where read back, equals
      the program's within 1e-6 s.

    Parameters
    ----------
    parsed
        The program as a language's parser read it.
    program
        The program the writer printed.
    robot
        The run's robot.
    spline_as
        The kind the language writes a spline point as, or None.
    """
    _assert_targets(parsed, program, robot, spline_as)


def assert_matches_program(
    parsed: ParsedProgram, program: Program, *, spline_as: str | None = None
) -> None:
    """:func:`assert_matches_plan` without the forward kinematics, for a program whose
    targets are not the FK of their joints."""
    _assert_targets(parsed, program, None, spline_as)


def assert_joint_timing(
    parsed: ParsedProgram, program: Program, *, speed: float | None, duration: float
) -> None:
    """Assert the timing of every joint move read back: a timed move's duration within
    ``duration`` s of the program's (it must be read back), an untimed one's speed (share
    of the joint rates) within ``speed`` (not checked when None)."""
    for k, (got, want) in enumerate(target_pairs(parsed, program)):
        if want.kind != "joint":
            continue
        if want.duration is not None:
            assert got.duration is not None, f"target {k}: no duration read back"
            assert abs(got.duration - want.duration) <= duration, (
                f"target {k}: duration {got.duration} s, the program's {want.duration} s"
            )
        elif speed is not None:
            assert got.speed is not None and want.speed is not None
            assert abs(got.speed - want.speed) <= speed, (
                f"target {k}: speed {got.speed}, the program's {want.speed}"
            )


SAME_FIELDS = ("kind", "config", "speed", "zone", "duration")
"""The fields of a target that a split program keeps as the whole one states them."""


def assert_same_targets(
    split: ParsedProgram, whole: ParsedProgram, *, fields: tuple[str, ...] = SAME_FIELDS
) -> None:
    """Assert that a program split into parts reads back as the whole one: as many
    targets, each with the same ``fields`` (of :data:`SAME_FIELDS`), the same pose and the
    same joints (the same numbers: both are printed from one program)."""
    assert len(split.targets) == len(whole.targets), (
        f"{len(split.targets)} targets in the parts, {len(whole.targets)} in the whole"
    )
    for k, (a, b) in enumerate(zip(split.targets, whole.targets, strict=True)):
        where = f"target {k} ({a.part})"
        for name in fields:
            assert getattr(a, name) == getattr(b, name), (
                f"{where}: {name} {getattr(a, name)!r}, the whole's {getattr(b, name)!r}"
            )
        for name in ("pose", "joints"):
            x, y = getattr(a, name), getattr(b, name)
            assert (x is None) == (y is None), f"{where}: {name} read back in one only"
            assert x is None or np.array_equal(x, y), f"{where}: {name} differs"


__all__ = [
    "ANGLE_TOLERANCE",
    "JOINT_TOLERANCE",
    "POSITION_TOLERANCE",
    "SAME_FIELDS",
    "SHIPPED_PLACEMENTS",
    "ExpectedTarget",
    "PlannedRun",
    "assert_joint_timing",
    "assert_matches_plan",
    "assert_matches_program",
    "assert_same_targets",
    "expected_targets",
    "frame_difference",
    "planned_run",
    "rotation_angle",
    "target_pairs",
]
