"""The indexed projection onto a path equals the dense one (every point against every piece).

The dense projection is the oracle: each piece's own ``project`` (the closed forms of
``trackplan.paths.curves``) on every point, the nearest taken, the earliest piece on ties.
Random paths of lines, arcs (closed ones included) and sampled curves up to 400 points,
random points near the path and far from it, drawn by hypothesis (derandomized).
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from tests.paths.random_paths import paths, points_near, random_nominal
from trackplan.paths import LineSpec, NominalPath, PointsSpec
from trackplan.paths.piece_table import PieceTable

PROPERTY = settings(max_examples=30, deadline=None, derandomize=True)


def dense_projection(nominal: NominalPath, points: np.ndarray):
    """s, distance and piece of the nearest point, from all N × P pairs."""
    sigma = np.empty((len(points), nominal.n_pieces))
    distance = np.empty_like(sigma)
    for p, piece in enumerate(nominal.pieces):
        sigma[:, p], distance[:, p] = piece.curve.project(points)
    best = np.argmin(distance, axis=1)
    rows = np.arange(len(points))
    s_start = np.array([piece.s_start for piece in nominal.pieces])
    return s_start[best] + sigma[rows, best], distance[rows, best], best, sigma, distance


@PROPERTY
@given(paths, st.integers(0, 2**31), st.sampled_from([1e-5, 1e-3, 0.05, 1.0]))
def test_indexed_projection_equals_dense(path, seed, scale):
    nominal = random_nominal(*path)
    points = points_near(nominal, seed, 300, scale)
    s, distance, piece = nominal.index.project(points)
    s_dense, d_dense, piece_dense, _, _ = dense_projection(nominal, points)
    np.testing.assert_allclose(distance, d_dense, rtol=0, atol=1e-13)
    # Same nearest piece, except on a tie (two pieces equally near to round-off).
    differ = piece != piece_dense
    tie = np.abs(distance - d_dense) <= 1e-12
    assert np.all(tie[differ])
    np.testing.assert_allclose(s[~differ], s_dense[~differ], rtol=0, atol=1e-12)
    s_public, d_public = nominal.project(points)
    np.testing.assert_array_equal(s_public, s)
    np.testing.assert_array_equal(d_public, distance)


@PROPERTY
@given(paths, st.integers(0, 2**31), st.sampled_from([1e-4, 2e-3, 0.1]))
def test_candidates_are_the_pieces_within_slack_of_the_nearest(path, seed, slack):
    nominal = random_nominal(*path)
    points = points_near(nominal, seed, 200, 1e-3)
    found = nominal.index.candidates(points, slack)
    _, d_dense, _, sigma, distance = dense_projection(nominal, points)
    np.testing.assert_allclose(found.nearest, d_dense, rtol=0, atol=1e-13)
    expected = distance <= d_dense[:, None] + slack
    got = np.zeros_like(expected)
    got[found.row, found.piece] = True
    # Pieces exactly at the edge of the slack may fall either way by round-off.
    edge = np.abs(distance - (d_dense[:, None] + slack)) <= 1e-12
    assert np.array_equal(got & ~edge, expected & ~edge)
    assert np.all(np.diff(found.row) >= 0)  # sorted by point, then piece
    same = np.diff(found.row) == 0
    assert np.all(np.diff(found.piece)[same] > 0)
    np.testing.assert_allclose(found.distance, distance[found.row, found.piece], atol=1e-13)
    np.testing.assert_allclose(found.sigma, sigma[found.row, found.piece], atol=1e-12)


def test_points_far_from_a_fine_polyline_are_projected_in_bounded_blocks():
    # 5,000 pieces on a circle and points on its axis: every piece is (nearly) the nearest.
    angle = np.linspace(0.0, 2 * np.pi, 5001)[1:]
    circle = np.c_[np.cos(angle) - 1.0, np.sin(angle), np.zeros_like(angle)]
    nominal = NominalPath.from_specs(np.zeros(3), [PointsSpec(circle)])
    axis = np.c_[np.full(40, -1.0), np.zeros(40), np.linspace(-1.0, 1.0, 40)]
    found = nominal.index.candidates(axis, 1e-3)
    _, d_dense, _, _, _ = dense_projection(nominal, axis)
    np.testing.assert_allclose(found.nearest, d_dense, atol=1e-13)
    assert len(found.row) == 40 * 5000  # within 1 mm of the nearest: every piece


def test_points_that_are_not_finite_meet_the_first_piece_at_nan():
    nominal = NominalPath.from_specs(np.zeros(3), [LineSpec(np.array([1.0, 0, 0]))])
    points = np.array([[0.5, 0.1, 0.0], [np.nan, 0.0, 0.0], [0.2, 0.0, 0.0]])
    found = nominal.index.candidates(points, 1e-3)
    np.testing.assert_array_equal(found.row, [0, 1, 2])
    assert np.isnan(found.nearest[1])
    np.testing.assert_allclose(found.nearest[[0, 2]], [0.1, 0.0])
    s, distance = nominal.project(points)
    np.testing.assert_allclose(s, [0.5, np.nan, 0.2])
    np.testing.assert_allclose(distance, [0.1, np.nan, 0.0])


def test_piece_table_evaluates_like_the_curves():
    nominal = random_nominal(5, 6)
    table = nominal.table
    for k, piece in enumerate(nominal.pieces):
        sigma = np.linspace(0.0, piece.length, 7)
        expected = piece.curve.evaluate(sigma)
        got = table.evaluate_on(np.full(7, k), sigma)
        for a, b in zip(got, expected, strict=True):
            np.testing.assert_allclose(a, b, rtol=0, atol=1e-14)
    assert table.total_length == pytest.approx(sum(p.length for p in nominal.pieces), rel=1e-14)


def test_polyline_table_is_built_without_objects():
    vertices = np.cumsum(np.random.default_rng(1).normal(size=(1000, 3)), axis=0)
    table = PieceTable.from_polyline(vertices)
    np.testing.assert_allclose(table.length, np.linalg.norm(np.diff(vertices, axis=0), axis=1))
    np.testing.assert_array_equal(table.start, vertices[:-1])
    ends = table.start + table.length[:, None] * table.direction
    np.testing.assert_allclose(ends, vertices[1:], atol=1e-13)


@PROPERTY
@given(paths, st.integers(0, 2**31), st.sampled_from([0.0, 1e-3, 0.1]))
def test_few_pieces_in_one_pass_equal_the_blocked_pairs(path, seed, slack):
    """A path of few pieces is projected in one compiled pass; a batch holding a point that
    is not finite takes the blocked pairs instead: the same candidates, to the bit."""
    nominal = random_nominal(*path)
    points = points_near(nominal, seed, 200, 1e-2)
    fast = nominal.index.candidates(points, slack)
    blocked = nominal.index.candidates(np.vstack([points, [[np.nan, 0.0, 0.0]]]), slack)
    kept = blocked.row < len(points)
    for field in ("row", "piece", "sigma", "distance"):
        np.testing.assert_array_equal(getattr(fast, field), getattr(blocked, field)[kept])
    np.testing.assert_array_equal(fast.nearest, blocked.nearest[: len(points)])
