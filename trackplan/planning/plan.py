"""Plan one placement end to end: geometry, joint path, time law, trajectory, check."""

from __future__ import annotations

import itertools
from dataclasses import dataclass
from typing import Literal

import numpy as np

from trackplan.case import Case
from trackplan.paths import NominalPath, Path, build_path
from trackplan.planning.checker import TrackingReference, check_trajectory
from trackplan.planning.derivatives import backward_derivatives
from trackplan.planning.objective import joint_travel
from trackplan.planning.placement import placement_transform, rpy_matrix
from trackplan.planning.poses import tool_poses
from trackplan.planning.result import (
    CheckReport,
    PlanResult,
    PlanStatus,
    SlowDown,
    Trajectory,
)
from trackplan.robots.kinematics import forward_kinematics
from trackplan.robots.path_ik import PathIKStatus, solve_path_ik
from trackplan.timing.smooth import TimeLaw, plan_smooth_time_law

GEOMETRIC_STEP = 2e-3
"""Arc-length step of the geometric reachability check, m."""

_STATUS = {
    PathIKStatus.UNREACHABLE: PlanStatus.UNREACHABLE,
    PathIKStatus.BRANCH_SWITCH: PlanStatus.BRANCH_SWITCH,
    PathIKStatus.POSITION_LIMITS: PlanStatus.POSITION_LIMITS,
}


@dataclass(frozen=True, eq=False)
class PathGeometry:
    """The case's path, built once and shared by every placement.

    Attributes
    ----------
    nominal
        The path as the user gave it.
    planned
        The path the tool follows (blended corners).
    """

    nominal: NominalPath
    planned: Path

    @classmethod
    def from_case(cls, case: Case, timing: str | None = None) -> PathGeometry:
        """Build the nominal and planned paths of a case (``paper`` timing: tangent arcs)."""
        nominal = NominalPath.from_specs(case.start, case.segments)
        mode: Literal["g2", "paper"] = "paper" if (timing or case.task.timing) == "paper" else "g2"
        return cls(nominal, build_path(nominal, case.task.tolerance, mode=mode))

    def zones(self) -> list[tuple[float, float, str]]:
        """Zones of the planned path with stops inserted as zero-length zones."""
        zones: list[tuple[float, float, str]] = []
        stops = sorted(float(s) for s in self.planned.stops)
        for s0, s1, kind in self.planned.zones:
            start = float(s0)
            for stop in (s for s in stops if s0 - 1e-12 <= s <= s1 + 1e-12):
                if stop > start + 1e-12:
                    zones.append((start, stop, kind))
                if not zones or zones[-1][2] != "stop":
                    zones.append((stop, stop, "stop"))
                start = stop
            if s1 > start + 1e-12:
                zones.append((start, float(s1), kind))
        return zones

    def on_curved_zone(self, s: np.ndarray) -> np.ndarray:
        """Whether arc lengths ``s`` (M,) lie on an arc or blend (corner speed), shape (M,)."""
        curved = np.zeros(np.shape(s), dtype=bool)
        for s0, s1, kind in self.planned.zones:
            if kind == "curved":
                curved |= (s >= s0) & (s <= s1)
        return curved

    def corner_intervals(self) -> np.ndarray:
        """Nominal arc-length intervals where the corner speed applies, shape (K, 2)."""
        curved = [(s0, s1) for s0, s1, kind in self.planned.zones if kind == "curved"]
        if not curved:
            return np.zeros((0, 2))
        ends = self.planned.sample(np.asarray(curved).ravel()).position
        s_nominal, _ = self.nominal.project(ends)
        return np.sort(s_nominal.reshape(-1, 2), axis=1)

    def grid(self, step: float = GEOMETRIC_STEP) -> np.ndarray:
        """Arc lengths covering the planned path with every zone boundary, shape (M,)."""
        edges = np.array([z[0] for z in self.planned.zones] + [self.planned.length])
        parts = [
            np.linspace(a, b, max(2, int(np.ceil((b - a) / step)) + 1), endpoint=False)
            for a, b in itertools.pairwise(edges)
            if b > a
        ]
        return np.concatenate([*parts, [self.planned.length]])


def tracking_reference(case: Case, geometry: PathGeometry, X: np.ndarray) -> TrackingReference:
    """What the checker holds a trajectory of this case at placement X to."""
    return TrackingReference(
        nominal=geometry.nominal,
        T_base_part=placement_transform(np.asarray(X, dtype=float)),
        R_part_tool=rpy_matrix(case.task.tool_rpy),
        tolerance=case.task.tolerance,
        rated_speed=case.task.rated_speed,
        corner_speed=case.task.corner_speed,
        corner_intervals=geometry.corner_intervals(),
    )


def make_trajectory(robot, q: np.ndarray, s: np.ndarray, sample_time: float) -> Trajectory:
    """Sampled trajectory with derivatives exactly as the checker computes them.

    Parameters
    ----------
    robot
        The robot (for the tool point by FK).
    q
        Joint positions, shape (N, n), rad.
    s
        Arc length on the planned path per sample, shape (N,), m.
    sample_time
        Ts, s.
    """
    qd, qdd, qddd = backward_derivatives(q, sample_time)
    position = forward_kinematics(robot, q)[:, :3, 3]
    speed = np.linalg.norm(np.diff(position, axis=0, prepend=position[:1]), axis=1) / sample_time
    t = np.arange(len(q)) * sample_time
    return Trajectory(sample_time, t, s, q, qd, qdd, qddd, position, speed)


def empty_trajectory(n_dof: int, sample_time: float) -> Trajectory:
    """A trajectory with no samples (nothing could be planned)."""
    zeros = np.zeros((0, n_dof))
    return Trajectory(
        sample_time,
        np.zeros(0),
        np.zeros(0),
        zeros,
        zeros,
        zeros,
        zeros,
        np.zeros((0, 3)),
        np.zeros(0),
    )


def plan_placement(
    case: Case,
    X: np.ndarray,
    *,
    timing: str | None = None,
    branch: int | None = None,
    geometry: PathGeometry | None = None,
) -> PlanResult:
    """Plan the case with the workpiece at placement X and check the result.

    Parameters
    ----------
    case
        The case.
    X
        Placement (x, y, z, roll, pitch, yaw), shape (6,), metres and radians.
    timing
        ``smooth`` or ``paper``; default: the case's ``task.timing``.
    branch
        Force an IK branch; default: the one with the largest joint-limit margin.
    geometry
        The case's paths when already built (the optimizer shares them).

    Returns
    -------
    PlanResult
        Feasible or not, with the trajectory (empty when the path is unreachable) and the
        checker's report.
    """
    timing = timing or case.task.timing
    X = np.asarray(X, dtype=float)
    geometry = geometry or PathGeometry.from_case(case, timing)
    if timing == "paper":
        from trackplan.timing.paper import plan_paper_trajectory

        q, s, branch_used, status, message = plan_paper_trajectory(case, geometry, X, branch)
        return _finish(case, geometry, X, timing, branch_used, q, s, None, status, message)

    robot = case.robot
    s_grid = geometry.grid()
    poses = tool_poses(X, geometry.planned.sample(s_grid).position, case.task.tool_rpy)
    path_ik = solve_path_ik(robot, poses[None], branch=branch)
    chosen = int(path_ik.branch[0])
    if not path_ik.ok[0]:
        status = _STATUS[path_ik.status[0]]
        return _finish(
            case, geometry, X, timing, chosen, None, None, None, status, path_ik.message[0]
        )
    q_reference = path_ik.q[0, 0]

    def joint_path(s: np.ndarray) -> np.ndarray:
        poses_s = tool_poses(X, geometry.planned.sample(s).position, case.task.tool_rpy)
        q = solve_path_ik(robot, poses_s[None], branch=chosen).q[0]
        shift = 2 * np.pi * np.round((q[0] - q_reference) / (2 * np.pi))
        return q - shift

    law = plan_smooth_time_law(
        robot,
        geometry.zones(),
        joint_path,
        case.task.rated_speed,
        case.task.corner_speed,
        case.task.sample_time,
    )
    if not law.s.size:
        return _finish(
            case,
            geometry,
            X,
            timing,
            chosen,
            None,
            None,
            law,
            PlanStatus.LIMITS_VIOLATED,
            law.message,
        )
    return _finish(case, geometry, X, timing, chosen, law.q, law.s, law, None, "")


def _finish(
    case: Case,
    geometry: PathGeometry,
    X: np.ndarray,
    timing: str,
    branch: int,
    q: np.ndarray | None,
    s: np.ndarray | None,
    law: TimeLaw | None,
    status: PlanStatus | None,
    message: str,
) -> PlanResult:
    """Check the sampled trajectory and assemble the result."""
    robot = case.robot
    Ts = case.task.sample_time
    if q is None or s is None or len(q) == 0:  # nothing planned (paper mode returns empty arrays)
        check = CheckReport(False, {}, {}, (), float("nan"), float("nan"))
        trajectory = empty_trajectory(robot.n_dof, Ts)
        return PlanResult(
            case.name,
            X,
            False,
            status or PlanStatus.UNREACHABLE,
            message,
            timing,
            branch,
            trajectory,
            check,
            float("nan"),
            float("nan"),
            geometry.nominal.length,
            0.0,
            0.0,
            (),
            {},
            geometry.planned,
            geometry.nominal,
        )
    trajectory = make_trajectory(robot, q, s, Ts)
    check = check_trajectory(robot, q, Ts, tracking_reference(case, geometry, X))
    if status is None:
        status = PlanStatus.FEASIBLE if check.ok else PlanStatus.LIMITS_VIOLATED
    if not message:
        message = check.violations[0].message if check.violations else "feasible: every limit met"
    speed_fraction, corner_speed, slowdowns = _speed_summary(case, geometry, trajectory, law)
    return PlanResult(
        case_name=case.name,
        placement=X,
        feasible=bool(check.ok and status is PlanStatus.FEASIBLE),
        status=status,
        message=message,
        timing=timing,
        branch=branch,
        trajectory=trajectory,
        check=check,
        objective=float(joint_travel(q, case.objective.weights)),
        duration=trajectory.duration,
        path_length=geometry.nominal.length,
        rated_speed_fraction=speed_fraction,
        min_corner_speed=corner_speed,
        slowdowns=slowdowns,
        references={},
        planned_path=geometry.planned,
        nominal_path=geometry.nominal,
    )


def _speed_summary(
    case: Case, geometry: PathGeometry, trajectory: Trajectory, law: TimeLaw | None
) -> tuple[float, float, tuple[SlowDown, ...]]:
    """Share of the path run at the rated speed, the lowest corner speed, the slow-downs.

    The rated share is measured on the samples (path speed ``Δs / Ts``), so it holds for
    either timing mode; the corner speed is the lowest plateau on arcs and blends (measured on
    the samples for the paper mode).
    """
    rated = case.task.rated_speed
    ds = np.diff(trajectory.s)
    path_speed = ds / trajectory.sample_time
    at_rated = np.abs(path_speed - rated) <= 1e-4 * rated  # paper mode: projection noise
    fraction = float(ds[at_rated].sum() / geometry.planned.length)
    curved = geometry.on_curved_zone(0.5 * (trajectory.s[1:] + trajectory.s[:-1]))
    corner = float(path_speed[curved].min()) if curved.any() else rated
    slowdowns: tuple[SlowDown, ...] = ()
    if law is not None:
        plateaus = [z.plateau for z in law.zones if z.kind == "curved"]
        corner = min(plateaus) if plateaus else rated
        slowdowns = tuple(
            SlowDown(z.s_start, z.s_end, z.plateau, rated, z.reason)
            for z in law.zones
            if z.kind == "straight" and z.plateau < rated * (1 - 1e-9)
        )
    return fraction, corner, slowdowns
