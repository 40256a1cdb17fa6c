"""The paper's circle with the seam frame: a fixed spin turns the wrist a full turn, a
free-varying one counter-rotates; the inner spin search and the placement search."""

from __future__ import annotations

import json

import numpy as np
import pytest

from tests.conftest import CASES
from trackplan.cli import ExitCode, main
from trackplan.io.case_file import load_case
from trackplan.planning.plan import check, plan
from trackplan.search.optimize import optimize
from trackplan.search.spin import optimize_spin
from trackplan.status import Status

TURN = "the tool turns 6.283 rad (1.00 turns) about its own axis"


@pytest.fixture(scope="module")
def fixed_case():
    return load_case(CASES / "paper-circle-seam-fixed.yaml")


@pytest.fixture(scope="module")
def free_case():
    return load_case(CASES / "paper-circle-seam-free.yaml")


@pytest.fixture(scope="module")
def free_plan(free_case):
    return optimize_spin(free_case, free_case.bounds.example)


def test_fixed_spin_at_the_example_explains_the_full_turn(fixed_case):
    result = plan(fixed_case, fixed_case.bounds.example)
    assert result.status is Status.POSITION_LIMITS
    assert "joint 6" in result.message and "leaves [-2.356, 2.356]" in result.message
    assert TURN in result.message


def test_free_varying_spin_plans_the_example_and_the_checker_agrees(free_case, free_plan):
    assert free_plan.success, free_plan.message
    spin = free_plan.joint_path.tool.spin
    assert len(spin.coefficients) == 6
    # the spin counter-rotates: it changes by more than the 4.7 rad that joint 6 could absorb
    # on its own were the wrist to make the full turn
    assert np.ptp(free_plan.trajectory.spin) > 2 * np.pi - 1.5 * np.pi
    report = check(
        free_case, free_plan.placement, free_plan.trajectory.q, free_case.task.sample_time
    )
    assert report.success and report.max_orientation_error < 1e-6
    lo, hi = free_case.task.tool.spin_range
    assert (
        lo - 1e-9 <= free_plan.trajectory.spin.min() <= free_plan.trajectory.spin.max() <= hi + 1e-9
    )
    s = free_plan.trajectory.s
    rate = np.abs(np.diff(free_plan.trajectory.spin)) / np.maximum(np.diff(s), 1e-12)
    assert rate[np.diff(s) > 1e-6].max() <= free_case.task.tool.spin_rate * (1 + 1e-6)


def test_a_plan_with_a_wrong_spin_fails_the_spin_check(free_case, free_plan):
    q = free_plan.trajectory.q.copy()
    q[:, 5] += 0.5 * np.linspace(0.0, 1.0, len(q)) ** 3  # the spin now leaves its range
    report = check(free_case, free_plan.placement, q, free_case.task.sample_time)
    assert {v.limit for v in report.violations} & {"spin", "spin rate"}


def test_plan_cli_fixed_exits_3_and_free_writes_the_spin(tmp_path, capsys):
    out = tmp_path / "fixed"
    code = main(
        ["plan", str(CASES / "paper-circle-seam-fixed.yaml"), "--out", str(out), "--no-report"]
    )
    assert code == ExitCode.INFEASIBLE
    assert "about its own axis" in capsys.readouterr().out
    out = tmp_path / "free"
    code = main(
        ["plan", str(CASES / "paper-circle-seam-free.yaml"), "--out", str(out), "--no-report"]
    )
    assert code == ExitCode.OK
    summary = json.loads((out / "result.json").read_text())
    assert summary["tool"]["frame"] == "seam" and summary["tool"]["spin"] == "free-varying"
    assert len(summary["spin"]["coefficients"]) == 6 and len(summary["spin"]["knots"]) == 10
    header = (out / "trajectory.csv").read_text().splitlines()[0].split(",")
    assert header[-1] == "spin"
    # the profile written is the one a plan given --spin-profile reproduces
    again = tmp_path / "again"
    code = main(
        [
            "plan",
            str(CASES / "paper-circle-seam-free.yaml"),
            "--out",
            str(again),
            "--no-report",
            "--spin-profile",
            str(out / "result.json"),
        ]
    )
    assert code == ExitCode.OK
    assert json.loads((again / "result.json").read_text())["objective"] == pytest.approx(
        summary["objective"], rel=1e-9
    )


def test_spin_given_to_a_fixed_spin_is_bad_input(tmp_path, capsys):
    code = main(
        [
            "plan",
            str(CASES / "paper-circle-seam-fixed.yaml"),
            "--out",
            str(tmp_path),
            "--spin",
            "0.3",
        ]
    )
    assert code == ExitCode.BAD_INPUT
    assert "spin is fixed" in capsys.readouterr().err


@pytest.mark.slow
def test_optimize_free_varying_finds_a_feasible_placement(free_case):
    result = optimize(free_case, budget=600, restarts=1)
    assert result.success, result.message
    report = check(free_case, result.X, result.final.trajectory.q, free_case.task.sample_time)
    assert report.success


@pytest.mark.slow
def test_optimize_fixed_is_verified_or_explains_the_turn(fixed_case):
    result = optimize(fixed_case, budget=600, restarts=1)
    if result.success:
        report = check(fixed_case, result.X, result.final.trajectory.q, fixed_case.task.sample_time)
        assert report.success
    else:
        assert TURN in result.message


def test_tool_figure_draws_the_spin_and_the_frames(free_case, free_plan, fixed_case):
    from trackplan.report.figures import plot_figures, shows_tool, tool_figure

    assert shows_tool(free_case) and shows_tool(fixed_case)
    assert "tool.png" in plot_figures(free_plan, free_case)
    figure = tool_figure(free_plan, free_case)
    lines = [line for ax in figure.axes for line in ax.get_lines()]
    (spin,) = [line for line in lines if line.get_gid() == "spin"]
    np.testing.assert_array_equal(spin.get_ydata(), free_plan.trajectory.spin)
    assert sum(line.get_gid() == "tool-frames" for line in lines) == 3


def test_part_frame_cases_get_no_tool_figure():
    from trackplan.report.figures import shows_tool

    assert not shows_tool(load_case(CASES / "paper-corner.yaml"))


def test_seam_weld_on_an_industrial_robot_optimises_with_a_free_spin():
    case = load_case(CASES / "seam-weld-free.yaml")
    assert case.robot.name == "kuka_kr6_r700_sixx" and case.task.tool.n_spin == 1
    result = optimize(case, budget=2000, restarts=1)
    assert result.success, result.message
    spin = result.final.joint_path.tool.spin
    assert len(spin.coefficients) == 1
    assert np.ptp(result.final.trajectory.spin) == 0.0  # one constant spin
    report = check(case, result.X, result.final.trajectory.q, case.task.sample_time)
    assert report.success and report.max_orientation_error < 0.06
