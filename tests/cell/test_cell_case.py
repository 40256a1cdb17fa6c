"""The shipped cell case end to end: the unconstrained optimum collides, the search avoids it."""

from __future__ import annotations

import json
import re
from pathlib import Path

import numpy as np
import pytest

from trackplan.cli import main
from trackplan.io.case_file import load_case
from trackplan.search.optimize import optimize
from trackplan.status import Status

REPO = Path(__file__).resolve().parents[2]
CELL_CASE = REPO / "cases" / "paper-corner-cell.yaml"
UNCONSTRAINED_OPTIMUM = ("0.2191", "0.1099", "0.0023", "0.0001", "0.3293", "1.1243")
"""``trackplan optimize cases/paper-corner.yaml`` (seed 0): the best placement without the cell."""


@pytest.mark.slow
def test_plan_at_the_unconstrained_optimum_reports_the_collision(
    capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    code = main(
        [
            "plan",
            str(CELL_CASE),
            "--placement",
            *UNCONSTRAINED_OPTIMUM,
            "--out",
            str(tmp_path),
            "--no-report",
        ]
    )
    out = capsys.readouterr().out
    assert code == 3
    # which link, which obstacle, when, how deep
    found = re.search(r"collision: (link \d) hits (\w+) ([\d.]+) mm deep at t = ([\d.]+) s", out)
    assert found is not None, out
    link, obstacle, depth, _ = found.groups()
    assert (link, obstacle) == ("link 2", "table")
    assert float(depth) > 10.0
    closest = json.loads((tmp_path / "result.json").read_text(encoding="utf-8"))["min_clearance"]
    assert closest["distance"] == pytest.approx(-float(depth) / 1e3, abs=1e-4)
    assert (closest["robot_body"], closest["other_body"]) == ("link 2", "table")
    assert "min clearance = " in out


@pytest.mark.slow
def test_optimize_finds_a_collision_free_placement() -> None:
    case = load_case(CELL_CASE)
    result = optimize(case)
    plan = result.final
    assert plan.feasible and plan.status is Status.FEASIBLE
    cell = plan.check.cell
    assert cell is not None
    assert cell.success and cell.min_clearance >= case.cell.clearance  # exact check of the plan
    assert np.all(cell.distance >= case.cell.clearance - 1e-9)
    assert plan.check.task_margins["clearance"] >= 0.0
