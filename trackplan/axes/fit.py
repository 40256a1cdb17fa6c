"""Smooth profiles through sampled axis positions: least-squares clamped cubic B-splines.

A profile (:class:`~trackplan.profiles.Profile`) is a clamped cubic B-spline on uniform
knots over [0, length]. :class:`SplineFit` fits its coefficients to samples by least
squares with a penalty on its second derivative (the heavier, the flatter the motion where
the samples leave room; the lightest only damps wiggles between samples, which the time law
would pay for in d²q/ds² and d³q/ds³), then clips the coefficients to the axis's range: by
the convex-hull property the curve stays inside it.
"""

from __future__ import annotations

from dataclasses import dataclass
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


def derivative_map(n_coefficients: int, length: float, order: int) -> np.ndarray:
    """The matrix (k − order, k) from a profile's coefficients to those of its
    ``order``-th derivative in s (a spline of degree 3 − order), unit / m^order."""
    knots, degree = clamped_knots(n_coefficients, length), DEGREE
    D = np.eye(n_coefficients)
    for _ in range(order):  # as profile_values differentiates
        spans = (knots[degree + 1 : -1] - knots[1 : -degree - 1]) / degree
        D = np.diff(D, axis=0) / spans[:, None]
        knots, degree = knots[1:-1], degree - 1
    return D


@dataclass(frozen=True, eq=False)
class SplineFit:
    """Least-squares fits of profiles with k coefficients to samples at fixed arc lengths.

    Attributes
    ----------
    s_fit
        Arc lengths of the fitted samples, shape (M,), m.
    s_check
        Arc lengths at which :meth:`fit` evaluates the fitted profiles, shape (C,), m.
    length
        Length of the profiles' range, m.
    n_coefficients
        k.
    """

    s_fit: np.ndarray
    s_check: np.ndarray
    length: float
    n_coefficients: int

    @property
    def _maps(self) -> tuple[Any, Any, np.ndarray, np.ndarray]:
        cached = self.__dict__.get("_cache")
        if cached is None:
            k, length = self.n_coefficients, self.length
            basis = design_matrix(self.s_fit, length, k)
            check = design_matrix(self.s_check, length, k)
            cached = (basis, check, derivative_map(k, length, 1), derivative_map(k, length, 2))
            self.__dict__["_cache"] = cached
        return cached  # type: ignore[no-any-return]

    def fit(
        self,
        values: np.ndarray,
        lower: np.ndarray,
        upper: np.ndarray,
        smoothing: float = SMOOTHING,
    ) -> tuple[np.ndarray, np.ndarray]:
        """Coefficients (k, n) of profiles through ``values`` (M, n) at :attr:`s_fit`,
        clipped to [lower, upper] (n,) each, and the profiles at :attr:`s_check` (C, n)."""
        basis, check, _, D2 = self._maps
        spacing = self.length / (self.n_coefficients - DEGREE)
        penalty = smoothing * len(self.s_fit) * spacing**4
        # the normal equations: BᵀB is banded and the penalty keeps them well conditioned
        normal = (basis.T @ basis).toarray() + penalty * (D2.T @ D2)
        coefficients = np.linalg.solve(normal, basis.T @ np.asarray(values, dtype=float))
        clipped: np.ndarray = np.clip(coefficients, lower, upper)
        return clipped, np.asarray(check @ clipped)

    def rate_bounds(self, coefficients: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Bounds of |d e/ds| and |d²e/ds²| over [0, length] per profile (n,) each: the
        largest coefficient of each derivative (convex hull; exact for the second, whose
        spline is linear between its coefficients)."""
        _, _, D1, D2 = self._maps
        return np.abs(D1 @ coefficients).max(axis=0), np.abs(D2 @ coefficients).max(axis=0)


def fit_coefficients(
    s: np.ndarray,
    values: np.ndarray,
    length: float,
    n_coefficients: int,
    lower: np.ndarray,
    upper: np.ndarray,
    smoothing: float = SMOOTHING,
) -> np.ndarray:
    """Coefficients (k, n) of profiles through samples ``values`` (M, n) at ``s`` (M,),
    clipped to [lower, upper] (n,) each; ``smoothing`` weighs the second derivative."""
    s = np.asarray(s, dtype=float)
    fitter = SplineFit(s, s, length, n_coefficients)
    return fitter.fit(values, lower, upper, smoothing)[0]
