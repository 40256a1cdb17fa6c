"""The core's structure: one pose and IK pass per plan, imports pointing down, the front door."""

from __future__ import annotations

import ast
import subprocess
import sys

import numpy as np
import pytest

import trackplan
import trackplan.jointpath as jointpath
from tests.conftest import CASES, REPO
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

    def branch_ik(robot, R, p, *args):  # the samples: their branch only
        calls.append(("ik", len(p)))
        return real_branch(robot, R, p, *args)

    monkeypatch.setattr(jointpath, "tool_poses", poses)
    monkeypatch.setattr(jointpath, "solve_path_ik", ik)
    monkeypatch.setattr(jointpath, "tool_pose_parts", parts)
    monkeypatch.setattr(jointpath, "branch_joints_along", branch_ik)
    case = trackplan.load_case(CASES / "paper-corner.yaml")
    result = trackplan.plan_placement(case, case.bounds.example)
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
        "result = trackplan.plan_placement(case, case.bounds.example)\n"
        "print(result.status.value, round(result.duration, 3))\n"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    status, duration = out.stdout.split()
    assert status == "feasible" and float(duration) > 0


def test_the_front_door_exports_the_api():
    for name in (
        "plan_placement",
        "optimize_placement",
        "check_trajectory",
        "check_case_trajectory",
        "load_case",
        "load_robot",
        "Status",
    ):
        assert callable(getattr(trackplan, name)) or name == "Status"
    assert set(trackplan.__all__) >= {"plan_placement", "optimize_placement", "load_case"}


@pytest.mark.parametrize(
    ("call", "key", "allowed"),
    [
        (
            lambda case: trackplan.plan_placement(case, case.bounds.example, timing="smoooth"),
            "timing",
            "smooth, paper",
        ),
        (
            lambda case: trackplan.optimize_placement(case, method="gaa", budget=10),
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
    with pytest.raises(CaseError, match="graded, flat"):
        trackplan.Penalty  # noqa: B018  (the enum is public)
        type(case.objective)(weights=case.objective.weights, penalty="flatt")


@pytest.mark.parametrize("X", [[0.1, 0.2], [0.1] * 7, [0.1, 0.2, 0.1, 0, 0, np.nan], "abc"])
def test_a_placement_must_be_six_finite_numbers(X):
    case = trackplan.load_case(CASES / "paper-corner.yaml")
    with pytest.raises(CaseError, match="placement"):
        trackplan.plan_placement(case, X)


def test_every_result_spells_success_the_same_way():
    case = trackplan.load_case(CASES / "paper-corner.yaml")
    result = trackplan.plan_placement(case, case.bounds.example)
    assert result.success is result.feasible is result.check.success is True
    assert result.status is trackplan.Status.FEASIBLE and result.status.success
    assert result.joint_path.success and result.joint_path.ik.success.all()
