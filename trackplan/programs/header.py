"""The header comment of a program: where it comes from and what it holds."""

from __future__ import annotations

from importlib.metadata import PackageNotFoundError, version

import numpy as np

from trackplan.case import Case
from trackplan.frames import rpy_from_matrix
from trackplan.planning.result import PlanResult
from trackplan.programs.model import Budget, ExternalAxis


def trackplan_version() -> str:
    """The installed trackplan's version, or ``unknown``."""
    try:
        return version("trackplan")
    except PackageNotFoundError:  # pragma: no cover - a source tree without metadata
        return "unknown"


def frame_text(T: np.ndarray) -> str:
    """A frame (4, 4), m, as ``xyz […] mm, rpy […] deg`` (R = Rz(yaw)·Ry(pitch)·Rx(roll))."""
    xyz = 1e3 * T[:3, 3]
    rpy = np.degrees(rpy_from_matrix(T[:3, :3]))
    return f"xyz [{_numbers(xyz, 4)}] mm, rpy [{_numbers(rpy, 5)}] deg"


def _numbers(values: np.ndarray, digits: int) -> str:
    # rounded first, then + 0.0: no "-0.000" for a value that rounds to zero
    return ", ".join(f"{round(float(v), digits) + 0.0:.{digits}f}" for v in values)


def header_lines(
    case: Case,
    plan: PlanResult,
    *,
    base: np.ndarray,
    tool: np.ndarray,
    form: str,
    budget: Budget | None = None,
    period: float | None = None,
    external: tuple[ExternalAxis, ...] = (),
) -> tuple[str, ...]:
    """The header lines, without comment marks.

    Parameters
    ----------
    case, plan
        The run.
    base
        The part frame in the controller's world, shape (4, 4), m.
    tool
        The TCP in the flange, shape (4, 4), m.
    form
        ``cartesian`` or ``joint``.
    budget
        The worst seam's tolerance budget (Cartesian form).
    period
        Time per move, s (joint form).
    external
        The external axes (track, positioner), in the program's order.
    """
    robot = case.robot
    X = np.asarray(plan.placement, dtype=float)
    convention = robot.convention
    if plan.success:
        said = plan.message.startswith(plan.status.value)
        verdict = f"verdict: {plan.message if said else f'{plan.status.value}: {plan.message}'}"
    else:
        verdict = (
            f"verdict: NOT FEASIBLE ({plan.status.value}): {plan.message}; exported with --force"
        )
    lines = [
        f"written by trackplan {trackplan_version()}",
        f"case: {case.name}" + (f" ({case.source})" if case.source else ""),
        f"robot: {robot.name} ({robot.n_dof} joints); controller {convention.vendor}: "
        f"{convention.source or 'joints and world as the model'}",
        f"placement X: [{_numbers(X[:3], 6)}] m, [{_numbers(X[3:], 6)}] rad = "
        f"[{_numbers(1e3 * X[:3], 3)}] mm, [{_numbers(np.degrees(X[3:]), 4)}] deg",
        (
            f"base (part frame on the positioner's flange): {frame_text(base)}"
            if any(axis.kind == "positioner" for axis in external)
            else f"base (part frame in the controller world): {frame_text(base)}"
        ),
        f"tool (TCP in the flange): {frame_text(tool)}",
        verdict,
        f"duration: {plan.duration:.3f} s (sample time {plan.trajectory.sample_time:g} s)",
    ]
    if external:
        listed = ", ".join(f"{axis.name} ({axis.kind}, {axis.unit})" for axis in external)
        lines.append(f"external axes, in order: {listed}")
    if form == "cartesian":
        lines.append("form: cartesian (path moves in the part frame; joint moves between seams)")
    else:
        lines.append(
            f"form: joint (the planned joint trajectory, one timed move every {period:g} s)"
        )
    if budget is not None:
        lines.append(
            f"tolerance budget (worst seam): tolerance {1e3 * budget.tolerance:.4f} mm"
            f" - plan tracking error {1e3 * budget.tracking_error:.4f} mm"
            f" - chord error {1e3 * budget.chord_error:.4f} mm"
            f" - zone {1e3 * budget.zone:.4f} mm = slack {1e3 * budget.slack:.4f} mm"
        )
    return tuple(lines)


__all__ = ["frame_text", "header_lines", "trackplan_version"]
