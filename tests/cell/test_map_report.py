"""The placement map and the cell in the report."""

from __future__ import annotations

import csv
import dataclasses
from pathlib import Path

import numpy as np
import pytest

from trackplan.cli import main
from trackplan.io.case_file import load_case
from trackplan.planning.plan import plan
from trackplan.report.figures import plot_figures
from trackplan.report.robot_view import CAPSULES_TRACE, CLOSEST_TRACE, robot_view_figure
from trackplan.search.placement_map import REASONS, placement_map

REPO = Path(__file__).resolve().parents[2]
CELL_CASE = REPO / "cases" / "paper-corner-cell.yaml"
OPTIMUM = np.array([0.2191, 0.1099, 0.0023, 0.0001, 0.3293, 1.1243])


@pytest.fixture(scope="module")
def case():
    loaded = load_case(CELL_CASE)
    task = dataclasses.replace(loaded.task, sample_time=0.005)  # fewer samples, same path
    return dataclasses.replace(loaded, task=task)


def test_map_collisions_are_the_cell_only_difference(case) -> None:
    with_cell = placement_map(case, OPTIMUM, n_points=13)
    without = placement_map(dataclasses.replace(case, cell=None), OPTIMUM, n_points=13)
    collision = REASONS.index("collision")
    feasible = REASONS.index("feasible")
    assert (with_cell.reason == collision).any()
    assert not (without.reason == collision).any()
    # a placement collides exactly where it is feasible without the cell and not with it
    np.testing.assert_array_equal(
        with_cell.reason == collision,
        (without.reason == feasible) & (with_cell.reason != feasible),
    )
    both = with_cell.reason == feasible
    assert np.all(without.reason[both] == feasible)
    assert np.all(np.isnan(with_cell.objective[~both]))
    assert np.all(np.isfinite(with_cell.objective[both]))
    # the orientation and height are the reference's
    X = with_cell.placements()
    assert np.all(X[..., 2] == OPTIMUM[2]) and np.all(X[..., 3:] == OPTIMUM[3:])


def test_map_command_writes_png_csv_and_panel(tmp_path: Path, capsys) -> None:
    rpy = [str(v) for v in OPTIMUM[3:]]
    code = main(
        [
            "map",
            str(CELL_CASE),
            "--rpy",
            *rpy,
            "--z",
            str(OPTIMUM[2]),
            "--points",
            "7",
            "--out",
            str(tmp_path),
        ]
    )
    assert code == 0
    assert "placement map" in capsys.readouterr().out
    assert (tmp_path / "map.png").stat().st_size > 0
    assert "data:image/png;base64" in (tmp_path / "map.html").read_text(encoding="utf-8")
    with (tmp_path / "map.csv").open(encoding="utf-8") as handle:
        rows = list(csv.DictReader(handle))
    assert len(rows) == 49
    assert {row["reason"] for row in rows} <= set(REASONS)
    assert all((row["J"] != "") == (row["reason"] == "feasible") for row in rows)


def test_report_draws_the_cell(case) -> None:
    result = plan(case, OPTIMUM)
    assert result.check.cell is not None and not result.check.cell.success
    assert "clearance.png" in plot_figures(result, case)
    figure = robot_view_figure(result, case, n_frames=5)
    names = [trace.name for trace in figure.data]
    assert {"obstacles", "workpiece", CLOSEST_TRACE, CAPSULES_TRACE} <= set(names)
    capsules = names.index(CAPSULES_TRACE)
    assert all(capsules in frame.traces for frame in figure.frames)
    column = list(figure.frames[0].traces).index(capsules)
    first, last = figure.frames[0].data[column], figure.frames[-1].data[column]
    assert not np.allclose(first.x, last.x)  # the capsules move with the robot
