"""Compiled kernels of the paths package: nearest pieces of points, from their nearest chunks
(or, on a path of few pieces, from every piece).

The Python API is :class:`trackplan.paths.projection.PieceIndex`; the table layout is that
of :class:`trackplan.paths.piece_table.PieceTable`. :func:`blend_parameter` is the curve
parameter of a quintic blend at arc lengths
(:meth:`trackplan.paths.curves.QuinticBlend.parameter`); :func:`piece_points` the piece,
position and tangent of a path's lines and arcs at arc lengths
(:func:`trackplan.paths.pieces.evaluate_points`).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit


@njit(cache=True, inline="always")
def project_point(
    x: np.ndarray,
    k: int,
    is_arc: np.ndarray,
    start: np.ndarray,
    direction: np.ndarray,
    length: np.ndarray,
    center: np.ndarray,
    axis: np.ndarray,
    e1: np.ndarray,
    e2: np.ndarray,
    radius: np.ndarray,
    angle: np.ndarray,
) -> tuple[float, float]:  # pragma: no cover
    """Kernel: arc length along piece ``k`` of the point nearest to ``x`` (3,), and the distance."""
    if not is_arc[k]:
        r0, r1, r2 = x[0] - start[k, 0], x[1] - start[k, 1], x[2] - start[k, 2]
        along = r0 * direction[k, 0] + r1 * direction[k, 1] + r2 * direction[k, 2]
        along = min(max(along, 0.0), length[k])
        d0 = r0 - along * direction[k, 0]
        d1 = r1 - along * direction[k, 1]
        d2 = r2 - along * direction[k, 2]
        return along, math.sqrt(d0 * d0 + d1 * d1 + d2 * d2)
    return _project_arc(
        x[0], x[1], x[2], center[k, 0], center[k, 1], center[k, 2],
        axis[k, 0], axis[k, 1], axis[k, 2], e1[k, 0], e1[k, 1], e1[k, 2],
        e2[k, 0], e2[k, 1], e2[k, 2], radius[k], angle[k],
    )  # fmt: skip


@njit(cache=True)
def _project_arc(
    x0: float, x1: float, x2: float, c0: float, c1: float, c2: float,
    a0: float, a1: float, a2: float, u0: float, u1: float, u2: float,
    v0: float, v1: float, v2: float, radius: float, angle: float,
) -> tuple[float, float]:  # pragma: no cover  # fmt: skip
    """Kernel: :func:`project_point` on an arc of centre c, axis a, in-plane unit vectors
    u (towards the start) and v, radius and angle.

    Scalars only: a call that passes no arrays costs no reference counting, so the line
    case of :func:`project_point` stays a few arithmetic operations per piece.
    """
    r0, r1, r2 = x0 - c0, x1 - c1, x2 - c2
    u = r0 * u0 + r1 * u1 + r2 * u2
    v = r0 * v0 + r1 * v1 + r2 * v2
    w = r0 * a0 + r1 * a1 + r2 * a2
    phi = math.atan2(v, u)
    if phi < 0.0:
        phi += 2.0 * math.pi
    if phi <= angle:
        return phi * radius, math.hypot(w, math.hypot(u, v) - radius)
    c, s = math.cos(angle), math.sin(angle)
    f0 = x0 - (c0 + radius * u0)
    f1 = x1 - (c1 + radius * u1)
    f2 = x2 - (c2 + radius * u2)
    l0 = x0 - (c0 + radius * (c * u0 + s * v0))
    l1 = x1 - (c1 + radius * (c * u1 + s * v1))
    l2 = x2 - (c2 + radius * (c * u2 + s * v2))
    first = f0 * f0 + f1 * f1 + f2 * f2
    last = l0 * l0 + l1 * l1 + l2 * l2
    if last < first:
        return angle * radius, math.sqrt(last)
    return 0.0, math.sqrt(first)


@njit(cache=True)
def dense_pieces(
    points: np.ndarray,
    slack: float,
    is_arc: np.ndarray,
    start: np.ndarray,
    direction: np.ndarray,
    length: np.ndarray,
    center: np.ndarray,
    axis: np.ndarray,
    e1: np.ndarray,
    e2: np.ndarray,
    arc_radius: np.ndarray,
    angle: np.ndarray,
) -> tuple[
    np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray
]:  # pragma: no cover
    """Kernel: the pieces within ``slack`` of the nearest piece of each point, every piece
    projected (a path of few pieces: no tree).

    Parameters
    ----------
    points
        Shape (B, 3), m, finite.
    slack
        m.
    is_arc, start, direction, length, center, axis, e1, e2, arc_radius, angle
        The piece table (P pieces).

    Returns
    -------
    bounds
        Pairs of point b are ``bounds[b]:bounds[b + 1]``, shape (B + 1,).
    piece, sigma, distance
        The pairs: piece (ascending within a point), arc length along it and distance, m.
    nearest
        Distance of each point from the whole path, shape (B,), m.
    row
        The point of each pair, shape (K,).
    """
    n = points.shape[0]
    n_pieces = length.shape[0]
    bounds = np.zeros(n + 1, dtype=np.int64)
    out_row = np.empty(n * n_pieces, dtype=np.int64)
    out_piece = np.empty(n * n_pieces, dtype=np.int64)
    out_sigma = np.empty(n * n_pieces)
    out_distance = np.empty(n * n_pieces)
    nearest = np.empty(n)
    sigmas = np.empty(n_pieces)
    distances = np.empty(n_pieces)
    used = 0
    for b in range(n):
        bounds[b] = used
        closest = np.inf
        for k in range(n_pieces):
            sigmas[k], distances[k] = project_point(
                points[b], k, is_arc, start, direction, length, center, axis, e1, e2,
                arc_radius, angle,
            )  # fmt: skip
            closest = min(closest, distances[k])
        nearest[b] = closest
        for k in range(n_pieces):
            if distances[k] > closest + slack:
                continue
            out_row[used] = b
            out_piece[used] = k
            out_sigma[used] = sigmas[k]
            out_distance[used] = distances[k]
            used += 1
    bounds[n] = used
    return (
        bounds, out_piece[:used], out_sigma[:used], out_distance[:used], nearest, out_row[:used]
    )  # fmt: skip


@njit(cache=True)
def near_pieces(
    points: np.ndarray,
    chunk_distance: np.ndarray,
    chunk_index: np.ndarray,
    radius: np.ndarray,
    skip: np.ndarray,
    slack: float,
    pad: float,
    chunk_piece: np.ndarray,
    half: np.ndarray,
    is_arc: np.ndarray,
    start: np.ndarray,
    direction: np.ndarray,
    length: np.ndarray,
    center: np.ndarray,
    axis: np.ndarray,
    e1: np.ndarray,
    e2: np.ndarray,
    arc_radius: np.ndarray,
    angle: np.ndarray,
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:  # pragma: no cover
    """Kernel: the pieces within ``slack`` of the nearest piece of each point.

    Parameters
    ----------
    points
        Shape (B, 3), m.
    chunk_distance, chunk_index
        The K nearest chunk midpoints of each point, ascending (B, K) (inf and C past the
        last chunk).
    radius
        Ball radius of each point (B,), m: chunks farther away are not looked at.
    skip
        Points left out (their ball holds more than K chunks), shape (B,) bool.
    slack, pad
        m; relative padding of the radii.
    chunk_piece, half
        Piece (C,) and half-length (C,), m, of each chunk.
    is_arc, start, direction, length, center, axis, e1, e2, arc_radius, angle
        The piece table.

    Returns
    -------
    bounds
        Pairs of point b are ``bounds[b]:bounds[b + 1]``, shape (B + 1,).
    piece, sigma, distance
        The pairs: piece (ascending within a point), arc length along it and distance, m.
    """
    n, k_max = chunk_index.shape
    bounds = np.zeros(n + 1, dtype=np.int64)
    out_piece = np.empty(n * k_max, dtype=np.int64)
    out_sigma = np.empty(n * k_max)
    out_distance = np.empty(n * k_max)
    found = np.empty(k_max, dtype=np.int64)
    sigmas = np.empty(k_max)
    distances = np.empty(k_max)
    used = 0
    for b in range(n):
        bounds[b] = used
        if skip[b]:
            continue
        first = chunk_distance[b, 0]
        count = 0
        for j in range(k_max):
            gap = chunk_distance[b, j]
            if gap > radius[b]:
                break
            c = chunk_index[b, j]
            if gap > (first + slack + half[c]) * (1.0 + pad) + pad * (slack + half[c]) + 1e-15:
                continue
            p = chunk_piece[c]
            seen = False
            for i in range(count):
                if found[i] == p:
                    seen = True
                    break
            if not seen:
                found[count] = p
                count += 1
        nearest = np.inf
        for i in range(count):
            sigmas[i], distances[i] = project_point(
                points[b],
                found[i],
                is_arc,
                start,
                direction,
                length,
                center,
                axis,
                e1,
                e2,
                arc_radius,
                angle,
            )
            nearest = min(nearest, distances[i])
        for i in range(count):  # the kept pairs, in ascending piece order (insertion)
            if distances[i] > nearest + slack:
                continue
            at = used
            while at > bounds[b] and out_piece[at - 1] > found[i]:
                out_piece[at] = out_piece[at - 1]
                out_sigma[at] = out_sigma[at - 1]
                out_distance[at] = out_distance[at - 1]
                at -= 1
            out_piece[at] = found[i]
            out_sigma[at] = sigmas[i]
            out_distance[at] = distances[i]
            used += 1
    bounds[n] = used
    return bounds, out_piece[:used], out_sigma[:used], out_distance[:used]


@njit(cache=True)
def fit_deviation(
    vertices: np.ndarray,
    n_sub: int,
    s_start: np.ndarray,
    is_arc: np.ndarray,
    start: np.ndarray,
    direction: np.ndarray,
    length: np.ndarray,
    center: np.ndarray,
    axis: np.ndarray,
    e1: np.ndarray,
    e2: np.ndarray,
    radius: np.ndarray,
    angle: np.ndarray,
    limit: float,
) -> tuple[float, float]:  # pragma: no cover
    """Kernel: distances between a few curves laid end to end and the polyline ``vertices``.

    The bound of :func:`trackplan.paths.fitting.fit_deviation`: each vertex is projected onto
    the curves; the curves are cut at those projections (made monotone) and each part is
    compared with its own polyline segment at ``n_sub`` sub-intervals, plus the sagitta of a
    sub-interval at the largest curvature.

    Parameters
    ----------
    vertices
        The polyline, shape (n, 3), m, n ≥ 2.
    n_sub
        Sub-intervals per polyline segment.
    s_start, is_arc, start, direction, length, center, axis, e1, e2, radius, angle
        The curves as a piece table (P rows), ``s_start`` their arc length from 0.
    limit
        m: the work stops as soon as a distance exceeds it (the values returned then
        exceed ``limit`` but are not the largest).

    Returns
    -------
    vertex_distance
        Largest distance of a vertex from the curves, m.
    curve_distance
        Upper bound of the largest distance of a curve point from the polyline, m.
    """
    n = vertices.shape[0]
    n_pieces = length.shape[0]
    total = s_start[n_pieces - 1] + length[n_pieces - 1]
    sigma = np.empty(n)
    vertex_distance = 0.0
    running = -np.inf
    for v in range(n):
        nearest = np.inf
        along = 0.0
        for k in range(n_pieces):
            s, d = project_point(
                vertices[v],
                k,
                is_arc,
                start,
                direction,
                length,
                center,
                axis,
                e1,
                e2,
                radius,
                angle,
            )
            if d < nearest:
                nearest, along = d, s_start[k] + s
        vertex_distance = max(vertex_distance, nearest)
        running = max(running, along)
        sigma[v] = min(max(running, 0.0), total)
    sigma[0], sigma[n - 1] = 0.0, total
    if vertex_distance > limit:
        return vertex_distance, 0.0
    kappa = 0.0
    for k in range(n_pieces):
        if is_arc[k]:
            kappa = max(kappa, 1.0 / radius[k])
    bound = 0.0
    point = np.empty(3)
    for v in range(n - 1):
        a, b = sigma[v], sigma[v + 1]
        step = (b - a) / n_sub
        sagitta = 0.0
        if kappa > 0.0:
            sagitta = (1.0 - math.cos(0.5 * min(kappa * step, math.pi))) / kappa
        c0 = vertices[v + 1, 0] - vertices[v, 0]
        c1 = vertices[v + 1, 1] - vertices[v, 1]
        c2 = vertices[v + 1, 2] - vertices[v, 2]
        chord2 = c0 * c0 + c1 * c1 + c2 * c2
        previous = 0.0
        for i in range(n_sub + 1):
            s = a + (b - a) * (i / n_sub)
            k = 0
            for j in range(1, n_pieces):
                if s >= s_start[j]:
                    k = j
            local = min(max(s - s_start[k], 0.0), length[k])
            if is_arc[k]:
                phi = local / radius[k]
                cos_phi, sin_phi = math.cos(phi), math.sin(phi)
                for m in range(3):
                    point[m] = center[k, m] + radius[k] * (cos_phi * e1[k, m] + sin_phi * e2[k, m])
            else:
                for m in range(3):
                    point[m] = start[k, m] + local * direction[k, m]
            r0 = point[0] - vertices[v, 0]
            r1 = point[1] - vertices[v, 1]
            r2 = point[2] - vertices[v, 2]
            t = min(max((r0 * c0 + r1 * c1 + r2 * c2) / chord2, 0.0), 1.0)
            d0, d1, d2 = r0 - t * c0, r1 - t * c1, r2 - t * c2
            gap = math.sqrt(d0 * d0 + d1 * d1 + d2 * d2)
            if i > 0:
                bound = max(bound, max(previous, gap) + sagitta)
            previous = gap
        if bound > limit:
            break
    return vertex_distance, bound


@njit(cache=True, inline="always")
def _horner(coefficients: np.ndarray, x: float) -> float:  # pragma: no cover
    """Kernel: the polynomial with ascending ``coefficients`` at ``x`` (numpy's polyval)."""
    value: float = coefficients[-1]
    for i in range(coefficients.size - 2, -1, -1):
        value = coefficients[i] + value * x
    return value


@njit(cache=True, inline="always")
def _blend_arc_length(
    u: float,
    breaks: np.ndarray,
    cumulative: np.ndarray,
    speed_squared: np.ndarray,
    nodes: np.ndarray,
    weights: np.ndarray,
) -> float:  # pragma: no cover
    """Kernel: arc length from 0 to ``u``: the panel table, then Gauss–Legendre in the panel."""
    n_panels = breaks.size - 1
    panel = min(int(u * n_panels), n_panels - 1)
    lower = breaks[panel]
    half = 0.5 * (u - lower)
    partial = 0.0
    for i in range(nodes.size):
        partial += math.sqrt(_horner(speed_squared, lower + half * (nodes[i] + 1.0))) * weights[i]
    length: float = cumulative[panel] + half * partial
    return length


@njit(cache=True)
def blend_parameter(
    sigma: np.ndarray,
    breaks: np.ndarray,
    cumulative: np.ndarray,
    speed_squared: np.ndarray,
    nodes: np.ndarray,
    weights: np.ndarray,
) -> np.ndarray:  # pragma: no cover
    """Kernel: the curve parameter u (M,) of a quintic blend at arc lengths ``sigma`` (M,).

    Each point starts from the cubic Hermite interpolant of u(S) on the panel table
    (``breaks``, ``cumulative``; du/dS = 1 / speed) and takes Newton steps until one is
    below 1e-9 m, then one more (it lands at rounding level); at most 30.
    """
    n_table = breaks.size
    slope = np.empty(n_table)
    for k in range(n_table):
        slope[k] = 1.0 / math.sqrt(_horner(speed_squared, breaks[k]))
    length = cumulative[-1]
    out = np.empty(sigma.size)
    for m in range(sigma.size):
        target = min(max(sigma[m], 0.0), length)
        k = np.searchsorted(cumulative, target, side="right") - 1
        k = min(max(k, 0), n_table - 2)
        width = cumulative[k + 1] - cumulative[k]
        x = (target - cumulative[k]) / width
        x2, x3 = x * x, x * x * x
        u = (
            (2 * x3 - 3 * x2 + 1) * breaks[k]
            + (x3 - 2 * x2 + x) * width * slope[k]
            + (-2 * x3 + 3 * x2) * breaks[k + 1]
            + (x3 - x2) * width * slope[k + 1]
        )
        for _ in range(30):
            arc = _blend_arc_length(u, breaks, cumulative, speed_squared, nodes, weights)
            step = (arc - target) / math.sqrt(_horner(speed_squared, u))
            u = min(max(u - step, 0.0), 1.0)
            if abs(step) < 1e-9:
                arc = _blend_arc_length(u, breaks, cumulative, speed_squared, nodes, weights)
                step = (arc - target) / math.sqrt(_horner(speed_squared, u))
                u = min(max(u - step, 0.0), 1.0)
                break
        out[m] = u
    return out


LINE_KIND = 0
ARC_KIND = 1
OTHER_KIND = 2
"""Piece kinds of :func:`piece_points`: its own arithmetic for lines and arcs; any other
piece (a blend) is left to the caller."""


@njit(cache=True)
def piece_points(
    s: np.ndarray,
    s_start: np.ndarray,
    length: np.ndarray,
    kind: np.ndarray,
    origin: np.ndarray,
    first: np.ndarray,
    second: np.ndarray,
    radius: np.ndarray,
    position: np.ndarray,
    tangent: np.ndarray,
) -> np.ndarray:  # pragma: no cover - compiled
    """Kernel: the piece of each arc length, and the position and unit tangent on lines and arcs.

    The piece of ``s[m]`` is the last whose start is ≤ it (the first one below the first
    start, the last one for NaN: numpy's ``searchsorted(side="right") - 1`` clipped); its
    arc length ``σ`` is ``s[m] - s_start`` clipped to [0, length]. A line (``origin`` its
    start, ``first`` its direction) gives ``origin + σ first`` and ``first``; an arc
    (``origin`` its centre, ``first`` and ``second`` its e1 and e2, ``radius``) gives
    ``origin + radius (cos φ e1 + sin φ e2)`` and ``cos φ e2 − sin φ e1``, φ = σ / radius:
    the operations of :meth:`trackplan.paths.curves.Line.point_tangent` and
    :meth:`~trackplan.paths.curves.Arc.point_tangent`, elementwise, so the same bits.
    Rows on other pieces are not written.

    Parameters
    ----------
    s
        Arc lengths, shape (M,), m.
    s_start, length
        Start and length of each piece, shape (P,), m (``s_start`` increasing).
    kind
        :data:`LINE_KIND`, :data:`ARC_KIND` or :data:`OTHER_KIND` per piece, shape (P,).
    origin, first, second
        Shape (P, 3) each, as above (unused entries any value).
    radius
        Shape (P,), m.
    position, tangent
        Outputs, shape (M, 3) each.

    Returns
    -------
    numpy.ndarray
        The piece of each arc length, shape (M,), int.
    """
    n_pieces = s_start.size
    index = np.empty(s.size, dtype=np.int64)
    for m in range(s.size):
        x = s[m]
        if x != x:
            k = n_pieces - 1
        else:
            lo, hi = 0, n_pieces
            while lo < hi:  # the first start above x
                mid = (lo + hi) // 2
                if s_start[mid] <= x:
                    lo = mid + 1
                else:
                    hi = mid
            k = max(lo - 1, 0)
        index[m] = k
        if kind[k] == OTHER_KIND:
            continue
        sigma = x - s_start[k]
        if sigma < 0.0:
            sigma = 0.0
        elif sigma > length[k]:
            sigma = length[k]
        if kind[k] == LINE_KIND:
            for j in range(3):
                position[m, j] = origin[k, j] + sigma * first[k, j]
                tangent[m, j] = first[k, j]
        else:
            phi = sigma / radius[k]
            c = math.cos(phi)
            n = math.sin(phi)
            for j in range(3):
                radial = c * first[k, j] + n * second[k, j]
                position[m, j] = origin[k, j] + radius[k] * radial
                tangent[m, j] = c * second[k, j] - n * first[k, j]
    return index
