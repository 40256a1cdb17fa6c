"""The smooth time law: steady process speed, jerk-limited speed changes, every joint limit.

Method (``docs/paper.md``, departures 3 and 6; ``docs/timing.md``):

1. The planned path is cut into zones: straight pieces (capped at the rated speed), curved
   pieces and G2 blends (capped at the corner speed, planned :data:`LIMIT_MARGIN` under it),
   and stops (full reversals). The joint path gives the signed q', q'', q''' on each zone's
   grid; at constant path speed v the joint velocity, acceleration and jerk are ``q' v``,
   ``q'' v²`` and ``q''' v³``, which caps the speed each grid point allows.
2. Zones are split into windows where the joint limits lower that cap on part of them
   (levels 0.9^k of the task cap on straights, 0.95^k on arcs and blends): a straight slows
   down only where it must, and the speed through a blend follows its joint demand.
3. Each window holds one plateau. Speed changes are jerk-limited (trapezoidal acceleration
   pulses) inside the faster of two neighbouring windows, so the speed never exceeds a cap.
   Their acceleration and jerk bounds are sized from the joint demand along the stretch they
   actually cover, at the speed, acceleration and jerk they have there
   (:func:`~trackplan.timing.demand.speed_change`). A window too short for its changes gets a
   lower plateau (look-ahead over all windows).
4. The profile is sampled at Ts, mapped to joints by IK, and run through the sample checks
   (:mod:`trackplan.timing.sample_checks`: the joint rate limits by backward differences,
   exactly as the checker, :data:`LIMIT_MARGIN` under each limit; more checks may be handed
   in). Where a sample still fails (the grid missed a peak), that window's plateau or
   speed-change bounds are lowered and the law is rebuilt.

Straight windows therefore run at exactly the rated speed wherever the limits allow.
"""

from __future__ import annotations

import numpy as np

from trackplan.choices import Timing
from trackplan.jointpath import JointPath
from trackplan.motion import JointSamples
from trackplan.status import Status
from trackplan.task import Task
from trackplan.timing.continuous import SpeedCurve, plan_speed_curve
from trackplan.timing.profile import speed_change_time
from trackplan.timing.protocol import SlowDown, TimedPath, TimeLaw, unsampled
from trackplan.timing.sample_checks import (
    LIMIT_MARGIN,
    SampleCheck,
    robot_checks,
    run_motion_checks,
)
from trackplan.timing.zones import ZonePlan, ZonePlanner, slow_down_windows, zone_demands

LIMIT_SHARE = 0.97
"""Share of each joint limit the planner aims at; the rest absorbs sampling effects."""
MAX_ITERATIONS = 12
MAX_SAMPLES = 2_000_000
"""Longest trajectory built, in samples (33 min at 1 ms): beyond it a joint limit has forced
the speed to almost nothing somewhere (a path through a singularity), and the time law
says where instead of sampling it."""


def plan_smooth_time_law(
    joint_path: JointPath, task: Task, sample_checks: tuple[SampleCheck, ...] | None = None
) -> TimedPath:
    """Shortest jerk-limited time law of the smooth mode (see the module docstring).

    Parameters
    ----------
    joint_path
        q(s) on the chosen IK branch, with its derivatives on the planning grid.
    task
        Rated and corner speeds (m/s) and the sample time Ts (s).
    sample_checks
        What the sampled joints must pass before the law returns
        (:mod:`trackplan.timing.sample_checks`); default: the robot's joint rate limits, and
        its torque limits when it has dynamics.

    Returns
    -------
    TimedPath
        Sampled at Ts from rest to rest; the last sample is the end of the path.
    """
    robot = joint_path.robot
    sample_time = task.sample_time
    checks = sample_checks if sample_checks is not None else robot_checks(robot)
    zones = joint_path.geometry.zones()
    demands = zone_demands(joint_path)
    zones, demands = slow_down_windows(
        robot, zones, demands, task.rated_speed, task.corner_speed, LIMIT_SHARE
    )
    planner = ZonePlanner(robot, zones, demands, task.rated_speed, task.corner_speed, LIMIT_SHARE)
    length = zones[-1][1]
    failing = ""  # the limit the last rebuild was for
    for iteration in range(1, MAX_ITERATIONS + 1):
        plans = planner.plan()
        halted = [
            p for p in plans if p.kind != "stop" and p.s_end > p.s_start and not p.plateau > 0.0
        ]
        if halted or not length > 0.0:
            message = _standstill_message(halted, length, failing)
            return unsampled(
                Timing.SMOOTH, Status.LIMITS_VIOLATED, message, sample_time, robot.n_dof
            )
        profile = planner.profile(plans, length, sample_time)
        n_steps = max(1, int(np.ceil(profile.duration / sample_time - 1e-9)))
        if n_steps > MAX_SAMPLES:
            slowest = min((p for p in plans if p.kind != "stop"), key=lambda p: p.plateau)
            hint = " (a singularity near the path?)" if slowest.reason.startswith("joint") else ""
            message = (
                f"the time law would need {profile.duration:.4g} s: {slowest.reason} holds the "
                f"speed to {slowest.plateau:.3g} m/s at s = {slowest.s_start:.4f}.."
                f"{slowest.s_end:.4f} m{hint}"
            )
            return unsampled(
                Timing.SMOOTH, Status.LIMITS_VIOLATED, message, sample_time, robot.n_dof
            )
        time_scale = max(1.0, n_steps * sample_time / profile.duration)
        t = np.arange(n_steps + 1) * sample_time
        s = profile.position(t / time_scale)
        s[-1] = length
        motion = JointSamples(robot, joint_path.joints(s), sample_time)
        worst = run_motion_checks(checks, motion)
        if not worst[0].size:
            law = _sampled(plans, task, s, motion, iteration, converged=True)
            return _or_curve(law, plans, profile.duration, joint_path, task, checks)
        failing = _failing_limit(worst, motion, s)
        planner.tighten(worst, s, t / time_scale, profile)
    law = _sampled(plans, task, s, motion, MAX_ITERATIONS, converged=False)
    return _or_curve(law, plans, profile.duration, joint_path, task, checks)


def _standstill_message(halted: list[ZonePlan], length: float, failing: str) -> str:
    """Why the law cannot move: a window whose speed the joint limits (or the rebuilds for
    ``failing``, the limit a sample kept breaking) brought down to 0, or a path of no length.
    """
    if not halted:
        return f"the path has no length to time ({length:.3g} m)"
    first = halted[0]
    where = f"s = {first.s_start:.4f}..{first.s_end:.4f} m"
    if failing:
        return (
            f"{failing}, and slowing {where} down to a standstill does not bring it under: "
            "no speed meets it (the joint path jumps there: a singularity on the path?)"
        )
    hint = " (a singularity on the path?)" if first.reason.startswith("joint") else ""
    return f"{first.reason} leaves no speed at {where}{hint}"


_ORDER_KINDS = {1: "velocity", 2: "acceleration", 3: "jerk"}


def _failing_limit(
    worst: tuple[np.ndarray, np.ndarray, np.ndarray], motion: JointSamples, s: np.ndarray
) -> str:
    """The worst failing sample of a sample check, in words: ``joint 1 acceleration is 4.8 ×
    its limit at s = 0.0020 m`` (``a joint limit …`` for a check other than the rates)."""
    sample, order, ratio = worst
    k = int(np.argmax(ratio))
    row, kind = int(sample[k]), int(order[k])
    where = f"at s = {s[row]:.4f} m"
    robot = motion.robot
    if kind in _ORDER_KINDS:  # the rates: which joint, and its use of the full limit
        values = (motion.qd, motion.qdd, motion.qddd)[kind - 1][row : row + 4]
        limit = (robot.v_max, robot.a_max, robot.j_max)[kind - 1]
        use = np.abs(values) / limit  # (rows, n)
        joint = int(np.argmax(use.max(axis=0)))
        peak = float(use[:, joint].max())
        if peak >= ratio[k] * (1.0 - LIMIT_MARGIN) * (1.0 - 1e-9):  # the check's sample
            return f"joint {joint + 1} {_ORDER_KINDS[kind]} is {peak:.3g} × its limit {where}"
    return f"a joint limit is {ratio[k]:.3g} × exceeded {where}"


CURVE_SHARE = 0.03
"""Share of the window plan's time spent in windows the joint limits slow down above which
the law also plans one continuous speed curve (:mod:`trackplan.timing.continuous`) and keeps
the faster of the two."""


REBUILT_CURVE_SHARE = 0.01
"""The same share for a window plan that its sample checks rebuilt (lowering whole plateaus
or speed changes, e.g. for the torques): there the curve, which lowers its limits around
the failing samples only, pays from less."""


REST_CHANGE_SHARE = 0.03
"""Share of the window plan's time that its start and its stop take beyond the same speed
changes at the bounds the joints allow at rest (:func:`_rest_change_loss`) above which the
law also plans the speed curve: a speed change runs at one acceleration and one jerk bound
over its whole stretch, so a start through a stretch of high joint demand is slow all along,
where the curve follows the demand node by node."""

RISING = 1e-9
"""Rise of the sampled speed from one sample to the next, relative to the mean speed, below
which a start (or, backwards in time, a stop) has ended."""
CHANGE_HEAD = 512
"""Samples first looked at for the end of a start or a stop (4 × more each time it is not
there)."""


def _or_curve(
    law: TimedPath,
    plans: list[ZonePlan],
    duration: float,
    joint_path: JointPath,
    task: Task,
    checks: tuple[SampleCheck, ...],
) -> TimedPath:
    """The window law, or the continuous speed curve where the joints slow the windows down
    enough for it to pay (:data:`CURVE_SHARE`, or :data:`REST_CHANGE_SHARE` for the start
    and the stop) and it is faster (or the windows failed)."""
    limited = sum(
        (p.s_end - p.s_start) / p.plateau
        for p in plans
        if p.kind != "stop" and p.plateau > 0.0 and p.reason not in ("rated speed", "corner speed")
    )
    share = CURVE_SHARE if law.iterations == 1 else REBUILT_CURVE_SHARE
    if (
        law.success
        and limited < share * duration
        and _rest_change_loss(law.s, task.sample_time, joint_path) < REST_CHANGE_SHARE * duration
    ):
        return law
    curve = plan_speed_curve(
        joint_path, task, checks, LIMIT_SHARE, to_beat=law.duration if law.success else np.inf
    )
    if curve is None or (law.success and curve.duration >= law.duration):
        return law
    return TimedPath(
        timing=Timing.SMOOTH,
        success=True,
        status=Status.FEASIBLE,
        message="",
        sample_time=task.sample_time,
        s=curve.s,
        q=curve.motion.q,
        slowdowns=_curve_slowdowns(curve, joint_path, task.rated_speed),
        iterations=law.iterations + curve.rebuilds,
        motion=curve.motion,
    )


def _rest_change_loss(s: np.ndarray, sample_time: float, joint_path: JointPath) -> float:
    """Time a sampled law's start and stop take beyond a jerk-limited speed change to (from)
    the same speed at the acceleration and jerk bounds the joints allow at rest there.

    At rest only the ``q' s̈`` and ``q' s⃛`` terms of the joint acceleration and jerk act,
    so those bounds are ``LIMIT_SHARE · min_j q̈max_j / |q'_j|`` and the same with ``q⃛max``
    at the path's first (last) point. A change is counted up to the first sample whose
    backward difference is at its top speed.

    Parameters
    ----------
    s
        Sampled arc length from rest to rest, shape (N,), m.
    sample_time
        Ts, s.
    joint_path
        q(s) with its derivatives on the planning grid.

    Returns
    -------
    float
        The two excesses (each at least 0) added, s.
    """
    if s.size < 3:
        return 0.0
    robot = joint_path.robot
    rise = RISING * float(s[-1] - s[0]) / (s.size - 1)  # of Δs per sample, from the mean speed
    loss = 0.0
    for path, d1 in ((s, joint_path.dq[0]), (s[-1] - s[::-1], joint_path.dq[-1])):
        top = _change_end(path, rise)
        accel_need = float(np.max(np.abs(d1) / robot.a_max))
        jerk_need = float(np.max(np.abs(d1) / robot.j_max))
        if accel_need == 0.0 or jerk_need == 0.0:
            continue
        speed = float(path[top + 1] - path[top]) / sample_time
        at_rest = speed_change_time(speed, LIMIT_SHARE / accel_need, LIMIT_SHARE / jerk_need)
        loss += max(0.0, (top + 1) * sample_time - at_rest)
    return loss


def _change_end(s: np.ndarray, rise: float) -> int:
    """Index k of the first backward difference ``s[k + 1] - s[k]`` of a start from rest
    after which the step grows by ``rise`` (m) or less: the top of the start. Looks at
    growing heads of ``s`` (N,), m, since a start is short next to a whole path."""
    head = CHANGE_HEAD
    while True:
        rising = np.diff(s[: head + 2], 2) > rise
        if not rising.all():
            return int(np.argmin(rising))
        if head + 2 >= s.size:
            return rising.size
        head *= 4


def _curve_slowdowns(
    curve: SpeedCurve, joint_path: JointPath, rated: float
) -> tuple[SlowDown, ...]:
    """Where a speed curve runs a straight piece below the rated speed because the joints
    cannot hold it there at a constant speed (as the windows do): each run of such nodes,
    at the lowest speed planned on it and the limit that sets its lowest cap."""
    straight = np.zeros(len(curve.s_nodes), dtype=bool)
    for s0, s1, kind in joint_path.geometry.zones():
        if kind == "straight":
            straight |= (curve.s_nodes >= s0) & (curve.s_nodes <= s1)
    forced = straight & (curve.joint_cap < rated) & (curve.speed < rated * (1 - 1e-9))
    edges = np.flatnonzero(np.diff(np.concatenate([[0], forced.astype(int), [0]])))
    out = []
    for first, stop in zip(edges[::2], edges[1::2], strict=True):
        rows = slice(first, stop)
        lowest = first + int(np.argmin(curve.joint_cap[rows]))
        out.append(
            SlowDown(
                float(curve.s_nodes[first]),
                float(curve.s_nodes[stop - 1]),
                float(curve.speed[rows].min()),
                rated,
                str(curve.reason[lowest]),
            )
        )
    return tuple(out)


def _sampled(
    plans: list[ZonePlan],
    task: Task,
    s: np.ndarray,
    motion: JointSamples,
    iterations: int,
    converged: bool,
) -> TimedPath:
    """The law's result: samples, slow-downs and corner speed from the zone plans."""
    rated = task.rated_speed
    plateaus = [z.plateau for z in plans if z.kind == "curved"]
    slowdowns = tuple(
        SlowDown(z.s_start, z.s_end, z.plateau, rated, z.reason)
        for z in plans
        if z.kind == "straight" and z.plateau < rated * (1 - 1e-9)
    )
    message = "" if converged else f"rate limits still exceeded after {iterations} rebuilds"
    return TimedPath(
        timing=Timing.SMOOTH,
        success=converged,
        status=Status.FEASIBLE if converged else Status.NOT_CONVERGED,
        message=message,
        sample_time=task.sample_time,
        s=s,
        q=motion.q,
        slowdowns=slowdowns,
        corner_speed=min(plateaus) if plateaus else rated,
        iterations=iterations,
        motion=motion,
    )


LAW = TimeLaw(Timing.SMOOTH, "g2", plan_smooth_time_law)
"""The smooth law, as :data:`trackplan.timing.TIME_LAWS` lists it."""
