"""The CLI under misuse and signals: checks before work, strict JSON, whole run folders."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time
import warnings
from pathlib import Path

import numpy as np
import pytest

from trackplan.cli import ExitCode, main
from trackplan.io.results import trajectory_header, write_result_json
from trackplan.io.run_folder import STAGING_PREFIX

ROOT = Path(__file__).resolve().parents[1]
CASES = ROOT / "cases"
CORNER = str(CASES / "paper-corner.yaml")
LINE = str(CASES / "paper-line.yaml")


def run(capsys: pytest.CaptureFixture[str], *args: str) -> tuple[int, str, str]:
    code = main(list(args))
    captured = capsys.readouterr()
    assert "Traceback" not in captured.out + captured.err
    return code, captured.out, captured.err


# --------------------------------------------------------------------------- checks first


@pytest.mark.parametrize(
    ("args", "expected"),
    [
        (("--out", "{file}"), "--out: '{file}' is a file, expected a folder"),
        (("--out", "{file}/run"), "--out: '{file}/run' lies under the file '{file}'"),
        (("--seed", "-1"), "Invalid value for '--seed'"),
        (("--method", ""), "--method must be one of multistart, ga, cmaes, de, random, got ''"),
        (
            ("--method", "pso"),
            "--method must be one of multistart, ga, cmaes, de, random, got 'pso'",
        ),
        (("--timing", "fast"), "--timing must be one of smooth, paper, got 'fast'"),
    ],
)
def test_optimize_refuses_bad_arguments_before_searching(
    capsys: pytest.CaptureFixture[str],
    tmp_path: Path,
    monkeypatch: pytest.MonkeyPatch,
    args: tuple[str, ...],
    expected: str,
) -> None:
    import trackplan.search.optimize as search

    def no_search(*_args: object, **_kwargs: object) -> None:
        pytest.fail("the search started before the arguments were checked")

    monkeypatch.setattr(search, "optimize", no_search)
    file = tmp_path / "taken"
    file.write_text("not a folder")
    args = tuple(arg.format(file=file) for arg in args)
    code, _, err = run(capsys, "optimize", LINE, *args)
    assert code == ExitCode.BAD_INPUT
    assert expected.format(file=file) in err


@pytest.mark.parametrize("value", ["nan", "inf", "-inf", "1e308"])
@pytest.mark.parametrize("command", ["plan", "check"])
def test_non_finite_or_huge_placement_is_refused(
    capsys: pytest.CaptureFixture[str], tmp_path: Path, value: str, command: str
) -> None:
    target = ["--out", str(tmp_path / "run")] if command == "plan" else [str(tmp_path)]
    placement = ["--placement", value, "0", "0", "0", "0", "0"]
    code, _, err = run(capsys, command, LINE, *target, *placement)
    assert code == ExitCode.BAD_INPUT
    assert err.startswith("--placement: X must be a finite number with |X| ≤ 1000")
    assert not (tmp_path / "run").exists()


# --------------------------------------------------------------------------- files


def test_result_json_is_strict_json_with_reasons_for_nulls(tmp_path: Path) -> None:
    file = tmp_path / "result.json"
    write_result_json({"objective": float("nan"), "margins": {"jerk": [1.0, float("inf")]}}, file)
    text = file.read_text()
    assert "NaN" not in text and "Infinity" not in text
    data = json.loads(text, parse_constant=lambda name: pytest.fail(f"bare {name}"))
    assert data["objective"] is None and data["margins"]["jerk"] == [1.0, None]
    assert data["null_reasons"] == {
        "objective": "not a finite number (nan)",
        "margins.jerk[1]": "not a finite number (inf)",
    }


def test_an_unreachable_plan_writes_strict_json(capsys, tmp_path: Path) -> None:
    out = tmp_path / "run"
    code, _, _ = run(
        capsys,
        "plan",
        LINE,
        "--out",
        str(out),
        "--no-report",
        "--placement",
        "5",
        "5",
        "5",
        "0",
        "0",
        "0",
    )
    assert code == ExitCode.INFEASIBLE
    data = json.loads((out / "result.json").read_text(), parse_constant=lambda n: pytest.fail(n))
    assert data["feasible"] is False and data["objective"] is None
    assert "objective" in data["null_reasons"]


def test_a_run_replaces_every_output_of_the_earlier_run(capsys, tmp_path: Path) -> None:
    out = tmp_path / "run"
    assert (
        run(capsys, "optimize", LINE, "--out", str(out), "--budget", "60", "--restarts", "1")[0]
        == 0
    )
    assert {"report.html", "history.csv", "joints.png"} <= {p.name for p in out.iterdir()}
    code, _, _ = run(
        capsys,
        "plan",
        LINE,
        "--out",
        str(out),
        "--no-report",
        "--placement",
        "5",
        "5",
        "5",
        "0",
        "0",
        "0",
    )
    assert code == ExitCode.INFEASIBLE
    assert sorted(p.name for p in out.iterdir()) == ["result.json", "trajectory.csv"]
    assert json.loads((out / "result.json").read_text())["status"] == "unreachable"


def test_check_and_export_refuse_an_inconsistent_folder(capsys, tmp_path: Path) -> None:
    out = tmp_path / "run"
    assert run(capsys, "plan", LINE, "--out", str(out), "--no-report")[0] == 0
    assert run(capsys, "check", LINE, str(out))[0] == 0
    csv = out / "trajectory.csv"
    lines = csv.read_text().splitlines()
    csv.write_text("\n".join(lines[: len(lines) // 2]) + "\n")  # as a killed writer would
    for args in (("check", LINE, str(out)), ("export", str(out))):
        code, _, err = run(capsys, *args)
        assert code == ExitCode.BAD_INPUT and "files of two runs are mixed" in err
    (out / "result.json").unlink()
    for args in (("check", LINE, str(out)), ("export", str(out))):
        code, _, err = run(capsys, *args)
        assert code == ExitCode.BAD_INPUT and "no result.json beside trajectory.csv" in err


def test_check_reads_columns_by_header(capsys, tmp_path: Path) -> None:
    out = tmp_path / "run"
    assert run(capsys, "plan", LINE, "--out", str(out), "--no-report")[0] == 0
    header, *rows = (out / "trajectory.csv").read_text().splitlines()
    names = header.split(",")
    table = np.array([row.split(",") for row in rows])
    order = list(reversed(range(len(names))))  # every column moved
    swapped = tmp_path / "swapped.csv"
    swapped.write_text(
        ",".join(names[i] for i in order)
        + "\n"
        + "\n".join(",".join(r[order]) for r in table)
        + "\n"
    )
    code, stdout, _ = run(capsys, "check", LINE, str(swapped))
    assert code == ExitCode.OK and stdout.rstrip().endswith("feasible")
    for broken, expected in (
        (["t", "q1", "q1", *names[3:]], "column 'q1' appears twice"),
        (["time", *names[1:]], "missing t"),
        ([n if n != "q4" else "x4" for n in names], "missing q4"),
    ):
        bad = tmp_path / "bad.csv"
        bad.write_text(",".join(broken) + "\n" + "\n".join(rows) + "\n")
        code, _, err = run(capsys, "check", LINE, str(bad))
        assert code == ExitCode.BAD_INPUT and expected in err and err.count("\n") == 1


def test_check_reads_the_placement_of_the_run(capsys, tmp_path: Path) -> None:
    out = tmp_path / "run"
    X = ["-0.2", "0.1", "0.19", "0.03", "-0.41", "0.5"]  # not the case's placement.example
    assert run(capsys, "plan", LINE, "--out", str(out), "--no-report", "--placement", *X)[0] == 0
    code, stdout, err = run(capsys, "check", LINE, str(out))
    assert (code, err) == (ExitCode.OK, "") and stdout.rstrip().endswith("feasible")
    example = ["-0.2230", "0.1029", "0.1829", "0.0312", "-0.4124", "0.5020"]
    code, stdout, _ = run(capsys, "check", LINE, str(out), "--placement", *example)
    assert code == ExitCode.INFEASIBLE  # the option still wins: the path lies elsewhere
    (out / "trajectory.csv").rename(tmp_path / "trajectory.csv")
    code, _, _ = run(capsys, "check", LINE, str(tmp_path / "trajectory.csv"))
    assert code == ExitCode.INFEASIBLE  # a bare CSV: the case's placement.example
    (tmp_path / "trajectory.csv").rename(out / "trajectory.csv")
    summary = json.loads((out / "result.json").read_text())
    summary["placement"]["yaw"] = "east"
    (out / "result.json").write_text(json.dumps(summary))
    code, _, err = run(capsys, "check", LINE, str(out))
    assert code == ExitCode.BAD_INPUT and err.count("\n") == 1
    assert err.startswith(f"{out / 'result.json'}: placement: expected {{x, y, z, roll, pitch,")


def _retimed(source: Path, target: Path, rows: slice, stretch: float, shift: float) -> Path:
    """The CSV ``source`` with only ``rows`` of its samples and t → stretch · t + shift."""
    header, *lines = source.read_text().splitlines()
    table = np.array([line.split(",") for line in lines])[rows]
    t = table[:, 0].astype(float) * stretch + shift
    table[:, 0] = [repr(float(value)) for value in t]
    target.write_text(header + "\n" + "\n".join(",".join(row) for row in table) + "\n")
    return target


@pytest.mark.parametrize(
    ("rows", "stretch", "shift", "message"),
    [
        # every 100th row kept, time stretched ×2 and shifted by 100 s: once called feasible
        (slice(None, None, 100), 2.0, 100.0, "line 2: t = 100 s, expected 0 s (a trajectory "),
        (slice(None), 1.0, 100.0, "line 2: t = 100 s, expected 0 s (a trajectory starts at t"),
        (slice(None), 2.0, 0.0, "line 3: t = 0.002 s, expected 0.001 s: sample 1 of the case's "),
        (slice(None, None, 100), 1.0, 0.0, "line 3: t = 0.1 s, expected 0.001 s: sample 1"),
        (slice(None), 1.0, 2e-9, "line 2: t = 2e-09 s, expected 0 s"),  # off by 2e-6 Ts
    ],
)
def test_check_holds_the_case_sample_time_and_start(
    capsys, tmp_path: Path, rows: slice, stretch: float, shift: float, message: str
) -> None:
    out = tmp_path / "run"
    assert run(capsys, "plan", LINE, "--out", str(out), "--no-report")[0] == 0
    csv = _retimed(out / "trajectory.csv", tmp_path / "retimed.csv", rows, stretch, shift)
    code, _, err = run(capsys, "check", LINE, str(csv))
    assert code == ExitCode.BAD_INPUT and err.count("\n") == 1, err
    assert err.startswith(f"{csv}: t: {message}"), err
    assert "task.sample_time = 0.001 s, within 1e-06 · Ts" in err


def test_check_accepts_times_within_the_tolerance(capsys, tmp_path: Path) -> None:
    out = tmp_path / "run"
    assert run(capsys, "plan", LINE, "--out", str(out), "--no-report")[0] == 0
    csv = _retimed(out / "trajectory.csv", tmp_path / "retimed.csv", slice(None), 1.0, 0.9e-9)
    code, stdout, err = run(capsys, "check", LINE, str(csv))
    assert (code, err) == (ExitCode.OK, "") and stdout.rstrip().endswith("feasible")


def test_trajectory_header_is_what_check_reads() -> None:
    assert trajectory_header(2)[:3] == ["t", "q1", "q2"]


# --------------------------------------------------------------------------- signals


def test_sigterm_during_the_search_writes_the_best_result(
    capsys: pytest.CaptureFixture[str], tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    import trackplan.search.driver as optimize

    record = optimize._record

    def record_then_signal(generation, *args, **kwargs):  # type: ignore[no-untyped-def]
        if generation == 2:
            os.kill(os.getpid(), signal.SIGTERM)
        return record(generation, *args, **kwargs)

    monkeypatch.setattr(optimize, "_record", record_then_signal)
    out = tmp_path / "run"
    args = ("optimize", CORNER, "--out", str(out), "--no-report", "--method", "ga")
    code, stdout, _ = run(capsys, *args)
    assert code == ExitCode.TERMINATED == 143
    summary = json.loads((out / "result.json").read_text())
    assert summary["status"] == "interrupted" and summary["interrupted"]["signal"] == "SIGTERM"
    assert summary["optimizer"]["stop_reason"] == "interrupted"
    assert summary["optimizer"]["evaluations"] == 58  # stopped after generation 2
    assert "stopped: interrupted" in stdout
    assert (
        run(
            capsys,
            "check",
            CORNER,
            str(out),
            "--placement",
            *map(str, summary["placement"].values()),
        )[0]
        == 0
    )
    assert signal.getsignal(signal.SIGTERM) == signal.SIG_DFL  # restored


def test_a_second_signal_while_writing_leaves_no_truncated_file(
    capsys: pytest.CaptureFixture[str], tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    import trackplan.io.results as results

    out = tmp_path / "run"
    assert run(capsys, "plan", LINE, "--out", str(out), "--no-report")[0] == 0
    before = {p.name: p.read_bytes() for p in out.iterdir()}
    write = results.write_result_json

    def interrupted_write(summary, file):  # type: ignore[no-untyped-def]
        write(summary, file)
        os.kill(os.getpid(), signal.SIGINT)  # the second Ctrl-C, while the run is written

    monkeypatch.setattr(results, "write_result_json", interrupted_write)
    code, _, err = run(capsys, "optimize", LINE, "--out", str(out), "--budget", "30", "--no-report")
    assert code == ExitCode.INTERRUPTED and err.strip().endswith("interrupted (SIGINT)")
    assert {p.name: p.read_bytes() for p in out.iterdir()} == before  # the earlier run, intact


def _start(args: list[str], tmp_path: Path) -> subprocess.Popen:
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    return subprocess.Popen(
        [sys.executable, "-m", "trackplan", *args],
        cwd=tmp_path,
        env=env,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )


@pytest.mark.slow
@pytest.mark.parametrize(
    ("signals", "code"), [((signal.SIGTERM,), 143), ((signal.SIGINT, signal.SIGINT), 130)]
)
def test_signals_to_a_running_optimize_process(
    tmp_path: Path, signals: tuple[int, ...], code: int
) -> None:
    out = tmp_path / "run"
    process = _start(["optimize", CORNER, "--out", str(out), "--restarts", "40"], tmp_path)
    time.sleep(15)  # imports, compilation, and into the search
    process.send_signal(signals[0])
    if len(signals) > 1:  # the second one as soon as the run is being written
        deadline = time.monotonic() + 60
        while time.monotonic() < deadline and not any(out.glob(f"{STAGING_PREFIX}*")):
            time.sleep(0.005)
        process.send_signal(signals[1])
    _, err = process.communicate(timeout=120)
    assert process.returncode == code and "Traceback" not in err
    if (out / "result.json").exists():  # a complete, consistent run
        summary = json.loads((out / "result.json").read_text())
        assert summary["status"] == "interrupted"
        X = [str(v) for v in summary["placement"].values()]
        assert main(["check", CORNER, str(out), "--placement", *X]) == ExitCode.OK
    else:  # nothing, or files without their result.json: refused
        assert not out.exists() or main(["check", CORNER, str(out)]) == ExitCode.BAD_INPUT


CTRL_C_WHILE_IMPORTING = """
import builtins, sys
real_import = builtins.__import__

def ctrl_c_on_the_commands(name, *args, **kwargs):
    if name == "trackplan.cli.app":  # what main() imports: numpy, typer, the planner
        raise KeyboardInterrupt
    return real_import(name, *args, **kwargs)

builtins.__import__ = ctrl_c_on_the_commands
from trackplan.cli import main
sys.exit(main(["validate", "case.yaml"]))
"""


def test_ctrl_c_during_start_up_prints_no_traceback(tmp_path: Path) -> None:
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    done = subprocess.run(
        [sys.executable, "-c", CTRL_C_WHILE_IMPORTING],
        cwd=tmp_path,
        env=env,
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert (done.returncode, done.stderr) == (130, "interrupted\n")


@pytest.mark.parametrize(
    ("row", "expected"),
    [
        ("0.002;0.1;0.2", "line 4: values separated by ';', expected commas"),
        ("0.002\t0.1\t0.2", "line 4: values separated by a tab, expected commas"),
        ("0.002,0.3_1,0.2", "line 4, column q1: expected a number, got '0.3_1'"),
        ("0.002,０.５,0.2", "line 4, column q1: expected a number, got '０.５'"),
        ("0.002,0.1", "line 4: 2 values, expected one in column 3 (q2)"),
    ],
    ids=["semicolons", "tabs", "underscore", "full-width", "short-row"],
)
def test_a_bad_trajectory_row_names_its_line_and_column(
    tmp_path: Path, row: str, expected: str
) -> None:
    from trackplan.errors import CaseError
    from trackplan.io.results import read_trajectory_csv

    file = tmp_path / "trajectory.csv"
    # a comment and a blank line before the bad row: numpy's row count skips both
    file.write_text(f"t,q1,q2\n0,0.1,0.2\n\n{row}\n# note\n0.003,0.1,0.2\n", encoding="utf-8")
    with pytest.raises(CaseError) as error:
        read_trajectory_csv(file)
    assert str(error.value) == f"{file}: {expected}"


@pytest.mark.parametrize(
    ("args", "expected"),
    [
        (("--z", "nan"), "--z: Z must be a finite number with |Z| ≤ 1000, got nan"),
        (("--rpy", "0", "1e300", "0"), "--rpy: PITCH must be a finite number with |PITCH| ≤ 1000"),
    ],
)
def test_map_names_the_option_of_a_bad_height_or_orientation(
    capsys: pytest.CaptureFixture[str], tmp_path: Path, args: tuple[str, ...], expected: str
) -> None:
    code, out, err = run(capsys, "map", LINE, "--out", str(tmp_path / "map"), *args)
    assert code == ExitCode.BAD_INPUT and out == ""
    assert err.count("\n") == 1 and err.startswith(expected)


def test_a_trajectory_of_only_a_header_is_one_line_without_numpy_warnings(
    capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    file = tmp_path / "trajectory.csv"
    file.write_text("t,q1,q2,q3,q4,q5,q6\n", encoding="utf-8")
    X = ["0", "0", "0", "0", "0", "0"]
    with warnings.catch_warnings(record=True) as caught:  # a user sees these on stderr
        warnings.simplefilter("always")
        code, out, err = run(capsys, "check", LINE, str(file), "--placement", *X)
    assert [str(w.message) for w in caught] == []
    assert code == ExitCode.BAD_INPUT and out == ""
    assert err == f"{file}: the trajectory needs at least 2 samples\n"


def test_check_names_a_device_and_a_binary_trajectory_plainly(
    capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    binary = tmp_path / "binary.csv"
    binary.write_bytes(b"\xff\xfe\x00t,q1\n")
    X = ["0", "0", "0", "0", "0", "0"]
    for source, expected in (
        ("/dev/null", "/dev/null: trajectory is not a regular file, expected a CSV file or a "),
        (str(binary), f"{binary}: cannot read trajectory: not UTF-8 text"),
    ):
        code, out, err = run(capsys, "check", LINE, source, "--placement", *X)
        assert code == ExitCode.BAD_INPUT and out == ""
        assert err.count("\n") == 1 and err.startswith(expected)
