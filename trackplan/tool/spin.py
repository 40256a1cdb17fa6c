"""The tool's spin about its own axis: a free profile (:mod:`trackplan.profiles`).

The names here are those the spin has always had; each is the free-profile mechanism's:
a :class:`SpinProfile` is a :class:`trackplan.profiles.Profile` in rad over the planned
path's arc length, and :func:`spin_free_profile` gives the :class:`~trackplan.profiles.FreeProfile`
of a spin mode.
"""

from __future__ import annotations

import enum

import numpy as np

from trackplan.profiles import (
    DEGREE,
    FreeProfile,
    Profile,
    clamped_knots,
    increment_spans,
    profile_values,
)

SPIN_COEFFICIENTS = 6
"""B-spline coefficients of a ``free-varying`` spin profile (clamped cubic, uniform knots)."""
SPIN_DEGREE = DEGREE
"""Degree of the spin profile."""
DEFAULT_SPIN_RATE = 20.0
"""Largest |d spin / ds| of a ``free-varying`` profile when the case gives none, rad/m."""

SpinProfile = Profile
"""Spin about the tool axis along the planned path, rad: one chosen free profile."""

spin_knots = clamped_knots
"""Clamped uniform knot vector of a spin profile (:func:`trackplan.profiles.clamped_knots`)."""

__all__ = [
    "DEFAULT_SPIN_RATE",
    "SPIN_COEFFICIENTS",
    "SPIN_DEGREE",
    "SpinMode",
    "SpinProfile",
    "increment_spans",
    "spin_free_profile",
    "spin_knots",
    "spin_values",
]


class SpinMode(enum.StrEnum):
    """How the spin about the tool axis is chosen."""

    FIXED = "fixed"
    FREE = "free"
    FREE_VARYING = "free-varying"


def spin_free_profile(
    mode: SpinMode, value: float, spin_range: tuple[float, float], rate: float
) -> FreeProfile:
    """The free profile of a spin mode.

    Parameters
    ----------
    mode
        ``fixed``: no node, the spin is ``value``; ``free``: one node in ``spin_range``;
        ``free-varying``: :data:`SPIN_COEFFICIENTS` nodes in ``spin_range``.
    value
        The spin of ``fixed``, rad.
    spin_range
        (lo, hi) of every node, rad.
    rate
        Largest |d spin / ds| of ``free-varying``, rad/m.
    """
    nodes = {SpinMode.FIXED: 0, SpinMode.FREE: 1}.get(mode, SPIN_COEFFICIENTS)
    lo, hi = spin_range
    return FreeProfile(nodes, np.asarray(lo), np.asarray(hi), rate=rate, fixed=value)


def spin_values(coefficients: np.ndarray, s: np.ndarray, length: float) -> np.ndarray:
    """Spins of B profiles at arc lengths ``s``.

    Parameters
    ----------
    coefficients
        Shape (B, k), rad (k = 1: constant spins).
    s
        Arc lengths, shape (M,), m.
    length
        Length of the planned path, m.

    Returns
    -------
    numpy.ndarray
        Shape (B, M), rad.
    """
    return profile_values(coefficients, s, length)
