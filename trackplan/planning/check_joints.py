"""The checker's joint checks: position, velocity, acceleration, jerk and torque limits."""

from __future__ import annotations

import dataclasses

import numpy as np

from trackplan._kernels import read_only
from trackplan.check_report import Violation
from trackplan.motion import JointSamples
from trackplan.planning import _kernels
from trackplan.planning.check_violations import RELATIVE_SLACK, met, violation_over
from trackplan.robots.dynamics.rne import inverse_dynamics
from trackplan.robots.model import Robot


def check_joint_limits(
    motion: JointSamples, t: np.ndarray
) -> tuple[dict[str, np.ndarray], dict[str, tuple[int, float]], list[Violation]]:
    """Every sample's joint positions, rates and torques against the robot's limits.

    Position: distance to the nearer bound as a fraction of the half range; the rates and
    torques (with dynamics): their magnitude as a fraction of the limit.

    Parameters
    ----------
    motion
        The joint samples at Ts, shape (N, n), rad, their backward differences and, with
        dynamics, their torques.
    t
        Sample times, at least N + 3 of them, s (the differences run past the last sample).

    Returns
    -------
    tuple
        Per limit kind the margins, shape (n,); per limit kind the 1-based joint and the
        time, s, where it is closest to binding; the violations, joint by joint.
    """
    robot, q = motion.robot, motion.q
    violations: list[Violation] = []
    margins: dict[str, np.ndarray] = {}
    binding: dict[str, tuple[int, float]] = {}
    half_range = 0.5 * (robot.q_max - robot.q_min)
    centre = 0.5 * (robot.q_max + robot.q_min)
    zero = np.zeros(robot.n_dof)
    signals = {
        "position": (q, centre, half_range),
        "velocity": (motion.qd, zero, robot.v_max),
        "acceleration": (motion.qdd, zero, robot.a_max),
        "jerk": (motion.qddd, zero, robot.j_max),
    }
    if robot.dynamics is not None and motion.torque is not None:
        signals["torque"] = (motion.torque, zero, robot.dynamics.torque_max)
    for kind, (values, middle, scale) in signals.items():
        peak, peak_row = _kernels.peak_use(
            read_only(np.ascontiguousarray(values)),
            read_only(np.asarray(middle, dtype=float)),
            read_only(np.asarray(scale, dtype=float)),
        )
        margins[kind] = met(1.0 - peak, RELATIVE_SLACK)
        worst_joint = int(np.argmax(peak))
        binding[kind] = (worst_joint + 1, float(t[peak_row[worst_joint]]))
        for j in np.flatnonzero(peak > 1.0 + RELATIVE_SLACK):
            limit = scale[j]
            if kind == "position":
                above = values[peak_row[j], j] > centre[j]
                limit = robot.q_max[j] if above else robot.q_min[j]
            use = np.abs(values[:, j] - middle[j]) / scale[j]
            violations.append(violation_over(kind, int(j) + 1, t, values[:, j], use, float(limit)))
    if robot.dynamics is not None:
        violations = [_at_any_speed(robot, motion.q_held, t, v) for v in violations]
    return margins, binding, violations


def _at_any_speed(robot: Robot, q: np.ndarray, t: np.ndarray, violation: Violation) -> Violation:
    """A torque violation that holding still against gravity already causes, said so."""
    if violation.limit != "torque" or violation.joint is None:
        return violation
    j = violation.joint - 1
    zero = np.zeros_like(q)
    holding = np.abs(inverse_dynamics(robot, q, zero, zero, friction=False)[:, j])
    worst = int(np.argmax(holding))
    if holding[worst] <= violation.bound * (1.0 + RELATIVE_SLACK):
        return violation
    message = (
        f"{violation.message}; holding against gravity alone needs {holding[worst]:.4g} N·m "
        f"at t = {t[worst]:.3f} s: infeasible at any speed"
    )
    return dataclasses.replace(violation, message=message)
