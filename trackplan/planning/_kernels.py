"""Compiled kernels of the planning package.

- :func:`monotone_assignment`: the in-order assignment of samples to pieces; the Python API
  is :func:`trackplan.planning.tracking.locate_on_nominal`.
- :func:`peak_use`: the checker's joint-limit peaks (:mod:`trackplan.planning.checker`).
  The joint limits are read from a handful of (N, n) arrays per plan; numpy would make a
  temporary array and a separate reduction per step. The kernel reads each array once, in
  the same order of operations as the numpy expressions it replaces, so the results are
  the same to the bit.
"""

from __future__ import annotations

import numpy as np
from numba import njit


@njit(cache=True)
def monotone_assignment(
    bounds: np.ndarray, piece: np.ndarray, current: int
) -> np.ndarray:  # pragma: no cover
    """Pick one candidate piece per sample, in time order.

    Stays on a piece while it remains a candidate, otherwise moves to the nearest candidate
    ahead (the first candidate when none is ahead).

    Parameters
    ----------
    bounds
        Candidates of sample k are ``piece[bounds[k]:bounds[k + 1]]``, shape (N + 1,); each
        sample has at least one.
    piece
        Candidate pieces, ascending within each sample, shape (K,).
    current
        The piece of the sample before the first, or −1 to start on the first sample's
        first candidate.

    Returns
    -------
    numpy.ndarray
        Shape (N,): the index into ``piece`` of each sample's choice.
    """
    n = len(bounds) - 1
    chosen = np.empty(n, dtype=np.int64)
    if current < 0 and n > 0:
        current = piece[bounds[0]]
    for k in range(n):
        first, last = bounds[k], bounds[k + 1]
        pick = -1
        for i in range(first, last):
            if piece[i] == current:
                pick = i
                break
        if pick < 0:
            pick = first
            for i in range(first, last):
                if piece[i] > current:
                    pick = i
                    break
            current = piece[pick]
        chosen[k] = pick
    return chosen


@njit(cache=True)
def peak_use(
    values: np.ndarray, centre: np.ndarray, scale: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
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
        # dividing by s > 0 keeps the order: the largest |v - c| gives the peak, and the
        # peak's first row is the first whose quotient rounds to it (such rows lie within
        # 1e-15 of the largest: only those are divided)
        largest = -np.inf
        first_nan = -1
        for r in range(n_rows):
            x = abs(values[r, j] - centre[j])
            if x != x:
                first_nan = r
                break
            if x > largest:
                largest = x
        if first_nan >= 0:
            peak[j], row[j] = np.nan, first_nan
            continue
        if n_rows == 0:
            continue
        best = largest / s
        near = largest * (1.0 - 1e-15)
        for r in range(n_rows):
            x = abs(values[r, j] - centre[j])
            if x >= near and x / s == best:
                row[j] = r
                break
        peak[j] = best
    return peak, row
