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
  matrix product and a temporary per step), and the tool's points between the samples
  from the joints (FK by :func:`trackplan.robots._kernels.chain_block`, without building
  their poses). Each product is summed in the order of its terms, without fused
  multiply-adds: machine-independent bits, which may differ from numpy's BLAS products in
  the last bit.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from trackplan.robots._kernels import FK_BLOCK, chain_block


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


@njit(cache=True, inline="always")
def _tool_point(T: np.ndarray, tail: np.ndarray, r: int, b: int) -> float:  # pragma: no cover
    """Kernel: row r of the tool point of configuration b of a :func:`chain_block` block,
    summed as :func:`~trackplan.robots._kernels.fk_flat` sums it."""
    point = T[4 * r, b] * tail[0, 3] + T[4 * r + 1, b] * tail[1, 3] + T[4 * r + 2, b] * tail[2, 3]
    return float(point + T[4 * r + 3, b])


@njit(cache=True)
def task_frames(
    T_base_tool: np.ndarray,
    T_base_part: np.ndarray,
    sample_time: float,
    chain: np.ndarray,
    tail: np.ndarray,
    q: np.ndarray,
    chord_step: float,
    max_parts: int,
) -> tuple[
    np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray
]:  # pragma: no cover - compiled
    """Kernel: the tool's points, velocities, speeds and x and z axes in the definition frame,
    and its points between the samples.

    With ``R``, ``t`` the rotation and origin of ``T_base_part``: ``p = Rᵀ (T[:3, 3] - t)``,
    ``x = Rᵀ T[:3, 0]``, ``z = Rᵀ T[:3, 2]`` per pose, the velocity the backward difference
    of ``p`` over Ts (0 at the first sample) and the speed its length.

    Between samples k and k + 1 the joints are interpolated linearly at the fractions j / m_k
    (j = 1 … m_k − 1) of the period, m_k = ⌈|p_k+1 − p_k| / chord_step⌉ clipped to
    [2, max_parts] (2 where the chord is NaN): the tool's points there are the FK of
    ``q_k + (j / m_k)(q_k+1 − q_k)`` (:func:`trackplan.robots._kernels.chain_block`, the
    arithmetic of :func:`~trackplan.robots._kernels.fk_flat` over blocks of the same
    configurations) placed in the definition frame as above: the same bits as FK of the
    interpolated joints and the points of their poses, without the poses.

    Parameters
    ----------
    T_base_tool
        Tool poses, shape (N, 4, 4).
    T_base_part
        Placement of the definition frame, shape (4, 4).
    sample_time
        Ts, s.
    chain, tail
        The robot's kernel chain (n, 4, 4) and tail (4, 4)
        (:attr:`trackplan.robots.model.Robot.kernel_chain`).
    q
        Joint positions at the samples, shape (N, n), rad (``T_base_tool`` is their FK).
    chord_step
        Largest chord between checked points, m (> 0).
    max_parts
        Most parts of one period.

    Returns
    -------
    points, velocity
        Shape (N, 3) each, m and m/s.
    speed
        Shape (N,), m/s.
    x_axis, z_axis
        Shape (N, 3) each.
    between
        The tool's points between the samples, shape (K,  3), m (none when N < 2).
    t_between
        Their times in periods from the first sample, ``k + j / m_k``, shape (K,).
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

    # the parts of each period, from its chord
    n_periods = max(n - 1, 0)
    parts = np.empty(n_periods, dtype=np.int64)
    n_between = 0
    for k in range(n_periods):
        c0 = points[k + 1, 0] - points[k, 0]
        c1 = points[k + 1, 1] - points[k, 1]
        c2 = points[k + 1, 2] - points[k, 2]
        m_k = np.ceil(np.sqrt(c0 * c0 + c1 * c1 + c2 * c2) / chord_step)
        if m_k != m_k or m_k < 2.0:
            m_k = 2.0
        elif m_k > max_parts:
            m_k = float(max_parts)
        parts[k] = int(m_k)
        n_between += parts[k] - 1
    between = np.empty((n_between, 3))
    t_between = np.empty(n_between)
    n_dof = q.shape[1]
    angle = np.zeros((n_dof, FK_BLOCK))
    cos = np.empty((n_dof, FK_BLOCK))
    sin = np.empty((n_dof, FK_BLOCK))
    T_block = np.empty((12, FK_BLOCK))
    k = 0  # the period of the next point and its index j in it
    j = 1
    for start in range(0, n_between, FK_BLOCK):
        m = min(FK_BLOCK, n_between - start)
        for b in range(m):
            fraction = j / parts[k]
            t_between[start + b] = k + fraction
            for i in range(n_dof):
                angle[i, b] = q[k, i] + fraction * (q[k + 1, i] - q[k, i])
            j += 1
            if j == parts[k]:
                k += 1
                j = 1
        chain_block(chain, angle, m, cos, sin, T_block)
        for b in range(m):  # the pose's point as fk_flat, then as the samples' above
            d0 = _tool_point(T_block, tail, 0, b) - R[0, 3]
            d1 = _tool_point(T_block, tail, 1, b) - R[1, 3]
            d2 = _tool_point(T_block, tail, 2, b) - R[2, 3]
            for c in range(3):
                between[start + b, c] = d0 * R[0, c] + d1 * R[1, c] + d2 * R[2, c]
    return points, velocity, speed, x_axis, z_axis, between, t_between
