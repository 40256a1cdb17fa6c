"""A run's plots and report.html: the same files whether the first plot is drawn in a forked
process or in turn, and a failure in the forked process is raised by the caller."""

from __future__ import annotations

import threading

import pytest

from tests.report.conftest import REPORT_FRAMES, REPORT_INFO
from trackplan.report import run_report
from trackplan.report.figures import joints_figure
from trackplan.report.run_report import can_fork, write_run_report

needs_fork = pytest.mark.skipif(
    not can_fork(), reason="no second core or no fork here: the plots are drawn in turn"
)


@needs_fork
def test_forked_and_serial_reports_are_the_same_files(tmp_path, corner, corner_result, history):
    outputs = {}
    for parallel in (True, False):
        plots, report = write_run_report(
            corner_result,
            corner,
            tmp_path / str(parallel),
            history,
            REPORT_INFO,
            parallel=parallel,
            n_frames=REPORT_FRAMES,
        )
        assert [p.name for p in plots] == ["joints.png", "path.png", "speed.png", "convergence.png"]
        outputs[parallel] = {p.name: p.read_bytes() for p in [*plots, report]}
    assert outputs[True].keys() == outputs[False].keys()
    for name, data in outputs[True].items():
        assert data == outputs[False][name], name


@needs_fork
def test_a_plot_failing_in_the_forked_process_raises_in_the_caller(
    tmp_path, monkeypatch, corner, corner_result
):
    def broken():
        raise ValueError("no figure for you")

    builders = {"broken.png": broken, "joints.png": lambda: joints_figure(corner_result, corner)}
    monkeypatch.setattr(run_report, "plot_figures", lambda *args: builders)
    with pytest.raises(ValueError, match="no figure for you"):
        write_run_report(corner_result, corner, tmp_path, n_frames=5)
    assert (tmp_path / "joints.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert not (tmp_path / "report.html").exists()


def test_no_fork_beside_other_python_threads():
    seen = []
    thread = threading.Thread(target=lambda: seen.append(can_fork()))
    release = threading.Event()
    waiter = threading.Thread(target=release.wait)
    waiter.start()
    try:
        thread.start()
        thread.join()
    finally:
        release.set()
        waiter.join()
    assert seen == [False]


def test_no_fork_on_one_core(monkeypatch):
    monkeypatch.setattr(run_report.os, "sched_getaffinity", lambda pid: {0})
    assert not can_fork()
