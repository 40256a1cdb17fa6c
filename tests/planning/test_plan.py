"""Planning one placement: the paper cases, the smooth time law's promises, the outputs."""

from __future__ import annotations

import dataclasses
import json

import numpy as np
import pytest

from trackplan.cli import main
from trackplan.errors import CaseError
from trackplan.frames import placement_transform
from trackplan.io.case_file import load_case
from trackplan.io.results import (
    read_segments,
    read_trajectory_csv,
    write_plan_csv,
    write_plan_files,
    write_trajectory_csv,
)
from trackplan.paths.path_geometry import PathGeometry
from trackplan.planning.checker import check_trajectory
from trackplan.planning.plan import check, make_trajectory, plan, tracking_reference
from trackplan.planning.trajectory_check import spans_from_segments
from trackplan.status import Status

from .conftest import CASES


@pytest.mark.parametrize("name", ["paper-line", "paper-circle", "paper-corner"])
def test_paper_cases_plan_feasibly_in_smooth_mode(name):
    case = load_case(CASES / f"{name}.yaml")
    result = plan(case, case.bounds.example)
    assert result.feasible, result.message
    # every output trajectory re-checked by the one checker, independently of the planner
    geometry = PathGeometry.from_case(case)
    report = check_trajectory(
        case.robot,
        result.trajectory.q,
        case.task.sample_time,
        tracking_reference(case, geometry, result.placement),
    )
    assert report.success, [v.message for v in report.violations]
    # the tool starts at the path's start, placed by X (Eq. 4)
    T = placement_transform(result.placement)
    start = T[:3, :3] @ case.start + T[:3, 3]
    np.testing.assert_allclose(result.trajectory.tool_position[0], start, atol=1e-9)
    lower_bound = result.path_length / case.task.rated_speed
    assert lower_bound < result.duration < 1.15 * lower_bound


def test_corner_passed_without_stopping(corner_plan):
    traj = corner_plan.trajectory
    path_speed = np.diff(traj.s) / traj.sample_time
    middle = (traj.s[1:] > 0.1 * traj.s[-1]) & (traj.s[1:] < 0.9 * traj.s[-1])
    assert path_speed[middle].min() > 0.02
    assert corner_plan.min_corner_speed == pytest.approx(path_speed[middle].min(), rel=1e-2)


def test_straight_pieces_run_at_exactly_the_rated_speed(corner_case, corner_plan):
    traj = corner_plan.trajectory
    rated = corner_case.task.rated_speed
    path_speed = np.diff(traj.s) / traj.sample_time
    assert path_speed.max() <= rated * (1 + 1e-9)
    exact = np.abs(path_speed - rated) <= 1e-9 * rated
    assert np.diff(traj.s)[exact].sum() / corner_plan.path_length > 0.85
    assert corner_plan.rated_speed_fraction > 0.85
    assert corner_plan.slowdowns == ()


def test_rest_to_rest(corner_plan):
    traj = corner_plan.trajectory
    assert traj.s[0] == 0.0
    assert traj.s[-1] == pytest.approx(corner_plan.planned_path.length, abs=1e-12)
    assert np.all(traj.qd[0] == 0)
    assert np.abs(traj.qd[-1]).max() < 1e-4  # rad/s: the last step of a jerk-limited stop
    assert np.abs(traj.qdd[-1]).max() < 0.1


def test_random_reachable_placements_always_meet_rate_limits(corner_case, corner_geometry):
    """Whenever the geometric path is reachable, the smooth law meets every rate limit."""
    rng = np.random.default_rng(3)
    lower, upper = corner_case.bounds.lower, corner_case.bounds.upper
    reach_min, reach_max = corner_case.bounds.reach
    planned = 0
    while planned < 6:
        X = rng.uniform(lower, upper)
        if not reach_min <= np.linalg.norm(X[:3]) <= reach_max:
            continue
        result = plan(corner_case, X, geometries={(0, False): corner_geometry})
        if result.status in (Status.UNREACHABLE, Status.POSITION_LIMITS):
            continue
        planned += 1
        assert result.feasible, (X, result.message)


def test_unreachable_placement_reports_why(corner_case, corner_geometry):
    result = plan(
        corner_case, np.array([2.0, 0, 0, 0, 0, 0]), geometries={(0, False): corner_geometry}
    )
    assert not result.feasible
    assert result.status is Status.UNREACHABLE
    assert "out of reach" in result.message
    assert result.trajectory.n_samples == 0


def test_trajectory_csv_round_trip(corner_plan, tmp_path):
    file = tmp_path / "trajectory.csv"
    write_trajectory_csv(corner_plan.trajectory, file)
    t, q = read_trajectory_csv(file, 6)
    np.testing.assert_array_equal(t, corner_plan.trajectory.t)
    np.testing.assert_array_equal(q, corner_plan.trajectory.q)
    header = file.read_text().splitlines()[0].split(",")
    assert header[:2] == ["t", "q1"] and header[-5:] == ["x", "y", "z", "speed", "spin"]
    assert len(header) == 1 + 4 * 6 + 5


def test_cli_plan_exit_codes_and_check_round_trip(tmp_path, capsys):
    case = str(CASES / "paper-corner.yaml")
    assert main(["plan", case, "--out", str(tmp_path / "ok"), "--no-report"]) == 0
    summary = json.loads((tmp_path / "ok" / "result.json").read_text())
    for key in (
        "placement",
        "feasible",
        "objective",
        "duration",
        "path_length",
        "max_tracking_error",
        "rated_speed_fraction",
        "min_corner_speed",
        "margins",
        "violations",
        "timing",
        "branch",
    ):
        assert key in summary
    assert summary["feasible"] is True and summary["timing"] == "smooth"
    assert main(["check", case, str(tmp_path / "ok")]) == 0
    paper = tmp_path / "paper"
    assert main(["plan", case, "--timing", "paper", "--out", str(paper), "--no-report"]) == 3
    summary = json.loads((paper / "result.json").read_text())
    assert summary["feasible"] is False and summary["violations"]
    assert summary["max_tracking_error"] == pytest.approx(2e-3, rel=1e-3)  # Eq. 10 arc
    assert main(["check", case, str(paper)]) == 3
    out = capsys.readouterr().out
    assert "VIOLATION" in out and "tracking" in out


def test_cli_plan_negative_placement_values(tmp_path):
    case = str(CASES / "paper-line.yaml")
    code = main(
        [
            "plan",
            case,
            "--placement",
            "-0.1322",
            "0.0610",
            "0.1829",
            "0.0312",
            "-0.4124",
            "0.5020",
            "--out",
            str(tmp_path),
            "--no-report",
        ]
    )
    assert code == 3  # the paper's Fig. 5 individual is out of reach for this PUMA
    summary = json.loads((tmp_path / "result.json").read_text())
    assert summary["placement"]["x"] == pytest.approx(-0.1322)
    assert summary["status"] == "unreachable"


def test_cli_plan_reference_durations(tmp_path):
    case = str(CASES / "paper-line.yaml")
    assert main(["plan", case, "--reference", "--out", str(tmp_path), "--no-report"]) == 0
    summary = json.loads((tmp_path / "result.json").read_text())
    # toppra (no jerk limit) ≤ TOPP3 (jerk-limited optimum) ≤ trackplan's duration ≤ 1.05 TOPP3
    assert summary["toppra_duration"] <= summary["topp3_duration"] <= summary["duration"]
    assert summary["duration"] <= 1.05 * summary["topp3_duration"]


def test_full_reversal_is_a_stop_and_go(tmp_path):
    text = (CASES / "paper-corner.yaml").read_text()
    text = text.replace(
        "    - line: {to: [0.3, 0, 0.5]}",
        "    - line: {to: [0.2, 0, 0]}\n    - line: {to: [0.2, 0, 0.3]}",
    )
    file = tmp_path / "reversal.yaml"
    file.write_text(text)
    case = load_case(file)
    result = plan(case, case.bounds.example)
    assert result.feasible, result.message  # the checker follows the path back along itself
    traj = result.trajectory
    at_turn = np.argmin(np.abs(traj.s - 0.5))
    assert np.diff(traj.s)[at_turn - 1 : at_turn + 1].max() / traj.sample_time < 1e-3


def test_a_time_law_too_long_to_sample_says_where(corner_case, corner_geometry, monkeypatch):
    import trackplan.timing.smooth as smooth

    monkeypatch.setattr(smooth, "MAX_SAMPLES", 1000)
    result = plan(corner_case, corner_case.bounds.example, geometries={(0, False): corner_geometry})
    assert result.status is Status.LIMITS_VIOLATED and not result.feasible
    assert "would need" in result.message and "m/s at s =" in result.message
    assert result.trajectory.n_samples == 0


def test_worst_margin_of_a_feasible_plan_is_its_least_unused_limit(corner_plan):
    """The speed margin (0 by design at the rated speed) and the coverage flag count only
    when broken: a feasible plan's worst margin is its least unused joint or task limit."""
    check = corner_plan.check
    assert corner_plan.success
    assert check.task_margins["speed"] == pytest.approx(0.0, abs=1e-6)
    worst = check.worst_margin()
    assert 0.0 < worst < 1.0
    joint_least = min(float(np.min(m)) for m in check.joint_margins.values())
    assert worst <= joint_least


def test_one_seam_is_checked_the_same_with_or_without_its_labels(corner_case, corner_plan):
    q, sample_time = corner_plan.trajectory.q, corner_case.task.sample_time
    unlabelled = check(corner_case, corner_plan.placement, q, sample_time)
    labelled = check(
        corner_case, corner_plan.placement, q, sample_time, segment=corner_plan.segment
    )
    assert unlabelled.success and labelled.success
    assert labelled.max_tracking_error == unlabelled.max_tracking_error
    assert labelled.max_tracking_error == pytest.approx(
        corner_plan.check.max_tracking_error, rel=1e-12
    )


def test_a_single_seam_run_gains_the_seam_keys_and_keeps_its_numeric_table(
    corner_case, corner_plan, tmp_path
):
    summary = write_plan_files(corner_plan, corner_case, tmp_path)
    written = json.loads((tmp_path / "result.json").read_text())
    assert written["path_length"] == pytest.approx(corner_plan.path_length, rel=1e-12)
    assert written["cycle_time"] == written["duration"] == summary["duration"]
    assert (written["air_time"], written["moves"], written["sequence_mode"]) == (0.0, [], "given")
    assert [seam["name"] for seam in written["seams"]] == ["paper-corner"]
    assert read_segments(tmp_path / "trajectory.csv") is None
    table = np.loadtxt(tmp_path / "trajectory.csv", delimiter=",", skiprows=1, ndmin=2)
    assert table.shape == (corner_plan.trajectory.n_samples, 1 + 4 * 6 + 5)


BRACKET_X = np.array([0.2223, -0.5, -0.2999, 0.05, 0.0499, -2.7271])
"""A placement of the shipped four-fillet bracket."""


def test_plan_refuses_a_spin_or_two_branch_options_it_cannot_apply(corner_case):
    two = load_case(CASES / "bracket-4-fillets.yaml")
    with pytest.raises(CaseError, match="4 seams: give one spin per seam"):
        plan(two, BRACKET_X, spin=np.array([0.1]))
    with pytest.raises(CaseError, match=r"branch \(every seam\) or branches"):
        plan(corner_case, corner_case.bounds.example, branch=0, branches=(0,))


def test_check_of_several_seams_needs_their_labels():
    case = load_case(CASES / "bracket-4-fillets.yaml")
    q = np.zeros((3, case.robot.n_dof))
    with pytest.raises(CaseError, match="4 seams: the trajectory needs its segment column"):
        check(case, BRACKET_X, q, case.task.sample_time)


def test_a_case_name_that_is_no_csv_field_labels_its_seam_safely(
    corner_case, corner_plan, tmp_path
):
    renamed = dataclasses.replace(corner_case, name='=weld, "left"')
    assert renamed.seam_names == ("_=weld_ _left_",)
    result = dataclasses.replace(corner_plan, segment=np.full(3, renamed.seams[0].name))
    result = dataclasses.replace(
        result,
        trajectory=make_trajectory(renamed.robot, corner_plan.trajectory.q[:3], np.zeros(3), 0.001),
    )
    write_plan_csv(result, tmp_path / "trajectory.csv")
    t, q = read_trajectory_csv(tmp_path / "trajectory.csv", renamed.robot.n_dof)
    assert t.tolist() == pytest.approx([0.0, 0.001, 0.002], abs=1e-15)
    assert q.shape == (3, renamed.robot.n_dof)
    segment = read_segments(tmp_path / "trajectory.csv")
    assert segment.tolist() == ["_=weld_ _left_"] * 3
    spans = spans_from_segments(renamed, corner_plan.placement, q, segment)
    assert [(span.kind, span.seam, span.first, span.last) for span in spans] == [("seam", 0, 0, 2)]
