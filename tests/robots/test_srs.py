"""The S-R-S closed form (arm angle): detection, round trips, ψ sweeps, one branch, oracles."""

from __future__ import annotations

from dataclasses import replace
from functools import cache
from pathlib import Path

import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st

from tests.oracles import oracle
from trackplan.frames import pose_matrix, rpy_matrix
from trackplan.io.robot_file import LIBRARY_DIR, builtin_robot
from trackplan.robots.families.base import branch_bits
from trackplan.robots.families.srs import SRSFamily, srs_from_chain
from trackplan.robots.kinematics import axis_frames, forward_kinematics
from trackplan.robots.model import Robot

SRS_PUBLISHED = {  # d_bs, d_se, d_ew, d_wf (m): the vendor packages' joint origins
    "kuka_iiwa14": (0.360, 0.420, 0.400, 0.126),
    "yaskawa_sia10d": (0.36, 0.36, 0.36, 0.155),
}
N_CONFIGS = 10_000
TOL = 1e-9  # m and rad


def wrapped(angle: np.ndarray) -> np.ndarray:
    """Angles in (−π, π]."""
    return np.pi - np.mod(np.pi - angle, 2 * np.pi)


def srs_chain(rng: np.random.Generator, *, tool: bool = False) -> Robot:
    """A random S-R-S chain: random lengths and overall scale, segments up or down the
    column (arm hanging or folded at q = 0), axes 2, 4, 6 in random horizontal directions,
    axes 1, 3, 5, 7 up or down, joint origins anywhere along their segments, offsets along
    the axes of joints 2, 4, 6 that the next joint takes back, a base shift, and a tool."""
    d_bs, d_se, d_ew, d_wf = rng.uniform(0.1, 0.6, 4) * rng.uniform(0.5, 3.0)
    up = rng.choice([-1.0, 1.0], 4)
    base = np.array([*rng.uniform(-0.3, 0.3, 2), 0.0])
    ez = np.array([0.0, 0.0, 1.0])
    shoulder = base + up[0] * d_bs * ez
    elbow = shoulder + up[1] * d_se * ez
    wrist = elbow + up[2] * d_ew * ez
    flange = wrist + up[3] * d_wf * ez
    f = rng.uniform(0.1, 0.9, 4)
    points = [
        base + f[0] * (shoulder - base),
        shoulder,
        shoulder + f[1] * (elbow - shoulder),
        elbow,
        elbow + f[2] * (wrist - elbow),
        wrist,
        wrist + f[3] * (flange - wrist),
    ]
    axes = np.zeros((7, 3))
    for j in range(7):
        if j % 2 == 0:
            axes[j] = rng.choice([-1.0, 1.0]) * ez
        else:
            phi = rng.uniform(-np.pi, np.pi)
            axes[j] = (np.cos(phi), np.sin(phi), 0.0)
    for j in (1, 3, 5):  # offset along the axis, taken back by the next joint
        shift = rng.uniform(-0.05, 0.05) * axes[j]
        points[j] = points[j] + shift
    origins = np.tile(np.eye(4), (7, 1, 1))
    previous = np.zeros(3)
    for j, point in enumerate(points):
        origins[j, :3, 3] = point - previous
        previous = point
    T_tip = np.eye(4)
    T_tip[:3, 3] = flange - previous
    T_tip[:3, :3] = rpy_matrix(rng.uniform(-np.pi, np.pi, 3))
    n = np.ones(7)
    tool_pose = np.eye(4)
    if tool:
        tool_pose = pose_matrix(rng.uniform(-0.1, 0.2, 3), rpy_matrix(rng.uniform(-1, 1, 3)))
    return Robot(
        name="random-srs",
        origins=origins,
        axes=axes,
        q_min=-np.pi * n,
        q_max=np.pi * n,
        v_max=n,
        a_max=n,
        j_max=n,
        T_tip=T_tip,
        T_flange_tool=tool_pose,
    )


@cache
def library_arm(name: str) -> tuple[Robot, SRSFamily]:
    """A library robot and its S-R-S family, loaded once."""
    robot = builtin_robot(name)
    return robot, family(robot)


def family(robot: Robot) -> SRSFamily:
    params = srs_from_chain(robot)
    assert params is not None
    return SRSFamily(robot, params)


def assert_round_trip(robot: Robot, q: np.ndarray) -> None:
    """FK(q) solved at ψ = arm_angle(q): every branch valid, every branch's FK is the pose
    to 1e-9, and one branch is q (mod 2π) to 1e-9 (all but 1 in 10,000: near a singularity
    the angles are ill-conditioned, to 1e-6 then)."""
    srs = family(robot)
    T = forward_kinematics(robot, q)
    psi = srs.arm_angle(q)
    q_ik, valid, aux = srs.solve_flat(T, free=psi)
    assert valid.all()
    T_back = forward_kinematics(robot, q_ik)
    assert np.abs(T_back - T[:, None]).max() < TOL
    distance = np.abs(wrapped(q_ik - q[:, None])).max(axis=-1).min(axis=-1)
    assert np.mean(distance < TOL) >= 0.9999
    assert distance.max() < 1e-6
    assert np.all(aux[..., :2] >= 0.0)


@pytest.mark.parametrize("name", sorted(SRS_PUBLISHED))
def test_library_arms_are_srs_with_the_published_lengths(name: str) -> None:
    srs = family(builtin_robot(name))
    assert srs.name == "srs" and srs.closed_form and srs.n_branches == 8
    assert srs.redundancy is not None and srs.redundancy.name == "arm angle"
    assert (srs.redundancy.lower, srs.redundancy.upper) == (-np.pi, np.pi)
    p = srs.parameters()
    derived = [p[key] for key in ("d_bs", "d_se", "d_ew", "d_wf")]
    np.testing.assert_allclose(derived, SRS_PUBLISHED[name], atol=1e-12)
    np.testing.assert_allclose(p["offsets"], 0.0, atol=1e-12)
    np.testing.assert_allclose(p["base"], 0.0, atol=1e-12)


@pytest.mark.parametrize("name", sorted(SRS_PUBLISHED))
def test_round_trip_on_random_configurations_in_the_limits(name: str, rng) -> None:
    robot = builtin_robot(name)
    assert_round_trip(robot, rng.uniform(robot.q_min, robot.q_max, (N_CONFIGS, 7)))


def test_random_srs_chains_are_detected_and_round_trip(rng) -> None:
    for k in range(6):
        robot = srs_chain(rng, tool=k % 2 == 1)
        assert_round_trip(robot, rng.uniform(-np.pi, np.pi, (1000, 7)))


def tilted(robot: Robot, joint: int, degrees: float) -> Robot:
    """The robot with one joint axis tilted by ``degrees`` about an axis ⊥ to it."""
    axes = robot.axes.copy()
    other = np.cross(axes[joint], [1.0, 0.0, 0.0])
    if np.linalg.norm(other) < 0.5:
        other = np.cross(axes[joint], [0.0, 1.0, 0.0])
    other /= np.linalg.norm(other)
    angle = np.radians(degrees)
    axes[joint] = np.cos(angle) * axes[joint] + np.sin(angle) * other
    return replace(robot, axes=axes)


def offset(robot: Robot, joint: int, metres: float) -> Robot:
    """The robot with one joint's origin moved by ``metres`` ⊥ to the column and to its
    axis (a lateral offset, as on the Kinova Gen3), the next joint's origin unchanged."""
    origins = robot.origins.copy()
    side = np.cross([0.0, 0.0, 1.0], robot.axes[joint])
    if np.linalg.norm(side) < 0.5:  # a column axis: move it sideways
        side = np.array([1.0, 0.0, 0.0])
    origins[joint, :3, 3] += metres * side / np.linalg.norm(side)
    return replace(robot, origins=origins)


def test_detection_negative() -> None:
    iiwa = builtin_robot("kuka_iiwa14")
    assert srs_from_chain(iiwa) is not None
    for joint in range(7):
        assert srs_from_chain(tilted(iiwa, joint, 1.0)) is None, joint
    for joint in range(1, 7):
        assert srs_from_chain(offset(iiwa, joint, 0.005)) is None, joint
    assert srs_from_chain(builtin_robot("kuka_kr6_r700_sixx")) is None  # six joints, OPW
    # An offset along an axis of joints 2, 4 or 6 that the next joint does not take back
    # moves the rest of the column off the line: not S-R-S either.
    origins = iiwa.origins.copy()
    origins[3, :3, 3] += 0.005 * iiwa.axes[3]
    assert srs_from_chain(replace(iiwa, origins=origins)) is None


def test_arm_angle_sweep_at_fixed_poses(rng) -> None:
    """Every solution over 64 arm angles reproduces the pose and has that arm angle."""
    for name in sorted(SRS_PUBLISHED):
        robot = builtin_robot(name)
        srs = family(robot)
        q = rng.uniform(robot.q_min, robot.q_max, (8, 7))
        T = np.repeat(forward_kinematics(robot, q), 64, axis=0)
        psi = np.tile(np.linspace(-np.pi, np.pi, 64, endpoint=False), 8)
        q_ik, valid, _ = srs.solve_flat(T, free=psi)
        assert valid.all()
        assert np.abs(forward_kinematics(robot, q_ik) - T[:, None]).max() < TOL
        back = srs.arm_angle(q_ik)
        assert np.abs(wrapped(back - psi[:, None])).max() < TOL
        # one arm angle, eight different configurations
        spread = np.abs(wrapped(q_ik[:, :, None] - q_ik[:, None, :])).max(axis=-1)
        assert np.all(spread[:, ~np.eye(8, dtype=bool)] > 1e-6)


def test_arm_angle_is_the_arm_planes_angle_from_the_reference_plane(rng) -> None:
    """Shimizu's definition from the chain's own axis frames: the angle about S→W from the
    vertical plane through S and W to the plane (S, E, W), modulo π (planes)."""
    robot, srs = library_arm("yaskawa_sia10d")  # joints l, u, b sit at S, E, W: no offsets
    q = rng.uniform(robot.q_min, robot.q_max, (500, 7))
    q = q[np.abs(np.sin(q[:, 3])) > 1e-3]  # the arm plane is defined
    frames = axis_frames(robot, q)
    S, E, W = frames[:, 2, :3, 3], frames[:, 4, :3, 3], frames[:, 6, :3, 3]
    u = (W - S) / np.linalg.norm(W - S, axis=-1, keepdims=True)
    n_arm = np.cross(E - S, W - S)
    n_ref = np.cross([0.0, 0.0, 1.0], W - S)
    psi = np.arctan2(np.sum(u * np.cross(n_ref, n_arm), axis=-1), np.sum(n_ref * n_arm, axis=-1))
    assert np.abs(wrapped(2.0 * (srs.arm_angle(q) - psi))).max() < 1e-9
    q[:, 2] = 0.0  # θ3 = 0: the reference arm itself
    assert np.abs(wrapped(2.0 * srs.arm_angle(q))).max() < 1e-9


def test_branch_bits_are_the_signs_of_theta_2_4_6(rng) -> None:
    robot = builtin_robot("yaskawa_sia10d")  # signs (1, 1, 1, -1, -1, -1, -1), no offsets
    srs = family(robot)
    q = rng.uniform(robot.q_min, robot.q_max, (2000, 7))
    q_ik, _, aux = srs.solve_flat(forward_kinematics(robot, q), free=srs.arm_angle(q))
    theta = srs.params.theta(q_ik)
    for branch in range(8):
        bits = np.array(branch_bits(branch))
        negative = theta[:, branch, [1, 3, 5]] < 0
        assert np.all(negative == bits.astype(bool)), branch
    # aux: d_se·|sin θ2|, |sin θ4|, and a wrist vector of norm |sin θ6|
    shoulder = srs.params.d_se * np.abs(np.sin(theta[..., 1]))
    np.testing.assert_allclose(aux[..., 0], shoulder, atol=1e-12)
    np.testing.assert_allclose(aux[..., 1], np.abs(np.sin(theta[..., 3])), atol=1e-12)
    norm = np.linalg.norm(aux[..., 2:], axis=-1)
    np.testing.assert_allclose(norm, np.abs(np.sin(theta[..., 5])), atol=1e-12)
    assert srs.describe_branch(0) == "shoulder + (q2 ≥ 0)/elbow + (q4 ≤ 0)/wrist + (q6 ≤ 0)"
    assert srs.describe_branch(7) == "shoulder − (q2 < 0)/elbow − (q4 > 0)/wrist − (q6 > 0)"


def test_wrist_vector_reverses_across_the_wrist_singularity() -> None:
    robot = builtin_robot("kuka_iiwa14")
    srs = family(robot)
    q = np.tile([0.3, 0.7, -0.4, -1.1, 0.5, 0.0, 0.2], (21, 1))
    q[:, 5] = np.linspace(-0.1, 0.1, 21)  # θ6 through 0
    T = forward_kinematics(robot, q)
    q_ik, valid, aux = srs.solve_branch(T, 0, free=srs.arm_angle(q), with_aux=True)
    assert valid.all()
    wrist = aux[:, 2:]
    assert np.linalg.norm(wrist[10]) < 1e-12
    assert np.all(np.sum(wrist[:9] * wrist[-9:][::-1], axis=-1) < 0.0)  # reversed
    assert np.all(np.sum(wrist[:9] * wrist[1:10], axis=-1) > 0.0)  # continuous on one side
    np.testing.assert_allclose(np.linalg.norm(wrist, axis=-1), np.abs(np.sin(q[:, 5])), atol=1e-12)
    # branch 0 keeps θ6 ≥ 0: the arm's own path is on branch 1 before the crossing
    assert np.all(q_ik[:, 5] >= -1e-12)


def test_one_branch_equals_that_branch_of_all_eight(rng) -> None:
    robot = srs_chain(rng, tool=True)
    srs = family(robot)
    q = rng.uniform(-np.pi, np.pi, (3000, 7))
    T = forward_kinematics(robot, q)
    T[::7, :3, 3] *= 4.0  # some out of reach
    psi = rng.uniform(-np.pi, np.pi, len(q))
    q_all, valid_all, aux_all = srs.solve_flat(T, free=psi)
    assert 0 < valid_all.sum() < valid_all.size
    for branch in range(8):
        q_one, valid, aux = srs.solve_branch(T, branch, free=psi, with_aux=True)
        np.testing.assert_array_equal(valid, valid_all[:, branch])
        assert np.nanmax(np.abs(q_one - q_all[:, branch])) <= 1e-12
        assert np.nanmax(np.abs(aux - aux_all[:, branch])) <= 1e-12
        assert np.isnan(q_one[~valid]).all() and np.isnan(aux[~valid]).all()
    one = srs.solve_branch_parts(T[0, :3, :3], T[:5, :3, 3], 2, free=psi[:5], with_aux=False)
    expected = srs.solve_branch(np.repeat(T[:1], 5, 0), 2, free=psi[:5])[0]
    q_r = one[0]
    keep = ~np.isnan(expected)
    np.testing.assert_allclose(q_r[keep], expected[keep], atol=1e-12)


def test_wind_to_holds_missed_poses_and_winds_the_joints() -> None:
    robot = builtin_robot("kuka_iiwa14")
    srs = family(robot)
    q = np.tile([0.3, 0.7, -0.4, -1.1, 0.5, 0.6, 0.2], (5, 1))
    q[:, 0] = np.linspace(0.0, 0.4, 5)
    T = forward_kinematics(robot, q)
    T[2, :3, 3] *= 5.0  # out of reach
    psi = srs.arm_angle(q)
    reference = q + 2.0 * np.pi * np.array([0, 0, 0, 0, 0, 0, 1])  # joint 7 one turn up
    s = np.arange(5.0)
    q_w, valid, _ = srs.solve_branch_parts(
        T[:, :3, :3], T[:, :3, 3], 0, free=psi, with_aux=False, wind_to=(s, s, reference)
    )
    assert valid.tolist() == [True, True, False, True, True]
    first = [srs.solve_branch(T[:1], b, free=psi[:1])[0] for b in range(8)]
    assert [b for b in range(8) if np.allclose(first[b], q[:1])] == [0]
    np.testing.assert_allclose(q_w[[0, 1, 3, 4]], reference[[0, 1, 3, 4]], atol=TOL)
    np.testing.assert_array_equal(q_w[2], q_w[1])  # held


def test_seed_solutions_in_the_limits(rng) -> None:
    robot = builtin_robot("kuka_iiwa14")
    srs = family(robot)
    q = rng.uniform(robot.q_min, robot.q_max, (200, 7))
    seeds, found = srs.seed_solutions(
        forward_kinematics(robot, q), robot.q_min, robot.q_max, free=srs.arm_angle(q)
    )
    assert seeds.shape == (200, 8, 7) and found[:, 0].all()
    inside = (seeds >= robot.q_min - 1e-12) & (seeds <= robot.q_max + 1e-12)
    assert inside[found].all()
    assert np.any(~found)  # ±120° on joints 2, 4, 6 cut some branches
    distance = np.abs(seeds - q[:, None]).max(axis=-1)
    assert np.all(np.nanmin(distance, axis=1) < 1e-8)  # the configuration itself is a seed


def test_free_is_required_and_broadcast() -> None:
    robot = builtin_robot("kuka_iiwa14")
    srs = family(robot)
    T = forward_kinematics(robot, np.full((3, 7), 0.3))
    with pytest.raises(ValueError, match="arm angle"):
        srs.solve_flat(T)
    _, valid, aux = srs.solve_flat(T, free=np.array([0.4, np.nan, np.inf]))
    assert valid.tolist() == [[True] * 8, [False] * 8, [False] * 8]
    assert np.isnan(aux[1:]).all()
    assert srs.solve_branch(T, 5, free=np.array([0.4, np.nan, -np.inf]))[1].tolist() == [
        True,
        False,
        False,
    ]
    q_scalar = srs.solve_flat(T, free=0.4)[0]
    q_array = srs.solve_flat(T, free=np.full(3, 0.4))[0]
    np.testing.assert_array_equal(q_scalar, q_array)


@pytest.mark.filterwarnings("ignore:Robot.URDF\\(\\) is deprecated:DeprecationWarning")
@pytest.mark.parametrize("name", sorted(SRS_PUBLISHED))
def test_roboticstoolbox_fk_of_the_urdf_agrees(name: str, rng) -> None:
    """roboticstoolbox reads the URDF itself: its FK of our chain and of our IK solutions."""
    rtb = oracle("roboticstoolbox")
    theirs = rtb.Robot.URDF(str(Path(LIBRARY_DIR / f"{name}.urdf").resolve()))
    robot = builtin_robot(name)
    srs = family(robot)
    q = rng.uniform(robot.q_min, robot.q_max, (20, 7))
    T = forward_kinematics(robot, q)
    T_theirs = np.array([theirs.fkine(qk, end="tool0").A for qk in q])
    assert np.abs(T - T_theirs).max() < TOL
    psi = rng.uniform(-np.pi, np.pi, len(q))
    q_ik, valid, _ = srs.solve_flat(T, free=psi)
    assert valid.all()
    T_ik = np.array([[theirs.fkine(qb, end="tool0").A for qb in qk] for qk in q_ik])
    assert np.abs(T_ik - T[:, None]).max() < TOL
    # the S-R-S model's own FK is the chain's (the lengths and the tail)
    p = srs.params
    shift = np.eye(4)
    shift[:2, 3] = p.base
    model = shift @ p.forward(p.theta(q)) @ p.T_tail
    assert np.abs(model - T_theirs).max() < TOL


@settings(max_examples=40, deadline=None, derandomize=True)
@given(
    st.lists(st.floats(-0.95, 0.95), min_size=7, max_size=7),
    st.floats(-np.pi, np.pi),
)
def test_property_every_branch_reproduces_the_pose_at_its_arm_angle(fraction, psi) -> None:
    robot, srs = library_arm("kuka_iiwa14")
    q = np.array(fraction) * robot.q_max
    T = forward_kinematics(robot, q[None])
    wrist = T[0, :3, 3] - srs.params.d_wf * T[0, :3, 2]  # the iiwa's tail is the identity
    # With the wrist centre on axis 1 the reference plane is undefined (module docstring).
    assume(np.hypot(wrist[0], wrist[1]) > 1e-6)
    q_ik, valid, aux = srs.solve_flat(T, free=np.array([psi]))
    assert valid.all()
    assert np.abs(forward_kinematics(robot, q_ik[0]) - T).max() < TOL
    back = srs.arm_angle(q_ik[0])
    sin_6 = np.abs(np.sin(srs.params.theta(q_ik[0])[:, 5]))
    assert np.abs(wrapped(back - psi)).max() < TOL
    np.testing.assert_allclose(np.linalg.norm(aux[0, :, 2:], axis=-1), sin_6, atol=1e-12)
