"""Reference time laws on the same joint path: toppra (no jerk) and copp-py's TOPP3 (jerk).

Both take the geometric joint path q(s) that trackplan times, with s the arc length of the
planned path (so the path speed ṡ is the tool's Cartesian speed), the same joint limits and
rest-to-rest boundaries, and return a :class:`ReferenceResult`.

- :func:`toppra_reference`: TOPP-RA (toppra 0.6, ``seidel`` solver wrapper,
  ``ParametrizeConstAccel``) under joint velocity and acceleration limits and the Cartesian
  speed cap. toppra has no Cartesian-speed constraint of its own; the path is given one extra
  coordinate equal to s, whose velocity bound is the cap (``JointVelocityConstraintVarying``
  on the n + 1 coordinates; its acceleration bound is set out of reach). Its duration is a
  lower bound for any jerk-limited law on the same path; its sampled output steps the
  acceleration, so it breaks jerk limits.
- :func:`topp3_reference`: copp-py's third-order TOPP (``topp3_socp``) with joint velocity,
  acceleration and jerk limits and the cap as a raw first-order bound ``ṡ² ≤ v_cap(s)²``,
  linearised around copp's own TOPP2-RA profile and re-linearised around its own result
  until the duration settles: the jerk-limited time optimum trackplan's smooth law is
  measured against.

q(s) is a quintic interpolating spline through the given samples, so both solvers see the
same continuous path with three continuous derivatives (TOPP3 needs q''').
:func:`reference_durations` computes both for a planned placement.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from scipy.interpolate import BSpline, make_interp_spline

from trackplan.errors import CaseError
from trackplan.jointpath import JointPath
from trackplan.robots.machine import Machine
from trackplan.robots.model import Robot
from trackplan.task import Task

GridJoints = np.ndarray | Callable[[np.ndarray], np.ndarray]
"""Joint path on the grid: samples (M, n) at ``s_grid``, or a callable s (M,) -> q (M, n)."""

UNREACHABLE_ACCELERATION = 1.0e6
"""Acceleration bound of toppra's extra arc-length coordinate, m/s² (never binds)."""
TOPP3_MAX_ROUNDS = 6
"""Largest number of TOPP3 solves (first linearisation around TOPP2-RA, then re-linearised)."""
TOPP3_SETTLED = 1.0e-4
"""Relative duration change below which the TOPP3 re-linearisation stops."""
A_FLOOR = 1.0e-8
"""Smallest ṡ² (m²/s²) of the TOPP3 linearisation profile (the rest ends are 0)."""


@dataclass(frozen=True, eq=False)
class ReferenceResult:
    """A reference time law on the same joint path.

    Attributes
    ----------
    name
        ``toppra`` or ``topp3``.
    success
        True when the solver returned a parameterisation.
    message
        One line: what was solved, or why it failed.
    duration
        Time from rest to rest, s (nan on failure).
    compute_time_s
        Wall-clock time of the solver: constraint set-up, solve and the duration, excluding
        the joint-path spline and the sampling at Ts, s.
    sample_time
        Ts, s.
    s
        Path arc length at each sample, shape (N,), m (empty on failure).
    q
        Joint positions sampled at Ts, shape (N, n), rad (empty on failure); the last sample
        is the end of the path.
    """

    name: str
    success: bool
    message: str
    duration: float
    compute_time_s: float
    sample_time: float
    s: np.ndarray
    q: np.ndarray


def joint_spline(s_grid: np.ndarray, q_grid: GridJoints) -> tuple[np.ndarray, BSpline]:
    """Quintic interpolating spline of q(s) through the samples.

    Parameters
    ----------
    s_grid
        Strictly increasing arc lengths, shape (M,), m, M ≥ 6.
    q_grid
        Joint samples (M, n), rad, or a callable returning them.

    Returns
    -------
    s_grid : numpy.ndarray
        The grid as float64, shape (M,).
    spline : scipy.interpolate.BSpline
        q(s), rad; ``spline(s, k)`` is the k-th derivative in rad/m^k.
    """
    s_grid = np.asarray(s_grid, dtype=float)
    q = q_grid(s_grid) if callable(q_grid) else np.asarray(q_grid, dtype=float)
    return s_grid, make_interp_spline(s_grid, q, k=5)


def _failure(
    name: str, message: str, n_dof: int, sample_time: float, spent: float
) -> ReferenceResult:
    return ReferenceResult(
        name, False, message, float("nan"), spent, sample_time, np.zeros(0), np.zeros((0, n_dof))
    )


def _sample_times(duration: float, sample_time: float) -> np.ndarray:
    """0, Ts, 2 Ts, … and the end time (appended when not on the grid), s."""
    t = np.arange(0.0, duration, sample_time)
    if duration - t[-1] > 1e-9 * sample_time:
        t = np.append(t, duration)
    else:
        t[-1] = duration
    return t


def toppra_reference(
    robot: Robot | Machine,
    s_grid: np.ndarray,
    q_grid: GridJoints,
    speed_cap_grid: np.ndarray,
    sample_time: float,
) -> ReferenceResult:
    """Time-optimal parameterisation by toppra under velocity, acceleration and speed limits.

    Parameters
    ----------
    robot
        Joint velocity and acceleration limits (``v_max``, ``a_max``), shape (n,).
    s_grid
        Arc length of the planned path, shape (M,), m, strictly increasing; also toppra's
        grid.
    q_grid
        q on the grid (M, n), rad, or a callable s -> q.
    speed_cap_grid
        Cartesian speed cap at each grid point, shape (M,), m/s.
    sample_time
        Ts of the sampled output, s.

    Returns
    -------
    ReferenceResult
        ``q`` sampled at Ts from toppra's constant-acceleration parameterisation.
    """
    import toppra
    import toppra.algorithm as algo
    import toppra.constraint as constraint

    s_grid, spline = joint_spline(s_grid, q_grid)
    n = robot.n_dof
    caps = np.asarray(speed_cap_grid, dtype=float)

    class _PathWithArcLength(toppra.interpolator.AbstractGeometricPath):  # type: ignore[misc]  # toppra has no stubs
        """q(s) with s itself appended as coordinate n + 1."""

        def __call__(self, path_positions, order=0):  # type: ignore[no-untyped-def]
            s = np.atleast_1d(np.asarray(path_positions, dtype=float))
            extra = {0: s, 1: np.ones_like(s)}.get(order, np.zeros_like(s))
            out = np.column_stack([spline(s, order), extra])
            return out[0] if np.ndim(path_positions) == 0 else out

        @property
        def dof(self) -> int:
            return n + 1

        @property
        def path_interval(self) -> np.ndarray:
            return np.array([s_grid[0], s_grid[-1]])

    start = time.perf_counter()
    vlim_joints = np.column_stack([-robot.v_max, robot.v_max])

    def vlim(s: float) -> np.ndarray:
        cap = float(np.interp(s, s_grid, caps))
        return np.vstack([vlim_joints, [-cap, cap]])

    alim = np.concatenate([robot.a_max, [UNREACHABLE_ACCELERATION]])
    instance = algo.TOPPRA(
        [
            constraint.JointVelocityConstraintVarying(vlim),
            constraint.JointAccelerationConstraint(alim),
        ],
        _PathWithArcLength(),
        gridpoints=s_grid,
        solver_wrapper="seidel",
        parametrizer="ParametrizeConstAccel",
    )
    trajectory = instance.compute_trajectory(0.0, 0.0)
    spent = time.perf_counter() - start
    if trajectory is None:
        code = instance.problem_data.return_code
        return _failure(
            "toppra", f"toppra found no parameterisation ({code})", n, sample_time, spent
        )
    duration = float(trajectory.duration)
    t = _sample_times(duration, sample_time)
    sampled = trajectory(t)
    s = np.clip(sampled[:, n], s_grid[0], s_grid[-1])
    s[-1] = s_grid[-1]
    message = f"toppra (seidel, const-accel) on {len(s_grid)} grid points: {duration:.4f} s"
    return ReferenceResult("toppra", True, message, duration, spent, sample_time, s, spline(s))


def topp3_reference(
    robot: Robot | Machine,
    s_grid: np.ndarray,
    q_grid: GridJoints,
    speed_cap_grid: np.ndarray,
    sample_time: float,
) -> ReferenceResult:
    """Jerk-limited time optimum by copp-py's TOPP3 (SOCP) under every joint limit and the cap.

    Takes the inputs of :func:`toppra_reference` (shapes and units are given there); the
    robot's jerk limits ``j_max`` (n,), rad/s³, apply as well and ``s_grid`` is the solver's
    station grid.

    Returns
    -------
    ReferenceResult
        ``q`` sampled at Ts from the TOPP3 profile.
    """
    import copp_py as copp

    s_grid, spline = joint_spline(s_grid, q_grid)
    n, m = robot.n_dof, len(s_grid)
    caps = np.asarray(speed_cap_grid, dtype=float)
    start = time.perf_counter()
    try:
        model = copp.Robot(n, capacity=m)
        model.append_s(s_grid)
        model.set_q(spline(s_grid), spline(s_grid, 1), spline(s_grid, 2), 0, dddq=spline(s_grid, 3))
        model.add_velocity_limits(robot.v_max, -robot.v_max, start_idx_s=0, length=m)
        model.add_acceleration_limits(robot.a_max, -robot.a_max, start_idx_s=0, length=m)
        model.add_jerk_limits(robot.j_max, -robot.j_max, start_idx_s=0, length=m)
        model.constraints.add_constraint_1st((caps**2)[:, None], 0)
        solver = copp.solver
        second = solver.topp2_ra.Problem(  # type: ignore[attr-defined]
            model.constraints, idx_s_interval=(0, m - 1), a_boundary=(0.0, 0.0)
        )
        linearisation = np.maximum(solver.topp2_ra.solve(second), A_FLOOR)
        b_linearisation: np.ndarray | None = None  # first round: TOPP2's a only
        duration = np.inf
        for rounds in range(1, TOPP3_MAX_ROUNDS + 1):  # noqa: B007 (reported below)
            problem = solver.topp3_socp.Problem(  # type: ignore[attr-defined]
                model.constraints,
                linearisation,
                idx_s_start=0,
                a_boundary=(0.0, 0.0),
                b_boundary=(0.0, 0.0),
                num_stationary_max=1,
                b_linearization=b_linearisation,
            )
            profile = solver.topp3_socp.solve(problem)
            previous = duration
            duration, t_s = copp.interpolation.s_to_t_topp3(s_grid, profile)
            linearisation = np.maximum(profile.a, A_FLOOR)
            b_linearisation = profile.b
            if abs(previous - duration) <= TOPP3_SETTLED * duration:
                break
        spent = time.perf_counter() - start
    except copp.CoppError as error:
        spent = time.perf_counter() - start
        return _failure("topp3", f"copp-py TOPP3 failed: {error}", n, sample_time, spent)
    s = copp.interpolation.t_to_s_topp3_uniform(s_grid, profile, t_s, sample_time)
    s = np.clip(s, s_grid[0], s_grid[-1])
    s[-1] = s_grid[-1]
    message = (
        f"copp-py TOPP3 (SOCP) on {m} stations, {rounds} linearisation rounds: {duration:.4f} s"
    )
    return ReferenceResult(
        "topp3", True, message, float(duration), spent, sample_time, s, spline(s)
    )


def speed_caps(
    zones: list[tuple[float, float, str]],
    s_grid: np.ndarray,
    rated_speed: float,
    corner_speed: float,
) -> np.ndarray:
    """Cartesian speed cap at each grid point: the corner speed on curved zones.

    Parameters
    ----------
    zones
        ``(s_start, s_end, kind)`` of the planned path, kind ``straight`` or ``curved``.
    s_grid
        Arc lengths, shape (M,), m.
    rated_speed, corner_speed
        v_r and v_t^max, m/s.

    Returns
    -------
    numpy.ndarray
        Shape (M,), m/s.
    """
    caps = np.full(len(s_grid), float(rated_speed))
    for s0, s1, kind in zones:
        if kind != "straight":
            caps[(s_grid >= s0) & (s_grid <= s1)] = min(rated_speed, corner_speed)
    return caps


def reference_inputs(
    joint_path: JointPath, task: Task
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Grid, joint samples and speed caps of a joint path, for the reference laws.

    Parameters
    ----------
    joint_path
        The placed path's joint path (its planning grid, each boundary once).
    task
        Rated and corner speeds, m/s.

    Returns
    -------
    s_grid : numpy.ndarray
        Shape (M,), m, increasing.
    q_grid : numpy.ndarray
        Shape (M, n), rad.
    caps : numpy.ndarray
        Shape (M,), m/s.
    """
    s_grid, first = np.unique(joint_path.s, return_index=True)
    zones = [(float(a), float(b), str(k)) for a, b, k in joint_path.geometry.planned.zones]
    caps = speed_caps(zones, s_grid, task.rated_speed, task.corner_speed)
    return s_grid, joint_path.q[first], caps


def reference_durations(joint_path: JointPath, task: Task) -> dict[str, float]:
    """toppra and TOPP3 durations on a joint path.

    The references follow the same planned path on the same IK branch with the same
    limits and speed caps as the plan, from rest to rest.

    Parameters
    ----------
    joint_path
        The placed path's joint path (``PlanResult.joint_path``).
    task
        Speeds (m/s) and Ts (s).

    Returns
    -------
    dict of str to float
        ``toppra_duration`` and ``topp3_duration``, s (nan when a reference failed or the
        path has no joint path on that branch).
    """
    for package, module in (("toppra", "toppra"), ("copp-py", "copp_py")):
        try:
            __import__(module)
        except ImportError:
            raise CaseError(
                f"--reference needs the {package} package: pip install -e '.[reference]'",
                key="--reference",
            ) from None
    if not joint_path.success:
        return {"toppra_duration": float("nan"), "topp3_duration": float("nan")}
    s_grid, q_grid, caps = reference_inputs(joint_path, task)
    Ts = task.sample_time
    second = toppra_reference(joint_path.robot, s_grid, q_grid, caps, Ts)
    third = topp3_reference(joint_path.robot, s_grid, q_grid, caps, Ts)
    return {"toppra_duration": second.duration, "topp3_duration": third.duration}
