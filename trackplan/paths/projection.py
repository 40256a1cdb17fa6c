"""Projection onto a path of many pieces through a spatial index, exact and O(N log P).

A dense projection measures every point against every piece: N × P pairs, 760 million for
a 20,000-point seam sampled 38,000 times. :class:`PieceIndex` cuts each piece into chunks
no longer than a common length and puts the chunk midpoints into a k-d tree
(:class:`scipy.spatial.cKDTree`). A chunk of arc length 2r lies within r of its midpoint,
so for a point x whose nearest midpoint is e away, every piece within e + slack of x has a
midpoint within e + slack + r: one ball query finds all the pieces that can be within
``slack`` of the nearest, and only those are projected exactly. The result is that of the
dense projection, not an approximation; points near the path meet a handful of pieces.
The work is split into blocks of bounded size, so a point far from the path (whose ball
holds many pieces) costs time, never unbounded memory.
"""

from __future__ import annotations

import itertools
from collections.abc import Iterator
from dataclasses import dataclass
from functools import cached_property
from typing import TYPE_CHECKING, NamedTuple

import numpy as np

from trackplan._kernels import read_only
from trackplan.paths._kernels import dense_pieces, near_pieces
from trackplan.paths.piece_table import PieceTable

if TYPE_CHECKING:
    from scipy.spatial import cKDTree

_EXTRA_CHUNKS = 1000
"""The chunk length is 2 × the path length / (P + this): a piece of average length or shorter
is one chunk, and there are at most 1.5 P + 500 chunks."""

_POINTS_PER_BLOCK = 1 << 14
"""Most points queried at once."""

_PAIRS_PER_BLOCK = 1 << 20
"""Most (point, chunk) pairs of a ball query held at once."""

_NEIGHBOURS = 32
"""Nearest chunk midpoints of each point found in one vectorised query; the points whose
query ball holds more are queried ball by ball."""

_DENSE_PIECES = 32
"""A path of at most this many pieces is projected onto every piece, without the tree."""

_NEIGHBOURS_NEAREST = 8
"""The same for the nearest piece only (no slack)."""

_WIDER = 4
"""The points whose ball holds more are asked again for this many times the neighbours."""

_PAD = 1e-9
"""Relative padding of the query radii (the tree rounds distances its own way), m/m."""


class Candidates(NamedTuple):
    """(point, piece) pairs, sorted by point then piece, with the exact projection.

    Attributes
    ----------
    row, piece
        Indices of the point and the piece, shape (K,).
    sigma, distance
        Arc length along the piece of the nearest point (m) and the distance to it (m),
        shape (K,).
    nearest
        Distance of each point from the whole path, shape (N,), m.
    """

    row: np.ndarray
    piece: np.ndarray
    sigma: np.ndarray
    distance: np.ndarray
    nearest: np.ndarray


@dataclass(frozen=True, eq=False)
class PieceIndex:
    """A k-d tree of piece chunks for exact nearest-piece queries.

    Attributes
    ----------
    table
        The pieces.
    """

    table: PieceTable

    @cached_property
    def _chunks(self) -> tuple[cKDTree, np.ndarray, np.ndarray, float]:
        """The tree of chunk midpoints, their piece (C,), half-lengths (C,) m, and the largest."""
        from scipy.spatial import cKDTree  # paths of few pieces never build the tree

        table = self.table
        step = 2.0 * table.total_length / (table.n_pieces + _EXTRA_CHUNKS)
        counts = np.maximum(1, np.ceil(table.length / step)).astype(int)
        piece = np.repeat(np.arange(table.n_pieces), counts)
        first = np.cumsum(counts) - counts
        j = np.arange(len(piece)) - np.repeat(first, counts)
        chunk = table.length[piece] / counts[piece]
        midpoints = table.evaluate_on(piece, (j + 0.5) * chunk).position
        half = 0.5 * chunk
        return cKDTree(midpoints), piece, half, float(half.max())

    def candidates(self, points: np.ndarray, slack: float) -> Candidates:
        """Every piece within ``slack`` of the nearest piece, for each point.

        Parameters
        ----------
        points
            Shape (N, 3), m.
        slack
            m, ≥ 0: 0 gives the nearest pieces only (several on a tie).

        Returns
        -------
        Candidates
            The pairs (point, piece) with distance ≤ nearest + ``slack``, each piece once.
        """
        points = np.asarray(points, dtype=float).reshape(-1, 3)
        n_pieces = self.table.n_pieces
        if n_pieces <= _DENSE_PIECES and np.isfinite(points).all():
            # every piece for every point, in one compiled pass: cheaper than a tree
            t = self.table
            _, piece, sigma, gap, nearest, row = dense_pieces(
                read_only(np.ascontiguousarray(points)), slack, *t.kernel_arrays()
            )
            return Candidates(row, piece, sigma, gap, nearest)
        finite = np.flatnonzero(np.isfinite(points).all(axis=1))
        parts = [(np.zeros(0, dtype=int), np.zeros(0, dtype=int), np.zeros(0), np.zeros(0))]
        if n_pieces <= _DENSE_PIECES:  # the same with points that are not finite
            every = np.arange(n_pieces)
            for start in range(0, len(finite), _POINTS_PER_BLOCK):
                block = points[finite[start : start + _POINTS_PER_BLOCK]]
                zeros = np.zeros((len(block), n_pieces))
                bounds, piece, sigma, gap = self._near_pieces(
                    block,
                    zeros,
                    np.tile(every, (len(block), 1)),
                    np.full(len(block), np.inf),
                    np.zeros(len(block), dtype=bool),
                    slack,
                    every,
                    np.zeros(n_pieces),
                )
                row = np.repeat(np.arange(len(block)), np.diff(bounds))
                parts.append((finite[start + row], piece, sigma, gap))
            return self._gathered(points, finite, parts)
        tree, chunk_piece, half, widest = self._chunks
        k_first = _NEIGHBOURS if slack > 0.0 else _NEIGHBOURS_NEAREST
        for start in range(0, len(finite), _POINTS_PER_BLOCK):
            block = points[finite[start : start + _POINTS_PER_BLOCK]]
            first, radius = np.zeros(len(block)), np.zeros(len(block))
            more = np.arange(len(block))
            found = []  # each point's pairs come from one query only, sorted by piece
            for k in (min(k_first, tree.n), min(_WIDER * k_first, tree.n)):
                # a finely sampled path puts more than k chunks in many balls: ask again for
                # more neighbours, vectorised, before going ball by ball
                distance, index = tree.query(block[more], k=k)
                distance, index = distance.reshape(len(more), k), index.reshape(len(more), k)
                first[more] = distance[:, 0]
                radius[more] = self._radius(distance[:, 0], slack + widest)
                full = (distance[:, -1] <= radius[more]) & (k < tree.n)  # more than k chunks
                bounds, piece, sigma, gap = self._near_pieces(
                    block[more], distance, index, radius[more], full, slack, chunk_piece, half
                )
                found.append(
                    (more[np.repeat(np.arange(len(more)), np.diff(bounds))], piece, sigma, gap)
                )
                more = more[full]
                if more.size == 0:
                    break
            for rows, chunk in self._ball_chunks(block, more, radius):
                found.append(self._pairs(block, first, rows, chunk, slack))
            row, piece, sigma, gap = (np.concatenate(values) for values in zip(*found, strict=True))
            order = np.argsort(row, kind="stable")  # a few sorted runs: merged in linear time
            parts.append((finite[start + row[order]], piece[order], sigma[order], gap[order]))
        return self._gathered(points, finite, parts)

    def _gathered(
        self,
        points: np.ndarray,
        finite: np.ndarray,
        parts: list[tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]],
    ) -> Candidates:
        """The pairs of all blocks together, in order, with the points that are not finite."""
        row, piece, sigma, distance = (
            np.concatenate(values) for values in zip(*parts, strict=True)
        )
        if len(finite) < len(points):  # a point that is not finite meets the first piece, at NaN
            bad = np.setdiff1d(np.arange(len(points)), finite)
            nan = np.full(len(bad), np.nan)
            row = np.concatenate([row, bad])
            piece = np.concatenate([piece, np.zeros(len(bad), dtype=int)])
            sigma, distance = np.concatenate([sigma, nan]), np.concatenate([distance, nan])
        if np.any(np.diff(row) < 0):
            order = np.lexsort((piece, row))
            row, piece, sigma, distance = row[order], piece[order], sigma[order], distance[order]
        nearest = np.full(len(points), np.inf)
        firsts = _firsts(row)
        nearest[row[firsts]] = np.minimum.reduceat(distance, firsts) if len(row) else []
        return Candidates(row, piece, sigma, distance, nearest)

    def _radius(self, first_distance: np.ndarray, extra: float) -> np.ndarray:
        return (first_distance + extra) * (1.0 + _PAD) + _PAD * extra + 1e-15

    def _near_pieces(
        self,
        block: np.ndarray,
        distance: np.ndarray,
        index: np.ndarray,
        radius: np.ndarray,
        skip: np.ndarray,
        slack: float,
        chunk_piece: np.ndarray,
        half: np.ndarray,
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """The kept pairs of the points of ``block`` whose ball holds at most k chunks
        (:func:`trackplan.paths._kernels.near_pieces`)."""
        t = self.table
        return near_pieces(
            block,
            distance,
            index,
            radius,
            skip,
            slack,
            _PAD,
            chunk_piece,
            half,
            t.is_arc,
            t.start,
            t.direction,
            t.length,
            t.center,
            t.axis,
            t.e1,
            t.e2,
            t.radius,
            t.angle,
        )

    def _ball_chunks(
        self, block: np.ndarray, more: np.ndarray, radius: np.ndarray
    ) -> Iterator[tuple[np.ndarray, np.ndarray]]:
        """Pairs (row of ``block``, chunk) for the points ``more`` whose ball holds many chunks.

        Ball by ball, in parts of at most :data:`_PAIRS_PER_BLOCK` pairs.
        """
        tree = self._chunks[0]
        start = 0
        while start < len(more):
            rows = more[start : start + _POINTS_PER_BLOCK]
            counts = tree.query_ball_point(block[rows], radius[rows], return_length=True)
            fits = np.searchsorted(np.cumsum(counts), _PAIRS_PER_BLOCK, side="right")
            rows = rows[: max(1, int(fits))]
            found = tree.query_ball_point(block[rows], radius[rows])
            counts = np.fromiter(map(len, found), dtype=int, count=len(found))
            chunk = np.fromiter(itertools.chain.from_iterable(found), dtype=int, count=counts.sum())
            yield np.repeat(rows, counts), chunk
            start += len(rows)

    def _pairs(
        self, block: np.ndarray, first: np.ndarray, row: np.ndarray, chunk: np.ndarray, slack: float
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """The pieces of the chunks found for points of ``block``, projected, and those within
        ``slack`` of the nearest kept; rows are those of ``block``."""
        tree, chunk_piece, half, _ = self._chunks
        # A chunk whose own half-length rules it out is dropped before projecting.
        gap = np.linalg.norm(block[row] - tree.data[chunk], axis=1)
        keep = gap <= self._radius(first[row], slack + half[chunk])
        n_pieces = self.table.n_pieces
        pair = np.sort(row[keep] * n_pieces + chunk_piece[chunk[keep]])
        first_of_pair = np.ones(len(pair), dtype=bool)
        first_of_pair[1:] = pair[1:] != pair[:-1]
        pair = pair[first_of_pair]
        row, piece = pair // n_pieces, pair % n_pieces
        sigma, distance = self.table.project_on(block[row], piece)
        nearest = np.full(len(block), np.inf)
        firsts = _firsts(row)
        nearest[row[firsts]] = np.minimum.reduceat(distance, firsts) if len(row) else []
        close = distance <= nearest[row] + slack
        return row[close], piece[close], sigma[close], distance[close]

    def project(self, points: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Nearest point of the path for each point.

        Parameters
        ----------
        points
            Shape (N, 3), m.

        Returns
        -------
        s
            Path arc length of the nearest point, shape (N,), m (the earliest piece on ties).
        distance
            Distance to it, shape (N,), m.
        piece
            Its piece, shape (N,).
        """
        found = self.candidates(points, 0.0)
        # the first (earliest) piece of each point at its nearest distance
        nearest = found.nearest[found.row]
        at_nearest = np.flatnonzero(
            (found.distance == nearest) | (np.isnan(found.distance) & np.isnan(nearest))
        )
        best = at_nearest[_firsts(found.row[at_nearest])]
        piece = found.piece[best]
        return self.table.s_start[piece] + found.sigma[best], found.distance[best], piece


def _firsts(row: np.ndarray) -> np.ndarray:
    """Index of the first entry of each run of equal values in ``row`` (K,), shape (R,)."""
    starts = np.ones(len(row), dtype=bool)
    starts[1:] = row[1:] != row[:-1]
    return np.flatnonzero(starts)
