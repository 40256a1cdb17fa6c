"""The nominal path: the path exactly as the user gave it, sharp corners included.

The tracking error of a trajectory is its distance from this path (docs/conventions.md).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from functools import cached_property
from typing import cast

import numpy as np

from trackplan.errors import CaseError
from trackplan.paths.curves import COLLINEAR_ANGLE, Arc, CurveJet, Line, Primitive
from trackplan.paths.piece_table import PieceTable
from trackplan.paths.pieces import Piece
from trackplan.paths.projection import PieceIndex
from trackplan.paths.specs import ArcSpec, LineSpec, SegmentSpec
from trackplan.paths.validation import check_segments


@dataclass(frozen=True, eq=False)
class Corner:
    """A junction of two pieces where the tangent turns.

    Attributes
    ----------
    junction
        The corner joins ``pieces[junction]`` and ``pieces[junction + 1]``.
    s
        Arc length of the corner on the nominal path, m.
    angle
        Angle between the incoming and outgoing unit tangents, rad, in (0, π].
    position
        Corner point, shape (3,), m.
    """

    junction: int
    s: float
    angle: float
    position: np.ndarray


@dataclass(frozen=True, eq=False)
class NominalPath:
    """The user's path: exact lines and arcs; a sampled curve is the polyline through its points.

    The pieces are held as arrays (:class:`~trackplan.paths.piece_table.PieceTable`): a
    sampled curve of a million points is a million lines, built and projected onto without a
    Python object each (``docs/paths.md``).

    Attributes
    ----------
    start
        Start point, shape (3,), m, in the definition frame.
    segments
        The segments it was built from.
    table
        Lines and arcs end to end on the arc length s.
    segment_index
        Index into ``segments`` of each piece, shape (n_pieces,).
    """

    start: np.ndarray
    segments: tuple[SegmentSpec, ...]
    table: PieceTable
    segment_index: np.ndarray

    @classmethod
    def from_specs(cls, start: np.ndarray, segments: Sequence[SegmentSpec]) -> NominalPath:
        """Build the nominal path from the user's segments.

        Parameters
        ----------
        start
            Start point, shape (3,), m.
        segments
            Lines, arcs and sampled curves in order, each from where the previous ends.

        Raises
        ------
        CaseError
            On the first degenerate segment found by
            :func:`~trackplan.paths.validation.check_segments`, with its key path.
        """
        problems = check_segments(start, segments)
        if problems:
            key, message = problems[0]
            raise CaseError(message, key=key)
        current = np.asarray(start, dtype=float)
        tables: list[PieceTable] = []
        owner: list[np.ndarray] = []
        for i, spec in enumerate(segments):
            if isinstance(spec, LineSpec):
                line = Line.between(current, np.asarray(spec.to, dtype=float))
                table, current = PieceTable.from_curves([line]), line.end
            elif isinstance(spec, ArcSpec):
                arc = Arc.from_rotation(current, spec.center, spec.normal, float(spec.angle))
                table, current = PieceTable.from_curves([arc]), arc.end
            else:
                vertices = np.vstack([current[None], np.asarray(spec.points, dtype=float)])
                table = PieceTable.from_polyline(vertices)
                current = table.start[-1] + table.length[-1] * table.direction[-1]
            tables.append(table)
            owner.append(np.full(table.n_pieces, i))
        return cls(
            np.asarray(start, dtype=float),
            tuple(segments),
            PieceTable.concatenate(tables),
            np.concatenate(owner),
        )

    @property
    def length(self) -> float:
        """Total arc length, m."""
        return self.table.total_length

    @property
    def n_pieces(self) -> int:
        """Number of lines and arcs."""
        return self.table.n_pieces

    @cached_property
    def pieces(self) -> tuple[Piece, ...]:
        """The lines and arcs end to end, one object each (built on first use)."""
        table = self.table
        return tuple(Piece(table.curve(k), float(table.s_start[k])) for k in range(table.n_pieces))

    @property
    def curves(self) -> tuple[Primitive, ...]:
        """The lines and arcs of the pieces, in order."""
        return tuple(cast(Primitive, piece.curve) for piece in self.pieces)

    def segment_curves(self, segment: int) -> list[Primitive]:
        """The lines and arcs made from ``segments[segment]``, in order."""
        return [self.table.curve(int(k)) for k in np.flatnonzero(self.segment_index == segment)]

    def vertices(self, segment: int) -> np.ndarray:
        """The polyline of a ``points`` segment, current point first, shape (K + 1, 3), m."""
        owned = np.flatnonzero(self.segment_index == segment)
        table, last = self.table, owned[-1]
        end = table.start[last] + table.length[last] * table.direction[last]
        return np.vstack([table.start[owned], end[None]])

    @cached_property
    def junction_angles(self) -> np.ndarray:
        """Turning angle of the tangent at each junction, shape (P − 1,), rad, in [0, π]:
        entry k joins pieces k and k + 1."""
        t_in = self.table.end_tangents()[:-1]
        t_out = self.table.start_tangents()[1:]
        across = np.linalg.norm(np.cross(t_in, t_out), axis=1)
        angles: np.ndarray = np.arctan2(across, np.einsum("ij,ij->i", t_in, t_out))
        angles.flags.writeable = False
        return angles

    @cached_property
    def corner_junctions(self) -> np.ndarray:
        """Junctions where the tangent turns by more than
        :data:`~trackplan.paths.curves.COLLINEAR_ANGLE`, shape (C,): entry ``k`` joins
        pieces k and k + 1 (polyline vertices included)."""
        return np.flatnonzero(self.junction_angles > COLLINEAR_ANGLE)

    @cached_property
    def corners(self) -> tuple[Corner, ...]:
        """The corners (:attr:`corner_junctions`) as objects, in order."""
        table = self.table
        return tuple(
            Corner(
                int(k),
                float(table.s_start[k + 1]),
                float(self.junction_angles[k]),
                table.start[k + 1],
            )
            for k in self.corner_junctions
        )

    @cached_property
    def index(self) -> PieceIndex:
        """The spatial index of the pieces (built on first use)."""
        return PieceIndex(self.table)

    def project(self, points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Nearest points on the nominal path.

        Parameters
        ----------
        points
            Shape (N, 3), m, in the definition frame.

        Returns
        -------
        s
            Arc length of the nearest point, shape (N,), m (the first one on ties).
        distance
            Distance to it, shape (N,), m: the tracking error.
        """
        s, distance, _ = self.index.project(np.asarray(points, dtype=float).reshape(-1, 3))
        return s, distance

    def evaluate(self, s: np.ndarray) -> tuple[CurveJet, np.ndarray]:
        """Position and arc-length derivatives at arc lengths ``s`` (M,), m, and the piece of
        each, shape (M,) (a junction belongs to the later piece)."""
        return self.table.evaluate(s)

    def tangents(self, s: np.ndarray, piece: np.ndarray) -> np.ndarray:
        """Unit tangents at arc lengths ``s`` (N,), m, on the given pieces (N,), shape (N, 3)."""
        table = self.table
        piece = np.asarray(piece, dtype=int)
        sigma = np.clip(np.asarray(s, dtype=float) - table.s_start[piece], 0.0, table.length[piece])
        return table.evaluate_on(piece, sigma).tangent

    def polyline(self, ds: float) -> np.ndarray:
        """Points along the path for drawing, at most ``ds`` (m) apart, ends included.

        Returns
        -------
        numpy.ndarray
            Shape (K, 3), m.
        """
        table = self.table
        counts = np.maximum(1, np.ceil(table.length / ds)).astype(int)
        piece = np.repeat(np.arange(table.n_pieces), counts)
        j = np.arange(len(piece)) - np.repeat(np.cumsum(counts) - counts, counts) + 1
        sigma = table.length[piece] * j / counts[piece]
        ends = table.evaluate_on(piece, sigma).position
        return np.vstack([self.start[None], ends])
