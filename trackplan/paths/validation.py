"""Checks of the user's path segments for degenerate geometry.

The case loader calls :func:`check_segments` and turns each finding into a
:class:`~trackplan.errors.CaseError` carrying the key path.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from trackplan.paths.curves import Arc
from trackplan.paths.specs import ArcSpec, LineSpec, PointsSpec, SegmentSpec

_Checked = tuple[list[tuple[str, str]], np.ndarray]
"""Problems found (key, message) and the point where the checked segment ends."""

#: Two points closer than this are the same point (m).
LENGTH_TOLERANCE = 1e-9

#: Largest |cos| of the angle between an arc's normal and its radius.
PERPENDICULAR_TOLERANCE = 1e-6

#: Smallest |angle| of an arc (rad).
ANGLE_TOLERANCE = 1e-12

#: Largest turn between consecutive chords of a sampled curve (rad): a curve that turns
#: further doubles back on itself, which has no tangent to fit there.
MAX_POINTS_TURN = np.radians(179.0)


def _format(vector: np.ndarray) -> str:
    return "(" + ", ".join(f"{x:.6g}" for x in np.ravel(vector)) + ")"


def _as_vector(value: object, n_rows: int | None = None) -> np.ndarray | None:
    """``value`` as a finite float array of shape (3,) or (n, 3), or None."""
    try:
        array = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        return None
    shape_ok = array.shape == (3,) if n_rows is None else (array.ndim == 2 and array.shape[1] == 3)
    if not shape_ok or not np.all(np.isfinite(array)):
        return None
    return array


def _check_line(key: str, spec: LineSpec, current: np.ndarray) -> _Checked:
    to = _as_vector(spec.to)
    if to is None:
        return [(f"{key}.line.to", "must be 3 finite numbers (x, y, z) in m")], current
    if np.linalg.norm(to - current) <= LENGTH_TOLERANCE:
        message = f"line of zero length: to = {_format(to)} m is the current point"
        return [(f"{key}.line.to", message)], to
    return [], to


def _check_arc(key: str, spec: ArcSpec, current: np.ndarray) -> _Checked:
    problems: list[tuple[str, str]] = []
    center, normal = _as_vector(spec.center), _as_vector(spec.normal)
    try:
        angle = float(spec.angle)
    except (TypeError, ValueError):
        angle = float("nan")
    if center is None:
        problems.append((f"{key}.arc.center", "must be 3 finite numbers (x, y, z) in m"))
    if normal is None:
        problems.append((f"{key}.arc.normal", "must be 3 finite numbers"))
    elif np.linalg.norm(normal) <= 1e-12:
        problems.append((f"{key}.arc.normal", f"must be non-zero, got {_format(normal)}"))
        normal = None
    if not np.isfinite(angle) or abs(angle) <= ANGLE_TOLERANCE:
        problems.append(
            (f"{key}.arc.angle", f"must be a non-zero finite angle in rad, got {angle}")
        )
    if center is None or normal is None:
        return problems, current
    axis = normal / np.linalg.norm(normal)
    radius_vector = current - center
    along = float(radius_vector @ axis)
    radius = float(np.linalg.norm(radius_vector - along * axis))
    if radius <= LENGTH_TOLERANCE:
        message = (
            f"arc of zero radius: the current point {_format(current)} m lies on the axis "
            f"through the center {_format(center)} m"
        )
        problems.append((f"{key}.arc.center", message))
        return problems, current
    cosine = abs(along) / float(np.linalg.norm(radius_vector))
    if cosine > PERPENDICULAR_TOLERANCE:
        degrees = np.degrees(np.arccos(min(cosine, 1.0)))
        message = (
            f"normal {_format(normal)} is not perpendicular to the radius "
            f"{_format(radius_vector)} m from the center to the current point: "
            f"angle {degrees:.4g}°, must be 90°"
        )
        problems.append((f"{key}.arc.normal", message))
    if problems:
        return problems, current
    return problems, Arc.from_rotation(current, center, normal, angle).end


def _check_points(key: str, spec: PointsSpec, current: np.ndarray) -> _Checked:
    points = _as_vector(spec.points, n_rows=0)
    if points is None:
        return [(f"{key}.points", "must be a list of finite (x, y, z) points in m")], current
    if len(points) < 2:
        return [(f"{key}.points", f"needs at least 2 points, got {len(points)}")], current
    previous = np.vstack([current[None], points[:-1]])
    gaps = np.linalg.norm(points - previous, axis=1)
    problems = []
    for k in np.flatnonzero(gaps <= LENGTH_TOLERANCE):
        what = "the current point" if k == 0 else f"point {k - 1}"
        message = f"point {_format(points[k])} m repeats {what}: consecutive points must differ"
        problems.append((f"{key}.points[{k}]", message))
    if problems:
        return problems, points[-1]
    chords = np.diff(np.vstack([current[None], points]), axis=0)
    chords /= np.linalg.norm(chords, axis=1, keepdims=True)
    cosine = np.einsum("ij,ij->i", chords[:-1], chords[1:])
    for k in np.flatnonzero(cosine < np.cos(MAX_POINTS_TURN)):
        degrees = np.degrees(np.arccos(max(-1.0, float(cosine[k]))))
        message = (
            f"the curve doubles back at point {_format(points[k])} m (turns by {degrees:.1f}°, "
            f"more than {np.degrees(MAX_POINTS_TURN):.0f}°): end the segment at this point "
            "and continue in a new segment"
        )
        problems.append((f"{key}.points[{k}]", message))
    return problems, points[-1]


def check_segments(start: np.ndarray, segments: Sequence[SegmentSpec]) -> list[tuple[str, str]]:
    """Find degenerate geometry in a path given as segments.

    Parameters
    ----------
    start
        Start point of the path, shape (3,), m.
    segments
        The segments in order; each starts where the previous one ends.

    Returns
    -------
    list of (key, message)
        One entry per problem, in order, with the key path of the offending value:
        ``path.segments[i].line.to`` (zero-length line), ``path.segments[i].arc.center``
        (zero radius), ``path.segments[i].arc.normal`` (zero, or not perpendicular to the
        radius), ``path.segments[i].arc.angle`` (zero), ``path.segments[i].points[k]``
        (repeats the point before it), ``path.segments[i].points`` (fewer than 2 points).
        Empty when the path is sound.
    """
    current = _as_vector(start)
    if current is None:
        return [("path.start", "must be 3 finite numbers (x, y, z) in m")]
    if len(segments) == 0:
        return [("path.segments", "needs at least one segment")]
    problems: list[tuple[str, str]] = []
    for i, spec in enumerate(segments):
        key = f"path.segments[{i}]"
        if isinstance(spec, LineSpec):
            found, current = _check_line(key, spec, current)
        elif isinstance(spec, ArcSpec):
            found, current = _check_arc(key, spec, current)
        elif isinstance(spec, PointsSpec):
            found, current = _check_points(key, spec, current)
        else:
            found = [(key, f"unknown segment type {type(spec).__name__}")]
        problems.extend(found)
    return problems
