"""The checker's task checks: tracking, tool orientation, Cartesian speed and coverage.

Each compares the tool's sampled motion with a
:class:`~trackplan.planning.check_reference.TrackingReference` (the nominal path, the tool
spec, the tolerance and the speed caps).
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from trackplan._kernels import read_only
from trackplan.check_report import DownhandFigures, Violation
from trackplan.motion import JointSamples
from trackplan.planning import _kernels
from trackplan.planning.check_downhand import check_downhand
from trackplan.planning.check_reference import TrackingReference
from trackplan.planning.check_tool import check_tool
from trackplan.planning.check_violations import (
    RELATIVE_SLACK,
    met,
    plural,
    violation_over,
    violations_of,
)
from trackplan.planning.tracking import (
    BETWEEN_STEP,
    MAX_BETWEEN_PER_PERIOD,
    jump_allowance,
    locate_on_nominal,
)
from trackplan.robots.machine import Machine
from trackplan.robots.path_ik import _NEWTON_TOL as NEWTON_TOLERANCE
from trackplan.tool.weave import WovenPath, tool_rotations

WEAVE_TOLERANCE = 0.05
"""Largest difference of a sample's lateral offset from the weave's, as a share of the
amplitude."""

IK_POSITION_TOLERANCE = NEWTON_TOLERANCE
"""Largest distance between a sample's tool point (FK of its joints) and the path point the
joints were solved for, m: the numeric IK's Newton tolerance
(:data:`trackplan.robots.path_ik._NEWTON_TOL`), also the default of the paper law's
resolved-rate IK (:func:`trackplan.robots.resolved_rate.solve_path_resolved_rate`);
closed-form IK is exact to round-off."""


def speed_slack(sample_time: float) -> float:
    """Speed above a cap that still counts as meeting it, m/s: ``2 ε / Ts``.

    The checker's speed is the backward difference ``|p_k − p_(k−1)| / Ts`` of two tool
    points, each within ε = :data:`IK_POSITION_TOLERANCE` of the point of the path the time
    law planned there, so it differs from the planned speed by at most ``2 ε / Ts``
    (5e-8 m/s at Ts = 4 ms). The time laws plan the path at most at each cap, so a plan
    counted feasible by the search (in smooth timing, every geometrically feasible
    placement) passes this check; a sampled speed above ``cap + 2 ε / Ts`` (plus
    :data:`RELATIVE_SLACK` of the cap for round-off) is a planned excess and a violation.

    Parameters
    ----------
    sample_time
        Ts, s.

    Returns
    -------
    float
        m/s.
    """
    return 2.0 * IK_POSITION_TOLERANCE / sample_time


def check_task(
    motion: JointSamples, ref: TrackingReference
) -> tuple[tuple[dict[str, float], list[Violation]], float, float, DownhandFigures | None]:
    """Tracking, orientation, Cartesian speed and coverage checks.

    Parameters
    ----------
    motion
        The joint samples at Ts, shape (N, n), rad, with their tool poses.
    ref
        What the tool must do.

    Returns
    -------
    tuple
        ((the margin per task kind, the violations found), the largest tracking error, m,
        the largest tool axis error, rad, and the downhand figures when the task has the
        rule).
    """
    robot, q, sample_time = motion.robot, motion.q, motion.sample_time
    T_base_part = np.ascontiguousarray(ref.T_base_part, dtype=float)
    # the tool's points, velocities and speeds, and its x and z axes (all the tool checks
    # read), in the definition frame; and its points between the samples, along the
    # joint-space interpolation a controller follows (each period in parts of at most
    # BETWEEN_STEP ρ of chord, at least two): one compiled pass over the poses and joints
    if isinstance(robot, Machine):
        frames = machine_task_frames(
            robot, motion.T_base_tool, T_base_part, sample_time, q, BETWEEN_STEP * ref.tolerance
        )
    else:
        chain, tail = robot.kernel_chain
        # read-only inputs: one compiled version whoever made them (read_only)
        frames = _kernels.task_frames(
            read_only(np.ascontiguousarray(motion.T_base_tool)),
            read_only(T_base_part),
            sample_time,
            read_only(chain),
            read_only(tail),
            read_only(np.ascontiguousarray(q)),
            BETWEEN_STEP * ref.tolerance,
            MAX_BETWEEN_PER_PERIOD,
        )
    p_part, velocity, speed, x_part, z_part, p_between, t_between = frames
    t = np.arange(len(q)) * sample_time
    violations: list[Violation] = []
    margins: dict[str, float] = {}
    if ref.weave is not None:  # the checks below read the weave's centre line
        p_part, velocity, speed, p_between, weave_found = unweave_samples(
            ref.weave, p_part, x_part, z_part, p_between, t_between, t, margins
        )
        violations.extend(weave_found)

    # tracking error and the position along the nominal path, in order of travel
    s_nominal, distance, piece = locate_on_nominal(
        ref.nominal, p_part, velocity, ref.tolerance, speed
    )
    worst = float(distance.max())
    if distance.max() > ref.tolerance * (1 + RELATIVE_SLACK):
        violations.append(
            violation_over("tracking", None, t, distance, distance / ref.tolerance, ref.tolerance)
        )
    # ... and between the samples
    if len(p_between):
        d_between = ref.nominal.index.candidates(p_between, 0.0).nearest  # distances only
        worst = max(worst, float(d_between.max()))
        if d_between.max() > ref.tolerance * (1 + RELATIVE_SLACK) and not violations_of(
            violations, "tracking"
        ):
            t_b = t_between * sample_time
            found = violation_over(
                "tracking", None, t_b, d_between, d_between / ref.tolerance, ref.tolerance
            )
            message = found.message.replace("tracking", "tracking between samples", 1)
            violations.append(replace(found, message=message))
    margins["tracking"] = float(met(1.0 - worst / ref.tolerance, RELATIVE_SLACK))

    orientation_error, tool_found = check_tool(ref, x_part, z_part, s_nominal, piece, t, margins)
    violations.extend(tool_found)

    # Cartesian speed against the cap that applies where the tool is
    in_corner = np.zeros(len(q), dtype=bool)
    for s0, s1 in np.asarray(ref.corner_intervals).reshape(-1, 2):
        in_corner |= (s_nominal >= s0) & (s_nominal <= s1)
    cap = np.where(in_corner, ref.corner_speed, ref.rated_speed)
    # a backward difference is the mean speed over the last period: where that period
    # straddles the end of a corner, the mean may reach the higher of the two caps
    cap[1:] = np.maximum(cap[1:], cap[:-1])
    corner = in_corner.copy()
    corner[1:] |= in_corner[:-1]  # either end of the period in a corner …
    corner &= cap == ref.corner_speed  # … and the corner speed its cap
    margins["speed"], over_speed = speed_verdict(speed, cap, corner, t, sample_time)
    violations.extend(over_speed)

    coverage = coverage_violations(ref, t, s_nominal, piece, speed, sample_time)
    margins["coverage"] = 1.0 if not coverage else -1.0
    violations.extend(coverage)
    downhand = None
    if ref.downhand is not None:
        downhand, margins["downhand"], flat = check_downhand(motion, ref, s_nominal, piece, t)
        violations.extend(flat)
    return (margins, violations), worst, orientation_error, downhand


def machine_task_frames(
    machine: Machine,
    T_carrier_tool: np.ndarray,
    T_carrier_part: np.ndarray,
    sample_time: float,
    q: np.ndarray,
    chord_step: float,
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """:func:`trackplan.planning._kernels.task_frames` of a machine, whose part moves with
    its carrier: the tool relative to the part at the samples and between them (every
    joint, the external axes too, interpolated linearly within a period).

    Parameters
    ----------
    machine
        The arm and its external axes.
    T_carrier_tool
        The tool in the carrier frame at the samples, shape (N, 4, 4).
    T_carrier_part
        The placement X in the carrier frame, shape (4, 4).
    sample_time
        Ts, s.
    q
        The joint vector at the samples, shape (N, n).
    chord_step
        Largest chord between checked points, m (> 0).

    Returns
    -------
    tuple
        As the kernel: points, velocity (N, 3), speed (N,), x and z axes (N, 3), the points
        between the samples (K, 3) and their times in periods (K,).
    """
    R = T_carrier_part[:3, :3]
    origin = T_carrier_part[:3, 3]
    points = (T_carrier_tool[:, :3, 3] - origin) @ R
    x_axis = T_carrier_tool[:, :3, 0] @ R
    z_axis = T_carrier_tool[:, :3, 2] @ R
    velocity = np.zeros_like(points)
    velocity[1:] = (points[1:] - points[:-1]) / sample_time
    speed = np.linalg.norm(velocity, axis=1)
    if len(q) < 2:
        return points, velocity, speed, x_axis, z_axis, np.zeros((0, 3)), np.zeros(0)
    chord = np.linalg.norm(points[1:] - points[:-1], axis=1)
    with np.errstate(invalid="ignore"):
        parts = np.ceil(chord / chord_step)
    parts = np.where(np.isfinite(parts), parts, 2.0)
    parts = np.clip(parts, 2, MAX_BETWEEN_PER_PERIOD).astype(np.int64)
    period = np.repeat(np.arange(len(parts)), parts - 1)
    first = np.cumsum(parts - 1) - (parts - 1)
    j = np.arange(len(period)) - first[period] + 1
    fraction = j / parts[period]
    q_between = q[period] + fraction[:, None] * (q[period + 1] - q[period])
    between = (machine.T_carrier_tool(q_between)[:, :3, 3] - origin) @ R
    return points, velocity, speed, x_axis, z_axis, between, period + fraction


def unweave_samples(
    weave: WovenPath,
    p_part: np.ndarray,
    x_part: np.ndarray,
    z_part: np.ndarray,
    p_between: np.ndarray,
    t_between: np.ndarray,
    t: np.ndarray,
    margins: dict[str, float],
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, list[Violation]]:
    """The weave's centre line of the tool points, and the weave check.

    Each sample is located on the planned path (:meth:`WovenPath.unweave`) and the weave's
    offset there taken off; its lateral offset must be the weave's within
    :data:`WEAVE_TOLERANCE` of the amplitude (the ``weave`` margin and violation).

    Parameters
    ----------
    weave
        The task's weave over the planned path.
    p_part, x_part, z_part
        The tool points and x and z axes at the samples, definition frame, (N, 3).
    p_between, t_between
        The tool points between the samples (B, 3) and their times in periods (B,).
    t
        Sample times, (N,), s.
    margins
        The task margins, updated with ``weave``.

    Returns
    -------
    tuple
        The centre points (N, 3), m, their backward-difference velocities (N, 3), m/s, and
        speeds (N,), m/s, the centre points between the samples (B, 3), m, and the weave
        violations.
    """
    rotations = tool_rotations(x_part, z_part)
    centre, lateral, expected, _ = weave.unweave(p_part, rotations)
    error = np.abs(lateral - expected)
    bound = WEAVE_TOLERANCE * weave.track.weave.amplitude
    worst = float(error.max()) if len(error) else 0.0
    margins["weave"] = float(met(1.0 - worst / bound, RELATIVE_SLACK))
    found = []
    if worst > bound * (1 + RELATIVE_SLACK):
        over = violation_over("weave", None, t, error, error / bound, bound)
        message = over.message.replace("weave", "weave: the lateral offset is off by", 1)
        found.append(replace(over, message=message))
    sample_time = float(t[1] - t[0]) if len(t) > 1 else 1.0
    velocity = np.zeros_like(centre)
    velocity[1:] = np.diff(centre, axis=0) / sample_time
    speed = np.linalg.norm(velocity, axis=1)
    between = p_between
    if len(p_between):
        k = np.clip(np.floor(t_between).astype(int), 0, len(rotations) - 1)
        between = weave.unweave(p_between, rotations[k])[0]
    return centre, velocity, speed, between, found


def speed_verdict(
    speed: np.ndarray, cap: np.ndarray, in_corner: np.ndarray, t: np.ndarray, sample_time: float
) -> tuple[float, list[Violation]]:
    """The speed margin and violation, one verdict: a sample is over its cap when it exceeds
    it by more than :func:`speed_slack` plus :data:`RELATIVE_SLACK` of the cap; the margin
    ``1 − max(speed / cap)`` is negative exactly then (0 when within the slack).

    Parameters
    ----------
    speed, cap
        Tool speed (backward differences) and the cap at each sample, shape (N,), m/s.
    in_corner
        Whether the corner speed is the cap at each sample (an arc or a corner blend),
        shape (N,), bool; elsewhere the rated speed is (a straight piece).
    t
        Sample times, shape (N,), s.
    sample_time
        Ts, s.
    """
    over = speed - cap > speed_slack(sample_time) + RELATIVE_SLACK * cap
    margin = 1.0 - float((speed / cap).max())
    if not over.any():
        return max(margin, 0.0), []
    ratio = np.where(over, speed / cap, 0.0)
    found = violation_over("speed", None, t, speed, ratio, float(cap[np.argmax(ratio)]))
    worst = int(np.argmax(ratio))
    value, bound = float(speed[worst]), float(cap[worst])
    if in_corner[worst]:
        which = f"the corner speed {bound:g} m/s (the cap on arcs and corner blends)"
    else:
        which = f"the rated speed {bound:g} m/s (the cap on straight pieces)"
    message = (
        f"speed {value:.6g} m/s exceeds {which} by {value - bound:.3g} m/s at "
        f"t = {t[worst]:.3f} s ({plural(int(over.sum()), 'sample')} from "
        f"t = {found.t_first:.3f} to {found.t_last:.3f} s)"
    )
    return min(margin, -RELATIVE_SLACK), [replace(found, message=message)]


def coverage_violations(
    ref: TrackingReference,
    t: np.ndarray,
    s: np.ndarray,
    piece: np.ndarray,
    speed: np.ndarray,
    sample_time: float,
) -> list[Violation]:
    """The whole nominal path covered from start to end, in order, with no jump.

    Parameters
    ----------
    ref
        What the tool must do (the nominal path, the tolerance ρ, the speed caps).
    t
        Sample times, shape (N,), s.
    s, piece
        Each sample's arc length on the nominal path, m, and nominal piece index, shape (N,).
    speed
        Tool speed at each sample, shape (N,), m/s.
    sample_time
        Ts, s.

    Returns
    -------
    list of Violation
        ``coverage`` violations: a late start, an early end, a run backwards, a jump.
    """
    nominal = ref.nominal
    tol = 2.0 * ref.tolerance
    found: list[Violation] = []

    def add(k: int, value: float, bound: float, text: str) -> None:
        found.append(
            Violation(
                limit="coverage",
                joint=None,
                t_first=float(t[k]),
                t_last=float(t[k]),
                worst=value,
                bound=bound,
                message=text,
            )
        )

    if s[0] > tol:
        add(
            0,
            float(s[0]),
            tol,
            f"coverage: the trajectory starts {s[0]:.4g} m into the path, not at its start",
        )
    if s[-1] < nominal.length - tol:
        add(
            len(s) - 1,
            float(s[-1]),
            nominal.length,
            f"coverage: the trajectory ends {nominal.length - s[-1]:.4g} m before the path end",
        )
    step = np.diff(s)
    backwards = np.flatnonzero(step < -tol)
    if backwards.size:
        k = int(backwards[0]) + 1
        add(
            k,
            float(step[k - 1]),
            0.0,
            f"coverage: the path is run backwards at t = {t[k]:.3f} s "
            f"({plural(backwards.size, 'step')})",
        )
    allowance = jump_allowance(nominal, ref.tolerance)  # (P,) extra jump allowed after piece p
    # one sample may advance up to a few times the task speed (a speed excess is reported
    # as such); more is a jump over part of the path
    step_cap = 4.0 * max(ref.rated_speed, ref.corner_speed) * sample_time + tol
    allowed = step_cap + np.where(piece[1:] != piece[:-1], allowance[piece[:-1]], 0.0)
    jumps = np.flatnonzero(step > allowed)
    if jumps.size:
        k = int(jumps[0]) + 1
        segment = np.asarray(nominal.segment_index)
        between = np.unique(segment[piece[k - 1] + 1 : piece[k]])
        between = between[(between != segment[piece[k - 1]]) & (between != segment[piece[k]])]
        if between.size:
            what = "segment " + ", ".join(str(int(i) + 1) for i in between) + " skipped"
        else:
            what = f"part of segment {int(segment[piece[k]]) + 1} skipped"
        add(
            k,
            float(step[k - 1]),
            float(allowed[k - 1]),
            f"coverage: {what} at t = {t[k]:.3f} s: {step[k - 1]:.4g} m in one sample",
        )
    return found
