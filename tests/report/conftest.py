"""Synthetic plan results for the report tests.

The planner is not needed to test the report: this module plans the paper's corner case
(Case 3: (0, 0, 0) → (0.5, 0, 0) → (0.3, 0, 0.5), placement X of the paper) with a small
pipeline of its own: a quintic-Bézier corner blend that stays within ρ, a speed law made
of quintic smoothstep ramps and plateaus, and Newton IK sample by sample; derivatives and
joint limits come from the project's backward differences and checker. One jerk violation
is planted on joint 6 (it turns the tool about its own axis, so the tool point and the
tracking error are unaffected).
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

import numpy as np
import pytest

from trackplan.case import Case, Objective, OptimizerSettings, PlacementBounds, Task
from trackplan.paths.specs import LineSpec
from trackplan.planning.checker import check_trajectory
from trackplan.planning.derivatives import backward_derivatives
from trackplan.planning.placement import placement_transform, pose_matrix, rpy_matrix
from trackplan.planning.result import (
    LIMIT_KINDS,
    CheckReport,
    PlanResult,
    PlanStatus,
    SlowDown,
    Trajectory,
)
from trackplan.robots.builtin import puma560
from trackplan.robots.kinematics import forward_kinematics, jacobian
from trackplan.robots.model import Robot

SAMPLE_TIME = 0.005  # s
TOLERANCE = 0.001  # ρ, m
RATED_SPEED = 0.15  # v_r, m/s
CORNER_SPEED_CAP = 0.05  # v_t^max, m/s
CORNER_SPEED = 0.01  # plateau actually held on the blend, m/s
SLOW_SPEED = 0.10  # plateau of the planted slow-down on the second line, m/s
RAMP_TIME = 0.6  # duration of every speed ramp, s
PAPER_PLACEMENT = np.array([0.0902, 0.2090, 0.2020, 0.3263, 0.3016, -0.2522])
PAPER_WEIGHTS = np.array([0.3, 0.2, 0.2, 0.1, 0.1, 0.1])
TOOL_RPY = np.array([-np.pi / 2, 0.0, 0.0])
CORNER = np.array([[0.0, 0.0, 0.0], [0.5, 0.0, 0.0], [0.3, 0.0, 0.5]])  # m
IK_START = np.array([1.8828, -0.3934, 0.9948, -0.6383, -1.7434, -1.6155])  # rad, near sample 0
PLANTED_JOINT = 6
PLANTED_TIME = 2.0  # s
PLANTED_JERK = 31.2  # rad/s³, against the limit of 20


def _smoothstep(u: np.ndarray) -> np.ndarray:
    """Quintic smoothstep S(u) on [0, 1]: zero slope and curvature at both ends."""
    return u**3 * (10.0 - 15.0 * u + 6.0 * u**2)


def _smoothstep_integral(u: np.ndarray) -> np.ndarray:
    """∫₀ᵘ S, with ∫₀¹ S = 1/2."""
    return u**4 * (2.5 - 3.0 * u + u**2)


@dataclass
class _SpeedLaw:
    """A speed law s(t) built from ramps (quintic smoothstep, RAMP_TIME long) and plateaus."""

    phases: list[tuple[float, float, float, float, float]]  # t0, duration, s0, v0, v1
    t: float = 0.0
    s: float = 0.0
    v: float = 0.0

    def ramp(self, v1: float) -> None:
        self.phases.append((self.t, RAMP_TIME, self.s, self.v, v1))
        self.s += 0.5 * (self.v + v1) * RAMP_TIME
        self.t += RAMP_TIME
        self.v = v1

    def hold_until(self, s_end: float) -> None:
        if s_end < self.s - 1e-12:
            raise ValueError(f"plateau would end at {s_end} before it starts at {self.s}")
        duration = (s_end - self.s) / self.v
        self.phases.append((self.t, duration, self.s, self.v, self.v))
        self.t += duration
        self.s = s_end

    def ramp_distance(self, v1: float) -> float:
        return 0.5 * (self.v + v1) * RAMP_TIME

    def sample(self, t: np.ndarray) -> np.ndarray:
        s = np.full_like(t, self.s)
        for t0, duration, s0, v0, v1 in self.phases:
            inside = (t >= t0) & (t < t0 + duration)
            u = (t[inside] - t0) / duration
            if v0 == v1:
                s[inside] = s0 + v0 * (t[inside] - t0)
            else:
                s[inside] = s0 + duration * (v0 * u + (v1 - v0) * _smoothstep_integral(u))
        return s


def _bezier_blend(corner: np.ndarray, tolerance: float) -> tuple[np.ndarray, float]:
    """Quintic Bézier blend of the middle corner: G2 with both lines, within 0.9 ρ.

    Returns the dense blend points (K, 3) and the distance d cut from each leg, m.
    """
    u_in = (corner[1] - corner[0]) / np.linalg.norm(corner[1] - corner[0])
    u_out = (corner[2] - corner[1]) / np.linalg.norm(corner[2] - corner[1])
    # control points at -d, -2d/3, -d/3 on the incoming leg and mirrored on the outgoing
    # one: three collinear points at each end make the end curvature zero.
    steps = np.array([-1.0, -2.0 / 3.0, -1.0 / 3.0, 1.0 / 3.0, 2.0 / 3.0, 1.0])
    u = np.linspace(0.0, 1.0, 4001)[:, None]
    weights = np.hstack([math.comb(5, k) * u**k * (1 - u) ** (5 - k) for k in range(6)])

    def blend(d: float) -> np.ndarray:
        control = np.array([corner[1] + d * h * (u_in if h < 0 else u_out) for h in steps])
        return weights @ control

    d_unit = 0.01  # the deviation is proportional to d
    d = d_unit * 0.9 * tolerance / np.max(distance_to_legs(blend(d_unit), corner))
    return blend(d), d


def distance_to_legs(points: np.ndarray, corner: np.ndarray) -> np.ndarray:
    """Distance of points (M, 3) from the polyline ``corner`` (K, 3), m."""
    a, b = corner[:-1], corner[1:]
    ab = b - a
    u = np.einsum("mkj,kj->mk", points[:, None, :] - a, ab) / np.einsum("kj,kj->k", ab, ab)
    foot = a + np.clip(u, 0.0, 1.0)[..., None] * ab
    return np.min(np.linalg.norm(points[:, None, :] - foot, axis=-1), axis=1)


def _polyline_at(points: np.ndarray, s: np.ndarray) -> np.ndarray:
    """Points at arc lengths s (M,) along a dense polyline (K, 3)."""
    arc = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(points, axis=0), axis=1))])
    return np.stack([np.interp(s, arc, points[:, i]) for i in range(3)], axis=1)


def _pose_error(T: np.ndarray, T_goal: np.ndarray) -> np.ndarray:
    """(Δp, Δω) from T to T_goal in the base frame, shape (6,)."""
    dw = 0.5 * sum(np.cross(T[:3, i], T_goal[:3, i]) for i in range(3))
    return np.concatenate([T_goal[:3, 3] - T[:3, 3], dw])


def _solve_ik(robot: Robot, T_base_tool: np.ndarray, q_start: np.ndarray) -> np.ndarray:
    """Newton IK along the poses (M, 4, 4), each sample seeded by the previous one."""
    q = np.empty((len(T_base_tool), robot.n_dof))
    q_k = q_start
    for k, T_goal in enumerate(T_base_tool):
        for _ in range(30):
            error = _pose_error(forward_kinematics(robot, q_k), T_goal)
            if np.linalg.norm(error) < 1e-13:
                break
            q_k = q_k + np.linalg.solve(jacobian(robot, q_k), error)
        else:
            raise RuntimeError(f"fixture IK did not converge at sample {k}")
        q[k] = q_k
    return q


def corner_case(robot: Robot) -> Case:
    """The paper's corner case (Section 4, Case 3) as a Case."""
    reach = (math.sqrt(0.0226), math.sqrt(0.7289))
    lower = np.array([-0.87, -0.87, -0.87, -1.57, -1.57, -1.57])
    return Case(
        name="paper-corner",
        robot=robot,
        start=CORNER[0],
        segments=(LineSpec(to=CORNER[1]), LineSpec(to=CORNER[2])),
        task=Task(
            rated_speed=RATED_SPEED,
            corner_speed=CORNER_SPEED_CAP,
            tolerance=TOLERANCE,
            sample_time=SAMPLE_TIME,
            tool_rpy=TOOL_RPY,
        ),
        bounds=PlacementBounds(lower=lower, upper=-lower, reach=reach, example=PAPER_PLACEMENT),
        objective=Objective(weights=PAPER_WEIGHTS),
        optimizer=OptimizerSettings(method="ga", population=30, seed=1),
    )


def plan_corner(case: Case) -> PlanResult:
    """Plan ``case`` (the corner case) at the paper's placement with the fixture pipeline."""
    robot = case.robot
    blend, d = _bezier_blend(CORNER, TOLERANCE)
    leg_1 = np.linalg.norm(CORNER[1] - CORNER[0])
    leg_2 = np.linalg.norm(CORNER[2] - CORNER[1])
    planned = np.vstack([CORNER[:1], blend, CORNER[2:]])
    blend_length = float(np.sum(np.linalg.norm(np.diff(blend, axis=0), axis=1)))
    s_blend_start = leg_1 - d
    s_blend_end = s_blend_start + blend_length
    length = s_blend_end + leg_2 - d
    slow_start, slow_end = s_blend_end + 0.15, s_blend_end + 0.25

    law = _SpeedLaw(phases=[])
    law.ramp(RATED_SPEED)
    law.hold_until(s_blend_start - law.ramp_distance(CORNER_SPEED))
    law.ramp(CORNER_SPEED)
    law.hold_until(s_blend_end)
    law.ramp(RATED_SPEED)
    law.hold_until(slow_start - law.ramp_distance(SLOW_SPEED))
    law.ramp(SLOW_SPEED)
    law.hold_until(slow_end)
    law.ramp(RATED_SPEED)
    law.hold_until(length - law.ramp_distance(0.0))
    law.ramp(0.0)

    t = np.arange(math.ceil(law.t / SAMPLE_TIME) + 1) * SAMPLE_TIME
    s = law.sample(t)
    T_base_part = placement_transform(PAPER_PLACEMENT)
    T_base_tool = T_base_part @ pose_matrix(_polyline_at(planned, s), rpy_matrix(TOOL_RPY))
    q = _solve_ik(robot, T_base_tool, IK_START)
    bump = np.exp(-0.5 * ((t - PLANTED_TIME) / 0.02) ** 2)
    bump_jerk = backward_derivatives(bump, SAMPLE_TIME)[2]
    base_jerk = backward_derivatives(q, SAMPLE_TIME)[2][:, PLANTED_JOINT - 1]
    k_peak = np.argmax(np.abs(bump_jerk))
    q[:, PLANTED_JOINT - 1] += bump * (PLANTED_JERK - base_jerk[k_peak]) / bump_jerk[k_peak]

    qd, qdd, qddd = backward_derivatives(q, SAMPLE_TIME)
    tool_position = forward_kinematics(robot, q)[:, :3, 3]
    speed = np.linalg.norm(backward_derivatives(tool_position, SAMPLE_TIME)[0], axis=1)
    trajectory = Trajectory(SAMPLE_TIME, t, s, q, qd, qdd, qddd, tool_position, speed)

    T_part_base = np.linalg.inv(T_base_part)
    points_part = tool_position @ T_part_base[:3, :3].T + T_part_base[:3, 3]
    tracking_error = float(np.max(distance_to_legs(points_part, CORNER)))
    check = dataclasses.replace(
        check_trajectory(robot, q, SAMPLE_TIME),  # the joint limits; the task is known here
        task_margins={
            "tracking": 1.0 - tracking_error / TOLERANCE,
            "speed": round(1.0 - float(speed.max()) / RATED_SPEED, 9),  # the plateaus hold v_r
            "orientation": 0.95,
            "coverage": 1.0,
        },
        max_tracking_error=tracking_error,
        max_orientation_error=1e-4,
    )
    violations = check.violations
    straight = leg_1 + leg_2 - 2 * d
    below_rated = (
        (slow_end - slow_start) + 2 * law.ramp_distance(SLOW_SPEED) + 2 * RATED_SPEED * RAMP_TIME
    )
    duration = float(t[-1])
    return PlanResult(
        case_name=case.name,
        placement=PAPER_PLACEMENT,
        feasible=check.ok,
        status=PlanStatus.FEASIBLE if check.ok else PlanStatus.LIMITS_VIOLATED,
        message=violations[0].message if violations else "feasible",
        timing="smooth",
        branch=0,
        trajectory=trajectory,
        check=check,
        objective=float(np.sum(PAPER_WEIGHTS * np.abs(np.diff(q, axis=0)))),
        duration=duration,
        path_length=float(leg_1 + leg_2),
        rated_speed_fraction=1.0 - below_rated / straight,
        min_corner_speed=CORNER_SPEED,
        slowdowns=(SlowDown(slow_start, slow_end, SLOW_SPEED, RATED_SPEED, "joint 4 velocity"),),
        references={"toppra_duration": 0.97 * duration, "topp3_duration": 0.985 * duration},
        planned_path=None,
        nominal_path=None,
    )


def empty_result(case: Case) -> PlanResult:
    """An unreachable placement: no trajectory at all."""
    n = case.robot.n_dof
    empty = np.zeros((0, n))
    trajectory = Trajectory(
        SAMPLE_TIME,
        np.zeros(0),
        np.zeros(0),
        empty,
        empty,
        empty,
        empty,
        np.zeros((0, 3)),
        np.zeros(0),
    )
    check = CheckReport(
        ok=False,
        joint_margins={kind: np.full(n, np.nan) for kind in LIMIT_KINDS},
        task_margins={"coverage": -1.0},
        violations=(),
        max_tracking_error=float("nan"),
        max_orientation_error=float("nan"),
    )
    return PlanResult(
        case_name=case.name,
        placement=np.array([0.8, 0.0, 0.4, 0.0, 0.0, 0.0]),
        feasible=False,
        status=PlanStatus.UNREACHABLE,
        message="path pose 12 at s = 0.061 m is out of reach",
        timing="smooth",
        branch=-1,
        trajectory=trajectory,
        check=check,
        objective=float("inf"),
        duration=float("nan"),
        path_length=1.0385,
        rated_speed_fraction=0.0,
        min_corner_speed=0.0,
        slowdowns=(),
        references={},
        planned_path=None,
        nominal_path=None,
    )


def optimizer_history(rng: np.random.Generator) -> dict[str, dict[str, np.ndarray]]:
    """A plausible optimize history for two methods."""
    history = {}
    for method, population, n_gen in (("ga", 30, 25), ("cmaes", 12, 40)):
        generation = np.arange(1, n_gen + 1)
        best = 0.9 + 4.0 * np.exp(-generation / 6.0) + 0.02 * rng.random(n_gen)
        history[method] = {
            "generation": generation,
            "evaluations": generation * population,
            "best": np.minimum.accumulate(best),
            "mean": best * 3.0 + 1e3 * np.exp(-generation / 3.0),
            "feasible_share": np.clip(1.0 - np.exp(-generation / 8.0), 0.0, 1.0),
            "wall_time": generation * 0.05 * population,
        }
    return history


@pytest.fixture(scope="session")
def corner() -> Case:
    """The paper's corner case with the built-in PUMA560."""
    return corner_case(puma560())


@pytest.fixture(scope="session")
def corner_result(corner: Case) -> PlanResult:
    """The corner case planned at the paper's placement, one planted jerk violation."""
    return plan_corner(corner)


@pytest.fixture(scope="session")
def unreachable_result(corner: Case) -> PlanResult:
    """An unreachable placement of the corner case: empty trajectory."""
    return empty_result(corner)


@pytest.fixture
def history() -> dict[str, dict[str, np.ndarray]]:
    """Optimizer history of two methods (ga, cmaes)."""
    return optimizer_history(np.random.default_rng(7))


REPORT_FRAMES = 60  # animation frames of the 3D view in the report tests


@pytest.fixture(scope="session")
def report_file(tmp_path_factory, corner: Case, corner_result: PlanResult):
    """report.html of the corner result with an optimizer history (written once)."""
    from trackplan.report import write_report

    history = optimizer_history(np.random.default_rng(7))
    info = {"method": "ga", "evaluations": 750, "wall_time": 37.5, "best_X": PAPER_PLACEMENT}
    out_dir = tmp_path_factory.mktemp("report")
    return write_report(corner_result, corner, out_dir, history, info, n_frames=REPORT_FRAMES)
