"""Weld normals declared on path segments: normals that turn along the seam.

A segment may carry its own surface normal (the weld's normal), which then wins over the
tool's ``normal``/``normals`` on that segment:

- an arc's ``weld_normal``: the normal at the arc's start, carried round the arc's axis
  with the point (:class:`ArcNormal`, a function of the position: exact wherever the planned
  path runs on the arc);
- a points segment's per-point normals: interpolated by a cubic spline (C2) in the
  segment's arc length through the points (:class:`PointsNormal`), then normalised.

A segment without its own normal keeps the tool's (:class:`ConstantNormal`). The fields are
evaluated at a position and at the arc length along their segment; both the nominal path
(the checker's reference) and the planned path (the orientation) use them.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, Protocol

import numpy as np

from trackplan.paths.nominal import NominalPath
from trackplan.paths.specs import ArcSpec, PointsSpec, SegmentSpec
from trackplan.tool.spec import ToolSpec

if TYPE_CHECKING:
    from scipy.interpolate import CubicSpline


class NormalField(Protocol):
    """A segment's surface normal (not normalised) at positions and segment arc lengths."""

    def __call__(self, position: np.ndarray, sigma: np.ndarray) -> np.ndarray:
        """Normals at ``position`` (M, 3), m, and arc length along the segment ``sigma``
        (M,), m, shape (M, 3)."""
        ...


@dataclass(frozen=True, eq=False)
class ConstantNormal:
    """The tool's normal, constant on the segment."""

    normal: np.ndarray

    def __call__(self, position: np.ndarray, sigma: np.ndarray) -> np.ndarray:
        return np.broadcast_to(self.normal, (len(sigma), 3)).copy()


@dataclass(frozen=True, eq=False)
class ArcNormal:
    """An arc's weld normal carried round its axis: ``a e_r + b e_t + c e_z`` at a point.

    ``e_z`` is the arc's unit axis, ``e_r`` the unit vector from the axis to the point and
    ``e_t = e_z × e_r``; (a, b, c) are the start normal's components in that frame at the
    arc's start, so the normal turns rigidly with the point (either sense of the angle).
    """

    center: np.ndarray
    axis: np.ndarray
    components: np.ndarray

    @classmethod
    def from_arc(cls, start: np.ndarray, arc: ArcSpec, weld_normal: np.ndarray) -> ArcNormal:
        """The field of ``arc`` starting at ``start`` (3,) with the normal there (3,)."""
        axis = np.asarray(arc.normal, dtype=float)
        axis = axis / np.linalg.norm(axis)
        center = np.asarray(arc.center, dtype=float)
        n = np.asarray(weld_normal, dtype=float)
        n = n / np.linalg.norm(n)
        e_r, e_t = _radial_frame(center, axis, np.asarray(start, dtype=float)[None])
        return cls(center, axis, np.array([e_r[0] @ n, e_t[0] @ n, axis @ n]))

    def __call__(self, position: np.ndarray, sigma: np.ndarray) -> np.ndarray:
        e_r, e_t = _radial_frame(self.center, self.axis, position)
        a, b, c = self.components
        return np.asarray(a * e_r + b * e_t + c * self.axis, dtype=float)


def _radial_frame(
    center: np.ndarray, axis: np.ndarray, position: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """Unit radial and circumferential directions at positions (M, 3) round an axis."""
    r = position - center
    r = r - np.outer(r @ axis, axis)
    e_r = r / np.maximum(np.linalg.norm(r, axis=1, keepdims=True), 1e-300)
    return e_r, np.cross(axis, e_r)


@dataclass(frozen=True, eq=False)
class PointsNormal:
    """Per-point normals interpolated by a cubic spline in the segment's arc length.

    The knots are the arc lengths of the points along the polyline from the segment's start
    (the current point, whose normal the spline continues from the first points, unless
    ``start_normal`` gives it, as a reversed segment does); the spline (not-a-knot ends, a
    line or parabola for two or three knots) interpolates each component, so the field is
    C2 in the arc length and exact at the points; it is normalised where it is used. Beyond
    the knots it continues as the end polynomials (blends at the ends stay smooth).
    """

    knots: np.ndarray
    spline: CubicSpline

    @classmethod
    def from_points(cls, start: np.ndarray, points: PointsSpec) -> PointsNormal:
        """The field of ``points`` (with normals) starting at ``start`` (3,)."""
        assert points.normals is not None
        vertices = np.vstack([np.asarray(start, dtype=float)[None], points.points])
        normals = np.asarray(points.normals, dtype=float)
        normals = normals / np.linalg.norm(normals, axis=1, keepdims=True)
        steps = np.linalg.norm(np.diff(vertices, axis=0), axis=1)
        knots = np.cumsum(steps)
        if points.start_normal is not None:  # a reversed segment: its start's normal is known
            first = np.asarray(points.start_normal, dtype=float)
            normals = np.vstack([first / np.linalg.norm(first), normals])
            knots = np.concatenate([[0.0], knots])
        # imported here: scipy.interpolate loads scipy's solvers, which a plan without
        # normals on points never needs (tests/test_startup.py)
        from scipy.interpolate import CubicSpline

        return cls(knots, CubicSpline(knots, normals, axis=0))

    def __call__(self, position: np.ndarray, sigma: np.ndarray) -> np.ndarray:
        return np.asarray(self.spline(sigma), dtype=float)


def declares_normals(segments: tuple[SegmentSpec, ...] | list[SegmentSpec]) -> bool:
    """Whether any segment carries its own weld normal."""
    return any(_own_normal(segment) for segment in segments)


def declared_lengths(segments: tuple[SegmentSpec, ...] | list[SegmentSpec]) -> np.ndarray:
    """Lengths of every normal declared on the segments, shape (N,) (empty without any)."""
    given = [
        np.atleast_2d(np.asarray(normal, dtype=float))
        for segment in segments
        for normal in [
            segment.weld_normal
            if isinstance(segment, ArcSpec)
            else segment.normals
            if isinstance(segment, PointsSpec)
            else None
        ]
        if normal is not None
    ]
    return np.linalg.norm(np.concatenate(given), axis=1) if given else np.zeros(0)


def _own_normal(segment: SegmentSpec) -> bool:
    if isinstance(segment, ArcSpec):
        return segment.weld_normal is not None
    return isinstance(segment, PointsSpec) and segment.normals is not None


def segment_fields(spec: ToolSpec, nominal: NominalPath) -> list[NormalField]:
    """The normal field of each segment of ``nominal``: its own, or the tool's.

    A segment without its own normal and a spec without one for it gets a zero field (the
    case loader refuses that before planning).
    """
    table = nominal.table
    fields: list[NormalField] = []
    for i, segment in enumerate(nominal.segments):
        first = int(np.flatnonzero(nominal.segment_index == i)[0])
        start = table.evaluate_on(np.array([first]), np.array([0.0])).position[0]
        if isinstance(segment, ArcSpec) and segment.weld_normal is not None:
            fields.append(ArcNormal.from_arc(start, segment, segment.weld_normal))
        elif isinstance(segment, PointsSpec) and segment.normals is not None:
            fields.append(PointsNormal.from_points(start, segment))
        elif spec.normal is None and spec.normals is None:
            fields.append(ConstantNormal(np.zeros(3)))
        else:
            fields.append(ConstantNormal(spec.segment_normals(np.array([i]))[0]))
    return fields


def segment_starts(nominal: NominalPath) -> np.ndarray:
    """Nominal arc length at the start of each segment, shape (S,), m."""
    table = nominal.table
    first = [
        int(np.flatnonzero(nominal.segment_index == i)[0]) for i in range(len(nominal.segments))
    ]
    return np.asarray(table.s_start[first], dtype=float)


def nominal_normals(
    spec: ToolSpec, nominal: NominalPath, s: np.ndarray, piece: np.ndarray
) -> np.ndarray:
    """The declared surface normal (not normalised) on the nominal path, shape (N, 3).

    At arc lengths ``s`` (N,) on pieces ``piece`` (N,): the field of the piece's segment at
    the nominal point (:func:`segment_fields`).
    """
    s = np.asarray(s, dtype=float)
    piece = np.asarray(piece, dtype=int)
    table = nominal.table
    sigma = np.clip(s - table.s_start[piece], 0.0, table.length[piece])
    position = table.evaluate_on(piece, sigma).position
    segment = nominal.segment_index[piece]
    starts = segment_starts(nominal)
    result = np.empty((len(s), 3))
    for i, field in enumerate(segment_fields(spec, nominal)):
        on = segment == i
        if on.any():
            result[on] = field(position[on], s[on] - starts[i])
    return result
