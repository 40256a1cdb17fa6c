"""Resolved-rate IK (paper Eq. 19–27): tracking, drift, the improved mode, batching."""

from __future__ import annotations

import numpy as np
import pytest

from trackplan.errors import CaseError
from trackplan.frames import pose_matrix
from trackplan.robots.kinematics import forward_kinematics
from trackplan.robots.path_ik import solve_path_ik
from trackplan.robots.resolved_rate import solve_path_resolved_rate


def line_through(robot, q_mid, direction, length, n_poses):
    """Poses on a line through FK(q_mid) with its orientation, shape (n_poses, 4, 4)."""
    T_mid = forward_kinematics(robot, q_mid)
    s = np.linspace(-0.5 * length, 0.5 * length, n_poses)[:, None]
    return pose_matrix(T_mid[:3, 3] + s * direction / np.linalg.norm(direction), T_mid[:3, :3])


@pytest.fixture
def puma_line(puma):
    """A 0.4 m line at 0.2 mm spacing and its closed-form joint path."""
    T = line_through(
        puma, np.array([0.2, -0.6, 0.4, 0.3, 0.8, 0.1]), np.array([0, 1.0, 0.3]), 0.4, 2001
    )
    reference = solve_path_ik(puma, T[None])
    assert reference.success[0]
    return T, reference.q[0]


def tool_error(robot, q, T):
    """Largest distance of the tool point from its target, m."""
    return np.linalg.norm(forward_kinematics(robot, q)[..., :3, 3] - T[..., :3, 3], axis=-1).max()


def test_paper_mode_tracks_a_line(puma, puma_line):
    T, reference = puma_line
    q = solve_path_resolved_rate(puma, T, reference[0])
    assert q.shape == reference.shape
    assert np.abs(q - reference).max() < 1e-5
    assert tool_error(puma, q, T) < 1e-6


def test_compensation_removes_the_drift(puma, puma_line):
    T, reference = puma_line
    paper = solve_path_resolved_rate(puma, T, reference[0], mode="paper")
    drifting = solve_path_resolved_rate(puma, T, reference[0], mode="uncompensated")
    paper_error = tool_error(puma, paper, T)
    drift = tool_error(puma, drifting, T)
    assert drift > 100 * paper_error
    # Without compensation the error grows along the path (about linearly).
    along = np.linalg.norm(forward_kinematics(puma, drifting)[:, :3, 3] - T[:, :3, 3], axis=-1)
    assert along[-1] > 5 * along[len(along) // 10]


def test_newton_mode_is_exact(puma, ur, puma_line):
    T, reference = puma_line
    q = solve_path_resolved_rate(puma, T, reference[0] + 1e-3, mode="newton")
    assert np.abs(q - reference).max() < 1e-9
    assert np.abs(forward_kinematics(puma, q) - T).max() < 1e-10
    T_ur = line_through(
        ur, np.array([0.3, -1.2, 1.4, -1.6, -1.5, 0.2]), np.array([1.0, 0.2, 0]), 0.3, 500
    )
    q_ur = solve_path_resolved_rate(
        ur, T_ur, np.array([0.3, -1.2, 1.4, -1.6, -1.5, 0.2]), mode="newton"
    )
    assert np.abs(forward_kinematics(ur, q_ur) - T_ur).max() < 1e-10


def test_batched_over_candidates_equals_loop(puma, puma_line, rng):
    T, reference = puma_line
    T_batch = np.stack([T[:500], T[500:1000], T[1000:1500]])
    q0 = reference[[0, 500, 1000]] + rng.normal(0, 1e-4, (3, 6))
    for mode in ("paper", "uncompensated", "newton"):
        batched = solve_path_resolved_rate(puma, T_batch, q0, mode=mode)
        assert batched.shape == (3, 500, 6)
        for c in range(3):
            single = solve_path_resolved_rate(puma, T_batch[c], q0[c], mode=mode)
            np.testing.assert_array_equal(batched[c], single)


def test_bad_arguments_raise(puma, puma_line):
    T, reference = puma_line
    with pytest.raises(CaseError):
        solve_path_resolved_rate(puma, T, reference[0], mode="fast")
    with pytest.raises(CaseError):
        solve_path_resolved_rate(puma, T, reference[0, :5])
    with pytest.raises(CaseError):
        solve_path_resolved_rate(puma, T[0], reference[0])
