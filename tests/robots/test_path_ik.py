"""Path IK: continuity, branch choice, switch detection, limits, batching, numeric mode."""

from __future__ import annotations

import numpy as np
import pytest

from trackplan.errors import CaseError
from trackplan.frames import placement_transform, pose_matrix, rpy_matrix
from trackplan.robots.families import solve_ik
from trackplan.robots.kinematics import forward_kinematics
from trackplan.robots.path_ik import (
    branch_joints,
    branch_joints_along,
    numeric_seeds,
    solve_path_ik,
    solve_path_ik_branches,
)
from trackplan.status import Status

# A 1 m line with constant tool orientation that the PUMA follows within its limits.
LINE_CENTRE = np.array([0.403, -0.159, 0.081])
LINE_DIRECTION = np.array([0.5758, 0.7321, -0.3639])
LINE_RPY = np.array([0.027, -0.128, -0.671])
SAMPLE_TIME = 1e-3
SPEED = 0.15


def line(centre, direction, rotation, length, n_poses):
    """Poses along a straight line with a constant orientation, shape (n_poses, 4, 4)."""
    direction = direction / np.linalg.norm(direction)
    s = np.linspace(-0.5 * length, 0.5 * length, n_poses)[:, None]
    return pose_matrix(centre + s * direction, rotation)


def feasible_line(n_poses):
    return line(LINE_CENTRE, LINE_DIRECTION, rpy_matrix(LINE_RPY), 1.0, n_poses)


def wrapped(angle):
    return np.pi - np.mod(np.pi - angle, 2 * np.pi)


def assert_follows(robot, result, T, tol=1e-9):
    """The joint paths reach the poses where they say so."""
    reached = forward_kinematics(robot, result.q)
    error = np.abs(reached - T).max(axis=(-1, -2))
    assert np.all(error[result.reachable] < tol)


def test_line_at_process_speed_is_continuous(puma):
    n_poses = round(1.0 / (SPEED * SAMPLE_TIME)) + 1  # poses 0.15 mm apart
    T = feasible_line(n_poses)[None]
    result = solve_path_ik(puma, T)
    assert result.success[0] and result.status[0] is Status.FEASIBLE
    assert result.first_problem[0] == -1 and not result.switch.any()
    assert_follows(puma, result, T)
    steps = np.abs(np.diff(result.q[0], axis=0))
    assert np.all(steps <= puma.v_max * SAMPLE_TIME)
    assert np.all((result.q >= puma.q_min) & (result.q <= puma.q_max))
    margin = np.minimum(result.q[0] - puma.q_min, puma.q_max - result.q[0]).min()
    assert result.margin[0] == pytest.approx(margin)
    assert "follows all" in result.message[0]


def test_default_branch_is_the_ok_one_with_the_largest_margin(puma):
    T = feasible_line(200)[None]
    chosen = solve_path_ik(puma, T)
    forced = [solve_path_ik(puma, T, branch=b) for b in range(8)]
    ok = [f.success[0] for f in forced]
    margins = [f.margin[0] if f.success[0] else -np.inf for f in forced]
    assert any(ok)
    assert chosen.branch[0] == int(np.argmax(margins))
    assert chosen.margin[0] == max(margins)


def test_forced_branch_is_honoured_and_is_that_closed_form_branch(puma):
    T = feasible_line(200)
    closed = solve_ik(puma, T).q
    candidates = np.stack([T, T, T])
    branches = np.array([5, 0, 3])
    result = solve_path_ik(puma, candidates, branch=branches)
    np.testing.assert_array_equal(result.branch, branches)
    for c, b in enumerate(branches):
        assert np.abs(wrapped(result.q[c] - closed[:, b])).max() < 1e-12
    single = solve_path_ik(puma, T[None], branch=6)
    assert single.branch[0] == 6
    assert np.abs(wrapped(single.q[0] - closed[:, 6])).max() < 1e-12


def test_batched_equals_loop_of_single_candidates(puma, rng):
    base = feasible_line(150)
    X = np.zeros((6, 6))
    X[:, :3] = rng.normal(0.0, 0.1, (6, 3))
    X[:, 3:] = rng.normal(0.0, 0.3, (6, 3))
    X[5, :3] = (0.6, 0.0, 0.0)  # pushed out of reach
    T = placement_transform(X)[:, None] @ base[None]
    batched = solve_path_ik(puma, T)
    assert len(set(batched.status)) > 1  # the batch mixes outcomes
    for c in range(len(X)):
        single = solve_path_ik(puma, T[c : c + 1])
        for field in ("q", "branch", "reachable", "switch", "success", "margin", "first_problem"):
            np.testing.assert_array_equal(getattr(batched, field)[c], getattr(single, field)[0])
        assert batched.status[c] == single.status[0]
        assert batched.message[c] == single.message[0]


def wrist_singular_line(robot, n_poses):
    """A line with fixed orientation along which q5 crosses 0 at the middle pose."""
    q_singular = np.array([0.1, -0.5, 0.3, 0.4, 0.0, 0.2])
    T_mid = forward_kinematics(robot, q_singular)
    T = line(T_mid[:3, 3], np.array([0.0, 1.0, 0.2]), T_mid[:3, :3], 0.1, n_poses)
    branch = int(np.argmin(np.abs(wrapped(solve_ik(robot, T_mid).q - q_singular)).max(-1)))
    return T, branch


def test_wrist_singularity_crossing_is_a_branch_switch(puma):
    n_poses = 201
    T, branch = wrist_singular_line(puma, n_poses)
    for b in (branch, branch ^ 1):  # both wrist labels of the singular arm
        result = solve_path_ik(puma, T[None], branch=b)
        assert result.status[0] is Status.BRANCH_SWITCH and not result.success[0]
        flagged = np.flatnonzero(result.switch[0])
        assert flagged.min() >= 99 and flagged.max() <= 101
        assert result.first_problem[0] <= flagged.min()  # the flipped wrist: limits first
        assert (
            f"joint 5 crosses the wrist singularity near pose {flagged.min()}" in result.message[0]
        )
    # On one closed-form label, q5 touches 0 there and q4 turns by about π in one step.
    q = solve_ik(puma, T).q[:, branch]
    assert np.abs(q[99:102, 4]).min() < 0.01
    assert np.abs(wrapped(np.diff(q[:, 3]))).max() > 2.0


def test_elbow_and_shoulder_singularities_are_branch_switches(puma):
    beta = np.arctan2(puma.dh[3, 0], puma.dh[2, 1])
    t = np.linspace(-0.1, 0.1, 101)[:, None]
    q = np.array([0.3, -0.4, -beta, 0.2, 0.9, 0.1]) + t * np.array([0.2, 0.3, 3.0, 0.4, 0.1, 0.2])
    stretched = forward_kinematics(puma, q)  # the elbow angle crosses 0 at t = 0
    tangent = line(
        np.array([0.15, 0.0, 0.3]),
        np.array([0.0, 1.0, 0.0]),
        rpy_matrix(np.array([0.3, 0.5, 0.2])),
        0.2,
        101,
    )  # touches r = 0
    for T, words in ((stretched, "elbow singularity"), (tangent, "shoulder singularity")):
        result = solve_path_ik(puma, T[None])
        assert result.status[0] is Status.BRANCH_SWITCH
        assert words in result.message[0]
        assert 49 <= result.first_problem[0] <= 51


def test_unreachable_pose_is_reported(puma):
    direction = LINE_DIRECTION / np.linalg.norm(LINE_DIRECTION)
    start = LINE_CENTRE - 0.5 * direction  # the feasible line, continued 0.6 m further
    T = line(start + 0.8 * direction, direction, rpy_matrix(LINE_RPY), 1.6, 101)
    reachable = solve_ik(puma, T).reachable
    first_out = int(np.argmin(reachable))
    assert 0 < first_out < 100
    result = solve_path_ik(puma, T[None])
    assert result.status[0] is Status.UNREACHABLE
    np.testing.assert_array_equal(result.reachable[0], reachable)
    assert result.first_problem[0] == first_out
    assert (
        f"pose {first_out} of 101 is out of reach ({(~reachable).sum()} poses in all)"
        in (result.message[0])
    )
    # Unreachable poses hold the last reachable configuration.
    np.testing.assert_array_equal(
        result.q[0, first_out:],
        np.broadcast_to(result.q[0, first_out - 1], result.q[0, first_out:].shape),
    )


def test_position_limits_and_jumps_are_reported(puma):
    T = feasible_line(200)[None]
    limited = [
        b for b in range(8) if solve_path_ik(puma, T, branch=b).status[0] is Status.POSITION_LIMITS
    ]
    assert limited
    result = solve_path_ik(puma, T, branch=limited[0])
    assert result.margin[0] < 0 and not result.success[0]
    assert "leaves [" in result.message[0]
    k = result.first_problem[0]
    outside = (result.q[0, k] < puma.q_min) | (result.q[0, k] > puma.q_max)
    assert outside.any()
    jumpy = solve_path_ik(puma, T, max_step=1e-4)
    assert jumpy.status[0] is Status.BRANCH_SWITCH and "jumps" in jumpy.message[0]
    assert jumpy.first_problem[0] == 1


def test_bad_arguments_raise(puma):
    T = feasible_line(10)[None]
    for kwargs in (
        {"branch": 8},
        {"branch": np.array([1, 2])},
        {"max_step": -1.0},
        {"max_step": np.ones(4)},
        {"method": "magic"},
        {"threads": 0},
    ):
        with pytest.raises(CaseError):
            solve_path_ik(puma, T, **kwargs)
    with pytest.raises(CaseError):
        solve_path_ik(puma, T[0])


@pytest.mark.parametrize("method", ["auto", "numeric"])
def test_ur5_path_is_continuous_on_a_line(ur, method):
    q_mid = np.array([0.3, -1.2, 1.4, -1.6, -1.5, 0.2])
    T_mid = forward_kinematics(ur, q_mid)
    T = line(T_mid[:3, 3], np.array([0.3, 1.0, -0.2]), T_mid[:3, :3], 0.4, 400)[None]
    result = solve_path_ik(ur, T, method=method)
    assert result.method == ("closed_form" if method == "auto" else "numeric")
    assert result.success[0], result.message[0]
    assert_follows(ur, result, T, tol=1e-9)
    assert np.abs(np.diff(result.q[0], axis=0)).max() < 0.02
    forced = solve_path_ik(ur, T, branch=int(result.branch[0]), method=method)
    np.testing.assert_array_equal(forced.q, result.q)
    assert numeric_seeds(ur).shape == (8, 6)


def test_numeric_mode_agrees_with_closed_form(puma):
    T = feasible_line(300)[None]
    closed = solve_path_ik(puma, T, method="closed_form")
    numeric = solve_path_ik(puma, T, method="numeric")
    assert numeric.success[0]
    assert_follows(puma, numeric, T)
    # The numeric branch is one of the closed-form branches along the whole path.
    branches = solve_ik(puma, T[0]).q
    gap = np.abs(wrapped(numeric.q[0][:, None] - branches)).max(axis=(0, 2))
    assert gap.min() < 1e-8
    assert numeric.margin[0] <= closed.margin[0] + 1e-9


def test_numeric_mode_flags_a_singularity_crossing(puma):
    T, _ = wrist_singular_line(puma, 201)
    statuses = {
        solve_path_ik(puma, T[None], branch=b, method="numeric").status[0] for b in range(8)
    }
    assert Status.BRANCH_SWITCH in statuses


def test_seven_joint_arm_plans_numerically_and_continuously():
    """A redundant URDF arm: numeric path IK with joint 3 held along a given profile,
    tracked sample to sample, continuous, joint 3 where the profile puts it."""
    from pathlib import Path

    from trackplan.io.robot_file import load_robot
    from trackplan.robots.describe import robot_info

    robot = load_robot(
        Path(__file__).resolve().parents[1] / "io" / "data" / "tilted7.urdf", assume_limits=True
    )
    q_mid = np.array([0.3, -0.5, 0.8, 0.4, 0.6, -0.3, 0.2])
    T_mid = forward_kinematics(robot, q_mid)
    T = line(T_mid[:3, 3], np.array([0.2, 1.0, -0.3]), T_mid[:3, :3], 0.1, 200)[None]
    free = np.linspace(0.8, 0.9, T.shape[1])[None]  # joint 3 along the path
    result = solve_path_ik(robot, T, free=free)
    assert result.method == "numeric"
    assert result.success[0], result.message[0]
    assert_follows(robot, result, T, tol=1e-9)
    assert np.abs(np.diff(result.q[0], axis=0)).max() < 0.02
    wound = (result.q[0, :, 2] - free[0] + np.pi) % (2 * np.pi) - np.pi
    np.testing.assert_allclose(wound, 0.0, atol=1e-12)
    assert robot_info(robot)["redundancy"]["parameter"] == "joint 3"
    with pytest.raises(CaseError, match="needs its joint 3"):
        solve_path_ik(robot, T)


def test_windings_of_wide_joints_are_enumerated_and_the_widest_margin_kept(puma):
    from trackplan.io.robot_file import builtin_robot

    for name, wide in (("ur5e", [0, 1, 2, 3, 4, 5]), ("kuka_kr6_r700_sixx", [5])):
        robot = builtin_robot(name)
        # q6 = 1 rad: a KUKA A6 (±350°) has a second winding only beyond ±10°.
        q_mid = 0.5 * (robot.q_min + robot.q_max) + np.array([0.3, -0.4, 0.5, 0.2, 0.6, 1.0])
        T_mid = forward_kinematics(robot, q_mid)
        T = line(T_mid[:3, 3], np.array([0.0, 1.0, 0.2]), T_mid[:3, :3], 0.05, 50)[None]
        result = solve_path_ik(robot, T)
        assert result.success[0], result.message[0]
        narrow = [j for j in range(6) if j not in wide]
        assert np.all(result.windings[0, wide] >= 2) and np.all(result.windings[0, narrow] == 1)
        path = result.q[0]
        for j in wide:  # every other winding that fits has no larger margin to the limits

            def margin(values, j=j, robot=robot):
                return min(values.min() - robot.q_min[j], robot.q_max[j] - values.max())

            kept = margin(path[:, j])
            others = [margin(path[:, j] + 2 * np.pi * turns) for turns in (-2, -1, 1, 2)]
            fitting = [m for m in others if m >= 0.0]
            assert len(fitting) == result.windings[0, j] - 1
            assert all(m <= kept for m in fitting)
    branches = solve_path_ik_branches(puma, feasible_line(50)[None])
    assert branches.windings.shape == (1, 8, 6) and branches.windings.max() <= 1


def ur_line(ur, n_poses):
    """Poses along a line the UR5 follows on its branches."""
    T_mid = forward_kinematics(ur, np.array([0.3, -1.2, 1.4, -1.6, -1.5, 0.2]))
    return line(T_mid[:3, 3], np.array([0.3, 1.0, -0.2]), T_mid[:3, :3], 0.4, n_poses)


@pytest.mark.parametrize("robot_name", ["puma", "ur"])
def test_branch_joints_are_the_path_ik_wound_to_a_reference(robot_name, request):
    """branch_joints (one branch solved, no path analysis) gives solve_path_ik's joints on
    that branch, each wound nearest the reference, with unreachable poses held."""
    robot = request.getfixturevalue(robot_name)
    T = feasible_line(400) if robot_name == "puma" else ur_line(robot, 400)
    T[150:160, :3, 3] *= 4.0  # out of reach: held at the pose before
    T[0, :3, 3] *= 4.0  # and before the first reachable one: that one
    shifts = 2 * np.pi * (np.arange(400 * 6).reshape(400, 6) % 5 - 2)
    solved = 0
    for branch in range(8):
        path = solve_path_ik(robot, T[None], branch=branch)
        if not path.reachable.any():
            continue
        solved += 1
        reference = path.q[0] + shifts + 0.3  # other windings, off by less than π
        found = branch_joints(robot, T, branch, reference)
        np.testing.assert_allclose(found, path.q[0] + shifts, rtol=0, atol=1e-12)
    assert solved >= 4


@pytest.mark.parametrize("robot_name", ["puma", "ur"])
def test_branch_joints_along_a_grid_wind_to_its_interpolation(robot_name, request):
    """branch_joints_along (poses by their parts; interpolation, holding and winding in one
    compiled pass) gives branch_joints with numpy.interp's reference, bit for bit: poses
    in any order, some before and after the grid, some out of reach; one rotation for
    all poses as one per pose."""
    robot = request.getfixturevalue(robot_name)
    T = feasible_line(300) if robot_name == "puma" else ur_line(robot, 300)
    T[100:104, :3, 3] *= 4.0
    rng = np.random.default_rng(3)
    s_grid = np.sort(rng.uniform(0.0, 1.0, 40))
    q_grid = rng.uniform(-9.0, 9.0, (40, 6))
    s = rng.uniform(-0.1, 1.1, 300)
    s[:3] = s_grid[[0, 17, -1]]
    reference = np.column_stack([np.interp(s, s_grid, q_grid[:, j]) for j in range(6)])
    R, p = T[:, :3, :3], T[:, :3, 3]
    for branch in (0, 3, 6):
        found = branch_joints_along(robot, R, p, branch, s, s_grid, q_grid)
        np.testing.assert_array_equal(found, branch_joints(robot, T, branch, reference))
        assert np.all(np.abs(found - reference) <= np.pi)
        one = branch_joints_along(robot, R[0], p, branch, s, s_grid, q_grid)  # line: one R
        np.testing.assert_array_equal(one, found)


def test_branch_joints_of_a_numeric_robot_are_its_path_ik():
    from pathlib import Path

    from trackplan.io.robot_file import load_robot

    robot = load_robot(
        Path(__file__).resolve().parents[1] / "io" / "data" / "tilted7.urdf", assume_limits=True
    )
    T_mid = forward_kinematics(robot, np.array([0.3, -0.5, 0.8, 0.4, 0.6, -0.3, 0.2]))
    T = line(T_mid[:3, 3], np.array([0.2, 1.0, -0.3]), T_mid[:3, :3], 0.1, 50)
    free = np.full(len(T), 0.8)  # joint 3 held
    path = solve_path_ik(robot, T[None], branch=0, free=free[None])
    assert path.success[0], path.message[0]
    shift = np.where(np.arange(7) == 2, 0.0, 2 * np.pi)  # the held joint is the profile's
    found = branch_joints(robot, T, 0, path.q[0] - shift, free=free)
    # both are Newton solutions of the poses to 1e-10 (m, rad) from nearby starts
    np.testing.assert_allclose(found, path.q[0] - shift, rtol=0, atol=1e-8)


@pytest.mark.parametrize("robot_name", ["puma", "ur"])
def test_screened_choice_is_the_choice_among_all_eight_branches(robot_name, request, monkeypatch):
    """solve_path_ik analyses the branch with the most room pose by pose first and keeps
    it alone only when no other branch can beat it: the same branch, joints, analysis and
    message as choosing among all eight analysed branches, and the screen's bound is never
    below a usable branch's analysed margin."""
    from trackplan.robots import path_branches, path_ik
    from trackplan.robots._path_kernels import room_bounds
    from trackplan.robots.families import ik_family

    robot = request.getfixturevalue(robot_name)
    base = feasible_line(300) if robot_name == "puma" else ur_line(robot, 300)
    rng = np.random.default_rng(8)
    X = np.column_stack([rng.normal(0.0, 0.08, (24, 3)), rng.normal(0.0, 0.4, (24, 3))])
    T = placement_transform(X)[:, None] @ base[None]
    every_branch = []
    real_all = path_branches.all_branch_paths

    def all_branches(*args):  # type: ignore[no-untyped-def]
        every_branch.append(args)
        return real_all(*args)

    monkeypatch.setattr(path_branches, "all_branch_paths", all_branches)
    short = 0
    for c in range(len(X)):
        every_branch.clear()
        chosen = solve_path_ik(robot, T[c : c + 1])
        short += not every_branch
        every = solve_path_ik_branches(robot, T[c : c + 1])
        b = int(path_ik._choose(every.success, every.first_problem, every.margin)[0])
        assert chosen.branch[0] == b
        np.testing.assert_array_equal(chosen.q[0], every.q[0, b])
        for field in ("reachable", "switch", "success", "margin", "first_problem", "winding"):
            np.testing.assert_array_equal(getattr(chosen, field)[0], getattr(every, field)[0, b])
        full = solve_path_ik(robot, T[c : c + 1], branch=b)
        assert chosen.status == full.status and chosen.message == full.message
        q_all, valid, _ = ik_family(robot).solve_flat(T[c])
        bound = room_bounds(q_all[None], valid[None], robot.q_min, robot.q_max)[0]
        usable = every.success[0]
        assert np.all(bound[usable] >= every.margin[0, usable] - 1e-12)
    assert 0 < short < len(X)  # both ways are exercised


def gathered_and_analysed(q_all, valid, aux, candidates, q_min, q_max, max_step):
    """The oracle of analyse_closed_form: each candidate branch's joints, reach and branch
    quantities gathered by numpy, the wrist reversals found by numpy, then analyse_paths."""
    from trackplan.robots._path_kernels import ELBOW, SHOULDER, WRIST, analyse_paths

    rows = np.arange(len(candidates))[:, None]
    q = q_all[rows, :, candidates]  # (B, K, M, n): the advanced indices' axes first
    reach = valid[rows, :, candidates]
    quantities = aux[rows, :, candidates]  # (B, K, M, 5)
    x, y, z = quantities[..., 2], quantities[..., 3], quantities[..., 4]
    magnitude = np.stack(
        [quantities[..., 0], quantities[..., 1], np.sqrt(x * x + y * y + z * z)], -1
    )
    crossing = np.zeros(reach.shape, dtype=np.int8)
    dot = x[..., 1:] * x[..., :-1] + y[..., 1:] * y[..., :-1] + z[..., 1:] * z[..., :-1]
    crossing[..., 1:][reach[..., 1:] & reach[..., :-1] & (dot <= 0.0)] = WRIST
    kinds = np.array([SHOULDER, ELBOW, WRIST])
    found = analyse_paths(q, reach, magnitude, kinds, crossing, q_min, q_max, max_step)
    return (q, reach, *found)


@pytest.mark.parametrize("seed", range(6))
def test_fused_analysis_is_the_gather_then_analysis(seed):
    """analyse_closed_form gives, bit for bit, what gathering the candidate branches and
    analysing them with analyse_paths gives, on random solutions with missed poses, jumps,
    measures through zero, wrist reversals and paths beyond the limits."""
    from trackplan.robots._path_kernels import N_FLOAT, N_INT, analyse_closed_form

    rng = np.random.default_rng(seed)
    n_cand, n_poses, n = 5, 60, 6
    walk = np.cumsum(rng.normal(0.0, 0.15, (n_cand, n_poses, 8, n)), axis=1)
    walk += rng.uniform(-np.pi, np.pi, (n_cand, 1, 8, n))
    jumps = rng.random((n_cand, n_poses, 8, n)) < 0.01
    walk[jumps] += rng.choice([-1.5, 1.5], jumps.sum())
    q_all = wrapped(walk)
    miss = [0.0, 0.02, 0.3, 1.0][seed % 4]  # share of missed poses
    valid = rng.random((n_cand, n_poses, 8)) >= miss
    valid[0, :, 3] = True  # one branch reaches every pose
    aux = np.cumsum(rng.normal(0.0, 0.2, (n_cand, n_poses, 8, 5)), axis=1)
    aux[..., :2] = np.abs(aux[..., :2] + rng.normal(0.0, 0.5, (n_cand, 1, 8, 2)))
    q_all[~valid] = np.nan
    aux[~valid] = np.nan
    if seed % 2:
        candidates = np.ascontiguousarray(np.broadcast_to(np.arange(8), (n_cand, 8)))
    else:
        candidates = rng.integers(0, 8, (n_cand, 3))
    q_min = np.array([-2.8, -2.0, -1.0, -4.0, -1.9, -8.0])
    q_max = np.array([2.8, 2.0, 1.2, 4.0, 1.9, 8.0])
    max_step = np.full(n, 0.9)
    n_k = candidates.shape[1]
    fused = (
        np.full((n_cand, n_k, n_poses, n), 7.0),
        np.ones((n_cand, n_k, n_poses), dtype=np.bool_),
        np.ones((n_cand, n_k, n_poses), dtype=np.bool_),
        np.full((n_cand, n_k, N_INT), 7, dtype=np.int64),
        np.full((n_cand, n_k, N_FLOAT), 7.0),
        np.full((n_cand, n_k, n), 7, dtype=np.int64),
        np.full((n_cand, n_k, n), 7, dtype=np.int64),
    )  # every entry is to be overwritten
    analyse_closed_form(q_all, valid, aux, candidates, q_min, q_max, max_step, *fused)
    expected = gathered_and_analysed(q_all, valid, aux, candidates, q_min, q_max, max_step)
    for mine, theirs in zip(fused, expected, strict=True):
        np.testing.assert_array_equal(mine, theirs)
    report = expected[3]
    assert (report[..., 2] > 0).any() == (miss > 0.0)  # missed poses
    assert (report[..., 6] > 0).any()  # switches


@pytest.mark.parametrize("robot_name", ["puma", "ur"])
def test_threads_give_the_same_paths(robot_name, request):
    """Sharing the candidates among threads changes no bit of the paths on all branches,
    whatever the number of threads and pieces."""
    from trackplan.robots import path_ik

    robot = request.getfixturevalue(robot_name)
    base = feasible_line(120) if robot_name == "puma" else ur_line(robot, 120)
    rng = np.random.default_rng(3)
    X = np.column_stack([rng.normal(0.0, 0.1, (23, 3)), rng.normal(0.0, 0.5, (23, 3))])
    T = placement_transform(X)[:, None] @ base[None]
    one = path_ik.solve_path_ik_branches(robot, T, threads=1)
    assert one.success.any() and not one.success.all()
    for threads in (2, 3):
        several = path_ik.solve_path_ik_branches(robot, T, threads=threads)
        for field in ("q", "reachable", "switch", "success", "margin", "first_problem"):
            np.testing.assert_array_equal(getattr(several, field), getattr(one, field))
        for field in ("reachable_fraction", "n_switches", "windings", "winding"):
            np.testing.assert_array_equal(getattr(several, field), getattr(one, field))


def test_thread_sharing_pauses_while_it_does_not_pay(monkeypatch):
    """After a shared call below the efficiency that pays, the next calls run on one
    thread, for a pause that doubles while sharing keeps not paying (up to the last) and
    starts again from the first once it pays."""
    from trackplan.robots import thread_sharing

    monkeypatch.setattr(thread_sharing, "path_threads", lambda: 2)
    sharing = thread_sharing.ThreadSharing()
    assert sharing.threads() == 2
    pauses = []
    for _ in range(7):
        sharing.note(0.5 * thread_sharing.EFFICIENT)
        counts = [sharing.threads() for _ in range(2 * thread_sharing.LAST_PAUSE)]
        pauses.append(counts.index(2))
        assert set(counts[: pauses[-1]]) == {1}
    first, last = thread_sharing.FIRST_PAUSE, thread_sharing.LAST_PAUSE
    assert pauses == [min(last, first * 2**i) for i in range(7)]
    assert pauses[-1] == last
    sharing.note(thread_sharing.EFFICIENT)  # paid: no pause, and the next pause is the first
    assert sharing.threads() == 2
    sharing.note(0.0)
    assert [sharing.threads() for _ in range(first + 1)] == [1] * first + [2]


def test_shared_calls_report_their_efficiency_to_the_callers_record(puma, monkeypatch):
    """A call with threads=None on two threads reports its parallel efficiency (in
    (0, 1.2]: the threads' CPU time over threads × wall) to the ThreadSharing its caller
    passes; a call given threads, or given no record, records nothing anywhere."""
    from trackplan.robots import path_ik, thread_sharing

    seen: list[tuple[int, float]] = []

    class Record(thread_sharing.ThreadSharing):
        def threads(self) -> int:
            return 2

        def note(self, efficiency: float) -> None:
            seen.append((id(self), efficiency))

    monkeypatch.setattr(thread_sharing, "path_threads", lambda: 2)
    mine, other = Record(), Record()
    T = np.broadcast_to(feasible_line(200), (12, 200, 4, 4))
    path_ik.solve_path_ik_branches(puma, T, sharing=mine)
    path_ik.solve_path_ik_branches(puma, T, threads=2, sharing=other)  # given: nothing
    path_ik.solve_path_ik_branches(puma, T)  # no record: two threads, nothing kept
    assert len(seen) == 1 and seen[0][0] == id(mine) and 0.0 < seen[0][1] <= 1.2


def test_a_paused_record_runs_the_callers_next_calls_on_one_thread(puma, monkeypatch):
    """The pause belongs to the caller's record: a record in a pause gives its caller one
    thread, while a call with another record (or none) still shares its work."""
    from concurrent.futures import ThreadPoolExecutor

    from trackplan.robots import path_branches, path_ik, thread_sharing

    monkeypatch.setattr(thread_sharing, "path_threads", lambda: 2)
    monkeypatch.setattr(path_branches, "path_threads", lambda: 2)
    pools: list[int] = []
    real_pool = ThreadPoolExecutor

    def counting_pool(workers: int) -> ThreadPoolExecutor:
        pools.append(workers)
        return real_pool(workers)

    monkeypatch.setattr(path_branches, "ThreadPoolExecutor", counting_pool)
    paused, fresh = thread_sharing.ThreadSharing(), thread_sharing.ThreadSharing()
    paused.note(0.0)  # did not pay: the next FIRST_PAUSE calls run on one thread
    T = np.broadcast_to(feasible_line(200), (12, 200, 4, 4))
    path_ik.solve_path_ik_branches(puma, T, sharing=paused)
    assert pools == []
    path_ik.solve_path_ik_branches(puma, T, sharing=fresh)
    path_ik.solve_path_ik_branches(puma, T)
    assert pools == [1, 1]
    assert paused.left == thread_sharing.FIRST_PAUSE - 1
