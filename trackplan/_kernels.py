"""Compiled kernels of the top-level modules.

- :func:`backward_differences`: the backward differences of a sampled joint motion in one
  pass; the Python API is :func:`trackplan.derivatives.backward_derivatives`. numpy makes
  the padded copy and three difference arrays before dividing; the kernel reads each sample
  once and does the same subtractions and divisions, so the results are the same to the bit.
- :func:`read_only`: the read-only view a kernel's input arrays are passed as, so that a
  kernel compiles once whoever made its inputs.
"""

from __future__ import annotations

import numpy as np
from numba import njit


def read_only(array: np.ndarray) -> np.ndarray:
    """``array`` itself when it is read-only, else a read-only view of it (no copy).

    numba compiles one version of a kernel per writable flag of each array argument (and
    compiling is most of a first run's time, docs/benchmarks.md): the same case data are
    read-only in the process that loaded the case and writable in a worker that unpickled
    them, a cached array is read-only and a fresh one writable. Passing a kernel's inputs
    through this gives it one version.
    """
    if not array.flags.writeable:
        return array
    view = array.view()
    view.flags.writeable = False
    return view


@njit(cache=True, error_model="numpy")
def backward_differences(
    q: np.ndarray, head: int, tail: int, ts1: float, ts2: float, ts3: float
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:  # pragma: no cover - compiled
    """Kernel: velocity, acceleration and jerk by backward differences of q (N, n).

    The sequence is q with ``head`` copies of q[0] before it and ``tail`` copies of
    q[-1] after it (``head`` ≥ 3); row r of each output is its difference ending at padded
    row ``r + 3``, divided by ``ts1``, ``ts2``, ``ts3`` (Ts, Ts², Ts³).

    Returns
    -------
    tuple of numpy.ndarray
        Each shape (N + head + tail − 3, n).
    """
    n_rows, n = q.shape
    rows = n_rows + head + tail - 3
    qd = np.empty((rows, n))
    qdd = np.empty((rows, n))
    qddd = np.empty((rows, n))
    for r in range(rows):
        i0 = min(max(r - head, 0), n_rows - 1)  # padded rows r … r + 3
        i1 = min(max(r + 1 - head, 0), n_rows - 1)
        i2 = min(max(r + 2 - head, 0), n_rows - 1)
        i3 = min(max(r + 3 - head, 0), n_rows - 1)
        for j in range(n):
            f0 = q[i1, j] - q[i0, j]
            f1 = q[i2, j] - q[i1, j]
            f2 = q[i3, j] - q[i2, j]
            s0 = f1 - f0
            s1 = f2 - f1
            qd[r, j] = f2 / ts1
            qdd[r, j] = s1 / ts2
            qddd[r, j] = (s1 - s0) / ts3
    return qd, qdd, qddd
