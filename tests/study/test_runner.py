"""run_study on an in-process Dask cluster: rows, run folders, faults, resume, Ctrl-C."""

from __future__ import annotations

import json
import math
from pathlib import Path

import pytest

from tests.conftest import CASES
from tests.study.conftest import UNREACHABLE_CASE, six_jobs, write_study
from trackplan.errors import CaseError
from trackplan.io.study_file import load_study
from trackplan.status import Status
from trackplan.study import StudyProgress, read_summary_csv, run_study
from trackplan.study.runner import MAX_RETRIES
from trackplan.study.summary import IGNORED_UNLESS_BROKEN


def test_six_jobs_summary_rows_match_each_runs_result_json(client, tmp_path: Path) -> None:
    study = load_study(six_jobs(tmp_path))
    seen: list[StudyProgress] = []
    result = run_study(study, tmp_path / "out", client, report=False, progress=seen.append)
    assert result.n_jobs == 6 and result.status is (
        Status.FEASIBLE
        if result.success
        else next(row.status for row in result.rows if not row.success)
    )
    assert [row.job for row in result.rows] == [job.key for job in study.jobs]
    assert result.rows == tuple(read_summary_csv(tmp_path / "out" / "summary.csv"))
    for job, row in zip(study.jobs, result.rows, strict=True):
        folder = tmp_path / "out" / "jobs" / job.key
        written = json.loads((folder / "result.json").read_text())
        assert (row.case, row.robot, row.sweep, row.seed) == (
            job.case_label,
            "puma560",
            "base",
            job.seed,
        )
        assert row.status is Status(written["status"]) and row.success == written["feasible"]
        assert row.J == written["objective"] and row.duration_s == written["duration"]
        assert row.tracking_error_m == written["max_tracking_error"]
        assert written["optimizer"]["seed"] == job.seed
        assert written["optimizer"]["evaluations"] == 20
        margins = [
            value
            for kind, entry in written["margins"].items()
            for value in (entry.values() if isinstance(entry, dict) else [entry])
            if kind not in IGNORED_UNLESS_BROKEN or value < 0
        ]
        assert row.worst_margin == min(margins)
        samples = (folder / "trajectory.csv").read_text().count("\n") - 1
        assert row.cycle_time_s == pytest.approx((samples - 1) * written["sample_time"])
        assert row.wall_time_s > 0 and row.worker.startswith("inproc://")
        assert sorted(p.name for p in folder.iterdir()) == [
            "history.csv",
            "job.json",
            "result.json",
            "trajectory.csv",
        ]
    assert result.success == all(row.success for row in result.rows)
    assert seen[-1].done == 6 and seen[-1].failed == 0
    assert [s.done for s in seen if s.last is not None] == [1, 2, 3, 4, 5, 6]
    page = (tmp_path / "out" / "summary.html").read_text()
    assert 'id="feasibility-matrix"' in page and "paper-circle__puma560__base__s2" in page
    assert client.run_on_scheduler(_allowed_failures) == MAX_RETRIES


def _allowed_failures(dask_scheduler=None) -> int:  # type: ignore[no-untyped-def]
    return dask_scheduler.allowed_failures


def test_a_job_that_raises_is_recorded_failed_and_the_rest_complete(client, tmp_path: Path) -> None:
    (tmp_path / "out-of-reach.yaml").write_text(UNREACHABLE_CASE)
    file = write_study(
        tmp_path,
        f"cases: ['{CASES}/paper-circle.yaml', out-of-reach.yaml]\nseeds: [0, 1]\n",
    )
    result = run_study(file, tmp_path / "out", client, report=False)
    failed = [row for row in result.rows if row.failed]
    assert [row.job for row in failed] == [
        "out-of-reach__puma560__base__s0",
        "out-of-reach__puma560__base__s1",
    ]
    for row in failed:
        assert row.message.startswith("CaseError: ") and "reach" in row.message
        assert math.isnan(row.J) and row.status is Status.FAILED
        assert not (tmp_path / "out" / "jobs" / row.job).exists()
        assert "Traceback" in (tmp_path / "out" / "errors" / f"{row.job}.txt").read_text()
    others = [row for row in result.rows if not row.failed]
    assert len(others) == 2 and all(math.isfinite(row.J) for row in others)
    assert not result.success and result.n_failed == 2 and result.status is Status.FAILED
    assert "2 failed" in result.message
    assert len(read_summary_csv(tmp_path / "out" / "summary.csv")) == 4


def test_resume_reruns_only_the_unfinished_jobs(client, tmp_path: Path) -> None:
    study = load_study(six_jobs(tmp_path))
    out = tmp_path / "out"
    run_study(study, out, client, report=False)
    with pytest.raises(CaseError, match="add --resume"):
        run_study(study, out, client, report=False)
    jobs = out / "jobs"
    kept = {job.key: (jobs / job.key / "job.json").stat().st_mtime_ns for job in study.jobs}
    lost = [study.jobs[1].key, study.jobs[4].key]
    for key in lost:  # as a killed batch leaves them: half written, under a temporary name
        (jobs / key).rename(jobs / f".{key}.0123abcd.partial")
        (jobs / f".{key}.0123abcd.partial" / "job.json").unlink()
        del kept[key]
    seen: list[StudyProgress] = []
    result = run_study(study, out, client, resume=True, report=False, progress=seen.append)
    assert result.n_skipped == 4 and seen[0].skipped == 4
    assert sorted(s.last.job for s in seen if s.last is not None) == sorted(lost)
    for key, mtime in kept.items():
        assert (jobs / key / "job.json").stat().st_mtime_ns == mtime
    assert sorted(p.name for p in jobs.iterdir()) == sorted(job.key for job in study.jobs)
    assert [row.job for row in result.rows] == [job.key for job in study.jobs]
    assert "4 skipped (already complete)" in result.message


def test_ctrl_c_cancels_the_pending_jobs_and_writes_the_summary(client, tmp_path: Path) -> None:
    study = load_study(six_jobs(tmp_path))

    def interrupt(state: StudyProgress) -> None:
        if state.last is not None:
            raise KeyboardInterrupt

    result = run_study(study, tmp_path / "out", client, report=False, progress=interrupt)
    assert result.status is Status.INTERRUPTED and not result.success
    assert 1 <= len(result.rows) < 6 and result.n_cancelled == 6 - len(result.rows)
    assert read_summary_csv(tmp_path / "out" / "summary.csv") == list(result.rows)
    assert (tmp_path / "out" / "summary.html").is_file()
    assert f"{result.n_cancelled} cancelled" in result.message


class _CancelledFuture:
    """What a Dask future of a cancelled task answers."""

    status = "cancelled"

    def cancelled(self) -> bool:
        return True

    def exception(self) -> BaseException:
        raise AssertionError("a cancelled task has no exception to wait for")


def test_a_cancelled_task_is_a_failed_row(tmp_path: Path) -> None:
    from trackplan.study.runner import _row

    (job,) = load_study(write_study(tmp_path, f"cases: ['{CASES}/paper-circle.yaml']\n")).jobs
    row = _row(_CancelledFuture(), job)  # type: ignore[arg-type]  # a stand-in future
    assert row.status is Status.FAILED and row.failed and row.message == "cancelled"
    assert row.job == job.key and math.isnan(row.J)
