"""Summary rows read back from run folders: infeasible runs without a trajectory, worst margin."""

from __future__ import annotations

import csv
import json
import math
from pathlib import Path

import pytest

from tests.conftest import CASES
from tests.study.conftest import write_study
from trackplan.errors import CaseError
from trackplan.io.study_file import load_study
from trackplan.status import Status
from trackplan.study import JobRow, read_summary_csv, run_job
from trackplan.study.summary import (
    IGNORED_UNLESS_BROKEN,
    row_from_run,
    worst_margin,
    write_summary_csv,
)

TOO_LONG = """
name: too-long
robot: puma560
path:
  start: [0, 0, 0]
  segments:
    - line: {to: [2.0, 0, 0]}
task: {rated_speed: 0.1}
"""
"""A valid case whose 2 m line no placement of the PUMA560 (reach 0.88 m) can follow:
every search ends with an unreachable plan and no trajectory."""


def test_an_infeasible_job_without_a_trajectory_is_a_row_with_its_verdict(tmp_path: Path) -> None:
    (tmp_path / "too-long.yaml").write_text(TOO_LONG, encoding="utf-8")
    study = load_study(write_study(tmp_path, "cases: [too-long.yaml]\n"))
    row = run_job(study.jobs[0], tmp_path / "out", report=False)
    written = json.loads((tmp_path / "out" / "jobs" / row.job / "result.json").read_text())
    assert written["objective"] is None and written["n_samples"] == 0
    assert not (tmp_path / "out" / "errors").exists()
    assert not row.failed and not row.success
    assert row.status is Status.UNREACHABLE and written["status"] == "unreachable"
    assert row.message == written["message"] and "out of reach" in row.message
    for value in (row.J, row.duration_s, row.cycle_time_s, row.tracking_error_m):
        assert math.isnan(value)
    assert math.isnan(row.worst_margin)  # no trajectory: no margin at all
    write_summary_csv([row], tmp_path / "summary.csv")
    (back,) = read_summary_csv(tmp_path / "summary.csv")
    assert back.status is Status.UNREACHABLE and math.isnan(back.J)


def test_worst_margin_is_the_smallest_margin_of_a_limit_with_headroom(tmp_path: Path) -> None:
    # paper-corner's plan runs at the rated speed (speed margin 0 by design) and keeps every
    # limit with headroom: its worst margin is known to be positive
    study = load_study(write_study(tmp_path, f"cases: ['{CASES}/paper-corner.yaml']\nseeds: [0]\n"))
    row = run_job(study.jobs[0], tmp_path / "out", report=False)
    written = json.loads((tmp_path / "out" / "jobs" / row.job / "result.json").read_text())
    margins = written["margins"]
    assert row.success and margins["speed"] == 0.0
    kept = [
        value
        for kind, entry in margins.items()
        if kind not in IGNORED_UNLESS_BROKEN
        for value in (entry.values() if isinstance(entry, dict) else [entry])
    ]
    assert len(kept) >= 5 * 6 + 3  # the joint limits, tracking, orientation, spin
    assert row.worst_margin == pytest.approx(min(kept), abs=1e-12)
    assert 0.0 < row.worst_margin < 1.0


@pytest.mark.parametrize(
    ("margins", "expected"),
    [
        ({"position": {"q1": 0.4, "q2": 0.25}, "tracking": 0.05, "speed": 0.0}, 0.05),
        ({"jerk": {"q1": 0.3}, "speed": -0.02, "coverage": 1.0}, -0.02),
        ({"jerk": {"q1": 0.3}, "speed": 0.0, "coverage": -1.0}, -1.0),
        ({"jerk": {"q1": -0.1}, "tracking": None, "speed": 0.0}, -0.1),
        ({"speed": 0.0, "coverage": 1.0}, math.nan),
        ({}, math.nan),
    ],
)
def test_worst_margin_of_a_margins_block(margins: dict, expected: float) -> None:
    found = worst_margin(margins)
    assert (math.isnan(found) and math.isnan(expected)) or found == pytest.approx(expected)


def test_a_run_folder_with_nulls_reads_back_as_nan(tmp_path: Path) -> None:
    folder = tmp_path / "run"
    folder.mkdir()
    keys = {"job": "a__b__base__s0", "case": "a", "robot": "b", "sweep": "base", "seed": 0}
    (folder / "job.json").write_text(json.dumps({**keys, "wall_time_s": 1.5, "worker": "w"}))
    result = {
        "status": "limits_violated",
        "feasible": False,
        "objective": None,
        "duration": None,
        "max_tracking_error": None,
        "margins": {"jerk": {"q1": -0.5}, "torque": None},
        "sample_time": 0.001,
        "n_samples": 0,
        "message": "jerk of joint 1 over its limit",
    }
    (folder / "result.json").write_text(json.dumps(result))
    row = row_from_run(folder)
    assert row.status is Status.LIMITS_VIOLATED and not row.failed
    assert math.isnan(row.J) and math.isnan(row.duration_s) and math.isnan(row.cycle_time_s)
    assert row.worst_margin == -0.5 and row.wall_time_s == 1.5


def test_summary_text_a_spreadsheet_would_run_is_neutralised_and_reads_back(
    tmp_path: Path,
) -> None:
    nan = math.nan
    rows = [
        JobRow("=cmd()__r__base__s0", "=cmd()", "r", "base", 0, Status.FAILED, False, nan, nan, nan,
               nan, -0.25, 1.0, "w", "-failed: @once"),
        JobRow("'=x__r__base__s1", "'=x", "r", "task.rated_speed=-1", 1, Status.FEASIBLE, True, 1.5,
               2.0, 2.0, 1e-4, 0.1, 1.0, "+w", "ok"),
    ]  # fmt: skip
    write_summary_csv(rows, tmp_path / "summary.csv")
    with (tmp_path / "summary.csv").open(newline="", encoding="utf-8") as handle:
        cells = list(csv.reader(handle))[1:]
    assert cells[0][:2] == ["'=cmd()__r__base__s0", "'=cmd()"]
    assert cells[0][11] == "-0.25"  # a number stays a number
    assert cells[0][14] == "'-failed: @once" and cells[1][13] == "'+w"
    assert cells[1][1] == "''=x" and cells[1][3] == "task.rated_speed=-1"
    back = read_summary_csv(tmp_path / "summary.csv")
    assert [row.job for row in back] == [row.job for row in rows]
    assert [row.message for row in back] == [row.message for row in rows]
    assert [row.case for row in back] == ["=cmd()", "'=x"] and back[1].worker == "+w"
    assert [row.status for row in back] == [Status.FAILED, Status.FEASIBLE]
    assert [cell[5] for cell in cells] == ["failed", "feasible"]  # the words of result files
    assert back[0].failed and not back[1].failed


def test_a_run_folder_with_an_unknown_status_is_one_clear_error(tmp_path: Path) -> None:
    folder = tmp_path / "run"
    folder.mkdir()
    keys = {"job": "a__b__base__s0", "case": "a", "robot": "b", "sweep": "base", "seed": 0}
    (folder / "job.json").write_text(json.dumps({**keys, "wall_time_s": 1.5, "worker": "w"}))
    result = {"status": "splendid", "feasible": False, "message": "?"}
    (folder / "result.json").write_text(json.dumps(result))
    with pytest.raises(CaseError) as caught:
        row_from_run(folder)
    line = str(caught.value)
    assert "result.json" in line and "status" in line and "'splendid'" in line
    assert "feasible" in line and "\n" not in line
