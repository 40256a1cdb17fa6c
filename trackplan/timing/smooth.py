"""The smooth time law: steady process speed, jerk-limited speed changes, every joint limit.

Method (design.md, "Where the paper is weak", items 3 and 6):

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

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from trackplan.planning.derivatives import backward_derivatives
from trackplan.robots.model import Robot
from trackplan.timing.profile import SpeedProfile, speed_change_distance, speed_change_phases

JointPath = Callable[[np.ndarray], np.ndarray]
"""Maps path arc lengths s (M,) in increasing order to joint positions (M, n) on one branch."""

LIMIT_SHARE = 0.97
"""Share of each joint limit the planner aims at; the rest absorbs sampling effects."""
STRAIGHT_GRID_STEP = 2e-3
"""Grid step on straight zones for the joint-path derivatives, m."""
CURVED_GRID_POINTS = 80
"""Grid points on each curved zone (arcs are split so a step stays below STRAIGHT_GRID_STEP)."""
MAX_ITERATIONS = 12


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
class TimeLaw:
    """A sampled time law and its joint trajectory.

    Attributes
    ----------
    profile
        The continuous s(t) (before the final time stretch to a whole number of periods).
    time_scale
        Factor ≥ 1 by which the profile's time is stretched so the last sample lands on
        the end of the path exactly.
    zones
        Zones and their plateaus.
    sample_time
        Ts, s.
    s
        Arc length at each sample, shape (N,), m.
    q
        Joint positions at each sample, shape (N, n), rad.
    iterations
        Rebuilds needed until the sampled trajectory met every rate limit.
    converged
        False when MAX_ITERATIONS rebuilds still left a rate-limit violation.
    """

    profile: SpeedProfile
    time_scale: float
    zones: tuple[ZonePlan, ...]
    sample_time: float
    s: np.ndarray
    q: np.ndarray
    iterations: int
    converged: bool

    @property
    def duration(self) -> float:
        """Time of the last sample, s."""
        return (len(self.s) - 1) * self.sample_time


@dataclass(frozen=True, eq=False)
class _ZoneDemand:
    """Largest |dq/ds|, |d²q/ds²|, |d³q/ds³| over a zone, each shape (n,)."""

    q1: np.ndarray
    q2: np.ndarray
    q3: np.ndarray


def plan_smooth_time_law(
    robot: Robot,
    zones: list[tuple[float, float, str]],
    joint_path: JointPath,
    rated_speed: float,
    corner_speed: float,
    sample_time: float,
) -> TimeLaw:
    """Shortest jerk-limited time law of the smooth mode (see the module docstring).

    Parameters
    ----------
    robot
        Joint limits.
    zones
        ``(s_start, s_end, kind)`` covering the planned path in order; kind is
        ``straight``, ``curved`` or ``stop`` (zero length, speed zero).
    joint_path
        q(s) on the chosen IK branch.
    rated_speed, corner_speed
        Task speed caps, m/s.
    sample_time
        Ts, s.

    Returns
    -------
    TimeLaw
    """
    demands = _zone_demands(zones, joint_path)
    n_zones = len(zones)
    cap_scale = np.ones(n_zones)
    change_scale = np.ones(n_zones)
    length = zones[-1][1]
    for iteration in range(1, MAX_ITERATIONS + 1):
        plans = _plan_zones(
            robot, zones, demands, rated_speed, corner_speed, cap_scale, change_scale
        )
        profile = _build_profile(robot, plans, demands, change_scale, length)
        n_steps = max(1, int(np.ceil(profile.duration / sample_time - 1e-9)))
        time_scale = n_steps * sample_time / profile.duration
        t = np.arange(n_steps + 1) * sample_time
        s = profile.evaluate(t / time_scale)[0]
        s[-1] = length
        q = joint_path(s)
        worst = _worst_rate_violations(robot, q, sample_time)
        if not worst:
            return TimeLaw(profile, time_scale, tuple(plans), sample_time, s, q, iteration, True)
        _tighten(worst, s, t / time_scale, profile, plans, cap_scale, change_scale)
    return TimeLaw(profile, time_scale, tuple(plans), sample_time, s, q, MAX_ITERATIONS, False)


def _zone_demands(
    zones: list[tuple[float, float, str]], joint_path: JointPath
) -> list[_ZoneDemand]:
    """Differentiate q(s) on a uniform grid per zone (one batched IK call for all zones)."""
    grids = []
    for s0, s1, kind in zones:
        span = s1 - s0
        if kind == "straight":
            n = int(np.clip(np.ceil(span / STRAIGHT_GRID_STEP), 8, 2000)) + 1
        else:
            n = max(CURVED_GRID_POINTS, int(np.ceil(span / STRAIGHT_GRID_STEP))) + 1
        grids.append(np.linspace(s0, s1, n) if span > 0 else np.array([s0]))
    q_all = joint_path(np.concatenate(grids))
    demands = []
    start = 0
    for grid in grids:
        q = q_all[start : start + len(grid)]
        start += len(grid)
        if len(grid) < 4:
            zero = np.zeros(q.shape[1])
            demands.append(_ZoneDemand(zero, zero, zero))
            continue
        h = grid[1] - grid[0]
        q1 = np.gradient(q, h, axis=0, edge_order=2)
        q2 = np.gradient(q1, h, axis=0, edge_order=2)
        q3 = np.gradient(q2, h, axis=0, edge_order=2)
        demands.append(
            _ZoneDemand(np.abs(q1).max(axis=0), np.abs(q2).max(axis=0), np.abs(q3).max(axis=0))
        )
    return demands


def _safe_ratio(numerator: np.ndarray, denominator: np.ndarray) -> np.ndarray:
    """numerator / denominator with +inf where the denominator is zero."""
    out = np.full(np.broadcast(numerator, denominator).shape, np.inf)
    np.divide(numerator, denominator, out=out, where=denominator > 0)
    return out


def _cruise_cap(robot: Robot, demand: _ZoneDemand, share: float) -> tuple[float, str]:
    """Highest constant path speed the joint limits allow on a zone, and what binds."""
    candidates = [
        (_safe_ratio(share * robot.v_max, demand.q1), "velocity"),
        (np.sqrt(_safe_ratio(share * robot.a_max, demand.q2)), "acceleration"),
        (np.cbrt(_safe_ratio(share * robot.j_max, demand.q3)), "jerk"),
    ]
    best, reason = np.inf, ""
    for values, kind in candidates:
        j = int(np.argmin(values))
        if values[j] < best:
            best, reason = float(values[j]), f"joint {j + 1} {kind}"
    return best, reason


def _change_bounds(
    robot: Robot, demand: _ZoneDemand, top_speed: float, share: float
) -> tuple[float, float]:
    """Path acceleration and jerk bounds for a speed change up to ``top_speed`` on a zone."""
    accel_room = share * robot.a_max - demand.q2 * top_speed**2
    jerk_room = share * robot.j_max - demand.q3 * top_speed**3
    accel = float(np.min(_safe_ratio(accel_room, demand.q1)))
    # the 3 |q''| v s̈ term couples acceleration and jerk: keep half the jerk room at least
    coupling = 3.0 * demand.q2 * top_speed
    accel_for_half = float(np.min(_safe_ratio(0.5 * jerk_room, coupling)))
    accel = min(accel, accel_for_half)
    jerk = float(np.min(_safe_ratio(jerk_room - coupling * accel, demand.q1)))
    if not (np.isfinite(accel) and np.isfinite(jerk)):
        accel = min(accel, 1e3)
        jerk = min(jerk, 1e5)
    return accel, jerk


def _plan_zones(
    robot: Robot,
    zones: list[tuple[float, float, str]],
    demands: list[_ZoneDemand],
    rated_speed: float,
    corner_speed: float,
    cap_scale: np.ndarray,
    change_scale: np.ndarray,
) -> list[ZonePlan]:
    """Caps per zone, then plateaus lowered until every zone fits its speed changes."""
    n = len(zones)
    caps = np.zeros(n)
    reasons = [""] * n
    for z, ((_, _, kind), demand) in enumerate(zip(zones, demands, strict=True)):
        if kind == "stop":
            caps[z], reasons[z] = 0.0, "stop"
            continue
        task_cap = rated_speed if kind == "straight" else corner_speed
        joint_cap, joint_reason = _cruise_cap(robot, demand, LIMIT_SHARE * cap_scale[z])
        if joint_cap < task_cap:
            caps[z], reasons[z] = joint_cap, joint_reason
        else:
            caps[z] = task_cap
            reasons[z] = "rated speed" if kind == "straight" else "corner speed"
    lengths = np.array([s1 - s0 for s0, s1, _ in zones])
    plateau = caps.copy()

    def distance(z: int, v_from: float, v_to: float) -> float:
        accel, jerk = _change_bounds(
            robot, demands[z], max(v_from, v_to), LIMIT_SHARE * change_scale[z]
        )
        if accel <= 0.0 or jerk <= 0.0:
            return np.inf
        return speed_change_distance(v_from, v_to, accel, jerk)

    def needed(z: int, v: float) -> float:
        before = plateau[z - 1] if z > 0 else 0.0
        after = plateau[z + 1] if z < n - 1 else 0.0
        total = distance(z, before, v) if before < v else 0.0
        return total + (distance(z, v, after) if after < v else 0.0)

    for _ in range(10 * n + 10):  # look-ahead passes until every zone fits
        changed = False
        for z in range(n):
            if plateau[z] == 0.0 or needed(z, plateau[z]) <= lengths[z]:
                continue
            low, high = 0.0, plateau[z]
            for _ in range(60):
                mid = 0.5 * (low + high)
                low, high = (mid, high) if needed(z, mid) <= lengths[z] else (low, mid)
            plateau[z] = low
            reasons[z] = f"{reasons[z]}; speed changes need {_change_limit_name(robot, demands[z])}"
            changed = True
        if not changed:
            break
    return [
        ZonePlan(s0, s1, kind, float(caps[z]), float(plateau[z]), reasons[z])
        for z, (s0, s1, kind) in enumerate(zones)
    ]


def _change_limit_name(robot: Robot, demand: _ZoneDemand) -> str:
    """The joint whose acceleration and jerk limits bound speed changes on a zone."""
    j = int(np.argmax(_safe_ratio(demand.q1, robot.j_max)))
    return f"joint {j + 1} acceleration/jerk (zone too short to reach the cap)"


def _build_profile(
    robot: Robot,
    plans: list[ZonePlan],
    demands: list[_ZoneDemand],
    change_scale: np.ndarray,
    length: float,
) -> SpeedProfile:
    """Jerk phases zone by zone: change in, cruise, change out."""
    phases: list[tuple[float, float]] = []
    n = len(plans)
    for z, plan in enumerate(plans):
        v = plan.plateau
        if v == 0.0:
            continue
        before = plans[z - 1].plateau if z > 0 else 0.0
        after = plans[z + 1].plateau if z < n - 1 else 0.0
        accel, jerk = _change_bounds(robot, demands[z], v, LIMIT_SHARE * change_scale[z])
        cruise = plan.s_end - plan.s_start
        change_in: list[tuple[float, float]] = []
        change_out: list[tuple[float, float]] = []
        if before < v:
            change_in = speed_change_phases(before, v, accel, jerk)
            cruise -= speed_change_distance(before, v, accel, jerk)
        if after < v:
            change_out = speed_change_phases(v, after, accel, jerk)
            cruise -= speed_change_distance(v, after, accel, jerk)
        phases.extend(change_in)
        phases.append((max(cruise, 0.0) / v, 0.0))
        phases.extend(change_out)
    return SpeedProfile.from_phases(phases, length)


def _worst_rate_violations(
    robot: Robot, q: np.ndarray, sample_time: float
) -> list[tuple[int, str, float]]:
    """Samples where a velocity, acceleration or jerk limit is exceeded.

    Returns
    -------
    list of (sample index, kind, ratio to the limit)
        The worst sample of each violated (kind, joint); indices past the end are clipped.
    """
    qd, qdd, qddd = backward_derivatives(q, sample_time, pad_end=True)
    found = []
    for kind, values, bound in (
        ("velocity", qd, robot.v_max),
        ("acceleration", qdd, robot.a_max),
        ("jerk", qddd, robot.j_max),
    ):
        ratio = np.abs(values) / bound
        for j in np.flatnonzero(ratio.max(axis=0) > 1.0):
            bad = np.flatnonzero(ratio[:, j] > 1.0)
            for k in bad:
                found.append((min(int(k), len(q) - 1), kind, float(ratio[k, j])))
    return found


def _tighten(
    worst: list[tuple[int, str, float]],
    s: np.ndarray,
    t_profile: np.ndarray,
    profile: SpeedProfile,
    plans: list[ZonePlan],
    cap_scale: np.ndarray,
    change_scale: np.ndarray,
) -> None:
    """Lower the plateau or the speed-change bounds of every zone that broke a limit."""
    starts = np.array([p.s_start for p in plans])
    power = {"velocity": 1.0, "acceleration": 2.0, "jerk": 3.0}
    phase = profile.phase_index(t_profile)
    cruising = (profile.jerk[phase] == 0.0) & (np.abs(profile.a0[phase]) < 1e-12)
    new_cap = np.ones(len(plans))
    new_change = np.ones(len(plans))
    for k, kind, ratio in worst:
        z = int(np.clip(np.searchsorted(starts, s[k], side="right") - 1, 0, len(plans) - 1))
        window = slice(max(0, k - 3), k + 1)
        if np.all(cruising[window]):
            new_cap[z] = min(new_cap[z], 0.97 * ratio ** (-1.0 / power[kind]))
        else:
            new_change[z] = min(new_change[z], 0.9 / ratio)
            # a change near a zone edge may also be bounded by the neighbour's demand
            if z + 1 < len(plans):
                new_change[z + 1] = min(new_change[z + 1], 0.9 / ratio)
    cap_scale *= new_cap
    change_scale *= new_change
