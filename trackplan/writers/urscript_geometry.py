"""The numbers a URScript program is written in: poses as rotation vectors, blend radii
that do not overlap, the orientation mode of ``movec`` and the ``servoj`` period.

Units are URScript's own: m, rad, s (Universal Robots, URScript manual, module motion:
"a pose ... the first 3 coordinates is a position vector and the last 3 an axis-angle").
See ``docs/export-urscript.md``.
"""

from __future__ import annotations

import math
from fractions import Fraction

import numpy as np

from trackplan.errors import CaseError
from trackplan.writers.numbers import fixed

BLEND_SHARE = 0.4
"""A blend radius is at most this share of the distance to the waypoint before and to the
one after it. Universal Robots' user manual (e-Series and CB3, "Blend parameters"): "Blends
cannot overlap, so it is not possible to set a blend radius that overlaps with the blend
radius of a previous or following waypoint"; two neighbours each at 40 % of their distance
leave 20 % of it free (RoboDK's UR post-processor cuts at the same 40 %)."""

ARC_MODE_TOLERANCE = 1e-6
"""Largest angle, rad, between the planned end orientation of an arc and the start
orientation turned with the arc's tangent, for ``movec(..., mode=1)`` (fixed orientation
relative to the tangent)."""


def number(value: float, digits: int = 9) -> str:
    """A URScript float literal, ``digits`` decimals, trailing zeros dropped (``0.425``,
    ``-1.5``, ``0.0``)."""
    return fixed(value, digits, keep=1)


def rotation_vectors(rotations: np.ndarray) -> np.ndarray:
    """The rotation vectors (unit axis · angle, rad) of rotation matrices, angle in [0, π].

    Parameters
    ----------
    rotations
        Shape (..., 3, 3), orthonormal.

    Returns
    -------
    numpy.ndarray
        Shape (..., 3), rad: URScript's ``rx, ry, rz``.
    """
    from scipy.spatial.transform import Rotation  # startup time: only programs need scipy

    rotations = np.asarray(rotations, dtype=float)
    flat = rotations.reshape(-1, 3, 3)
    vectors: np.ndarray = Rotation.from_matrix(flat).as_rotvec().reshape(*rotations.shape[:-2], 3)
    return vectors


def rotation_vector(rotation: np.ndarray) -> np.ndarray:
    """The rotation vector of one rotation matrix (3, 3): shape (3,), rad."""
    return rotation_vectors(rotation)


def pose_literals(poses: np.ndarray) -> list[str]:
    """``p[x, y, z, rx, ry, rz]`` of each (4, 4) pose of ``poses`` (N, 4, 4): m and a
    rotation vector in rad, 9 decimals (1 nm, 1 nrad: a pose read back is within 0.01 mm
    and 0.001° of the pose)."""
    poses = np.asarray(poses, dtype=float).reshape(-1, 4, 4)
    values = np.concatenate([poses[:, :3, 3], rotation_vectors(poses[:, :3, :3])], axis=1)
    return ["p[" + ", ".join(number(v) for v in row) + "]" for row in values]


def pose_literal(pose: np.ndarray) -> str:
    """``p[x, y, z, rx, ry, rz]`` of one (4, 4) pose (:func:`pose_literals`)."""
    return pose_literals(pose)[0]


def joints_literal(joints: np.ndarray) -> str:
    """``[q1, …, q6]``, rad, 9 decimals (1e-9 rad)."""
    return "[" + ", ".join(number(v) for v in joints) + "]"


def blend_radii(points: list[np.ndarray | None], zones: list[float]) -> np.ndarray:
    """Blend radius at each waypoint: the asked zone cut to :data:`BLEND_SHARE` of the
    distance to the waypoint before and after it; 0 at the last waypoint.

    Parameters
    ----------
    points
        The TCP position at each waypoint in one frame, shape (3,) each, m; None where
        unknown (a joint move of a robot not given): that waypoint and its neighbours'
        sides towards it get 0.
    zones
        The zone asked at each waypoint, m.

    Returns
    -------
    numpy.ndarray
        Shape (len(points),), m.
    """
    radii = np.maximum(np.asarray(zones, dtype=float), 0.0)
    if radii.size == 0:
        return radii
    unknown = np.full(3, np.nan)
    positions = np.array([unknown if p is None else p for p in points], dtype=float)
    share = BLEND_SHARE * np.linalg.norm(np.diff(positions, axis=0), axis=1)  # (n - 1,)
    share = np.where(np.isnan(share), 0.0, share)  # a neighbour of unknown place: no blend
    radii[1:] = np.minimum(radii[1:], share)
    radii[:-1] = np.minimum(radii[:-1], share)
    radii[np.isnan(positions[:, 0])] = 0.0
    radii[-1] = 0.0
    return radii


def arc_mode(start: np.ndarray | None, via: np.ndarray, end: np.ndarray) -> int:
    """``movec``'s orientation mode for an arc from ``start`` through ``via`` to ``end``.

    1 (fixed: the orientation turns with the arc's tangent) when the end orientation is the
    start orientation turned about the arc's normal by the arc's angle; else 0
    (unconstrained: the controller interpolates the orientation from start to end).

    Parameters
    ----------
    start
        The pose the arc starts from, shape (4, 4), or None when unknown (then 0).
    via, end
        The via and end poses, shape (4, 4), in the same frame.

    Returns
    -------
    int
        0 or 1.
    """
    if start is None:
        return 0
    a, b, c = start[:3, 3], via[:3, 3], end[:3, 3]
    normal = np.cross(b - a, c - b)
    length = float(np.linalg.norm(normal))
    if length < 1e-12:
        return 0
    normal /= length
    ab, ac = b - a, c - a
    cross = np.cross(ab, ac)
    centre = a + (np.cross(cross, ab) * float(ac @ ac) + np.cross(ac, cross) * float(ab @ ab)) / (
        2.0 * float(cross @ cross)
    )
    u, w = a - centre, c - centre
    angle = float(np.arctan2(np.cross(u, w) @ normal, u @ w)) % (2.0 * np.pi)
    turn = _axis_rotation(normal, angle)
    error = turn @ start[:3, :3] @ end[:3, :3].T
    residual = float(np.arccos(np.clip((np.trace(error) - 1.0) / 2.0, -1.0, 1.0)))
    return 1 if residual <= ARC_MODE_TOLERANCE else 0


def _axis_rotation(axis: np.ndarray, angle: float) -> np.ndarray:
    """Rotation about a unit axis by ``angle`` rad (Rodrigues), shape (3, 3)."""
    k = np.array([[0.0, -axis[2], axis[1]], [axis[2], 0.0, -axis[0]], [-axis[1], axis[0], 0.0]])
    rotation: np.ndarray = np.eye(3) + np.sin(angle) * k + (1.0 - np.cos(angle)) * (k @ k)
    return rotation


def _fraction(value: float) -> Fraction:
    """``value`` s as a fraction of 1 µs resolution (sample times are given in decimals)."""
    return Fraction(value).limit_denominator(1_000_000)


def is_multiple(value: float, step: float) -> bool:
    """True when ``value`` is a whole multiple (≥ 1) of ``step``, to 1e-9 of a step."""
    ratio = value / step
    return ratio >= 1.0 - 1e-9 and abs(ratio - round(ratio)) <= 1e-9 * max(1.0, ratio)


def least_common_multiple(a: float, b: float) -> float:
    """The least common multiple of two times, s (to 1 µs resolution)."""
    fa, fb = _fraction(a), _fraction(b)
    denominator = fa.denominator * fb.denominator
    na, nb = fa.numerator * fb.denominator, fb.numerator * fa.denominator
    return float(Fraction(math.lcm(na, nb), denominator))


def check_period(period: float, sample_time: float, cycle: float) -> None:
    """Refuse a ``servoj`` period that is not a multiple of the controller's cycle.

    Parameters
    ----------
    period
        The time of each ``servoj``, s.
    sample_time
        The trajectory's sample time, s (the period is a multiple of it).
    cycle
        The controller's step, s (0.002 on e-Series, 0.008 on CB3).

    Raises
    ------
    CaseError
        Key ``--period``: naming a period that works, the least common multiple of the
        sample time and the cycle.
    """
    if is_multiple(period, cycle):
        return
    works = least_common_multiple(sample_time, cycle)
    raise CaseError(
        f"the servoj period {number(period, 6)} s is not a multiple of the controller's "
        f"{number(cycle, 6)} s cycle: give --period {number(works, 6)} (a multiple of both "
        f"the {number(sample_time, 6)} s sample time and the cycle)",
        key="--period",
    )


__all__ = [
    "ARC_MODE_TOLERANCE",
    "BLEND_SHARE",
    "arc_mode",
    "blend_radii",
    "check_period",
    "is_multiple",
    "joints_literal",
    "least_common_multiple",
    "number",
    "pose_literal",
    "pose_literals",
    "rotation_vector",
    "rotation_vectors",
]
