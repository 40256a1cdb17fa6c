"""Local finite-difference stencils for the first three derivatives of a sampled function.

A joint path q(s) is known only pointwise (by IK), so its derivatives in s come from small
stencils of :data:`STENCIL_POINTS` points at spacing h. A stencil is kept inside an interval
[lo, hi] (one-sided near its ends): at a junction of a line and a G2 blend q''' jumps, and a
centred stencil across it would smear the jump.
"""

from __future__ import annotations

import numpy as np

STENCIL_POINTS = 5
"""Points of each stencil; the weights are exact for polynomials of degree 4."""


def _unit_weights() -> np.ndarray:
    """Weights at unit spacing, shape (STENCIL_POINTS offsets, 3 orders, STENCIL_POINTS)."""
    weights = np.empty((STENCIL_POINTS, 3, STENCIL_POINTS))
    for offset in range(STENCIL_POINTS):
        x = np.arange(STENCIL_POINTS, dtype=float) - offset
        powers = np.vander(x, STENCIL_POINTS, increasing=True).T  # row k: x**k
        for order, factorial in ((1, 1.0), (2, 2.0), (3, 6.0)):
            rhs = np.zeros(STENCIL_POINTS)
            rhs[order] = factorial
            weights[offset, order - 1] = np.linalg.solve(powers, rhs)
    return weights


UNIT_WEIGHTS = _unit_weights()
"""Stencil weights at unit spacing, indexed [offset of the evaluation point, order - 1, point]."""


def stencil_points(
    s: np.ndarray, lo: np.ndarray, hi: np.ndarray, h: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """Where to evaluate the function for the derivatives at ``s``.

    Parameters
    ----------
    s
        Evaluation points, shape (M,).
    lo, hi
        Interval each stencil must stay in, shape (M,) (or scalars); ``hi - lo ≥ 4 h``
        unless the interval is a point.
    h
        Stencil spacing, shape (M,) (or scalar), > 0 except on point intervals.

    Returns
    -------
    points : numpy.ndarray
        Shape (M, STENCIL_POINTS), increasing along each row.
    offset : numpy.ndarray
        Index of ``s`` among its stencil's points, shape (M,), int in 0 … 4.
    """
    s = np.asarray(s, dtype=float)
    lo, hi, h = (np.broadcast_to(np.asarray(v, dtype=float), s.shape) for v in (lo, hi, h))
    last = STENCIL_POINTS - 1
    first = np.clip(s - 2 * h, lo, np.maximum(hi - last * h, lo))
    points = first[:, None] + h[:, None] * np.arange(STENCIL_POINTS)
    safe_h = np.where(h > 0, h, 1.0)
    offset = np.clip(np.rint((s - first) / safe_h), 0, last).astype(int)
    return points, offset


def stencil_derivatives(
    values: np.ndarray, offset: np.ndarray, h: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """First, second and third derivatives from the values at :func:`stencil_points`.

    Parameters
    ----------
    values
        Function values at the stencil points, shape (M, STENCIL_POINTS, n).
    offset
        As returned by :func:`stencil_points`, shape (M,).
    h
        Stencil spacing, shape (M,) (or scalar); where it is 0 the derivatives are 0.

    Returns
    -------
    tuple of numpy.ndarray
        ``(d1, d2, d3)``, each shape (M, n).
    """
    h = np.broadcast_to(np.asarray(h, dtype=float), offset.shape)
    weights = UNIT_WEIGHTS[offset]  # (M, 3, P)
    raw = np.einsum("mdp,mpn->dmn", weights, values)  # (3, M, n)
    safe_h = np.where(h > 0, h, np.inf)[:, None]
    return raw[0] / safe_h, raw[1] / safe_h**2, raw[2] / safe_h**3
