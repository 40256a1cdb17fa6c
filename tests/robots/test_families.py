"""Closed-form IK families (OPW, UR): detection, round trips, oracles, edge cases."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest
from numba import njit

from tests.conftest import replace_dh
from tests.oracles import oracle
from trackplan.errors import CaseError
from trackplan.frames import pose_matrix, rpy_matrix
from trackplan.io.robot_file import builtin_names, builtin_robot
from trackplan.robots.families import _kernels as kern
from trackplan.robots.families import ik_family, solve_ik
from trackplan.robots.kinematics import axis_frames, forward_kinematics
from trackplan.robots.model import Robot

N_POSES = 10_000
BUILTINS = tuple(n for n in builtin_names() if ik_family(builtin_robot(n)).closed_form)
OPW_PUBLISHED = {  # a1, a2, b, c1, c2, c3, c4; offsets; sign corrections (opw_kinematics)
    "kuka_kr6_r700_sixx": (
        (0.025, -0.035, 0.0, 0.400, 0.315, 0.365, 0.080),
        (0, -np.pi / 2, 0, 0, 0, 0),
        (-1, 1, 1, -1, 1, -1),
    ),
    "kuka_kr10_r1420": (
        (0.150, -0.020, 0.0, 0.450, 0.610, 0.660, 0.080),
        (0, -np.pi / 2, 0, 0, 0, 0),
        (-1, 1, 1, -1, 1, -1),
    ),
    "abb_irb2400": (
        (0.100, -0.135, 0.0, 0.615, 0.705, 0.755, 0.085),
        (0, 0, -np.pi / 2, 0, 0, 0),
        (1, 1, 1, 1, 1, 1),
    ),
    "abb_irb1600": (
        (0.150, 0.0, 0.0, 0.4865, 0.475, 0.600, 0.065),
        (0, 0, -np.pi / 2, 0, 0, 0),
        (1, 1, 1, 1, 1, 1),
    ),
    "fanuc_m20ia": (
        (0.15, -0.25, 0.0, 0.525, 0.79, 0.835, 0.10),
        (0, 0, -np.pi / 2, 0, 0, np.pi),
        (1, 1, -1, -1, -1, -1),
    ),
}
UR_PUBLISHED = {  # d1, a2, a3, d4, d5, d6 (Universal Robots' DH table)
    "ur5": (0.089159, -0.425, -0.39225, 0.10915, 0.09465, 0.0823),
    "ur5e": (0.1625, -0.425, -0.3922, 0.1333, 0.0997, 0.0996),
    "ur10e": (0.1807, -0.6127, -0.57155, 0.17415, 0.11985, 0.11655),
}


def wrapped(angle):
    """Angles in (−π, π]."""
    return np.pi - np.mod(np.pi - angle, 2 * np.pi)


def assert_round_trip(robot, q, tol=1e-9, q_tol=1e-8, found=1.0):
    """Every valid branch of IK(FK(q)) reproduces the pose, and q is among them."""
    T = forward_kinematics(robot, q)
    ik = solve_ik(robot, T)
    assert ik.valid.any(axis=-1).all()
    valid_q = ik.q[ik.valid]
    assert np.all((valid_q > -np.pi) & (valid_q <= np.pi))
    T_back = forward_kinematics(robot, np.nan_to_num(ik.q))
    error = np.abs(T_back - T[..., None, :, :]).max(axis=(-1, -2))
    assert error[ik.valid].max() < tol
    distance = np.nanmin(np.abs(wrapped(ik.q - q[..., None, :])).max(axis=-1), axis=-1)
    assert np.mean(distance < q_tol) >= found
    return ik


@pytest.mark.parametrize("name", BUILTINS)
def test_round_trip_on_random_reachable_poses(name, rng):
    robot = builtin_robot(name)
    q = rng.uniform(-np.pi, np.pi, (N_POSES, 6))
    ik = assert_round_trip(robot, q, found=0.9999)  # a few land within 1e-8 of a singularity
    assert ik.valid.sum() > 4 * N_POSES  # most poses have several branches


@pytest.mark.parametrize("name", sorted(OPW_PUBLISHED))
def test_opw_parameters_are_derived_from_the_chain(name):
    family = ik_family(builtin_robot(name))
    assert family.name == "opw"
    lengths, _, _ = OPW_PUBLISHED[name]
    derived = [family.parameters()[key] for key in ("a1", "a2", "b", "c1", "c2", "c3", "c4")]
    np.testing.assert_allclose(derived, lengths, atol=1e-12)


@pytest.mark.parametrize("name", sorted(UR_PUBLISHED))
def test_ur_parameters_are_derived_from_the_chain(name):
    family = ik_family(builtin_robot(name))
    assert family.name == "ur"
    derived = [family.parameters()[key] for key in ("d1", "a2", "a3", "d4", "d5", "d6")]
    np.testing.assert_allclose(derived, UR_PUBLISHED[name], atol=1e-12)


@pytest.mark.parametrize("name", sorted(OPW_PUBLISHED))
def test_opw_agrees_with_py_opw_kinematics(name, rng):
    """The same eight solutions as an independent OPW implementation (rs-opw-kinematics)."""
    opw = oracle("py_opw_kinematics")
    from scipy.spatial.transform import RigidTransform

    lengths, offsets, signs = OPW_PUBLISHED[name]
    model = opw.KinematicModel(
        **dict(zip(("a1", "a2", "b", "c1", "c2", "c3", "c4"), lengths, strict=True)),
        offsets=tuple(float(v) for v in offsets),
        flip_axes=tuple(bool(s < 0) for s in signs),
    )
    theirs_robot = opw.Robot(model, degrees=False)
    robot = builtin_robot(name)
    q = rng.uniform(-np.pi, np.pi, (2000, 6))
    T = forward_kinematics(robot, q)
    T_oracle = np.array([theirs_robot.forward(tuple(qk)).as_matrix() for qk in q[:200]])
    assert np.abs(T[:200] - T_oracle).max() < 1e-9  # same flange frame and joint convention
    theirs = wrapped(theirs_robot.reach(RigidTransform.from_matrix(T)).joints)
    ours = solve_ik(robot, T)
    for k in range(len(q)):
        mine = ours.q[k][ours.valid[k]]
        other = theirs[k][~np.isnan(theirs[k]).any(axis=-1)]
        assert len(mine) == len(other)
        gap = np.abs(wrapped(mine[:, None] - other[None])).max(axis=-1)
        # 1e-8 rad: near a stretched elbow both solvers' angles are √ε-sensitive.
        assert gap.min(axis=1).max() < 1e-8 and gap.min(axis=0).max() < 1e-8


def test_puma_branches_match_roboticstoolbox(puma, rng):
    rtb = oracle("roboticstoolbox")
    SE3 = oracle("spatialmath").SE3  # installed with roboticstoolbox
    reference = rtb.models.DH.Puma560()
    reference.links[0].d = 0.0  # our table: no pedestal, d3 = 0.15
    reference.links[2].d = 0.15
    q = rng.uniform(-np.pi, np.pi, (20, 6))
    T = forward_kinematics(puma, q)
    ik = solve_ik(puma, T)
    for k in range(len(q)):
        theirs = np.array(
            [
                # An SE3, not a 4×4 array: roboticstoolbox 1.3 reads only an SE3 here.
                reference.ikine_a(SE3(T[k], check=False), c).q
                for c in ("run", "ruf", "rdn", "rdf", "lun", "luf", "ldn", "ldf")
            ]
        )
        gap = np.abs(wrapped(ik.q[k][:, None] - theirs[None])).max(axis=-1)
        assert gap.min(axis=1).max() < 1e-9 and gap.min(axis=0).max() < 1e-9


def test_tool_is_handled_exactly(rng):
    tool = pose_matrix(np.array([0.02, -0.01, 0.25]), rpy_matrix(np.array([0.3, -0.2, 1.0])))
    for name in ("kuka_kr6_r700_sixx", "ur5e"):
        robot = replace(builtin_robot(name), T_flange_tool=tool)
        assert ik_family(robot).name in ("opw", "ur")
        assert_round_trip(robot, rng.uniform(-np.pi, np.pi, (2000, 6)), found=0.999)


def test_other_puma_geometry_offsets_and_last_link(puma, rng):
    robot = replace_dh(
        puma,
        d=np.array([0.66, 0.05, 0.1, 0.5, 0.0, 0.08]),
        a=np.array([0.0, 0.6, -0.05, 0.0, 0.0, 0.03]),
        alpha=np.array([np.pi / 2, 0.0, -np.pi / 2, np.pi / 2, -np.pi / 2, 0.4]),
        offset=np.array([0.1, -np.pi / 2, 0.3, -0.2, 0.5, 1.0]),
    )
    assert ik_family(robot).name == "opw"
    assert_round_trip(robot, rng.uniform(-np.pi, np.pi, (2000, 6)), found=0.999)


def tilted(robot: Robot, joint: int, degrees: float, towards: int) -> Robot:
    """The robot with one joint axis tilted by ``degrees`` towards base axis ``towards``."""
    axes = robot.axes.copy()
    angle = np.radians(degrees)
    axes[joint] = np.cos(angle) * axes[joint] + np.sin(angle) * np.eye(3)[towards]
    return replace(robot, axes=axes)


def test_family_detection_positive_and_negative(puma, ur):
    for name in BUILTINS:
        assert ik_family(builtin_robot(name)).name in ("opw", "ur")
    assert ik_family(puma).name == "opw" and ik_family(ur).name == "ur"
    kr6 = builtin_robot("kuka_kr6_r700_sixx")  # axes at q = 0: -z, y, y, -x, y, -x
    for joint, towards in ((0, 0), (1, 0), (2, 0), (3, 1), (4, 0), (5, 1)):
        # one axis tilted by 1° out of the OPW structure: neither OPW nor UR
        assert ik_family(tilted(kr6, joint, 1.0, towards)).name == "numeric", joint
    for joint, towards in ((1, 0), (3, 0), (4, 0), (5, 2)):  # axes -y, -y, -z, -y
        assert ik_family(tilted(builtin_robot("ur5e"), joint, 1.0, towards)).name == "numeric"
    # Axis 4 tilted within the arm plane still meets the wrist centre at right angles to
    # axes 3 and 5: still OPW, with other a2, c3 and offsets.
    still_opw = tilted(kr6, 3, 1.0, 2)
    assert ik_family(still_opw).name == "opw"
    assert ik_family(still_opw).parameters()["c3"] != ik_family(kr6).parameters()["c3"]
    offset_wrist = replace_dh(puma, d=np.array([0, 0, 0.15, 0.43, 0.01, 0]))
    assert ik_family(offset_wrist).name == "numeric"  # axes 4, 5, 6 do not meet
    five = replace_dh(
        puma,
        **dict(zip(("d", "a", "alpha", "offset"), puma.dh[:5].T, strict=True)),
        **{k: getattr(puma, k)[:5] for k in ("q_min", "q_max", "v_max", "a_max", "j_max")},
    )
    assert ik_family(five).name == "numeric"
    with pytest.raises(CaseError, match="no closed-form IK"):
        solve_ik(five, np.eye(4))


@pytest.mark.parametrize("name", ["puma560", "kuka_kr6_r700_sixx", "abb_irb2400"])
def test_opw_branch_bits_have_their_geometric_meaning(name, rng):
    """Shoulder: the wrist centre's side of joint 1; elbow: the elbow's side of the
    shoulder–wrist line; wrist: the sign of the OPW θ5, each constant over a branch."""
    robot = builtin_robot(name)
    family = ik_family(robot)
    q = rng.uniform(-np.pi, np.pi, (2000, 6))
    ik = solve_ik(robot, forward_kinematics(robot, q))
    frames = axis_frames(robot, np.nan_to_num(ik.q))
    shoulder, elbow, wrist = frames[..., 2, :3, 3], frames[..., 3, :3, 3], frames[..., 5, :3, 3]
    axis2 = frames[..., 2, :3, 2]
    plane_x = np.cross(axis2, [0.0, 0.0, 1.0])  # along the arm plane, horizontal
    front = np.einsum("...i,...i->...", wrist - frames[..., 1, :3, 3], plane_x)
    side = np.einsum("...i,...i->...", np.cross(wrist - shoulder, elbow - shoulder), axis2)
    theta5 = np.asarray(family.params.signs)[4] * ik.q[..., 4] + family.params.offsets[4]
    for values, flip in ((front, 4), (side, 2), (np.sin(theta5), 1)):
        clear = ik.valid & (np.abs(values) > 1e-9)
        for b in range(8):
            signs = np.unique(np.sign(values[:, b][clear[:, b]]))
            assert len(signs) == 1, (b, flip)  # one side per branch
            both = clear[:, b] & clear[:, b ^ flip]
            assert both.any() and np.all(np.sign(values[both, b ^ flip]) == -signs[0])


def test_any_leading_shape(puma, rng):
    q = rng.uniform(-np.pi, np.pi, (3, 5, 6))
    T = forward_kinematics(puma, q)
    ik = solve_ik(puma, T)
    flat = solve_ik(puma, T.reshape(-1, 4, 4))
    assert ik.q.shape == (3, 5, 8, 6) and ik.valid.shape == (3, 5, 8)
    np.testing.assert_array_equal(ik.q.reshape(-1, 8, 6), flat.q)
    single = solve_ik(puma, T[1, 2])
    assert single.q.shape == (8, 6)
    np.testing.assert_array_equal(single.q, ik.q[1, 2])


@pytest.mark.parametrize("name", ["puma560", "ur5e"])
def test_unreachable_poses_are_invalid(name, rng):
    robot = builtin_robot(name)
    q = rng.uniform(-np.pi, np.pi, (100, 6))
    far = forward_kinematics(robot, q)
    far[:, :3, 3] *= 3.0 / np.linalg.norm(far[:, :3, 3], axis=-1, keepdims=True)
    ik = solve_ik(robot, far)
    assert not ik.valid.any() and not ik.reachable.any()
    assert np.isnan(ik.q).all()


@pytest.mark.parametrize("name", ["puma560", "kuka_kr6_r700_sixx", "fanuc_m20ia", "ur5e"])
def test_one_branch_kernel_is_that_branch_of_the_eight(name, rng):
    """solve_branch runs the all-branch kernel's operations on one arm: the same bits of
    the joints and branch quantities, on reachable, unreachable and wrist-singular poses
    alike."""
    robot = builtin_robot(name)
    q = rng.uniform(-np.pi, np.pi, (2000, 6))
    q[::5, 4] = 0.0  # wrist singular
    T = forward_kinematics(robot, q)
    T[1::7, :3, 3] *= 3.0  # out of reach
    family = ik_family(robot)
    q_all, valid_all, aux_all = family.solve_flat(T)
    assert not valid_all.all() and valid_all.any()
    for branch in range(8):
        q_one, valid_one, aux_one = family.solve_branch(T, branch, with_aux=True)
        np.testing.assert_array_equal(valid_one, valid_all[:, branch])
        np.testing.assert_array_equal(q_one, q_all[:, branch])
        np.testing.assert_array_equal(aux_one, aux_all[:, branch])
        np.testing.assert_array_equal(family.solve_branch(T, branch)[0], q_one)


@pytest.mark.parametrize("name", ["puma560", "kuka_kr6_r700_sixx", "ur5e"])
def test_wrist_singularity_has_a_deterministic_split(name, rng):
    robot = builtin_robot(name)
    family = ik_family(robot)
    p = family.params
    q = rng.uniform(-np.pi, np.pi, (500, 6))
    q[:, 4] = -p.offsets[4] * p.signs[4]  # θ5 = 0: the wrist is singular
    T = forward_kinematics(robot, q)
    ik = solve_ik(robot, T)
    assert (
        np.abs(forward_kinematics(robot, np.nan_to_num(ik.q)) - T[:, None])[ik.valid].max() < 1e-9
    )
    # The arms that keep the input's arm joints are singular (θ5 depends on them only).
    arm = 3 if family.name == "opw" else 1
    original = np.abs(wrapped(ik.q[:, :, :arm] - q[:, None, :arm])).max(-1) < 1e-8
    joint = 3 if family.name == "opw" else 5  # OPW sets q4, UR sets q6
    settled = np.abs(wrapped(ik.q[:, 0::2, joint])) < 1e-12  # wrist 0: 0
    flipped = np.abs(np.abs(wrapped(ik.q[:, 1::2, joint])) - np.pi) < 1e-12  # wrist 1: π
    assert original[:, 0::2].sum() >= len(q)  # at least one such arm per pose
    assert settled[original[:, 0::2]].mean() > 0.9  # round-off keeps most exactly singular
    assert flipped[original[:, 1::2]].mean() > 0.9


def test_stretched_arm_and_shoulder_cylinder_are_reachable(puma, rng):
    q = rng.uniform(-np.pi, np.pi, (100, 6))
    q[:, 2] = -np.arctan2(puma.dh[3, 0], puma.dh[2, 1])  # the arm stretched
    assert_round_trip(puma, q, q_tol=1e-6)  # there the angles are √ε-sensitive
    psi = rng.uniform(-np.pi, np.pi, 100)  # wrist centre on the cylinder of radius d3
    centre = np.stack([0.15 * np.cos(psi), 0.15 * np.sin(psi), rng.uniform(-0.5, 0.5, 100)], -1)
    T = pose_matrix(centre, rpy_matrix(rng.uniform(-np.pi, np.pi, (100, 3))))
    ik = solve_ik(puma, T)
    assert ik.valid.all()
    assert np.abs(forward_kinematics(puma, ik.q) - T[:, None]).max() < 1e-9
    assert np.abs(wrapped(ik.q[:, :4, 0] - ik.q[:, 4:, 0])).max() < 1e-6  # shoulders meet


@njit(cache=True)
def _compiled_atan2(y, x, out):  # pragma: no cover - compiled
    for i in range(y.size):
        out[i] = kern.atan2(y[i], x[i])


def test_compiled_atan2_is_libm_atan2_to_two_ulp(rng):
    """The kernels' arctangent against numpy's (libm's) on random and edge arguments."""
    n = 200_000
    scale = np.exp(rng.uniform(-40.0, 40.0, (2, n)))
    y, x = rng.normal(size=(2, n)) * np.where(rng.random((2, n)) < 0.5, 1.0, scale)
    got = np.empty(n)
    _compiled_atan2(y, x, got)
    expected = np.arctan2(y, x)
    assert (np.abs(got - expected) <= 2 * np.spacing(np.abs(expected))).all()
    assert np.mean(got == expected) > 0.9
    edges = np.array([0.0, -0.0, 1.0, -1.0, 1e-300, -1e-300, 1e300, -1e300, np.nan])
    y, x = (a.ravel().copy() for a in np.meshgrid(edges, edges))
    got = np.empty(y.size)
    _compiled_atan2(y, x, got)
    expected = np.arctan2(y, x)
    np.testing.assert_array_equal(got, expected)  # NaN where NaN
    same = ~np.isnan(expected)
    np.testing.assert_array_equal(np.signbit(got[same]), np.signbit(expected[same]))
