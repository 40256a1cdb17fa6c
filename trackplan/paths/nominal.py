"""The nominal path: the path exactly as the user gave it, sharp corners included.

The tracking error of a trajectory is its distance from this path (docs/conventions.md).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from functools import cached_property
from itertools import pairwise
from typing import cast

import numpy as np

from trackplan.errors import CaseError
from trackplan.paths.geometry import (
    COLLINEAR_ANGLE,
    Arc,
    Line,
    Primitive,
    end_jet,
    project_onto_arcs,
    project_onto_lines,
    start_jet,
    turning_angle,
)
from trackplan.paths.pieces import Piece, chain, evaluate_pieces
from trackplan.paths.specs import ArcSpec, LineSpec, SegmentSpec
from trackplan.paths.validation import check_segments

# Largest number of (point, piece) pairs projected at once: bounds the scratch memory.
_PAIRS_PER_BLOCK = 1 << 20


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

    Attributes
    ----------
    start
        Start point, shape (3,), m, in the definition frame.
    segments
        The segments it was built from.
    pieces
        Lines and arcs end to end on the arc length s.
    segment_index
        Index into ``segments`` of each piece, shape (n_pieces,).
    """

    start: np.ndarray
    segments: tuple[SegmentSpec, ...]
    pieces: tuple[Piece, ...]
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
        curves: list[Primitive] = []
        owner: list[int] = []
        for i, spec in enumerate(segments):
            new: list[Primitive]
            if isinstance(spec, LineSpec):
                new = [Line.between(current, np.asarray(spec.to, dtype=float))]
            elif isinstance(spec, ArcSpec):
                arc = Arc.from_rotation(current, spec.center, spec.normal, float(spec.angle))
                new = [arc]
            else:
                vertices = np.vstack([current[None], np.asarray(spec.points, dtype=float)])
                new = [Line.between(a, b) for a, b in pairwise(vertices)]
            curves.extend(new)
            owner.extend([i] * len(new))
            current = new[-1].end
        return cls(np.asarray(start, dtype=float), tuple(segments), chain(curves), np.array(owner))

    @property
    def length(self) -> float:
        """Total arc length, m."""
        return self.pieces[-1].s_end

    @property
    def curves(self) -> tuple[Primitive, ...]:
        """The lines and arcs of the pieces, in order."""
        return tuple(cast(Primitive, piece.curve) for piece in self.pieces)

    def segment_curves(self, segment: int) -> list[Primitive]:
        """The lines and arcs made from ``segments[segment]``, in order."""
        return [self.curves[k] for k in np.flatnonzero(self.segment_index == segment)]

    def vertices(self, segment: int) -> np.ndarray:
        """The polyline of a ``points`` segment, current point first, shape (K + 1, 3), m."""
        owned = self.segment_curves(segment)
        return np.vstack([curve.start for curve in owned] + [owned[-1].end])

    @cached_property
    def corners(self) -> tuple[Corner, ...]:
        """Junctions where the tangent turns by more than
        :data:`~trackplan.paths.geometry.COLLINEAR_ANGLE`, in order (polyline vertices included)."""
        found = []
        for k, (a, b) in enumerate(pairwise(self.pieces)):
            angle = turning_angle(end_jet(a.curve).tangent[0], start_jet(b.curve).tangent[0])
            if angle > COLLINEAR_ANGLE:
                found.append(Corner(k, b.s_start, angle, b.curve.start))
        return tuple(found)

    @cached_property
    def _stacked(self) -> dict[str, np.ndarray]:
        lines = [k for k, curve in enumerate(self.curves) if isinstance(curve, Line)]
        arcs = [k for k, curve in enumerate(self.curves) if isinstance(curve, Arc)]
        line_curves = [cast(Line, self.curves[k]) for k in lines]
        arc_curves = [cast(Arc, self.curves[k]) for k in arcs]
        return {
            "lines": np.array(lines, dtype=int),
            "line_start": np.array([c.start for c in line_curves]).reshape(-1, 3),
            "line_direction": np.array([c.direction for c in line_curves]).reshape(-1, 3),
            "line_length": np.array([c.length for c in line_curves]),
            "arcs": np.array(arcs, dtype=int),
            "arc_center": np.array([c.center for c in arc_curves]).reshape(-1, 3),
            "arc_radius": np.array([c.radius for c in arc_curves]),
            "arc_e1": np.array([c.e1 for c in arc_curves]).reshape(-1, 3),
            "arc_axis": np.array([c.axis for c in arc_curves]).reshape(-1, 3),
            "arc_angle": np.array([c.angle for c in arc_curves]),
            "s_start": np.array([piece.s_start for piece in self.pieces]),
        }

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
        points = np.asarray(points, dtype=float).reshape(-1, 3)
        st = self._stacked
        s = np.empty(len(points))
        distance = np.empty(len(points))
        block = max(1, _PAIRS_PER_BLOCK // len(self.pieces))
        for first in range(0, len(points), block):
            chunk = points[first : first + block]
            sigma_l, dist_l = project_onto_lines(
                chunk, st["line_start"], st["line_direction"], st["line_length"]
            )
            sigma_a, dist_a = project_onto_arcs(
                chunk,
                st["arc_center"],
                st["arc_radius"],
                st["arc_axis"],
                st["arc_e1"],
                st["arc_angle"],
            )
            sigma = np.hstack([sigma_l, sigma_a])
            dist = np.hstack([dist_l, dist_a])
            owner = np.concatenate([st["lines"], st["arcs"]])
            # Order columns by piece so that ties resolve to the earliest piece.
            order = np.argsort(owner, kind="stable")
            sigma, dist, owner = sigma[:, order], dist[:, order], owner[order]
            best = np.argmin(dist, axis=1)
            rows = np.arange(len(chunk))
            s[first : first + block] = st["s_start"][owner[best]] + sigma[rows, best]
            distance[first : first + block] = dist[rows, best]
        return s, distance

    def polyline(self, ds: float) -> np.ndarray:
        """Points along the path for drawing, at most ``ds`` (m) apart, ends included.

        Returns
        -------
        numpy.ndarray
            Shape (K, 3), m.
        """
        s = [np.zeros(1)]
        for piece in self.pieces:
            n = max(1, int(np.ceil(piece.length / ds)))
            s.append(piece.s_start + piece.length * np.arange(1, n + 1) / n)
        jet, _ = evaluate_pieces(self.pieces, np.concatenate(s))
        return jet.position
