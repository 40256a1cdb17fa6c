"""The paper's objective (Eq. 8): weighted joint travel."""

from __future__ import annotations

import numpy as np


def joint_travel(q: np.ndarray, weights: np.ndarray) -> np.ndarray:
    """``J = Σ_k Σ_i C_i |q_i(k) − q_i(k−1)|`` (Eq. 8).

    Parameters
    ----------
    q
        Joint paths, shape (..., N, n), rad.
    weights
        C_i, shape (n,).

    Returns
    -------
    numpy.ndarray
        J, shape (...), rad (weighted).
    """
    steps = np.abs(np.diff(np.asarray(q, dtype=float), axis=-2))
    return np.einsum("...kn,n->...", steps, np.asarray(weights, dtype=float))
