"""Segmentation of a sampled curve into lines and arcs (a G1 arc spline of biarcs).

The paper holds that "any curve can be divided into lines and arcs". A polyline through
sampled points is covered greedily by biarcs: from the current vertex and tangent, the
biarc (two arcs meeting tangentially, equal tangent lengths) to vertex j ending along the
estimated tangent there reaches as far as it can within the fitting tolerance; the next
biarc starts with that tangent. A smooth sampled curve therefore becomes a few arcs that
are all tangent-continuous: their junctions are only G1 (the curvature jumps) and get mild
blends. The tangent at a vertex is that of the circle through it and its two neighbours.

Where not even the next vertex can be reached along the current tangent, the polyline has
a real corner there: the chain restarts with the tangent of the circle through the corner
and the next two vertices (or, failing that, with a line to the next vertex), so the
corner stays a corner and is blended like any other. Consecutive lines on one line, or
arcs on one circle, are merged.

The bound on the distance from the fit to the polyline is rigorous: the fit is split at
the nearest points of the polyline's vertices and each part is compared with its own
polyline segment only, in a few sub-arcs. Along a chord the distance to a segment is
convex, so it peaks at the chord's ends, and a sub-arc of curvature ≤ κ and length h lies
within (1 − cos(κh/2))/κ of its chord. Hence: distance ≤ max over sub-arc ends + that.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np

from trackplan.paths import _kernels as kernels
from trackplan.paths.curves import COLLINEAR_ANGLE, Arc, Line, Primitive, end_jet, unit
from trackplan.paths.piece_table import PieceTable

# Sub-intervals per polyline segment when bounding the distance of a fit from the polyline.
_SAMPLES_PER_SEGMENT = 4

# Largest half-turn (rad) of an arc of a biarc: beyond a half circle it is no fit.
_MAX_HALF_TURN = 0.5 * np.pi - 1e-6


@dataclass(frozen=True, eq=False)
class PolylineFit:
    """Lines and arcs covering a polyline, end to end.

    Attributes
    ----------
    curves
        The primitives in order, from the first vertex to the last.
    spans
        First and last polyline vertex of the stretch each curve belongs to, shape
        (n_curves, 2) (the two arcs of a biarc share their stretch).
    deviation
        Upper bound of each curve's distance from the polyline, shape (n_curves,), m.
    """

    curves: tuple[Primitive, ...]
    spans: np.ndarray
    deviation: np.ndarray


def vertex_tangents(vertices: np.ndarray) -> np.ndarray:
    """Unit tangents (K, 3) at the vertices (K, 3) of a polyline, K ≥ 2.

    At an interior vertex, the tangent of the circle through it and its neighbours; at an
    end, that of the circle through the end and the next two vertices (the chord for K = 2
    or where the three are collinear).
    """
    n = len(vertices)
    if n == 2:
        return np.tile(unit(vertices[1] - vertices[0]), (2, 1))
    middle = np.clip(np.arange(n), 1, n - 2)
    a, b, c = vertices[middle - 1], vertices[middle], vertices[middle + 1]
    u, v = b - a, c - a
    w = np.cross(u, v)
    w2 = np.sum(w * w, axis=1)
    straight = np.sqrt(w2) <= 1e-12 * np.linalg.norm(u, axis=1) * np.linalg.norm(v, axis=1)
    w2 = np.where(straight, 1.0, w2)[:, None]
    uu, vv = np.sum(u * u, axis=1)[:, None], np.sum(v * v, axis=1)[:, None]
    center = a + (uu * np.cross(v, w) + vv * np.cross(w, u)) / (2.0 * w2)
    # The circle a → b → c turns right-handedly about w: its tangent at p is w × (p − centre).
    tangent = np.cross(w, vertices - center)
    norm = np.linalg.norm(tangent, axis=1, keepdims=True)
    tangent = tangent / np.where(straight[:, None], 1.0, norm)
    return np.where(straight[:, None], unit(c - a), tangent)


def biarc(
    start: np.ndarray, t0: np.ndarray, end: np.ndarray, t1: np.ndarray
) -> list[Primitive] | None:
    """The equal-tangent-length biarc from ``start`` along ``t0`` to ``end`` along ``t1``.

    Parameters
    ----------
    start, end
        Shape (3,), m, distinct.
    t0, t1
        Unit tangents (3,) at the ends.

    Returns
    -------
    list of Line or Arc, or None
        Two curves meeting tangentially (a line where an arc would be straight), or None
        when no such biarc exists or an arc would turn half a circle.
    """
    chord = end - start
    tangent_sum = t0 + t1
    along = float(chord @ tangent_sum)
    a = 2.0 * (1.0 - float(t0 @ t1))
    root = along * along + a * float(chord @ chord)
    if root < 0.0 or along + np.sqrt(root) <= 0.0:
        return None
    # α solves a α² + 2 (v·(t0 + t1)) α − |v|² = 0, in the form free of cancellation.
    alpha = float(chord @ chord) / (along + np.sqrt(root))
    q0, q1 = start + alpha * t0, end - alpha * t1
    middle = 0.5 * (q0 + q1)
    curves: list[Primitive] = []
    for a_point, tangent, b_point in ((start, t0, middle), (middle, unit(q1 - q0), end)):
        gap = b_point - a_point
        if float(np.linalg.norm(gap)) <= 1e-15 * float(np.linalg.norm(chord)):
            continue
        half_turn = np.arctan2(np.linalg.norm(np.cross(tangent, gap)), tangent @ gap)
        if half_turn > _MAX_HALF_TURN:
            return None
        curves.append(Arc.from_tangent(a_point, tangent, b_point))
    return curves


def fit_deviation(
    curves: Sequence[Primitive], vertices: np.ndarray, limit: float = np.inf
) -> tuple[float, float]:
    """Distances between curves laid end to end and the polyline ``vertices`` (n, 3), m.

    The bound of the module docstring, by the compiled kernel
    :func:`trackplan.paths._kernels.fit_deviation`: O(n · len(curves)) time, O(n) memory.

    Parameters
    ----------
    curves
        Lines and arcs end to end, from the first vertex to the last.
    vertices
        The polyline, shape (n, 3), m, n ≥ 2.
    limit
        m: the work stops once a distance exceeds it; one of the values returned then
        exceeds ``limit``, but they need not be the largest.

    Returns
    -------
    vertex_distance
        Largest distance of a vertex from the curves, m.
    curve_distance
        Upper bound of the largest distance of a curve point from the polyline, m.
    """
    table = PieceTable.from_curves(curves)
    s_start = np.concatenate([[0.0], np.cumsum(table.length)])[:-1]
    vertex_distance, curve_distance = kernels.fit_deviation(
        np.ascontiguousarray(vertices, dtype=float),
        _SAMPLES_PER_SEGMENT,
        s_start,
        table.is_arc,
        table.start,
        table.direction,
        table.length,
        table.center,
        table.axis,
        table.e1,
        table.e2,
        table.radius,
        table.angle,
        float(limit),
    )
    return float(vertex_distance), float(curve_distance)


def _longest(
    vertices: np.ndarray,
    first: int,
    make: Callable[[int], list[Primitive] | None],
    tolerance: float,
) -> tuple[int, list[Primitive], float]:
    """The farthest vertex reachable by ``make(j)`` from ``first`` within ``tolerance``.

    Gallops (1, 2, 4, … vertices ahead) to a failure, then bisects. Returns the last vertex
    index reached (``first`` if none), its curves and their deviation bound.
    """
    best: tuple[int, list[Primitive], float] = (first, [], 0.0)

    def attempt(last: int) -> bool:
        nonlocal best
        curves = make(last)
        if not curves:
            return False
        vertex_distance, curve_distance = fit_deviation(
            curves, vertices[first : last + 1], tolerance
        )
        if max(vertex_distance, curve_distance) > tolerance:
            return False
        best = (last, curves, curve_distance)
        return True

    n_last = len(vertices) - 1
    good, step = first, 1
    bad = n_last + 1
    while good < n_last:
        trial = min(first + step, n_last)
        if not attempt(trial):
            bad = trial
            break
        good, step = trial, 2 * step
    while bad - good > 1:
        middle = (good + bad) // 2
        if attempt(middle):
            good = middle
        else:
            bad = middle
    return best


def _same_geometry(a: Primitive, b: Primitive) -> bool:
    """Whether ``b`` continues ``a`` on the same line or circle."""
    if isinstance(a, Line) and isinstance(b, Line):
        return float(np.linalg.norm(np.cross(a.direction, b.direction))) <= COLLINEAR_ANGLE
    if isinstance(a, Arc) and isinstance(b, Arc):
        scale = 1e-12 * a.radius
        return (
            abs(a.radius - b.radius) <= scale
            and float(np.linalg.norm(a.center - b.center)) <= scale
            and float(np.linalg.norm(a.axis - b.axis)) <= 1e-12
        )
    return False


def _merge(a: Primitive, b: Primitive) -> Primitive:
    """One curve for ``a`` followed by ``b`` on the same line or circle."""
    if isinstance(a, Line):
        return Line.between(a.start, b.end)
    return Arc(a.center, a.radius, a.axis, a.e1, a.angle + b.length / a.radius)


def fit_polyline(vertices: np.ndarray, tolerance: float) -> PolylineFit:
    """Cover a polyline with tangent-continuous lines and arcs where it is smooth.

    Parameters
    ----------
    vertices
        The polyline, shape (K, 3), K ≥ 2, m; consecutive vertices distinct.
    tolerance
        Largest distance between the fit and the polyline (both ways: vertices from the
        fit and fit points from the polyline), m.

    Returns
    -------
    PolylineFit
        Primitives from the first to the last vertex, end to end.
    """
    vertices = np.asarray(vertices, dtype=float)
    estimates = vertex_tangents(vertices)
    curves: list[Primitive] = []
    spans: list[tuple[int, int]] = []
    deviation: list[float] = []

    def biarcs_from(first: int, tangent: np.ndarray) -> tuple[int, list[Primitive], float]:
        def make(last: int) -> list[Primitive] | None:
            return biarc(vertices[first], tangent, vertices[last], estimates[last])

        return _longest(vertices, first, make, tolerance)

    first = 0
    tangent = estimates[0]
    while first < len(vertices) - 1:
        last, found, bound = biarcs_from(first, tangent)
        if not found:
            # A corner at this vertex: restart along the circle through it and the next two.
            last, found, bound = biarcs_from(first, vertex_tangents(vertices[first : first + 3])[0])
        if not found:
            last, found, bound = (
                first + 1,
                [Line.between(vertices[first], vertices[first + 1])],
                0.0,
            )
        for curve in found:
            if curves and _same_geometry(curves[-1], curve):
                curves[-1] = _merge(curves[-1], curve)
                spans[-1] = (spans[-1][0], last)
                deviation[-1] = max(deviation[-1], bound)
            else:
                curves.append(curve)
                spans.append((first, last))
                deviation.append(bound)
        tangent = end_jet(curves[-1]).tangent[0]
        first = last
    return PolylineFit(tuple(curves), np.array(spans), np.array(deviation))
