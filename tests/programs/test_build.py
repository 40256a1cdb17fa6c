"""build_program, Cartesian form: targets, moves, speeds, zones, frames, verdict."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from tests.conftest import CASES
from tests.programs.roundtrip import (
    ANGLE_TOLERANCE,
    POSITION_TOLERANCE,
    PlannedRun,
    frame_difference,
    planned_run,
)
from trackplan.errors import CaseError
from trackplan.frames import placement_transform
from trackplan.programs import (
    CircularMove,
    JointMove,
    LinearMove,
    Program,
    SplineMove,
    Target,
    build_program,
)
from trackplan.robots.controller import ControllerConvention
from trackplan.robots.kinematics import forward_kinematics

SINGLE = ("paper-corner", "paper-circle", "bracket-weld")
"""Shipped single-seam cases whose example placement plans feasibly: a blended corner,
a full circle, and lines, arcs and a fitted curve."""


def cartesian_targets(program: Program) -> list[Target]:
    """Every Cartesian target in order (a circular move's via, then its end)."""
    out: list[Target] = []
    for move in program.moves():
        if isinstance(move, LinearMove):
            out.append(move.target)
        elif isinstance(move, CircularMove):
            out += [move.via, move.target]
        elif isinstance(move, SplineMove):
            out += list(move.targets)
    return out


def seam_moves(program: Program) -> list[LinearMove | CircularMove | SplineMove]:
    return [m for s in program.sections if s.kind == "seam" for m in s.moves]  # type: ignore[misc]


def end_of(move: LinearMove | CircularMove | SplineMove) -> Target:
    return move.targets[-1] if isinstance(move, SplineMove) else move.target


@pytest.mark.parametrize("name", SINGLE)
def test_every_target_is_the_fk_of_its_planned_joints(name: str) -> None:
    run = planned_run(name)
    assert run.plan.success, run.plan.message
    program = build_program(run)
    robot = run.case.robot
    T_X = placement_transform(run.plan.placement)
    targets = cartesian_targets(program)
    assert targets
    fk = forward_kinematics(robot, np.array([t.model_joints for t in targets]))
    for target, pose in zip(targets, fk, strict=True):
        distance, angle = frame_difference(T_X @ target.pose, pose)
        assert distance <= POSITION_TOLERANCE and angle <= ANGLE_TOLERANCE
        np.testing.assert_allclose(
            target.joints, robot.convention.to_controller(target.model_joints), atol=1e-12
        )


@pytest.mark.parametrize("name", SINGLE)
def test_the_seam_starts_and_ends_on_the_planned_joints(name: str) -> None:
    run = planned_run(name)
    program = build_program(run)
    q = run.plan.trajectory.q
    start = program.sections[0]
    assert start.kind == "start" and len(start.moves) == 1
    first = start.moves[0]
    assert isinstance(first, JointMove) and first.zone == 0.0
    np.testing.assert_allclose(first.model_joints, q[0], atol=1e-12)
    last = end_of(seam_moves(program)[-1])
    np.testing.assert_allclose(last.model_joints, q[-1], atol=1e-6)  # rad
    # the seam's last target is the planned path's end
    path = run.plan.seams[0].plan.joint_path.geometry.planned
    _, end, _ = path.points(np.array([path.length]))
    np.testing.assert_allclose(last.pose[:3, 3], end[0], atol=1e-12)


def test_a_blended_corner_is_line_spline_line_within_half_the_budget() -> None:
    run = planned_run("paper-corner")
    program = build_program(run)
    moves = seam_moves(program)
    assert [type(m) for m in moves] == [LinearMove, SplineMove, LinearMove]
    budget = program.budget
    assert budget is not None
    room = budget.tolerance - budget.tracking_error
    assert 0.0 < budget.chord_error <= 0.5 * room
    # the chord error measured independently: dense points of the planned blend against
    # the polyline of the spline's points (from the line's end)
    path = run.plan.seams[0].plan.joint_path.geometry.planned
    blend = next(p for p in path.pieces if p.kind == "blend")
    spline = moves[1]
    assert isinstance(spline, SplineMove)
    corners = np.array([end_of(moves[0]).pose[:3, 3]] + [t.pose[:3, 3] for t in spline.targets])
    _, dense, _ = path.points(np.linspace(blend.s_start, blend.s_end, 4001))
    a, b = corners[:-1], corners[1:]
    ab = b - a
    along = np.clip(np.einsum("mk,pk->mp", dense, ab) - np.sum(a * ab, axis=1), 0, None) / np.sum(
        ab * ab, axis=1
    )
    along = np.minimum(along, 1.0)
    nearest = a[None] + along[..., None] * ab[None]
    distance = np.linalg.norm(dense[:, None] - nearest, axis=2).min(axis=1)
    assert float(distance.max()) <= budget.chord_error * (1 + 1e-3) + 1e-12
    assert float(distance.max()) >= 0.5 * budget.chord_error  # the measure is not vacuous


def test_zones_keep_chord_plus_zone_within_the_budget_and_stop_at_the_end() -> None:
    for name in SINGLE:
        program = build_program(planned_run(name))
        budget = program.budget
        assert budget is not None and budget.slack >= 0.0
        room = budget.tolerance - budget.tracking_error
        moves = seam_moves(program)
        assert moves[-1].zone == 0.0
        for move in moves:
            assert 0.0 <= move.zone <= room - budget.chord_error + 1e-15
        assert max(m.zone for m in moves) == budget.zone
        assert all(m.zone == 0.0 for m in program.moves() if isinstance(m, JointMove))


def test_a_full_circle_is_three_arcs_through_their_mid_points() -> None:
    run = planned_run("paper-circle")
    program = build_program(run)
    moves = seam_moves(program)
    assert len(moves) == 3 and all(isinstance(m, CircularMove) for m in moves)
    arc = run.plan.seams[0].plan.joint_path.geometry.planned.pieces[0].curve
    centre, radius = arc.center, arc.radius  # type: ignore[union-attr]
    start = program.sections[0].moves[0]
    assert isinstance(start, JointMove)
    points = [run.plan.trajectory.tool_position[0]]
    T_X = placement_transform(run.plan.placement)
    points = [(np.linalg.inv(T_X) @ np.append(points[0], 1.0))[:3]]
    for move in moves:
        assert isinstance(move, CircularMove)
        points += [move.via.pose[:3, 3], move.target.pose[:3, 3]]
    points_array = np.array(points)
    np.testing.assert_allclose(np.linalg.norm(points_array - centre, axis=1), radius, atol=1e-9)
    # each via halves its arc: 60° between consecutive points
    u = (points_array - centre) / radius
    angles = np.degrees(np.arccos(np.clip(np.sum(u[1:] * u[:-1], axis=1), -1, 1)))
    np.testing.assert_allclose(angles, 60.0, atol=1e-6)


def test_speeds_follow_the_plan_and_slow_down_at_the_corner() -> None:
    import trackplan

    shipped = planned_run("paper-corner")
    task = replace(shipped.case.task, corner_speed=0.05)  # m/s, a third of the rated speed
    case = replace(shipped.case, task=task)
    plan = trackplan.plan(case, shipped.plan.placement)
    assert plan.success, plan.message
    program = build_program(PlannedRun(case=case, plan=plan))
    first, blend, last = seam_moves(program)
    speed = plan.trajectory.speed
    assert max(m.speed for m in (first, blend, last)) == pytest.approx(speed.max(), rel=1e-12)
    assert first.speed == pytest.approx(task.rated_speed, rel=1e-2)
    assert last.speed == pytest.approx(task.rated_speed, rel=1e-2)
    # the blend's move runs at the plan's peak over the blend: at most the corner speed
    path = plan.seams[0].plan.joint_path.geometry.planned
    piece = next(p for p in path.pieces if p.kind == "blend")
    s = plan.trajectory.s
    on_blend = (s >= piece.s_start) & (s <= piece.s_end)
    assert blend.speed == pytest.approx(speed[on_blend].max(), rel=1e-2)
    assert blend.speed <= task.corner_speed * (1 + 1e-6)
    for move in program.moves():
        if isinstance(move, JointMove):
            assert 0.0 < move.speed <= 1.0


def test_the_frames_are_the_placement_in_the_controller_world_and_the_tcp() -> None:
    run = planned_run("paper-corner")
    robot = run.case.robot
    world = placement_transform(np.array([0.1, -0.2, 0.525, 0.0, 0.0, np.pi]))
    convention = ControllerConvention(
        vendor="fanuc",
        signs=np.array([1.0, 1.0, -1.0, -1.0, -1.0, -1.0]),
        offsets=np.array([0.0, -np.pi / 2, 0.0, 0.0, 0.0, 0.0]),
        coupling=(2, 1, 1.0),
        world=world,
        source="a test convention",
    )
    tool = placement_transform(np.array([0.0, 0.0, 0.01, 0.0, 0.0, 0.2]))
    moved = replace(robot, controller=convention, T_flange_tool=tool)
    case = replace(run.case, robot=moved)
    import trackplan

    plan = trackplan.plan(case, run.plan.placement)
    program = build_program(PlannedRun(case=case, plan=plan))
    T_X = placement_transform(plan.placement)
    np.testing.assert_allclose(program.base, np.linalg.inv(world) @ T_X, atol=1e-12)
    np.testing.assert_allclose(program.tool, tool, atol=0)
    assert program.vendor == "fanuc"
    for target in cartesian_targets(program):
        np.testing.assert_allclose(
            target.joints, convention.to_controller(target.model_joints), atol=1e-12
        )
        world_tcp = convention.world_from_base(forward_kinematics(moved, target.model_joints))
        distance, angle = frame_difference(program.base @ target.pose, world_tcp)
        assert distance <= POSITION_TOLERANCE and angle <= ANGLE_TOLERANCE
    start = program.sections[0].moves[0]
    assert isinstance(start, JointMove)
    assert not np.allclose(start.joints, start.model_joints)


def test_the_header_states_the_run() -> None:
    run = planned_run("paper-corner")
    program = build_program(run, name="my weld")
    text = "\n".join(program.header)
    assert program.name == "my weld"
    for expected in (
        "written by trackplan ",
        "case: paper-corner",
        "robot: puma560",
        "placement X: [0.090200, 0.209000, 0.202000] m",
        "[90.200, 209.000, 202.000] mm",
        "base (part frame in the controller world): xyz [90.2000, 209.0000, 202.0000] mm",
        "tool (TCP in the flange): xyz [0.0000, 0.0000, 0.0000] mm",
        "verdict: feasible",
        f"duration: {run.plan.duration:.3f} s",
        "form: cartesian",
        "tolerance budget (worst seam): tolerance 1.0000 mm",
    ):
        assert expected in text, expected
    assert build_program(run).name == "paper-corner"
    assert program.sample_time == run.plan.trajectory.sample_time
    assert program.period is None and program.feasible
    np.testing.assert_array_equal(program.v_max, run.case.robot.v_max)
    assert program.n_dof == 6 and program.robot == "puma560"


def test_a_run_that_is_not_feasible_needs_force() -> None:
    run = planned_run("puma-payload")  # its example placement breaks a torque limit
    assert not run.plan.success
    with pytest.raises(CaseError) as error:
        build_program(run)
    assert error.value.key == "--force"
    line = str(error.value)
    assert "\n" not in line
    assert line.startswith("--force: the run is not feasible (")
    assert line.endswith("): exporting it needs --force")
    assert run.plan.message in line
    program = build_program(run, force=True)
    assert not program.feasible
    verdict = next(line for line in program.header if line.startswith("verdict:"))
    assert "NOT FEASIBLE" in verdict and run.plan.message in verdict and "--force" in verdict


def test_an_unknown_form_is_refused() -> None:
    with pytest.raises(CaseError, match="--motion: must be one of cartesian, joint"):
        build_program(planned_run("paper-corner"), motion="spline")


def test_a_reversal_inside_a_seam_is_a_stop_point(tmp_path: Path) -> None:
    import trackplan

    text = (CASES / "paper-line.yaml").read_text(encoding="utf-8")
    there_and_back = "    - line: {to: [0.3, 0, 0.5]}\n    - line: {to: [0.15, 0, 0.25]}\n"
    text = text.replace("    - line: {to: [0.3, 0, 0.5]}\n", there_and_back)
    file = tmp_path / "reversal.yaml"
    file.write_text(text, encoding="utf-8")
    case = trackplan.load_case(file)
    assert case.bounds.example is not None
    plan = trackplan.plan(case, case.bounds.example)
    assert plan.success, plan.message
    path = plan.seams[0].plan.joint_path.geometry.planned
    assert len(path.stops) == 1
    program = build_program(PlannedRun(case=case, plan=plan))
    out, back = seam_moves(program)
    assert isinstance(out, LinearMove) and isinstance(back, LinearMove)
    np.testing.assert_allclose(out.target.pose[:3, 3], [0.3, 0.0, 0.5], atol=1e-12)
    assert out.zone == 0.0 and back.zone == 0.0  # the plan stops at the turn and the end
    budget = program.budget
    assert budget is not None and budget.tracking_error < 1e-6  # lines: the whole budget


def test_a_spline_that_ends_where_the_plan_stops_blends_through_its_points(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    from trackplan.programs import cartesian

    monkeypatch.setattr(cartesian, "MIN_MOVE", 10.0)  # m: every piece joins one spline
    run = planned_run("paper-corner")
    program = build_program(run)
    through, last = seam_moves(program)
    assert isinstance(through, SplineMove) and isinstance(last, SplineMove)
    budget = program.budget
    assert budget is not None and budget.slack >= 0.0
    assert len(through.targets) > 2 and through.zone == budget.zone > 0.0
    assert len(last.targets) == 1 and last.zone == 0.0
    assert through.speed == last.speed
    path = run.plan.seams[0].plan.joint_path.geometry.planned
    _, end, _ = path.points(np.array([path.length]))
    np.testing.assert_allclose(last.targets[0].pose[:3, 3], end[0], atol=1e-12)
