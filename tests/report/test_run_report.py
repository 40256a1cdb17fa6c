"""A run's plots and report.html: the same files whether they are drawn in two processes, in
turn or by a plot worker, and a failure anywhere is raised by the caller."""

from __future__ import annotations

import dataclasses
import os
import signal
import threading

import numpy as np
import pytest

from tests.report.conftest import REPORT_FRAMES, REPORT_INFO, optimizer_history
from trackplan import forking
from trackplan.report import figures, path_plots, run_report, speed_plot
from trackplan.report.figure_style import BandedFigure, figure_pixels
from trackplan.report.joints_plot import JOINT_BANDS, joints_figure
from trackplan.report.path_plots import path_figure, plot_kinematics
from trackplan.report.plot_worker import PlotWorker, plot_worker
from trackplan.report.run_report import can_fork, write_run_report
from trackplan.report.speed_plot import speed_figure

needs_fork = pytest.mark.skipif(
    not can_fork(), reason="no second core or no fork here: the plots are drawn in turn"
)
PLOTS = ["joints.png", "path.png", "speed.png", "convergence.png"]


def _write(out_dir, corner, corner_result, **options):
    """The files of a run's report, by name."""
    history = optimizer_history(np.random.default_rng(7))
    plots, report = write_run_report(
        corner_result, corner, out_dir, history, REPORT_INFO, n_frames=REPORT_FRAMES, **options
    )
    assert [p.name for p in plots] == PLOTS
    return {p.name: p.read_bytes() for p in [*plots, report]}


@pytest.fixture(scope="module")
def serial(tmp_path_factory, corner, corner_result):
    return _write(tmp_path_factory.mktemp("serial"), corner, corner_result, parallel=False)


def _assert_same(files, serial):
    assert files.keys() == serial.keys()
    for name, data in files.items():
        assert data == serial[name], name


@needs_fork
def test_forked_and_serial_reports_are_the_same_files(tmp_path, corner, corner_result, serial):
    files = _write(tmp_path, corner, corner_result, parallel=True)
    _assert_same(files, serial)


def _not_here(*args, **kwargs):
    raise AssertionError("the plots were drawn in the caller")


@needs_fork
def test_a_plot_worker_writes_the_same_files(tmp_path, monkeypatch, corner, corner_result, serial):
    monkeypatch.setattr(run_report, "draw_plots", _not_here)
    with plot_worker() as worker:
        assert worker is not None
        os.kill(worker.pid, signal.SIGINT)  # ignored: the caller decides about interruptions
        files = _write(tmp_path, corner, corner_result, worker=worker)
    _assert_same(files, serial)
    with pytest.raises(ChildProcessError):  # it ended and was collected
        os.waitpid(worker.pid, os.WNOHANG)


@needs_fork
def test_the_plots_are_drawn_here_when_the_worker_is_gone(tmp_path, corner, corner_result, serial):
    worker = PlotWorker.start()
    assert worker is not None
    os.kill(worker.pid, signal.SIGKILL)
    files = _write(tmp_path, corner, corner_result, worker=worker)
    _assert_same(files, serial)


def test_bands_stack_into_the_full_joints_figure(corner, corner_result):
    full = figure_pixels(joints_figure(corner_result, corner))
    bands = [figure_pixels(joints_figure(corner_result, corner, rows)) for rows in JOINT_BANDS]
    assert len(bands) > 1
    stacked = np.concatenate(bands)
    assert stacked.shape == full.shape
    np.testing.assert_array_equal(stacked, full)  # to the pixel


def _broken_plots(corner, corner_result):
    def broken():
        raise ValueError("no figure for you")

    return {"broken.png": broken, "joints.png": lambda: joints_figure(corner_result, corner)}


@needs_fork
def test_a_plot_failing_in_the_forked_process_raises_in_the_caller(
    tmp_path, monkeypatch, corner, corner_result
):
    builders = _broken_plots(corner, corner_result)
    monkeypatch.setattr(run_report, "plot_figures", lambda *args: builders)
    with pytest.raises(ValueError, match="no figure for you"):
        write_run_report(corner_result, corner, tmp_path, n_frames=5)
    assert (tmp_path / "joints.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert not (tmp_path / "report.html").exists()


@needs_fork
def test_a_plot_failing_in_the_worker_raises_in_the_caller(
    tmp_path, monkeypatch, corner, corner_result
):
    builders = _broken_plots(corner, corner_result)
    monkeypatch.setattr(figures, "plot_figures", lambda *args: builders)  # the worker's
    monkeypatch.setattr(run_report, "plot_figures", lambda *args: builders)
    with plot_worker() as worker, pytest.raises(ValueError, match="no figure for you"):
        write_run_report(corner_result, corner, tmp_path, n_frames=5, worker=worker)
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


def test_no_fork_and_no_worker_on_one_core(monkeypatch):
    monkeypatch.setattr(forking.os, "sched_getaffinity", lambda pid: {0})
    assert not can_fork()
    assert PlotWorker.start() is None
    with forking.forked_pool() as pool:
        assert pool is None


def test_the_plots_drawn_with_given_kinematics_start_no_kernel(monkeypatch, corner, corner_result):
    """Given the run's PlotKinematics (as a plot worker is), drawing the plots calls none of
    the functions that run numba's kernels, and the path and speed plots are the pixels of
    those that compute their kinematics themselves."""
    kinematics = plot_kinematics(corner_result, corner)
    builders = figures.plot_figures(corner_result, corner, None, kinematics)
    pixels = {}
    with monkeypatch.context() as patched:
        for module, kernel in (
            (path_plots, "carrier_tool_frames"),
            (path_plots, "carrier_chain_points"),
            (path_plots, "tracking_error"),
            (speed_plot, "tracking_error"),
        ):
            patched.setattr(module, kernel, _not_here)
        for name, plot in builders.items():
            bands = plot.bands if isinstance(plot, BandedFigure) else (plot,)
            pixels[name] = [figure_pixels(build()) for build in bands]
    assert list(pixels) == ["joints.png", "path.png", "speed.png"]
    itself = {
        "path.png": path_figure(corner_result, corner),
        "speed.png": speed_figure(corner_result, corner),
    }
    for name, figure in itself.items():
        np.testing.assert_array_equal(pixels[name][0], figure_pixels(figure), name)


def _wild(corner_result):
    """The corner result with jerks a thousand times larger (symlog panels)."""
    trajectory = corner_result.trajectory
    return dataclasses.replace(
        corner_result, trajectory=dataclasses.replace(trajectory, qddd=1000 * trajectory.qddd)
    )


@pytest.mark.slow  # 8.5 s: the fast tier keeps the other report tests
@pytest.mark.parametrize("which", ["planted violation", "symlog jerk", "no trajectory"])
def test_plots_on_blank_figures_made_beforehand_are_the_same_pixels(
    which, corner, corner_result, unreachable_result
):
    """A plot worker draws on figures made before the result came (blank_canvases): the
    same pixels as figures made when the plot is drawn, whatever the panels' scales."""
    result = {
        "planted violation": corner_result,
        "symlog jerk": _wild(corner_result),
        "no trajectory": unreachable_result,
    }[which]
    history = optimizer_history(np.random.default_rng(7))
    kinematics = plot_kinematics(result, corner)
    canvases = figures.blank_canvases(corner.robot.n_dof)
    on_blanks = figures.plot_figures(result, corner, history, kinematics, canvases)
    fresh = figures.plot_figures(result, corner, history, kinematics)
    assert on_blanks.keys() == fresh.keys()
    for name, plot in on_blanks.items():
        if isinstance(plot, BandedFigure):
            pairs = zip(plot.bands, fresh[name].bands, strict=True)  # type: ignore[union-attr]
        else:
            pairs = zip([plot], [fresh[name]], strict=True)
        for build_on_blank, build_fresh in pairs:
            np.testing.assert_array_equal(
                figure_pixels(build_on_blank()), figure_pixels(build_fresh()), name
            )
    assert canvases == {}  # every blank figure was taken
