"""build_program on several seams: approach, retract and air moves, reversed seams,
per-seam speeds and budgets."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from tests.programs.roundtrip import planned_run
from trackplan.planning.result import Span
from trackplan.programs import (
    CircularMove,
    JointMove,
    LinearMove,
    SplineMove,
    Target,
    build_program,
)
from trackplan.programs.cartesian import seam_moves, span_joint_moves


def last_target(moves: tuple[object, ...]) -> Target:
    move = moves[-1]
    if isinstance(move, SplineMove):
        return move.targets[-1]
    assert isinstance(move, LinearMove | CircularMove)
    return move.target


def first_target(moves: tuple[object, ...]) -> Target:
    move = moves[0]
    if isinstance(move, SplineMove):
        return move.targets[0]
    if isinstance(move, CircularMove):
        return move.via
    assert isinstance(move, LinearMove)
    return move.target


def test_sections_follow_the_spans_with_joint_moves_between_seams() -> None:
    run = planned_run("bracket-4-fillets")
    plan = run.plan
    program = build_program(run)
    assert [s.kind for s in program.sections] == ["start"] + [s.kind for s in plan.spans]
    assert [s.label for s in program.sections[1:]] == [s.label for s in plan.spans]
    q = plan.trajectory.q
    for section, span in zip(program.sections[1:], plan.spans, strict=True):
        if span.kind == "seam":
            assert not any(isinstance(m, JointMove) for m in section.moves)
            np.testing.assert_allclose(
                last_target(section.moves).model_joints, q[span.last], atol=1e-6
            )
            continue
        assert len(section.moves) == 1
        move = section.moves[0]
        assert isinstance(move, JointMove) and move.zone == 0.0 and move.duration is None
        np.testing.assert_allclose(move.model_joints, q[span.last], atol=0)
        peak = np.max(np.abs(plan.trajectory.qd[span.first + 1 : span.last + 1]))
        assert 0.01 <= move.speed <= 1.0
        shares = np.abs(plan.trajectory.qd[span.first + 1 : span.last + 1]) / (run.case.robot.v_max)
        assert move.speed == pytest.approx(max(float(shares.max()), 0.01), rel=1e-12)
        assert peak > 0.0


def test_reversed_seams_run_end_to_start() -> None:
    run = planned_run("bracket-4-fillets")
    program = build_program(run)
    directions = {seam.name: seam.reversed for seam in run.plan.seams}
    assert directions["gusset"] and directions["rib-left"] and not directions["rib-right"]
    sections = {s.label: s for s in program.sections if s.kind == "seam"}
    # the gusset as written: (0.05, 0.2) → (0.2, 0.2) → (0.2, 0.15); reversed it starts on
    # the short leg at x = 0.2 and ends at (0.05, 0.2)
    gusset = sections["gusset"].moves
    assert [type(m) for m in gusset] == [LinearMove, SplineMove, LinearMove]
    first = first_target(gusset).pose[:3, 3]
    assert first[0] == pytest.approx(0.2, abs=1e-9) and 0.15 < first[1] < 0.2
    np.testing.assert_allclose(last_target(gusset).pose[:3, 3], [0.05, 0.2, 0.0], atol=1e-12)
    (rib,) = sections["rib-left"].moves  # (0.05, 0.08) → (0.15, 0.08), reversed
    assert isinstance(rib, LinearMove)
    np.testing.assert_allclose(rib.target.pose[:3, 3], [0.05, 0.08, 0.0], atol=1e-12)
    (rib,) = sections["rib-right"].moves  # (0.05, 0.10) → (0.15, 0.10), forward
    assert isinstance(rib, LinearMove)
    np.testing.assert_allclose(rib.target.pose[:3, 3], [0.15, 0.10, 0.0], atol=1e-12)
    # the approach before a reversed seam ends at the seam's end as written
    q = run.plan.trajectory.q
    span = next(s for s in run.plan.spans if s.label == "rib-left")
    approach = program.sections[1 + run.plan.spans.index(span) - 1]
    assert approach.kind == "approach"
    np.testing.assert_allclose(approach.moves[0].model_joints, q[span.first], atol=0)  # type: ignore[union-attr]


def test_each_seam_keeps_its_own_rated_speed() -> None:
    run = planned_run("bracket-4-fillets")
    program = build_program(run)
    rated = {seam.name: seam.task.rated_speed for seam in run.case.seams}
    for section in program.sections:
        if section.kind != "seam":
            continue
        speeds = [float(m.speed) for m in section.moves]  # type: ignore[union-attr]
        assert max(speeds) <= rated[section.label] * (1 + 1e-6)
        assert max(speeds) == pytest.approx(rated[section.label], rel=1e-2)
    assert rated["boss"] < rated["gusset"]


def test_the_budget_is_the_worst_seams_and_every_seam_keeps_its_own() -> None:
    run = planned_run("bracket-4-fillets")
    program = build_program(run)
    budgets = [
        seam_moves(run.case, seam, check)[1]
        for seam, check in zip(run.plan.seams, run.plan.seam_checks, strict=True)
    ]
    assert program.budget is not None
    assert program.budget.slack == min(b.slack for b in budgets)
    for budget, check, seam in zip(budgets, run.plan.seam_checks, run.plan.seams, strict=True):
        assert budget.tracking_error == check.max_tracking_error
        assert budget.tolerance == run.case.seams[seam.index].task.tolerance
        assert budget.slack >= 0.0


def test_an_air_move_through_a_via_is_two_joint_moves() -> None:
    run = planned_run("bracket-4-fillets")
    plan = run.plan
    air = next(span for span in plan.spans if span.kind == "air")
    middle = (air.first + air.last) // 2
    via = plan.trajectory.q[middle]
    moves = span_joint_moves(run.case.robot, plan, replace(air, via=via.copy()))
    assert len(moves) == 2 and all(isinstance(m, JointMove) for m in moves)
    first, second = moves
    assert isinstance(first, JointMove) and isinstance(second, JointMove)
    np.testing.assert_allclose(first.model_joints, via, atol=0)
    np.testing.assert_allclose(second.model_joints, plan.trajectory.q[air.last], atol=0)
    assert first.zone == second.zone == 0.0
    shares = np.abs(plan.trajectory.qd) / run.case.robot.v_max
    assert first.speed == pytest.approx(shares[air.first + 1 : middle + 1].max(), rel=1e-12)
    assert second.speed == pytest.approx(shares[middle + 1 : air.last + 1].max(), rel=1e-12)
    plain = span_joint_moves(run.case.robot, plan, Span(**{**air.__dict__, "via": None}))
    assert len(plain) == 1
