"""Closed-form IK of the PUMA560 family: round trips, branches, oracle, edge cases."""

from __future__ import annotations

import warnings
from dataclasses import replace

import numpy as np
import pytest

from trackplan.errors import CaseError
from trackplan.frames import pose_matrix, rpy_matrix
from trackplan.robots.ik_closed_form import (
    branch_bits,
    describe_branch,
    has_closed_form,
    solve_ik_closed_form,
)
from trackplan.robots.kinematics import forward_kinematics, joint_frames

N_POSES = 10_000


def wrapped(angle):
    """Angles in (−π, π]."""
    return np.pi - np.mod(np.pi - angle, 2 * np.pi)


def assert_round_trip(robot, q, tol=1e-10, q_tol=1e-8):
    """Every valid branch of IK(FK(q)) reproduces the pose, and q is one of them."""
    T = forward_kinematics(robot, q)
    ik = solve_ik_closed_form(robot, T)
    assert ik.valid.all()
    assert np.all((ik.q > -np.pi) & (ik.q <= np.pi))
    T_back = forward_kinematics(robot, ik.q)
    assert np.abs(T_back - T[..., None, :, :]).max() < tol
    distance = np.abs(wrapped(ik.q - q[..., None, :])).max(axis=-1).min(axis=-1)
    assert distance.max() < q_tol
    return ik


def test_round_trip_on_random_poses(puma, rng):
    q = rng.uniform(-np.pi, np.pi, (N_POSES, 6))
    assert_round_trip(puma, q)


def test_round_trip_for_other_link_lengths_offsets_tool_and_last_link(puma, rng):
    tool = pose_matrix(np.array([0.02, -0.01, 0.12]), rpy_matrix(np.array([0.3, -0.2, 1.0])))
    robot = replace(
        puma,
        d=np.array([0.66, 0.05, 0.1, 0.5, 0.0, 0.08]),
        a=np.array([0.0, 0.6, -0.05, 0.0, 0.0, 0.03]),
        alpha=np.array([np.pi / 2, 0.0, -np.pi / 2, np.pi / 2, -np.pi / 2, 0.4]),
        offset=np.array([0.1, -np.pi / 2, 0.3, -0.2, 0.5, 1.0]),
        T_flange_tool=tool,
    )
    assert has_closed_form(robot)
    assert_round_trip(robot, rng.uniform(-np.pi, np.pi, (2000, 6)))


def test_has_closed_form_says_which_structures(puma, ur):
    assert has_closed_form(puma)
    assert not has_closed_form(ur)
    assert not has_closed_form(replace(puma, d=np.array([0, 0, 0.15, 0.43, 0.01, 0])))
    alpha = puma.alpha.copy()
    alpha[3] = -alpha[3]
    assert not has_closed_form(replace(puma, alpha=alpha))
    with pytest.raises(CaseError, match="no closed-form IK"):
        solve_ik_closed_form(ur, np.eye(4))


def test_branch_bits_have_their_geometric_meaning(puma, rng):
    q = rng.uniform(-np.pi, np.pi, (2000, 6))
    ik = solve_ik_closed_form(puma, forward_kinematics(puma, q))
    frames = joint_frames(puma, ik.q)
    shoulder, elbow, wrist = frames[..., 1, :3, 3], frames[..., 2, :3, 3], frames[..., 5, :3, 3]
    x1 = frames[..., 1, :3, 0]  # points along the arm plane's horizontal
    z1 = frames[..., 1, :3, 2]
    in_front = np.einsum("...i,...i->...", wrist - shoulder, x1) >= 0
    # Elbow above the shoulder–wrist line within the arm plane (normal ±z1).
    side = np.einsum("...i,...i->...", np.cross(wrist - shoulder, elbow - shoulder), z1)
    up = side * np.where(in_front, 1.0, -1.0) > 0
    for b in range(8):
        s, e, w = branch_bits(b)
        assert np.all(in_front[:, b] == (s == 0))
        assert np.all((ik.q[:, b, 4] >= 0) == (w == 0))
        assert np.all(up[:, b] == (e == 0)), describe_branch(b)


def test_branches_match_roboticstoolbox_configurations(puma, rng):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        import roboticstoolbox as rtb
    oracle = rtb.models.DH.Puma560()
    oracle.links[0].d = 0.0  # our table: no pedestal, d3 = 0.15
    oracle.links[2].d = 0.15
    letters = {0: "run", 1: "ruf", 2: "rdn", 3: "rdf", 4: "lun", 5: "luf", 6: "ldn", 7: "ldf"}
    # rtb's 'n' (not flipped) wrist is q5 ≤ 0 for this table: our wrist bit 1.
    letters = {b: cfg[:2] + ("f" if b % 2 == 0 else "n") for b, cfg in letters.items()}
    q = rng.uniform(-np.pi, np.pi, (20, 6))
    T = forward_kinematics(puma, q)
    ik = solve_ik_closed_form(puma, T)
    for b, config in letters.items():
        for k in range(len(q)):
            theirs = oracle.ikine_a(T[k], config).q
            assert np.abs(wrapped(ik.q[k, b] - theirs)).max() < 1e-9, (b, config)


def test_any_leading_shape(puma, rng):
    q = rng.uniform(-np.pi, np.pi, (3, 5, 6))
    T = forward_kinematics(puma, q)
    ik = solve_ik_closed_form(puma, T)
    flat = solve_ik_closed_form(puma, T.reshape(-1, 4, 4))
    assert ik.q.shape == (3, 5, 8, 6) and ik.valid.shape == (3, 5, 8)
    np.testing.assert_array_equal(ik.q.reshape(-1, 8, 6), flat.q)
    single = solve_ik_closed_form(puma, T[1, 2])
    assert single.q.shape == (8, 6)
    np.testing.assert_array_equal(single.q, ik.q[1, 2])


def test_unreachable_poses_are_invalid(puma, rng):
    q = rng.uniform(-np.pi, np.pi, (100, 6))
    T = forward_kinematics(puma, q)
    far = T.copy()
    far[:, :3, 3] *= 3.0 / np.linalg.norm(far[:, :3, 3], axis=-1, keepdims=True)
    inside_shoulder = T.copy()
    inside_shoulder[:, :3, 3] = (0.05, 0.02, 0.3)  # closer to joint 1's axis than d3
    for bad in (far, inside_shoulder):
        ik = solve_ik_closed_form(puma, bad)
        assert not ik.valid.any() and not ik.reachable.any()
        assert np.isnan(ik.q).all()


def test_wrist_singularity_has_a_deterministic_split(puma, rng):
    q = rng.uniform(-np.pi, np.pi, (500, 6))
    q[:, 4] = 0.0
    T = forward_kinematics(puma, q)
    ik = solve_ik_closed_form(puma, T)
    assert np.abs(forward_kinematics(puma, ik.q) - T[:, None]).max() < 1e-10
    original = np.abs(wrapped(ik.q[:, :, :3] - q[:, None, :3])).max(-1) < 1e-8
    singular = original & (np.abs(ik.q[:, :, 4]) <= 1e-12)
    assert singular.mean() > 0.9 * original.mean()  # round-off keeps most exactly singular
    q4 = ik.q[:, :, 3]
    assert np.all(q4[:, 0::2][singular[:, 0::2]] == 0.0)  # wrist 0: q4 = 0
    assert np.all(np.abs(q4[:, 1::2][singular[:, 1::2]] - np.pi) < 1e-15)  # wrist 1: q4 = π
    # Joint 6 takes the whole rotation q4 + q6 of the input on wrist 0.
    rows, branches = np.nonzero(singular[:, 0::2])
    q6 = ik.q[rows, 2 * branches, 5]
    assert np.abs(wrapped(q6 - q[rows, 3] - q[rows, 5])).max() < 1e-8


def test_stretched_arm_and_shoulder_cylinder_are_reachable(puma, rng):
    q = rng.uniform(-np.pi, np.pi, (100, 6))
    q[:, 2] = -np.arctan2(puma.d[3], puma.a[2])  # sin(θ3 + β) = 0: stretched
    # At the boundary the angles are √ε-sensitive, the poses still exact.
    assert_round_trip(puma, q, q_tol=1e-6)
    # Wrist centre (= tool point, d6 = 0) on the cylinder of radius d3 about joint 1: r = 0.
    psi = rng.uniform(-np.pi, np.pi, 100)
    centre = np.stack([0.15 * np.cos(psi), 0.15 * np.sin(psi), rng.uniform(-0.5, 0.5, 100)], -1)
    T = pose_matrix(centre, rpy_matrix(rng.uniform(-np.pi, np.pi, (100, 3))))
    ik = solve_ik_closed_form(puma, T)
    assert ik.valid.all()
    assert np.abs(forward_kinematics(puma, ik.q) - T[:, None]).max() < 1e-9
    assert np.abs(wrapped(ik.q[:, :4, 0] - ik.q[:, 4:, 0])).max() < 1e-6  # shoulders meet
