"""The batched fitness (Eq. 30): screening, branch choice, ordering of infeasible candidates."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from tests.conftest import CASES
from trackplan.case import Case
from trackplan.frames import tool_poses
from trackplan.io.case_file import load_case
from trackplan.paths.path_geometry import PathGeometry
from trackplan.planning.objectives import joint_travel
from trackplan.planning.plan import plan as plan_placement
from trackplan.robots.path_ik import solve_path_ik, solve_path_ik_branches
from trackplan.search.fitness import (
    CURVED_POSES,
    PlacementFitness,
    screening_grid,
)
from trackplan.search.screening import code
from trackplan.search.space import SearchSpace
from trackplan.status import Status

PAPER_X = np.array([0.0902, 0.2090, 0.2020, 0.3263, 0.3016, -0.2522])
"""The paper's Case 3 optimum (Section 4)."""
GOOD_X = np.array([-0.0896, -0.1998, -0.0157, 0.0, 0.3835, -1.2381])
"""A placement of the corner case with low J (found by the search)."""


@pytest.fixture(scope="module")
def case() -> Case:
    return load_case(CASES / "paper-corner.yaml")


@pytest.fixture(scope="module")
def geometry(case: Case) -> PathGeometry:
    return PathGeometry.from_case(case)


def _fitness(case: Case, geometry: PathGeometry, timing: str = "smooth") -> PlacementFitness:
    return PlacementFitness(case, SearchSpace.from_case(case), geometry, timing)


def test_screening_grid_covers_the_blend(geometry: PathGeometry) -> None:
    s = screening_grid(geometry)
    assert 100 <= len(s) <= 200
    assert s[0] == 0.0 and s[-1] == pytest.approx(geometry.planned.length)
    for s0, s1, kind in geometry.planned.zones:
        assert np.any(np.isclose(s, s0))
        if kind == "curved":
            assert np.count_nonzero((s >= s0 - 1e-12) & (s <= s1 + 1e-12)) >= CURVED_POSES


def test_every_branch_matches_the_single_branch_solver(case: Case, geometry: PathGeometry, rng):
    space = SearchSpace.from_case(case)
    X = np.vstack([PAPER_X, GOOD_X, space.sample(rng, 10)])
    poses = tool_poses(
        X,
        geometry.planned.sample(screening_grid(geometry)).position,
        case.task.tool.base_rotations(np.zeros((1, 3)))[0],
    )
    branches = solve_path_ik_branches(case.robot, poses)
    assert branches.q.shape == (12, 8, poses.shape[1], 6)
    for k in range(8):
        single = solve_path_ik(case.robot, poses, branch=k)
        assert np.array_equal(single.success, branches.success[:, k])
        assert np.array_equal(single.reachable, branches.reachable[:, k])
        assert np.allclose(single.q, branches.q[:, k], equal_nan=True)
        assert np.array_equal(single.margin, branches.margin[:, k])


def test_branch_with_the_least_travel_is_chosen(case: Case, geometry: PathGeometry) -> None:
    fitness = _fitness(case, geometry)
    result = fitness.evaluate(np.vstack([PAPER_X, GOOD_X]))
    assert result.feasible.all()
    poses = tool_poses(np.vstack([PAPER_X, GOOD_X]), fitness.points, fitness.R_base)
    for i in range(2):
        travels = []
        for k in range(8):
            single = solve_path_ik(case.robot, poses[i : i + 1], branch=k)
            if single.success[0]:
                travels.append((joint_travel(single.q[0], case.objective.weights), k))
        assert (result.objective[i], result.branch[i]) == pytest.approx(min(travels))
    assert result.fitness == pytest.approx(result.objective)


@pytest.mark.parametrize("X", [PAPER_X, GOOD_X], ids=["paper optimum", "searched optimum"])
def test_screened_travel_matches_the_full_plan(
    case: Case, geometry: PathGeometry, X: np.ndarray
) -> None:
    screened = _fitness(case, geometry).evaluate(X[None])
    plan = plan_placement(
        case, X, branch=int(screened.branch[0]), geometries={(0, False): geometry}
    )
    assert plan.feasible
    assert screened.objective[0] == pytest.approx(plan.objective, rel=5e-3)


def test_every_feasible_ranks_before_every_infeasible(case: Case, geometry: PathGeometry, rng):
    fitness = _fitness(case, geometry)
    X = rng.uniform(case.bounds.lower, case.bounds.upper, size=(400, 6))
    result = fitness.evaluate(X)
    feasible = result.feasible
    assert 0 < feasible.sum() < len(X)
    assert result.fitness[feasible].max() < result.fitness[~feasible].min()
    assert np.all(result.fitness[~feasible] > case.objective.flat_penalty)
    assert np.all(np.isnan(result.objective[~feasible]))
    assert np.all(result.violation[feasible] == 0.0) and np.all(result.violation[~feasible] > 0)
    reach = result.finding == code(Status.REACH)
    geometric = np.isin(result.finding, [code(Status.UNREACHABLE), code(Status.BRANCH_SWITCH)])
    assert reach.any() and geometric.any()
    assert result.fitness[geometric].max() < result.fitness[reach].min()


def test_graded_violation_grows_away_from_feasibility(case: Case, geometry: PathGeometry):
    """Sliding the path away from the robot: more poses out of reach, a worse fitness."""
    fitness = _fitness(case, geometry)
    X = np.tile(GOOD_X, (5, 1))
    X[:, 1] -= np.array([0.0, 0.45, 0.5, 0.55, 0.6])  # y towards the outer reach
    result = fitness.evaluate(X)
    assert result.feasible[0] and not result.feasible[1:].any()
    assert np.all(np.diff(result.fitness[1:]) > 0)
    outside = fitness.evaluate(np.array([[0.7, 0.7, 0.0, 0, 0, 0], [0.8, 0.8, 0.0, 0, 0, 0]]))
    assert np.all(outside.finding == code(Status.REACH)) and outside.fitness[0] < outside.fitness[1]


def test_flat_penalty_is_the_papers_constant(case: Case, geometry: PathGeometry, rng) -> None:
    flat = replace(case, objective=replace(case.objective, penalty="flat", flat_penalty=1e3))
    result = _fitness(flat, geometry).evaluate(rng.uniform(-0.87, 0.87, size=(100, 6)))
    assert np.all(result.fitness[~result.feasible] == 1e3)


def test_time_weight_adds_the_duration(case: Case, geometry: PathGeometry) -> None:
    timed = replace(case, objective=replace(case.objective, time_weight=0.1))
    fitness = _fitness(timed, geometry)
    result = fitness.evaluate(np.vstack([GOOD_X, PAPER_X]))
    assert np.all(result.feasible) and np.all(np.isfinite(result.duration))
    assert result.fitness == pytest.approx(result.objective + 0.1 * result.duration)
    # a candidate that cannot beat the incumbent is not timed: its fitness is a lower bound
    lazy = fitness.evaluate(PAPER_X[None], incumbent=1.0)
    assert np.isnan(lazy.duration[0])
    bound = lazy.duration_bound[0]
    assert lazy.fitness[0] == pytest.approx(lazy.objective[0] + 0.1 * bound)
    assert geometry.planned.length / case.task.rated_speed <= bound < result.duration[1]
