"""The text the commands print: case descriptions, robot tables, plan and search summaries."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
from rich.markup import escape

from trackplan.case import Case
from trackplan.frames import rpy_from_matrix
from trackplan.paths import NominalPath
from trackplan.planning.result import CheckReport, PlanResult
from trackplan.robots.model import Robot

if TYPE_CHECKING:  # rich's tables only for the commands that print one
    from rich.console import Console
    from rich.table import Table


def describe_case(case: Case, file: Path | str) -> list[str]:
    """Summary lines of a valid case: name, robot, its seams (each path's segments, length
    and corner angles), the task and the sequencing."""
    task = case.task
    sequencing = case.sequencing
    lines = [
        f"{file}: ok",
        f"  name      {case.name}",
        f"  robot     {case.robot.name} ({case.robot.n_dof} joints)",
        f"  seams     {len(case.seams)}: {', '.join(case.seam_names)}",
    ]
    for seam in case.seams:
        path = NominalPath.from_specs(seam.start, seam.segments)
        corners = "; ".join(
            f"{angle:.1f}° between segments[{segment - 1}] and segments[{segment}]"
            for segment, angle in segment_corners(path)
        )
        lines += [
            f"  path      {seam.name}: {_count(len(seam.segments), 'segment')}, length "
            f"{path.length:.4f} m{'' if seam.reversible else ', not reversible'}",
            f"  corners   {corners or 'none'}",
        ]
    return [
        *lines,
        f"  task      rated speed {task.rated_speed:g} m/s, corner speed "
        f"{task.corner_speed:g} m/s, tolerance {task.tolerance * 1e3:g} mm, "
        f"sample time {task.sample_time * 1e3:g} ms, timing {task.timing}",
        f"  sequence  {sequencing.sequence}, approach {sequencing.approach:g} m, "
        f"home {'none' if sequencing.home is None else 'given'}",
        *_tcp_line(case),
        *_axes_lines(case),
    ]


def _axes_lines(case: Case) -> list[str]:
    """The case's welding-cell keys: positioner, track, downhand and weaves, when given."""
    lines = []
    if case.positioner is not None:
        positioner = case.positioner
        pose = ", ".join(f"{v:.6g}" for v in positioner.pose)
        keys = ("x", "y", "z", "roll", "pitch", "yaw")
        searched = ", ".join(keys[k] for k in positioner.searched)
        lines.append(
            f"  positioner {positioner.model}: {positioner.n_dof} "
            f"{'axis' if positioner.n_dof == 1 else 'axes'} "
            f"({', '.join(positioner.chain.joint_names)}), pose [{pose}] m, rad"
            + (f", searching {searched}" if searched else "")
        )
    if case.track is not None:
        track = case.track
        axis = ", ".join(f"{v:.4g}" for v in track.axis)
        lines.append(
            f"  track     along [{axis}], [{track.lower:g}, {track.upper:g}] m, "
            f"{track.velocity:g} m/s, {track.acceleration:g} m/s², {track.jerk:g} m/s³"
        )
    if case.downhand is not None:
        lines.append(
            f"  downhand  slope ≤ {np.degrees(case.downhand.slope):.4g}°, rotation ≤ "
            f"{np.degrees(case.downhand.rotation):.4g}°"
        )
    for seam in case.seams:
        weave = seam.task.weave
        if weave is not None:
            lines.append(
                f"  weave     {seam.name}: {weave.pattern} in the {weave.plane} plane, "
                f"{weave.amplitude * 1e3:g} mm to each side, {weave.frequency:g} Hz"
                + (f", dwell {weave.dwell:g} s" if weave.dwell else "")
            )
    return lines


def _tcp_line(case: Case) -> list[str]:
    """The case's ``tcp`` (xyz in m, rpy in rad), when it gives one."""
    if case.tcp_source != "case":
        return []
    T = case.robot.T_flange_tool
    xyz = ", ".join(f"{v:.6g}" for v in T[:3, 3])
    rpy = ", ".join(f"{v:.6g}" for v in rpy_from_matrix(T[:3, :3]))
    return [f"  tcp       xyz [{xyz}] m, rpy [{rpy}] rad in the flange (the case's)"]


def segment_corners(path: NominalPath) -> list[tuple[int, float]]:
    """The corners where one segment meets the next, as the user sees them.

    Returns
    -------
    list of (int, float)
        Per corner: the index of the segment that starts there, and the angle between
        the two legs in degrees (180 for no turn; the β of the paper's Eq. 9). The turns
        between the points of one ``points`` segment are left out: they sample a curve.
    """
    owner = path.segment_index
    junctions = path.corner_junctions
    junctions = junctions[owner[junctions] != owner[junctions + 1]]
    return [
        (int(owner[k + 1]), float(np.degrees(np.pi - path.junction_angles[k]))) for k in junctions
    ]


def robot_table(robot: Robot) -> Table:
    """A table of one robot's chain (origin and axis per joint) and joint limits."""
    from rich.table import Table

    from trackplan.frames import rpy_from_matrix

    table = Table(
        title=escape(f"{robot.name} ({robot.n_dof} joints)"),
        caption=escape(robot.source) or None,
    )
    headers = (
        "joint",
        "origin xyz m",
        "origin rpy °",
        "axis",
        "position °",
        "velocity rad/s",
        "acceleration rad/s²",
        "jerk rad/s³",
    )
    for header in headers:
        table.add_column(header, justify="right")

    def triple(values: np.ndarray) -> str:
        return " ".join(f"{v:.4g}" for v in np.where(np.abs(values) < 1e-12, 0.0, values))

    for i, joint in enumerate(robot.joint_names):
        origin = robot.origins[i]
        table.add_row(
            escape(joint),
            triple(origin[:3, 3]),
            triple(np.degrees(rpy_from_matrix(origin[:3, :3]))),
            triple(robot.axes[i]),
            f"[{np.degrees(robot.q_min[i]):g}, {np.degrees(robot.q_max[i]):g}]",
            f"{robot.v_max[i]:g}",
            f"{robot.a_max[i]:g}",
            f"{robot.j_max[i]:g}",
        )
    return table


def print_check(
    console: Console, source: str, n_samples: int, ts: float, report: CheckReport
) -> None:
    """What ``trackplan check`` found: margins per limit, tracking error, violations."""
    console.print(f"{escape(source)}: {_count(n_samples, 'sample')} at Ts = {ts:g} s")
    for kind, margin in report.joint_margins.items():
        cells = "  ".join(f"{m:+.3f}" for m in margin)
        console.print(f"  {kind:<13} margin per joint: {cells}")
    for kind, task_margin in report.task_margins.items():
        console.print(f"  {kind:<13} margin: {task_margin:+.3f}")
    console.print(f"  max tracking error {report.max_tracking_error * 1e3:.4f} mm")
    for violation in report.violations:
        console.print(f"  VIOLATION {escape(violation.message)}")
    count = _count(len(report.violations), "violation")
    console.print("feasible" if report.success else f"infeasible: {count}")


def print_plan(
    console: Console, result: PlanResult, out: Path, *, rated_speed: float | None = None
) -> None:
    """A few lines on what a plan achieved and where its files are: the verdict, the whole
    trajectory's figures, and for seams joined by moves the cycle time, sequence and each
    seam's; ``rated_speed`` (m/s, the case's) for :func:`rated_speed_text`."""
    violations = result.check.violations
    if result.feasible:
        console.print(f"{escape(result.case_name)}: {escape(result.message)}")
    elif violations:  # the list below says it all; the message would repeat its first line
        console.print(
            f"{escape(result.case_name)}: INFEASIBLE ({result.status.value}): "
            f"{_count(len(violations), 'violation')}"
        )
    else:
        console.print(
            f"{escape(result.case_name)}: INFEASIBLE ({result.status.value}): "
            f"{escape(result.message)}"
        )
    if result.trajectory.n_samples:
        console.print(
            f"  J = {result.objective:.4f}  duration = {result.duration:.3f} s  "
            f"{rated_speed_text(result, rated_speed)}  "
            f"min corner speed = {result.min_corner_speed:.4f} m/s  "
            f"max tracking error = {result.check.max_tracking_error * 1e3:.4f} mm  "
            f"branch {result.branch}"
        )
        cell = result.check.cell
        if cell is not None:
            console.print(
                f"  min clearance = {1e3 * cell.min_clearance:.1f} mm "
                f"({escape(cell.closest[0])} – {escape(cell.closest[1])} at "
                f"t = {cell.t_closest:.3f} s; required {1e3 * cell.clearance:.1f} mm)"
            )
        if result.energy is not None:
            energy = result.energy
            console.print(
                f"  copper loss = {energy.copper_loss:.4g} {escape(energy.copper_loss_unit)}  "
                f"mechanical energy = {energy.mechanical_energy:.4g} J  peak torque = "
                f"{100 * energy.peak_torque_ratio:.1f} % of the limit (joint "
                f"{energy.peak_torque_joint})"
            )
        for slow in result.slowdowns:
            console.print(
                f"  slow-down: s = {slow.s_start:.4f}..{slow.s_end:.4f} m at "
                f"{slow.speed:.4f} m/s ({100 * (1 - slow.speed / slow.rated_speed):.1f} % below "
                f"rated): {escape(slow.limit)}"
            )
        for key, value in result.references.items():
            console.print(f"  {key} = {value:.4f} s")
    if result.trajectory.n_samples and len(result.spans) > 1:  # seams joined by moves
        order = ", ".join(
            f"{escape(seam.name)} {'reversed' if seam.reversed else 'forward'}"
            for seam in result.seams
        )
        console.print(
            f"  cycle time = {result.duration:.3f} s (welding {result.seam_time:.3f} s, "
            f"approach, retract and air {result.air_time:.3f} s)  J = {result.objective:.4f}"
        )
        console.print(f"  sequence: {order}")
        console.print(f"  placement X = ({', '.join(f'{v:.4f}' for v in result.placement)})")
        for seam, own in zip(result.seams, result.seam_checks, strict=True):
            console.print(
                f"  {escape(seam.name)}: {seam.plan.duration:.3f} s, "
                f"max tracking error {1e3 * own.max_tracking_error:.4f} mm, "
                f"{len(seam.plan.slowdowns)} slow-downs"
            )
    for violation in violations[:8]:
        console.print(f"  VIOLATION {escape(violation.message)}")
    if len(violations) > 8:
        console.print(f"  ... and {len(violations) - 8} more in result.json")
    console.print(f"  results in {escape(str(out))}/")


def rated_speed_text(result: PlanResult, rated_speed: float | None = None) -> str:
    """How much of the path runs at the rated speed (``docs/results.md``): the share of
    its length, or, when that share would read 0.0 %, the top tool speed and its share of
    the rated speed (``rated_speed``, m/s): a curve cruising at 99.9 % of the rated speed,
    or the paper's law with its sampling noise, would read 0.0 % of the path."""
    share = f"{100 * result.rated_speed_fraction:.1f}"
    if share != "0.0":
        return f"rated speed on {share} % of the path"
    top = float(np.max(result.trajectory.speed, initial=0.0))
    if rated_speed is None or rated_speed <= 0:
        return f"top speed = {top:.4f} m/s"
    return f"top speed = {top:.4f} m/s ({100 * top / rated_speed:.1f} % of the rated speed)"


def print_search(  # type: ignore[no-untyped-def]
    console: Console, result, out: Path, *, rated_speed: float | None = None
) -> None:
    """The search summary, then the final plan's summary (``rated_speed``: the case's,
    m/s)."""
    initial = result.initial
    before = (
        f"J = {initial.objective:.4f}"
        if initial.feasible
        else f"infeasible ({initial.status.value})"
    )
    console.print(
        f"{escape(result.method)} (seed {result.seed}): {result.evaluations} evaluations in "
        f"{_count(result.generations, 'generation')} over {_count(result.runs, 'run')}, "
        f"{result.wall_time_s:.2f} s, "
        f"last run stopped: {escape(result.stop_reason)}"
    )
    console.print(f"  before (centre of the bounds, X = {_vector(initial.placement)}): {before}")
    after = escape(result.message)  # on failure: which seam, how close; planned below
    console.print(f"  after  (X = {_vector(result.X)}): {after}")
    from trackplan.search.space import bounds_note

    note = bounds_note(result.on_bounds)
    if note:
        console.print(f"  note: {escape(note)}")
    print_plan(console, result.final, out, rated_speed=rated_speed)


def _vector(values: np.ndarray) -> str:
    return "(" + ", ".join(f"{v:.4f}" for v in values) + ")"


def _count(n: int, noun: str) -> str:
    return f"{n} {noun}" if n == 1 else f"{n} {noun}s"
