"""NominalPath: the user's path as given, its corners, projection and drawing."""

from __future__ import annotations

import numpy as np
import pytest

from trackplan.paths import ArcSpec, LineSpec, NominalPath, PointsSpec, paper_corner_angle

PAPER_CORNER = (np.zeros(3), [LineSpec(np.array([0.5, 0, 0])), LineSpec(np.array([0.3, 0, 0.5]))])


@pytest.fixture(scope="module")
def mixed() -> NominalPath:
    """Line, tangent arc, line, sampled curve."""
    t = np.linspace(0.0, 0.1, 11)[1:]
    return NominalPath.from_specs(
        np.zeros(3),
        [
            LineSpec(np.array([0.2, 0.0, 0.0])),
            ArcSpec(np.array([0.2, 0.0, 0.1]), np.array([0.0, -1.0, 0.0]), np.pi / 2),
            LineSpec(np.array([0.3, 0.0, 0.3])),
            PointsSpec(np.c_[0.3 + t, np.zeros_like(t), 0.3 + 2 * t**2]),
        ],
    )


def test_pieces_follow_the_segments(mixed):
    assert [piece.kind for piece in mixed.pieces] == ["line", "arc", "line"] + ["line"] * 10
    np.testing.assert_array_equal(mixed.segment_index, [0, 1, 2] + [3] * 10)
    assert mixed.length == pytest.approx(sum(piece.length for piece in mixed.pieces))
    polyline = np.linalg.norm(np.diff(mixed.vertices(3), axis=0), axis=1).sum()
    assert mixed.length == pytest.approx(0.2 + 0.05 * np.pi + 0.2 + polyline, rel=1e-15)
    ends = [piece.curve.end for piece in mixed.pieces[:-1]]
    starts = [piece.curve.start for piece in mixed.pieces[1:]]
    np.testing.assert_allclose(ends, starts, atol=1e-15)
    np.testing.assert_allclose(mixed.pieces[1].curve.end, [0.3, 0.0, 0.1], atol=1e-15)


def test_paper_corner_angle():
    nominal = NominalPath.from_specs(*PAPER_CORNER)
    (corner,) = nominal.corners
    beta = paper_corner_angle(np.zeros(3), np.array([0.5, 0, 0]), np.array([0.3, 0, 0.5]))
    assert corner.junction == 0
    assert corner.s == pytest.approx(0.5)
    assert corner.angle == pytest.approx(np.pi - beta)
    assert np.degrees(beta) == pytest.approx(68.198590513648, abs=1e-9)
    np.testing.assert_allclose(corner.position, [0.5, 0, 0])


def test_tangent_junctions_are_not_corners(mixed):
    # Line → tangent arc → line: no corner; the polyline vertices are corners.
    assert mixed.corners[0].junction == 2


def test_project_matches_brute_force(mixed, rng):
    near = mixed.polyline(1e-3)[::7]
    points = near + rng.normal(scale=0.01, size=near.shape)
    s, distance = mixed.project(points)
    cloud = mixed.polyline(5e-6)
    brute = np.array([np.linalg.norm(cloud - p, axis=1).min() for p in points])
    np.testing.assert_array_less(distance, brute + 1e-12)
    np.testing.assert_allclose(distance, brute, atol=5e-6)
    # The arc length given is that of the nearest point.
    cloud_s = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(cloud, axis=0), axis=1))])
    nearest = [cloud_s[np.argmin(np.linalg.norm(cloud - p, axis=1))] for p in points]
    np.testing.assert_allclose(s, nearest, atol=1e-5)


def test_project_gives_the_tracking_error():
    nominal = NominalPath.from_specs(*PAPER_CORNER)
    offsets = np.array([1e-3, 2e-3, 5e-4])
    # Points off the first leg (in y, perpendicular) and inside the corner on the bisector.
    points = np.c_[[0.1, 0.2, 0.3], offsets, [0, 0, 0]]
    s, distance = nominal.project(points)
    np.testing.assert_allclose(distance, offsets, rtol=1e-14)
    np.testing.assert_allclose(s, [0.1, 0.2, 0.3], rtol=1e-14)
    (corner,) = nominal.corners
    bisector = np.array([-1.0 - 0.2 / np.sqrt(0.29), 0, 0.5 / np.sqrt(0.29)])
    bisector /= np.linalg.norm(bisector)
    inside = corner.position + 0.01 * bisector
    _, (gap,) = nominal.project(inside[None])
    assert gap == pytest.approx(0.01 * np.cos(corner.angle / 2), rel=1e-12)


def test_project_handles_many_points_in_blocks(mixed, rng):
    points = rng.uniform(-0.1, 0.5, size=(120_000, 3))
    s, distance = mixed.project(points)
    s_few, distance_few = mixed.project(points[-50:])
    np.testing.assert_array_equal(distance[-50:], distance_few)
    np.testing.assert_array_equal(s[-50:], s_few)


def test_polyline_spacing(mixed):
    points = mixed.polyline(5e-3)
    gaps = np.linalg.norm(np.diff(points, axis=0), axis=1)
    assert gaps.max() <= 5e-3 + 1e-15
    np.testing.assert_allclose(points[0], mixed.start)
    np.testing.assert_allclose(points[-1], mixed.pieces[-1].curve.end, atol=1e-15)
    _, distance = mixed.project(points)
    assert distance.max() < 1e-15


def test_circle_of_the_paper():
    circle = NominalPath.from_specs(
        np.zeros(3), [ArcSpec(np.array([0.0, 0.0, -0.2]), np.array([0.0, 1.0, 0.0]), 2 * np.pi)]
    )
    assert circle.length == pytest.approx(2 * np.pi * 0.2, rel=1e-15)
    points = circle.polyline(1e-3)
    np.testing.assert_allclose(points[:, 1], 0.0, atol=1e-16)  # in the x–z plane
    np.testing.assert_allclose(np.linalg.norm(points - [0, 0, -0.2], axis=1), 0.2, rtol=1e-15)
    quarter = points[np.argmin(np.abs(np.linspace(0, 1, len(points)) - 0.25))]
    np.testing.assert_allclose(quarter, [0.2, 0.0, -0.2], atol=1e-3)
