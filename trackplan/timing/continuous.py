"""A continuous speed curve under the joint limits, for paths whose speed cap varies quickly.

Near a wrist singularity the joints cap the path speed along a stretch whose cap changes
every few millimetres. The window plan of :mod:`trackplan.timing.smooth` then holds a
staircase of short plateaus under the lowest constant-speed cap of each window, where the
jerk-limited optimum follows the cap continuously, and even rises above it where a speed
change cancels part of the joint demand (``q' s̈`` against ``q'' ṡ²``). This module plans
the speed as one curve instead.

With ``x(s) = ṡ²`` (so ``s̈ = x'/2`` and ``s⃛ = ṡ x''/2``) the joint velocity, acceleration
and jerk are

    q̇ = q' √x,    q̈ = q' x'/2 + q'' x,    q⃛ = √x (q' x''/2 + 3 q'' x'/2 + q''' x).

The nodes are the planning grid's own points (fine inside a blend, where q'' and q''' change
within a fraction of a millimetre) with the gaps between them cut to at most
:data:`NODE_SPACING`, the spacing growing gradually away from a fine part
(:data:`NODE_GROWTH`). Between the grid's points a node takes the joint derivatives from IK
where they ask for more than the grid's interpolated ones, and a grid gap where they rise
unseen (a seam frame that starts turning between two points of a straight's coarse grid) is
bisected and graded (:func:`_demand`, :func:`_features`). With three-point differences on
these nodes for ``x'`` and ``x''`` (exact for quadratics on any spacing) the acceleration is
linear in x, and so is the jerk once ``√x`` is bounded by a speed ``v̄`` known to lie above
it: ``|q' x''/2 + 3 q'' x'/2 + q''' x| ≤ q⃛max / v̄`` with ``x ≤ v̄²`` is a sufficient
(conservative) form. Under these linear bounds, the velocity limits and the task's speed
caps, a linear program (HiGHS's dual simplex, through :func:`scipy.optimize.linprog`)
maximises ``Σ w x``, each node weighted by its share of the travel time (``ds / x^1.5`` at
a reference x, so a node near rest costs what it costs in time). It is solved in rounds:
first with ``v̄`` :data:`FIRST_ROOMS` times the constant speed the joints allow at each
node, then with ``v̄`` each of :data:`SPEED_ROOMS` times the previous solution (the
reference x of the weights), so that the last bound lies within 10 % of the speed it
bounds. The signed joint-path derivatives enter as they are, so the curve uses the
cancellations the optimum uses; but the path-jerk term ``q' x''/2`` alone stays within
:data:`CANCEL_ROOM` times the jerk bound, so that a rebuild that lowers the jerk limit
where the samples rang lowers the path jerk there too (near a wrist flip the terms are a
thousand times the limit, and the program would rather cancel more of them). Only rows
that can bind enter the
program (a row whose largest value for ``0 ≤ x ≤ v̄²`` stays within its limit cannot), and
nodes far from any slowed or changing part cruise at their cap outside it
(:func:`_cruising`).

Each stretch between stops is planned from rest to rest; next to a rest, where the
difference quotients cannot see the acceleration grow from zero, x is also bounded by a
start at constant path jerk (:func:`_rest_envelope`). The nodes become times by the
constant-acceleration step ``Δt = 2h / (ṡ_k + ṡ_{k+1})`` (constant jerk next to a rest), and
s(t) is the quintic spline through (t, s) at the nodes, at rest at both ends, sampled at Ts.
The samples go through the law's sample checks and the speed caps; where one fails, the
limits (or the cap) of the nodes around it are lowered by the ratio found and the curve is
planned again (:data:`MAX_REBUILDS` times at most), over a reach that grows by
:data:`REBUILD_SPREAD` each time the same nodes fail again. A check other than the joint
rates (the torques) names no limit of the program: where it fails, the speed of the nodes
around it is capped below the speed planned there, by the check's ratio and order.
"""

from __future__ import annotations

import functools
import itertools
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from trackplan.jointpath import STENCIL_FRACTION, JointPath
from trackplan.motion import JointSamples
from trackplan.robots.model import Robot
from trackplan.task import Task
from trackplan.timing.sample_checks import (
    LIMIT_MARGIN,
    RateLimits,
    SampleCheck,
    run_motion_checks,
)

NODE_SPACING = 1e-3
"""Largest distance between two nodes of the speed curve, m."""
NODE_GROWTH = 0.25
"""Largest growth of the node spacing per metre of distance from a finer part, m/m."""
MIN_NODES = 24
"""Fewest nodes of a stretch between stops (a short stretch gets a finer spacing)."""
SPEED_ROOMS = (1.3, 1.1)
"""How far above the previous round's solution each round after the first may plan the
speed (its jerk bound assumes the speed stays below it): the second round 1.3 ×, the third
1.1 × (the first bounds √x by :data:`FIRST_ROOMS` times the constant-speed cap of the
joints)."""
FIRST_ROOMS = (1.5, 1.0)
"""How far above the constant-speed cap the joints allow (at each node) the first round's
speed may go (its jerk bound assumes the speed stays below it): the first room, and the
next one tried when a solution leaves a node inside the stretch at rest (:data:`RESTING`)."""
SLOW_FLOOR = 0.05
"""Share of the fastest speed below which the objective weighs a node as if it ran at it."""
CRUISE_ROOM = 1.5
"""How far above the speed cap the joints must allow a constant speed for a node to cruise
at its cap without the linear program (see :func:`_cruising`)."""
CRUISE_CLEARANCE = 0.05
"""Distance from any slowed or changing node beyond which a node cruises at its cap, m."""
MAX_DURATION = 2000.0
"""Longest curve sampled, s (the window law's longest, 2 000 000 samples at 1 ms): a curve
that would take longer has (almost) stopped inside a stretch, and the window law stands."""
RESTING = 1e-9
"""Share of the top ``x`` below which a node inside a stretch is at rest: a solution with
such a node is kept only if no later try of :func:`_solve` is faster."""
MAX_REBUILDS = 10
"""Plans of the curve with lowered limits before the law gives up on it."""
REST_JERK_SHARE = 0.95
"""Share of the path jerk the joints allow that a start from rest or a stop plans with."""
REBUILD_REACH = 3
"""Nodes on each side of a failing sample whose limits a rebuild lowers (the first time)."""
REBUILD_SPREAD = 1.5
"""Growth of that reach for each earlier rebuild that lowered the same nodes."""
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
CANCEL_ROOM = 2.0
"""How far the path-jerk term ``√x q' x''/2`` of the joint jerk may pass the jerk limit on
its own, the other terms cancelling the rest (a row of its own in the linear program)."""
SLOW_DOWNS = 3
"""Tries after the last rebuild that stretch the whole curve in time by the worst failure's
ratio (:func:`_slow_down`) instead of giving the curve up: a failure that creeps along a
speed change for every rebuild costs the curve a few tenths of a per cent, not the window
plan's lead over it."""
SLOW_DOWN_MARGIN = 1.002
"""Extra stretch of each such try (the samples' rates do not fall exactly with the time
scale: the samples fall elsewhere on the curve)."""
REBUILD_FACTOR = 0.97
"""A rebuild lowers the failing limit to this share of its value over the ratio found."""


@dataclass(frozen=True, eq=False)
class SpeedCurve:
    """A sampled continuous speed curve that passed its sample checks.

    Attributes
    ----------
    s
        Arc length at each sample, shape (N,), m; from 0 to the path's length.
    motion
        The samples' joints with their backward differences, as the checks read them.
    s_nodes, speed
        The nodes (G,), m, and the path speed planned there (G,), m/s.
    joint_cap
        Highest constant speed the joint limits allow at each node, shape (G,), m/s.
    reason
        What sets it there, e.g. ``"joint 4 jerk"``, shape (G,).
    rebuilds
        Plans of the curve it took (1 when the first passed).
    """

    s: np.ndarray
    motion: JointSamples
    s_nodes: np.ndarray
    speed: np.ndarray
    joint_cap: np.ndarray
    reason: np.ndarray
    rebuilds: int

    @property
    def duration(self) -> float:
        """Time of the last sample, s."""
        return (len(self.s) - 1) * self.motion.sample_time


@dataclass(frozen=True, eq=False)
class _Stretch:
    """Nodes of one stretch between stops and the joint demand at them.

    ``d1, d2, d3`` have shape (2, G, n): the derivatives just before and just after each
    node (they differ only at zone boundaries, where both are checked).
    """

    s: np.ndarray
    cap: np.ndarray
    d1: np.ndarray
    d2: np.ndarray
    d3: np.ndarray


def plan_speed_curve(
    joint_path: JointPath,
    task: Task,
    checks: tuple[SampleCheck, ...],
    share: float,
    to_beat: float = np.inf,
) -> SpeedCurve | None:
    """The continuous speed curve of a joint path (see the module), or None.

    Parameters
    ----------
    joint_path
        q(s) with its derivatives on the planning grid.
    task
        Rated and corner speeds, m/s, and Ts, s.
    checks
        The sample checks the samples must pass.
    share
        Share of each joint limit planned against.
    to_beat
        Duration, s, of a law already found (the window plan's). A rebuild plans with
        lower limits, which in practice never makes the curve faster; so once the nodes'
        own timing (before sampling) reaches ``to_beat``, the work stops and None is
        returned.

    Returns
    -------
    SpeedCurve or None
        None when a linear program fails, the curve cannot beat ``to_beat``, or the samples
        still fail a check after :data:`MAX_REBUILDS` plans.
    """
    stretches = _stretches(joint_path, task)
    robot = joint_path.robot
    rates = tuple(c for c in checks if isinstance(c, RateLimits))
    others = tuple(c for c in checks if not isinstance(c, RateLimits))
    # v, a, j limits; speed cap; speed ceiling, m/s (from the checks other than the rates)
    scales = [np.vstack([np.ones((4, len(st.s))), np.full(len(st.s), np.inf)]) for st in stretches]
    hits = [np.zeros(len(st.s), dtype=int) for st in stretches]  # rebuilds that lowered a node
    speeds: list[np.ndarray] = []
    for rebuild in range(1, MAX_REBUILDS + SLOW_DOWNS + 1):
        if rebuild <= MAX_REBUILDS:
            speeds = []
            for stretch, scale in zip(stretches, scales, strict=True):
                limits = (
                    share
                    * scale[:3, :, None]
                    * np.stack([robot.v_max, robot.a_max, robot.j_max])[:, None, :]
                )
                x = _solve(stretch, limits, np.minimum(stretch.cap * scale[3], scale[4]))
                if x is None:
                    return None
                speeds.append(np.sqrt(x))
        if (
            sum(_node_steps(st, v).sum() for st, v in zip(stretches, speeds, strict=True))
            >= to_beat
        ):
            return None
        s = _sample(stretches, speeds, task.sample_time)
        if s is None:
            return None
        motion = JointSamples(robot, joint_path.joints(s), task.sample_time)
        # the rate checks name the limit to lower; any other check (the torques) asks for a
        # lower speed where it fails (order 5)
        sample, order, ratio = run_motion_checks(rates, motion)
        other = run_motion_checks(others, motion) if others else (sample[:0], order[:0], ratio[:0])
        fast, excess = _over_speed(s, task, stretches)
        if not sample.size and not fast.size and not other[0].size:
            s_nodes = np.concatenate([st.s for st in stretches])
            speed = np.concatenate(speeds)
            caps = [_joint_caps(st, robot, share) for st in stretches]
            joint_cap = np.concatenate([c[0] for c in caps])
            reason = np.concatenate([c[1] for c in caps])
            return SpeedCurve(s, motion, s_nodes, speed, joint_cap, reason, rebuild)
        # the spline rings above a speed cap it joins: a lower cap there (order 4)
        sample = np.concatenate([sample, fast, other[0]])
        order = np.concatenate([order, np.full(fast.size, 4), 4 + other[1]])
        ratio = np.concatenate([ratio, excess, other[2]])
        if rebuild < MAX_REBUILDS:
            for stretch, scale, hit, v in zip(stretches, scales, hits, speeds, strict=True):
                _lower(stretch.s, v, scale, hit, s[sample], order, ratio)
        else:
            # the rebuilds are spent (a failure creeping along a speed change): the whole
            # curve runs slower in time, which lowers every rate alike
            slower = _slow_down(order, ratio)
            speeds = [v / slower for v in speeds]
    return None


def _slow_down(order: np.ndarray, ratio: np.ndarray) -> float:
    """Factor (> 1) by which the curve's time stretches so that failures of these orders
    (V,) and ratios (V,) pass (see :func:`_lower` for the orders): a rate of order o falls
    with the o-th power of the factor, the speed cap with its first power, a check other
    than the rates (order 4 + o) as its order says; :data:`SLOW_DOWN_MARGIN` more."""
    power = np.where(order <= 3, order, np.where(order == 4, 1, order - 4))
    return float(np.max(ratio ** (1.0 / power))) * SLOW_DOWN_MARGIN


def _stretches(joint_path: JointPath, task: Task) -> list[_Stretch]:
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
        out.append(_Stretch(s, cap, *sides))
    return out


def _demand(
    s: np.ndarray,
    grid: np.ndarray,
    values: list[np.ndarray],
    exact: Callable[[np.ndarray], tuple[np.ndarray, np.ndarray, np.ndarray]],
    robot: Robot,
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
    robot: Robot,
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
    derivatives: tuple[np.ndarray, np.ndarray, np.ndarray], robot: Robot
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


def _solve(stretch: _Stretch, limits: np.ndarray, cap: np.ndarray) -> np.ndarray | None:
    """Node values of ``x = ṡ²`` (G,) maximising the time-weighted ``Σ w x`` under the limits
    (see the module), or None when the linear program fails.

    Parameters
    ----------
    limits
        Joint velocity, acceleration and jerk limits at each node, shape (3, G, n).
    cap
        Speed cap planned at each node, shape (G,), m/s.
    """
    import scipy.sparse as sparse  # scipy's LP stack only where a curve is planned
    from scipy.optimize import linprog

    s, d1, d2, d3 = stretch.s, stretch.d1, stretch.d2, stretch.d3
    count = len(s)
    with np.errstate(divide="ignore"):
        velocity = np.min(limits[0] / np.abs(d1), axis=(0, 2))
    top = np.minimum(np.minimum(cap, velocity) ** 2, _rest_envelope(s, d1, limits[2]))
    k = np.arange(1, count - 1)
    slope, bend = _differences(s)  # x'[k] = slope @ x[k-1:k+2], x''[k] = bend @ ...
    # accel:  q' x'/2 + q'' x
    # jerk:   q' x''/2 + 1.5 q'' x' + q''' x
    q1, q2, q3 = (d[:, k, :, None] for d in (d1, d2, d3))  # (2, m, n, 1)
    centre = np.array([0.0, 1.0, 0.0])
    coefficients = np.stack(
        [
            q1 * slope[:, None] / 2 + q2 * centre,
            q1 * bend[:, None] / 2 + 1.5 * q2 * slope[:, None] + q3 * centre,
        ]
    )  # (2 kinds, 2 sides, m, n, 3 columns)
    columns = np.broadcast_to(
        np.stack([k - 1, k, k + 1], axis=-1)[None, None, :, None, :], coefficients.shape
    )
    # the side after a node repeats the side before it except at zone boundaries
    same = np.all([np.all(d[0, k] == d[1, k], axis=-1) for d in (d1, d2, d3)], axis=0)  # (m,)
    distinct = np.stack([np.ones_like(same), ~same])[None, None, :, :, None]  # (1,1,2,m,1)
    signed = np.stack([coefficients, -coefficients])  # rows ≤ rhs in both directions
    positive = np.maximum(signed, 0.0)
    signed_columns = np.stack([columns, columns])
    # the path-jerk term alone: |q' x''/2| ≤ CANCEL_ROOM q⃛max / v̄ for every joint and side
    # is one row each way per node, |x''/2| ≤ CANCEL_ROOM (lowest q⃛max / |q'|) / v̄
    with np.errstate(divide="ignore"):
        path_jerk = CANCEL_ROOM * np.min(limits[2][k][None] / np.abs(d1[:, k]), axis=(0, 2))
    bend_rows = np.stack([bend / 2, -bend / 2])  # (2 signs, m, 3 columns)
    bend_positive = np.maximum(bend_rows, 0.0)
    bend_columns = np.broadcast_to(np.stack([k - 1, k, k + 1], axis=-1), bend_rows.shape)
    with np.errstate(divide="ignore"):
        steady = np.min(
            np.minimum(np.sqrt(limits[1] / np.abs(d2)), np.cbrt(limits[2] / np.abs(d3))),
            axis=(0, 2),
        )
    cruise = _cruising(s, top, steady)
    solution = best = None
    best_duration = MAX_DURATION
    tries = [(held, room) for room in FIRST_ROOMS for held in _holds(cruise)]
    for held, room in tries:
        # held at the cap first; if that leaves no room for a speed change, everything free
        x = np.minimum(top, (room * steady) ** 2)
        reference = x
        for next_room in (*SPEED_ROOMS, 1.0):
            bound = np.sqrt(x)
            with np.errstate(divide="ignore"):
                jerk = limits[2][k] / np.maximum(bound[k], 1e-9)[:, None]
            rhs = np.stack([np.broadcast_to(limits[1][k], jerk.shape), jerk])[:, None]
            rhs = np.broadcast_to(rhs, signed.shape[:-1])  # (2 signs, 2 kinds, 2 sides, m, n)
            bend_rhs = np.broadcast_to(path_jerk / np.maximum(bound[k], 1e-9), bend_rows.shape[:-1])
            # a row binds only if its largest value for 0 ≤ x ≤ the round's bound passes
            # rhs, and only if it reaches a node that is not held
            keep = distinct & (np.einsum("...c,...c->...", positive, x[signed_columns]) > rhs)
            keep &= ~np.all(held[signed_columns], axis=-1)
            bend_keep = np.einsum("...c,...c->...", bend_positive, x[bend_columns]) > bend_rhs
            bend_keep &= ~np.all(held[bend_columns], axis=-1)
            solution = x
            if keep.any() or bend_keep.any():
                kept = np.concatenate([signed[keep], bend_rows[bend_keep]])
                kept_columns = np.concatenate([signed_columns[keep], bend_columns[bend_keep]])
                matrix = sparse.csr_matrix(
                    (kept.ravel(), (np.repeat(np.arange(len(kept)), 3), kept_columns.ravel())),
                    shape=(len(kept), count),
                )
                result = linprog(
                    -_time_weights(s, reference),
                    A_ub=matrix,
                    b_ub=np.concatenate([rhs[keep], bend_rhs[bend_keep]]),
                    bounds=np.stack([np.where(held, x, 0.0), x], axis=1),
                    method="highs-ds",
                    options={"presolve": False},
                )
                if result.status != 0:
                    solution = None
                    break
                solution = np.clip(result.x, 0.0, x)
            x = np.minimum(top, next_room**2 * solution)
            reference = solution
        if solution is None:
            continue
        duration = _node_steps(stretch, np.sqrt(solution)).sum()
        if duration < best_duration:
            best, best_duration = solution, duration
        if duration < MAX_DURATION and solution[1:-1].min() > RESTING * solution.max():
            break
    return best


def _holds(cruise: np.ndarray) -> tuple[np.ndarray, ...]:
    """The nodes held at their cap in turn (G,), bool: the cruising ones, then none."""
    return (cruise, np.zeros_like(cruise)) if cruise.any() else (cruise,)


def _time_weights(s: np.ndarray, reference: np.ndarray) -> np.ndarray:
    """Weights (G,) of the linear program's objective ``Σ w x``: the travel time
    ``∫ ds / √x`` falls by ``Δx · ds / (2 x^1.5)`` when x rises by ``Δx``, so each node
    weighs its share of the path over ``x^1.5`` at the reference ``x`` (the round's bound,
    then the previous solution), floored at :data:`SLOW_FLOOR` of the fastest node's speed so
    that a node at rest still counts. Largest weight 1."""
    length = np.diff(s, prepend=s[0]) + np.diff(s, append=s[-1])
    floor = (SLOW_FLOOR**2) * max(float(reference.max()), 1e-300)
    weights = length / np.maximum(reference, floor) ** 1.5
    normalised: np.ndarray = weights / weights.max()
    return normalised


def _cruising(s: np.ndarray, top: np.ndarray, steady: np.ndarray) -> np.ndarray:
    """Nodes the linear program holds at their bound ``top`` (G,), bool: those farther than
    :data:`CRUISE_CLEARANCE` from any node where ``top`` changes or where the joints allow
    less than :data:`CRUISE_ROOM` times the speed ``√top`` at a constant speed. There the
    curve cruises at its cap (the window plan's plateaus), and the linear program only plans
    the slowed parts and the speed changes around them (if that leaves a speed change too
    little room, :func:`_solve` plans again with every node free)."""
    flat = np.ones(len(s), dtype=bool)
    flat[1:-1] = (top[1:-1] == top[:-2]) & (top[1:-1] == top[2:])
    flat[[0, -1]] = False
    busy = s[~(flat & (CRUISE_ROOM**2 * top <= steady**2))]
    if not busy.size:
        return np.ones(len(s), dtype=bool)
    index = np.searchsorted(busy, s)
    after = busy[np.minimum(index, len(busy) - 1)]
    before = busy[np.maximum(index - 1, 0)]
    nearest: np.ndarray = np.minimum(np.abs(after - s), np.abs(s - before))
    return nearest > CRUISE_CLEARANCE


def _differences(s: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Three-point difference weights at the inner nodes of ``s`` (G,): the first and the
    second derivative at node k are the weights (G - 2, 3) times the values at k - 1, k and
    k + 1 (exact for quadratics on any spacing; the central differences on a uniform one)."""
    h1 = np.diff(s)[:-1, None]
    h2 = np.diff(s)[1:, None]
    total = h1 + h2
    slope = np.hstack([-h2 / (h1 * total), (h2 - h1) / (h1 * h2), h1 / (h2 * total)])
    bend = np.hstack([2.0 / (h1 * total), -2.0 / (h1 * h2), 2.0 / (h2 * total)])
    return slope, bend


def _rest_envelope(s: np.ndarray, d1: np.ndarray, jerk: np.ndarray) -> np.ndarray:
    """Bound on ``x = ṡ²`` (G,) near the rests at both ends of a stretch.

    Leaving or reaching a rest at a constant path jerk ``J`` covers ``s = J t³/6`` at
    ``ṡ = J t²/2``, so ``x = (6^(4/3)/4) J^(2/3) s^(4/3)`` at a distance ``s`` from the rest.
    ``J`` is :data:`REST_JERK_SHARE` of the lowest path jerk ``q⃛max / |q'|`` between the rest
    and the node (the rest of the joint jerk is left to the terms in q'' and q'''). The
    linear program's difference quotients cannot see the first interval, where the
    acceleration must grow from zero; this bound shapes it.

    Parameters
    ----------
    s
        Nodes, shape (G,), m.
    d1
        q' before and after each node, shape (2, G, n), rad/m.
    jerk
        Joint jerk limits at each node, shape (G, n), rad/s³.
    """
    with np.errstate(divide="ignore"):
        path_jerk = REST_JERK_SHARE * np.min(jerk / np.abs(d1), axis=(0, 2))
    forward = np.minimum.accumulate(path_jerk)
    backward = np.minimum.accumulate(path_jerk[::-1])[::-1]
    start = 6.0 ** (4.0 / 3.0) / 4.0 * np.cbrt(forward * (s - s[0]) ** 2) ** 2
    end = 6.0 ** (4.0 / 3.0) / 4.0 * np.cbrt(backward * (s[-1] - s) ** 2) ** 2
    envelope: np.ndarray = np.minimum(start, end)
    return envelope


def _node_steps(stretch: _Stretch, speed: np.ndarray) -> np.ndarray:
    """Time between consecutive nodes, shape (G - 1,), s, at the node speeds ``speed`` (G,):
    constant acceleration between nodes, constant jerk next to the rests at both ends."""
    step: np.ndarray = 2.0 * np.diff(stretch.s) / np.maximum(speed[1:] + speed[:-1], 1e-300)
    step[[0, -1]] *= 1.5  # from and to rest at constant jerk: s/ṡ = t/3, not t/2
    return step


def _sample(
    stretches: list[_Stretch], speeds: list[np.ndarray], sample_time: float
) -> np.ndarray | None:
    """Arc length at Ts along the curve, from rest to rest, shape (N,), m (None when the
    curve stops inside a stretch, has no length, or would last :data:`MAX_DURATION` or
    more).

    Node times from constant acceleration between nodes (constant jerk next to a rest).
    The fraction of a period left at the end is spread over the whole curve: every step
    lasts longer by the same factor (below 1 + Ts / duration), which lowers every speed,
    acceleration and jerk a little and changes none of them abruptly (stretching only the
    steps after the last top speed stepped the speed there by up to 0.3 %, and the spline's
    jerk rang up to 3.4 times the limit over it). s(t) of each stretch is the quintic
    spline through (t, s) at the nodes, at rest (ṡ = s̈ = 0) at both ends, so its jerk is
    continuous.
    """
    steps = [_node_steps(stretch, v) for stretch, v in zip(stretches, speeds, strict=True)]
    duration = float(sum(step.sum() for step in steps))
    if not 0.0 < duration < MAX_DURATION:  # no length to time, or too slow
        return None
    n_steps = max(1, int(np.ceil(duration / sample_time - 1e-9)))
    # every step a little longer: slower (by less than a period over the duration), and
    # smooth: a longer step at one node would be a speed step the spline rings over
    steps = [step * (n_steps * sample_time / duration) for step in steps]
    times = np.arange(n_steps + 1) * sample_time
    out = np.empty(len(times))
    start = 0.0
    from scipy.interpolate import make_interp_spline  # only where a curve is sampled

    rest = [(1, 0.0), (2, 0.0)]
    for stretch, step in zip(stretches, steps, strict=True):
        t = start + np.concatenate([[0.0], np.cumsum(step)])
        spline = make_interp_spline(t, stretch.s, k=5, bc_type=(rest, rest))
        inside = (times >= t[0] - 1e-9 * sample_time) & (times <= t[-1] + 1e-9 * sample_time)
        out[inside] = spline(np.clip(times[inside], t[0], t[-1]))
        start = t[-1]
    first, end = stretches[0].s[0], stretches[-1].s[-1]
    out = np.maximum.accumulate(np.clip(out, first, end))
    out[-1] = end
    return out


def _over_speed(
    s: np.ndarray, task: Task, stretches: list[_Stretch]
) -> tuple[np.ndarray, np.ndarray]:
    """Samples whose mean speed over the period before them, ``Δs / Ts``, passes the cap of
    the zone they end in or of the one before, shape (V,), int (the caps of the nodes
    around them, which lie on the lower side at a zone boundary), and speed / cap there."""
    nodes = np.concatenate([st.s for st in stretches])
    caps = np.concatenate([st.cap for st in stretches])
    cap = caps[np.clip(np.searchsorted(nodes, s), 0, len(nodes) - 1)] / CAP_SHARE
    cap[1:] = np.maximum(cap[1:], cap[:-1])
    speed = np.diff(s, prepend=s[0]) / task.sample_time
    bad = np.flatnonzero(speed > cap * (1.0 + 1e-9))
    return bad, speed[bad] / cap[bad]


def _lower(
    s_nodes: np.ndarray,
    speed: np.ndarray,
    scale: np.ndarray,
    hits: np.ndarray,
    s_bad: np.ndarray,
    order: np.ndarray,
    ratio: np.ndarray,
) -> None:
    """Lower the limit of each failing order at the nodes around each failing sample.

    Orders 1–3 are the joint velocity, acceleration and jerk (``scale`` rows 0–2: the
    limit by :data:`REBUILD_FACTOR` over the ratio found); order 4 the speed cap (row 3, by
    the excess found and twice as much again); order ``4 + o`` a check other than the rates
    (the torques) whose value scales with the speed to the power ``o``: the node speeds
    ``speed`` (G,), m/s, fall to ``(REBUILD_FACTOR / ratio)^(1/o)`` of what they are (a
    ceiling, row 4, m/s) and the acceleration limit with their square, as if that part of
    the curve ran slower in time.

    The reach is :data:`REBUILD_REACH` nodes, times :data:`REBUILD_SPREAD` for each earlier
    rebuild that lowered the node nearest the sample (``hits`` (G,), counted here): a speed
    change whose start fails again just beside the lowered nodes is caught within a few
    rebuilds instead of creeping one node a time.
    """
    inside = (s_bad >= s_nodes[0]) & (s_bad <= s_nodes[-1])
    # positions in nodes (fractional): the reach counts nodes, wherever they are finer
    position = np.interp(s_bad[inside], s_nodes, np.arange(len(s_nodes)))
    index = np.arange(len(s_nodes))
    factor = np.ones((4, len(s_nodes)))
    ceiling = scale[4].copy()
    touched = np.zeros(len(s_nodes), dtype=bool)
    for where, o, r in zip(position, order[inside], ratio[inside], strict=True):
        reach = REBUILD_REACH * REBUILD_SPREAD ** hits[int(where + 0.5)]
        # full lowering within the reach, tapering off over as much again beyond it, so
        # the lowered limit has no step of its own
        taper = np.clip(2.0 - np.abs(index - where) / reach, 0.0, 1.0)
        near = taper > 0.0
        touched |= near
        if o > 4:
            lowered = 1.0 - taper * (1.0 - (REBUILD_FACTOR / r) ** (1.0 / (o - 4)))
            ceiling[near] = np.minimum(ceiling[near], lowered[near] * speed[near])
            factor[1] = np.minimum(factor[1], lowered**2)
            continue
        target = REBUILD_FACTOR / r if o < 4 else (1.0 - 2.0 * (r - 1.0)) / r
        factor[o - 1] = np.minimum(factor[o - 1], 1.0 - taper * (1.0 - target))
    scale[:4] *= factor
    scale[4] = ceiling
    hits += touched


def _joint_caps(stretch: _Stretch, robot: Robot, share: float) -> tuple[np.ndarray, np.ndarray]:
    """Highest constant speed the joints allow at each node, shape (G,), m/s, and what sets
    it (e.g. ``"joint 4 jerk"``), shape (G,)."""
    q1, q2, q3 = (np.abs(d).max(axis=0) for d in (stretch.d1, stretch.d2, stretch.d3))
    with np.errstate(divide="ignore"):
        caps = np.stack(
            [
                share * robot.v_max / q1,
                np.sqrt(share * robot.a_max / q2),
                np.cbrt(share * robot.j_max / q3),
            ]
        )  # (3, G, n)
    flat = caps.transpose(1, 0, 2).reshape(len(stretch.s), -1)
    best = np.argmin(flat, axis=1)
    n = robot.n_dof
    kinds = ("velocity", "acceleration", "jerk")
    reasons = np.array([f"joint {b % n + 1} {kinds[b // n]}" for b in best])
    return flat[np.arange(len(best)), best], reasons
