"""Smooth profiles through sampled axis positions: least-squares clamped cubic B-splines.

A profile (:class:`~trackplan.profiles.Profile`) is a clamped cubic B-spline on uniform
knots over [0, length]. :func:`fit_coefficients` fits its coefficients to samples by least
squares with a small penalty on its second derivative's coefficients (it damps wiggles
between samples, which the time law would pay for in d²q/ds² and d³q/ds³), then clips the
coefficients to the axis's range: by the convex-hull property the curve stays inside it.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from trackplan.profiles import clamped_knots
from trackplan.profiles.bspline import DEGREE

SMOOTHING = 1e-6
"""Weight of the second derivative's squared coefficients (times the knot spacing to the
fourth) against the mean squared error of the samples: a second derivative of 1 rad per
knot spacing squared costs as much as an error of 1 mrad at every sample."""


def design_matrix(s: np.ndarray, length: float, n_coefficients: int) -> Any:
    """B-spline basis of a profile with ``n_coefficients`` at ``s`` (M,): a sparse
    (M, k) matrix (four entries a row)."""
    from scipy.interpolate import BSpline  # scipy on demand (startup time)

    knots = clamped_knots(n_coefficients, length)
    return BSpline.design_matrix(np.clip(np.asarray(s, dtype=float), 0.0, length), knots, DEGREE)


def second_derivative_map(n_coefficients: int, length: float) -> np.ndarray:
    """The matrix (k − 2, k) from a profile's coefficients to those of its second
    derivative in s (a linear spline): zero for a straight line, unit / m²."""
    knots, degree = clamped_knots(n_coefficients, length), DEGREE
    D = np.eye(n_coefficients)
    for _ in range(2):  # as profile_values differentiates
        spans = (knots[degree + 1 : -1] - knots[1 : -degree - 1]) / degree
        D = np.diff(D, axis=0) / spans[:, None]
        knots, degree = knots[1:-1], degree - 1
    return D


def fit_coefficients(
    s: np.ndarray,
    values: np.ndarray,
    length: float,
    n_coefficients: int,
    lower: np.ndarray,
    upper: np.ndarray,
) -> np.ndarray:
    """Coefficients (k, n) of profiles through samples ``values`` (M, n) at ``s`` (M,),
    clipped to [lower, upper] (n,) each."""
    values = np.asarray(values, dtype=float)
    basis = design_matrix(s, length, n_coefficients)
    D = second_derivative_map(n_coefficients, length)
    spacing = length / (n_coefficients - DEGREE)
    penalty = SMOOTHING * len(s) * spacing**4
    # the normal equations: BᵀB is banded and the penalty keeps them well conditioned
    normal = (basis.T @ basis).toarray() + penalty * (D.T @ D)
    coefficients = np.linalg.solve(normal, basis.T @ values)
    clipped: np.ndarray = np.clip(coefficients, lower, upper)
    return clipped
