"""Locating samples on the nominal path: the indexed version equals the dense algorithm.

The oracle is the dense algorithm (every sample against every piece, an (N, P) candidate
matrix walked in time order), kept here as it was before the index. Random paths of lines,
arcs and sampled curves, and tool points that follow them with noise, forwards, with
pauses, or backwards, drawn by hypothesis (derandomized).
"""

from __future__ import annotations

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from tests.paths.random_paths import paths, random_nominal
from trackplan.paths import LineSpec, NominalPath, PointsSpec
from trackplan.paths.curves import unwrap_closed_arc
from trackplan.planning import tracking
from trackplan.planning.tracking import DIRECTION_SLACK, jump_allowance, locate_on_nominal

PROPERTY = settings(max_examples=30, deadline=None, derandomize=True)


def dense_locate(nominal: NominalPath, points, velocity, tolerance):
    """The dense algorithm: (N, P) candidates, then the in-order walk."""
    pieces = nominal.pieces
    n = len(points)
    sigma = np.empty((n, len(pieces)))
    dist = np.empty((n, len(pieces)))
    agrees = np.empty((n, len(pieces)), dtype=bool)
    speed = np.linalg.norm(velocity, axis=1)
    for p, piece in enumerate(pieces):
        sigma[:, p], dist[:, p] = piece.curve.project(points)
        tangent = piece.curve.evaluate(sigma[:, p]).tangent
        agrees[:, p] = np.einsum("nk,nk->n", tangent, velocity) >= -DIRECTION_SLACK * speed
    nearest = dist.min(axis=1)
    close = dist <= nearest[:, None] + max(tolerance, 1e-12)
    candidates = close & agrees
    candidates[~candidates.any(axis=1)] = close[~candidates.any(axis=1)]
    assigned = np.empty(n, dtype=int)
    piece = int(np.argmax(candidates[0]))
    for k in range(n):
        if not candidates[k, piece]:
            options = np.flatnonzero(candidates[k])
            ahead = options[options > piece]
            piece = int(ahead[0]) if ahead.size else int(options[0])
        assigned[k] = piece
    local = sigma[np.arange(n), assigned]
    for p, piece_p in enumerate(pieces):
        on_piece = assigned == p
        if piece_p.kind == "arc" and piece_p.curve.angle >= 2 * np.pi - 1e-9 and on_piece.any():
            local[on_piece] = unwrap_closed_arc(
                local[on_piece], 2 * np.pi * piece_p.curve.radius, piece_p.length
            )
    s_start = np.array([p.s_start for p in pieces])
    return s_start[assigned] + local, nearest, assigned


def _trajectory(nominal: NominalPath, seed: int, motion: str, noise: float):
    """Tool points in time order along the path and their finite-difference velocity."""
    rng = np.random.default_rng(seed)
    n = 400
    s = np.linspace(0.0, nominal.length, n)
    if motion == "pauses":
        s = np.repeat(s[::4], 4)
    elif motion == "backwards":
        s = s[::-1]
    points = nominal.evaluate(s)[0].position + rng.normal(scale=noise, size=(n, 3))
    velocity = np.diff(points, axis=0, prepend=points[:1]) / 1e-3
    return points, velocity


@PROPERTY
@given(
    paths,
    st.integers(0, 2**31),
    st.sampled_from(["forwards", "pauses", "backwards"]),
    st.sampled_from([0.0, 1e-4, 1e-3]),
    st.sampled_from([1e-4, 1e-3, 5e-3]),
)
def test_locate_equals_the_dense_algorithm(path, seed, motion, noise, tolerance):
    nominal = random_nominal(*path)
    points, velocity = _trajectory(nominal, seed, motion, noise)
    s, distance, piece = locate_on_nominal(nominal, points, velocity, tolerance)
    s_dense, d_dense, piece_dense = dense_locate(nominal, points, velocity, tolerance)
    np.testing.assert_allclose(distance, d_dense, rtol=0, atol=1e-13)
    # A candidate exactly at the edge of ρ may fall either way by round-off; short of that
    # the assignment is the same sample for sample.
    same = piece == piece_dense
    assert same.mean() > 0.99
    np.testing.assert_allclose(s[same], s_dense[same], rtol=0, atol=1e-12)


def test_locate_follows_a_20k_point_polyline_in_order():
    angle = np.linspace(0.0, 6 * np.pi, 20_000)
    helix = np.c_[0.1 * np.cos(angle) - 0.1, 0.1 * np.sin(angle), 0.3 * angle / (6 * np.pi)]
    nominal = NominalPath.from_specs(np.zeros(3), [PointsSpec(helix[1:])])
    s_true = np.linspace(0.0, nominal.length, 38_000)
    points = nominal.evaluate(s_true)[0].position + np.array([0.0, 0.0, 1e-4])
    velocity = np.gradient(points, axis=0)
    s, distance, piece = locate_on_nominal(nominal, points, velocity, 1e-3)
    assert np.all(np.diff(piece) >= 0)
    # A sample stays on its piece while that remains within ρ of the nearest: s may lag by ρ.
    np.testing.assert_allclose(s, s_true, atol=1e-3 + 1e-4)
    assert np.all(np.diff(s) >= -1e-12)
    assert distance.max() <= 1e-4 + 1e-12


def test_jump_allowance_at_corners():
    nominal = NominalPath.from_specs(
        np.zeros(3),
        [LineSpec(np.array([0.5, 0.0, 0.0])), LineSpec(np.array([0.5, 0.5, 0.0]))],
    )
    allowance = jump_allowance(nominal, 1e-3)
    np.testing.assert_allclose(allowance, [2e-3, 0.0], rtol=1e-12)


def test_locate_in_blocks_equals_locate_at_once(monkeypatch):
    nominal = random_nominal(11, 6)
    points, velocity = _trajectory(nominal, 3, "pauses", 2e-4)
    whole = locate_on_nominal(nominal, points, velocity, 1e-3)
    monkeypatch.setattr(tracking, "LOCATE_BLOCK", 37)
    blocks = locate_on_nominal(nominal, points, velocity, 1e-3)
    for a, b in zip(whole, blocks, strict=True):
        np.testing.assert_array_equal(a, b)
