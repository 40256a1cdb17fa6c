"""``trackplan batch``: bad input is one line and exit 2; a batch killed and resumed."""

from __future__ import annotations

import json
import os
import signal
import socket
import subprocess
import sys
import time
from pathlib import Path

import pytest

from tests.conftest import CASES, REPO
from tests.study.conftest import six_jobs, write_study
from trackplan.cli import ExitCode, main
from trackplan.io.study_file import load_study
from trackplan.study import read_summary_csv, run_study


def run(capsys: pytest.CaptureFixture[str], *args: str) -> tuple[int, str, str]:
    code = main(list(args))
    captured = capsys.readouterr()
    return code, captured.out, captured.err


def free_port() -> int:
    """A TCP port on 127.0.0.1 that nothing listens on (just released)."""
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        return int(probe.getsockname()[1])


@pytest.mark.parametrize(
    ("text", "where"),
    [
        (f"cases: ['{CASES}/nothing-*.yaml']\n", "cases[0]: "),
        (f"cases: ['{CASES}/paper-line.yaml']\nrobots: [nope]\n", "robots[0]: unknown robot"),
        (f"cases: ['{CASES}/paper-line.yaml']\nset:\n  task.speed: [1]\n", "set.task.speed: "),
    ],
)
def test_bad_study_is_one_line_and_exit_2(
    capsys: pytest.CaptureFixture[str], tmp_path: Path, text: str, where: str
) -> None:
    file = write_study(tmp_path, text, tiny=False)
    code, out, err = run(capsys, "batch", str(file), "--out", str(tmp_path / "out"))
    assert code == ExitCode.BAD_INPUT and out == ""
    assert err.count("\n") == 1 and err.startswith(f"{file}: {where}")
    assert not (tmp_path / "out").exists()


def test_unreachable_scheduler_names_the_address(
    capsys: pytest.CaptureFixture[str], tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setattr("trackplan.study.runner.CONNECT_TIMEOUT_S", 1.0)
    address = f"tcp://127.0.0.1:{free_port()}"
    file = six_jobs(tmp_path)
    code, _, err = run(capsys, "batch", str(file), "--scheduler", address)
    assert code == ExitCode.BAD_INPUT and err.count("\n") == 1
    assert err.startswith(f"--scheduler: no Dask scheduler answers at {address} within 1 s")


def test_workers_and_scheduler_together_are_refused(
    capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    file = six_jobs(tmp_path)
    code, _, err = run(
        capsys, "batch", str(file), "--workers", "2", "--scheduler", "tcp://127.0.0.1:1"
    )
    assert code == ExitCode.BAD_INPUT and "give --workers or --scheduler, not both" in err


def _two_jobs(folder: Path) -> Path:
    return write_study(folder, f"cases: ['{CASES}/paper-circle.yaml']\nseeds: [0, 1]\n")


def test_batch_prints_a_line_per_job_and_the_outcome(
    capsys: pytest.CaptureFixture[str], client, tmp_path: Path
) -> None:
    out = tmp_path / "out"
    address = client.scheduler.address  # the in-process cluster: reachable from this process
    args = ("batch", str(_two_jobs(tmp_path)), "--out", str(out), "--scheduler", address)
    code, stdout, _ = run(capsys, *args, "--no-report")
    rows = read_summary_csv(out / "summary.csv")
    assert code == (ExitCode.OK if all(row.success for row in rows) else ExitCode.INFEASIBLE)
    lines = stdout.splitlines()
    assert [line[:6] for line in lines[:2]] == ["[1/2] ", "[2/2] "]
    printed = {line[6:].split(": ")[0]: line for line in lines[:2]}
    assert sorted(printed) == sorted(row.job for row in rows)
    for row in rows:
        assert f": {row.status.value} (" in printed[row.job] and row.worker in printed[row.job]
    assert lines[2].startswith("study: 2 jobs: ") and f"summary in {out}" in lines[3]
    code, _, err = run(capsys, *args)
    assert code == ExitCode.BAD_INPUT and "add --resume" in err


def test_batch_draws_a_progress_bar_on_a_terminal(
    capsys: pytest.CaptureFixture[str],
    client,
    tmp_path: Path,
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    from rich.progress import Progress

    monkeypatch.setenv("TTY_COMPATIBLE", "1")  # rich draws the bar as on a terminal
    update = Progress.update
    states: list[tuple[object, object, object]] = []

    def record(self: Progress, task: object, **fields: object) -> None:
        states.append((fields.get("completed"), fields.get("total"), fields.get("failed")))
        update(self, task, **fields)

    monkeypatch.setattr(Progress, "update", record)
    out = tmp_path / "out"
    args = ("batch", str(_two_jobs(tmp_path)), "--out", str(out), "--no-report")
    code, stdout, _ = run(capsys, *args, "--scheduler", client.scheduler.address)
    assert code in (ExitCode.OK, ExitCode.INFEASIBLE)
    assert states[-1] == (2, 2, 0) and (1, 2, 0) in states
    assert "[1/2]" not in stdout and "study: 2 jobs" in stdout


@pytest.mark.slow
def test_a_killed_batch_resumes_with_only_the_unfinished_jobs(client, tmp_path: Path) -> None:
    """The CLI on a local cluster of its own is killed (with its workers) after two jobs."""
    file = six_jobs(tmp_path)
    out = tmp_path / "out"
    env = {**os.environ, "PYTHONPATH": str(REPO)}
    command = [sys.executable, "-m", "trackplan", "batch", str(file), "--out", str(out)]
    batch = subprocess.Popen(
        [*command, "--workers", "1", "--no-report"],
        env=env,
        stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT,
        start_new_session=True,  # its own process group: the workers die with it
    )
    try:
        deadline = time.monotonic() + 120
        while _finished(out) < 2:
            assert batch.poll() is None, batch.stdout.read().decode() if batch.stdout else ""
            assert time.monotonic() < deadline, "two jobs did not finish within 120 s"
            time.sleep(0.1)
    finally:
        os.killpg(batch.pid, signal.SIGKILL)
        batch.wait(timeout=30)
    study = load_study(file)
    finished = {
        job.key: json.loads((out / "jobs" / job.key / "job.json").read_text())
        for job in study.jobs
        if (out / "jobs" / job.key / "job.json").is_file()
    }
    assert 2 <= len(finished) < 6
    result = run_study(study, out, client, resume=True, report=False)
    assert result.n_skipped == len(finished)
    assert [row.job for row in result.rows] == [job.key for job in study.jobs]
    for row in result.rows:
        if row.job in finished:  # kept as the killed batch wrote them
            assert row.worker == finished[row.job]["worker"]
            assert row.worker.startswith("tcp://")
        else:
            assert row.worker.startswith("inproc://")
    assert read_summary_csv(out / "summary.csv") == list(result.rows)


def _finished(out: Path) -> int:
    """Complete run folders in a study's output folder."""
    jobs = out / "jobs"
    return len(list(jobs.glob("*/job.json"))) if jobs.is_dir() else 0


def test_resuming_over_a_run_folder_with_an_unknown_status_is_one_line_and_exit_2(
    capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    study_file = write_study(tmp_path, f"cases: ['{CASES}/paper-circle.yaml']\nseeds: [0]\n")
    (job,) = load_study(study_file).jobs
    folder = tmp_path / "out" / "jobs" / job.key
    folder.mkdir(parents=True)
    (folder / "job.json").write_text(
        json.dumps({**job.describe(), "wall_time_s": 1.0, "worker": "w"})
    )
    (folder / "result.json").write_text(json.dumps({"status": "great", "feasible": True}))
    code, stdout, err = run(
        capsys, "batch", str(study_file), "--out", str(tmp_path / "out"), "--resume"
    )
    assert code == ExitCode.BAD_INPUT and stdout == ""
    assert err.count("\n") == 1 and "Traceback" not in err
    assert f"{folder / 'result.json'}: status: unknown status 'great'" in err
