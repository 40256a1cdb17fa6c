"""Joint derivatives as a controller consuming the samples sees them (docs/conventions.md)."""

from __future__ import annotations

import numpy as np

from trackplan._kernels import backward_differences

REST_PADDING = 3
"""Samples at rest appended after the last one: the robot stays still after the trajectory,
so the first three backward differences past the end are checked too."""


def backward_derivatives(
    q: np.ndarray, sample_time: float, pad_end: bool = False
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Velocity, acceleration and jerk by backward differences at Ts, at rest before the start.

    ``qd[k] = (q[k] - q[k-1]) / Ts`` with ``q[-1] = q[0]``, and likewise for the higher
    differences (``np.diff(q, n) / Ts**n`` of the sequence padded with the rest state).

    Parameters
    ----------
    q
        Positions, shape (N, n) (or (N,) for a scalar signal).
    sample_time
        Ts, s.
    pad_end
        Also return the :data:`REST_PADDING` samples after the end, where the robot holds
        ``q[-1]`` (shape (N + 3, n) instead of (N, n)).

    Returns
    -------
    tuple of numpy.ndarray
        ``(qd, qdd, qddd)`` in unit/s, unit/s², unit/s³.
    """
    q = np.asarray(q, dtype=float)
    if not len(q):
        return np.zeros(q.shape), np.zeros(q.shape), np.zeros(q.shape)
    columns = np.ascontiguousarray(q.reshape(len(q), -1))
    tail = REST_PADDING if pad_end else 0
    found = backward_differences(
        columns, REST_PADDING, tail, sample_time, sample_time**2, sample_time**3
    )
    return tuple(d.reshape(-1, *q.shape[1:]) for d in found)  # type: ignore[return-value]
