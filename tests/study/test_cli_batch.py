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

from tests.study.conftest import CASES, six_jobs, write_study
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


@pytest.mark.slow
def test_a_killed_batch_resumes_with_only_the_unfinished_jobs(client, tmp_path: Path) -> None:
    """The CLI on a local cluster of its own is killed (with its workers) after two jobs."""
    file = six_jobs(tmp_path)
    out = tmp_path / "out"
    env = {**os.environ, "PYTHONPATH": str(Path(__file__).resolve().parents[2])}
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
