"""The shipped cases whose seams come from a STEP part alone (issue 34's acceptance): each
plans feasibly at its example placement and passes the project's checker on a fresh check
of its joints; the positioner cases weld downhand at every sample."""

from __future__ import annotations

from pathlib import Path

import pytest

import trackplan

CASES = Path(__file__).parents[2] / "cases"


@pytest.mark.slow
@pytest.mark.parametrize("name", ["cad-pipe-flange", "cad-pipe-saddle", "cad-t-joint"])
def test_a_cad_case_plans_feasibly_and_passes_the_checker(name: str) -> None:
    case = trackplan.load_case(CASES / f"{name}.yaml")
    assert case.source is not None
    result = trackplan.plan(case, case.bounds.example)
    assert result.success, result.message
    trajectory = result.trajectory
    report = trackplan.check(
        case, result.placement, trajectory.q, trajectory.sample_time, segment=result.segment
    )
    assert report.success, [v.message for v in report.violations]
    if case.downhand is not None:
        assert report.downhand is not None and report.downhand.share == 1.0
