"""Pieces: curves laid end to end on one arc-length parameter s."""

from __future__ import annotations

import itertools
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from trackplan.paths._kernels import ARC_KIND, LINE_KIND, OTHER_KIND, piece_points
from trackplan.paths.curves import Arc, Curve, CurveJet, Line


@dataclass(frozen=True, eq=False)
class Piece:
    """One curve of a path and where it starts on the path's arc length.

    Attributes
    ----------
    curve
        A :class:`~trackplan.paths.curves.Line`, :class:`~trackplan.paths.curves.Arc`
        or :class:`~trackplan.paths.curves.QuinticBlend`.
    s_start
        Arc length of the path at the start of the piece, m.
    """

    curve: Curve
    s_start: float

    @property
    def kind(self) -> str:
        """``"line"``, ``"arc"`` or ``"blend"``."""
        return self.curve.kind

    @property
    def length(self) -> float:
        """Arc length of the piece, m."""
        return self.curve.length

    @property
    def s_end(self) -> float:
        """Arc length of the path at the end of the piece, m."""
        return self.s_start + self.curve.length

    @property
    def straight(self) -> bool:
        """True for lines (rated speed applies), False for arcs and blends."""
        return self.curve.straight


def chain(curves: Sequence[Curve]) -> tuple[Piece, ...]:
    """Lay ``curves`` end to end from s = 0."""
    starts = np.concatenate([[0.0], np.cumsum([curve.length for curve in curves])])
    return tuple(Piece(curve, float(s)) for curve, s in zip(curves, starts[:-1], strict=True))


def evaluate_pieces(pieces: Sequence[Piece], s: np.ndarray) -> tuple[CurveJet, np.ndarray]:
    """Position and arc-length derivatives of a chain of pieces at path arc lengths ``s``.

    Parameters
    ----------
    pieces
        Consecutive pieces, as made by :func:`chain`.
    s
        Arc lengths (M,), m, within [0, total length]; a value on a junction belongs to the
        later piece, the total length to the last one.

    Returns
    -------
    jet
        Position (M, 3), m; unit tangent (M, 3); curvature vector (M, 3), 1/m; its
        derivative (M, 3), 1/m².
    piece
        Index of the piece of each sample, shape (M,).
    """
    s = np.asarray(s, dtype=float)
    index, rows = _piece_rows(pieces, s)
    fields = [np.empty((s.size, 3)) for _ in range(4)]
    for piece, selected in zip(pieces, rows, strict=True):
        sigma = np.clip(s[selected] - piece.s_start, 0.0, piece.length)
        if sigma.size == 0:
            continue
        for out, value in zip(fields, piece.curve.evaluate(sigma), strict=True):
            out[selected] = value
    return CurveJet(*fields), index


@dataclass(frozen=True, eq=False)
class PointTable:
    """A chain of pieces laid out for :func:`~trackplan.paths._kernels.piece_points`.

    Attributes
    ----------
    s_start, length
        Start and length of each piece, shape (P,), m.
    kind
        Line, arc or other (a blend), shape (P,), int (the kernel's kinds).
    origin, first, second
        A line's start and direction; an arc's centre, e1 and e2; shape (P, 3) each.
    radius
        An arc's radius, shape (P,), m.
    """

    s_start: np.ndarray
    length: np.ndarray
    kind: np.ndarray
    origin: np.ndarray
    first: np.ndarray
    second: np.ndarray
    radius: np.ndarray

    @classmethod
    def from_pieces(cls, pieces: Sequence[Piece]) -> PointTable:
        """The table of consecutive pieces, as made by :func:`chain`."""
        n = len(pieces)
        kind = np.full(n, OTHER_KIND, dtype=np.int64)
        origin, first, second = np.zeros((n, 3)), np.zeros((n, 3)), np.zeros((n, 3))
        radius = np.ones(n)
        for k, piece in enumerate(pieces):
            curve = piece.curve
            if isinstance(curve, Line):
                kind[k], origin[k], first[k] = LINE_KIND, curve.start, curve.direction
            elif isinstance(curve, Arc):
                kind[k], origin[k], radius[k] = ARC_KIND, curve.center, curve.radius
                first[k], second[k] = curve.e1, curve.e2
        s_start = np.array([piece.s_start for piece in pieces])
        length = np.array([piece.length for piece in pieces])
        return cls(s_start, length, kind, origin, first, second, radius)


def evaluate_points(
    pieces: Sequence[Piece], s: np.ndarray, table: PointTable | None = None
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Position and unit tangent of a chain of pieces at path arc lengths ``s``.

    The first two fields of :func:`evaluate_pieces`, with the same values, without the
    curvature terms: lines and arcs in one compiled pass
    (:func:`~trackplan.paths._kernels.piece_points`), each blend's rows by its own
    :meth:`~trackplan.paths.curves.QuinticBlend.point_tangent`.

    Parameters
    ----------
    pieces
        Consecutive pieces, as made by :func:`chain`.
    s
        Arc lengths (M,), m, within [0, total length].
    table
        The pieces' :class:`PointTable`, when kept; default: built.

    Returns
    -------
    position
        Shape (M, 3), m.
    tangent
        Unit, shape (M, 3).
    piece
        Index of the piece of each sample, shape (M,).
    """
    s = np.ascontiguousarray(s, dtype=float).ravel()
    t = PointTable.from_pieces(pieces) if table is None else table
    position = np.empty((s.size, 3))
    tangent = np.empty((s.size, 3))
    index = piece_points(
        s, t.s_start, t.length, t.kind, t.origin, t.first, t.second, t.radius, position, tangent
    )
    other = np.flatnonzero(t.kind[index] == OTHER_KIND)  # rows on blends, in order
    if other.size:
        on = index[other]
        order = np.argsort(on, kind="stable")
        rows, on = other[order], on[order]
        for group in np.split(rows, np.flatnonzero(np.diff(on)) + 1):
            piece = pieces[int(index[group[0]])]
            sigma = np.clip(s[group] - piece.s_start, 0.0, piece.length)
            position[group], tangent[group] = piece.curve.point_tangent(sigma)
    return position, tangent, index


def _piece_rows(
    pieces: Sequence[Piece], s: np.ndarray
) -> tuple[np.ndarray, list[slice | np.ndarray]]:
    """The piece of each of ``s`` (M,) and each piece's rows: slices where ``s`` is in
    order (a trajectory's samples), masks otherwise."""
    starts = np.array([piece.s_start for piece in pieces])
    index = np.clip(np.searchsorted(starts, s, side="right") - 1, 0, len(pieces) - 1)
    rows: list[slice | np.ndarray]
    if np.all(index[1:] >= index[:-1]):
        edges = np.searchsorted(index, np.arange(len(pieces) + 1))
        rows = [slice(a, b) for a, b in itertools.pairwise(edges)]
    else:
        rows = [index == k for k in range(len(pieces))]
    return index, rows
