"""The Panda family (joint 7 given): detection, round trips, one branch, oracle, edge cases."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from tests.oracles import oracle
from trackplan.frames import pose_matrix, rpy_matrix
from trackplan.io.robot_file import builtin_robot
from trackplan.robots.families.base import RedundancyParameter
from trackplan.robots.families.panda import PandaFamily, panda_from_chain
from trackplan.robots.kinematics import forward_kinematics
from trackplan.robots.model import Robot

N_POSES = 10_000
TOL = 1e-9
PANDA_ALPHA = (0.0, -np.pi / 2, np.pi / 2, np.pi / 2, -np.pi / 2, np.pi / 2, np.pi / 2)
PANDA_A = (0.0, 0.0, 0.0, 0.0825, -0.0825, 0.0, 0.088)  # franka_arm.xacro, per joint
PANDA_D = (0.333, 0.0, 0.316, 0.0, 0.384, 0.0, 0.0)
FLANGE = 0.107


@pytest.fixture(scope="module")
def panda() -> Robot:
    return builtin_robot("franka_panda")


@pytest.fixture(scope="module")
def family(panda: Robot) -> PandaFamily:
    params = panda_from_chain(panda)
    assert params is not None
    return PandaFamily(panda, params)


def _rx(angle: float) -> np.ndarray:
    c, s = np.cos(angle), np.sin(angle)
    return np.array([[1, 0, 0, 0], [0, c, -s, 0], [0, s, c, 0], [0, 0, 0, 1.0]])


def _shift(x: float = 0.0, y: float = 0.0, z: float = 0.0) -> np.ndarray:
    T = np.eye(4)
    T[:3, 3] = x, y, z
    return T


def modified_dh_chain(
    alpha=PANDA_ALPHA, a=PANDA_A, d=PANDA_D, tip=FLANGE, base=None, like=None
) -> Robot:
    """A chain in Franka's own frames: joint i's origin ``Rx(α_i) Tx(a_i) Tz(d_i)``, every
    axis z, the flange ``tip`` along z7, ``base`` before joint 1, limits of ``like``."""
    rows = zip(alpha, a, d, strict=True)
    origins = np.stack([_rx(al) @ _shift(x=ai, z=di) for al, ai, di in rows])
    if base is not None:
        origins[0] = base @ origins[0]
    limits = like if like is not None else builtin_robot("franka_panda")
    return Robot(
        name="chain",
        origins=origins,
        axes=np.tile([0.0, 0.0, 1.0], (7, 1)),
        q_min=limits.q_min,
        q_max=limits.q_max,
        v_max=limits.v_max,
        a_max=limits.a_max,
        j_max=limits.j_max,
        T_tip=_shift(z=tip),
    )


def wrapped(angle: np.ndarray) -> np.ndarray:
    """Angles in (−π, π]."""
    return np.pi - np.mod(np.pi - angle, 2 * np.pi)


def assert_round_trip(robot: Robot, family: PandaFamily, q: np.ndarray) -> np.ndarray:
    """Every valid branch of IK(FK(q)) with free = q7 reproduces the pose to 1e-9 m (and
    rotation entries), and one of them is q (to 1e-9 rad, modulo 2π). Returns the branch
    that is q, per pose."""
    T = forward_kinematics(robot, q)
    Q, valid, aux = family.solve_flat(T, free=q[:, 6])
    assert valid.any(axis=1).all()
    assert np.all((Q[valid] > -np.pi) & (Q[valid] <= np.pi))
    assert np.isnan(Q[~valid]).all() and np.isnan(aux[~valid]).all()
    back = forward_kinematics(robot, np.where(valid[..., None], Q, 0.0))
    error = np.abs(back - T[:, None]).max(axis=(-1, -2))
    assert error[valid].max() < TOL
    distance = np.where(valid, np.abs(wrapped(Q - q[:, None, :])).max(axis=-1), np.inf)
    assert distance.min(axis=1).max() < TOL
    return distance.argmin(axis=1)


def test_parameters_are_derived_and_equal_the_published(family: PandaFamily):
    p = family.parameters()
    published = dict(d1=0.333, d3=0.316, d5=0.384, a4=0.0825, a5=-0.0825, a7=0.088)
    for key, value in published.items():
        assert p[key] == pytest.approx(value, abs=1e-12), key
    assert p["d_flange"] == pytest.approx(FLANGE, abs=1e-12)
    np.testing.assert_allclose(p["offsets"], 0.0, atol=1e-12)
    assert p["signs"] == [1.0] * 7 and p["base"] == [0.0, 0.0]
    np.testing.assert_allclose(family.params.T_tail, _shift(z=FLANGE), atol=1e-12)
    assert family.name == "panda" and family.closed_form and family.n_branches == 8
    assert family.redundancy == RedundancyParameter("joint 7", -2.8973, 2.8973, joint=6)


def test_round_trip_on_random_configurations_in_the_limits(panda, family, rng):
    q = rng.uniform(panda.q_min, panda.q_max, (N_POSES, 7))
    branch = assert_round_trip(panda, family, q)
    # He & Liu's four (elbow 0) are not all: joint 4 near its upper limit is elbow 1
    assert set(np.unique(branch)) == set(range(8))


def test_franka_frames_shifted_base_and_a_tool_give_the_same_arm(panda, rng):
    """Franka's own link frames (every axis z), a base turned and moved, a flipped axis
    and a tool: other offsets, signs and tails, the same round trips."""
    base = pose_matrix(np.array([0.2, -0.1, 0.05]), rpy_matrix(np.array([0.0, 0.0, 0.7])))
    chain = modified_dh_chain(base=base)
    axes = chain.axes.copy()
    axes[3] = -axes[3]  # joint 4 turned the other way: its limits mirror
    chain = replace(
        chain,
        axes=axes,
        q_min=np.where(np.arange(7) == 3, -panda.q_max, panda.q_min),
        q_max=np.where(np.arange(7) == 3, -panda.q_min, panda.q_max),
        T_flange_tool=pose_matrix(
            np.array([0.01, 0.02, 0.15]), rpy_matrix(np.array([0.3, -0.2, 0.1]))
        ),
    )
    params = panda_from_chain(chain)
    assert params is not None
    assert params.base == pytest.approx((0.2, -0.1), abs=1e-12)
    assert params.d1 == pytest.approx(0.383, abs=1e-12)
    assert params.signs == (1.0, 1.0, 1.0, -1.0, 1.0, 1.0, 1.0)
    assert params.d_flange == pytest.approx(FLANGE, abs=1e-12)
    q = rng.uniform(chain.q_min, chain.q_max, (2000, 7))
    assert_round_trip(chain, PandaFamily(chain, params), q)


def tilted(robot: Robot, joint: int, degrees: float, towards: int) -> Robot:
    """The robot with one joint axis tilted by ``degrees`` towards axis ``towards`` of its
    own frame."""
    axes = robot.axes.copy()
    angle = np.radians(degrees)
    axes[joint] = np.cos(angle) * axes[joint] + np.sin(angle) * np.eye(3)[towards]
    return replace(robot, axes=axes)


def test_an_axis_turned_within_the_structure_is_still_a_panda(panda, rng):
    """Axis 2 turned about axis 1 (still perpendicular to axes 1 and 3, still through the
    shoulder point): a Panda with another joint-1 offset, solved as exactly."""
    turned = tilted(panda, 1, 1.0, 0)
    params = panda_from_chain(turned)
    assert params is not None
    assert params.offsets[0] == pytest.approx(-np.radians(1.0), abs=1e-12)
    q = rng.uniform(panda.q_min, panda.q_max, (1000, 7))
    assert_round_trip(turned, PandaFamily(turned, params), q)


def test_detection_negative(panda, puma):
    iiwa = modified_dh_chain(  # KUKA LBR iiwa 14: S-R-S, no offsets (another family)
        alpha=(0.0, -np.pi / 2, np.pi / 2, np.pi / 2, -np.pi / 2, -np.pi / 2, np.pi / 2),
        a=(0.0,) * 7,
        d=(0.36, 0.0, 0.42, 0.0, 0.4, 0.0, 0.0),
        tip=0.126,
    )
    assert panda_from_chain(iiwa) is None
    # axes at q = 0: z, y, z, -y, z, -y, -z; each tilted by 1° out of the structure
    for joint, towards in ((0, 0), (1, 2), (2, 1), (3, 2), (4, 1), (5, 2), (6, 1)):
        assert panda_from_chain(tilted(panda, joint, 1.0, towards)) is None, joint
    shifted = panda.origins.copy()
    shifted[4] = _shift(y=0.01) @ shifted[4]  # axis 5 off axis 4's plane: d4 ≠ 0
    assert panda_from_chain(replace(panda, origins=shifted)) is None
    assert panda_from_chain(puma) is None  # six joints


def test_one_branch_is_that_branch_of_the_eight(panda, family, rng):
    q = rng.uniform(panda.q_min, panda.q_max, (3000, 7))
    T = forward_kinematics(panda, q)
    free = q[:, 6] + rng.normal(0.0, 0.3, len(q))  # some poses unreachable on some branches
    Q, valid, aux = family.solve_flat(T, free=free)
    assert not valid.all() and valid.any()
    for branch in range(8):
        q1, v1, a1 = family.solve_branch(T, branch, free=free, with_aux=True)
        np.testing.assert_array_equal(v1, valid[:, branch])
        np.testing.assert_array_equal(q1, Q[:, branch])  # NaN where not valid, as there
        np.testing.assert_array_equal(a1, aux[:, branch])
    # one rotation for all poses (a tool held in one orientation)
    R = T[0, :3, :3]
    T_same = T.copy()
    T_same[:, :3, :3] = R
    Q2, valid2, _ = family.solve_flat(T_same, free=free)
    q1, v1, _ = family.solve_branch_parts(R, T[:, :3, 3], 5, free=free, with_aux=False)
    np.testing.assert_array_equal(v1, valid2[:, 5])
    np.testing.assert_array_equal(q1, Q2[:, 5])


def test_one_branch_holds_and_winds_near_a_reference(panda, family, rng):
    q = rng.uniform(panda.q_min, panda.q_max, (50, 7))
    T = forward_kinematics(panda, q)
    T[10:12, :3, 3] = [2.0, 0.0, 0.5]  # out of reach: held at pose 9
    free = q[:, 6].copy()
    q_b, valid_b, _ = family.solve_branch(T, 0, free=free)
    np.testing.assert_array_equal(np.flatnonzero(~valid_b), [10, 11])
    s = np.linspace(0.0, 1.0, 50)
    grid = q_b[0] + 2 * np.pi * np.array([1, -1, 0, 1, 0, 1, 0])  # whole turns away
    wound, valid, _ = family.solve_branch_parts(
        T[:, :3, :3],
        T[:, :3, 3],
        0,
        free=free,
        with_aux=False,
        wind_to=(s, np.array([0.0, 1.0]), np.stack([grid, grid])),
    )
    np.testing.assert_array_equal(valid, valid_b)
    reached = np.flatnonzero(valid_b)
    assert np.all(np.isfinite(wound))
    np.testing.assert_allclose(wrapped(wound[reached] - q_b[reached]), 0.0, atol=1e-12)
    assert np.abs(wound[reached[0]] - grid).max() < np.pi + 1e-9
    np.testing.assert_allclose(wound[10], wound[9], atol=1e-12)  # held, wound alike
    np.testing.assert_allclose(wound[11], wound[9], atol=1e-12)


def test_branch_quantities_have_their_geometric_meaning(panda, family, rng):
    """Shoulder: |sin θ2|; elbow: |sin(θ4 − φ4)| (zero stretched); wrist vector: its norm
    is |sin δ| ρ / L, zero where the two θ6 of a pose meet; elbow 0 has θ4 < φ4."""
    q = rng.uniform(panda.q_min, panda.q_max, (2000, 7))
    Q, valid, aux = family.solve_flat(forward_kinematics(panda, q), free=q[:, 6])
    np.testing.assert_allclose(aux[..., 0][valid], np.abs(np.sin(Q[..., 1][valid])), atol=1e-12)
    p = family.params
    phi4 = np.arctan2(2 * (p.d3 * p.a5 - p.a4 * p.d5), 2 * (p.a4 * p.a5 + p.d3 * p.d5))
    offset4 = wrapped(Q[..., 3] - phi4)
    np.testing.assert_allclose(aux[..., 1][valid], np.abs(np.sin(offset4[valid])), atol=1e-9)
    assert np.all(offset4[:, [0, 1, 4, 5]][valid[:, [0, 1, 4, 5]]] <= 1e-12)  # elbow 0
    assert np.all(offset4[:, [2, 3, 6, 7]][valid[:, [2, 3, 6, 7]]] >= -1e-12)
    # the two θ6 of one (shoulder, elbow) differ by 2δ, and the wrist norm is ρ |sin δ| / L
    both = valid[:, 0] & valid[:, 1]
    half = 0.5 * wrapped(Q[both, 0, 5] - Q[both, 1, 5])
    norm = np.linalg.norm(aux[both, 0, 2:], axis=-1)
    assert np.all((norm < 1e-12) == (np.abs(np.sin(half)) < 1e-12))
    assert np.corrcoef(norm, np.abs(np.sin(half)))[0, 1] > 0.5
    np.testing.assert_array_equal(aux[:, 0, 2:], aux[:, 5, 2:])  # one per elbow


def test_wrist_vector_reverses_where_a_path_crosses_axis_5_through_the_shoulder(panda, family):
    """θ4 = 0 puts axis 5 through the shoulder point (a4 = −a5): the two θ6 meet there and a
    joint path through it goes from one wrist bit to the other, exactly where the wrist
    vector reverses (once) and its norm is least."""
    q = np.tile([0.3, 0.5, -0.4, 0.0, 0.7, 1.1, 0.2], (40, 1))
    q[:, 3] = np.linspace(-0.1, 0.1, 40)
    Q, valid, aux = family.solve_flat(forward_kinematics(panda, q), free=q[:, 6])
    distance = np.where(valid, np.abs(wrapped(Q - q[:, None])).max(axis=-1), np.inf)
    branch = distance.argmin(axis=1)
    assert distance.min(axis=1).max() < TOL
    np.testing.assert_array_equal(branch, [2] * 20 + [3] * 20)  # elbow 1, wrist 0 → 1
    wrist = aux[np.arange(40), branch, 2:]
    dot = np.sum(wrist[1:] * wrist[:-1], axis=1)
    np.testing.assert_array_equal(np.flatnonzero(dot <= 0.0), [19])
    norm = np.linalg.norm(wrist, axis=1)
    assert set(np.argsort(norm)[:2]) == {19, 20}


def test_stretched_arm_is_reached_far_and_nan_poses_are_not(panda, family):
    q = np.array([[0.3, 0.4, -0.2, -0.467, 0.1, 1.2, 0.5]])  # θ4 ≈ φ4: nearly stretched
    Q, valid, aux = family.solve_flat(forward_kinematics(panda, q), free=q[:, 6])
    assert valid[0].any() and aux[0, valid[0], 1].max() < 1e-3
    far = pose_matrix(np.array([2.0, 0.0, 0.5]), np.eye(3))[None]
    Q, valid, aux = family.solve_flat(far, free=np.zeros(1))
    assert not valid.any() and np.isnan(Q).all() and np.isnan(aux).all()
    nan_pose = forward_kinematics(panda, q)
    nan_pose[0, 0, 3] = np.nan
    for T, free in ((nan_pose, q[:, 6]), (forward_kinematics(panda, q), np.array([np.nan]))):
        Q, valid, aux = family.solve_flat(T, free=free)
        assert not valid.any() and np.isnan(Q).all() and np.isnan(aux).all()
        q_b, valid_b, _ = family.solve_branch(T, 2, free=free)
        assert not valid_b.any() and np.isnan(q_b).all()
    with pytest.raises(ValueError, match="joint 7"):
        family.solve_flat(far)


def test_seed_solutions_are_in_the_limits_and_include_the_configuration(panda, family, rng):
    q = rng.uniform(panda.q_min, panda.q_max, (200, 7))
    seeds, found = family.seed_solutions(
        forward_kinematics(panda, q), panda.q_min, panda.q_max, free=q[:, 6]
    )
    assert found[:, 0].all()
    inside = (seeds >= panda.q_min - 1e-12) & (seeds <= panda.q_max + 1e-12)
    assert inside.all(axis=-1)[found].all()
    distance = np.where(found, np.abs(seeds - q[:, None]).max(axis=-1), np.inf)
    assert distance.min(axis=1).max() < TOL


def test_forward_kinematics_agree_with_roboticstoolbox(panda, rng):
    """rtb's DH Panda puts the flange (0.107) into joint 7's d and the hand in its tool:
    with its tool removed, its end frame is our tool0 (Franka's panda_link8)."""
    rtb = oracle("roboticstoolbox")
    reference = rtb.models.DH.Panda()
    q = rng.uniform(panda.q_min, panda.q_max, (50, 7))
    tool = np.linalg.inv(np.asarray(reference.tool.A))
    expected = np.stack([np.asarray(reference.fkine(qk).A) @ tool for qk in q])
    assert np.abs(forward_kinematics(panda, q) - expected).max() < TOL


@settings(max_examples=40, deadline=None)
@given(
    q=st.lists(st.floats(0.0, 1.0), min_size=7, max_size=7),
    tool=st.lists(st.floats(-0.2, 0.2), min_size=6, max_size=6),
)
def test_round_trip_with_any_tool(q, tool):
    robot = builtin_robot("franka_panda")
    tool_pose = pose_matrix(np.array(tool[:3]), rpy_matrix(5 * np.array(tool[3:])))
    robot = replace(robot, T_flange_tool=tool_pose)
    params = panda_from_chain(robot)
    assert params is not None
    config = robot.q_min + np.array(q) * (robot.q_max - robot.q_min)
    family = PandaFamily(robot, params)
    if abs(np.sin(config[1])) > 1e-6:
        assert_round_trip(robot, family, config[None])
        return
    # q2 = 0: axes 1 and 3 in line; q1 is put at 0 and q3 takes q1 + q3 (same pose)
    T = forward_kinematics(robot, config[None])
    Q, valid, _ = family.solve_flat(T, free=config[None, 6])
    assert valid[0].any()
    for k in np.flatnonzero(valid[0]):  # every valid branch reaches the pose
        assert np.abs(forward_kinematics(robot, Q[0, k]) - T[0]).max() < TOL
    # one of them is the configuration with q1 put at 0 (not always branch 0: with joints 4
    # and 6 at their lower limits it is another one)
    expected = np.array([0.0, config[1], config[0] + config[2], *config[3:]])
    gaps = np.abs(wrapped(Q[0, valid[0]] - expected)).max(axis=-1)
    assert gaps.min() < TOL
