"""The round-trip helpers the language tests share: they pass a faithful read-back and
fail one that is off by more than the tolerances."""

from __future__ import annotations

import functools
from dataclasses import replace

import numpy as np
import pytest

import trackplan
from tests.programs.parsed import ParsedProgram, ParsedTarget
from tests.programs.roundtrip import (
    PlannedRun,
    assert_joint_timing,
    assert_matches_plan,
    assert_matches_program,
    assert_same_targets,
    expected_targets,
    planned_run,
)
from trackplan.frames import placement_transform
from trackplan.programs import CircularMove, JointMove, LinearMove, Program, build_program
from trackplan.robots.controller import ControllerConvention
from trackplan.robots.model import Robot


@functools.cache
def program_and_robot(motion: str) -> tuple[Program, Robot]:
    """bracket-weld (lines, an arc, blends) with a controller that counts the joints and
    puts its world otherwise than the model."""
    shipped = planned_run("bracket-weld")
    convention = ControllerConvention(
        vendor="abb",
        signs=np.array([1.0, -1.0, 1.0, 1.0, -1.0, 1.0]),
        offsets=np.array([0.1, 0.0, -np.pi / 2, 0.0, 0.0, np.pi]),
        coupling=(2, 1, 1.0),
        world=placement_transform(np.array([0.0, 0.0, 0.4, 0.0, 0.0, np.pi])),
        source="a test convention",
    )
    robot = replace(shipped.case.robot, controller=convention)
    case = replace(shipped.case, robot=robot)
    plan = trackplan.plan(case, shipped.plan.placement)
    assert plan.success, plan.message
    period = None if motion == "cartesian" else 20 * plan.trajectory.sample_time
    return build_program(PlannedRun(case=case, plan=plan), motion=motion, period=period), robot


def read_back(program: Program, *, spline_as: str = "spline") -> ParsedProgram:
    """A faithful ParsedProgram of a program, as a perfect parser would return it."""
    targets = []
    for expected in expected_targets(program):
        kind = spline_as if expected.kind == "spline" else expected.kind
        targets.append(
            ParsedTarget(
                kind=kind,
                pose=None if expected.pose is None else expected.pose.copy(),
                joints=expected.joints.copy() if expected.kind == "joint" else None,
                duration=expected.duration,
            )
        )
    return ParsedProgram(
        name=program.name, base=program.base.copy(), tool=program.tool.copy(), targets=targets
    )


def test_expected_targets_flatten_every_move_in_order() -> None:
    program, _ = program_and_robot("cartesian")
    expected = expected_targets(program)
    assert len(expected) == program.n_points
    kinds = [e.kind for e in expected]
    assert kinds[0] == "joint"
    assert {"linear", "circular_via", "circular_end", "spline"} <= set(kinds)
    moves = list(program.moves())
    circular = next(m for m in moves if isinstance(m, CircularMove))
    k = next(k for k, e in enumerate(expected) if e.kind == "circular_via")
    assert expected[k].pose is circular.via.pose
    assert expected[k + 1].kind == "circular_end" and expected[k + 1].pose is circular.target.pose


@pytest.mark.parametrize("motion", ["cartesian", "joint"])
def test_a_faithful_read_back_matches(motion: str) -> None:
    program, robot = program_and_robot(motion)
    assert_matches_plan(read_back(program), program, robot)


def test_spline_points_may_read_back_as_linear_moves() -> None:
    program, robot = program_and_robot("cartesian")
    assert_matches_plan(read_back(program, spline_as="linear"), program, robot)
    parsed = read_back(program, spline_as="circular_end")
    with pytest.raises(AssertionError, match="read back as circular_end"):
        assert_matches_plan(parsed, program, robot)


def shifted(pose: np.ndarray, metres: float = 0.0, degrees: float = 0.0) -> np.ndarray:
    moved = pose.copy()
    moved[:3, 3] += metres * np.array([0.6, 0.0, 0.8])
    angle = np.radians(degrees)
    turn = np.array(
        [[np.cos(angle), -np.sin(angle), 0], [np.sin(angle), np.cos(angle), 0], [0, 0, 1]]
    )
    moved[:3, :3] = moved[:3, :3] @ turn
    return moved


@pytest.mark.parametrize("kind", ["linear", "circular_via", "spline"])
def test_a_target_off_by_two_hundredths_of_a_millimetre_fails(kind: str) -> None:
    program, robot = program_and_robot("cartesian")
    parsed = read_back(program)
    target = next(t for t in parsed.targets if t.kind == kind)
    assert target.pose is not None
    target.pose = shifted(target.pose, metres=2e-5)
    with pytest.raises(AssertionError, match=r"mm from the plan"):
        assert_matches_plan(parsed, program, robot)
    target.pose = shifted(target.pose, metres=-2e-5 + 5e-6)  # 0.005 mm: within
    assert_matches_plan(parsed, program, robot)


def test_a_target_turned_by_two_thousandths_of_a_degree_fails() -> None:
    program, robot = program_and_robot("cartesian")
    parsed = read_back(program)
    target = next(t for t in parsed.targets if t.kind == "linear")
    assert target.pose is not None
    target.pose = shifted(target.pose, degrees=0.002)
    with pytest.raises(AssertionError, match=r"deg from the plan"):
        assert_matches_plan(parsed, program, robot)


def test_frames_off_by_two_hundredths_of_a_millimetre_fail() -> None:
    program, robot = program_and_robot("cartesian")
    for field in ("base", "tool"):
        parsed = read_back(program)
        setattr(parsed, field, shifted(getattr(parsed, field), metres=2e-5))
        with pytest.raises(AssertionError, match=f"{field} frame"):
            assert_matches_plan(parsed, program, robot)


@pytest.mark.parametrize("motion", ["cartesian", "joint"])
def test_joints_off_by_more_than_a_microradian_fail(motion: str) -> None:
    program, robot = program_and_robot(motion)
    parsed = read_back(program)
    target = parsed.targets[-1] if motion == "joint" else parsed.targets[0]
    assert target.joints is not None
    target.joints = target.joints + np.array([0, 0, 0, 2e-6, 0, 0])
    with pytest.raises(AssertionError, match="rad from the plan"):
        assert_matches_plan(parsed, program, robot)


def test_a_model_joint_written_for_a_controller_joint_fails() -> None:
    program, robot = program_and_robot("joint")
    parsed = read_back(program)
    move = next(m for m in program.moves() if isinstance(m, JointMove))
    parsed.targets[0].joints = move.model_joints.copy()  # the convention forgotten
    with pytest.raises(AssertionError, match="rad from the plan"):
        assert_matches_plan(parsed, program, robot)


def test_a_lost_or_repeated_target_fails() -> None:
    program, robot = program_and_robot("cartesian")
    parsed = read_back(program)
    lost = replace(parsed, targets=parsed.targets[:-1])
    with pytest.raises(AssertionError, match="targets read back"):
        assert_matches_plan(lost, program, robot)
    repeated = replace(parsed, targets=[*parsed.targets, parsed.targets[-1]])
    with pytest.raises(AssertionError, match="targets read back"):
        assert_matches_plan(repeated, program, robot)


def test_a_wrong_duration_fails() -> None:
    program, robot = program_and_robot("joint")
    parsed = read_back(program)
    assert parsed.targets[5].duration is not None
    parsed.targets[5].duration += 1e-3
    with pytest.raises(AssertionError, match="duration"):
        assert_matches_plan(parsed, program, robot)


def test_the_read_back_is_compared_with_the_fk_not_with_the_program() -> None:
    """A pose that the program and its parser agree on but that is not the FK of the
    planned joints fails: the helper checks the plan, not the writer against itself."""
    program, robot = program_and_robot("cartesian")
    moves = list(program.moves())
    k = next(k for k, m in enumerate(moves) if isinstance(m, LinearMove))
    line = moves[k]
    assert isinstance(line, LinearMove)
    wrong = replace(line, target=replace(line.target, pose=shifted(line.target.pose, 2e-5)))
    sections = []
    for section in program.sections:
        sections.append(
            replace(section, moves=tuple(wrong if m is line else m for m in section.moves))
        )
    bad = replace(program, sections=tuple(sections))
    with pytest.raises(AssertionError, match="mm from the plan"):
        assert_matches_plan(read_back(bad), bad, robot)


def test_a_pose_the_program_and_fk_disagree_on_passes_only_against_the_program() -> None:
    """assert_matches_program compares with the program's targets, not with the FK; a
    target 0.02 mm off the program's fails it."""
    program, _ = program_and_robot("cartesian")
    line = next(m for m in program.moves() if isinstance(m, LinearMove))
    wrong = replace(line, target=replace(line.target, pose=shifted(line.target.pose, 2e-5)))
    sections = tuple(
        replace(s, moves=tuple(wrong if m is line else m for m in s.moves))
        for s in program.sections
    )
    bad = replace(program, sections=sections)
    assert_matches_program(read_back(bad), bad)
    with pytest.raises(AssertionError, match="mm from the program"):
        assert_matches_program(read_back(bad), program)


def test_a_spline_read_back_as_another_kind_than_the_languages_fails() -> None:
    program, robot = program_and_robot("cartesian")
    assert_matches_plan(read_back(program, spline_as="linear"), program, robot, spline_as="linear")
    with pytest.raises(AssertionError, match="read back as linear"):
        assert_matches_plan(
            read_back(program, spline_as="linear"), program, robot, spline_as="spline"
        )


def test_joint_timing_fails_on_a_lost_or_wrong_duration_or_speed() -> None:
    program, _ = program_and_robot("joint")
    parsed = read_back(program)
    for target, expected in zip(parsed.targets, expected_targets(program), strict=True):
        target.speed = expected.speed
    assert_joint_timing(parsed, program, speed=1e-6, duration=1e-9)
    parsed.targets[0].speed = (parsed.targets[0].speed or 0.0) + 1e-3  # the untimed start
    with pytest.raises(AssertionError, match="speed"):
        assert_joint_timing(parsed, program, speed=1e-6, duration=1e-9)
    assert_joint_timing(parsed, program, speed=None, duration=1e-9)
    parsed.targets[3].duration = None
    with pytest.raises(AssertionError, match="no duration"):
        assert_joint_timing(parsed, program, speed=None, duration=1e-9)


def test_a_split_program_that_differs_from_the_whole_fails() -> None:
    program, _ = program_and_robot("cartesian")
    whole = read_back(program)
    assert_same_targets(read_back(program), whole)
    split = read_back(program)
    split.targets[4].zone = 1e-5
    with pytest.raises(AssertionError, match="zone"):
        assert_same_targets(split, whole)
    assert_same_targets(split, whole, fields=("kind", "config", "speed", "duration"))
    split = read_back(program)
    pose = split.targets[4].pose
    assert pose is not None
    pose[0, 3] += 1e-9
    with pytest.raises(AssertionError, match="pose differs"):
        assert_same_targets(split, whole)
