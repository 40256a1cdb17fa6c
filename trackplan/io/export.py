"""Export a run's trajectory for other tools: plain CSV, JSON, or a ROS 2 JointTrajectory.

The source is a run directory (or its ``trajectory.csv``, header
``t,q1..qn,qd1..qdn,qdd1..qddn,qddd1..qdddn,x,y,z,speed,spin``) or a
:class:`~trackplan.planning.result.Trajectory` in memory. Joint names come from
``result.json`` next to the CSV (key ``joint_names``) when it is there, else ``q1..qn``.

Formats and default files (written next to ``trajectory.csv``):

- ``csv`` → ``trajectory.export.csv``: ``t,<joint names>``, one row per sample (s, rad);
  the header is quoted as the ``csv`` module quotes, and a name that a spreadsheet would
  take for a formula gets a leading ``'`` (:func:`neutralised`).
- ``json`` → ``trajectory.json``: joint names, units and every column as arrays.
- ``ros`` → ``trajectory.ros.yaml``: a ``trajectory_msgs/msg/JointTrajectory`` as YAML.
"""

from __future__ import annotations

import json
import os
from collections.abc import Sequence
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np
import yaml

from trackplan.errors import CaseError
from trackplan.io.csv_cells import neutralised
from trackplan.io.csv_table import write_csv_table
from trackplan.io.results import trajectory_header
from trackplan.io.run_folder import OWNED_FILES, verified_trajectory, write_atomically
from trackplan.planning.result import Trajectory
from trackplan.run_files import RESULT_FILE, TRAJECTORY_FILE

EXPORT_FORMATS = ("csv", "json", "ros")
EXPORT_FILES = {
    "csv": "trajectory.export.csv",
    "json": "trajectory.json",
    "ros": "trajectory.ros.yaml",
}
UNITS = {
    "t": "s",
    "positions": "rad",
    "velocities": "rad/s",
    "accelerations": "rad/s^2",
    "jerks": "rad/s^3",
    "tool_position": "m",
    "speed": "m/s",
}


@dataclass(frozen=True, eq=False)
class TrajectoryTable:
    """The columns of a ``trajectory.csv`` with the joint names.

    Attributes
    ----------
    joint_names
        One name per joint, length n.
    t
        Sample times, shape (N,), s, increasing.
    q, qd, qdd, qddd
        Joint positions and their backward differences, shape (N, n): rad, rad/s, rad/s², rad/s³.
    tool_position
        Tool point in the base frame, shape (N, 3), m.
    speed
        Cartesian tool speed, shape (N,), m/s.
    """

    joint_names: tuple[str, ...]
    t: np.ndarray
    q: np.ndarray
    qd: np.ndarray
    qdd: np.ndarray
    qddd: np.ndarray
    tool_position: np.ndarray
    speed: np.ndarray

    @classmethod
    def from_trajectory(
        cls, trajectory: Trajectory, joint_names: Sequence[str] | None = None
    ) -> TrajectoryTable:
        """The table of an in-memory trajectory (joint names ``q1..qn`` unless given)."""
        n_dof = trajectory.q.shape[1]
        return cls(
            joint_names=_checked_names(joint_names, n_dof, "joint_names", None),
            t=trajectory.t,
            q=trajectory.q,
            qd=trajectory.qd,
            qdd=trajectory.qdd,
            qddd=trajectory.qddd,
            tool_position=trajectory.tool_position,
            speed=trajectory.speed,
        )


def _checked_names(
    names: Sequence[str] | None, n_dof: int, key: str, file: str | None
) -> tuple[str, ...]:
    """``names`` as a tuple of n distinct non-empty strings, or ``q1..qn`` when None."""
    if names is None:
        return tuple(f"q{i + 1}" for i in range(n_dof))
    if (
        isinstance(names, str)
        or len(names) != n_dof
        or not all(isinstance(name, str) and name for name in names)
        or len(set(names)) != n_dof
    ):
        raise CaseError(
            f"must be a list of {n_dof} distinct joint names, got {names!r}", file=file, key=key
        )
    return tuple(names)


def _joint_names_next_to(csv_file: Path, n_dof: int) -> tuple[str, ...]:
    """Joint names from ``result.json`` beside the CSV (key ``joint_names``), else ``q1..qn``."""
    result_file = csv_file.parent / RESULT_FILE
    if not result_file.is_file():
        return _checked_names(None, n_dof, "joint_names", None)
    try:
        summary = json.loads(result_file.read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError, json.JSONDecodeError) as error:
        raise CaseError(f"cannot read the run summary: {error}", file=str(result_file)) from None
    names = summary.get("joint_names") if isinstance(summary, dict) else None
    return _checked_names(names, n_dof, "joint_names", str(result_file))


def _trajectory_file(source: Path) -> Path:
    """The CSV file itself, or ``trajectory.csv`` inside a run directory."""
    if source.is_dir() or source.suffix.lower() != ".csv":
        return source / TRAJECTORY_FILE
    return source


def read_trajectory_table(file: Path) -> TrajectoryTable:
    """Read a run's ``trajectory.csv`` completely (every column), with its joint names.

    Parameters
    ----------
    file
        The CSV file, or the run directory holding ``trajectory.csv``.

    Returns
    -------
    TrajectoryTable
        Joint names from ``result.json`` beside the file when present.

    Raises
    ------
    CaseError
        Naming the file and what is wrong: missing, unreadable, a header that is not
        ``t,q1..qn,qd1..qdn,qdd1..qddn,qddd1..qdddn,x,y,z,speed,spin`` (and ``segment``
        for several seams), a non-numeric or short
        row, a non-finite value, no sample, or times that do not increase.
    """
    file = _trajectory_file(Path(file))
    where = str(file)
    try:
        lines = file.read_text(encoding="utf-8-sig").splitlines()  # a byte order mark skipped
    except FileNotFoundError:
        raise CaseError("no trajectory file: plan or optimize a case first", file=where) from None
    except (OSError, UnicodeDecodeError) as error:
        raise CaseError(f"cannot read the trajectory: {error}", file=where) from None
    header = lines[0].strip().split(",") if lines else []
    body = [line for line in lines[1:] if line.strip()]
    if header[-1:] == ["segment"]:  # a cycle of several seams: the labels are not exported
        header = header[:-1]
        body = [line.rsplit(",", 1)[0] for line in body]
    if not body:
        raise CaseError("the trajectory has no sample", file=where)
    try:
        rows = np.loadtxt(body, delimiter=",", ndmin=2)
    except ValueError as error:
        raise CaseError(f"malformed row: {error}", file=where) from None
    n_dof, rest = divmod(len(header) - 6, 4)
    if n_dof < 1 or rest or header != trajectory_header(n_dof):
        raise CaseError(
            "header must be t,q1..qn,qd1..qdn,qdd1..qddn,qddd1..qdddn,x,y,z,speed,spin, "
            f"got {','.join(header)!r}",
            file=where,
            key="header",
        )
    if rows.shape[1] != len(header):
        raise CaseError(f"rows have {rows.shape[1]} columns, the header {len(header)}", file=where)
    bad = np.argwhere(~np.isfinite(rows))
    if bad.size:
        line, column = int(bad[0, 0]) + 2, header[int(bad[0, 1])]
        raise CaseError(f"non-finite {column} on line {line}", file=where)
    t = rows[:, 0]
    if t[0] < 0 or np.any(np.diff(t) <= 0):
        raise CaseError(
            "times must start at or after 0 s and increase from row to row", file=where, key="t"
        )
    q, qd, qdd, qddd = (rows[:, 1 + k * n_dof : 1 + (k + 1) * n_dof] for k in range(4))
    return TrajectoryTable(
        joint_names=_joint_names_next_to(file, n_dof),
        t=t,
        q=q,
        qd=qd,
        qdd=qdd,
        qddd=qddd,
        tool_position=rows[:, -5:-2],
        speed=rows[:, -2],
    )


def _duration_msg(t: float) -> dict[str, int]:
    """A ``builtin_interfaces/Duration`` of t seconds: whole seconds and nanoseconds."""
    sec, nanosec = divmod(round(t * 1e9), 1_000_000_000)
    return {"sec": sec, "nanosec": nanosec}


def joint_trajectory_msg(table: TrajectoryTable, frame_id: str = "") -> dict:
    """A ROS 2 ``trajectory_msgs/msg/JointTrajectory`` as plain data.

    Parameters
    ----------
    table
        The trajectory.
    frame_id
        ``header.frame_id``; empty by default, as joint-space trajectories carry none.

    Returns
    -------
    dict
        ``{header: {stamp: {sec, nanosec}, frame_id}, joint_names, points: [{positions,
        velocities, accelerations, effort: [], time_from_start: {sec, nanosec}}]}``; a zero
        stamp means "start when received".
    """
    return {
        "header": {"stamp": {"sec": 0, "nanosec": 0}, "frame_id": frame_id},
        "joint_names": list(table.joint_names),
        "points": [
            {
                "positions": q,
                "velocities": qd,
                "accelerations": qdd,
                "effort": [],
                "time_from_start": _duration_msg(t),
            }
            for t, q, qd, qdd in zip(
                table.t.tolist(),
                table.q.tolist(),
                table.qd.tolist(),
                table.qdd.tolist(),
                strict=True,
            )
        ],
    }


def _refuse_run_file(target: Path, csv_file: Path) -> None:
    """Refuse an output that is the source ``trajectory.csv`` or another file of its run.

    Paths are compared resolved (``..``, symbolic links), and by inode when both exist
    (hard links).
    """
    run_files = {csv_file, *(csv_file.parent / name for name in OWNED_FILES)}
    resolved = target.resolve()
    for own in run_files:
        same = resolved == own.resolve()
        if not same and target.exists() and own.exists():
            same = os.path.samefile(target, own)
        if same:
            raise CaseError(
                f"{str(target)!r} is the run's own {own.name}: exporting there would replace "
                "it; give another file",
                key="output",
            )


def _write_csv(table: TrajectoryTable, output: Path) -> None:
    header = ["t", *(neutralised(name) for name in table.joint_names)]
    write_csv_table(output, np.column_stack([table.t, table.q]), header)


def _write_json(table: TrajectoryTable, output: Path) -> None:
    content = {
        "joint_names": list(table.joint_names),
        "units": UNITS,
        "t": table.t.tolist(),
        "positions": table.q.tolist(),
        "velocities": table.qd.tolist(),
        "accelerations": table.qdd.tolist(),
        "jerks": table.qddd.tolist(),
        "tool_position": table.tool_position.tolist(),
        "speed": table.speed.tolist(),
    }
    # one key per line keeps the file readable without a line per number
    body = ",\n".join(f"  {json.dumps(key)}: {json.dumps(value)}" for key, value in content.items())
    output.write_text("{\n" + body + "\n}\n", encoding="utf-8")


def _write_ros(table: TrajectoryTable, output: Path, frame_id: str) -> None:
    dumper = getattr(yaml, "CSafeDumper", yaml.SafeDumper)
    text = yaml.dump(
        joint_trajectory_msg(table, frame_id),
        Dumper=dumper,
        sort_keys=False,
        default_flow_style=None,
        width=120,
    )
    output.write_text(text, encoding="utf-8")


def export_trajectory(
    source: Path | str | Trajectory,
    fmt: str,
    output: Path | str | None = None,
    *,
    joint_names: Sequence[str] | None = None,
    frame_id: str = "",
) -> Path:
    """Export a trajectory as CSV, JSON or a ROS 2 JointTrajectory (YAML).

    Parameters
    ----------
    source
        A run directory, its ``trajectory.csv``, or a trajectory in memory.
    fmt
        ``csv``, ``json`` or ``ros``.
    output
        The file to write; by default ``trajectory.export.csv``, ``trajectory.json`` or
        ``trajectory.ros.yaml`` next to ``trajectory.csv`` (an existing directory receives
        the default name). Required when ``source`` is a :class:`Trajectory`.
    joint_names
        Overrides the joint names (else ``result.json``'s ``joint_names``, else ``q1..qn``).
    frame_id
        ``header.frame_id`` of the ROS message.

    Returns
    -------
    pathlib.Path
        The file written.

    Raises
    ------
    CaseError
        For an unknown format, a missing or malformed ``trajectory.csv`` or ``result.json``,
        wrong joint names, or no ``output`` for an in-memory trajectory.
    """
    fmt = fmt.lower()
    if fmt not in EXPORT_FORMATS:
        raise CaseError(
            f"unknown export format {fmt!r}: use one of {', '.join(EXPORT_FORMATS)}", key="format"
        )
    if isinstance(source, Trajectory):
        if output is None:
            raise CaseError(
                "an output file is needed to export a trajectory held in memory", key="output"
            )
        if source.n_samples == 0:
            raise CaseError("the trajectory has no sample", key="trajectory")
        table = TrajectoryTable.from_trajectory(source, joint_names)
        target = Path(output)
    else:
        source = Path(source)
        csv_file = verified_trajectory(source) if source.is_dir() else _trajectory_file(source)
        table = read_trajectory_table(csv_file)
        if joint_names is not None:
            names = _checked_names(joint_names, table.q.shape[1], "joint_names", None)
            table = replace(table, joint_names=names)
        target = csv_file.parent / EXPORT_FILES[fmt] if output is None else Path(output)
    if target.is_dir():
        target = target / EXPORT_FILES[fmt]
    if target.exists() and not target.is_file():  # a device or a FIFO: never replaced
        raise CaseError(f"{str(target)!r} is not a regular file; give a file name", key="output")
    if not isinstance(source, Trajectory):
        _refuse_run_file(target, csv_file)
    target.parent.mkdir(parents=True, exist_ok=True)
    if fmt == "csv":
        write_atomically(target, lambda file: _write_csv(table, file))
    elif fmt == "json":
        write_atomically(target, lambda file: _write_json(table, file))
    else:
        write_atomically(target, lambda file: _write_ros(table, file, frame_id))
    return target
