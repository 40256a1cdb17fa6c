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

import itertools
from dataclasses import dataclass

import numpy as np

from trackplan.choices import Timing
from trackplan.jointpath import JointPath
from trackplan.motion import JointSamples
from trackplan.robots.model import Robot
from trackplan.status import Status
from trackplan.task import Task
from trackplan.timing import _kernels, _kernels_samples
from trackplan.timing.continuous import SpeedCurve, plan_speed_curve
from trackplan.timing.demand import (
    SpeedChange,
    ZoneDemand,
    cruise_cap,
    speed_change,
)
from trackplan.timing.profile import (
    SpeedProfile,
    speed_change_distance,
    speed_change_phases,
    speed_change_time,
)
from trackplan.timing.protocol import SlowDown, TimedPath, TimeLaw, unsampled
from trackplan.timing.sample_checks import (
    LIMIT_MARGIN,
    SampleCheck,
    robot_checks,
    run_motion_checks,
)

LIMIT_SHARE = 0.97
"""Share of each joint limit the planner aims at; the rest absorbs sampling effects."""
MAX_ITERATIONS = 12
PLATEAU_GRID = 24
PLATEAU_ROUNDS = 2
"""A plateau lowered to fit its zone's speed changes is searched on a grid of PLATEAU_GRID
speeds, PLATEAU_ROUNDS times finer each round (precision 1/24² ≈ 2e-3 of the cap)."""
MAX_SAMPLES = 2_000_000
"""Longest trajectory built, in samples (33 min at 1 ms): beyond it a joint limit has forced
the speed to almost nothing somewhere (a path through a singularity), and the time law
says where instead of sampling it."""


@dataclass(frozen=True)
class ZonePlan:
    """One zone of the path and the speed it is run at.

    Attributes
    ----------
    s_start, s_end
        Arc length on the planned path, m.
    kind
        ``straight``, ``curved`` or ``stop``.
    cap
        Highest constant speed the task and the joint limits allow here, m/s.
    plateau
        Speed actually held (lower when the zone is too short for its speed changes), m/s.
    reason
        What sets the plateau: ``rated speed``, ``corner speed``, ``joint 4 velocity``, …
    """

    s_start: float
    s_end: float
    kind: str
    cap: float
    plateau: float
    reason: str


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
    demands = _zone_demands(joint_path)
    zones, demands = _slow_down_windows(robot, zones, demands, task.rated_speed, task.corner_speed)
    planner = _ZonePlanner(robot, zones, demands, task.rated_speed, task.corner_speed)
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


def _zone_demands(joint_path: JointPath) -> list[ZoneDemand]:
    """Signed dq/ds, d²q/ds², d³q/ds³ of each zone, from the joint path's planning grid
    (views of its rows: the grid runs zone after zone)."""
    zone = joint_path.zone
    n_zones = len(joint_path.geometry.zones())
    rows_of: list[slice | np.ndarray]
    if np.all(zone[1:] >= zone[:-1]):
        bounds = np.searchsorted(zone, np.arange(n_zones + 1)).tolist()
        rows_of = [slice(a, b) for a, b in itertools.pairwise(bounds)]
    else:
        rows_of = [np.flatnonzero(zone == z) for z in range(n_zones)]
    return [
        ZoneDemand(
            joint_path.s[rows], joint_path.dq[rows], joint_path.ddq[rows], joint_path.dddq[rows]
        )
        for rows in rows_of
    ]


WINDOW_LEVEL = 0.9
"""Ratio between successive speed levels of slow-down windows on straight zones."""
CURVED_WINDOW_LEVEL = 0.95
"""Ratio between successive speed levels on arcs and blends, where the speed follows the
joint limits more closely (a blend's joint jerk peaks near its ends)."""
WINDOW_MIN_LENGTH = 5e-3
"""Shortest slow-down window on a straight zone, m: shorter runs join their slower neighbour."""
CURVED_WINDOW_SHARE = 0.125
"""Shortest window on an arc or blend, as a share of the zone's length (when below
WINDOW_MIN_LENGTH: a blend a few millimetres long gets several windows)."""


def _slow_down_windows(
    robot: Robot,
    zones: list[tuple[float, float, str]],
    demands: list[ZoneDemand],
    rated_speed: float,
    corner_speed: float,
) -> tuple[list[tuple[float, float, str]], list[ZoneDemand]]:
    """Split zones where the joint limits force a lower speed on only part of them.

    Along a zone the local cap (the speed the joints allow at each grid point) is rounded
    down to levels ``task cap · r^k`` (r = :data:`WINDOW_LEVEL` on straight zones,
    :data:`CURVED_WINDOW_LEVEL` on curved ones); runs of one level become windows of their
    own, so a straight piece slows down only where it must and runs at the rated speed
    elsewhere, and the speed through a blend follows its joint demand. Short windows join
    the slower neighbour (never raising a cap).
    """
    out_zones: list[tuple[float, float, str]] = []
    out_demands: list[ZoneDemand] = []
    for (s0, s1, kind), demand in zip(zones, demands, strict=True):
        task_cap = rated_speed if kind == "straight" else corner_speed
        usable = kind != "stop" and len(demand.s) > 2
        local = demand.local_caps(robot, LIMIT_SHARE) if usable else None
        if local is None or local.min() >= task_cap:
            out_zones.append((s0, s1, kind))
            out_demands.append(demand)
            continue
        straight = kind == "straight"
        ratio = np.minimum(local, task_cap) / task_cap
        step = np.log(WINDOW_LEVEL if straight else CURVED_WINDOW_LEVEL)
        level = np.ceil(np.log(np.maximum(ratio, 1e-12)) / step - 1e-9)
        level = np.maximum(level, 0).astype(int)
        shortest = WINDOW_MIN_LENGTH
        if not straight:
            shortest = min(shortest, CURVED_WINDOW_SHARE * (s1 - s0))
        for first, last in _level_runs(demand.s, level, shortest):
            a = s0 if first == 0 else 0.5 * (demand.s[first - 1] + demand.s[first])
            b = s1 if last == len(demand.s) - 1 else 0.5 * (demand.s[last] + demand.s[last + 1])
            out_zones.append((float(a), float(b), kind))
            out_demands.append(demand.part(max(first - 1, 0), min(last + 2, len(demand.s))))
    return out_zones, out_demands


def _level_runs(s: np.ndarray, level: np.ndarray, shortest: float) -> list[tuple[int, int]]:
    """Runs (first, last grid index) of equal level, runs under ``shortest`` (m) merged
    into slower ones (compiled: :func:`trackplan.timing._kernels_samples.level_runs`)."""
    starts, ends = _kernels_samples.level_runs(s, level.astype(np.int64), shortest)
    return list(zip(starts.tolist(), ends.tolist(), strict=True))


class _ZonePlanner:
    """Plateaus and speed changes over the zones, with per-zone safety scales."""

    def __init__(
        self,
        robot: Robot,
        zones: list[tuple[float, float, str]],
        demands: list[ZoneDemand],
        rated_speed: float,
        corner_speed: float,
    ) -> None:
        self.robot = robot
        self.zones = zones
        self.demands = demands
        self.rated_speed = rated_speed
        self.corner_speed = corner_speed
        self.cap_scale = np.ones(len(zones))
        self.change_scale = np.ones(len(zones))
        self._changes: dict[tuple[int, float, float], SpeedChange] = {}
        self._zone_arrays: tuple[np.ndarray, ...] | None = None

    def _packed(self) -> tuple[np.ndarray, ...]:
        """The zones' grids and peaks one after the other, for the compiled plateau search:
        ``offsets (Z + 1,), s (G,), peaks (Z, 3, n)`` and the running maxima from each
        zone's start and from its end, ``(G, 3, n)`` each (built once)."""
        if self._zone_arrays is None:
            demands = self.demands
            sizes = [len(d.s) for d in demands]
            self._zone_arrays = (
                np.concatenate([[0], np.cumsum(sizes)]).astype(np.int64),
                np.concatenate([d.s for d in demands]),
                np.stack([d.peak_array for d in demands]),
                np.concatenate([d.running_maxima(0) for d in demands]),
                np.concatenate([d.running_maxima(1) for d in demands]),
            )
        return self._zone_arrays

    def change(self, z: int, v_from: float, v_to: float) -> SpeedChange:
        """The speed change inside zone z: a rise starts at its start, a fall ends at its end.

        Its bounds come from the joint demand along the stretch it covers, at the speed it
        has there (:func:`~trackplan.timing.demand.speed_change`, started from the quick
        change over the stretch it covers).
        """
        key = (z, v_from, v_to)
        if key not in self._changes:
            s0, s1, _ = self.zones[z]
            share = LIMIT_SHARE * self.change_scale[z]
            self._changes[key] = speed_change(
                self.robot,
                self.demands[z],
                s0,
                s1,
                v_from,
                v_to,
                at_start=v_to > v_from,
                share=share,
                quick_start=True,
            )
        return self._changes[key]

    def plan(self) -> list[ZonePlan]:
        """Caps per zone, then plateaus lowered until every zone fits its speed changes.

        The plateau search runs compiled over all zones
        (:func:`trackplan.timing._kernels.plateau_search`): a zone whose quick speed
        changes (:func:`~trackplan.timing._kernels.quick_distances`, never shorter than
        :meth:`change`'s) need more than its length is lowered to the highest speed of a
        :data:`PLATEAU_GRID` grid that fits, :data:`PLATEAU_ROUNDS` times finer each round,
        in look-ahead passes until every zone fits.
        """
        zones = self.zones
        n = len(zones)
        caps = np.zeros(n)
        reasons = [""] * n
        for z, (_, _, kind) in enumerate(zones):
            if kind == "stop":
                caps[z], reasons[z] = 0.0, "stop"
                continue
            task_cap = _task_cap(kind, self.rated_speed, self.corner_speed)
            share = LIMIT_SHARE * self.cap_scale[z]
            joint_cap, joint_reason = cruise_cap(self.robot, self.demands[z].peaks(), share)
            if joint_cap < task_cap:
                caps[z], reasons[z] = joint_cap, joint_reason
            else:
                caps[z] = task_cap
                reasons[z] = "rated speed" if kind == "straight" else "corner speed"
        lengths = np.array([s1 - s0 for s0, s1, _ in zones])
        offsets, s, peaks, from_start, from_end = self._packed()
        share = (LIMIT_SHARE * self.change_scale)[:, None]
        plateau, lowered = _kernels.plateau_search(
            lengths,
            caps,
            offsets,
            s,
            peaks,
            from_start,
            from_end,
            share * self.robot.a_max,
            share * self.robot.j_max,
            PLATEAU_GRID,
            PLATEAU_ROUNDS,
        )
        for z in np.flatnonzero(lowered).tolist():
            reasons[z] = _too_short(reasons[z])
        return [
            ZonePlan(s0, s1, kind, float(caps[z]), float(plateau[z]), reasons[z])
            for z, (s0, s1, kind) in enumerate(zones)
        ]

    def profile(self, plans: list[ZonePlan], length: float, sample_time: float) -> SpeedProfile:
        """Jerk phases zone by zone (change in, cruise, change out), lasting whole periods.

        The fraction of a period left over is absorbed by the final stop, made slightly
        gentler (lower jerk), so that every cruise keeps its exact speed.
        """
        phases = self._phases(plans, stretch=0.0)
        assert phases is not None  # without stretch every zone fits by construction
        duration = sum(d for d, _ in phases)
        slack = np.ceil(duration / sample_time - 1e-9) * sample_time - duration
        if slack > 1e-12:
            phases = self._phases(plans, stretch=slack) or phases
        return SpeedProfile.from_phases(phases, length)

    def _phases(self, plans: list[ZonePlan], stretch: float) -> list[tuple[float, float]] | None:
        """Jerk phases of the plan, the final stop ``stretch`` s longer in total.

        Returns None when the last zone has no cruise left to give the longer stop.
        """
        phases: list[tuple[float, float]] = []
        n = len(plans)
        last = max((z for z, p in enumerate(plans) if p.plateau > 0.0), default=-1)
        for z, plan in enumerate(plans):
            v = plan.plateau
            if v == 0.0:
                continue
            before = plans[z - 1].plateau if z > 0 else 0.0
            after = plans[z + 1].plateau if z < n - 1 else 0.0
            cruise = plan.s_end - plan.s_start
            change_in: list[tuple[float, float]] = []
            change_out: list[tuple[float, float]] = []
            if before < v:
                rise = self.change(z, before, v)
                change_in = speed_change_phases(before, v, rise.accel, rise.jerk)
                cruise -= rise.distance
            if after < v:
                fall = self.change(z, v, after)
                distance, accel, jerk = fall.distance, fall.accel, fall.jerk
                if z == last and stretch > 0.0:
                    # a stop lasting δ longer covers v·δ/2 more: the cruise gives it, and the
                    # whole motion then lasts δ/2 longer: stretch the stop by 2·stretch.
                    longer = speed_change_time(v - after, accel, jerk) + 2.0 * stretch
                    jerk = _jerk_for_duration(v - after, accel, jerk, longer)
                    distance = speed_change_distance(v, after, accel, jerk)
                change_out = speed_change_phases(v, after, accel, jerk)
                cruise -= distance
            if cruise < 0.0:
                if stretch > 0.0:
                    return None
                cruise = 0.0
            phases.extend(change_in)
            phases.append((cruise / v, 0.0))
            phases.extend(change_out)
        return phases

    def tighten(
        self,
        worst: tuple[np.ndarray, np.ndarray, np.ndarray],
        s: np.ndarray,
        t_profile: np.ndarray,
        profile: SpeedProfile,
    ) -> None:
        """Lower the plateau or the speed-change bounds of every zone that broke a limit.

        A violation whose backward-difference window (4 samples) lies in a cruise lowers
        the zone's plateau by ratio^(-1/order); one that touches a speed change lowers the
        change bounds of its zone and of the next (a change at a zone edge feels both).
        """
        sample, order, ratio = worst
        n_zones = len(self.zones)
        starts = np.array([z[0] for z in self.zones])
        zone = np.clip(np.searchsorted(starts, s[sample], side="right") - 1, 0, n_zones - 1)
        phase = profile.phase_index(t_profile)
        cruising = (profile.jerk[phase] == 0.0) & (np.abs(profile.a0[phase]) < 1e-12)
        window = np.convolve(cruising.astype(int), np.ones(4, dtype=int))[: len(cruising)]
        in_cruise = window[sample] == np.minimum(sample + 1, 4)
        new_cap = np.ones(n_zones)
        np.minimum.at(
            new_cap, zone[in_cruise], 0.98 * ratio[in_cruise] ** (-1.0 / order[in_cruise])
        )
        new_change = np.ones(n_zones)
        changing = ~in_cruise
        for shift in (0, 1):
            np.minimum.at(
                new_change, np.minimum(zone[changing] + shift, n_zones - 1), 0.95 / ratio[changing]
            )
        self.cap_scale *= new_cap
        self.change_scale *= new_change
        self._changes.clear()


def _task_cap(kind: str, rated_speed: float, corner_speed: float) -> float:
    """The task's speed cap on a zone of this kind, m/s: the rated speed on straight zones
    (exactly), the corner speed less :data:`LIMIT_MARGIN` on curved ones."""
    if kind == "straight":
        return rated_speed
    return min(rated_speed, corner_speed * (1.0 - LIMIT_MARGIN))


def _too_short(reason: str) -> str:
    """The reason of a plateau lowered because its zone cannot fit its speed changes."""
    if reason in ("rated speed", "corner speed"):
        return f"too short to reach the {reason} under the joint acceleration and jerk limits"
    return f"{reason}; too short for its speed changes under the joint limits"


def _jerk_for_duration(delta: float, accel: float, jerk: float, duration: float) -> float:
    """The (lower) jerk bound that makes a speed change of ``delta`` last ``duration``."""
    low, high = 0.0, jerk
    for _ in range(80):
        mid = 0.5 * (low + high)
        if mid > 0.0 and speed_change_time(delta, accel, mid) > duration:
            if mid == low:  # the bisection has come to rest: the rounds left change nothing
                break
            low = mid
        else:
            if mid == high:
                break
            high = mid
    return high


LAW = TimeLaw(Timing.SMOOTH, "g2", plan_smooth_time_law)
"""The smooth law, as :data:`trackplan.timing.TIME_LAWS` lists it."""
