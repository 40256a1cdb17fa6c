"""Objectives by name, the Pareto front, and ``optimize --pareto``."""

from __future__ import annotations

import csv
import dataclasses
from pathlib import Path

import numpy as np
import pytest

from trackplan.cli import ExitCode, main
from trackplan.errors import CaseError
from trackplan.io.case_file import load_case
from trackplan.planning.objectives import KINDS, OBJECTIVES, plan_objective
from trackplan.search.pareto import nondominated, pareto_front, parse_objective_pair

CASES = Path(__file__).resolve().parents[2] / "cases"


@pytest.fixture(scope="module")
def corner():
    return load_case(CASES / "paper-corner.yaml")


def test_registry_names():
    assert KINDS == ("travel", "time", "energy", "copper", "weighted")
    assert [name for name, spec in OBJECTIVES.items() if spec.needs_dynamics] == [
        "energy",
        "copper",
    ]


def test_objective_kind_in_the_case_file(tmp_path: Path):
    text = (CASES / "paper-corner.yaml").read_text(encoding="utf-8")
    file = tmp_path / "case.yaml"
    file.write_text(
        text.replace(
            "objective:\n", "objective:\n  kind: weighted\n  mix: {travel: 1, copper: 0.1}\n"
        ),
        encoding="utf-8",
    )
    objective = load_case(file).objective
    assert (objective.kind, objective.mix) == ("weighted", {"travel": 1.0, "copper": 0.1})
    for bad, message in [
        ("  kind: weighted\n", "objective.kind: weighted needs objective.mix"),
        ("  kind: weighted\n  mix: {work: 1}\n", "objective.mix.work: unknown objective 'work'"),
        ("  mix: {time: 1}\n", "objective.mix: mix is only used with kind: weighted"),
    ]:
        file.write_text(text.replace("objective:\n", "objective:\n" + bad), encoding="utf-8")
        with pytest.raises(CaseError) as error:
            load_case(file)
        assert error.value.one_line().startswith(f"{file}: {message}")
    ur5 = text.replace("robot: puma560", "robot: ur5").replace(
        "objective:\n", "objective:\n  kind: copper\n"
    )
    file.write_text(ur5, encoding="utf-8")
    with pytest.raises(CaseError, match="copper needs joint torques, but robot ur5"):
        load_case(file)


def test_weighted_objective_of_a_plan(corner, corner_plan_for_objectives):
    plan = corner_plan_for_objectives
    weighted = dataclasses.replace(
        corner.objective, kind="weighted", mix={"travel": 2.0, "time": 0.5, "copper": 0.1}
    )
    expected = 2.0 * plan.objective + 0.5 * plan.duration + 0.1 * plan.energy.copper_loss
    assert plan_objective(weighted, plan) == pytest.approx(expected, rel=1e-12)


@pytest.fixture(scope="module")
def corner_plan_for_objectives(corner):
    from trackplan.planning.plan import plan as plan_placement

    return plan_placement(corner, corner.bounds.example)


def test_single_objective_search_screens_copper_close_to_the_plan(
    corner, corner_plan_for_objectives
):
    """The quasi-static copper estimate on the screening grid is within 30 % of the planned
    value at the paper's placement (the plan is slower than the least time at corners)."""
    from trackplan.paths.path_geometry import PathGeometry
    from trackplan.search.fitness import PlacementFitness
    from trackplan.search.space import SearchSpace

    case = dataclasses.replace(
        corner, objective=dataclasses.replace(corner.objective, kind="copper")
    )
    fitness = PlacementFitness(
        case, SearchSpace.from_case(case), PathGeometry.from_case(case), "smooth"
    )
    screened = fitness.evaluate(corner.bounds.example[None, :])
    planned = corner_plan_for_objectives.energy.copper_loss
    assert screened.feasible[0]
    assert 0.7 * planned < screened.objective[0] <= 1.05 * planned


def test_nondominated():
    values = np.array([[1.0, 5.0], [2.0, 3.0], [2.5, 4.0], [3.0, 1.0], [0.5, 0.5]])
    feasible = np.array([True, True, True, True, False])
    np.testing.assert_array_equal(nondominated(values, feasible), [True, True, False, True, False])


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("travel", "--pareto: expected two different objectives A,B"),
        ("travel,travel", "--pareto: expected two different objectives A,B"),
        ("travel,work", "--pareto: unknown objective 'work'"),
        ("travel,copper,time", "--pareto: expected two different objectives A,B"),
    ],
)
def test_bad_pareto_pairs(text: str, message: str):
    with pytest.raises(CaseError) as error:
        parse_objective_pair(text)
    assert error.value.one_line().startswith(message)


def test_bad_pareto_pair_exits_2(capsys: pytest.CaptureFixture[str], tmp_path: Path):
    code = main(
        ["optimize", str(CASES / "paper-corner.yaml"), "--pareto", "copper", "--out", str(tmp_path)]
    )
    err = capsys.readouterr().err
    assert code == ExitCode.BAD_INPUT
    assert err.strip().splitlines() == [
        "--pareto: expected two different objectives A,B (of travel, time, energy, copper), "
        "got 'copper'"
    ]


@pytest.mark.slow
def test_pareto_front_end_to_end(corner, tmp_path: Path, capsys: pytest.CaptureFixture[str]):
    """A small travel–copper front: every point re-planned and checked, the files written,
    and the travel-optimal end uses more copper than the copper-optimal end."""
    small = dataclasses.replace(
        corner, optimizer=dataclasses.replace(corner.optimizer, population=16)
    )
    result = pareto_front(small, ("travel", "copper"), generations=8)
    assert result.success and len(result.plans) == len(result.X) >= 2
    for plan, values in zip(result.plans, result.values, strict=True):
        assert plan.feasible == plan.check.success
        assert values[0] == pytest.approx(plan.objective)
        assert values[1] == pytest.approx(plan.energy.copper_loss)
    front = result.values[result.nondominated]
    assert np.all(np.diff(front[:, 0]) >= 0) and np.all(np.diff(front[:, 1]) <= 0)
    code = main(
        [
            "optimize",
            str(CASES / "paper-corner.yaml"),
            "--pareto",
            "travel,copper",
            "--out",
            str(tmp_path),
            "--no-report",
        ]
    )
    assert code == ExitCode.OK
    with open(tmp_path / "pareto.csv", encoding="utf-8") as stream:
        rows = list(csv.DictReader(stream))
    assert rows and {"x", "travel", "copper", "feasible", "nondominated"} <= set(rows[0])
    assert (tmp_path / rows[0]["folder"] / "result.json").is_file()


def test_objective_option(capsys: pytest.CaptureFixture[str], tmp_path: Path):
    """``--objective`` picks a registered objective; unknown names and torque objectives on a
    robot without dynamics are one line and exit 2."""
    from trackplan.planning.objectives import with_objective

    case = load_case(CASES / "paper-corner.yaml")
    assert with_objective(case, "copper").objective.kind == "copper"
    for args, message in [
        (("paper-corner.yaml", "work"), "--objective: unknown objective 'work'"),
        (("ur5-bead.yaml", "energy"), "--objective: energy needs joint torques, but robot ur5"),
    ]:
        code = main(
            ["optimize", str(CASES / args[0]), "--objective", args[1], "--out", str(tmp_path)]
        )
        err = capsys.readouterr().err.strip().splitlines()
        assert code == ExitCode.BAD_INPUT and len(err) == 1 and err[0].startswith(message)
