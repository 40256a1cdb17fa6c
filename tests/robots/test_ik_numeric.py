"""Numerical IK: round trips from nearby seeds, honest flags, broadcasting, other chains."""

from __future__ import annotations

import numpy as np
import pytest

from tests.conftest import replace_dh
from trackplan.errors import CaseError
from trackplan.robots.ik_numeric import solve_ik_numeric
from trackplan.robots.kinematics import forward_kinematics


def rotation_angle(R_a, R_b):
    """Angle of R_a R_bᵀ, rad."""
    trace = np.einsum("...ij,...ij->...", R_a, R_b)
    return np.arccos(np.clip(0.5 * (trace - 1.0), -1.0, 1.0))


@pytest.mark.parametrize("name", ["ur", "puma"])
def test_round_trip_from_seeds_near_the_solution(name, request, rng):
    robot = request.getfixturevalue(name)
    q = rng.uniform(-np.pi, np.pi, (2000, robot.n_dof))
    T = forward_kinematics(robot, q)
    seed = q + rng.normal(0.0, 0.1, q.shape)
    ik = solve_ik_numeric(robot, T, seed)
    assert ik.success.mean() > 0.99
    T_back = forward_kinematics(robot, ik.q)
    position = np.linalg.norm(T_back[..., :3, 3] - T[..., :3, 3], axis=-1)
    # The reported errors are the true ones, and success means within the tolerance.
    np.testing.assert_allclose(ik.position_error, position, atol=1e-13)
    assert np.all(position[ik.success] <= 1e-10)
    assert np.all(ik.orientation_error[ik.success] <= 1e-10)
    assert np.all(rotation_angle(T_back[..., :3, :3], T[..., :3, :3])[ik.success] < 1e-7)
    assert np.median(ik.n_iter) <= 6
    assert np.abs(ik.q - q)[ik.success].max() < 0.5  # stays on the seed's branch


def test_unreachable_pose_is_reported_as_failure(ur, rng):
    T = forward_kinematics(ur, rng.uniform(-np.pi, np.pi, (20, 6)))
    T[:, :3, 3] *= 2.0 / np.linalg.norm(T[:, :3, 3], axis=-1, keepdims=True)  # 2 m: too far
    ik = solve_ik_numeric(ur, T, np.zeros(6))
    assert not ik.success.any()
    assert np.all(ik.position_error > 0.9)
    assert np.all(np.isfinite(ik.q))


def test_broadcasts_poses_against_seeds(ur, rng):
    q = rng.uniform(-np.pi, np.pi, (5, 6))
    T = forward_kinematics(ur, q)
    seeds = q[None] + rng.normal(0.0, 0.05, (3, 1, 6))
    ik = solve_ik_numeric(ur, T, seeds)
    assert ik.q.shape == (3, 5, 6) and ik.success.shape == (3, 5)
    single = solve_ik_numeric(ur, T[4], seeds[2, 4])
    np.testing.assert_array_equal(single.q, ik.q[2, 4])
    with pytest.raises(CaseError):
        solve_ik_numeric(ur, T, np.zeros(5))
    with pytest.raises(CaseError):
        solve_ik_numeric(ur, T, np.zeros((4, 6)))


@pytest.mark.parametrize("n_dof", [5, 7])
def test_other_chain_lengths(ur, rng, n_dof):
    extra = n_dof - 6
    pad = np.zeros(abs(extra))
    if extra > 0:  # a redundant arm: one more joint about z at the flange
        robot = replace_dh(
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
    else:
        columns = dict(zip(("d", "a", "alpha", "offset"), ur.dh[:n_dof].T, strict=True))
        limits = {k: getattr(ur, k)[:n_dof] for k in ("q_min", "q_max", "v_max", "a_max", "j_max")}
        robot = replace_dh(ur, **columns, **limits)
    q = rng.uniform(-np.pi, np.pi, (200, n_dof))
    T = forward_kinematics(robot, q)
    ik = solve_ik_numeric(robot, T, q + rng.normal(0.0, 0.05, q.shape))
    assert ik.success.mean() > 0.98
    assert np.abs(forward_kinematics(robot, ik.q) - T)[ik.success].max() < 1e-9
