"""The smooth law's zones: slow-down windows, plateaus and jerk-limited speed changes.

:func:`zone_demands` cuts the joint path's grid into the zones of the planned path;
:func:`slow_down_windows` splits a zone where the joint limits lower its speed cap on part
of it (levels ``cap · r^k``); :class:`ZonePlanner` holds one plateau per window, sizes the
speed changes between them from the joint demand they cover
(:func:`~trackplan.timing.demand.speed_change`), turns them into a
:class:`~trackplan.timing.profile.SpeedProfile` and lowers a window's plateau or change
bounds where the sampled joints fail a check. The law that drives it is
:mod:`trackplan.timing.smooth`.
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass

import numpy as np

from trackplan.jointpath import JointPath
from trackplan.robots.machine import Machine
from trackplan.robots.model import Robot
from trackplan.timing import _kernels, _kernels_samples
from trackplan.timing.demand import SpeedChange, ZoneDemand, cruise_cap, speed_change
from trackplan.timing.profile import (
    SpeedProfile,
    speed_change_distance,
    speed_change_phases,
    speed_change_time,
)
from trackplan.timing.sample_checks import LIMIT_MARGIN

PLATEAU_GRID = 24
PLATEAU_ROUNDS = 2
"""A plateau lowered to fit its zone's speed changes is searched on a grid of PLATEAU_GRID
speeds, PLATEAU_ROUNDS times finer each round (precision 1/24² ≈ 2e-3 of the cap)."""


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


def zone_demands(joint_path: JointPath) -> list[ZoneDemand]:
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


def slow_down_windows(
    robot: Robot | Machine,
    zones: list[tuple[float, float, str]],
    demands: list[ZoneDemand],
    rated_speed: float,
    corner_speed: float,
    share: float,
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
        local = demand.local_caps(robot, share) if usable else None
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
        for first, last in level_runs(demand.s, level, shortest):
            a = s0 if first == 0 else 0.5 * (demand.s[first - 1] + demand.s[first])
            b = s1 if last == len(demand.s) - 1 else 0.5 * (demand.s[last] + demand.s[last + 1])
            out_zones.append((float(a), float(b), kind))
            out_demands.append(demand.part(max(first - 1, 0), min(last + 2, len(demand.s))))
    return out_zones, out_demands


def level_runs(s: np.ndarray, level: np.ndarray, shortest: float) -> list[tuple[int, int]]:
    """Runs (first, last grid index) of equal level, runs under ``shortest`` (m) merged
    into slower ones (compiled: :func:`trackplan.timing._kernels_samples.level_runs`)."""
    starts, ends = _kernels_samples.level_runs(s, level.astype(np.int64), shortest)
    return list(zip(starts.tolist(), ends.tolist(), strict=True))


class ZonePlanner:
    """Plateaus and speed changes over the zones, with per-zone safety scales."""

    def __init__(
        self,
        robot: Robot | Machine,
        zones: list[tuple[float, float, str]],
        demands: list[ZoneDemand],
        rated_speed: float,
        corner_speed: float,
        limit_share: float,
    ) -> None:
        self.robot = robot
        self.zones = zones
        self.demands = demands
        self.rated_speed = rated_speed
        self.corner_speed = corner_speed
        self.limit_share = limit_share
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
            share = self.limit_share * self.change_scale[z]
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
            share = self.limit_share * self.cap_scale[z]
            joint_cap, joint_reason = cruise_cap(self.robot, self.demands[z].peaks(), share)
            if joint_cap < task_cap:
                caps[z], reasons[z] = joint_cap, joint_reason
            else:
                caps[z] = task_cap
                reasons[z] = "rated speed" if kind == "straight" else "corner speed"
        lengths = np.array([s1 - s0 for s0, s1, _ in zones])
        offsets, s, peaks, from_start, from_end = self._packed()
        share = (self.limit_share * self.change_scale)[:, None]
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
