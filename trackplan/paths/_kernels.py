"""Compiled kernels of the paths package: nearest pieces of points, from their nearest chunks
(or, on a path of few pieces, from every piece).

The Python API is :class:`trackplan.paths.projection.PieceIndex`; the table layout is that
of :class:`trackplan.paths.piece_table.PieceTable`.
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
    r0, r1, r2 = x[0] - center[k, 0], x[1] - center[k, 1], x[2] - center[k, 2]
    u = r0 * e1[k, 0] + r1 * e1[k, 1] + r2 * e1[k, 2]
    v = r0 * e2[k, 0] + r1 * e2[k, 1] + r2 * e2[k, 2]
    w = r0 * axis[k, 0] + r1 * axis[k, 1] + r2 * axis[k, 2]
    phi = math.atan2(v, u)
    if phi < 0.0:
        phi += 2.0 * math.pi
    if phi <= angle[k]:
        return phi * radius[k], math.hypot(w, math.hypot(u, v) - radius[k])
    c, s = math.cos(angle[k]), math.sin(angle[k])
    first = 0.0
    last = 0.0
    for i in range(3):
        a = x[i] - (center[k, i] + radius[k] * e1[k, i])
        b = x[i] - (center[k, i] + radius[k] * (c * e1[k, i] + s * e2[k, i]))
        first += a * a
        last += b * b
    if last < first:
        return angle[k] * radius[k], math.sqrt(last)
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
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:  # pragma: no cover
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
    """
    n = points.shape[0]
    n_pieces = length.shape[0]
    bounds = np.zeros(n + 1, dtype=np.int64)
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
            out_piece[used] = k
            out_sigma[used] = sigmas[k]
            out_distance[used] = distances[k]
            used += 1
    bounds[n] = used
    return bounds, out_piece[:used], out_sigma[:used], out_distance[:used], nearest


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
