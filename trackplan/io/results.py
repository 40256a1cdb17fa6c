"""Run outputs of every plan (trajectory.csv with its ``segment`` column, result.json) and
reading a trajectory back."""

from __future__ import annotations

import json
import math
import re
import warnings
from dataclasses import replace
from pathlib import Path
from typing import Any

import numpy as np

from trackplan.case import PLACEMENT_KEYS, Case
from trackplan.errors import CaseError
from trackplan.frames import rpy_from_matrix
from trackplan.io.csv_table import format_table, write_csv_table
from trackplan.io.run_folder import HASH_KEY, file_sha256
from trackplan.io.sizes import MAX_TRAJECTORY_BYTES, max_samples
from trackplan.jointpath import JointPath
from trackplan.planning.result import SEAM, CheckReport, PlanResult, Trajectory
from trackplan.robots.families import ik_family
from trackplan.robots.machine import machine_of
from trackplan.run_files import RESULT_FILE, TRAJECTORY_FILE
from trackplan.timing.protocol import SlowDown


def trajectory_header(n_dof: int) -> list[str]:
    """Column names ``t,q1..qn,qd1..qdn,qdd1..qddn,qddd1..qdddn,x,y,z,speed,spin``."""
    columns = ["t"]
    for prefix in ("q", "qd", "qdd", "qddd"):
        columns += [f"{prefix}{i + 1}" for i in range(n_dof)]
    return [*columns, "x", "y", "z", "speed", "spin"]


def slowdown_record(slowdown: SlowDown) -> dict[str, Any]:
    """One ``slowdowns`` entry of result.json: where (m), how fast (m/s) and why."""
    return {
        "s_start": slowdown.s_start,
        "s_end": slowdown.s_end,
        "speed": slowdown.speed,
        "rated_speed": slowdown.rated_speed,
        "shortfall": 1.0 - slowdown.speed / slowdown.rated_speed,
        "limit": slowdown.limit,
    }


def trajectory_table(trajectory: Trajectory) -> np.ndarray:
    """The columns of :func:`trajectory_header` as one table, shape (N, 4 n + 6)."""
    n_dof = trajectory.q.shape[1] if trajectory.q.ndim == 2 else 0
    if not trajectory.n_samples:
        return np.zeros((0, 4 * n_dof + 6))
    spin = (
        trajectory.spin
        if len(trajectory.spin) == trajectory.n_samples
        else np.zeros(trajectory.n_samples)
    )
    return np.column_stack(
        [
            trajectory.t,
            trajectory.q,
            trajectory.qd,
            trajectory.qdd,
            trajectory.qddd,
            trajectory.tool_position,
            trajectory.speed,
            spin,
        ]
    )


def write_trajectory_csv(trajectory: Trajectory, file: Path) -> None:
    """Write one row per sample, each value the shortest text that reads back exactly.

    So the file re-checks identically (see :mod:`trackplan.io.csv_table`).
    """
    n_dof = trajectory.q.shape[1] if trajectory.q.ndim == 2 else 0
    write_csv_table(file, trajectory_table(trajectory), trajectory_header(n_dof))


def read_trajectory_csv(file: Path, n_dof: int | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Read the time and joint columns of a ``trajectory.csv``, whoever wrote it.

    Columns are found by their header names, in any order: ``t`` and ``q1..qn``; other
    columns are ignored (the text column ``segment`` of a cycle too).

    Parameters
    ----------
    file
        The CSV file (a header row, then one row per sample).
    n_dof
        Expected number of joints, or None to take it from the header.

    Returns
    -------
    tuple of numpy.ndarray
        ``t`` (N,), s, and ``q`` (N, n), rad.

    Raises
    ------
    CaseError
        When the file is missing or unreadable, a column is missing or named twice, a
        value is not a finite number, or there are fewer than 2 samples.
    """
    file = Path(file)
    try:
        size = file.stat().st_size
        with file.open(encoding="utf-8-sig") as handle:  # a byte order mark is skipped
            header = [name.strip() for name in handle.readline().strip().split(",")]
    except (OSError, UnicodeDecodeError) as error:
        raise _unreadable(error, file) from None
    if size > MAX_TRAJECTORY_BYTES:
        raise CaseError(
            f"the file has {size / 2**20:.0f} MiB, more than the {MAX_TRAJECTORY_BYTES // 2**20} "
            "MiB of the longest trajectory a plan may have: give a trajectory of one run",
            file=str(file),
        )
    columns = [name for name in header if name != "segment"]  # several seams
    twice = sorted({name for name in columns if columns.count(name) > 1})
    if twice:
        raise CaseError(f"column {twice[0]!r} appears twice", file=str(file), key="header")
    joints = [name for name in columns if name[:1] == "q" and name[1:].isdigit()]
    n = len(joints) if n_dof is None else n_dof
    wanted = ["t", *(f"q{i + 1}" for i in range(n))]
    missing = [name for name in wanted if name not in columns]
    if missing or (n_dof is not None and len(joints) != n_dof) or n == 0:
        found = ",".join(columns)[:120]
        raise CaseError(
            f"expected columns t,q1..q{n} (one per joint), missing {','.join(missing) or 'none'}"
            f", found {len(joints)} joint columns in header {found!r}",
            file=str(file),
            key="header",
        )
    try:  # only the columns wanted are converted: 3 times faster on a 30-column file
        with warnings.catch_warnings():  # "input contained no data": refused below
            warnings.simplefilter("ignore", UserWarning)
            data = np.loadtxt(
                file, delimiter=",", skiprows=1, ndmin=2, usecols=[header.index(c) for c in wanted]
            )
    except (OSError, UnicodeDecodeError) as error:
        raise _unreadable(error, file) from None
    except ValueError as error:
        where = _first_bad_line(file, header, wanted)
        if where is None:  # not expected: numpy's own words, one line
            where = "not a numeric CSV table: " + str(error).splitlines()[0][:200]
        raise CaseError(where, file=str(file)) from None
    if data.shape[0] < 2:
        raise CaseError("the trajectory needs at least 2 samples", file=str(file))
    if data.shape[0] > max_samples(n):
        raise CaseError(
            f"{data.shape[0]} samples, more than the {max_samples(n)} a plan of a {n}-joint "
            "robot may have: give a trajectory of one run",
            file=str(file),
        )
    if not np.all(np.isfinite(data)):
        row = int(np.argwhere(~np.isfinite(data))[0, 0]) + 2
        raise CaseError(f"non-finite number on line {row}", file=str(file))
    return data[:, 0], data[:, 1:]


_VALUE = re.compile(
    r"[+-]?(?:(?:[0-9]+(?:\.[0-9]*)?|\.[0-9]+)(?:[eE][+-]?[0-9]+)?|nan|inf(?:inity)?)",
    re.ASCII | re.IGNORECASE,
)
"""A value ``numpy.loadtxt`` reads as a float (a non-finite one is refused afterwards)."""


def _first_bad_line(file: Path, header: list[str], wanted: list[str]) -> str | None:
    """Where ``numpy.loadtxt`` failed, as ``line N, column q1: …`` (file lines from 1).

    Only called once loadtxt has failed: numpy's message counts rows without blank and
    comment lines from 0 and its columns from 1, so the line is found again here.
    """
    columns = {name: header.index(name) for name in wanted}
    with file.open(encoding="utf-8-sig") as handle:
        handle.readline()  # the header
        for number, line in enumerate(handle, start=2):
            row = line.split("#", 1)[0].strip()
            if not row:
                continue
            fields = row.split(",")
            problem = _field_problem(fields, columns)
            if problem is None:
                continue
            for mark, text in ((";", "';'"), ("\t", "a tab")):
                if mark in row:
                    return f"line {number}: values separated by {text}, expected commas"
            return f"line {number}{problem}"
    return None


def _field_problem(fields: list[str], columns: dict[str, int]) -> str | None:
    """What is wrong with a row's wanted fields (``, column q1: …``), or None."""
    for name, column in columns.items():
        if column >= len(fields):
            return f": {len(fields)} values, expected one in column {column + 1} ({name})"
        value = fields[column].strip()
        if not _VALUE.fullmatch(value):
            return f", column {name}: expected a number, got {value[:60]!r}"
    return None


def _unreadable(error: OSError | UnicodeDecodeError, file: Path) -> CaseError:
    if isinstance(error, UnicodeDecodeError):
        return CaseError("cannot read trajectory: not UTF-8 text", file=str(file))
    reason = getattr(error, "strerror", None) or type(error).__name__
    return CaseError(f"cannot read trajectory: {reason}", file=str(file))


def _cell_summary(check: CheckReport) -> dict:
    """``min_clearance`` block of ``result.json`` when the case has a cell."""
    cell = check.cell
    if cell is None:
        return {}
    return {
        "min_clearance": {
            "distance": float(cell.min_clearance),
            "robot_body": cell.closest[0],
            "other_body": cell.closest[1],
            "t": float(cell.t_closest),
            "clearance": float(cell.clearance),
        }
    }


def _energy_summary(result: PlanResult) -> dict:
    """Energy figures of ``result.json`` (None without dynamics or without a trajectory)."""
    energy = result.energy
    return {
        "mechanical_energy": None if energy is None else energy.mechanical_energy,
        "copper_loss": None if energy is None else energy.copper_loss,
        "copper_loss_unit": None if energy is None else energy.copper_loss_unit,
        "peak_torque_ratio": None if energy is None else energy.peak_torque_ratio,
    }


def result_summary(result: PlanResult, joint_names: tuple[str, ...]) -> dict:
    """The ``result.json`` content of a plan (plain JSON types)."""
    check = result.check
    return {
        "case": result.case_name,
        "placement": dict(zip(PLACEMENT_KEYS, map(float, result.placement), strict=True)),
        "feasible": bool(result.feasible),
        "status": result.status.value,
        "message": result.message,
        "objective": float(result.objective),
        "duration": float(result.duration),
        "path_length": float(result.path_length),
        "max_tracking_error": float(check.max_tracking_error),
        "max_orientation_error": float(check.max_orientation_error),
        "tool": result.joint_path.tool.spec.describe(),
        "spin": result.joint_path.tool.spin.as_dict(),
        "redundancy": redundancy_record(result.joint_path),
        "rated_speed_fraction": float(result.rated_speed_fraction),
        "min_corner_speed": float(result.min_corner_speed),
        **_energy_summary(result),
        "weave": None if result.weave is None else result.weave.as_dict(),
        "margins": {
            **{
                kind: dict(zip(joint_names, map(float, values), strict=True))
                for kind, values in check.joint_margins.items()
            },
            **{kind: float(value) for kind, value in check.task_margins.items()},
        },
        "binding": {kind: {"joint": j, "t": t} for kind, (j, t) in check.binding.items()},
        **_cell_summary(check),
        **({} if check.downhand is None else {"downhand": check.downhand.as_dict()}),
        "violations": [
            {
                "limit": v.limit,
                "joint": v.joint,
                "t_first": v.t_first,
                "t_last": v.t_last,
                "worst": v.worst,
                "bound": v.bound,
                "message": v.message,
            }
            for v in check.violations
        ],
        "slowdowns": [slowdown_record(d) for d in result.slowdowns],
        "timing": result.timing,
        "branch": int(result.branch),
        "joint_names": list(joint_names),
        "sample_time": float(result.trajectory.sample_time),
        "n_samples": int(result.trajectory.n_samples),
        **{key: float(value) for key, value in result.references.items()},
    }


NULL_REASONS_KEY = "null_reasons"
"""Key of ``result.json`` listing why a value is ``null``: ``{key path: reason}``."""


def strict_json(value: Any, path: str = "") -> tuple[Any, dict[str, str]]:
    """A copy of plain JSON data with every non-finite float replaced by None.

    JSON has no NaN or infinity (RFC 8259): ``json.dumps`` would write the bare words
    ``NaN``/``Infinity``, which strict readers refuse.

    Returns
    -------
    tuple
        The cleaned data, and ``{key path: reason}`` of each replaced value.
    """
    if isinstance(value, float | np.floating) and not math.isfinite(value):
        return None, {path or "$": f"not a finite number ({float(value)!r})"}
    if isinstance(value, dict):
        cleaned, reasons = {}, {}
        for key, item in value.items():
            cleaned[key], found = strict_json(item, f"{path}.{key}" if path else str(key))
            reasons.update(found)
        return cleaned, reasons
    if isinstance(value, list | tuple):
        items, reasons = [], {}
        for i, item in enumerate(value):
            cleaned_item, found = strict_json(item, f"{path}[{i}]")
            items.append(cleaned_item)
            reasons.update(found)
        return items, reasons
    return value, {}


def write_result_json(summary: dict, file: Path) -> None:
    """Write a summary dict as indented, strict JSON.

    A non-finite number (an objective with no trajectory, a margin of a limit that does
    not apply) is written as ``null``, and its key path is listed with the reason under
    :data:`NULL_REASONS_KEY`.
    """
    cleaned, reasons = strict_json(summary)
    if reasons:
        cleaned[NULL_REASONS_KEY] = reasons
    Path(file).write_text(json.dumps(cleaned, indent=2, allow_nan=False) + "\n")


def plan_summary(result: PlanResult, case: Case) -> dict:
    """The ``result.json`` content of a plan (plain JSON types; ``docs/files.md``): the
    plan's figures (:func:`result_summary`), then its seams, moves and sequence
    (:func:`seams_summary`)."""
    return {
        **result_summary(result, case.machine.joint_names),
        "axes": axes_summary(case),
        "positioner_pose": None
        if case.positioner is None
        else [float(v) for v in case.positioner.pose],
        "case_file": case_file(case),
        "robot_file": robot_file(case),
        "tcp": tcp_summary(case),
        **seams_summary(result, case),
    }


def axes_summary(case: Case) -> list[dict]:
    """``result.json``'s ``axes``: every joint of the trajectory in order (the robot's, the
    track, the positioner's), each with its ``name``, ``kind`` (``robot``, ``track`` or
    ``positioner``) and ``unit`` (``rad`` or ``m``)."""
    machine = machine_of(case.machine)
    return [
        {"name": name, "kind": kind, "unit": unit}
        for name, kind, unit in zip(machine.joint_names, machine.kinds, machine.units, strict=True)
    ]


def recorded_positioner(case: Case, summary: dict, where: str) -> Case:
    """The case with its positioner standing where a run's ``result.json`` (``summary``)
    records it (``positioner_pose``, the pose the run planned at, searched or given); the
    case itself without a positioner.

    Raises
    ------
    CaseError
        When the case has a positioner and the run records no pose of six finite numbers.
    """
    if case.positioner is None:
        return case
    recorded = summary.get("positioner_pose")
    try:
        pose = np.asarray(recorded, dtype=float).reshape(-1)
    except (TypeError, ValueError):
        pose = np.zeros(0)
    if pose.shape != (6,) or not np.all(np.isfinite(pose)):
        raise CaseError(
            f"the case has a positioner, but {RESULT_FILE} records no positioner_pose "
            f"[x, y, z, roll, pitch, yaw] (got {recorded!r}): plan the case again",
            file=where,
        )
    return replace(case, positioner=case.positioner.at(pose))


def tcp_summary(case: Case) -> dict:
    """``result.json``'s ``tcp``: the TCP used in the flange (``xyz``, m; ``rpy``, rad, as a
    robot file's ``tool``), where it comes from (``source``: ``case``, ``robot`` or
    ``none``) and, when the case's ``tcp`` replaced a robot's own tool, that tool
    (``replaced``, else None)."""

    def pose(T: np.ndarray) -> dict:
        return {
            "xyz": [float(v) for v in T[:3, 3]],
            "rpy": [float(v) for v in rpy_from_matrix(T[:3, :3])],
        }

    own = case.robot_tool
    replaced = own is not None and not np.allclose(own, np.eye(4))
    return {
        **pose(case.robot.T_flange_tool),
        "source": case.tcp_source,
        "replaced": pose(own) if replaced and own is not None else None,
    }


def case_file(case: Case) -> str | None:
    """The absolute path of the case file a case was read from, or None for a case built in
    Python (``result.json``'s ``case_file``: what :func:`trackplan.programs.replay.replay_run`
    re-plans a run from)."""
    if case.source is None:
        return None
    return str(Path(case.source).resolve())


def robot_file(case: Case) -> str | None:
    """The absolute path of the robot file the case file names (``robot: my-arm.yaml``),
    or None for a built-in robot, a case built in Python, or a case file that no longer
    reads (``result.json``'s ``robot_file``)."""
    if case.source is None:
        return None
    import yaml

    from trackplan.io.robot_file import is_robot_file

    file = Path(case.source)
    try:
        data = yaml.safe_load(file.read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError, yaml.YAMLError):
        return None
    name = data.get("robot") if isinstance(data, dict) else None
    if not isinstance(name, str) or not is_robot_file(name):
        return None
    return str((file.parent / name).resolve())


def write_plan_files(
    result: PlanResult, case: Case, out_dir: Path, extra: dict | None = None
) -> dict:
    """Write ``trajectory.csv`` and ``result.json`` of a plan into ``out_dir``.

    trajectory.csv has the ``segment`` column when the case names its seams (``paths:``)
    or the plan has more than one span (moves): the table of a single path stays the
    all-numeric one that scripts read with ``numpy.loadtxt``.

    Returns
    -------
    dict
        The summary written to ``result.json`` (``extra`` merged in).
    """
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    labels = bool(case.paths) or len(result.spans) > 1
    write_plan_csv(result, out_dir / TRAJECTORY_FILE, labels=labels)
    summary = {
        **plan_summary(result, case),
        **(extra or {}),
        HASH_KEY: file_sha256(out_dir / TRAJECTORY_FILE),
    }
    write_result_json(summary, out_dir / RESULT_FILE)
    return summary


SEGMENT_COLUMN = "segment"
"""Last column of trajectory.csv: the seam's name, or approach/retract/air."""


def write_plan_csv(result: PlanResult, file: Path, *, labels: bool = True) -> None:
    """Write one row per sample: the trajectory's columns, then, with ``labels``,
    ``segment`` (a plan made without labels has the case name on every sample)."""
    if not labels:
        write_trajectory_csv(result.trajectory, file)
        return
    lines = format_table(trajectory_table(result.trajectory)).decode("ascii").splitlines()
    labels_ = result.segment
    if len(labels_) != len(lines):
        labels_ = np.full(len(lines), result.case_name, dtype=object)
    rows = [f"{line},{label}" for line, label in zip(lines, labels_, strict=True)]
    n_dof = result.trajectory.q.shape[1]
    header = ",".join([*trajectory_header(n_dof), SEGMENT_COLUMN])
    Path(file).write_text("\n".join([header, *rows]) + "\n", encoding="utf-8")


def seams_summary(result: PlanResult, case: Case) -> dict:
    """The ``result.json`` keys of the seams, the moves and the sequence of a plan (plain
    JSON types; ``docs/files.md``)."""
    joint_names = case.machine.joint_names
    sample_time = result.trajectory.sample_time
    seams = []
    for seam, own in zip(result.seams, result.seam_checks, strict=True):
        span = next(p for p in result.spans if p.kind == SEAM and p.seam == seam.index)
        plan = seam.plan
        seams.append(
            {
                "name": seam.name,
                "reversed": seam.reversed,
                "t_start": span.first * sample_time,
                "t_end": span.last * sample_time,
                "duration": float(plan.duration),
                "objective": float(plan.objective),
                "path_length": float(plan.path_length),
                "rated_speed": float(case.seams[seam.index].task.rated_speed),
                "rated_speed_fraction": float(plan.rated_speed_fraction),
                "min_corner_speed": float(plan.min_corner_speed),
                "max_tracking_error": float(own.max_tracking_error),
                "max_orientation_error": float(own.max_orientation_error),
                "branch": int(plan.branch),
                "spin": plan.joint_path.tool.spin.as_dict(),
                "redundancy": redundancy_record(plan.joint_path),
                "feasible": bool(own.success),
                "slowdowns": [slowdown_record(d) for d in plan.slowdowns],
                "weave": None if plan.weave is None else plan.weave.as_dict(),
            }
        )
    moves = [
        {
            "kind": span.kind,
            "t_start": span.first * sample_time,
            "t_end": span.last * sample_time,
            "duration": (span.last - span.first) * sample_time,
            "via": None if span.via is None else list(map(float, span.via)),
        }
        for span in result.spans
        if span.kind != SEAM
    ]
    sequencing = case.sequencing
    return {
        "cycle_time": float(result.duration),
        "seam_time": float(result.seam_time),
        "air_time": float(result.air_time),
        "approach": float(sequencing.approach),
        "approach_deviation": float(result.approach_deviation),
        "sequence_mode": sequencing.sequence,
        "sequence": [
            {"seam": case.seams[v.seam].name, "reversed": bool(v.reversed)}
            for v in result.sequence.visits
        ],
        "sequence_exact": bool(result.sequence.exact),
        "home": None
        if sequencing.home is None
        else dict(zip(joint_names, map(float, sequencing.home), strict=True)),
        "seams": seams,
        "moves": moves,
        "unplanned": {name: plan.message for name, plan in result.unplanned.items()},
    }


def read_segments(file: Path) -> np.ndarray | None:
    """The ``segment`` column of a trajectory.csv, shape (N,), str, or None when the file
    has none (a trajectory written elsewhere: every sample on the case's one seam)."""
    lines = Path(file).read_text(encoding="utf-8").splitlines()
    header = lines[0].split(",") if lines else []
    if SEGMENT_COLUMN not in header:
        return None
    column = header.index(SEGMENT_COLUMN)
    return np.array([line.split(",")[column] for line in lines[1:] if line.strip()])


def redundancy_record(joint_path: JointPath) -> dict[str, object] | None:
    """A redundant arm's free parameter along a seam for result.json: ``parameter`` (its
    name), then ``value`` (a constant, rad) or ``knots``, ``coefficients``, ``degree`` (a
    B-spline over the seam's arc length, m and rad); None for other arms."""
    if joint_path.redundancy is None:
        return None
    parameter = ik_family(joint_path.arm).redundancy
    name = "free parameter" if parameter is None else parameter.name
    return {"parameter": name, **joint_path.redundancy.as_dict()}
