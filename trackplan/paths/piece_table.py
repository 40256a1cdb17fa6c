"""Lines and arcs end to end, stacked in arrays: one row per piece.

A path of a sampled curve has as many pieces as points (a million in a scanned seam), too
many for one Python object each. :class:`PieceTable` holds them as arrays, is built from a
polyline without a loop, and evaluates and projects pairs of (point, piece) vectorised.
The formulas are those of :class:`~trackplan.paths.curves.Line` and
:class:`~trackplan.paths.curves.Arc`, so the values agree to round-off.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from trackplan._kernels import read_only
from trackplan.paths.curves import Arc, CurveJet, Line, Primitive


@dataclass(frozen=True, eq=False)
class PieceTable:
    """P lines and arcs laid end to end from s = 0.

    Attributes
    ----------
    s_start, length
        Path arc length at the start of each piece and its length, shape (P,), m.
    is_arc
        Shape (P,) bool.
    start
        Start point of each piece, shape (P, 3), m.
    direction
        Unit direction of a line, shape (P, 3) (zero on arcs).
    center, axis, e1, e2
        Of an arc (:class:`~trackplan.paths.curves.Arc`), shape (P, 3) each (zero on lines).
    radius, angle
        Of an arc, m and rad, shape (P,) each (1 and 0 on lines).
    """

    s_start: np.ndarray
    length: np.ndarray
    is_arc: np.ndarray
    start: np.ndarray
    direction: np.ndarray
    center: np.ndarray
    axis: np.ndarray
    e1: np.ndarray
    e2: np.ndarray
    radius: np.ndarray
    angle: np.ndarray

    @classmethod
    def from_polyline(cls, vertices: np.ndarray) -> PieceTable:
        """The lines between consecutive ``vertices`` (K, 3), m, K ≥ 2, each pair distinct."""
        vertices = np.asarray(vertices, dtype=float)
        chord = np.diff(vertices, axis=0)
        length = np.sqrt(np.einsum("ij,ij->i", chord, chord))
        return cls._lines(vertices[:-1], chord / length[:, None], length)

    @classmethod
    def from_curves(cls, curves: Sequence[Primitive]) -> PieceTable:
        """The table of ``curves`` (lines and arcs) laid end to end."""
        n = len(curves)
        table = cls._lines(np.zeros((n, 3)), np.zeros((n, 3)), np.zeros(n))
        for k, curve in enumerate(curves):
            table.length[k] = curve.length
            table.start[k] = curve.start
            if isinstance(curve, Line):
                table.direction[k] = curve.direction
            else:
                table.is_arc[k] = True
                table.center[k], table.axis[k] = curve.center, curve.axis
                table.e1[k], table.e2[k] = curve.e1, curve.e2
                table.radius[k], table.angle[k] = curve.radius, curve.angle
        return table

    @classmethod
    def _lines(cls, start: np.ndarray, direction: np.ndarray, length: np.ndarray) -> PieceTable:
        n = len(length)
        zeros = np.zeros((n, 3))
        return cls(
            np.zeros(n),
            length,
            np.zeros(n, dtype=bool),
            start,
            direction,
            zeros,
            zeros.copy(),
            zeros.copy(),
            zeros.copy(),
            np.ones(n),
            np.zeros(n),
        )

    @classmethod
    def concatenate(cls, tables: Sequence[PieceTable]) -> PieceTable:
        """The pieces of ``tables`` in order, laid end to end from s = 0."""
        fields = {
            name: np.concatenate([getattr(table, name) for table in tables])
            for name in cls.__dataclass_fields__
        }
        fields["s_start"] = np.concatenate([[0.0], np.cumsum(fields["length"])])[:-1]
        for value in fields.values():
            value.flags.writeable = False
        return cls(**fields)

    def kernel_arrays(self) -> tuple[np.ndarray, ...]:
        """``is_arc, start, direction, length, center, axis, e1, e2, radius, angle`` as the
        path kernels take them (:mod:`trackplan.paths._kernels`), read-only
        (:func:`~trackplan._kernels.read_only`: one compiled version of each kernel)."""
        return tuple(
            read_only(array)
            for array in (
                self.is_arc, self.start, self.direction, self.length, self.center,
                self.axis, self.e1, self.e2, self.radius, self.angle,
            )
        )  # fmt: skip

    @property
    def n_pieces(self) -> int:
        """P."""
        return len(self.length)

    @property
    def total_length(self) -> float:
        """Arc length of the whole chain, m."""
        return float(self.s_start[-1] + self.length[-1])

    def curve(self, k: int) -> Primitive:
        """Piece ``k`` as a :class:`~trackplan.paths.curves.Line` or ``Arc``."""
        if self.is_arc[k]:
            return Arc(
                self.center[k],
                float(self.radius[k]),
                self.axis[k],
                self.e1[k],
                float(self.angle[k]),
            )
        return Line(self.start[k], self.direction[k], float(self.length[k]))

    def piece_at(self, s: np.ndarray) -> np.ndarray:
        """Piece (M,) of each arc length ``s`` (M,), m; a junction belongs to the later piece."""
        index = np.searchsorted(self.s_start, np.asarray(s, dtype=float), side="right") - 1
        return np.clip(index, 0, self.n_pieces - 1)

    def evaluate_on(self, piece: np.ndarray, sigma: np.ndarray) -> CurveJet:
        """Position and arc-length derivatives on pieces ``piece`` (M,) at their own arc
        lengths ``sigma`` (M,), m (not clipped)."""
        piece = np.asarray(piece, dtype=int)
        sigma = np.asarray(sigma, dtype=float)
        arc = self.is_arc[piece]
        position = self.start[piece] + sigma[:, None] * self.direction[piece]
        tangent = self.direction[piece].copy()
        curvature = np.zeros_like(position)
        derivative = np.zeros_like(position)
        if arc.any():
            k = piece[arc]
            radius = self.radius[k][:, None]
            phi = sigma[arc][:, None] / radius
            e1, e2 = self.e1[k], self.e2[k]
            radial = np.cos(phi) * e1 + np.sin(phi) * e2
            along = np.cos(phi) * e2 - np.sin(phi) * e1
            position[arc] = self.center[k] + radius * radial
            tangent[arc] = along
            curvature[arc] = -radial / radius
            derivative[arc] = -along / radius**2
        return CurveJet(position, tangent, curvature, derivative)

    def tangent_on(self, piece: np.ndarray, sigma: np.ndarray) -> np.ndarray:
        """Unit tangents (M, 3) on pieces ``piece`` (M,) at their arc lengths ``sigma`` (M,), m."""
        piece = np.asarray(piece, dtype=int)
        tangent: np.ndarray = self.direction[piece]
        arc = self.is_arc[piece]
        if arc.any():
            k = piece[arc]
            phi = np.asarray(sigma, dtype=float)[arc][:, None] / self.radius[k][:, None]
            tangent[arc] = np.cos(phi) * self.e2[k] - np.sin(phi) * self.e1[k]
        return tangent

    def evaluate(self, s: np.ndarray) -> tuple[CurveJet, np.ndarray]:
        """Position and derivatives at path arc lengths ``s`` (M,), m, and the piece of each (M,).

        A value on a junction belongs to the later piece, the total length to the last one.
        """
        s = np.asarray(s, dtype=float)
        piece = self.piece_at(s)
        sigma = np.clip(s - self.s_start[piece], 0.0, self.length[piece])
        return self.evaluate_on(piece, sigma), piece

    def end_tangents(self) -> np.ndarray:
        """Unit tangent at the end of each piece, shape (P, 3)."""
        tangent = self.direction.copy()
        arc = np.flatnonzero(self.is_arc)
        if arc.size:
            # φ = length / radius, as Arc.evaluate computes it at σ = length.
            phi = ((self.radius[arc] * self.angle[arc]) / self.radius[arc])[:, None]
            tangent[arc] = np.cos(phi) * self.e2[arc] - np.sin(phi) * self.e1[arc]
        return tangent

    def start_tangents(self) -> np.ndarray:
        """Unit tangent at the start of each piece, shape (P, 3)."""
        return np.where(self.is_arc[:, None], self.e2, self.direction)

    def project_on(self, points: np.ndarray, piece: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Nearest points of M points, each on its own piece.

        For an arc of more than one turn the first turn is reported (the distance is the same),
        as :func:`~trackplan.paths.curves.project_onto_arcs` does.

        Parameters
        ----------
        points
            Shape (M, 3), m.
        piece
            Index of the piece for each point, shape (M,).

        Returns
        -------
        sigma
            Arc length of the nearest point along its piece, shape (M,), m.
        distance
            Distance to it, shape (M,), m.
        """
        points = np.asarray(points, dtype=float)
        piece = np.asarray(piece, dtype=int)
        sigma = np.empty(len(piece))
        distance = np.empty(len(piece))
        arc = self.is_arc[piece]
        line = ~arc
        if line.any():
            k = piece[line]
            rel = points[line] - self.start[k]
            direction = self.direction[k]
            along = np.clip(np.einsum("nk,nk->n", rel, direction), 0.0, self.length[k])
            sigma[line] = along
            distance[line] = np.linalg.norm(rel - along[:, None] * direction, axis=-1)
        if arc.any():
            k = piece[arc]
            p = points[arc]
            center, radius, angle = self.center[k], self.radius[k], self.angle[k]
            e1, e2, axis = self.e1[k], self.e2[k], self.axis[k]
            rel = p - center
            x = np.einsum("nk,nk->n", rel, e1)
            y = np.einsum("nk,nk->n", rel, e2)
            z = np.einsum("nk,nk->n", rel, axis)
            phi = np.mod(np.arctan2(y, x), 2.0 * np.pi)
            inside = phi <= angle
            d_inside = np.hypot(z, np.hypot(x, y) - radius)
            first = center + radius[:, None] * e1
            last = center + radius[:, None] * (
                np.cos(angle)[:, None] * e1 + np.sin(angle)[:, None] * e2
            )
            d_first = np.linalg.norm(p - first, axis=-1)
            d_last = np.linalg.norm(p - last, axis=-1)
            at_end = d_last < d_first
            sigma[arc] = np.where(inside, phi, np.where(at_end, angle, 0.0)) * radius
            distance[arc] = np.where(inside, d_inside, np.minimum(d_first, d_last))
        return sigma, distance
