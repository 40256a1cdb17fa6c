"""Read a run's trajectory as a table for the export writers (:mod:`trackplan.writers`).

The source is a run directory (or its ``trajectory.csv``, header
``t,q1..qn,qd1..qdn,qdd1..qddn,qddd1..qdddn,x,y,z,speed,spin``) or a
:class:`~trackplan.planning.result.Trajectory` in memory. Joint names come from
``result.json`` next to the CSV (key ``joint_names``) when it is there, else ``q1..qn``.
"""

from __future__ import annotations

import json
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from trackplan.errors import CaseError
from trackplan.io.results import trajectory_header
from trackplan.planning.result import Trajectory
from trackplan.run_files import RESULT_FILE, TRAJECTORY_FILE


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
            joint_names=checked_joint_names(joint_names, n_dof, "joint_names", None),
            t=trajectory.t,
            q=trajectory.q,
            qd=trajectory.qd,
            qdd=trajectory.qdd,
            qddd=trajectory.qddd,
            tool_position=trajectory.tool_position,
            speed=trajectory.speed,
        )


def checked_joint_names(
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
        return checked_joint_names(None, n_dof, "joint_names", None)
    try:
        summary = json.loads(result_file.read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError, json.JSONDecodeError) as error:
        raise CaseError(f"cannot read the run summary: {error}", file=str(result_file)) from None
    names = summary.get("joint_names") if isinstance(summary, dict) else None
    return checked_joint_names(names, n_dof, "joint_names", str(result_file))


def trajectory_file(source: Path) -> Path:
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
    file = trajectory_file(Path(file))
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
