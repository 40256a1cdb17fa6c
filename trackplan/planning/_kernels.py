"""Compiled kernels of the planning package.

- :func:`assign_pieces`: the in-order assignment of samples to the candidate pieces the
  motion agrees with, in one pass over the candidate pairs; the Python API is
  :func:`trackplan.planning.tracking.locate_on_nominal`.
- :func:`peak_use`: the checker's joint-limit peaks (:mod:`trackplan.planning.checker`).
  The joint limits are read from a handful of (N, n) arrays per plan; numpy would make a
  temporary array and a separate reduction per step. The kernel reads each array once,
  row by row, in the same order of operations as the numpy expressions it replaces, so
  the results are the same to the bit.
- :func:`task_frames`: the checker's tool points, velocities, speeds and tool axes in the
  definition frame, from the tool poses in one pass (numpy would make a strided copy, a
  matrix product and a temporary per step). Each product is summed in the order of its
  terms, without fused multiply-adds: machine-independent bits, which may differ from
  numpy's BLAS products in the last bit.
"""

from __future__ import annotations

import numpy as np
from numba import njit


@njit(cache=True)
def assign_pieces(
    row: np.ndarray,
    piece: np.ndarray,
    sigma: np.ndarray,
    direction: np.ndarray,
    is_arc: np.ndarray,
    radius: np.ndarray,
    e1: np.ndarray,
    e2: np.ndarray,
    velocity: np.ndarray,
    speed: np.ndarray,
    slack: float,
    current: int,
) -> np.ndarray:  # pragma: no cover - compiled
    """Pick one candidate piece per sample, in time order, among those the motion agrees with.

    A sample near one piece keeps it; near several, those whose tangent at the candidate
    point agrees with the motion (``tangent · velocity ≥ −slack · speed``), or every one
    when none agrees. Among those kept it stays on the current piece while it remains one,
    otherwise moves to the nearest one ahead (the first one when none is ahead).

    Parameters
    ----------
    row, piece, sigma
        The candidate pairs: sample (ascending), piece (ascending within a sample) and arc
        length along the piece, m, shape (K,) each; each of the N samples has at least one.
    direction, is_arc, radius, e1, e2
        The piece table's line directions (P, 3), arc flags (P,), radii (P,) and in-plane
        axes (P, 3) each: a line's tangent is its direction, an arc's at σ is
        ``cos(σ/r) e2 − sin(σ/r) e1``.
    velocity, speed
        The samples' velocities (N, 3) and their lengths (N,).
    slack
        :data:`trackplan.planning.tracking.DIRECTION_SLACK`.
    current
        The piece of the sample before the first, or −1 to start on the first sample's
        first candidate kept.

    Returns
    -------
    numpy.ndarray
        Shape (N,): the index of each sample's pair.
    """
    n = speed.size
    chosen = np.empty(n, dtype=np.int64)
    keep = np.ones(piece.size, dtype=np.bool_)
    first = 0
    for k in range(n):
        stop = first
        while stop < row.size and row[stop] == k:
            stop += 1
        if stop - first > 1:
            floor = -slack * speed[k]
            m0, m1, m2 = velocity[k, 0], velocity[k, 1], velocity[k, 2]
            any_agrees = False
            for i in range(first, stop):
                p = piece[i]
                if is_arc[p]:
                    phi = sigma[i] / radius[p]
                    c, s = np.cos(phi), np.sin(phi)
                    t0 = c * e2[p, 0] - s * e1[p, 0]
                    t1 = c * e2[p, 1] - s * e1[p, 1]
                    t2 = c * e2[p, 2] - s * e1[p, 2]
                else:
                    t0, t1, t2 = direction[p, 0], direction[p, 1], direction[p, 2]
                # the sum in the order numpy's einsum takes over three terms
                keep[i] = (t0 * m0 + t2 * m2) + t1 * m1 >= floor
                any_agrees = any_agrees or keep[i]
            if not any_agrees:
                keep[first:stop] = True
        if current < 0:
            for i in range(first, stop):
                if keep[i]:
                    current = piece[i]
                    break
        pick = -1
        for i in range(first, stop):
            if keep[i] and piece[i] == current:
                pick = i
                break
        if pick < 0:
            for i in range(first, stop):
                if keep[i] and (pick < 0 or piece[i] > current):
                    pick = i
                    if piece[i] > current:
                        break
            current = piece[pick]
        chosen[k] = pick
        first = stop
    return chosen


@njit(cache=True)
def peak_use(
    values: np.ndarray, centre: np.ndarray, scale: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:  # pragma: no cover - compiled
    """Largest ``|values - centre| / scale`` per column, and the first row where it occurs.

    ``np.abs(values - centre) / scale`` reduced by ``max`` and ``argmax`` along the rows,
    NaN included as numpy treats it (the first NaN is the peak).

    Parameters
    ----------
    values
        Shape (M, n).
    centre, scale
        Shape (n,) each.

    Returns
    -------
    peak
        Shape (n,).
    row
        Shape (n,), int: the first row of each column's peak.
    """
    n_rows, n_cols = values.shape
    peak = np.full(n_cols, -np.inf)
    row = np.zeros(n_cols, dtype=np.int64)
    # one pass over each column: its largest |v - c|, its first row and its first NaN (the
    # running values in registers: a store per row to arrays they alias costs 3 times more)
    largest = np.full(n_cols, -np.inf)
    largest_row = np.zeros(n_cols, dtype=np.int64)
    first_nan = np.full(n_cols, -1, dtype=np.int64)
    for j in range(n_cols):
        c = centre[j]
        big = -np.inf
        big_row = 0
        nan_row = -1
        for r in range(n_rows):
            x = abs(values[r, j] - c)
            if x > big:
                big = x
                big_row = r
            elif x != x and nan_row < 0:
                nan_row = r
        largest[j], largest_row[j], first_nan[j] = big, big_row, nan_row
    for j in range(n_cols):
        s = scale[j]
        if not (0.0 < s < np.inf):  # not a positive finite scale: each quotient as numpy
            best = -np.inf
            for r in range(n_rows):
                use = abs(values[r, j] - centre[j]) / s
                if use != use or use > best:
                    best, row[j] = use, r
                    if use != use:
                        break
            peak[j] = best
            continue
        if first_nan[j] >= 0:
            peak[j], row[j] = np.nan, first_nan[j]
            continue
        if n_rows == 0:
            continue
        # dividing by s > 0 keeps the order: the largest |v - c| gives the peak, and the
        # peak's first row is the first whose quotient rounds to it (such rows lie within
        # 1e-15 of the largest and no later than the largest's first row: only those are
        # divided)
        best = largest[j] / s
        near = largest[j] * (1.0 - 1e-15)
        for r in range(largest_row[j] + 1):
            x = abs(values[r, j] - centre[j])
            if x >= near and x / s == best:
                row[j] = r
                break
        peak[j] = best
    return peak, row


@njit(cache=True)
def task_frames(
    T_base_tool: np.ndarray, T_base_part: np.ndarray, sample_time: float
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:  # pragma: no cover
    """Kernel: the tool's points, velocities, speeds and x and z axes in the definition frame.

    With ``R``, ``t`` the rotation and origin of ``T_base_part``: ``p = Rᵀ (T[:3, 3] - t)``,
    ``x = Rᵀ T[:3, 0]``, ``z = Rᵀ T[:3, 2]`` per pose, the velocity the backward difference
    of ``p`` over Ts (0 at the first sample) and the speed its length.

    Parameters
    ----------
    T_base_tool
        Tool poses, shape (N, 4, 4).
    T_base_part
        Placement of the definition frame, shape (4, 4).
    sample_time
        Ts, s.

    Returns
    -------
    points, velocity
        Shape (N, 3) each, m and m/s.
    speed
        Shape (N,), m/s.
    x_axis, z_axis
        Shape (N, 3) each.
    """
    n = T_base_tool.shape[0]
    points = np.empty((n, 3))
    velocity = np.empty((n, 3))
    speed = np.empty(n)
    x_axis = np.empty((n, 3))
    z_axis = np.empty((n, 3))
    R = T_base_part
    for k in range(n):
        T = T_base_tool[k]
        d0 = T[0, 3] - R[0, 3]
        d1 = T[1, 3] - R[1, 3]
        d2 = T[2, 3] - R[2, 3]
        for j in range(3):
            r0, r1, r2 = R[0, j], R[1, j], R[2, j]
            points[k, j] = d0 * r0 + d1 * r1 + d2 * r2
            x_axis[k, j] = T[0, 0] * r0 + T[1, 0] * r1 + T[2, 0] * r2
            z_axis[k, j] = T[0, 2] * r0 + T[1, 2] * r1 + T[2, 2] * r2
        before = max(k - 1, 0)
        for j in range(3):
            velocity[k, j] = (points[k, j] - points[before, j]) / sample_time
        v0, v1, v2 = velocity[k, 0], velocity[k, 1], velocity[k, 2]
        speed[k] = np.sqrt(v0 * v0 + v1 * v1 + v2 * v2)
    return points, velocity, speed, x_axis, z_axis
