"""A continuous speed curve under the joint limits, for paths whose speed cap varies
quickly.

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
:data:`~trackplan.timing.curve_nodes.NODE_SPACING`, the spacing growing gradually away from
a fine part (:data:`~trackplan.timing.curve_nodes.NODE_GROWTH`). Between the grid's points a
node takes the joint derivatives from IK where they ask for more than the grid's
interpolated ones, and a grid gap where they rise unseen (a seam frame that starts turning
between two points of a straight's coarse grid) is bisected and graded
(:func:`~trackplan.timing.curve_nodes._demand`,
:func:`~trackplan.timing.curve_nodes._features`). With three-point differences on these
nodes for ``x'`` and ``x''`` (exact for quadratics on any spacing) the acceleration is
linear in x, and so is the jerk once ``√x`` is bounded by a speed ``v̄`` known to lie above
it: ``|q' x''/2 + 3 q'' x'/2 + q''' x| ≤ q⃛max / v̄`` with ``x ≤ v̄²`` is a sufficient
(conservative) form. Under these linear bounds, the velocity limits and the task's speed
caps, a linear program (HiGHS's dual simplex, through :func:`scipy.optimize.linprog`)
maximises ``Σ w x``, each node weighted by its share of the travel time (``ds / x^1.5`` at a
reference x, so a node near rest costs what it costs in time). It is solved in rounds: first
with ``v̄`` :data:`~trackplan.timing.curve_program.FIRST_ROOMS` times the constant speed the
joints allow at each node, then with ``v̄`` each of
:data:`~trackplan.timing.curve_program.SPEED_ROOMS` times the previous solution (the
reference x of the weights), so that the last bound lies within 10 % of the speed it bounds.
The signed joint-path derivatives enter as they are, so the curve uses the cancellations the
optimum uses; but the path-jerk term ``q' x''/2`` alone stays within
:data:`~trackplan.timing.curve_program.CANCEL_ROOM` times the jerk bound, so that a rebuild
that lowers the jerk limit where the samples rang lowers the path jerk there too (near a
wrist flip the terms are a thousand times the limit, and the program would rather cancel
more of them). Only rows that can bind enter the program (a row whose largest value for ``0
≤ x ≤ v̄²`` stays within its limit cannot), and nodes far from any slowed or changing part
cruise at their cap outside it (:func:`~trackplan.timing.curve_program._cruising`).

Each stretch between stops is planned from rest to rest; next to a rest, where the
difference quotients cannot see the acceleration grow from zero, x is also bounded by a
start at constant path jerk (:func:`~trackplan.timing.curve_program._rest_envelope`). The
nodes become times by the constant-acceleration step ``Δt = 2h / (ṡ_k + ṡ_{k+1})`` (constant
jerk next to a rest), and s(t) is the quintic spline through (t, s) at the nodes, at rest at
both ends, sampled at Ts. The samples go through the law's sample checks and the speed caps;
where one fails, the limits (or the cap) of the nodes around it are lowered by the ratio
found and the curve is planned again (:data:`MAX_REBUILDS` times at most), over a reach that
grows by :data:`REBUILD_SPREAD` each time the same nodes fail again. A check other than the
joint rates (the torques) names no limit of the program: where it fails, the speed of the
nodes around it is capped below the speed planned there, by the check's ratio and order.

The nodes are built in :mod:`trackplan.timing.curve_nodes`, the linear program solved in
:mod:`trackplan.timing.curve_program`; this module plans, samples and rebuilds the curve.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from trackplan.jointpath import JointPath
from trackplan.motion import JointSamples
from trackplan.robots.machine import Machine
from trackplan.robots.model import Robot
from trackplan.task import Task
from trackplan.timing.curve_nodes import CAP_SHARE, Stretch, node_steps, split_stretches
from trackplan.timing.curve_program import MAX_DURATION, solve_curve
from trackplan.timing.sample_checks import (
    RateLimits,
    SampleCheck,
    run_motion_checks,
)

MAX_REBUILDS = 10
"""Plans of the curve with lowered limits before the law gives up on it."""
REBUILD_REACH = 3
"""Nodes on each side of a failing sample whose limits a rebuild lowers (the first time)."""
REBUILD_SPREAD = 1.5
"""Growth of that reach for each earlier rebuild that lowered the same nodes."""
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
    stretches = split_stretches(joint_path, task)
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
                x = solve_curve(stretch, limits, np.minimum(stretch.cap * scale[3], scale[4]))
                if x is None:
                    return None
                speeds.append(np.sqrt(x))
        if sum(node_steps(st, v).sum() for st, v in zip(stretches, speeds, strict=True)) >= to_beat:
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


def _sample(
    stretches: list[Stretch], speeds: list[np.ndarray], sample_time: float
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
    steps = [node_steps(stretch, v) for stretch, v in zip(stretches, speeds, strict=True)]
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
    s: np.ndarray, task: Task, stretches: list[Stretch]
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


def _joint_caps(
    stretch: Stretch, robot: Robot | Machine, share: float
) -> tuple[np.ndarray, np.ndarray]:
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
