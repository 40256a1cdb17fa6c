"""The exact cell check of a sampled trajectory: clearance, collisions, self-collisions.

Every sample is screened by the compiled kernel; where a pair's distance decides
(:func:`pair_distances`) it is recomputed by the exact library (:mod:`trackplan.cell.exact`).
Screened distances never exceed the exact ones (equal for primitives, enclosing boxes for
meshes), so a pair screened farther than the band cannot break the clearance.
"""

from __future__ import annotations

import numpy as np

from trackplan.cell.exact import ExactDistance
from trackplan.cell.model import Capsules, Shape
from trackplan.cell.screening import CellGeometry, cell_frames, part_placements
from trackplan.check_report import CellReport, Violation
from trackplan.robots.machine import Machine
from trackplan.robots.model import Robot

EXACT_BAND = 0.01
"""Pairs screened within this distance above the clearance are re-measured exactly, m."""
SLACK = 1e-9
"""Distances within this of the clearance count as meeting it, m."""


def pair_distances(
    geometry: CellGeometry,
    frames: np.ndarray,
    T_base_part: np.ndarray,
    group: np.ndarray | None = None,
    *,
    exact: bool = True,
) -> np.ndarray:
    """Distances of every checked pair at every sample, exact where they decide.

    Every sample is screened; the exact library re-measures each pair at the closest
    sample of every stretch of time it spends within :data:`EXACT_BAND` of the clearance
    and of every stretch of overlap (the screening equals the exact distance for
    primitives to 1e-6 m when apart; overlapping, the exact value is the penetration depth
    and the screened one a grade), at its overall minimum, and, for meshes (screened as
    boxes that enclose them), at every sample within the band.

    Parameters
    ----------
    geometry
        The cell laid out for the robot.
    frames
        The frames the capsules move with (:func:`~trackplan.cell.screening.cell_frames`),
        shape (N, F, 4, 4).
    T_base_part
        Placement of the definition frame in the frame of the obstacles (the robot's base,
        a machine's cell), shape (4, 4), or one per group, shape (G, 4, 4).
    group
        The placement of each sample, shape (N,), int; default all 0.
    exact
        Re-measure exactly as above; False returns the screened distances.

    Returns
    -------
    numpy.ndarray
        Shape (N, P + Q), m: capsule–body pairs, then self pairs.
    """
    frames = np.asarray(frames, dtype=float)
    T_part = np.asarray(T_base_part, dtype=float).reshape(-1, 4, 4)
    group = np.zeros(len(frames), np.int64) if group is None else np.asarray(group, np.int64)
    body, own = geometry.screen(frames, T_part, group)
    distance = np.concatenate([body, own], axis=1)
    if not exact or distance.size == 0:
        return distance
    band = distance < geometry.cell.clearance + EXACT_BAND
    # the screening is exact for primitives (tests/cell): re-measure where it decides, at
    # the closest sample of each stretch of time a pair spends within the band (and so of
    # each overlap) and at its overall minimum; mesh pairs (screened as boxes) at every
    # sample within the band
    near = np.zeros_like(band)
    near[np.argmin(distance, axis=0), np.arange(distance.shape[1])] = True
    mesh = [geometry.bodies[o].shape is Shape.MESH for o in geometry.pair_body]
    for p in range(distance.shape[1]):
        for stretches in (band[:, p], distance[:, p] < 0.0):
            inside = np.flatnonzero(stretches)
            if not len(inside):
                continue
            if p < len(mesh) and mesh[p]:
                near[inside, p] = True
                continue
            for stretch in np.split(inside, np.flatnonzero(np.diff(inside) > 1) + 1):
                near[stretch[np.argmin(distance[stretch, p])], p] = True
    oracle = ExactDistance()
    for s, p in zip(*np.nonzero(near), strict=True):
        distance[s, p] = _exact(oracle, geometry, frames[s], T_part[group[s]], int(p))
    return distance


def _exact(
    oracle: ExactDistance, geometry: CellGeometry, frames: np.ndarray, T_part: np.ndarray, p: int
) -> float:
    """Exact distance of pair p (capsule–body pairs, then self pairs) at one sample: frames
    (F, 4, 4), the part's placement (4, 4); the oracle keeps the nearest points."""
    capsules = geometry.capsules
    n_body_pairs = len(geometry.pair_capsule)
    if p < n_body_pairs:
        k, o = geometry.pair_capsule[p], geometry.pair_body[p]
        a, b = _world(frames, capsules, k)
        T_world_frame = T_part if o >= geometry.n_obstacles else np.eye(4)
        return oracle.capsule_body(a, b, capsules.radius[k], geometry.bodies[o], T_world_frame)
    i, j = geometry.self_pairs[p - n_body_pairs]
    a0, b0 = _world(frames, capsules, i)
    a1, b1 = _world(frames, capsules, j)
    return oracle.capsule_capsule(a0, b0, capsules.radius[i], a1, b1, capsules.radius[j])


def nearest_points(
    geometry: CellGeometry,
    robot: Robot | Machine,
    q: np.ndarray,
    T_carrier_part: np.ndarray,
    pair: int,
) -> tuple[np.ndarray, float]:
    """The nearest points of one checked pair at one configuration (coal's witness points).

    Parameters
    ----------
    geometry
        The cell laid out for ``robot``.
    robot
        The robot or machine.
    q
        One configuration, shape (n,) (a machine's every column).
    T_carrier_part
        Placement of the definition frame in the carrier frame, shape (4, 4).
    pair
        Index into :meth:`CellGeometry.pair_names`.

    Returns
    -------
    tuple
        The points on the capsule and on the other body, shape (2, 3), in the frame of
        the obstacles (a robot's base, a machine's cell frame), m; and the exact signed
        distance, m.
    """
    q = np.asarray(q, dtype=float).reshape(1, -1)
    frames = cell_frames(robot, q)
    geometry.check_frames(frames)
    T_part, group = part_placements(robot, q, T_carrier_part)
    oracle = ExactDistance()
    distance = _exact(oracle, geometry, frames[0], T_part[group[0]], pair)
    return oracle.last_points, distance


def _world(frames: np.ndarray, capsules: Capsules, k: int) -> tuple[np.ndarray, np.ndarray]:
    """World end points of capsule k; frames (F, 4, 4) of one sample."""
    T = frames[capsules.frame[k]]
    a, b = capsules.segment[k] @ T[:3, :3].T + T[:3, 3]
    return a, b


def check_cell(
    geometry: CellGeometry,
    robot: Robot | Machine,
    q: np.ndarray,
    sample_time: float,
    T_carrier_part: np.ndarray,
) -> CellReport:
    """Check a sampled trajectory against the cell.

    Parameters
    ----------
    geometry
        The cell laid out for ``robot``.
    robot
        The robot, or a machine (arm, track, positioner; everything in the cell frame).
    q
        Joint positions, shape (N, n), rad; for a machine every column (arm, track in m,
        positioner).
    sample_time
        Ts, s.
    T_carrier_part
        Placement of the definition frame in the carrier frame (the robot's base frame; a
        machine's positioner flange, or its cell frame without a positioner), shape (4, 4).

    Returns
    -------
    CellReport
    """
    q = np.asarray(q, dtype=float)
    frames = cell_frames(robot, q)
    geometry.check_frames(frames)
    T_part, group = part_placements(robot, q, T_carrier_part)
    distance = pair_distances(geometry, frames, T_part, group)
    t = np.arange(len(q)) * sample_time
    clearance = geometry.cell.clearance
    names = geometry.pair_names()
    if distance.shape[1] == 0:
        return CellReport(
            min_clearance=np.inf,
            closest=("", ""),
            t_closest=0.0,
            point=0,
            clearance=clearance,
            margin=1.0,
            distance=np.full(len(q), np.inf),
            violations=(),
        )
    point, pair = np.unravel_index(int(np.argmin(distance)), distance.shape)
    least = float(distance[point, pair])
    violations = []
    for p in np.flatnonzero(distance.min(axis=0) < clearance - SLACK):
        bad = np.flatnonzero(distance[:, p] < clearance - SLACK)
        worst = int(bad[np.argmin(distance[bad, p])])
        value = float(distance[worst, p])
        who, other = names[p]
        span = f"from t = {t[bad[0]]:.3f} to {t[bad[-1]]:.3f} s"
        if value < 0.0:
            kind = "collision"
            text = (
                f"collision: {who} hits {other} {-value * 1e3:.1f} mm deep at "
                f"t = {t[worst]:.3f} s ({span})"
            )
        else:
            kind = "clearance"
            text = (
                f"clearance: {who} comes {value * 1e3:.1f} mm from {other} "
                f"(least allowed {clearance * 1e3:.1f} mm) at t = {t[worst]:.3f} s ({span})"
            )
        violations.append(
            Violation(
                limit=kind,
                joint=None,
                t_first=float(t[bad[0]]),
                t_last=float(t[bad[-1]]),
                worst=value,
                bound=clearance,
                message=text,
            )
        )
    violations.sort(key=lambda v: v.t_first)
    margin = min(1.0, (least - clearance) / max(clearance, 1e-3))
    return CellReport(
        min_clearance=least,
        closest=names[pair],
        t_closest=float(t[point]),
        point=int(point),
        clearance=clearance,
        margin=margin,
        distance=distance.min(axis=1),
        violations=tuple(violations),
    )
