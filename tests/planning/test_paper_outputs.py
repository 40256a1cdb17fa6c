"""The paper cases' planned outputs at their example placements, pinned.

Speed work on the time law, the joint path and the checker must leave these unchanged
beyond round-off; a deliberate change of the law updates them (and ``docs/paper.md``).
"""

from __future__ import annotations

import pytest

from trackplan.io.case_file import load_case
from trackplan.planning.plan import plan

from .conftest import CASES

PINNED = {
    "paper-line": (4.193, 0.6947451064389432),
    "paper-corner": (7.636, 1.526365196118646),
    "paper-circle": (8.563, 1.4702129617110467),
}
"""Duration (s) and objective J (rad) of each paper case at ``placement.example``."""


@pytest.mark.parametrize("name", sorted(PINNED))
def test_paper_case_outputs_are_unchanged(name):
    case = load_case(CASES / f"{name}.yaml")
    result = plan(case, case.bounds.example)
    duration, objective = PINNED[name]
    assert result.feasible, result.message
    assert result.trajectory.t[-1] == pytest.approx(duration, rel=1e-9, abs=0.0)
    assert result.objective == pytest.approx(objective, rel=1e-9, abs=0.0)
