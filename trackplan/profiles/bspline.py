"""Clamped cubic B-splines on uniform knots over a path parameter s ∈ [0, length].

The curve of every free profile (:mod:`trackplan.profiles`): its knots, the spans that bound
its rate by the convex-hull property, and its values and derivatives for many coefficient
sets at many s at once (a design matrix product, no loop over samples).
"""

from __future__ import annotations

import numpy as np

DEGREE = 3
"""Degree of a profile's B-spline."""
MAX_ORDER = 2
"""Highest derivative with respect to s that :func:`profile_values` evaluates."""


def clamped_knots(n_coefficients: int, length: float) -> np.ndarray:
    """Clamped uniform knot vector of a cubic B-spline on [0, length].

    Parameters
    ----------
    n_coefficients
        k, the number of coefficients: 1 (a constant, no knots) or at least ``DEGREE + 1``.
    length
        Length of the path parameter's range, m.

    Returns
    -------
    numpy.ndarray
        Shape (k + 4,), m (shape (0,) for a constant).
    """
    if n_coefficients == 1:
        return np.zeros(0)
    inner = np.linspace(0.0, length, n_coefficients - DEGREE + 1)
    return np.concatenate([[0.0] * DEGREE, inner, [length] * DEGREE])


def increment_spans(n_coefficients: int, length: float) -> np.ndarray:
    """``(t_{i+4} − t_{i+1}) / 3`` of a profile's knots, shape (k − 1,), m.

    The first derivative's B-spline coefficients are ``(c_{i+1} − c_i) / span_i``, so
    ``|c_{i+1} − c_i| ≤ rate · span_i`` for every i bounds the profile's |d value / ds| by rate.
    """
    t = clamped_knots(n_coefficients, length)
    i = np.arange(n_coefficients - 1)
    spans: np.ndarray = (t[i + DEGREE + 1] - t[i + 1]) / DEGREE
    return spans


def profile_values(
    coefficients: np.ndarray, s: np.ndarray, length: float, order: int = 0
) -> np.ndarray:
    """Values, or a derivative with respect to s, of B profiles at ``s``.

    Parameters
    ----------
    coefficients
        Shape (B, k), in the profile's unit (k = 1: constant profiles).
    s
        Path parameter, shape (M,), m; clipped to [0, length].
    length
        Length of the path parameter's range, m.
    order
        0: the values; 1 or 2: the first or second derivative (unit / m, unit / m²).

    Returns
    -------
    numpy.ndarray
        Shape (B, M).
    """
    if not 0 <= order <= MAX_ORDER:
        raise ValueError(f"derivative order {order} outside [0, {MAX_ORDER}]")
    c = np.atleast_2d(np.asarray(coefficients, dtype=float))
    s = np.asarray(s, dtype=float)
    if c.shape[1] == 1:
        if order > 0:
            return np.zeros((len(c), s.size))
        return np.broadcast_to(c, (len(c), s.size)).copy()
    from scipy.interpolate import BSpline  # only varying profiles need scipy (startup time)

    knots = clamped_knots(c.shape[1], length)
    degree = DEGREE
    for _ in range(order):  # the derivative of a B-spline is one of a degree less
        spans = (knots[degree + 1 : -1] - knots[1 : -degree - 1]) / degree
        c = np.diff(c, axis=1) / spans
        knots, degree = knots[1:-1], degree - 1
    basis = BSpline.design_matrix(np.clip(s, 0.0, length), knots, degree).toarray()
    values: np.ndarray = c @ basis.T
    return values
