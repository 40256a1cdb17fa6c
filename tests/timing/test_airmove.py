"""Air moves: ruckig's jerk-limited rest-to-rest moves, sampled at Ts, and their time bounds."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from ruckig import DurationDiscretization, InputParameter, Ruckig, Trajectory

from trackplan.derivatives import backward_derivatives
from trackplan.io.robot_file import builtin_robot
from trackplan.planning.checker import check_trajectory
from trackplan.timing.airmove import (
    PLANNING_MARGIN,
    air_time_estimate,
    plan_air_move,
    trapezoid_time,
)
from trackplan.timing.sample_checks import RateLimits, robot_checks

TS = 0.004
N_MOVES = 40
ROBOTS = ("puma560", "ur5e")


def limits(robot):
    return robot.v_max, robot.a_max, robot.j_max


def random_pairs(robot, n, seed):
    """``n`` pairs of configurations inside the limits (a third of them close together)."""
    rng = np.random.default_rng(seed)
    start = rng.uniform(robot.q_min, robot.q_max, (n, robot.n_dof))
    end = rng.uniform(robot.q_min, robot.q_max, (n, robot.n_dof))
    near = np.clip(start + rng.uniform(-0.05, 0.05, start.shape), robot.q_min, robot.q_max)
    end[::3] = near[::3]
    return start, end


@pytest.fixture(scope="module", params=ROBOTS)
def moves(request):
    """(robot, start (M, n), end (M, n), planned moves) for seeded random pairs."""
    robot = builtin_robot(request.param)
    start, end = random_pairs(robot, N_MOVES, seed=12)
    planned = [plan_air_move(a, b, *limits(robot), TS) for a, b in zip(start, end, strict=True)]
    return robot, start, end, planned


def test_moves_end_exactly_at_their_configurations(moves):
    _, start, end, planned = moves
    for a, b, move in zip(start, end, planned, strict=True):
        assert np.array_equal(move.q[0], a)
        assert np.array_equal(move.q[-1], b)
        assert move.via is None
        assert move.sample_time == TS
        assert move.duration == pytest.approx((len(move.q) - 1) * TS)


def test_moves_pass_the_sample_checks_and_the_checker(moves):
    robot, _, _, planned = moves
    check = RateLimits(robot)
    for move in planned:
        sample, _, _ = check(move.q, TS)
        assert sample.size == 0
        report = check_trajectory(robot, move.q, TS)
        for kind in ("position", "velocity", "acceleration", "jerk"):
            assert report.joint_margins[kind].min() >= 0.0, kind
        # the jerk limit is what binds a time-optimal move: it is used, not left idle
        assert report.joint_margins["jerk"].min() < 1e-3


def test_moves_start_and_end_at_rest(moves):
    """From rest under a jerk limit j: |v(t)| <= j t²/2 and |a(t)| <= j t, and the backward
    differences average these over the last one or two periods; the same towards the end.
    A move that started with a speed or an acceleration step would break these bounds."""
    robot, _, _, planned = moves
    j = robot.j_max * (1.0 + 1e-9)
    for move in planned:
        qd, qdd, _ = backward_derivatives(move.q, TS, pad_end=True)
        n = len(move.q)
        for k in range(3):
            t_from_start = k * TS
            assert np.all(np.abs(qd[k]) <= j * t_from_start**2 / 2.0 + 1e-12)
            assert np.all(np.abs(qdd[k]) <= j * t_from_start + 1e-9)
            last = n - 1 - k
            t_to_end = k * TS
            assert np.all(np.abs(qd[last]) <= j * (t_to_end + TS) ** 2 / 2.0 + 1e-12)
            assert np.all(np.abs(qdd[last]) <= j * (t_to_end + 2.0 * TS) + 1e-9)
        # and it holds still after the end
        assert np.all(qd[n:] == 0.0)


def test_moves_are_time_optimal_within_one_period(moves):
    """duration >= estimate >= trapezoid; and the synchronised move takes no longer than the
    slowest joint alone, up to the rounding to whole periods and the planning margin."""
    robot, start, end, planned = moves
    duration = np.array([move.duration for move in planned])
    estimate = air_time_estimate(start, end, *limits(robot))
    trapezoid = trapezoid_time(start, end, robot.v_max, robot.a_max)
    assert np.all(duration >= estimate - 1e-12)
    assert np.all(estimate >= trapezoid)
    assert np.all(duration <= estimate / (1.0 - PLANNING_MARGIN) + TS + 1e-9)
    # the jerk limit costs time: strictly more than the trapezoid on every real move
    assert np.all(estimate > trapezoid)


@pytest.mark.parametrize("name", ROBOTS)
def test_estimate_equals_ruckigs_single_joint_durations(name):
    """The closed form against ruckig's own per-joint time-optimal durations."""
    robot = builtin_robot(name)
    start, end = random_pairs(robot, 30, seed=5)
    estimate = air_time_estimate(start, end, *limits(robot))
    for a, b, value in zip(start, end, estimate, strict=True):
        given = InputParameter(robot.n_dof)
        given.current_position = a.tolist()
        given.target_position = b.tolist()
        given.max_velocity = robot.v_max.tolist()
        given.max_acceleration = robot.a_max.tolist()
        given.max_jerk = robot.j_max.tolist()
        trajectory = Trajectory(robot.n_dof)
        Ruckig(robot.n_dof).calculate(given, trajectory)
        assert value == pytest.approx(max(trajectory.independent_min_durations), rel=1e-9)


def test_samples_equal_ruckigs_own_evaluation():
    """The vectorised sampling of the profiles against ruckig's ``at_time``, sample by sample."""
    robot = builtin_robot("puma560")
    start, end = random_pairs(robot, 3, seed=8)
    scale = 1.0 - PLANNING_MARGIN
    for a, b in zip(start, end, strict=True):
        move = plan_air_move(a, b, *limits(robot), TS)
        given = InputParameter(robot.n_dof)
        given.current_position = a.tolist()
        given.target_position = b.tolist()
        given.max_velocity = (scale * robot.v_max).tolist()
        given.max_acceleration = (scale * robot.a_max).tolist()
        given.max_jerk = (scale * robot.j_max).tolist()
        given.duration_discretization = DurationDiscretization.Discrete
        trajectory = Trajectory(robot.n_dof)
        Ruckig(robot.n_dof, TS).calculate(given, trajectory)
        expected = np.array([trajectory.at_time(k * TS)[0] for k in range(len(move.q))])
        np.testing.assert_allclose(move.q, expected, rtol=0.0, atol=1e-12)


def test_via_move_stops_exactly_at_the_via():
    robot = builtin_robot("ur5e")
    start, end = random_pairs(robot, 6, seed=3)
    for a, b, via in zip(start[:3], end[:3], start[3:], strict=True):
        move = plan_air_move(a, b, *limits(robot), TS, via=via)
        at_via = np.flatnonzero(np.all(move.q == via, axis=1))
        assert at_via.size == 1
        first = plan_air_move(a, via, *limits(robot), TS)
        second = plan_air_move(via, b, *limits(robot), TS)
        assert at_via[0] == len(first.q) - 1
        assert move.duration == pytest.approx(first.duration + second.duration)
        np.testing.assert_array_equal(move.via, via)
        assert np.array_equal(move.q[-1], b)
        assert RateLimits(robot)(move.q, TS)[0].size == 0


def test_a_move_to_the_same_configuration_is_one_sample():
    robot = builtin_robot("puma560")
    q = np.zeros(robot.n_dof)
    move = plan_air_move(q, q, *limits(robot), TS)
    assert move.q.shape == (1, robot.n_dof)
    assert move.duration == 0.0
    assert air_time_estimate(q, q, *limits(robot)) == 0.0


def test_one_joint_closed_form_by_hand():
    """1 rad at v = 1, a = 2, j = 10: jerk 0.2 s, constant acceleration 0.3 s, 0.3 s at
    speed; 1.7 s (trapezoid: 1 + 0.5 = 1.5 s). A short move, 0.01 rad, never reaches a:
    4 (D / 2j)^(1/3)."""
    one = np.array([1.0]), np.array([2.0]), np.array([10.0])
    assert air_time_estimate(np.zeros(1), np.ones(1), *one) == pytest.approx(1.7)
    assert trapezoid_time(np.zeros(1), np.ones(1), one[0], one[1]) == pytest.approx(1.5)
    short = air_time_estimate(np.zeros(1), np.full(1, 0.01), *one)
    assert short == pytest.approx(4.0 * (0.01 / 20.0) ** (1.0 / 3.0))


@settings(max_examples=30, deadline=None)
@given(
    batch=st.integers(1, 4),
    seed=st.integers(0, 2**31 - 1),
)
def test_estimates_batched_equal_one_at_a_time(batch, seed):
    robot = builtin_robot("puma560")
    rng = np.random.default_rng(seed)
    start = rng.uniform(robot.q_min, robot.q_max, (batch, 3, robot.n_dof))
    end = rng.uniform(robot.q_min, robot.q_max, (batch, 3, robot.n_dof))
    together = air_time_estimate(start, end, *limits(robot))
    trapezoid = trapezoid_time(start, end, robot.v_max, robot.a_max)
    assert together.shape == (batch, 3)
    for index in np.ndindex(batch, 3):
        assert together[index] == air_time_estimate(start[index], end[index], *limits(robot))
        assert trapezoid[index] == trapezoid_time(
            start[index], end[index], robot.v_max, robot.a_max
        )
    assert np.all(together >= trapezoid)


@pytest.mark.parametrize(
    ("change", "match"),
    [
        ({"q_end": np.zeros(5)}, "shape"),
        ({"velocity": -np.ones(6)}, "positive"),
        ({"sample_time": 0.0}, "sample_time"),
        ({"via": np.zeros(3)}, "shape"),
        ({"q_end": np.full(6, np.nan)}, "finite"),
    ],
)
def test_bad_arguments_raise_one_clear_error(change, match):
    arguments = {
        "q_start": np.zeros(6),
        "q_end": np.ones(6),
        "velocity": np.ones(6),
        "acceleration": np.ones(6),
        "jerk": np.ones(6),
        "sample_time": TS,
    }
    via = change.pop("via", None)
    arguments.update(change)
    with pytest.raises(ValueError, match=match):
        plan_air_move(**arguments, via=via)


def test_torque_checks_slow_down_only_the_moves_that_need_it():
    """At full rate limits a few random PUMA560 moves exceed a torque limit (ruckig knows
    no dynamics); with the robot's checks those are stretched in time until they pass, and
    every other move is left exactly as it was."""
    robot = builtin_robot("puma560")
    rng = np.random.default_rng(4)
    pairs = rng.uniform(robot.q_min, robot.q_max, (100, 2, robot.n_dof))
    checks = robot_checks(robot)
    n_slowed = 0
    for a, b in pairs:
        free = plan_air_move(a, b, *limits(robot), TS)
        checked = plan_air_move(a, b, *limits(robot), TS, checks=checks)
        report = check_trajectory(robot, checked.q, TS)
        assert report.success, [v.message for v in report.violations]
        if check_trajectory(robot, free.q, TS).success:
            assert checked.speed_factor == 1.0
            np.testing.assert_array_equal(checked.q, free.q)
        else:
            n_slowed += 1
            assert checked.speed_factor < 1.0
            assert checked.duration > free.duration
            assert np.array_equal(checked.q[-1], b)
    assert n_slowed >= 2
