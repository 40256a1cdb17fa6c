"""The search space and the GA operators that reproduce MATLAB's ga (paper, Section 4)."""

from __future__ import annotations

import numpy as np
import pytest
from pymoo.core.population import Population
from pymoo.core.problem import Problem

from tests.conftest import CASES
from trackplan.case import PlacementBounds
from trackplan.errors import CaseError
from trackplan.io.case_file import load_case
from trackplan.search.operators import (
    AdaptiveFeasibleMutation,
    EliteSurvival,
    MatlabMating,
    ReachRepair,
    ScatteredCrossover,
    StallTermination,
    StochasticUniformSelection,
    elite_count,
    rank_scaled_expectation,
    stochastic_uniform,
)
from trackplan.search.space import SearchSpace, box_distance_range


@pytest.fixture(scope="module")
def space() -> SearchSpace:
    """The paper's search space (Eq. 31, 32)."""
    return SearchSpace.from_case(load_case(CASES / "paper-corner.yaml"))


def _bounds(xyz_low: float, xyz_high: float, reach: tuple[float, float]) -> PlacementBounds:
    lower = np.array([xyz_low] * 3 + [-1.0] * 3)
    upper = np.array([xyz_high] * 3 + [1.0] * 3)
    return PlacementBounds(lower, upper, reach)


def test_box_distance_range() -> None:
    assert box_distance_range([-1, -1, -1], [1, 1, 1]) == pytest.approx((0.0, np.sqrt(3)))
    assert box_distance_range([0.9, 0.9, 0.9], [1, 1, 1]) == pytest.approx(
        (np.sqrt(3) * 0.9, np.sqrt(3))
    )
    assert box_distance_range([-2, 1, 0], [-1, 3, 0]) == pytest.approx((np.sqrt(2), np.sqrt(13)))


@pytest.mark.parametrize(
    ("low", "high", "reach"),
    [(0.9, 1.0, (0.15, 0.85)), (-0.05, 0.05, (0.15, 0.85))],
    ids=["box beyond the reach", "box inside the inner radius"],
)
def test_bounds_without_admissible_placement_are_bad_input(
    low: float, high: float, reach: tuple[float, float]
) -> None:
    with pytest.raises(CaseError, match="no placement satisfies the reach constraint") as error:
        SearchSpace.from_bounds(_bounds(low, high, reach), "case.yaml")
    assert error.value.key == "placement.reach" and error.value.file == "case.yaml"


def test_anchor_is_the_admissible_point_nearest_the_centre(space: SearchSpace) -> None:
    # the paper's box is centred on the base origin, inside the inner reach radius
    assert space.anchor == pytest.approx([space.reach[0], 0, 0, 0, 0, 0])
    off_centre = SearchSpace.from_bounds(_bounds(0.5, 0.7, (0.1, 0.9)))
    assert np.linalg.norm(off_centre.anchor[:3]) == pytest.approx(0.9)
    assert off_centre.anchor[:3] == pytest.approx(np.full(3, 0.9 / np.sqrt(3)))


def test_sampling_and_repair_stay_admissible(space: SearchSpace, rng) -> None:
    X = space.sample(rng, 500)
    assert X.shape == (500, 6) and space.contains(X).all()
    wild = rng.uniform(-3, 3, size=(500, 6))
    repaired = space.repair(wild)
    assert space.contains(repaired).all()
    inside = space.contains(wild)
    assert np.array_equal(repaired[inside], wild[inside])
    thin = SearchSpace.from_bounds(_bounds(0.3, 0.6, (0.85, 0.86)))
    assert thin.contains(thin.repair(rng.uniform(-1, 1, size=(200, 6)))).all()
    assert thin.contains(thin.sample(rng, 50)).all()


def test_rank_scaling_is_proportional_to_one_over_root_rank() -> None:
    fitness = np.array([3.0, 1.0, 2.0, 1e6, 5.0])
    expectation = rank_scaled_expectation(fitness, 8)
    ranks = np.array([3, 1, 2, 5, 4])
    assert expectation.sum() == pytest.approx(8)
    assert expectation == pytest.approx(8 / np.sqrt(ranks) / np.sum(1 / np.sqrt(ranks)))


def test_stochastic_uniform_selects_in_proportion_to_the_expectation(rng) -> None:
    fitness = rng.permutation(30).astype(float)
    expectation = rank_scaled_expectation(fitness, 50)
    counts = np.zeros(30)
    for _ in range(2000):
        chosen = stochastic_uniform(expectation, 50, rng)
        once = np.bincount(chosen, minlength=30)
        # stochastic universal sampling: each individual floor(e) or ceil(e) times
        assert np.all(once >= np.floor(expectation) - 1e-9)
        assert np.all(once <= np.ceil(expectation) + 1e-9)
        counts += once
    assert counts / 2000 == pytest.approx(expectation, abs=0.03)


class _Box(Problem):
    def __init__(self, space: SearchSpace):
        super().__init__(n_var=6, n_obj=1, xl=space.lower, xu=space.upper)


class _Algorithm:
    """What the operators read from a pymoo algorithm."""

    def __init__(self, pop: Population):
        self.pop = pop


def _population(X: np.ndarray, F: np.ndarray) -> Population:
    pop = Population.new("X", X)
    pop.set("F", F[:, None])
    return pop


def test_mating_makes_matlab_counts_of_admissible_children(space: SearchSpace, rng) -> None:
    assert elite_count(30) == 2 and elite_count(20) == 1
    pop = _population(space.sample(rng, 30), rng.random(30))
    mutation = AdaptiveFeasibleMutation(space)
    mating = MatlabMating(
        StochasticUniformSelection(), ScatteredCrossover(), mutation, 0.8, ReachRepair(space)
    )
    for generation in range(6):
        children = mating.do(_Box(space), pop, 28, random_state=rng, algorithm=_Algorithm(pop))
        assert len(children) == 28  # 22 crossover children (round(0.8 · 28)), 6 mutation
        assert space.contains(children.get("X")).all()
        F = pop.get("F")[:, 0]
        pop = _population(children.get("X")[:28].copy(), F[:28] * (1 + generation))
    assert mutation.step < 1.0  # no improvement in the later generations: the step shrank


def test_scattered_crossover_takes_each_gene_from_a_parent(rng) -> None:
    X = rng.random((2, 50, 6))
    child = ScatteredCrossover()._do(None, X, random_state=rng)[0]
    assert np.all((child == X[0]) | (child == X[1]))
    assert 0.3 < np.mean(child == X[0]) < 0.7


def test_mutation_step_adapts_like_matlab(space: SearchSpace) -> None:
    mutation = AdaptiveFeasibleMutation(space)
    steps = [mutation.adapt(best) for best in (5.0, 4.0, 4.0, 4.0, 3.0, 3.0)]
    assert steps == pytest.approx([1.0, 1.0, 0.25, 0.0625, 0.25, 0.0625])


def test_elite_survival_keeps_the_best_parents(space: SearchSpace, rng) -> None:
    parents = _population(space.sample(rng, 10), np.arange(10.0)[::-1])
    children = _population(space.sample(rng, 8), np.full(8, 100.0))
    survivors = EliteSurvival(2).do(
        _Box(space),
        Population.merge(parents, children),
        n_survive=10,
        algorithm=_Algorithm(parents),
    )
    assert len(survivors) == 10
    assert survivors.get("F")[:2, 0] == pytest.approx([0.0, 1.0])
    assert np.array_equal(survivors.get("X")[2:], children.get("X"))


@pytest.mark.parametrize(
    ("best", "stops_at"),
    [
        (np.r_[1e6, np.full(80, 2.0)], 52),  # no change for 50 generations
        (2.0 - 0.01 * np.arange(80), None),  # 0.5 over 50 generations: still improving
        (np.r_[2.0 - 0.001 * np.arange(60), np.full(20, 1.941)], 51),  # 0.05 / 50 / 1.95 ≤ 1e-3
    ],
)
def test_stall_termination(best: np.ndarray, stops_at: int | None) -> None:
    termination = StallTermination(50, 1e-3)
    stopped = None
    for generation, value in enumerate(best, start=1):
        algorithm = _Algorithm(_population(np.zeros((1, 6)), np.array([value])))
        if termination.update(algorithm) >= 1.0:
            stopped = generation
            break
    assert stopped == stops_at
