"""Trade one downhand angle for the other where "straight up" breaks the slope bound.

The closed form (:mod:`trackplan.axes.pointwise`) turns the weld normal exactly up. When
the normal is not square to the travel direction (a seam climbing across a surface, a
normal blended between two segments), the travel then slopes by the angle between them,
which may exceed the slope bound while a lean of the normal within the rotation bound
would bring the slope inside it. :func:`polish` moves the positioner's angles at such
samples by a damped Gauss–Newton (Levenberg–Marquardt) iteration on the two excesses
``max(0, rotation − rotation_bound)`` and ``max(0, slope − slope_bound)``, batched over
the samples, with a forward-difference Jacobian.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

ITERATIONS = 30
"""Gauss–Newton steps at most."""
STEP = 1e-7
"""Forward-difference step of the Jacobian, rad."""
DAMPING = 1e-9
"""Levenberg–Marquardt damping added to JᵀJ's diagonal, rad⁻² (keeps singular steps finite)."""


def polish(
    angles: Callable[[np.ndarray], tuple[np.ndarray, np.ndarray]],
    start: np.ndarray,
    slope_bound: float,
    rotation_bound: float,
) -> np.ndarray:
    """Positioner angles (K, n) near ``start`` (K, n) whose slope and rotation are within
    the bounds (rad) where some are: the excesses driven to zero.

    ``angles(e)`` gives the slope and rotation (K,) each at angles e (K, n) of the K
    samples, in order.
    """
    e = np.array(start, dtype=float)
    K, n = e.shape

    def excess(values: np.ndarray) -> np.ndarray:
        slope, rotation = angles(values)
        return np.stack(
            [np.maximum(rotation - rotation_bound, 0.0), np.maximum(slope - slope_bound, 0.0)],
            axis=1,
        )

    r = excess(e)
    for _ in range(ITERATIONS):
        if not np.any(r > 0.0):
            break
        J = np.empty((K, 2, n))
        for j in range(n):  # n axes (two or three), each a batched evaluation
            shifted = e.copy()
            shifted[:, j] += STEP
            J[:, :, j] = (excess(shifted) - r) / STEP
        JtJ = np.einsum("kij,kil->kjl", J, J) + DAMPING * np.eye(n)
        step = np.linalg.solve(JtJ, -np.einsum("kij,ki->kj", J, r)[..., None])[..., 0]
        step = np.where(np.any(r > 0.0, axis=1)[:, None], step, 0.0)
        e = e + step
        r = excess(e)
    return e
