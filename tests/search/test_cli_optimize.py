"""``trackplan optimize`` and ``trackplan demo``: files, result.json blocks, exit codes."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from tests.conftest import CASES
from trackplan.cli import ExitCode, main
from trackplan.cli.common import shipped_cases_dir
from trackplan.errors import CaseError
from trackplan.io.history import read_history_csv, write_history_csv
from trackplan.run_files import HISTORY_FILE
from trackplan.search import SearchHistory


def run(capsys: pytest.CaptureFixture[str], *args: str) -> tuple[int, str, str]:
    code = main(list(args))
    captured = capsys.readouterr()
    return code, captured.out, captured.err


def _case_file(tmp_path: Path, old: str, new: str) -> Path:
    """The corner case with one piece of its text replaced (and no example placement)."""
    lines = (CASES / "paper-corner.yaml").read_text(encoding="utf-8").splitlines(keepends=True)
    text = "".join(line for line in lines if not line.lstrip().startswith("example:"))
    assert old in text
    file = tmp_path / "case.yaml"
    file.write_text(text.replace(old, new), encoding="utf-8")
    return file


def test_optimize_writes_the_plan_files_and_the_search(
    capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    out = tmp_path / "run"
    code, stdout, _ = run(
        capsys,
        "optimize",
        str(CASES / "paper-corner.yaml"),
        "--out",
        str(out),
        "--budget",
        "200",
        "--seed",
        "2",
        "--method",
        "ga",
        "--no-report",
    )
    assert code == ExitCode.OK
    assert sorted(p.name for p in out.iterdir()) == ["history.csv", "result.json", "trajectory.csv"]
    summary = json.loads((out / "result.json").read_text())
    optimizer = summary["optimizer"]
    assert (optimizer["method"], optimizer["seed"]) == ("ga", 2)
    assert (optimizer["evaluations"], optimizer["stop_reason"]) == (200, "budget")
    assert optimizer["generations"] == 8 and optimizer["wall_time_s"] > 0
    initial = summary["initial"]
    assert set(initial) == {"placement", "feasible", "status", "message", "objective", "violations"}
    assert initial["placement"]["x"] == pytest.approx(0.150333)
    assert summary["feasible"] and summary["objective"] < initial["objective"]
    history = read_history_csv(out / HISTORY_FILE)
    assert history.evaluations[-1] == 200 and len(history) == 8
    assert history.best[-1] == pytest.approx(optimizer["fitness"])
    assert "evaluations in 8 generations" in stdout and "before (centre of the bounds" in stdout


def test_ctrl_c_during_the_progress_bar_still_writes_everything(
    capsys: pytest.CaptureFixture[str], tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    from rich.progress import Progress

    monkeypatch.setenv("TTY_COMPATIBLE", "1")  # rich draws the bar as on a terminal
    update = Progress.update
    descriptions: list[str] = []

    def interrupting(self: Progress, task: object, **fields: object) -> None:
        descriptions.append(str(fields.get("description")))
        update(self, task, **fields)
        if len(descriptions) == 3:
            raise KeyboardInterrupt

    monkeypatch.setattr(Progress, "update", interrupting)
    out = tmp_path / "run"
    code, stdout, _ = run(
        capsys,
        "optimize",
        str(CASES / "paper-corner.yaml"),
        "--method",
        "ga",
        "--out",
        str(out),
        "--no-report",
    )
    assert code == ExitCode.INTERRUPTED
    assert descriptions[0].startswith("generation 1  30 evaluations  best J")
    assert "feasible" in descriptions[0] and "%" in descriptions[0]
    summary = json.loads((out / "result.json").read_text())
    assert summary["optimizer"]["stop_reason"] == "interrupted"
    assert summary["status"] == "interrupted" and summary["interrupted"]["signal"] == "SIGINT"
    assert summary["optimizer"]["evaluations"] == 86 and summary["feasible"]
    assert len(read_history_csv(out / HISTORY_FILE)) == 3
    assert "stopped: interrupted" in stdout


def test_impossible_case_exits_3_with_the_violations(
    capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    file = _case_file(tmp_path, "line: {to: [0.5, 0, 0]}", "line: {to: [3.0, 0, 0]}")
    out = tmp_path / "run"
    code, stdout, _ = run(
        capsys, "optimize", str(file), "--out", str(out), "--budget", "90", "--no-report"
    )
    assert code == ExitCode.INFEASIBLE
    assert "no feasible placement in 90 evaluations" in stdout and "out of reach" in stdout
    summary = json.loads((out / "result.json").read_text())
    assert not summary["feasible"] and summary["status"] == "unreachable"
    assert summary["optimizer"]["status"] == "unreachable"
    assert (out / HISTORY_FILE).is_file()


def test_bounds_outside_the_reach_exit_2(capsys: pytest.CaptureFixture[str], tmp_path: Path):
    file = _case_file(tmp_path, "  x: [-0.87, 0.87]", "  x: [0.86, 0.87]")
    code, _, err = run(capsys, "optimize", str(file), "--out", str(tmp_path / "run"))
    assert code == ExitCode.BAD_INPUT
    assert err.startswith(f"{file}: placement.reach: no placement satisfies the reach")
    assert len(err.strip().splitlines()) == 1


@pytest.mark.parametrize("method", ["pso", ""])
def test_bad_method_exits_2(
    capsys: pytest.CaptureFixture[str], tmp_path: Path, method: str
) -> None:
    out = tmp_path / "x"
    code, _, err = run(
        capsys, "optimize", str(CASES / "paper-line.yaml"), "--method", method, "--out", str(out)
    )
    assert code == ExitCode.BAD_INPUT
    assert (
        err
        == f"--method: --method must be one of multistart, ga, cmaes, de, random, got {method!r}\n"
    )
    assert not out.exists()


def test_history_round_trip(tmp_path: Path) -> None:
    history = SearchHistory(
        generation=np.array([1, 2]),
        evaluations=np.array([30, 58]),
        best=np.array([1e6 + 0.25, 0.123456789012345]),
        mean=np.array([1e6, 5e5]),
        feasible_share=np.array([0.0, 1 / 3]),
        wall_time=np.array([0.5, 0.75]),
    )
    write_history_csv(history, tmp_path / "h.csv")
    back = read_history_csv(tmp_path / "h.csv")
    for key, column in history.as_columns().items():
        assert np.array_equal(back.as_columns()[key], column), key
    (tmp_path / "bad.csv").write_text("generation,best\n1,2\n")
    with pytest.raises(CaseError, match="expected the header generation,evaluations"):
        read_history_csv(tmp_path / "bad.csv")
    with pytest.raises(CaseError, match="history file not found"):
        read_history_csv(tmp_path / "missing.csv")


@pytest.mark.slow
def test_demo_writes_the_report(
    capsys: pytest.CaptureFixture[str], tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    assert (shipped_cases_dir() / "paper-corner.yaml").is_file()
    out = tmp_path / "demo"
    code, stdout, _ = run(capsys, "demo", "--out", str(out))
    assert code == ExitCode.OK
    report = out / "report.html"
    assert report.is_file() and f"report: {report.resolve()}" in stdout
    for name in ("trajectory.csv", "result.json", "history.csv", "convergence.png"):
        assert (out / name).is_file(), name
    assert json.loads((out / "result.json").read_text())["optimizer"]["stop_reason"] == "converged"


@pytest.mark.slow
@pytest.mark.parametrize(("case", "family"), [("kuka-weld", "opw"), ("ur5e-glue", "ur")])
def test_robot_library_cases_optimize_to_a_checked_feasible_placement(
    capsys: pytest.CaptureFixture[str], tmp_path: Path, case: str, family: str
) -> None:
    out = tmp_path / case
    code, _, _ = run(
        capsys, "optimize", str(CASES / f"{case}.yaml"), "--out", str(out), "--no-report"
    )
    assert code == ExitCode.OK
    summary = json.loads((out / "result.json").read_text())
    assert summary["feasible"]
    robot = summary["robot"]
    assert robot["family"] == family and "assumed" in robot["assumptions"][0]
    placement = [summary["placement"][key] for key in ("x", "y", "z", "roll", "pitch", "yaw")]
    code, stdout, _ = run(
        capsys,
        "check",
        str(CASES / f"{case}.yaml"),
        str(out),
        "--placement",
        *(repr(value) for value in placement),
    )
    assert code == ExitCode.OK and stdout.rstrip().endswith("feasible")
