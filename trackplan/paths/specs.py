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
    axis through ``center`` (3,) along ``normal`` (3,). ``angle`` may exceed 2π.

    ``weld_normal`` (3,): the weld's surface normal at the arc's start, carried round the
    arc's axis with the point (None: the tool's ``normal``/``normals`` hold on the arc)."""

    center: np.ndarray
    normal: np.ndarray
    angle: float
    weld_normal: np.ndarray | None = None


@dataclass(frozen=True, eq=False)
class PointsSpec:
    """A sampled curve from the current point through ``points``, shape (K, 3).

    ``normals`` (K, 3): the weld's surface normal at each point, interpolated along the
    curve (None: the tool's normal holds); ``start_normal`` (3,) is the current point's
    (None: continued from the first points' normals)."""

    points: np.ndarray
    normals: np.ndarray | None = None
    start_normal: np.ndarray | None = None


SegmentSpec = LineSpec | ArcSpec | PointsSpec
