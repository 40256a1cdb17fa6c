"""Compiled kernels of the planning package: the in-order assignment of samples to pieces.

The Python API is :func:`trackplan.planning.tracking.locate_on_nominal`.
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
