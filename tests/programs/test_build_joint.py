"""build_program, joint form: every k-th sample, timed, the last kept; split programs."""

from __future__ import annotations

import numpy as np
import pytest

from tests.programs.roundtrip import expected_targets, planned_run
from trackplan.errors import CaseError
from trackplan.programs import JointMove, Program, Section, build_program, split_program
from trackplan.programs.joint_form import sample_indices


def timed_moves(program: Program) -> list[JointMove]:
    """The timed joint moves (every section but the start)."""
    moves = [m for s in program.sections[1:] for m in s.moves]
    assert all(isinstance(m, JointMove) for m in moves)
    return moves  # type: ignore[return-value]


def test_every_sample_by_default() -> None:
    run = planned_run("paper-corner")
    trajectory = run.plan.trajectory
    program = build_program(run, motion="joint")
    assert program.motion == "joint" and program.budget is None
    assert program.period == trajectory.sample_time
    start = program.sections[0]
    assert start.kind == "start" and len(start.moves) == 1
    first = start.moves[0]
    assert isinstance(first, JointMove) and first.duration is None
    moves = timed_moves(program)
    assert len(moves) == trajectory.n_samples - 1
    joints = np.array([m.joints for m in moves])
    np.testing.assert_allclose(joints, trajectory.q[1:], atol=0)  # identity convention
    durations = np.array([m.duration for m in moves])
    np.testing.assert_allclose(durations, trajectory.sample_time, rtol=1e-9)
    speeds = np.array([m.speed for m in moves])
    assert np.all((speeds >= 0.01) & (speeds <= 1.0))
    peak = np.max(np.abs(trajectory.qd[1:]) / run.case.robot.v_max, axis=1)
    np.testing.assert_allclose(speeds, np.clip(peak, 0.01, 1.0), rtol=1e-12)
    assert moves[-1].zone == 0.0
    assert "form: joint (the planned joint trajectory, one timed move every 0.001 s)" in (
        program.header
    )


def test_a_period_of_k_samples_keeps_every_kth_and_the_last() -> None:
    run = planned_run("paper-corner")
    trajectory = run.plan.trajectory
    n, ts = trajectory.n_samples, trajectory.sample_time
    k = next(k for k in (7, 11, 13, 17) if (n - 1) % k)  # the last sample is off the step
    program = build_program(run, motion="joint", period=k * ts)
    assert program.period == pytest.approx(k * ts, abs=1e-15)
    moves = timed_moves(program)
    index = np.append(np.arange(0, n, k), n - 1)
    assert len(moves) == len(index) - 1
    np.testing.assert_allclose([m.joints for m in moves], trajectory.q[index[1:]], atol=0)
    durations = np.array([m.duration for m in moves])
    np.testing.assert_allclose(durations[:-1], k * ts, rtol=1e-9)
    np.testing.assert_allclose(durations[-1], ((n - 1) % k) * ts, rtol=1e-9)
    np.testing.assert_allclose(durations.sum(), trajectory.duration, rtol=1e-12)


def test_a_period_on_the_step_ends_on_the_last_sample_once() -> None:
    n = 31
    np.testing.assert_array_equal(sample_indices(n, 5), np.arange(0, 31, 5))
    np.testing.assert_array_equal(sample_indices(n, 7), [0, 7, 14, 21, 28, 30])
    np.testing.assert_array_equal(sample_indices(n, 1), np.arange(31))
    np.testing.assert_array_equal(sample_indices(n, 100), [0, 30])


@pytest.mark.parametrize("period", [0.0015, 0.0, -0.002, float("nan"), 0.0020001])
def test_a_period_that_is_no_multiple_of_the_sample_time_is_refused(period: float) -> None:
    run = planned_run("paper-corner")  # sample time 1 ms
    with pytest.raises(CaseError) as error:
        build_program(run, motion="joint", period=period)
    assert error.value.key == "--period"
    assert "must be a positive multiple of the sample time 0.001 s" in str(error.value)


def test_a_period_within_a_nanosecond_of_a_multiple_is_taken() -> None:
    run = planned_run("paper-corner")
    program = build_program(run, motion="joint", period=0.002 + 5e-10)
    assert program.period == pytest.approx(0.002, abs=1e-15)


def test_joint_zones_stop_where_the_plan_rests_and_keep_within_the_budget() -> None:
    run = planned_run("bracket-4-fillets")  # seams joined by approach, retract, air moves
    plan = run.plan
    program = build_program(run, motion="joint", period=4 * plan.trajectory.sample_time)
    assert [s.label for s in program.sections[1:]] == [span.label for span in plan.spans]
    seams = iter(plan.seam_checks)
    for section, span in zip(program.sections[1:], plan.spans, strict=True):
        moves = [m for m in section.moves if isinstance(m, JointMove)]
        if span.kind == "seam":
            check = next(seams)
            tolerance = run.case.seams[span.seam or 0].task.tolerance
            room = tolerance - check.max_tracking_error
            assert max(m.zone for m in moves) <= room
    # every span ends at rest: a move that ends there stops
    index = sample_indices(plan.trajectory.n_samples, 4)
    rests = {span.last for span in plan.spans}
    moves = timed_moves(program)
    for m, i in enumerate(index[1:]):
        if int(i) in rests:
            assert moves[m].zone == 0.0
    assert any(moves[m].zone > 0.0 for m in range(len(moves)))


def flat(sections: tuple[Section, ...]) -> list[np.ndarray]:
    """Every target's controller joints, in order, of some sections."""
    program = Program(
        name="p",
        motion="cartesian",
        robot="r",
        vendor="generic",
        n_dof=6,
        base=np.eye(4),
        tool=np.eye(4),
        sections=sections,
        header=(),
        sample_time=0.001,
    )
    return [t.joints for t in expected_targets(program)]


@pytest.mark.parametrize(
    ("case_name", "motion", "max_points"),
    [
        ("bracket-4-fillets", "joint", 500),
        ("bracket-weld", "cartesian", 7),
        ("bracket-4-fillets", "cartesian", 5),
    ],
)
def test_a_split_program_reads_back_as_the_whole(
    case_name: str, motion: str, max_points: int
) -> None:
    program = build_program(planned_run(case_name), motion=motion)
    parts = split_program(program, max_points)
    assert len(parts) > 1
    assert all(part.n_points <= max_points for part in parts)
    whole = flat(program.sections)
    pieces = [joints for part in parts for joints in flat(part.sections)]
    assert len(pieces) == len(whole) == program.n_points
    for got, want in zip(pieces, whole, strict=True):
        np.testing.assert_array_equal(got, want)
    labels = [s.label for part in parts for s in part.sections]
    assert [label for k, label in enumerate(labels) if k == 0 or labels[k - 1] != label] == [
        s.label for s in program.sections
    ]
