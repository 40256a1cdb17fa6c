"""The plain trajectory writers: CSV, JSON and a ROS 2 JointTrajectory (YAML).

Each writes one file, ``options["file_name"]`` in the folder it is given (default its
``default_file``), from the source's table (:class:`~trackplan.writers.source.ExportSource`):

- ``csv`` → ``trajectory.export.csv``: ``t,<joint names>``, one row per sample (s, rad);
  the header is quoted as the ``csv`` module quotes, and a name that a spreadsheet would
  take for a formula gets a leading ``'`` (:func:`~trackplan.io.csv_cells.neutralised`).
- ``json`` → ``trajectory.json``: joint names, units and every column as arrays; with
  external axes (a run whose ``result.json`` lists ``axes``) each joint's position unit
  (``joint_units``: ``rad``, or ``m`` for a track).
- ``ros`` → ``trajectory.ros.yaml``: a ``trajectory_msgs/msg/JointTrajectory`` as YAML.
"""

from __future__ import annotations

import json
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import yaml

from trackplan.io.csv_cells import neutralised
from trackplan.io.csv_table import write_csv_table
from trackplan.io.export import TrajectoryTable
from trackplan.run_files import RESULT_FILE
from trackplan.writers.source import ExportSource

UNITS = {
    "t": "s",
    "positions": "rad",
    "velocities": "rad/s",
    "accelerations": "rad/s^2",
    "jerks": "rad/s^3",
    "tool_position": "m",
    "speed": "m/s",
}
"""Units of the JSON export's arrays."""


@dataclass(frozen=True)
class CsvWriter:
    """``t,<joint names>``: times (s) and joint positions (rad), shortest round-trip floats."""

    name: str = "csv"
    suffix: str = ".csv"
    default_file: str = "trajectory.export.csv"
    folder: bool = False

    def write(self, source: ExportSource, folder: Path, **options: Any) -> tuple[str, ...]:
        """Write the CSV file (options other than ``file_name`` are ignored)."""
        name, table = _file_name(self, options), source.table
        header = ["t", *(neutralised(joint) for joint in table.joint_names)]
        write_csv_table(folder / name, np.column_stack([table.t, table.q]), header)
        return (name,)


@dataclass(frozen=True)
class JsonWriter:
    """Joint names, units and every column of the trajectory as JSON arrays."""

    name: str = "json"
    suffix: str = ".json"
    default_file: str = "trajectory.json"
    folder: bool = False

    def write(self, source: ExportSource, folder: Path, **options: Any) -> tuple[str, ...]:
        """Write the JSON file, one key per line (options other than ``file_name`` are
        ignored)."""
        name, table = _file_name(self, options), source.table
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
        joint_units = _joint_units(source)
        if joint_units is not None:
            content["joint_units"] = joint_units
        # one key per line keeps the file readable without a line per number
        body = ",\n".join(
            f"  {json.dumps(key)}: {json.dumps(value)}" for key, value in content.items()
        )
        (folder / name).write_text("{\n" + body + "\n}\n", encoding="utf-8")
        return (name,)


@dataclass(frozen=True)
class RosWriter:
    """A ROS 2 ``trajectory_msgs/msg/JointTrajectory`` as YAML (option ``frame_id``)."""

    name: str = "ros"
    suffix: str = ".yaml"
    default_file: str = "trajectory.ros.yaml"
    folder: bool = False

    def write(self, source: ExportSource, folder: Path, **options: Any) -> tuple[str, ...]:
        """Write the YAML message; ``frame_id`` (default empty) goes to ``header.frame_id``."""
        name, table = _file_name(self, options), source.table
        dumper = getattr(yaml, "CSafeDumper", yaml.SafeDumper)
        text = yaml.dump(
            joint_trajectory_msg(table, str(options.get("frame_id", ""))),
            Dumper=dumper,
            sort_keys=False,
            default_flow_style=None,
            width=120,
        )
        (folder / name).write_text(text, encoding="utf-8")
        return (name,)


def _joint_units(source: ExportSource) -> list[str] | None:
    """Each joint's position unit from the run's ``result.json`` ``axes`` (name, kind,
    unit) when it lists external axes and matches the table; else None (every joint
    rad, as ``units`` says)."""
    if source.folder is None:
        return None
    try:
        summary = json.loads((source.folder / RESULT_FILE).read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return None
    axes = summary.get("axes") if isinstance(summary, dict) else None
    if not isinstance(axes, list) or len(axes) != source.table.q.shape[1]:
        return None
    units = [axis.get("unit") if isinstance(axis, dict) else None for axis in axes]
    if not all(unit in ("rad", "m") for unit in units) or all(unit == "rad" for unit in units):
        return None
    return [str(unit) for unit in units]


def _file_name(writer: CsvWriter | JsonWriter | RosWriter, options: dict[str, Any]) -> str:
    """The file a one-file writer writes: ``options["file_name"]``, else its default."""
    return str(options.get("file_name") or writer.default_file)


def _duration_msg(t: float) -> dict[str, int]:
    """A ``builtin_interfaces/Duration`` of t seconds: whole seconds and nanoseconds."""
    sec, nanosec = divmod(round(t * 1e9), 1_000_000_000)
    return {"sec": sec, "nanosec": nanosec}


def joint_trajectory_msg(table: TrajectoryTable, frame_id: str = "") -> dict[str, Any]:
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
