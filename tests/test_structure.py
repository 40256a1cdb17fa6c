"""The core's structure: one pose and IK pass per plan, imports pointing down, the front door."""

from __future__ import annotations

import ast
import importlib
import subprocess
import sys

import numpy as np
import pytest

import trackplan
import trackplan.jointpath as jointpath
from tests.conftest import CASES, REPO
from trackplan.choices import Penalty
from trackplan.errors import CaseError


def test_a_plan_makes_one_pose_pass_and_one_ik_pass_on_its_grid(monkeypatch):
    calls: list[tuple[str, int]] = []
    real_poses, real_ik = jointpath.tool_poses, jointpath.solve_path_ik
    real_parts, real_branch = jointpath.tool_pose_parts, jointpath.branch_joints_along

    def poses(X, positions, R_part_tool):
        calls.append(("poses", len(positions)))
        return real_poses(X, positions, R_part_tool)

    def ik(robot, T, *args, **kwargs):
        calls.append(("ik", T.shape[1]))
        return real_ik(robot, T, *args, **kwargs)

    def parts(X, positions, R_part_tool):  # the samples: rotations and positions only
        calls.append(("poses", len(positions)))
        return real_parts(X, positions, R_part_tool)

    def branch_ik(robot, R, p, *args, **kwargs):  # the samples: their branch only
        calls.append(("ik", len(p)))
        return real_branch(robot, R, p, *args, **kwargs)

    monkeypatch.setattr(jointpath, "tool_poses", poses)
    monkeypatch.setattr(jointpath, "solve_path_ik", ik)
    monkeypatch.setattr(jointpath, "tool_pose_parts", parts)
    monkeypatch.setattr(jointpath, "branch_joints_along", branch_ik)
    case = trackplan.load_case(CASES / "paper-corner.yaml")
    result = trackplan.plan(case, case.bounds.example)
    assert result.success, result.message
    n_grid = 5 * len(result.joint_path.s)  # every grid point with its stencil
    assert calls[:2] == [("poses", n_grid), ("ik", n_grid)]
    # after the grid, only the trajectory samples are mapped (once per rebuild of the law)
    n_samples = result.trajectory.n_samples
    assert len(calls) > 2
    assert all(n == n_samples for _, n in calls[2:])
    assert [kind for kind, _ in calls[2:]] == ["poses", "ik"] * (len(calls[2:]) // 2)


def test_timing_imports_nothing_from_planning():
    for module in (REPO / "trackplan" / "timing").glob("*.py"):
        tree = ast.parse(module.read_text())
        for node in ast.walk(tree):
            names = []
            if isinstance(node, ast.ImportFrom) and node.module:
                names = [node.module]
            elif isinstance(node, ast.Import):
                names = [alias.name for alias in node.names]
            for name in names:
                assert not name.startswith(("trackplan.planning", "trackplan.search")), (
                    f"{module.name} imports {name}"
                )


def test_the_five_line_notebook_use_works():
    code = (
        "import trackplan\n"
        f"case = trackplan.load_case({str(CASES / 'paper-corner.yaml')!r})\n"
        "result = trackplan.plan(case, case.bounds.example)\n"
        "print(result.status.value, round(result.duration, 3))\n"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    status, duration = out.stdout.split()
    assert status == "feasible" and float(duration) > 0


FRONT_DOOR = {
    "load_case",
    "load_robot",
    "builtin_robot",
    "plan",
    "optimize",
    "check",
    "export",
    "study",
    "Case",
    "Robot",
    "PlanResult",
    "SearchResult",
    "CheckReport",
    "StudyResult",
    "Status",
    "TrackplanError",
    "CaseError",
}


def test_the_front_door_is_the_verbs_and_their_result_types():
    assert set(trackplan.__all__) == FRONT_DOOR | {"__version__"}
    assert len(trackplan.__all__) <= 20
    verbs = {"load_case", "load_robot", "builtin_robot", "plan", "optimize", "check", "export"}
    for name in sorted(FRONT_DOOR):
        value = getattr(trackplan, name)
        assert callable(value), name
        assert name in verbs | {"study"} or isinstance(value, type), name
    assert issubclass(trackplan.CaseError, trackplan.TrackplanError)
    assert trackplan.export is importlib.import_module("trackplan.writers").export


def test_the_study_verb_is_the_callable_study_package(monkeypatch):
    # importing a submodule binds the package to trackplan.study: the package is the verb
    import trackplan.study.runner as runner

    assert trackplan.study is sys.modules["trackplan.study"]
    calls = []
    monkeypatch.setattr("trackplan.study.runner.study", lambda *a, **k: calls.append((a, k)))
    trackplan.study("spec.yaml", "out", workers=1)
    assert calls == [(("spec.yaml", "out"), {"workers": 1})]
    assert runner.run_study is sys.modules["trackplan.study.runner"].run_study


def test_a_name_outside_the_front_door_and_the_deprecations_is_no_attribute():
    with pytest.raises(AttributeError, match="no attribute 'plan_everything'"):
        trackplan.plan_everything  # noqa: B018


@pytest.mark.parametrize("name", sorted(trackplan._DEPRECATED))
def test_an_old_name_warns_with_its_new_home_and_resolves(name):
    module, attribute, instead = trackplan._DEPRECATED[name]
    with pytest.warns(DeprecationWarning, match=instead or module) as record:
        value = getattr(trackplan, name)
    assert record[0].filename == __file__  # the warning points at the caller
    assert value is getattr(importlib.import_module(module), attribute)
    if instead == "trackplan.study":  # the callable package calls runner.study
        assert value is sys.modules["trackplan.study.runner"].study
    elif instead:  # a renamed name resolves to the front door's name
        assert value is getattr(trackplan, instead.removeprefix("trackplan."))
    assert name not in vars(trackplan)  # not cached: every use warns


def test_every_name_exported_before_the_front_door_is_kept_or_deprecated():
    before = {
        *("BUILTIN_ROBOTS", "OBJECTIVES", "TIME_LAWS", "AirMove", "Case", "CaseError"),
        *("CheckReport", "CycleResult", "CycleSearchResult", "EnergyFigures", "JointPath"),
        *("Method", "OptimizeResult", "ParetoResult", "Payload", "Penalty", "PlanResult"),
        *("Robot", "RobotDynamics", "Sequence", "Status", "TimeLaw", "Timing"),
        *("TrackplanError", "Trajectory", "Visit", "air_time_estimate", "best_sequence"),
        *("builtin_names", "builtin_robot", "check_case_trajectory", "check_cycle_trajectory"),
        *("check_trajectory", "energy_figures", "forward_kinematics", "given_sequence"),
        *("gravity_load", "inverse_dynamics", "jacobian", "load_case", "load_robot"),
        *("optimize_cycle", "optimize_placement", "pareto_front", "plan_air_move"),
        *("plan_cycle", "plan_placement", "run_study", "sequence_cost", "time_law"),
        *("trapezoid_time", "optimize_spin", "ToolSpec", "placement_map", "PlacementMap"),
        *("CellReport", "Cell"),
    }
    assert before <= FRONT_DOOR | set(trackplan._DEPRECATED)
    assert not FRONT_DOOR & set(trackplan._DEPRECATED)


@pytest.mark.parametrize(
    ("call", "key", "allowed"),
    [
        (
            lambda case: trackplan.plan(case, case.bounds.example, timing="smoooth"),
            "timing",
            "smooth, paper",
        ),
        (
            lambda case: trackplan.optimize(case, method="gaa", budget=10),
            "method",
            "ga, cmaes, de, random",
        ),
    ],
)
def test_a_wrong_choice_lists_the_allowed_values(call, key, allowed):
    case = trackplan.load_case(CASES / "paper-corner.yaml")
    with pytest.raises(CaseError) as error:
        call(case)
    assert error.value.key == key and allowed in error.value.message


def test_a_penalty_outside_the_vocabulary_is_refused():
    case = trackplan.load_case(CASES / "paper-corner.yaml")
    assert [penalty.value for penalty in Penalty] == ["graded", "flat"]  # the enum is public
    with pytest.raises(CaseError, match="graded, flat"):
        type(case.objective)(weights=case.objective.weights, penalty="flatt")


@pytest.mark.parametrize("X", [[0.1, 0.2], [0.1] * 7, [0.1, 0.2, 0.1, 0, 0, np.nan], "abc"])
def test_a_placement_must_be_six_finite_numbers(X):
    case = trackplan.load_case(CASES / "paper-corner.yaml")
    with pytest.raises(CaseError, match="placement"):
        trackplan.plan(case, X)


def test_every_result_spells_success_the_same_way():
    case = trackplan.load_case(CASES / "paper-corner.yaml")
    result = trackplan.plan(case, case.bounds.example)
    assert result.success is result.feasible is result.check.success is True
    assert result.status is trackplan.Status.FEASIBLE and result.status.success
    assert result.joint_path.success and result.joint_path.ik.success.all()


def _layer_names() -> set[str]:
    """Every module or package named in the layer contract of pyproject.toml."""
    import re
    import tomllib

    config = tomllib.loads((REPO / "pyproject.toml").read_text(encoding="utf-8"))
    (layers,) = [
        contract["layers"]
        for contract in config["tool"]["importlinter"]["contracts"]
        if contract["type"] == "layers"
    ]
    return {name for layer in layers for name in re.split(r"[\s:|()]+", layer) if name}


def test_every_module_sits_in_a_layer_of_the_contract():
    # a module in no layer is never checked by lint-imports: a new module must be placed
    named = _layer_names()
    unplaced = []
    for file in sorted((REPO / "trackplan").rglob("*.py")):
        parts = file.relative_to(REPO).with_suffix("").parts
        if parts[-1] == "__init__":
            parts = parts[:-1]
        if len(parts) == 1 or parts == ("trackplan", "__main__"):
            continue  # the package itself, and `python -m trackplan`
        prefixes = {".".join(parts[:k]) for k in range(2, len(parts) + 1)}
        split = file.name == "__init__.py" and any(
            name.startswith(".".join(parts) + ".") for name in named
        )  # a package whose modules sit in several layers: its modules are placed
        if not (prefixes & named or split):
            unplaced.append(".".join(parts))
    assert unplaced == []
