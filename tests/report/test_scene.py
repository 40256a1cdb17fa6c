"""Geometry behind the plots: nominal polyline, distances, frames, path frames."""

from __future__ import annotations

import itertools

import numpy as np
import pytest

from trackplan.paths.specs import ArcSpec, LineSpec, PointsSpec
from trackplan.planning.placement import placement_transform
from trackplan.report.scene import (
    chain_points,
    distance_to_polyline,
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


def test_full_circle_stays_on_the_circle_within_the_chord_error():
    # the paper's Case 2: start (0, 0, 0), radius 0.2, centre (0, 0, -0.2), in the x-z plane
    center = np.array([0.0, 0.0, -0.2])
    arc = ArcSpec(center=center, normal=np.array([0.0, 1.0, 0.0]), angle=2 * np.pi)
    points = nominal_polyline(np.zeros(3), [arc], chord_error=1e-6)
    radius = np.linalg.norm(points - center, axis=1)
    np.testing.assert_allclose(radius, 0.2, atol=1e-12)
    np.testing.assert_allclose(points[-1], points[0], atol=1e-12)
    np.testing.assert_allclose(points[:, 1], 0.0, atol=1e-12)
    midpoints = 0.5 * (points[1:] + points[:-1])
    assert np.max(0.2 - np.linalg.norm(midpoints - center, axis=1)) <= 1e-6
    # right-hand rotation about +y takes (0, 0, 0) - c = +z towards +x
    assert points[1, 0] > 0


def test_lines_and_points_are_kept_exactly():
    start = np.array([0.1, 0.0, 0.0])
    samples = np.array([[0.3, 0.1, 0.0], [0.4, 0.1, 0.1]])
    points = nominal_polyline(start, [LineSpec(to=np.array([0.2, 0.0, 0.0])), PointsSpec(samples)])
    np.testing.assert_array_equal(points, np.vstack([start, [0.2, 0.0, 0.0], samples]))


def test_distance_to_polyline_matches_dense_sampling(rng):
    polyline = rng.normal(size=(7, 3))
    points = rng.normal(size=(50, 3))
    u = np.linspace(0.0, 1.0, 4001)[:, None]
    dense = np.vstack([a + u * (b - a) for a, b in itertools.pairwise(polyline)])
    brute = np.min(np.linalg.norm(points[:, None, :] - dense[None], axis=-1), axis=1)
    distance = distance_to_polyline(points, polyline)
    assert np.all(distance <= brute + 1e-12)
    np.testing.assert_allclose(distance, brute, atol=1e-3)


def test_distance_to_a_single_point():
    np.testing.assert_allclose(
        distance_to_polyline(np.array([[3.0, 4.0, 0.0]]), np.zeros((1, 3))), [5.0]
    )


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
    np.testing.assert_allclose(points_part, nominal_polyline(corner.start, corner.segments))
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
