"""Points of a curved stretch of a planned path whose polyline stays within a chord error.

A Cartesian program writes a blend (or any stretch that is neither a line nor an arc) as
a spline through points of the planned path; a language without a spline writes linear
moves through the same points. :func:`spline_points` chooses those points so that the
polyline between them keeps within a given distance of the curve, and
:func:`chord_errors` measures that distance, both vectorised over the points.
"""

from __future__ import annotations

import numpy as np

from trackplan.paths.planned import Path

CHORD_SUBSAMPLES = 32
"""Curve points checked inside each chord (the largest distance is that of these)."""

CHORD_SAFETY = 0.95
"""Share of the asked chord error the points aim at (the measure is a sampled maximum)."""

DENSE_STEP = 2e-4
"""Step of the dense curvature sample that spaces the points, m."""

MAX_REFINEMENTS = 30
"""Rounds of adding points before giving up on a chord error (never reached on a path
whose curvature is bounded)."""


def chord_errors(path: Path, s: np.ndarray) -> np.ndarray:
    """The largest distance of the curve from each chord between consecutive points.

    Parameters
    ----------
    path
        The planned path.
    s
        Arc lengths of the points, strictly increasing, shape (M,), m.

    Returns
    -------
    numpy.ndarray
        Shape (M − 1,), m: for chord k, the largest distance of the curve between
        ``s[k]`` and ``s[k + 1]`` (at :data:`CHORD_SUBSAMPLES` points) from the segment
        joining the curve's points there.
    """
    s = np.asarray(s, dtype=float)
    if len(s) < 2:
        return np.zeros(0)
    u = np.linspace(0.0, 1.0, CHORD_SUBSAMPLES + 1)
    inner = s[:-1, None] + (s[1:] - s[:-1])[:, None] * u[None, :]  # (M-1, K+1)
    _, points, _ = path.points(inner.ravel())
    points = points.reshape(*inner.shape, 3)
    start, end = points[:, :1, :], points[:, -1:, :]
    chord = end - start
    length2 = np.maximum(np.sum(chord * chord, axis=-1), 1e-300)  # (M-1, 1)
    along = np.clip(np.sum((points - start) * chord, axis=-1) / length2, 0.0, 1.0)
    nearest = start + along[..., None] * chord
    distance = np.linalg.norm(points - nearest, axis=-1)
    worst: np.ndarray = distance.max(axis=1)
    return worst


def spline_points(path: Path, s0: float, s1: float, chord: float) -> tuple[np.ndarray, float]:
    """Arc lengths of points on ``[s0, s1]`` whose polyline keeps within ``chord``.

    The points are spaced by the curvature κ(s) (a chord of length l on a curve of
    curvature κ leaves it by about κ l²/8): their number density is √(κ / 8 c); their
    count grows until every chord's measured error (:func:`chord_errors`) is within the
    bound.

    Parameters
    ----------
    path
        The planned path.
    s0, s1
        The stretch, m, ``s0 ≤ s1`` (an empty one is its end point).
    chord
        The largest distance of the polyline from the curve, m, > 0.

    Returns
    -------
    s
        Arc lengths of the points after ``s0``, shape (M,), m, increasing, ending on
        ``s1``.
    error
        The largest chord error reached, m.
    """
    if not s1 > s0:
        return np.array([s1]), 0.0
    n_dense = max(64, int(np.ceil((s1 - s0) / DENSE_STEP)))
    dense = np.linspace(s0, s1, n_dense + 1)
    kappa = np.linalg.norm(path.sample(dense).curvature, axis=1)
    density = np.sqrt(kappa / (8.0 * CHORD_SAFETY * chord)) + 1e-9
    cumulative = np.concatenate(
        [[0.0], np.cumsum(0.5 * (density[1:] + density[:-1]) * np.diff(dense))]
    )
    count = max(1, int(np.ceil(cumulative[-1])))
    for _ in range(MAX_REFINEMENTS):
        levels = np.linspace(0.0, cumulative[-1], count + 1)
        s = np.interp(levels, cumulative, dense)
        s[0], s[-1] = s0, s1
        s = np.unique(s)
        errors = chord_errors(path, s)
        worst = float(errors.max()) if len(errors) else 0.0
        if worst <= chord:
            return s[1:], worst
        count = int(np.ceil(count * max(1.2, np.sqrt(worst / (CHORD_SAFETY * chord)))))
    return s[1:], worst


__all__ = ["chord_errors", "spline_points"]
