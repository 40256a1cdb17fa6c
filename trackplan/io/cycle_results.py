"""Run outputs of a workpiece with several seams: trajectory.csv with its ``segment`` column
and result.json with the per-seam figures, the sequence, the air and cycle time."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from trackplan.case import PLACEMENT_KEYS, Case
from trackplan.io.csv_table import format_table
from trackplan.io.results import (
    slowdown_record,
    trajectory_header,
    trajectory_table,
    write_result_json,
)
from trackplan.io.run_folder import HASH_KEY, file_sha256
from trackplan.planning.cycle import CycleResult
from trackplan.planning.result import CheckReport, Violation
from trackplan.run_files import RESULT_FILE, TRAJECTORY_FILE

SEGMENT_COLUMN = "segment"
"""Last column of a cycle's trajectory.csv: the seam's name, or approach/retract/air."""


def write_cycle_trajectory_csv(result: CycleResult, file: Path) -> None:
    """Write one row per sample: the columns of a single path, then ``segment``."""
    lines = format_table(trajectory_table(result.trajectory)).decode("ascii").splitlines()
    rows = [f"{line},{label}" for line, label in zip(lines, result.segment, strict=True)]
    n_dof = result.trajectory.q.shape[1]
    header = ",".join([*trajectory_header(n_dof), SEGMENT_COLUMN])
    Path(file).write_text("\n".join([header, *rows]) + "\n", encoding="utf-8")


def _violations(violations: tuple[Violation, ...]) -> list[dict]:
    return [
        {
            "limit": v.limit,
            "joint": v.joint,
            "t_first": v.t_first,
            "t_last": v.t_last,
            "worst": v.worst,
            "bound": v.bound,
            "message": v.message,
        }
        for v in violations
    ]


def _margins(check: CheckReport, joint_names: tuple[str, ...]) -> dict:
    return {
        **{
            kind: dict(zip(joint_names, map(float, values), strict=True))
            for kind, values in check.joint_margins.items()
        },
        **{kind: float(value) for kind, value in check.task_margins.items()},
    }


def cycle_summary(result: CycleResult, case: Case) -> dict:
    """The ``result.json`` content of a cycle (plain JSON types; ``docs/files.md``)."""
    joint_names = case.robot.joint_names
    check = result.check
    sample_time = result.trajectory.sample_time
    seams = []
    for seam, own in zip(result.seams, result.seam_checks, strict=True):
        piece = next(p for p in result.pieces if p.kind == "seam" and p.seam == seam.index)
        plan = seam.plan
        seams.append(
            {
                "name": seam.name,
                "reversed": seam.reversed,
                "t_start": piece.first * sample_time,
                "t_end": piece.last * sample_time,
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
                "feasible": bool(own.success),
                "slowdowns": [slowdown_record(d) for d in plan.slowdowns],
            }
        )
    moves = [
        {
            "kind": piece.kind,
            "t_start": piece.first * sample_time,
            "t_end": piece.last * sample_time,
            "duration": (piece.last - piece.first) * sample_time,
            "via": None if piece.via is None else list(map(float, piece.via)),
        }
        for piece in result.pieces
        if piece.kind != "seam"
    ]
    cell = check.cell
    cycle = case.cycle
    return {
        "case": result.case_name,
        "placement": dict(zip(PLACEMENT_KEYS, map(float, result.placement), strict=True)),
        "feasible": bool(result.feasible),
        "status": result.status.value,
        "message": result.message,
        "objective": float(result.objective),
        "duration": float(result.duration),
        "cycle_time": float(result.duration),
        "seam_time": float(result.seam_time),
        "air_time": float(result.air_time),
        "approach": 0.0 if cycle is None else float(cycle.approach),
        "approach_deviation": float(result.approach_deviation),
        "sequence_mode": "given" if cycle is None else cycle.sequence,
        "sequence": [
            {"seam": case.seams[v.seam].name, "reversed": bool(v.reversed)}
            for v in result.sequence.visits
        ],
        "sequence_exact": bool(result.sequence.exact),
        "home": None
        if cycle is None or cycle.home is None
        else dict(zip(joint_names, map(float, cycle.home), strict=True)),
        "seams": seams,
        "moves": moves,
        "unplanned": {name: plan.message for name, plan in result.unplanned.items()},
        "max_tracking_error": float(check.max_tracking_error),
        "max_orientation_error": float(check.max_orientation_error),
        "margins": _margins(check, joint_names),
        "binding": {kind: {"joint": j, "t": t} for kind, (j, t) in check.binding.items()},
        **(
            {}
            if cell is None
            else {
                "min_clearance": {
                    "distance": float(cell.min_clearance),
                    "robot_body": cell.closest[0],
                    "other_body": cell.closest[1],
                    "t": float(cell.t_closest),
                    "clearance": float(cell.clearance),
                }
            }
        ),
        "violations": _violations(check.violations),
        "timing": result.timing,
        "joint_names": list(joint_names),
        "sample_time": float(sample_time),
        "n_samples": int(result.trajectory.n_samples),
    }


def write_cycle_files(
    result: CycleResult, case: Case, out_dir: Path, extra: dict | None = None
) -> dict:
    """Write ``trajectory.csv`` (with ``segment``) and ``result.json`` of a cycle.

    Returns
    -------
    dict
        The summary written to ``result.json`` (``extra`` merged in).
    """
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    write_cycle_trajectory_csv(result, out_dir / TRAJECTORY_FILE)
    summary = {
        **cycle_summary(result, case),
        **(extra or {}),
        HASH_KEY: file_sha256(out_dir / TRAJECTORY_FILE),
    }
    write_result_json(summary, out_dir / RESULT_FILE)
    return summary


def read_segments(file: Path) -> np.ndarray:
    """The ``segment`` column of a cycle's trajectory.csv, shape (N,), str.

    Raises
    ------
    CaseError
        When the file has no ``segment`` column.
    """
    from trackplan.errors import CaseError

    lines = Path(file).read_text(encoding="utf-8").splitlines()
    header = lines[0].split(",") if lines else []
    if SEGMENT_COLUMN not in header:
        raise CaseError(
            "no segment column: not the trajectory of a case with several seams",
            file=str(file),
            key="header",
        )
    column = header.index(SEGMENT_COLUMN)
    return np.array([line.split(",")[column] for line in lines[1:] if line.strip()])
