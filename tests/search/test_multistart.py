"""multistart's local runs (the cmaes package), their race, its run under a pymoo termination,
and what the search imports."""

from __future__ import annotations

import subprocess
import sys

import numpy as np
import pytest

from tests.conftest import CASES
from trackplan.io.case_file import load_case
from trackplan.paths.path_geometry import PathGeometry
from trackplan.search import multistart
from trackplan.search.multistart import LocalRun, MultiStartSearch
from trackplan.search.optimize import optimize
from trackplan.search.space import SearchSpace


def _descend(run: LocalRun, centre: np.ndarray) -> list[np.ndarray]:
    """Run on a shifted sphere until it stops; every generation asked."""
    asked = []
    while not run.stopped:
        Z = run.ask()
        asked.append(Z)
        run.tell(np.sum((Z - centre) ** 2, axis=1))
    return asked


def test_the_cma_class_is_cmaes_own() -> None:
    import cmaes

    assert multistart.cmaes_cma() is cmaes.CMA


def test_local_run_descends_a_sphere_inside_the_unit_box() -> None:
    centre = np.array([0.55, 0.45, 0.5, 0.6, 0.4, 0.5])
    run = LocalRun(np.full(6, 0.35), seed=3)
    asked = _descend(run, centre)
    assert all(np.all((Z >= 0.0) & (Z <= 1.0)) for Z in asked)
    assert run.evaluations <= multistart.LOCAL_EVALUATIONS
    assert run.evaluations == multistart.LOCAL_POPULATION * len(asked)
    # from a start 0.15 off in every variable (f = 0.135) to the floor
    assert run.best < 1e-6


def test_local_run_is_reproducible_from_its_seed() -> None:
    centre = np.full(6, 0.5)
    first, second, other = (LocalRun(np.full(6, 0.3), seed=s) for s in (11, 11, 12))
    a, b, c = _descend(first, centre), _descend(second, centre), _descend(other, centre)
    assert len(a) == len(b) and all(np.array_equal(x, y) for x, y in zip(a, b, strict=True))
    assert not np.array_equal(a[0], c[0])


def test_local_run_stops_when_the_fitness_is_flat() -> None:
    run = LocalRun(np.full(6, 0.5), seed=1)
    while not run.stopped:
        run.ask()
        run.tell(np.full(multistart.LOCAL_POPULATION, 0.25))
    assert run.evaluations < multistart.LOCAL_EVALUATIONS


def test_the_race_stops_the_runs_that_fell_behind() -> None:
    search = MultiStartSearch(SearchSpace.from_case(load_case(CASES / "paper-corner.yaml")))
    runs = [LocalRun(np.full(6, 0.5), seed=s) for s in range(4)]
    margin = multistart.RACE_MARGIN
    # leader, close behind, far behind, far behind but too young to judge
    for run, best, generations in zip(
        runs,
        (1.0, 1.0 + 0.5 * margin, 1.0 + 2 * margin, 1.0 + 2 * margin),
        (9, 9, multistart.RACE_GENERATIONS, multistart.RACE_GENERATIONS - 1),
        strict=True,
    ):
        run.best, run.generations = best, generations
    search.runs = runs
    search._asking = runs
    search._race()
    assert [run.dropped for run in runs] == [False, False, True, False]
    assert [run.stopped for run in runs] == [False, False, True, False]


def test_a_pymoo_termination_runs_the_same_search_as_a_pymoo_algorithm() -> None:
    """Given a pymoo termination, multistart runs as a pymoo Algorithm (AskTellAlgorithm):
    its generations are those of the search without pymoo, draw for draw, until the
    termination stops it."""
    case = load_case(CASES / "paper-corner.yaml")
    geometry = PathGeometry.from_case(case)
    n_gen = multistart.MULTISTART_SAMPLES // multistart.MULTISTART_BATCH + 4  # 4 local ones
    alone = optimize(case, seed=3, geometry=geometry)
    stopped = optimize(case, seed=3, geometry=geometry, termination=("n_gen", n_gen))
    assert stopped.stop_reason == "custom" and stopped.generations == n_gen < alone.generations
    for key in ("evaluations", "best", "mean", "feasible_share"):
        np.testing.assert_array_equal(
            getattr(stopped.history, key), getattr(alone.history, key)[:n_gen]
        )


@pytest.mark.slow
def test_the_search_imports_neither_cma_nor_matplotlib_nor_scipy_stats() -> None:
    """cma imports matplotlib.pyplot and scipy.stats (2 s on an idle machine), the cmaes
    package's __init__ scipy.stats: the default search needs none of them."""
    code = (
        "import sys; import trackplan.cli.app; "
        "from trackplan.io.case_file import load_case; "
        "from trackplan.search import multistart; from trackplan.search.optimize import optimize; "
        f"case = load_case({str(CASES / 'paper-line.yaml')!r}); "
        "r = optimize(case, budget=multistart.MULTISTART_SAMPLES + 30); "
        "assert r.history.evaluations[-1] > multistart.MULTISTART_SAMPLES; "
        "print(sorted(m for m in ('cma', 'matplotlib', 'scipy.stats') if m in sys.modules))"
    )
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    assert done.stdout.strip() == "[]"


def test_the_method_modules_import_one_way() -> None:
    """algorithms.py may reach pymoo_algorithms.py (for CMA-ES), never the reverse: no cycle."""
    import ast
    import inspect

    from trackplan.search import pymoo_algorithms

    tree = ast.parse(inspect.getsource(pymoo_algorithms))
    imported = {
        node.module for node in ast.walk(tree) if isinstance(node, ast.ImportFrom) and node.module
    }
    assert "trackplan.search.algorithms" not in imported
    assert "trackplan.search.multistart" in imported
