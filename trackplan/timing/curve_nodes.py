"""The nodes of the continuous speed curve and the joint demand at each of them.

A :class:`Stretch` is the path between two stops; :func:`split_stretches` places its nodes (the
planning grid's points, gaps cut to :data:`NODE_SPACING` and graded by :data:`NODE_GROWTH`,
gaps where the demand steps bisected) and gives each node its signed joint derivatives
(q', q'', q''') and the task's speed cap; :func:`node_steps` turns node speeds into times.
The method is described in :mod:`trackplan.timing.continuous`.
"""

from __future__ import annotations

import functools
import itertools
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from trackplan.jointpath import STENCIL_FRACTION, JointPath
from trackplan.robots.machine import Machine
from trackplan.robots.model import Robot
from trackplan.task import Task
from trackplan.timing.sample_checks import LIMIT_MARGIN

NODE_SPACING = 1e-3
"""Largest distance between two nodes of the speed curve, m."""
NODE_GROWTH = 0.25
"""Largest growth of the node spacing per metre of distance from a finer part, m/m."""
MIN_NODES = 24
"""Fewest nodes of a stretch between stops (a short stretch gets a finer spacing)."""
CAP_SHARE = 0.999
"""Share of the task's speed caps the curve plans against: its spline rings slightly (about
1e-4) above a cruise it joins."""
REFINE_DEPTH = 7
"""Bisections of a gap between nodes where the joint demand steps (:func:`_features`)."""
REFINE_RATIO = 1.25
"""Change of the constant speed the joints allow from one node to the next above which the
gap between them is bisected."""
REFINE_ROOM = 1.0
"""A gap is bisected only where the joints allow less than this times the rated speed."""
REFINE_GAP = 1e-5
"""Shortest gap between nodes that is bisected, m."""


@dataclass(frozen=True, eq=False)
class Stretch:
    """Nodes of one stretch between stops and the joint demand at them.

    ``d1, d2, d3`` have shape (2, G, n): the derivatives just before and just after each
    node (they differ only at zone boundaries, where both are checked).
    """

    s: np.ndarray
    cap: np.ndarray
    d1: np.ndarray
    d2: np.ndarray
    d3: np.ndarray


def split_stretches(joint_path: JointPath, task: Task) -> list[Stretch]:
    """The stretches between stops, each with its nodes, caps and joint demand."""
    zones = joint_path.geometry.zones()
    bounds = [0.0] + [z[0] for z in zones if z[2] == "stop"] + [zones[-1][1]]
    moving = [(z, zone) for z, zone in enumerate(zones) if zone[2] != "stop"]
    out = []
    for a, b in itertools.pairwise(bounds):
        if b - a <= 1e-12:
            continue
        inside = [(z, zone) for z, zone in moving if zone[0] < b and zone[1] > a]
        rows = np.isin(joint_path.zone, [z for z, _ in inside])
        grid = joint_path.s[rows]
        spans = np.array([zone[:2] for _, zone in inside])
        steps = np.array([_grid_step(joint_path.s[joint_path.zone == z]) for z, _ in inside])
        exact = functools.partial(_exact_derivatives, joint_path, spans, steps)
        values = [d[rows] for d in (joint_path.dq, joint_path.ddq, joint_path.dddq)]
        s = _nodes(grid, a, b)
        sides, missed = _demand(s, grid, values, exact, joint_path.robot)
        if missed.size:
            window = _within(s, missed)
            features = _features(s[window], missed, exact, joint_path.robot, task.rated_speed)
            s = _nodes(np.concatenate([grid, features]), a, b)
            sides, _ = _demand(s, grid, values, exact, joint_path.robot)
        count = len(s)
        before = np.concatenate([[s[0]], s[:-1]])
        after = np.concatenate([s[1:], [s[-1]]])
        cap = np.full(count, np.inf)
        for _, (s0, s1, kind) in inside:
            speed = task.rated_speed
            if kind != "straight":
                speed = min(task.rated_speed, task.corner_speed * (1.0 - LIMIT_MARGIN))
            near = (after >= s0) & (before <= s1)  # a node's neighbourhood touches the zone
            cap[near] = np.minimum(cap[near], CAP_SHARE * speed)
        out.append(Stretch(s, cap, *sides))
    return out


def _demand(
    s: np.ndarray,
    grid: np.ndarray,
    values: list[np.ndarray],
    exact: Callable[[np.ndarray], tuple[np.ndarray, np.ndarray, np.ndarray]],
    robot: Robot | Machine,
) -> tuple[list[np.ndarray], np.ndarray]:
    """q', q'', q''' at the nodes ``s`` (G,) just before and just after each, shape
    (2, G, n) each, and the gaps of the planning grid where the joint demand rises between
    its points, shape (M, 2), m.

    On the grid's own points they are the grid's ``values`` (q', q'', q''' at ``grid``,
    each (R, n)); between them, the linear interpolation of these or the derivatives from
    IK (``exact``), whichever asks the joints for more at a constant speed
    (:func:`_steady_demand`): the interpolation overstates the demand where it falls
    quickly (which keeps the plans that work as they were) and misses it where it rises
    within a gap. Those gaps are returned: the ones holding a node whose demand from IK
    passes :data:`REFINE_RATIO` cubed times the interpolated one.
    """
    sides = [np.stack([_interp(s, grid, v, last) for last in (True, False)]) for v in values]
    fill = np.flatnonzero(~np.isin(s, grid))
    if not fill.size:
        return sides, np.zeros((0, 2))
    from_ik = exact(s[fill])
    interpolated = tuple(np.abs(side[:, fill]).max(axis=0) for side in sides)
    demand = _steady_demand(from_ik, robot)
    guess = _steady_demand(interpolated, robot)
    higher = demand >= guess
    for side, value in zip(sides, from_ik, strict=True):
        side[:, fill[higher]] = value[higher]
    distinct = np.unique(grid)
    cell = np.unique(np.searchsorted(distinct, s[fill[demand > REFINE_RATIO**3 * guess]]))
    return sides, np.stack([distinct[cell - 1], distinct[cell]], axis=1)


def _within(s: np.ndarray, gaps: np.ndarray) -> np.ndarray:
    """Whether each point of ``s`` (G,) lies in one of the closed ``gaps`` (M, 2), (G,) bool."""
    inside = (s[:, None] >= gaps[None, :, 0]) & (s[:, None] <= gaps[None, :, 1])
    found: np.ndarray = np.any(inside, axis=1)
    return found


def _grid_step(grid: np.ndarray) -> float:
    """Mean step of a zone's planning grid (G,), m, as the joint path's stencils use it."""
    return float(grid[-1] - grid[0]) / max(len(grid) - 1, 1)


def _exact_derivatives(
    joint_path: JointPath, spans: np.ndarray, steps: np.ndarray, s: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """q', q'', q''' at arc lengths ``s`` (M,) by IK on stencils inside the zone of each
    point, with the planning grid's spacing (:data:`~trackplan.jointpath.STENCIL_FRACTION`
    of the zone's grid step); each shape (M, n), rad/m, rad/m², rad/m³.

    Parameters
    ----------
    spans
        Start and end of the stretch's zones, shape (Z, 2), m.
    steps
        Grid step of each zone, shape (Z,), m.
    """
    zone = np.clip(np.searchsorted(spans[:, 1], s), 0, len(spans) - 1)
    lo, hi = spans[zone, 0], spans[zone, 1]
    h = np.minimum(STENCIL_FRACTION * steps[zone], (hi - lo) / 4.0)
    return joint_path.derivatives(s, lo, hi, h)


def _features(
    s: np.ndarray,
    missed: np.ndarray,
    exact: Callable[[np.ndarray], tuple[np.ndarray, np.ndarray, np.ndarray]],
    robot: Robot | Machine,
    rated: float,
) -> np.ndarray:
    """Points (F,), m, where the joint demand steps between two nodes.

    The planning grid is coarse on a straight piece, but the tool's seam frame turns within
    a few millimetres of a junction (``docs/tool.md``), and the joints' q''' rises there from
    nothing to its peak at once. The gaps between the nodes ``s`` (G,) that lie in the grid
    gaps ``missed`` (M, 2), m (see :func:`_demand`) are bisected, up to :data:`REFINE_DEPTH`
    times, with the derivatives from IK (``exact``), wherever the constant speed the joints'
    acceleration and jerk allow changes by more than :data:`REFINE_RATIO` from one node to
    the next while staying below :data:`REFINE_ROOM` times the rated speed ``rated``, m/s.
    The points found go to :func:`_nodes` with the grid's.
    """
    points = s
    demand = _steady_demand(exact(points), robot)
    found = []
    for _ in range(REFINE_DEPTH):
        gaps = np.diff(points)
        low = np.minimum(demand[:-1], demand[1:])
        high = np.maximum(demand[:-1], demand[1:])
        wide = (
            (high > REFINE_RATIO**3 * low)
            & (high * (REFINE_ROOM * rated) ** 3 > 1.0)
            & (gaps > REFINE_GAP)
            & _within(points[:-1] + 0.5 * gaps, missed)
        )
        if not wide.any():
            break
        middle = points[:-1][wide] + 0.5 * gaps[wide]
        found.append(middle)
        order = np.argsort(np.concatenate([points, middle]), kind="stable")
        points = np.concatenate([points, middle])[order]
        demand = np.concatenate([demand, _steady_demand(exact(middle), robot)])[order]
    if not found:
        return np.zeros(0)
    return np.concatenate(found)


def _steady_demand(
    derivatives: tuple[np.ndarray, np.ndarray, np.ndarray], robot: Robot | Machine
) -> np.ndarray:
    """One over the cube of the constant speed the joints' acceleration and jerk limits
    allow at each point, shape (M,), s³/m³: the largest ``(|q''| / a_max)^1.5`` and
    ``|q'''| / j_max`` over the joints."""
    _, d2, d3 = derivatives
    acceleration = np.max(np.abs(d2) / robot.a_max, axis=1) ** 1.5
    demand: np.ndarray = np.maximum(acceleration, np.max(np.abs(d3) / robot.j_max, axis=1))
    return demand


def _nodes(grid: np.ndarray, a: float, b: float) -> np.ndarray:
    """Nodes of the stretch ``a..b`` (G,), m: the planning grid's own points (fine where the
    path bends quickly) and, between them, nodes at most :data:`NODE_SPACING` apart (and at
    least :data:`MIN_NODES` in all) whose spacing grows by at most :data:`NODE_GROWTH` of
    the distance away from a finer part, so that neighbouring steps stay alike and the
    three-point differences stay accurate.

    The spacing wanted at each grid point is its shorter gap; it is limited to
    ``t_j + NODE_GROWTH |s - s_j|`` from every other point j and varies linearly inside a gap,
    where the nodes lie at equal steps of ``∫ ds / t(s)``.
    """
    points = np.unique(np.clip(np.concatenate([[a, b], grid]), a, b))
    spacing = min(NODE_SPACING, (b - a) / (MIN_NODES - 1))
    # grid points closer than a thousandth of the spacing would give ill-conditioned
    # difference quotients: keep the first of them (and the end)
    keep = np.concatenate([[True], np.diff(points) > 1e-3 * spacing])
    points = points[keep]
    points[-1] = b
    gaps = np.diff(points)
    wanted = np.minimum(spacing, np.minimum(np.append(gaps, np.inf), np.insert(gaps, 0, np.inf)))
    slope = NODE_GROWTH
    wanted = np.minimum.accumulate(wanted - slope * points) + slope * points
    wanted = np.minimum.accumulate((wanted + slope * points)[::-1])[::-1] - slope * points
    t0, t1 = wanted[:-1], wanted[1:]
    rate = (t1 - t0) / gaps  # dt/ds inside each gap
    flat = np.abs(rate) < 1e-9
    steps = np.where(flat, gaps / t0, np.log(t1 / t0) / np.where(flat, 1.0, rate))
    pieces = np.maximum(1, np.ceil(steps - 1e-9)).astype(int)
    gap = np.repeat(np.arange(len(gaps)), pieces)
    index = np.arange(pieces.sum()) - np.repeat(np.cumsum(pieces) - pieces, pieces)
    u = index * (steps / pieces)[gap]  # ∫ ds / t from the gap's start
    r = rate[gap]
    offset = np.where(
        flat[gap], u * t0[gap], t0[gap] * np.expm1(r * u) / np.where(flat[gap], 1.0, r)
    )
    return np.concatenate([points[:-1][gap] + offset, [b]])


def _interp(s: np.ndarray, grid: np.ndarray, values: np.ndarray, last: bool) -> np.ndarray:
    """Linear interpolation of ``values`` (G, n) on a grid with repeated zone boundaries,
    taking the last (``last``) or first of the repeated rows, shape (M, n)."""
    if last:
        distinct, index = np.unique(grid[::-1], return_index=True)
        index = len(grid) - 1 - index
    else:
        distinct, index = np.unique(grid, return_index=True)
    return np.stack(
        [np.interp(s, distinct, values[index, j]) for j in range(values.shape[1])], axis=1
    )


def node_steps(stretch: Stretch, speed: np.ndarray) -> np.ndarray:
    """Time between consecutive nodes, shape (G - 1,), s, at the node speeds ``speed`` (G,):
    constant acceleration between nodes, constant jerk next to the rests at both ends."""
    step: np.ndarray = 2.0 * np.diff(stretch.s) / np.maximum(speed[1:] + speed[:-1], 1e-300)
    step[[0, -1]] *= 1.5  # from and to rest at constant jerk: s/ṡ = t/3, not t/2
    return step
