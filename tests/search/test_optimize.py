"""optimize: reproducibility, budget, Ctrl-C, the final re-check, impossible cases."""

from __future__ import annotations

import multiprocessing
import os
import signal
import threading
from concurrent.futures import BrokenExecutor, Executor, Future, ThreadPoolExecutor
from dataclasses import replace

import numpy as np
import pytest

from tests.conftest import CASES
from trackplan.case import Case, PlacementBounds
from trackplan.errors import CaseError
from trackplan.forking import can_fork, forked_pool
from trackplan.io.case_file import load_case
from trackplan.paths.path_geometry import PathGeometry
from trackplan.paths.specs import LineSpec
from trackplan.planning.plan import plan
from trackplan.planning.result import PlanResult
from trackplan.search import GenerationRecord, SearchResult
from trackplan.search.fitness import PlacementFitness
from trackplan.search.optimize import optimize
from trackplan.search.screening import SeamScreen, code
from trackplan.search.space import SearchSpace
from trackplan.status import Status


@pytest.fixture(scope="module")
def case() -> Case:
    return load_case(CASES / "paper-corner.yaml")


@pytest.fixture(scope="module")
def geometry(case: Case) -> PathGeometry:
    return PathGeometry.from_case(case)


def test_same_seed_same_history_and_result(case: Case, geometry: PathGeometry) -> None:
    runs = [optimize(case, seed=7, budget=400, geometries={(0, False): geometry}) for _ in range(2)]
    first, second = runs
    for key, column in first.history.as_columns().items():
        if key != "wall_time":
            assert np.array_equal(column, second.history.as_columns()[key]), key
    assert np.array_equal(first.X, second.X) and first.branch == second.branch
    assert first.objective == second.objective
    other = optimize(case, seed=8, budget=400, geometries={(0, False): geometry})
    assert not np.array_equal(other.X, first.X)


def test_budget_is_exact_and_the_result_checked(case: Case, geometry: PathGeometry) -> None:
    result = optimize(case, method="ga", budget=100, geometries={(0, False): geometry})
    assert result.evaluations == 100 and result.stop_reason == "budget"
    assert result.history.evaluations.tolist() == [30, 58, 86, 100]
    assert result.generations == 4 and result.method == "ga" and result.seed == 0
    assert result.success and result.status is Status.FEASIBLE
    assert result.final.feasible and result.final.check.success
    assert np.array_equal(result.final.placement, result.X)
    assert result.objective == pytest.approx(result.fitness, rel=5e-3)
    assert np.all(np.diff(result.history.best) <= 0)
    assert result.initial.placement == pytest.approx([case.bounds.reach[0], 0, 0, 0, 0, 0])


@pytest.mark.parametrize("method", ["cmaes", "de", "random", "multistart"])
def test_other_methods_are_reproducible(case: Case, geometry: PathGeometry, method: str) -> None:
    budget = 2150 if method == "multistart" else 150  # multistart: into its first local run
    first, second = (
        optimize(case, method=method, seed=3, budget=budget, geometries={(0, False): geometry})
        for _ in range(2)
    )
    assert first.method == method and first.evaluations == budget
    assert first.success and first.final.check.success
    assert np.array_equal(first.history.best, second.history.best)
    assert np.array_equal(first.X, second.X)


def test_time_weight_with_an_executor(case: Case, geometry: PathGeometry) -> None:
    """Timing candidates in threads gives the same search as timing them in turn."""
    timed = replace(case, objective=replace(case.objective, time_weight=0.1))
    serial = optimize(timed, budget=58, geometries={(0, False): geometry})
    with ThreadPoolExecutor(2) as executor:
        threaded = optimize(timed, budget=58, geometries={(0, False): geometry}, executor=executor)
    assert np.array_equal(serial.history.best, threaded.history.best)
    assert serial.success and np.array_equal(serial.X, threaded.X)
    assert serial.fitness == pytest.approx(serial.objective + 0.1 * serial.final.duration, rel=1e-3)


def test_ctrl_c_keeps_the_best_placement(case: Case, geometry: PathGeometry) -> None:
    seen: list[GenerationRecord] = []

    def progress(record: GenerationRecord) -> None:
        seen.append(record)
        if record.generation == 3:
            raise KeyboardInterrupt

    result = optimize(case, method="ga", progress=progress, geometries={(0, False): geometry})
    assert result.stop_reason == "interrupted"
    assert [r.generation for r in seen] == [1, 2, 3] and result.generations == 3
    assert result.evaluations == seen[-1].evaluations == 86
    assert result.status is Status.INTERRUPTED and not result.success and result.final.success
    assert result.fitness == pytest.approx(seen[-1].best)


def _same_plan(a: PlanResult, b: PlanResult) -> None:
    assert a.status is b.status and a.objective == b.objective and a.branch == b.branch
    assert np.array_equal(a.placement, b.placement)
    assert np.array_equal(a.trajectory.t, b.trajectory.t)
    assert np.array_equal(a.trajectory.q, b.trajectory.q)


@pytest.fixture(scope="module")
def serial_ga(case: Case, geometry: PathGeometry) -> SearchResult:
    return optimize(case, method="ga", budget=100, geometries={(0, False): geometry})


def _worker_pids() -> list[int]:
    return [child.pid for child in multiprocessing.active_children() if child.pid is not None]


@pytest.mark.skipif(not can_fork(), reason="no second core or no fork here")
@pytest.mark.parametrize("signum", [None, signal.SIGINT, signal.SIGTERM])
def test_plans_in_the_background_are_the_same(
    case: Case, geometry: PathGeometry, serial_ga: SearchResult, signum: int | None
) -> None:
    """The before and final plans made in a forked process while the search runs are those
    made here after it. The process ignores Ctrl-C; killed (SIGTERM) during the search, the
    plans are made here."""
    if threading.active_count() > 1:  # e.g. a Dask client's loop, left by a study test
        names = ", ".join(thread.name for thread in threading.enumerate()[1:])
        pytest.skip(f"threads of earlier tests in this process make forking unsafe: {names}")
    sent: list[int] = []

    def progress(record: GenerationRecord) -> None:
        if signum is not None and record.generation == 2:
            sent.extend(_worker_pids())
            for pid in sent:
                os.kill(pid, signum)

    with forked_pool() as pool:
        assert pool is not None
        result = optimize(
            case,
            method="ga",
            budget=100,
            geometries={(0, False): geometry},
            background=pool,
            progress=progress,
        )
        alive = _worker_pids()
    if signum is None:
        assert len(alive) == 1
    else:
        assert len(sent) == 1 and alive == ([] if signum == signal.SIGTERM else sent)
    assert np.array_equal(result.history.best, serial_ga.history.best)
    _same_plan(result.initial, serial_ga.initial)
    _same_plan(result.final, serial_ga.final)
    assert result.success and result.objective == serial_ga.objective


def test_a_broken_background_plans_here(
    case: Case, geometry: PathGeometry, serial_ga: SearchResult
) -> None:
    class Broken(Executor):
        def submit(self, fn, /, *args, **kwargs):  # type: ignore[no-untyped-def]
            job: Future = Future()
            job.set_exception(BrokenExecutor("gone"))
            return job

    result = optimize(
        case, method="ga", budget=100, geometries={(0, False): geometry}, background=Broken()
    )
    _same_plan(result.initial, serial_ga.initial)
    _same_plan(result.final, serial_ga.final)


def test_final_recheck_catches_a_wrong_screening(
    case: Case, geometry: PathGeometry, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Screening that calls an unreachable placement feasible with the best J: the final
    re-check at full Ts rejects it and the next best distinct candidate is returned."""
    planted = np.array([0.8, 0.2, 0.0, 0.0, 0.0, 0.0])  # the path leaves the workspace
    assert not plan(case, planted, geometries={(0, False): geometry}).feasible
    screen = PlacementFitness.screen_seam

    def lying(self: PlacementFitness, X: np.ndarray) -> SeamScreen:
        seam = screen(self, X)
        liar = np.all(np.isclose(X[:, :6], planted), axis=1)[None]
        return replace(
            seam,
            ok=seam.ok | liar,
            objective=np.where(liar, 1e-3, seam.objective),
            violation=np.where(liar, 0.0, seam.violation),
            finding=np.where(liar, code(Status.FEASIBLE), seam.finding),
        )

    monkeypatch.setattr(PlacementFitness, "screen_seam", lying)
    sample = SearchSpace.sample

    def planting(self: SearchSpace, rng: np.random.Generator, n: int) -> np.ndarray:
        drawn = sample(self, rng, n)
        drawn[0] = planted
        return drawn

    monkeypatch.setattr(SearchSpace, "sample", planting)
    result = optimize(case, budget=60, geometries={(0, False): geometry})
    assert result.rejected.shape == (1, 6) and np.allclose(result.rejected[0], planted)
    assert result.success and result.final.check.success
    assert not np.allclose(result.X, planted)
    assert "failed the final check" in result.message


def test_no_candidate_passing_the_check_gives_infeasible(
    case: Case, geometry: PathGeometry, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Every screened-feasible candidate fails the check: the result says infeasible."""
    screen = PlacementFitness.screen_seam

    def everything_feasible(self: PlacementFitness, X: np.ndarray) -> SeamScreen:
        seam = screen(self, X)
        return replace(
            seam,
            ok=np.ones_like(seam.ok),
            # the truly feasible rank last and stay out of the archive
            objective=np.where(seam.ok, 10.0, 1e-3),
            violation=np.zeros_like(seam.violation),
            finding=np.full_like(seam.finding, code(Status.FEASIBLE)),
        )

    monkeypatch.setattr(PlacementFitness, "screen_seam", everything_feasible)
    result = optimize(case, budget=30, seed=1, geometries={(0, False): geometry})
    assert not result.success and result.status is not Status.FEASIBLE
    assert not result.final.feasible and len(result.rejected) >= 1


def test_impossible_case_explains_the_closest_candidate(case: Case) -> None:
    long_line = replace(case, segments=(LineSpec(np.array([3.0, 0.0, 0.0])),))
    result = optimize(long_line, budget=120)
    assert not result.success and result.status is not Status.FEASIBLE
    assert result.final.status.value == "unreachable"
    assert "no feasible placement in 120 evaluations" in result.message
    assert "out of reach" in result.message
    assert np.all(result.history.feasible_share == 0.0)
    assert result.fitness > case.objective.flat_penalty


def test_empty_reach_is_bad_input(case: Case) -> None:
    bounds = case.bounds
    far = PlacementBounds(
        np.r_[np.full(3, 0.9), bounds.lower[3:]],
        np.r_[np.full(3, 1.0), bounds.upper[3:]],
        bounds.reach,
    )
    with pytest.raises(CaseError, match="no placement satisfies the reach constraint"):
        optimize(replace(case, bounds=far))


@pytest.mark.parametrize(
    ("options", "match"),
    [({"method": "pso"}, "method must be one of"), ({"timing": "fast"}, "timing must be one")],
)
def test_bad_options(case: Case, options: dict, match: str) -> None:
    with pytest.raises(CaseError, match=match):
        optimize(case, **options)


@pytest.mark.slow
def test_corner_beats_the_papers_optimum(case: Case, geometry: PathGeometry) -> None:
    """The default search finds a lower J than the paper's published X planned by us."""
    paper = plan(
        case,
        np.array([0.0902, 0.2090, 0.2020, 0.3263, 0.3016, -0.2522]),
        geometries={(0, False): geometry},
    )
    result = optimize(case, geometries={(0, False): geometry})
    assert result.success and result.stop_reason == "converged"
    assert result.objective < paper.objective
    assert result.objective == pytest.approx(result.fitness, rel=5e-3)


def test_multistart_descends_from_its_best_distinct_samples(
    case: Case, geometry: PathGeometry
) -> None:
    """Local runs start from mutually distant good samples and improve on the sampling."""
    from trackplan.search import multistart

    result = optimize(case, method="multistart", seed=2, geometries={(0, False): geometry})
    sampled = result.history.evaluations <= multistart.MULTISTART_SAMPLES
    assert result.success and result.stop_reason == "converged"
    assert result.history.best[~sampled].min() < result.history.best[sampled].min()
    assert result.evaluations <= multistart.MULTISTART_SAMPLES + multistart.MULTISTART_STARTS * (
        multistart.LOCAL_EVALUATIONS + multistart.LOCAL_POPULATION
    )


def test_a_pymoo_algorithm_and_termination_can_be_passed_in(
    case: Case, geometry: PathGeometry
) -> None:
    from pymoo.algorithms.soo.nonconvex.ga import GA

    result = optimize(
        case,
        method=GA(pop_size=20),
        termination=("n_gen", 4),
        seed=1,
        geometries={(0, False): geometry},
    )
    assert result.method == "GA" and result.runs == 1 and result.stop_reason == "custom"
    assert result.evaluations == 80 and result.generations == 4


@pytest.mark.parametrize(("method", "budget"), [("multistart", 2300), ("cmaes", 120), ("ga", 60)])
def test_a_fixed_coordinate_stays_fixed(
    case: Case, geometry: PathGeometry, method: str, budget: int
) -> None:
    """``min = max`` fixes a coordinate: scaled searches (CMA-ES) must not divide by its
    zero span; the multistart budget reaches its local runs."""
    lower, upper = case.bounds.lower.copy(), case.bounds.upper.copy()
    lower[0] = upper[0] = 0.25  # x fixed
    fixed = replace(case, bounds=replace(case.bounds, lower=lower, upper=upper))
    result = optimize(fixed, method=method, budget=budget, geometries={(0, False): geometry})
    assert result.X[0] == 0.25
    assert result.evaluations == budget


def test_scaling_maps_a_fixed_coordinate_to_the_middle() -> None:
    space = SearchSpace(
        lower=np.array([0.2, -1, -1, 0, 0, 0]),
        upper=np.array([0.2, 1, 1, 1, 1, 1]),
        reach=(0.0, 10.0),
        anchor=np.array([0.2, 0, 0, 0, 0, 0]),
    )
    X = np.array([[0.2, 0.5, -1, 0.25, 1, 0]])
    Z = space.to_unit(X)
    np.testing.assert_array_equal(Z, [[0.5, 0.75, 0, 0.25, 1, 0]])
    np.testing.assert_array_equal(space.from_unit(Z), X)
