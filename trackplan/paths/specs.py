"""Path segment specifications: the path as the user gives it, in the definition frame.

These are plain data read from a case file; :mod:`trackplan.paths` turns them into
geometry. Lengths in metres, angles in radians.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True, eq=False)
class LineSpec:
    """A straight line from the current point to ``to``, shape (3,)."""

    to: np.ndarray


@dataclass(frozen=True, eq=False)
class ArcSpec:
    """A circular arc: right-hand rotation of the current point by ``angle`` about the
    axis through ``center`` (3,) along ``normal`` (3,). ``angle`` may exceed 2π."""

    center: np.ndarray
    normal: np.ndarray
    angle: float


@dataclass(frozen=True, eq=False)
class PointsSpec:
    """A sampled curve from the current point through ``points``, shape (K, 3)."""

    points: np.ndarray


SegmentSpec = LineSpec | ArcSpec | PointsSpec
