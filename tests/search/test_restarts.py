"""Independent restarts: the first run is the single run, later runs only improve it."""

from __future__ import annotations

import numpy as np
import pytest

from tests.conftest import CASES
from trackplan.cli import main
from trackplan.errors import CaseError
from trackplan.io.case_file import load_case
from trackplan.paths.path_geometry import PathGeometry
from trackplan.search.driver import run_seeds
from trackplan.search.optimize import optimize


@pytest.fixture(scope="module")
def case():
    return load_case(CASES / "paper-circle.yaml")


@pytest.fixture(scope="module")
def geometry(case):
    return PathGeometry.from_case(case)


def test_run_seeds_start_with_the_seed_and_are_stable():
    assert run_seeds(5, 1) == [5]
    three = run_seeds(5, 3)
    assert three[0] == 5 and len(set(three)) == 3
    assert run_seeds(5, 6)[:3] == three  # more restarts keep the earlier runs


@pytest.mark.slow  # 4 s of searches
def test_restarts_contain_the_single_run_and_never_do_worse(case, geometry):
    single = optimize(case, seed=2, restarts=1, geometry=geometry)
    several = optimize(case, seed=2, restarts=3, geometry=geometry)
    assert single.runs == 1 and several.runs == 3
    n = len(single.history)
    np.testing.assert_array_equal(several.history.best[:n], single.history.best)
    assert several.fitness <= single.fitness
    assert several.evaluations > single.evaluations
    assert np.all(np.diff(several.history.best) <= 0)  # the best so far, over all runs
    again = optimize(case, seed=2, restarts=3, geometry=geometry)
    np.testing.assert_array_equal(again.X, several.X)


def test_budget_spans_the_runs(case, geometry):
    result = optimize(case, seed=0, restarts=50, budget=700, geometry=geometry)
    assert result.evaluations == 700 and result.stop_reason == "budget"


def test_bad_restarts(case, tmp_path, capsys):
    with pytest.raises(CaseError, match="restarts"):
        optimize(case, restarts=0)
    text = (CASES / "paper-circle.yaml").read_text().replace("seed: 0", "seed: 0\n  restarts: 0")
    file = tmp_path / "bad.yaml"
    file.write_text(text)
    assert main(["validate", str(file)]) == 2
    assert "optimizer.restarts" in capsys.readouterr().err
