"""A placement on a bound of the search box is said: the console, result.json, the report."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from tests.conftest import CASES
from trackplan.cli import ExitCode, main
from trackplan.io.case_file import load_case
from trackplan.report.html import report_page
from trackplan.search.optimize import optimize
from trackplan.search.space import BOUND_SHARE, BoundHit, SearchSpace, bounds_note

CORNER = CASES / "paper-corner.yaml"
BUDGET = "300"
"""The corner case's default search with this budget ends with yaw on its lower bound."""


@pytest.fixture(scope="module")
def space() -> SearchSpace:
    return SearchSpace.from_case(load_case(CORNER))


def test_on_a_bound_means_within_a_share_of_the_box_width(space: SearchSpace) -> None:
    width = space.upper - space.lower
    X = 0.5 * (space.lower + space.upper)
    assert space.bound_hits(X) == ()
    X[3] = space.upper[3] - 0.5 * BOUND_SHARE * width[3]  # roll just under its upper bound
    X[0] = space.lower[0] + 0.99 * BOUND_SHARE * width[0]  # x just over its lower bound
    X[4] = space.lower[4] + 2.0 * BOUND_SHARE * width[4]  # pitch: inside, not on it
    hits = space.bound_hits(X)
    assert [(h.variable, h.side) for h in hits] == [("x", "lower"), ("roll", "upper")]
    assert hits[1].bound == space.upper[3] and hits[1].value == X[3]
    assert "roll = " in hits[1].describe() and "upper bound 1.57 rad" in hits[1].describe()


def test_a_variable_the_box_fixes_is_not_reported(space: SearchSpace) -> None:
    lower, upper = space.lower.copy(), space.upper.copy()
    upper[5] = lower[5]  # yaw fixed
    fixed = SearchSpace(lower, upper, space.reach, space.anchor)
    X = 0.5 * (lower + upper)
    assert fixed.bound_hits(X) == ()


def test_the_note_names_the_variable_the_bound_and_the_key_to_widen() -> None:
    note = bounds_note([BoundHit("pitch", "lower", -1.5699, -1.57)])
    assert "pitch = -1.5699 rad is on its lower bound -1.57 rad" in note
    assert "placement.pitch" in note
    assert bounds_note([]) == ""


def test_optimize_says_which_variable_lies_on_which_bound(
    capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    out = tmp_path / "run"
    code = main(["optimize", str(CORNER), "--budget", BUDGET, "--out", str(out), "--no-report"])
    stdout = capsys.readouterr().out
    assert code == ExitCode.OK
    summary = json.loads((out / "result.json").read_text())
    hits = summary["optimizer"]["on_bounds"]
    assert hits, "the scenario: yaw ends on its lower bound"
    X = np.array([summary["placement"][k] for k in ("x", "y", "z", "roll", "pitch", "yaw")])
    space = SearchSpace.from_case(load_case(CORNER))
    assert hits == [hit.as_dict() for hit in space.bound_hits(X)]
    assert {"variable": "yaw", "side": "lower"}.items() <= hits[0].items()
    assert "note: the placement lies on a bound of the search box: yaw = " in " ".join(
        stdout.split()
    )


def test_the_report_says_it_under_the_verdict() -> None:
    case = load_case(CORNER)
    result = optimize(case, budget=int(BUDGET))
    assert result.on_bounds
    info = {"optimizer": {"on_bounds": [hit.as_dict() for hit in result.on_bounds]}}
    page = report_page(result.final, case, [], "", None, info)
    assert '<p id="on-bounds">Note: the placement lies on a bound of the search box' in page
    assert "placement.yaw" in page
    assert 'id="on-bounds"' not in report_page(result.final, case, [], "", None, None)
