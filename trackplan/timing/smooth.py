"""The smooth time law: steady process speed, jerk-limited speed changes, every joint limit.

Method (docs/paper.md, departures 3 and 6; docs/timing.md):

1. The planned path is cut into zones: straight pieces (capped at the rated speed), curved
   pieces and G2 blends (capped at the corner speed), and stops (full reversals).
2. On a fine grid of each zone the joint path q(s) is differentiated in s. At constant
   path speed v the joint velocity, acceleration and jerk are ``q' v``, ``q'' v²`` and
   ``q''' v³``, which caps the speed each zone may hold.
3. Each zone holds one plateau speed. Speed changes are jerk-limited (trapezoidal
   acceleration pulses) whose path acceleration and jerk bounds come from the joint limits:
   ``|q'| s̈ + |q''| v² ≤ q̈max`` and ``|q'| s⃛ + 3 |q''| v s̈ + |q'''| v³ ≤ q⃛max``. A change
   happens inside the faster of the two zones, so the speed never exceeds a cap. A zone
   too short for its changes gets a lower plateau (look-ahead over all zones).
4. The profile is sampled at Ts, mapped to joints, and checked with backward differences
   exactly as the checker does. Where a sample still breaks a limit (the grid missed a peak),
   that zone's plateau or speed-change bounds are lowered and the law is rebuilt.

Straight zones therefore run at exactly the rated speed wherever the limits allow.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from trackplan.case import Task
from trackplan.choices import Timing
from trackplan.derivatives import backward_derivatives
from trackplan.jointpath import JointPath
from trackplan.robots.model import Robot
from trackplan.status import Status
from trackplan.timing.profile import (
    SpeedProfile,
    speed_change_distance,
    speed_change_phases,
    speed_change_time,
)
from trackplan.timing.protocol import SlowDown, TimeLaw, TimeLawSpec, unsampled

LIMIT_SHARE = 0.97
"""Share of each joint limit the planner aims at; the rest absorbs sampling effects."""
MAX_ITERATIONS = 12
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


@dataclass(frozen=True, eq=False)
class _ZoneDemand:
    """|dq/ds|, |d²q/ds²|, |d³q/ds³| on a zone's grid.

    Attributes
    ----------
    s
        Grid, shape (G,), m.
    q1, q2, q3
        Absolute derivatives at the grid points, shape (G, n).
    """

    s: np.ndarray
    q1: np.ndarray
    q2: np.ndarray
    q3: np.ndarray

    def peaks(
        self, s_from: float | None = None, s_to: float | None = None
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Largest |q'|, |q''|, |q'''| per joint over the zone, or over [s_from, s_to]."""
        if s_from is None or s_to is None or len(self.s) < 2:
            return self.q1.max(axis=0), self.q2.max(axis=0), self.q3.max(axis=0)
        step = self.s[1] - self.s[0]
        inside = (self.s >= s_from - step) & (self.s <= s_to + step)
        return (
            self.q1[inside].max(axis=0),
            self.q2[inside].max(axis=0),
            self.q3[inside].max(axis=0),
        )


def plan_smooth_time_law(joint_path: JointPath, task: Task) -> TimeLaw:
    """Shortest jerk-limited time law of the smooth mode (see the module docstring).

    Parameters
    ----------
    joint_path
        q(s) on the chosen IK branch, with its derivatives on the planning grid.
    task
        Rated and corner speeds (m/s) and the sample time Ts (s).

    Returns
    -------
    TimeLaw
        Sampled at Ts from rest to rest; the last sample is the end of the path.
    """
    robot = joint_path.robot
    sample_time = task.sample_time
    zones = joint_path.geometry.zones()
    demands = _zone_demands(joint_path)
    zones, demands = _slow_down_windows(robot, zones, demands, task.rated_speed, task.corner_speed)
    planner = _ZonePlanner(robot, zones, demands, task.rated_speed, task.corner_speed)
    length = zones[-1][1]
    for iteration in range(1, MAX_ITERATIONS + 1):
        plans = planner.plan()
        profile = planner.profile(plans, length, sample_time)
        n_steps = max(1, int(np.ceil(profile.duration / sample_time - 1e-9)))
        if n_steps > MAX_SAMPLES:
            slowest = min((p for p in plans if p.kind != "stop"), key=lambda p: p.plateau)
            message = (
                f"the time law would need {profile.duration:.4g} s: {slowest.reason} holds the "
                f"speed to {slowest.plateau:.3g} m/s at s = {slowest.s_start:.4f}.."
                f"{slowest.s_end:.4f} m (a singularity near the path?)"
            )
            return unsampled(
                Timing.SMOOTH, Status.LIMITS_VIOLATED, message, sample_time, robot.n_dof
            )
        time_scale = max(1.0, n_steps * sample_time / profile.duration)
        t = np.arange(n_steps + 1) * sample_time
        s = profile.evaluate(t / time_scale)[0]
        s[-1] = length
        q = joint_path.joints(s)
        worst = _worst_rate_violations(robot, q, sample_time)
        if not worst[0].size:
            return _sampled(plans, task, s, q, iteration, converged=True)
        planner.tighten(worst, s, t / time_scale, profile)
    return _sampled(plans, task, s, q, MAX_ITERATIONS, converged=False)


def _sampled(
    plans: list[ZonePlan],
    task: Task,
    s: np.ndarray,
    q: np.ndarray,
    iterations: int,
    converged: bool,
) -> TimeLaw:
    """The law's result: samples, slow-downs and corner speed from the zone plans."""
    rated = task.rated_speed
    plateaus = [z.plateau for z in plans if z.kind == "curved"]
    slowdowns = tuple(
        SlowDown(z.s_start, z.s_end, z.plateau, rated, z.reason)
        for z in plans
        if z.kind == "straight" and z.plateau < rated * (1 - 1e-9)
    )
    message = "" if converged else f"rate limits still exceeded after {iterations} rebuilds"
    return TimeLaw(
        timing=Timing.SMOOTH,
        success=converged,
        status=Status.FEASIBLE if converged else Status.NOT_CONVERGED,
        message=message,
        sample_time=task.sample_time,
        s=s,
        q=q,
        slowdowns=slowdowns,
        corner_speed=min(plateaus) if plateaus else rated,
        iterations=iterations,
    )


def _zone_demands(joint_path: JointPath) -> list[_ZoneDemand]:
    """|dq/ds|, |d²q/ds²|, |d³q/ds³| of each zone, from the joint path's planning grid."""
    demands = []
    for z in range(len(joint_path.geometry.zones())):
        rows = joint_path.zone == z
        demands.append(
            _ZoneDemand(
                joint_path.s[rows],
                np.abs(joint_path.dq[rows]),
                np.abs(joint_path.ddq[rows]),
                np.abs(joint_path.dddq[rows]),
            )
        )
    return demands


WINDOW_LEVEL = 0.9
"""Ratio between successive speed levels of slow-down windows."""
WINDOW_MIN_LENGTH = 5e-3
"""Shortest slow-down window, m: shorter runs join their slower neighbour."""


def _local_caps(robot: Robot, demand: _ZoneDemand) -> np.ndarray:
    """Highest constant speed the joint limits allow at each grid point, shape (G,), m/s."""
    share = LIMIT_SHARE
    caps = np.minimum(
        _safe_ratio(share * robot.v_max, demand.q1).min(axis=1),
        np.sqrt(_safe_ratio(share * robot.a_max, demand.q2)).min(axis=1),
    )
    return np.minimum(caps, np.cbrt(_safe_ratio(share * robot.j_max, demand.q3)).min(axis=1))


def _slow_down_windows(
    robot: Robot,
    zones: list[tuple[float, float, str]],
    demands: list[_ZoneDemand],
    rated_speed: float,
    corner_speed: float,
) -> tuple[list[tuple[float, float, str]], list[_ZoneDemand]]:
    """Split zones where the joint limits force a lower speed on only part of them.

    Along a zone the local cap (the speed the joints allow at each grid point) is rounded
    down to levels ``task cap · 0.9^k``; runs of one level become windows of their own, so a
    straight piece slows down only where it must and runs at the rated speed elsewhere.
    Windows shorter than WINDOW_MIN_LENGTH join the slower neighbour (never raising a cap).
    """
    out_zones: list[tuple[float, float, str]] = []
    out_demands: list[_ZoneDemand] = []
    for (s0, s1, kind), demand in zip(zones, demands, strict=True):
        task_cap = rated_speed if kind == "straight" else corner_speed
        local = _local_caps(robot, demand) if kind != "stop" and len(demand.s) > 2 else None
        if local is None or local.min() >= task_cap:
            out_zones.append((s0, s1, kind))
            out_demands.append(demand)
            continue
        ratio = np.minimum(local, task_cap) / task_cap
        level = np.ceil(np.log(np.maximum(ratio, 1e-12)) / np.log(WINDOW_LEVEL) - 1e-9)
        level = np.maximum(level, 0).astype(int)
        runs = _level_runs(demand.s, level)
        for first, last in runs:
            lo = max(first - 1, 0)
            hi = min(last + 2, len(demand.s))
            a = s0 if first == 0 else 0.5 * (demand.s[first - 1] + demand.s[first])
            b = s1 if last == len(demand.s) - 1 else 0.5 * (demand.s[last] + demand.s[last + 1])
            out_zones.append((float(a), float(b), kind))
            out_demands.append(
                _ZoneDemand(demand.s[lo:hi], demand.q1[lo:hi], demand.q2[lo:hi], demand.q3[lo:hi])
            )
    return out_zones, out_demands


def _level_runs(s: np.ndarray, level: np.ndarray) -> list[tuple[int, int]]:
    """Runs (first, last grid index) of equal level, short runs merged into slower ones."""
    level = level.copy()
    while True:
        edges = np.flatnonzero(np.diff(level)) + 1
        starts = np.concatenate([[0], edges])
        ends = np.concatenate([edges - 1, [len(level) - 1]])
        lengths = s[ends] - s[starts]
        short = np.flatnonzero(lengths < WINDOW_MIN_LENGTH)
        if short.size == 0 or len(starts) == 1:
            return list(zip(starts.tolist(), ends.tolist(), strict=True))
        k = int(short[np.argmin(lengths[short])])
        own = int(level[starts[k]])
        neighbours = [j for j in (k - 1, k + 1) if 0 <= j < len(starts)]
        slower = max(neighbours, key=lambda j: int(level[starts[j]]))
        if int(level[starts[slower]]) >= own:  # join the slower neighbour
            level[starts[k] : ends[k] + 1] = level[starts[slower]]
        else:  # the short run is the slowest: its slower neighbour slows down to it
            level[starts[slower] : ends[slower] + 1] = own


def _safe_ratio(numerator: np.ndarray, denominator: np.ndarray) -> np.ndarray:
    """numerator / denominator with +inf where the denominator is zero."""
    out = np.full(np.broadcast(numerator, denominator).shape, np.inf)
    np.divide(numerator, denominator, out=out, where=denominator > 0)
    return out


def _cruise_cap(robot: Robot, peaks: tuple, share: float) -> tuple[float, str]:
    """Highest constant path speed the joint limits allow on a zone, and what binds."""
    q1, q2, q3 = peaks
    candidates = [
        (_safe_ratio(share * robot.v_max, q1), "velocity"),
        (np.sqrt(_safe_ratio(share * robot.a_max, q2)), "acceleration"),
        (np.cbrt(_safe_ratio(share * robot.j_max, q3)), "jerk"),
    ]
    best, reason = np.inf, ""
    for values, kind in candidates:
        j = int(np.argmin(values))
        if values[j] < best:
            best, reason = float(values[j]), f"joint {j + 1} {kind}"
    return best, reason


MAX_PATH_ACCELERATION = 50.0
"""Upper bound on |s̈|, m/s², where no joint bounds it (a joint path that does not move)."""
MAX_PATH_JERK = 5000.0
"""Upper bound on |s⃛|, m/s³, likewise."""


def _change_bounds(
    robot: Robot, peaks: tuple, top_speed: float, share: float
) -> tuple[float, float]:
    """Path acceleration and jerk bounds for a speed change up to ``top_speed``.

    From ``|q'| s̈ + |q''| v² ≤ q̈max`` and ``|q'| s⃛ + 3 |q''| v s̈ + |q'''| v³ ≤ q⃛max``,
    with the acceleration bound lowered where needed to leave half the jerk room to ``s⃛``.
    """
    q1, q2, q3 = peaks
    accel_room = share * robot.a_max - q2 * top_speed**2
    jerk_room = share * robot.j_max - q3 * top_speed**3
    coupling = 3.0 * q2 * top_speed
    accel = min(
        float(np.min(_safe_ratio(accel_room, q1))),
        float(np.min(_safe_ratio(0.5 * jerk_room, coupling))),
    )
    jerk = float(np.min(_safe_ratio(jerk_room - coupling * accel, q1)))
    return min(accel, MAX_PATH_ACCELERATION), min(jerk, MAX_PATH_JERK)


class _ZonePlanner:
    """Plateaus and speed changes over the zones, with per-zone safety scales."""

    def __init__(
        self,
        robot: Robot,
        zones: list[tuple[float, float, str]],
        demands: list[_ZoneDemand],
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

    def change(self, z: int, v_from: float, v_to: float) -> tuple[float, float, float]:
        """Distance, acceleration and jerk bounds of a speed change inside zone z.

        A rise starts at the zone's start, a fall ends at its end. The bounds come from the
        joint demand over the stretch the change covers: first over the whole zone, then
        over the shorter stretch that needs, which stays valid because it lies inside.
        """
        s0, s1, _ = self.zones[z]
        top = max(v_from, v_to)
        share = LIMIT_SHARE * self.change_scale[z]
        demand = self.demands[z]
        accel, jerk = _change_bounds(self.robot, demand.peaks(), top, share)
        if accel <= 0.0 or jerk <= 0.0:
            return np.inf, accel, jerk
        distance = speed_change_distance(v_from, v_to, accel, jerk)
        if distance < s1 - s0:
            stretch = (s0, s0 + distance) if v_to > v_from else (s1 - distance, s1)
            local = _change_bounds(self.robot, demand.peaks(*stretch), top, share)
            accel, jerk = max(accel, local[0]), max(jerk, local[1])
            distance = speed_change_distance(v_from, v_to, accel, jerk)
        return distance, accel, jerk

    def plan(self) -> list[ZonePlan]:
        """Caps per zone, then plateaus lowered until every zone fits its speed changes."""
        zones = self.zones
        n = len(zones)
        caps = np.zeros(n)
        reasons = [""] * n
        for z, (_, _, kind) in enumerate(zones):
            if kind == "stop":
                caps[z], reasons[z] = 0.0, "stop"
                continue
            task_cap = self.rated_speed if kind == "straight" else self.corner_speed
            share = LIMIT_SHARE * self.cap_scale[z]
            joint_cap, joint_reason = _cruise_cap(self.robot, self.demands[z].peaks(), share)
            if joint_cap < task_cap:
                caps[z], reasons[z] = joint_cap, joint_reason
            else:
                caps[z] = task_cap
                reasons[z] = "rated speed" if kind == "straight" else "corner speed"
        lengths = np.array([s1 - s0 for s0, s1, _ in zones])
        plateau = caps.copy()

        def needed(z: int, v: float) -> float:
            before = plateau[z - 1] if z > 0 else 0.0
            after = plateau[z + 1] if z < n - 1 else 0.0
            total = self.change(z, before, v)[0] if before < v else 0.0
            return total + (self.change(z, v, after)[0] if after < v else 0.0)

        for _ in range(10 * n + 10):  # look-ahead passes until every zone fits
            changed = False
            for z in range(n):
                if plateau[z] == 0.0 or needed(z, plateau[z]) <= lengths[z]:
                    continue
                low, high = 0.0, plateau[z]
                for _ in range(50):
                    mid = 0.5 * (low + high)
                    low, high = (mid, high) if needed(z, mid) <= lengths[z] else (low, mid)
                plateau[z] = low
                if "too short" not in reasons[z]:
                    reasons[z] = _too_short(reasons[z])
                changed = True
            if not changed:
                break
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
                distance, accel, jerk = self.change(z, before, v)
                change_in = speed_change_phases(before, v, accel, jerk)
                cruise -= distance
            if after < v:
                distance, accel, jerk = self.change(z, v, after)
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
            low = mid
        else:
            high = mid
    return high


def _worst_rate_violations(
    robot: Robot, q: np.ndarray, sample_time: float
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Samples where a velocity, acceleration or jerk limit is exceeded.

    Returns
    -------
    tuple of numpy.ndarray
        ``(sample, order, ratio)``, each shape (V,): the sample index (past-the-end samples
        clipped to the last), the derivative order (1 velocity, 2 acceleration, 3 jerk) and
        the worst joint's value over its limit (> 1).
    """
    qd, qdd, qddd = backward_derivatives(q, sample_time, pad_end=True)
    samples, orders, ratios = [], [], []
    for order, values, bound in (
        (1, qd, robot.v_max),
        (2, qdd, robot.a_max),
        (3, qddd, robot.j_max),
    ):
        ratio = (np.abs(values) / bound).max(axis=1)
        bad = np.flatnonzero(ratio > 1.0)
        samples.append(np.minimum(bad, len(q) - 1))
        orders.append(np.full(bad.size, order))
        ratios.append(ratio[bad])
    return np.concatenate(samples), np.concatenate(orders), np.concatenate(ratios)


SPEC = TimeLawSpec(Timing.SMOOTH, "g2", plan_smooth_time_law)
"""The smooth law, as :data:`trackplan.timing.TIME_LAWS` lists it."""
