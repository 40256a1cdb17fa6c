"""A real cluster: ``dask scheduler`` and two ``dask worker`` processes on 127.0.0.1.

``trackplan batch --scheduler`` runs a study on it; one worker is killed while it runs a
job. Every job must still complete (on the other worker), and every run folder must pass
the project's checker when its trajectory is re-checked from the files.
"""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time
from collections.abc import Iterator
from pathlib import Path

import numpy as np
import pytest

from tests.conftest import REPO
from tests.study.conftest import six_jobs
from tests.study.test_cli_batch import free_port
from trackplan.io.results import read_trajectory_csv
from trackplan.io.study_file import load_study
from trackplan.planning.plan import check
from trackplan.study import read_summary_csv

pytestmark = pytest.mark.slow

START_TIMEOUT_S = 120
BATCH_TIMEOUT_S = 300


def _start(*args: str) -> subprocess.Popen:
    """A ``python -m dask ...`` process in its own process group (killed with its children)."""
    env = {**os.environ, "PYTHONPATH": str(REPO)}
    return subprocess.Popen(
        [sys.executable, "-m", "dask", *args],
        env=env,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
        start_new_session=True,
    )


def _stop(process: subprocess.Popen) -> None:
    if process.poll() is None:
        os.killpg(process.pid, signal.SIGKILL)
    process.wait(timeout=30)


@pytest.fixture
def cluster() -> Iterator[tuple[str, list[subprocess.Popen]]]:
    """The scheduler's address and the two worker processes."""
    from distributed import Client

    address = f"tcp://127.0.0.1:{free_port()}"
    port = address.rsplit(":", 1)[1]
    scheduler = _start("scheduler", "--host", "127.0.0.1", "--port", port, "--no-dashboard")
    worker_args = ("--nthreads", "1", "--no-dashboard", "--preload", "trackplan.study.preload")
    workers = [_start("worker", address, *worker_args) for _ in range(2)]
    try:
        with Client(address, timeout=START_TIMEOUT_S) as client:
            client.wait_for_workers(2, timeout=START_TIMEOUT_S)
        yield address, workers
    finally:
        for process in [*workers, scheduler]:
            _stop(process)


def test_batch_on_a_cluster_survives_a_killed_worker(cluster, tmp_path: Path) -> None:
    from distributed import Client

    address, _ = cluster
    file = six_jobs(tmp_path)
    out = tmp_path / "out"
    command = ["batch", str(file), "--out", str(out), "--no-report", "--scheduler", address]
    batch = subprocess.Popen(
        [sys.executable, "-m", "trackplan", *command],
        env={**os.environ, "PYTHONPATH": str(REPO)},
        stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT,
        start_new_session=True,
    )
    try:
        with Client(address, timeout=30) as client:
            victim, lost = _kill_a_busy_worker(client, out)
            killed = time.time()
        stdout, _ = batch.communicate(timeout=BATCH_TIMEOUT_S)
    finally:
        _stop(batch)
    log = stdout.decode()
    assert batch.returncode in (0, 3), log
    study = load_study(file)
    rows = read_summary_csv(out / "summary.csv")
    assert [row.job for row in rows] == [job.key for job in study.jobs], log
    assert not any(row.failed for row in rows), log
    for row in rows:
        finished = (out / "jobs" / row.job / "job.json").stat().st_mtime
        if row.job in lost and finished > killed:  # the dead worker's jobs ran again elsewhere
            assert row.worker != victim
    assert any(row.job in lost and row.worker != victim for row in rows)
    for job in study.jobs:
        folder = out / "jobs" / job.key
        t, q = read_trajectory_csv(folder / "trajectory.csv", job.case.robot.n_dof)
        row = next(row for row in rows if row.job == job.key)
        placement = json.loads((folder / "result.json").read_text())["placement"]
        X = [placement[key] for key in ("x", "y", "z", "roll", "pitch", "yaw")]
        report = check(job.case, np.array(X), q, float(t[1] - t[0]))
        assert report.success == row.success, (job.key, [v.message for v in report.violations])
        assert report.max_tracking_error == pytest.approx(row.tracking_error_m, rel=1e-9)


def _kill_a_busy_worker(client, out: Path) -> tuple[str, set[str]]:  # type: ignore[no-untyped-def]
    """Once a job has finished, SIGKILL a worker (and its nanny) that holds a job now.

    Returns its address and the jobs it held.
    """
    deadline = time.monotonic() + BATCH_TIMEOUT_S
    while True:
        assert time.monotonic() < deadline, "no job finished in time"
        done = list((out / "jobs").glob("*/job.json")) if (out / "jobs").is_dir() else []
        busy = {worker: keys for worker, keys in client.processing().items() if keys}
        if done and busy:
            break
        time.sleep(0.1)
    victim, keys = next(iter(busy.items()))
    pid = client.run(os.getpid, workers=[victim])[victim]
    os.killpg(os.getpgid(pid), signal.SIGKILL)
    return victim, {key.rsplit("-", 1)[0] for key in keys}
