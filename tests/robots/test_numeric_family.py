"""The numeric family: every branch of a pose, a held joint for 7-joint arms, tracking."""

from __future__ import annotations

import numpy as np
import pytest

from tests.conftest import replace_dh
from trackplan.errors import CaseError
from trackplan.io.robot_file import builtin_robot
from trackplan.robots.families import ik_family
from trackplan.robots.families.numeric import NumericFamily
from trackplan.robots.ik_numeric import solve_ik_numeric, track_poses
from trackplan.robots.kinematics import axis_frames, forward_kinematics
from trackplan.robots.numeric_seeding import N_SOBOL, start_configurations

MATCH = 1e-6
"""rad: a numeric solution is a closed-form one when every joint agrees to this (mod 2π)."""


def circular(a: np.ndarray) -> np.ndarray:
    """Angles folded into (−π, π]."""
    folded: np.ndarray = a - 2.0 * np.pi * np.round(a / (2.0 * np.pi))
    return folded


def random_poses(robot, rng, count):
    """FK of uniform configurations inside the limits (a 2π window for wide joints)."""
    low = np.maximum(robot.q_min, -np.pi)
    high = np.minimum(robot.q_max, np.pi)
    q = rng.uniform(low, high, (count, robot.n_dof))
    return q, forward_kinematics(robot, q)


@pytest.mark.parametrize("name", ["kuka_kr6_r700_sixx", "ur5e"])
def test_finds_every_closed_form_solution_in_the_limits(name):
    robot = builtin_robot(name)
    rng = np.random.default_rng(30)
    _, T = random_poses(robot, rng, 300)
    closed = ik_family(robot)
    assert closed.closed_form
    q_ref, found_ref = closed.seed_solutions(T, robot.q_min, robot.q_max)
    numeric = NumericFamily(robot)  # forced numeric
    q_num, found = numeric.seed_solutions(T, robot.q_min, robot.q_max)
    assert q_num.shape == (300, 8, 6) and found.shape == (300, 8)
    # every numeric solution reaches the pose (the chain's own FK), inside the limits
    solutions = q_num[found]
    back = forward_kinematics(robot, solutions)
    pose_of = np.repeat(np.arange(300), found.sum(axis=1))
    assert np.abs(back - T[pose_of]).max() < 1e-9
    assert np.all((solutions >= robot.q_min) & (solutions <= robot.q_max))
    assert np.all(np.isnan(q_num[~found]))
    # ... and is one of the closed form's (never a wrong one)
    close = np.all(
        np.abs(circular(q_num[:, :, None] - q_ref[:, None, :])) <= MATCH, axis=-1
    )  # (N, 8 numeric, 8 closed)
    matched = np.any(close & found_ref[:, None, :], axis=2)
    assert np.all(matched[found])
    # every closed-form solution in the limits is found on at least 99 % of the poses
    covered = np.any(close & found[:, :, None], axis=1)  # (N, 8 closed)
    complete = np.all(covered | ~found_ref, axis=1)
    assert complete.mean() >= 0.99, complete.mean()
    np.testing.assert_array_equal(found.sum(axis=1)[complete], found_ref.sum(axis=1)[complete])


def test_solutions_come_in_a_fixed_order(ur, rng):
    _, T = random_poses(ur, rng, 20)
    family = NumericFamily(ur)
    q_a, found_a = family.seed_solutions(T, ur.q_min, ur.q_max)
    q_b, found_b = family.seed_solutions(T, ur.q_min, ur.q_max)
    np.testing.assert_array_equal(found_a, found_b)
    np.testing.assert_array_equal(q_a, q_b)
    # the found first; each distinct from the others
    assert np.all(np.diff(found_a.astype(int), axis=1) <= 0)
    for q, found in zip(q_a, found_a, strict=True):
        distinct = q[found]
        gap = np.abs(distinct[:, None] - distinct[None]).max(axis=-1)
        assert np.all(gap[~np.eye(len(distinct), dtype=bool)] > 1e-6)


def signature(robot, q):
    """The documented structural signature 4·s + 2·e + w of solutions q (..., n), in numpy."""
    frames = axis_frames(robot, q)[..., 1:-1, :3, :]  # joint i's frame: origin o, axis z
    z, o = frames[..., 2], frames[..., 3]
    n = robot.n_dof
    w, e = o[..., n - 2, :], (3 if n >= 7 else 2)
    shoulder = np.einsum("...i,...i", z[..., 1, :], np.cross(z[..., 0, :], w - o[..., 0, :]))
    arm = np.cross(o[..., e, :] - o[..., 1, :], w - o[..., e, :])
    elbow = np.einsum("...i,...i", z[..., e, :], arm)
    wrist = np.einsum("...i,...i", z[..., n - 2, :], np.cross(z[..., n - 3, :], z[..., n - 1, :]))
    return 4 * (shoulder < 0) + 2 * (elbow < 0) + (wrist < 0)


@pytest.mark.parametrize("name", ["ur5e", "kinova_gen3"])
def test_solutions_are_ordered_by_signature_then_margin(name, rng):
    robot = builtin_robot(name)
    q, T = random_poses(robot, rng, 30)
    free = q[:, 2] if robot.n_dof == 7 else None
    solutions, found = NumericFamily(robot).seed_solutions(T, robot.q_min, robot.q_max, free=free)
    key = np.where(found, signature(robot, np.nan_to_num(solutions)), 99)
    margin = np.minimum(solutions - robot.q_min, robot.q_max - solutions).min(axis=-1)
    step = np.diff(key, axis=1)
    assert np.all(step >= 0)
    same = (step == 0) & found[:, 1:]
    assert np.all(np.diff(margin, axis=1)[same] <= 1e-12)
    assert len(np.unique(key[found])) >= 4  # several signatures occur


def test_starts_are_deterministic_and_cover_the_limits(ur):
    family = NumericFamily(ur)
    starts = family.starts()
    assert starts.shape == (8 + N_SOBOL, 6)
    np.testing.assert_array_equal(starts, NumericFamily(ur).starts())
    sobol = starts[8:]
    middle = 0.5 * (ur.q_min + ur.q_max)
    assert np.all(np.abs(sobol - middle) <= np.pi)  # the 2π window of a ±2π joint
    wide = start_configurations(starts[:8], -np.ones(6), np.ones(6))[8:]
    assert np.all(np.abs(wide) <= 1.0) and np.ptp(wide, axis=0).min() > 1.5


def seven_joint(ur):
    """The UR with a seventh joint about z at the flange: a redundant arm."""
    pad = np.zeros(1)
    return replace_dh(
        ur,
        d=np.r_[ur.dh[:, 0], 0.05],
        a=np.r_[ur.dh[:, 1], pad],
        alpha=np.r_[ur.dh[:, 2], pad],
        offset=np.r_[ur.dh[:, 3], pad],
        q_min=np.r_[ur.q_min, -np.pi],
        q_max=np.r_[ur.q_max, np.pi],
        v_max=np.r_[ur.v_max, 1.0],
        a_max=np.r_[ur.a_max, 1.0],
        j_max=np.r_[ur.j_max, 1.0],
    )


def test_a_seven_joint_arm_holds_its_redundancy_joint(rng):
    gen3 = builtin_robot("kinova_gen3")
    family = NumericFamily(gen3)
    assert family.redundancy is not None
    assert family.redundancy.name == "joint 3" and family.redundancy.joint == 2
    assert (family.redundancy.lower, family.redundancy.upper) == (gen3.q_min[2], gen3.q_max[2])
    assert family.parameters() == {"free_joint": 3}
    q, T = random_poses(gen3, rng, 40)
    q_num, found = family.seed_solutions(T, gen3.q_min, gen3.q_max, free=q[:, 2])
    # the pose's own configuration is reachable with joint 3 at its value: found (in the
    # limits, moved by the lowest multiple of 2π above q_min)
    own = q + 2 * np.pi * np.ceil((gen3.q_min - q) / (2 * np.pi))
    hit = np.any(found & (np.abs(q_num - own[:, None]).max(axis=-1) < 1e-6), axis=1)
    assert hit.mean() >= 0.95
    solutions = q_num[found]
    pose_of = np.repeat(np.arange(40), found.sum(axis=1))
    assert np.abs(forward_kinematics(gen3, solutions) - T[pose_of]).max() < 1e-9
    np.testing.assert_allclose(circular(solutions[:, 2] - q[pose_of, 2]), 0.0, atol=1e-12)
    # another joint chosen
    other = NumericFamily(gen3, free_joint=4)
    assert other.redundancy is not None and other.redundancy.joint == 4
    q_5, found_5 = other.seed_solutions(T[:5], gen3.q_min, gen3.q_max, free=q[:5, 4])
    np.testing.assert_allclose(
        circular(q_5[found_5][:, 4] - np.repeat(q[:5, 4], found_5.sum(1))), 0, atol=1e-12
    )


def test_free_joint_only_for_seven_joint_arms(ur):
    assert NumericFamily(ur).redundancy is None
    with pytest.raises(CaseError, match="7-joint arms only"):
        NumericFamily(ur, free_joint=2)
    with pytest.raises(CaseError, match="no joint"):
        NumericFamily(seven_joint(ur), free_joint=7)
    T = forward_kinematics(ur, np.zeros((1, 6)))
    with pytest.raises(ValueError, match="free=None"):
        NumericFamily(ur).seed_solutions(T, ur.q_min, ur.q_max, free=np.zeros(1))


@pytest.mark.parametrize("name", ["ur5e", "kinova_gen3"])
def test_tracking_from_a_nearby_reference(name, rng):
    robot = builtin_robot(name)
    q, T = random_poses(robot, rng, 500)
    q_ref = q + rng.uniform(-1e-3, 1e-3, q.shape)
    free = q[:, 2] if robot.n_dof == 7 else None
    solved, ok = track_poses(robot, T[:, :3, :3], T[:, :3, 3], q_ref, free)
    assert ok.mean() > 0.99
    assert np.abs(forward_kinematics(robot, solved[ok]) - T[ok]).max() < 1e-9
    assert np.abs(solved - q)[ok].max() < 0.05  # the reference's solution, not another
    if free is not None:
        np.testing.assert_array_equal(solved[:, 2], free)
    # one rotation (3, 3) for all poses: as that rotation repeated per pose
    R = T[0, :3, :3]
    p = T[0, :3, 3] + rng.uniform(-0.002, 0.002, (20, 3))
    held = None if free is None else free[:20]
    one = track_poses(robot, R, p, np.tile(q[0], (20, 1)), held)
    tiled = track_poses(robot, np.tile(R, (20, 1, 1)), p, np.tile(q[0], (20, 1)), held)
    np.testing.assert_array_equal(one[0], tiled[0])
    assert one[1].all() and tiled[1].all()


def test_tracking_chains_without_a_square_jacobian(ur, rng):
    five = replace_dh(
        ur,
        **dict(zip(("d", "a", "alpha", "offset"), ur.dh[:5].T, strict=True)),
        **{k: getattr(ur, k)[:5] for k in ("q_min", "q_max", "v_max", "a_max", "j_max")},
    )
    for robot in (five, seven_joint(ur)):  # damped Newton only (minimum norm for 7)
        q = rng.uniform(-np.pi, np.pi, (200, robot.n_dof))
        T = forward_kinematics(robot, q)
        solved, ok = track_poses(robot, T[:, :3, :3], T[:, :3, 3], q + 1e-3)
        assert ok.mean() > 0.98
        assert np.abs(forward_kinematics(robot, solved[ok]) - T[ok]).max() < 1e-9


def test_warm_starts_take_two_gauss_newton_steps(ur, rng):
    q, T = random_poses(ur, rng, 400)
    ik = solve_ik_numeric(ur, T, q + rng.uniform(-1e-3, 1e-3, q.shape))
    assert ik.success.mean() > 0.99
    # undamped steps converge quadratically: 1e-3 → 1e-6 → 1e-12
    assert np.median(ik.n_iter) <= 2


def test_tracking_near_the_wrist_singularity_keeps_the_reference_solution():
    ur5e = builtin_robot("ur5e")
    rng = np.random.default_rng(5)
    q = rng.uniform(-np.pi, np.pi, (2000, 6))
    q[:, 4] = rng.uniform(-1e-3, 1e-3, 2000)  # θ5 ≈ 0: the wrist singularity
    T = forward_kinematics(ur5e, q)
    q_ref = q + rng.uniform(-1e-3, 1e-3, q.shape)
    solved, ok = track_poses(ur5e, T[:, :3, :3], T[:, :3, 3], q_ref)
    # undamped steps up to 0.5 rad on the ill-conditioned Jacobian: 98.8 % solved, 0.10 rad
    # away; capped at 0.05 rad (the damped steps take over): 99.4 %, 0.028 rad
    assert ok.mean() > 0.99
    assert np.abs(solved - q)[ok].max() < 0.05


def test_tracking_refuses_wrong_shapes(ur):
    p = np.zeros((3, 3))
    with pytest.raises(CaseError, match="q_ref"):
        track_poses(ur, np.eye(3), p, np.zeros((2, 6)))
    with pytest.raises(CaseError, match="R_base_tool"):
        track_poses(ur, np.tile(np.eye(3), (2, 1, 1)), p, np.zeros((3, 6)))
    with pytest.raises(CaseError, match="p_base_tool"):
        track_poses(ur, np.eye(3), np.zeros(3), np.zeros((3, 6)))
    with pytest.raises(CaseError, match="free"):
        track_poses(ur, np.eye(3), p, np.zeros((3, 6)), np.zeros(2))


def test_kinova_gen3_is_the_published_chain(rng):
    gen3 = builtin_robot("kinova_gen3")
    assert gen3.n_dof == 7
    assert type(ik_family(gen3)).__name__ == "NumericFamily"
    continuous = [0, 2, 4, 6]
    np.testing.assert_allclose(gen3.q_max[continuous], 2 * np.pi)
    np.testing.assert_allclose(gen3.q_max[[1, 3, 5]], [2.24, 2.57, 2.09])
    np.testing.assert_allclose(gen3.v_max, [1.3963] * 4 + [1.2218] * 3)
    # at q = 0 the arm stands straight up: 0.15643 + 0.12838 + 0.21038 + 0.21038 + 0.20843
    # + 0.10593 + 0.10593 + 0.061525 m high (to Kinova's rounding of π/2 as 1.5708), the
    # 5.4 to 6.4 mm offsets adding up to 24.9 mm along −y
    flange = forward_kinematics(gen3, np.zeros(7))
    np.testing.assert_allclose(flange[:3, 3], [0.0, -0.02486, 1.187275], atol=2e-4)
