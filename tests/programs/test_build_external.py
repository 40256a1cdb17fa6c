"""The program builder with external axes: a planned run given a track (its trajectory
widened by a track column made here), so that every joint move and target must carry the
track value of its own sample or arc length (``docs/export.md``, *External axes*)."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from tests.programs.fanuc_parser import parse_fanuc
from tests.programs.krl_parser import parse_krl
from tests.programs.rapid_parser import parse_rapid
from tests.programs.roundtrip import PlannedRun, planned_run, target_pairs
from trackplan.errors import CaseError
from trackplan.frames import placement_transform
from trackplan.io.robot_file import builtin_robot
from trackplan.planning.result import SEAM
from trackplan.programs import build_program
from trackplan.programs.model import (
    CircularMove,
    ExternalAxis,
    JointMove,
    LinearMove,
    Move,
    Program,
    SplineMove,
    Target,
)
from trackplan.robots.controller import ControllerConvention
from trackplan.robots.machine import Positioner, Track
from trackplan.writers.fanuc import render_fanuc
from trackplan.writers.krl import render_krl
from trackplan.writers.rapid import render_rapid

TRACK = Track(
    axis=np.array([1.0, 0.0, 0.0]), lower=0.0, upper=4.0, velocity=1.0, acceleration=2.0, jerk=20.0
)
OFFSET, SLOPE = 0.75, 0.2
"""The track column made here: ``OFFSET + SLOPE · s`` over each seam (s its own arc
length, m), held between seams."""


def with_track(run: PlannedRun) -> tuple[PlannedRun, np.ndarray]:
    """The run's case given a track, its trajectory a track column; the column (N,)."""
    plan = run.plan
    trajectory = plan.trajectory
    column = np.full(trajectory.n_samples, OFFSET)
    seams = iter(plan.seams)
    for span in plan.spans:
        if span.kind == SEAM:
            seam_s = next(seams).plan.trajectory.s
            assert len(seam_s) == span.last - span.first + 1
            column[span.first : span.last + 1] = OFFSET + SLOPE * seam_s
            column[span.last + 1 :] = column[span.last]
    wide = dataclasses.replace(
        trajectory,
        q=np.column_stack([trajectory.q, column]),
        qd=np.column_stack([trajectory.qd, np.zeros_like(column)]),
        qdd=np.column_stack([trajectory.qdd, np.zeros_like(column)]),
        qddd=np.column_stack([trajectory.qddd, np.zeros_like(column)]),
    )
    case = dataclasses.replace(run.case, track=TRACK)
    return PlannedRun(case=case, plan=dataclasses.replace(plan, trajectory=wide)), column


@pytest.fixture(scope="module")
def tracked() -> tuple[PlannedRun, np.ndarray]:
    return with_track(planned_run("paper-corner"))


def test_the_program_lists_the_track_and_says_so(tracked: tuple[PlannedRun, np.ndarray]) -> None:
    run, _ = tracked
    program = build_program(run, motion="joint")
    assert program.external_axes == (ExternalAxis(name="track", kind="track", unit="m", v_max=1.0),)
    assert not program.coordinated
    assert "external axes, in order: track (track, m)" in program.header


def test_every_joint_form_move_carries_its_samples_track_value(
    tracked: tuple[PlannedRun, np.ndarray],
) -> None:
    run, column = tracked
    program = build_program(run, motion="joint")
    moves = [move for move in program.moves() if isinstance(move, JointMove)]
    # the start move goes to sample 0, then one timed move per sample
    assert len(moves) == run.plan.trajectory.n_samples
    values = np.array([move.external[0] for move in moves])
    np.testing.assert_allclose(values, column, rtol=0, atol=1e-12)
    arm = np.array([move.model_joints for move in moves])
    np.testing.assert_allclose(arm, run.plan.trajectory.q[:, :-1], rtol=0, atol=1e-12)


def move_targets(move: Move) -> tuple[Target, ...]:
    """The Cartesian targets of a move in order (none for a joint move)."""
    if isinstance(move, SplineMove):
        return move.targets
    if isinstance(move, CircularMove):
        return (move.via, move.target)
    if isinstance(move, LinearMove):
        return (move.target,)
    return ()


def _arc_lengths(program: Program, run: PlannedRun) -> list[float]:
    """Each Cartesian target's arc length along its seam: the nearest of a fine sampling
    of the seam's planned path (within 0.05 mm), found from its pose alone."""
    plan = run.plan
    out: list[float] = []
    seams = iter(plan.seams)
    for section in program.sections[1:]:
        if section.kind != SEAM:
            continue
        path = next(seams).plan.joint_path.geometry.planned
        s = np.linspace(0.0, path.length, int(path.length / 5e-5) + 2)
        _, points, _ = path.points(s)
        for move in section.moves:
            targets = move_targets(move)
            for target in targets:
                nearest = np.argmin(np.linalg.norm(points - target.pose[:3, 3], axis=1))
                out.append(float(s[nearest]))
    return out


def test_every_cartesian_target_carries_the_track_at_its_arc_length(
    tracked: tuple[PlannedRun, np.ndarray],
) -> None:
    run, column = tracked
    program = build_program(run, motion="cartesian")
    targets = [
        target
        for section in program.sections
        if section.kind == SEAM
        for move in section.moves
        for target in move_targets(move)
    ]
    assert targets
    found = np.array([target.external[0] for target in targets])
    expected = OFFSET + SLOPE * np.array(_arc_lengths(program, run))
    np.testing.assert_allclose(found, expected, rtol=0, atol=SLOPE * 5e-5)
    joint_moves = [move for move in program.moves() if isinstance(move, JointMove)]
    np.testing.assert_allclose(joint_moves[0].external, column[:1], atol=1e-12)
    # written and read back as KRL E1, mm, within its 1e-4 mm
    parsed = parse_krl(render_krl(program, robot=run.case.robot))
    for got, want in target_pairs(parsed, program):
        assert abs(got.external[0] - 1000.0 * want.external[0]) <= 0.5e-4 + 1e-9


@pytest.mark.slow
@pytest.mark.parametrize("motion", ["cartesian", "joint"])
def test_a_run_planned_with_a_track_reads_back_from_every_language(motion: str) -> None:
    """The shipped case on a track, planned: KRL, RAPID and TP carry the planned track
    values on every target, read back by their own parsers (mm, within the print)."""
    shipped = planned_run("track-long-seam")
    assert shipped.plan.success, shipped.plan.message
    # the KR10 as a generic robot, so that every language drives it
    robot = dataclasses.replace(shipped.case.robot, controller=None)
    case, plan = dataclasses.replace(shipped.case, robot=robot), shipped.plan
    run = PlannedRun(case=case, plan=plan)
    program = build_program(run, motion=motion)
    track = program.external_axes[0]
    assert track.kind == "track"
    robot = case.robot
    readers = [
        (parse_krl(render_krl(program, robot=robot)), 0.5e-4),
        (parse_rapid(render_rapid(program, robot=robot)), 0.5e-4),
        (parse_fanuc(render_fanuc(program, robot=robot)), 0.5e-3),
    ]
    for parsed, tolerance in readers:
        for got, want in target_pairs(parsed, program):
            assert abs(got.external[0] - 1000.0 * want.external[0]) <= tolerance + 1e-9
    if motion == "joint":
        moves = [move for move in program.moves() if isinstance(move, JointMove)]
        np.testing.assert_allclose(
            [move.external[0] for move in moves], plan.trajectory.q[:, robot.n_dof], atol=1e-12
        )


def test_with_a_positioner_the_base_is_the_part_on_its_flange() -> None:
    """A positioner carries the part: the program's base is the placement itself (the part
    in the carrier frame), not the part in the controller's world; TP writes the joint
    form's positioner axes as motion group 2 and refuses the Cartesian form."""
    shipped = planned_run("paper-corner")
    world = np.eye(4)
    world[2, 3] = 0.525  # a controller world above the base, as the M-20iA's
    convention = ControllerConvention(
        vendor="generic", signs=np.ones(6), offsets=np.zeros(6), world=world
    )
    robot = dataclasses.replace(shipped.case.robot, controller=convention)
    chain = builtin_robot("puma560")
    case = dataclasses.replace(
        shipped.case,
        robot=robot,
        positioner=Positioner(chain=chain, pose=np.zeros(6), model="stand-in"),
    )
    trajectory = shipped.plan.trajectory
    turn = np.linspace(-1.0, 1.0, trajectory.n_samples)[:, None] * np.arange(1, 7) / 10.0
    wide = dataclasses.replace(
        trajectory,
        q=np.column_stack([trajectory.q, turn]),
        qd=np.column_stack([trajectory.qd, np.zeros_like(turn)]),
        qdd=np.column_stack([trajectory.qdd, np.zeros_like(turn)]),
        qddd=np.column_stack([trajectory.qddd, np.zeros_like(turn)]),
    )
    run = PlannedRun(case=case, plan=dataclasses.replace(shipped.plan, trajectory=wide))
    part = placement_transform(shipped.plan.placement)
    assert not np.allclose(robot.convention.world_from_base(part), part)
    flange_line = "base (part frame on the positioner's flange)"
    for motion in ("cartesian", "joint"):
        program = build_program(run, motion=motion)
        assert program.coordinated
        assert [axis.kind for axis in program.external_axes] == ["positioner"] * 6
        np.testing.assert_allclose(program.base, part, atol=1e-15)
        assert any(line.startswith(flange_line) for line in program.header)
    # every 25th sample keeps the listing short for the parser
    joint = build_program(run, motion="joint", period=25 * trajectory.sample_time)
    parsed = parse_fanuc(render_fanuc(joint, robot=robot))
    assert parsed.coupled == "GP2"
    for got, want in target_pairs(parsed, joint):
        np.testing.assert_allclose(got.external, np.degrees(want.external), atol=0.5e-4 + 1e-9)
    with pytest.raises(CaseError, match="--motion joint"):
        render_fanuc(build_program(run, motion="cartesian"), robot=robot)
