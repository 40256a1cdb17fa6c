"""Geometry behind the plots: nominal polyline, distances, frames, path frames."""

from __future__ import annotations

import numpy as np
import pytest

from trackplan.frames import placement_transform
from trackplan.report.scene import (
    chain_points,
    equal_limits,
    frame_indices,
    nominal_polyline,
    path_points,
    sphere_wireframe,
    tracking_error,
    transform_points,
    triad_lines,
)
from trackplan.robots.kinematics import forward_kinematics


def test_nominal_polyline_is_the_user_path_densely_sampled(corner):
    points = nominal_polyline(corner)
    assert np.max(np.linalg.norm(np.diff(points, axis=0), axis=1)) <= 1e-3 + 1e-12
    # the sharp corner is kept: the corner vertex is one of the points
    assert np.min(np.linalg.norm(points - np.array([0.5, 0.0, 0.0]), axis=1)) < 1e-12
    np.testing.assert_allclose(points[0], corner.start)


def test_path_points_are_the_tool_points_in_both_frames(corner, corner_result):
    points_part, points_base = path_points(corner_result, corner)
    np.testing.assert_array_equal(points_base, corner_result.trajectory.tool_position)
    T_base_part = placement_transform(corner_result.placement)
    np.testing.assert_allclose(transform_points(T_base_part, points_part), points_base, atol=1e-12)
    # in the definition frame the path starts where the case starts
    np.testing.assert_allclose(points_part[0], corner.start, atol=1e-9)


def test_tracking_error_agrees_with_the_check_and_stays_within_tolerance(corner, corner_result):
    error = tracking_error(corner_result, corner)
    assert error.shape == (corner_result.trajectory.n_samples,)
    assert error.max() == pytest.approx(corner_result.check.max_tracking_error, rel=1e-9)
    assert error.max() <= corner.task.tolerance


def test_path_points_fall_back_to_the_nominal_path(corner, unreachable_result):
    points_part, points_base = path_points(unreachable_result, corner)
    np.testing.assert_allclose(points_part, nominal_polyline(corner))
    T_base_part = placement_transform(unreachable_result.placement)
    np.testing.assert_allclose(points_base, transform_points(T_base_part, points_part))
    assert tracking_error(unreachable_result, corner).size == 0


@pytest.mark.parametrize(
    ("n_samples", "n_frames", "count"), [(1834, 150, 150), (40, 150, 40), (1, 5, 1)]
)
def test_frame_indices_spread_over_the_whole_trajectory(n_samples, n_frames, count):
    idx = frame_indices(n_samples, n_frames)
    assert len(idx) == count
    assert idx[0] == 0 and idx[-1] == n_samples - 1
    assert np.all(np.diff(idx) > 0)


def test_chain_points_end_at_the_tool(puma, rng):
    q = rng.uniform(puma.q_min, puma.q_max, size=(5, puma.n_dof))
    chain = chain_points(puma, q)
    assert chain.shape == (5, puma.n_dof + 2, 3)
    np.testing.assert_allclose(chain[:, 0], 0.0)
    np.testing.assert_allclose(chain[:, -1], forward_kinematics(puma, q)[:, :3, 3])


def test_sphere_triads_and_equal_limits():
    shell = sphere_wireframe(0.5)
    finite = shell[np.all(np.isfinite(shell), axis=1)]
    np.testing.assert_allclose(np.linalg.norm(finite, axis=1), 0.5)
    lines = triad_lines(
        np.stack([np.eye(4), placement_transform(np.array([1, 2, 3, 0, 0, 0]))]), 0.1
    )
    assert lines.shape == (3, 6, 3)
    np.testing.assert_allclose(lines[2, 4], [1.0, 2.0, 3.1])  # z axis of the second frame
    limits = equal_limits(np.array([[0.0, 0.0, 0.0], [np.nan] * 3, [1.0, 0.2, 0.3]]))
    widths = limits[:, 1] - limits[:, 0]
    np.testing.assert_allclose(widths, widths[0])
    assert np.all(limits[:, 0] <= [0.0, 0.0, 0.0]) and np.all(limits[:, 1] >= [1.0, 0.2, 0.3])
