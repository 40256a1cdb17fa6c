"""The one checker: every sample against every limit, with where and how much.

It serves the planner, the optimizer, the tests and ``trackplan check``. It never returns a
bare bool: a :class:`~trackplan.planning.result.CheckReport` carries margins per limit and
joint, and every violation with its time window and worst value.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field, replace
from typing import TYPE_CHECKING

import numpy as np

from trackplan._kernels import read_only
from trackplan.motion import JointSamples
from trackplan.paths import NominalPath
from trackplan.planning import _kernels
from trackplan.planning.result import CheckReport, Violation
from trackplan.planning.tool_zones import nominal_rotations
from trackplan.planning.tracking import (
    BETWEEN_STEP,
    MAX_BETWEEN_PER_PERIOD,
    jump_allowance,
    locate_on_nominal,
)
from trackplan.robots.dynamics.rne import inverse_dynamics
from trackplan.robots.model import Robot
from trackplan.robots.path_ik import _NEWTON_TOL as NEWTON_TOLERANCE
from trackplan.tool import SpinMode, ToolFrame, ToolSpec

if TYPE_CHECKING:
    from trackplan.cell.screening import CellGeometry

UNITS = {
    "position": "rad",
    "velocity": "rad/s",
    "acceleration": "rad/s²",
    "jerk": "rad/s³",
    "torque": "N·m",
    "tracking": "m",
    "orientation": "rad",
    "spin": "rad",
    "spin rate": "rad/m",
    "speed": "m/s",
    "coverage": "m",
    "clearance": "m",
}
RELATIVE_SLACK = 1e-9
"""Values within this relative amount of a limit count as meeting it (float round-off)."""
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


ORIENTATION_TOLERANCE = 1e-3
"""Largest tool orientation error accepted, rad."""


@dataclass(frozen=True, eq=False)
class TrackingReference:
    """What the tool must do, for the task checks.

    Attributes
    ----------
    nominal
        The path as the user gave it (:class:`trackplan.paths.NominalPath`), definition frame.
    T_base_part
        Placement of the definition frame, shape (4, 4).
    tool
        How the tool is held (:class:`trackplan.tool.ToolSpec`): the tool axis is checked
        against it at every sample, the spin against its value, range and rate.
    tolerance
        ρ, m.
    rated_speed, corner_speed
        Speed caps on straight pieces and at corners, m/s.
    corner_intervals
        Arc-length intervals of the nominal path where the corner speed applies, shape (K, 2), m.
    tool_zones
        Transition zones (:func:`trackplan.planning.tool_zones.transition_zones`), shape
        (K, 3): nominal arc lengths (m) and the extra tool axis deviation allowed (rad).
    orientation_tolerance
        Largest tool axis error, and spin error of a fixed spin, rad.
    """

    nominal: NominalPath
    T_base_part: np.ndarray
    tool: ToolSpec
    tolerance: float
    rated_speed: float
    corner_speed: float
    corner_intervals: np.ndarray
    tool_zones: np.ndarray = field(default_factory=lambda: np.zeros((0, 3)))
    orientation_tolerance: float = ORIENTATION_TOLERANCE


def check_trajectory(
    robot: Robot,
    q: np.ndarray,
    sample_time: float,
    reference: TrackingReference | None = None,
    cell: CellGeometry | None = None,
) -> CheckReport:
    """Check a sampled joint trajectory against the robot's limits and the task.

    Derivatives are backward differences at Ts with the robot at rest before the first and
    after the last sample (docs/conventions.md), exactly what a controller consuming the
    samples sees. A robot with dynamics also has its torques checked, from the same q, q̇,
    q̈ (``docs/dynamics.md``).

    Parameters
    ----------
    robot
        The robot (limits and kinematics).
    q
        Joint positions, shape (N, n), rad, one row per controller period.
    sample_time
        Ts, s.
    reference
        The task to check against (tracking, orientation, Cartesian speed, coverage);
        None checks joint limits only.
    cell
        The work cell laid out for the robot (:class:`trackplan.cell.screening.CellGeometry`):
        adds the clearance margin and collision violations (:mod:`trackplan.cell.check`);
        its workpiece is placed at ``reference.T_base_part`` (identity without a reference).

    Returns
    -------
    CheckReport
        Margins, violations and the worst tracking and orientation errors.
    """
    return check_motion(JointSamples(robot, q, sample_time), reference, cell)


def check_motion(
    motion: JointSamples,
    reference: TrackingReference | None = None,
    cell: CellGeometry | None = None,
) -> CheckReport:
    """:func:`check_trajectory` of sampled joints whose derivatives, torques and tool poses
    other readers share (:class:`~trackplan.motion.JointSamples`: each computed once).

    Parameters
    ----------
    motion
        The joint samples at Ts, shape (N, n), rad, and the robot.
    reference, cell
        As :func:`check_trajectory`.

    Returns
    -------
    CheckReport
    """
    robot, q, sample_time = motion.robot, motion.q, motion.sample_time
    t = np.arange(len(q) + 3) * sample_time
    qd, qdd, qddd = motion.qd, motion.qdd, motion.qddd
    violations: list[Violation] = []
    margins: dict[str, np.ndarray] = {}
    binding: dict[str, tuple[int, float]] = {}

    # position: distance to the nearer bound as a fraction of the half range; the rates
    # and torques: their magnitude as a fraction of the limit
    half_range = 0.5 * (robot.q_max - robot.q_min)
    centre = 0.5 * (robot.q_max + robot.q_min)
    zero = np.zeros(robot.n_dof)
    signals = {
        "position": (q, centre, half_range),
        "velocity": (qd, zero, robot.v_max),
        "acceleration": (qdd, zero, robot.a_max),
        "jerk": (qddd, zero, robot.j_max),
    }
    if robot.dynamics is not None and motion.torque is not None:
        signals["torque"] = (motion.torque, zero, robot.dynamics.torque_max)
    for kind, (values, middle, scale) in signals.items():
        peak, peak_row = _kernels.peak_use(
            read_only(np.ascontiguousarray(values)),
            read_only(np.asarray(middle, dtype=float)),
            read_only(np.asarray(scale, dtype=float)),
        )
        margins[kind] = _met(1.0 - peak, RELATIVE_SLACK)
        worst_joint = int(np.argmax(peak))
        binding[kind] = (worst_joint + 1, float(t[peak_row[worst_joint]]))
        for j in np.flatnonzero(peak > 1.0 + RELATIVE_SLACK):
            limit = scale[j]
            if kind == "position":
                above = values[peak_row[j], j] > centre[j]
                limit = robot.q_max[j] if above else robot.q_min[j]
            use = np.abs(values[:, j] - middle[j]) / scale[j]
            violations.append(_violation(kind, int(j) + 1, t, values[:, j], use, float(limit)))
    if robot.dynamics is not None:
        violations = [_at_any_speed(robot, motion.q_held, t, v) for v in violations]

    task_margins: dict[str, float] = {}
    max_tracking = 0.0
    max_orientation = 0.0
    if reference is not None:
        task, max_tracking, max_orientation = _check_task(motion, reference)
        task_margins, task_violations = task
        violations.extend(task_violations)

    cell_report = None
    if cell is not None:
        from trackplan.cell.check import check_cell

        T_base_part = reference.T_base_part if reference is not None else np.eye(4)
        cell_report = check_cell(cell, robot, q, sample_time, T_base_part)
        task_margins["clearance"] = cell_report.margin
        violations.extend(cell_report.violations)

    return CheckReport(
        success=not violations,
        joint_margins=margins,
        task_margins=task_margins,
        violations=tuple(violations),
        max_tracking_error=max_tracking,
        max_orientation_error=max_orientation,
        binding=binding,
        cell=cell_report,
    )


def _count(n: int, noun: str) -> str:
    """``1 sample``, ``2 samples``."""
    return f"{n} {noun}" if n == 1 else f"{n} {noun}s"


def _met(margin: np.ndarray | float, slack: float) -> np.ndarray:
    """A margin within the round-off slack of a limit counts as met: reported as 0, not < 0."""
    if isinstance(margin, float):  # one number: no array round trip
        return np.asarray(0.0 if -slack <= margin < 0 else margin)
    margin = np.asarray(margin, dtype=float)
    return np.where((margin < 0) & (margin >= -slack), 0.0, margin)


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


def _violation(
    kind: str, joint: int | None, t: np.ndarray, values: np.ndarray, use: np.ndarray, bound: float
) -> Violation:
    """Summarise the samples where ``use > 1`` into one :class:`Violation`."""
    bad = np.flatnonzero(use > 1.0 + RELATIVE_SLACK)
    worst = int(bad[np.argmax(use[bad])])
    value = float(values[worst])
    who = f"joint {joint} {kind}" if joint is not None else kind
    message = (
        f"{who} {abs(value):.4g} {UNITS[kind]} exceeds {abs(bound):.4g} at t = {t[worst]:.3f} s"
        f" ({_count(len(bad), 'sample')} from t = {t[bad[0]]:.3f} to {t[bad[-1]]:.3f} s)"
    )
    return Violation(
        limit=kind,
        joint=joint,
        t_first=float(t[bad[0]]),
        t_last=float(t[bad[-1]]),
        worst=value,
        bound=bound,
        message=message,
    )


def _check_task(
    motion: JointSamples, ref: TrackingReference
) -> tuple[tuple[dict[str, float], list[Violation]], float, float]:
    """Tracking, orientation, Cartesian speed and coverage checks."""
    robot, q, sample_time = motion.robot, motion.q, motion.sample_time
    T_base_part = np.ascontiguousarray(ref.T_base_part, dtype=float)
    # the tool's points, velocities and speeds, and its x and z axes (all the tool checks
    # read), in the definition frame; and its points between the samples, along the
    # joint-space interpolation a controller follows (each period in parts of at most
    # BETWEEN_STEP ρ of chord, at least two): one compiled pass over the poses and joints
    chain, tail = robot.kernel_chain
    # read-only inputs: one compiled version whoever made them (read_only)
    p_part, velocity, speed, x_part, z_part, p_between, t_between = _kernels.task_frames(
        read_only(np.ascontiguousarray(motion.T_base_tool)),
        read_only(T_base_part),
        sample_time,
        read_only(chain),
        read_only(tail),
        read_only(np.ascontiguousarray(q)),
        BETWEEN_STEP * ref.tolerance,
        MAX_BETWEEN_PER_PERIOD,
    )
    t = np.arange(len(q)) * sample_time
    violations: list[Violation] = []
    margins: dict[str, float] = {}

    # tracking error and the position along the nominal path, in order of travel
    s_nominal, distance, piece = locate_on_nominal(
        ref.nominal, p_part, velocity, ref.tolerance, speed
    )
    worst = float(distance.max())
    if distance.max() > ref.tolerance * (1 + RELATIVE_SLACK):
        violations.append(
            _violation("tracking", None, t, distance, distance / ref.tolerance, ref.tolerance)
        )
    # ... and between the samples
    if len(p_between):
        d_between = ref.nominal.index.candidates(p_between, 0.0).nearest  # distances only
        worst = max(worst, float(d_between.max()))
        if d_between.max() > ref.tolerance * (1 + RELATIVE_SLACK) and not violations_of(
            violations, "tracking"
        ):
            t_b = t_between * sample_time
            found = _violation(
                "tracking", None, t_b, d_between, d_between / ref.tolerance, ref.tolerance
            )
            message = found.message.replace("tracking", "tracking between samples", 1)
            violations.append(replace(found, message=message))
    margins["tracking"] = float(_met(1.0 - worst / ref.tolerance, RELATIVE_SLACK))

    orientation_error, tool_found = _check_tool(ref, x_part, z_part, s_nominal, piece, t, margins)
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
    margins["speed"], over_speed = _speed_verdict(speed, cap, corner, t, sample_time)
    violations.extend(over_speed)

    coverage = _coverage_violations(ref, t, s_nominal, piece, speed, sample_time)
    margins["coverage"] = 1.0 if not coverage else -1.0
    violations.extend(coverage)
    return (margins, violations), worst, orientation_error


def _speed_verdict(
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
    found = _violation("speed", None, t, speed, ratio, float(cap[np.argmax(ratio)]))
    worst = int(np.argmax(ratio))
    value, bound = float(speed[worst]), float(cap[worst])
    if in_corner[worst]:
        which = f"the corner speed {bound:g} m/s (the cap on arcs and corner blends)"
    else:
        which = f"the rated speed {bound:g} m/s (the cap on straight pieces)"
    message = (
        f"speed {value:.6g} m/s exceeds {which} by {value - bound:.3g} m/s at "
        f"t = {t[worst]:.3f} s ({_count(int(over.sum()), 'sample')} from "
        f"t = {found.t_first:.3f} to {found.t_last:.3f} s)"
    )
    return min(margin, -RELATIVE_SLACK), [replace(found, message=message)]


def violations_of(violations: list[Violation], limit: str) -> list[Violation]:
    """The violations of one limit."""
    return [violation for violation in violations if violation.limit == limit]


def _check_tool(
    ref: TrackingReference,
    x_part: np.ndarray,
    z_part: np.ndarray,
    s_nominal: np.ndarray,
    piece: np.ndarray,
    t: np.ndarray,
    margins: dict[str, float],
) -> tuple[float, list[Violation]]:
    """Tool axis against the spec on the nominal path; spin value, range and rate.

    Outside transition zones the tool axis must match the spec to the orientation
    tolerance; inside, to the tolerance plus the zone's bound. The spin is measured about
    the actual tool axis from the spec's zero-spin frame, outside transition zones.

    Parameters
    ----------
    x_part, z_part
        The tool's x axis and its axis (z) at the samples in the definition frame, shape
        (N, 3) each.

    Returns
    -------
    tuple
        The largest tool axis error, rad, and the violations found.
    """
    nominal, spec, tol = ref.nominal, ref.tool, ref.orientation_tolerance
    if spec.frame is ToolFrame.PART:  # one rotation (3, 3) for the whole path
        R_spec = spec.base_rotations(np.zeros((1, 3)))[0]
    else:
        R_spec = nominal_rotations(spec, nominal, s_nominal, piece)
    axis_cos = np.clip(_along(z_part, R_spec, 2), -1.0, 1.0)
    allowed = np.full(len(t), tol)
    for s0, s1, bound in np.asarray(ref.tool_zones).reshape(-1, 3):
        allowed[(s_nominal >= s0) & (s_nominal <= s1)] += bound
    outside = allowed == tol
    everywhere = bool(outside.all())  # no transition zone: one tolerance, no copies
    found: list[Violation] = []
    if everywhere and tol > 0.0:
        # the largest error over the one tolerance: the arccos of the smallest cosines only
        largest = float(np.arccos(_smallest(axis_cos)).max())
        margins["orientation"] = float(_met(1.0 - largest / tol, RELATIVE_SLACK))
    else:
        axis_error = np.arccos(axis_cos)
        largest = float(axis_error.max())
        margins["orientation"] = float(_met(1.0 - (axis_error / allowed).max(), RELATIVE_SLACK))
    if margins["orientation"] < 0:
        axis_error = np.arccos(axis_cos)
        found.append(_violation("orientation", None, t, axis_error, axis_error / allowed, tol))

    if not outside.any():
        return largest, found
    x_along = [_along(x_part, R_spec, j) for j in (0, 1)]
    x_along = x_along if everywhere else [x[outside] for x in x_along]
    t_out, s_out, piece_out = (
        (t, s_nominal, piece) if everywhere else (t[outside], s_nominal[outside], piece[outside])
    )
    if spec.spin is SpinMode.FIXED:
        # the error is taken modulo 2π: only a reported spin needs unwrapping
        rows = _largest_spin_errors(x_along[0], x_along[1], spec.spin_value)
        error = _spin_error(np.arctan2(x_along[1][rows], x_along[0][rows]), spec.spin_value)
        margins["spin"] = float(_met(1.0 - error.max() / tol, RELATIVE_SLACK))
        if margins["spin"] < 0:
            spin = np.arctan2(x_along[1], x_along[0])
            error = _spin_error(spin, spec.spin_value)
            unwrapped = np.unwrap(spin)
            found.append(_violation("spin", None, t_out, unwrapped, error / tol, spec.spin_value))
        return largest, found
    spin = np.unwrap(np.arctan2(x_along[1], x_along[0]))
    lo, hi = spec.spin_range
    spin = spin + 2 * np.pi * np.round((0.5 * (lo + hi) - np.median(spin)) / (2 * np.pi))
    excess = np.maximum(lo - spin, spin - hi)
    margins["spin"] = float(_met(-excess.max() / max(hi - lo, tol), RELATIVE_SLACK)) + 0.0
    if excess.max() > tol:
        bound = hi if spin.max() > hi else lo
        found.append(_violation("spin", None, t_out, spin, 1.0 + excess / tol, bound))
    rate_cap = 0.0 if spec.spin is SpinMode.FREE else spec.spin_rate
    ds = np.diff(s_out)
    same = (piece_out[1:] == piece_out[:-1]) & (ds > 0.0)
    step = np.abs(np.diff(spin))[same]
    cap = rate_cap * ds[same] + tol * (1.0 if rate_cap == 0.0 else 1e-6)
    if step.size and np.any(step > cap):
        rate = step / np.maximum(ds[same], 1e-12)
        worst = int(np.argmax(step / cap))
        when = float(t_out[1:][same][worst])
        found.append(
            Violation(
                limit="spin rate",
                joint=None,
                t_first=when,
                t_last=when,
                worst=float(rate[worst]),
                bound=rate_cap,
                message=(
                    f"spin rate {rate[worst]:.4g} rad/m exceeds {rate_cap:.4g} at t = {when:.3f} s"
                ),
            )
        )
    return largest, found


SCREEN_WINDOW = 1e-9
"""Relative width of the screens that spare the checker most of its arccos and arctan2
(:func:`_smallest`, :func:`_largest_spin_errors`): far wider than their round-off, so that
the largest of the screened values is the largest of all, to the bit."""


def _smallest(cosines: np.ndarray) -> np.ndarray:
    """The cosines in [-1, 1] whose arccos may be the largest, shape (K,).

    On [c, 1] with c ≥ 0 arccos falls with a slope of at least 1/√(1 - c²): a cosine more
    than ``1e-3 · SCREEN_WINDOW · (1 - c)`` above the smallest c has an arccos smaller by
    more than a thousand times its round-off, so the largest arccos of all is among these
    few (each evaluated as numpy does). A smallest cosine below 0, or a NaN: all of them.
    """
    low = cosines.min()
    if not low >= 0.0:
        return cosines
    return cosines[cosines <= low + 1e-3 * SCREEN_WINDOW * (1.0 - low)]


def _spin_error(spin: np.ndarray, value: float) -> np.ndarray:
    """The distance of each spin (M,) from ``value`` modulo 2π, rad, shape (M,)."""
    turn = spin - value
    return np.abs(turn - 2 * np.pi * np.round(turn / (2 * np.pi)))


def _largest_spin_errors(x_cos: np.ndarray, x_sin: np.ndarray, value: float) -> np.ndarray:
    """Rows whose spin ``arctan2(x_sin, x_cos)`` may be the farthest from ``value``.

    While every spin error θ is under 60°, ``tan θ = |x_sin cos v - x_cos sin v| /
    (x_cos cos v + x_sin sin v)`` ranks them: rows whose tangent is below the largest by more
    than :data:`SCREEN_WINDOW` (relative) have a smaller θ by more than round-off. The
    computed error also carries an absolute round-off of about 1e-15 (|v| + 8) rad (of the
    arctan2 near v and of the turns taken off), zero for v = 0: rows within a thousand times
    that of the largest tangent stay. Otherwise (an error of 60° or more, or a NaN) every
    row.

    Returns
    -------
    numpy.ndarray
        Row indices into the (M,) inputs, shape (K,).
    """
    c, s = np.cos(value), np.sin(value)
    along = x_cos * c + x_sin * s
    if not np.all(along > 0.5 * np.sqrt(x_cos * x_cos + x_sin * x_sin)):
        return np.arange(len(x_cos))
    tangent = np.abs(x_sin * c - x_cos * s) / along
    high = tangent.max()
    if not np.isfinite(high):
        return np.arange(len(x_cos))
    noise = 0.0 if value == 0.0 else 1e-12 * (abs(value) + 8.0)
    return np.flatnonzero(tangent >= high * (1.0 - SCREEN_WINDOW) - noise)


def _along(v: np.ndarray, R: np.ndarray, j: int) -> np.ndarray:
    """Per sample, ``v`` (N, 3) dotted with column j of R: one rotation (3, 3) or one per
    sample (N, 3, 3); shape (N,)."""
    if R.ndim == 2:
        return v @ R[:, j]
    return np.einsum("ni,ni->n", v, R[:, :, j])


def _coverage_violations(
    ref: TrackingReference,
    t: np.ndarray,
    s: np.ndarray,
    piece: np.ndarray,
    speed: np.ndarray,
    sample_time: float,
) -> list[Violation]:
    """The whole nominal path covered from start to end, in order, with no jump."""
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
            f"({_count(backwards.size, 'step')})",
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
