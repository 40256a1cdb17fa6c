"""Run outputs (trajectory.csv, result.json, history.csv) and reading a trajectory back."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from trackplan.case import PLACEMENT_KEYS
from trackplan.errors import CaseError
from trackplan.planning.result import CheckReport, PlanResult, Trajectory
from trackplan.run_files import RESULT_FILE, TRAJECTORY_FILE


def trajectory_header(n_dof: int) -> list[str]:
    """Column names ``t,q1..qn,qd1..qdn,qdd1..qddn,qddd1..qdddn,x,y,z,speed``."""
    columns = ["t"]
    for prefix in ("q", "qd", "qdd", "qddd"):
        columns += [f"{prefix}{i + 1}" for i in range(n_dof)]
    return [*columns, "x", "y", "z", "speed"]


def write_trajectory_csv(trajectory: Trajectory, file: Path) -> None:
    """Write one row per sample (full float precision, so the file re-checks identically)."""
    n_dof = trajectory.q.shape[1] if trajectory.q.ndim == 2 else 0
    table = (
        np.column_stack(
            [
                trajectory.t,
                trajectory.q,
                trajectory.qd,
                trajectory.qdd,
                trajectory.qddd,
                trajectory.tool_position,
                trajectory.speed,
            ]
        )
        if trajectory.n_samples
        else np.zeros((0, 4 * n_dof + 5))
    )
    np.savetxt(
        file,
        table,
        delimiter=",",
        header=",".join(trajectory_header(n_dof)),
        comments="",
        fmt="%.17g",
    )


def read_trajectory_csv(file: Path, n_dof: int | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Read the time and joint columns of a ``trajectory.csv``, whoever wrote it.

    Parameters
    ----------
    file
        The CSV file (header ``t,q1..qn,...``; extra columns are ignored).
    n_dof
        Expected number of joints, or None to take it from the header.

    Returns
    -------
    tuple of numpy.ndarray
        ``t`` (N,), s, and ``q`` (N, n), rad.

    Raises
    ------
    CaseError
        When the file is missing, unreadable, or its columns are wrong.
    """
    file = Path(file)
    try:
        with file.open() as handle:
            header = handle.readline().strip().split(",")
        data = np.loadtxt(file, delimiter=",", skiprows=1, ndmin=2)
    except OSError as error:
        raise CaseError(f"cannot read trajectory: {error.strerror}", file=str(file)) from None
    except ValueError as error:
        raise CaseError(f"not a numeric CSV table: {error}", file=str(file)) from None
    if not header or header[0] != "t":
        raise CaseError("the first column must be 't'", file=str(file), key="header")
    joints = [name for name in header if name[:1] == "q" and name[1:].isdigit()]
    if n_dof is not None and len(joints) != n_dof:
        raise CaseError(
            f"expected columns q1..q{n_dof} for the robot, found {len(joints)}",
            file=str(file),
            key="header",
        )
    if data.shape[0] < 2:
        raise CaseError("the trajectory needs at least 2 samples", file=str(file))
    if not np.all(np.isfinite(data)):
        row = int(np.argwhere(~np.isfinite(data))[0, 0]) + 2
        raise CaseError(f"non-finite number on line {row}", file=str(file))
    index = [header.index(name) for name in joints]
    return data[:, 0], data[:, index]


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
        "rated_speed_fraction": float(result.rated_speed_fraction),
        "min_corner_speed": float(result.min_corner_speed),
        **_energy_summary(result),
        "margins": {
            **{
                kind: dict(zip(joint_names, map(float, values), strict=True))
                for kind, values in check.joint_margins.items()
            },
            **{kind: float(value) for kind, value in check.task_margins.items()},
        },
        "binding": {kind: {"joint": j, "t": t} for kind, (j, t) in check.binding.items()},
        **_cell_summary(check),
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
        "slowdowns": [
            {
                "s_start": d.s_start,
                "s_end": d.s_end,
                "speed": d.speed,
                "rated_speed": d.rated_speed,
                "shortfall": 1.0 - d.speed / d.rated_speed,
                "limit": d.limit,
            }
            for d in result.slowdowns
        ],
        "timing": result.timing,
        "branch": int(result.branch),
        "joint_names": list(joint_names),
        "sample_time": float(result.trajectory.sample_time),
        "n_samples": int(result.trajectory.n_samples),
        **{key: float(value) for key, value in result.references.items()},
    }


def write_result_json(summary: dict, file: Path) -> None:
    """Write a summary dict as indented JSON."""
    Path(file).write_text(json.dumps(summary, indent=2, allow_nan=True) + "\n")


def write_plan_files(
    result: PlanResult, joint_names: tuple[str, ...], out_dir: Path, extra: dict | None = None
) -> dict:
    """Write ``trajectory.csv`` and ``result.json`` of a plan into ``out_dir``.

    Returns
    -------
    dict
        The summary written to ``result.json`` (``extra`` merged in).
    """
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    write_trajectory_csv(result.trajectory, out_dir / TRAJECTORY_FILE)
    summary = {**result_summary(result, joint_names), **(extra or {})}
    write_result_json(summary, out_dir / RESULT_FILE)
    return summary
