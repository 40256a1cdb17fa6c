"""The cycle of several seams: reversed paths, approach poses, air moves that land exactly,
directions of travel, segment labels, and the checker on the joined trajectory."""

from __future__ import annotations

import copy
import itertools
import json
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
import yaml

from tests.conftest import CASES
from trackplan.case import Sequencing
from trackplan.cell.check import check_cell
from trackplan.cell.screening import CellGeometry
from trackplan.errors import CaseError
from trackplan.frames import placement_transform
from trackplan.io.case_file import load_case, load_case_text
from trackplan.io.results import (
    read_segments,
    read_trajectory_csv,
    write_plan_csv,
    write_plan_files,
)
from trackplan.paths import NominalPath
from trackplan.paths.specs import ArcSpec, LineSpec, PointsSpec
from trackplan.planning.assembly import VIA_LIFT
from trackplan.planning.plan import check, plan
from trackplan.planning.result import AIR, APPROACH, RETRACT
from trackplan.planning.seams import reversed_segments
from trackplan.planning.sequence import Sequence, Visit
from trackplan.planning.trajectory_check import spans_from_segments
from trackplan.robots.kinematics import forward_kinematics
from trackplan.timing.airmove import plan_air_move

X = np.array([0.2223, -0.5, -0.2999, 0.05, 0.0499, -2.7271])
"""A placement where the shipped bracket's seams are feasible (found by its search)."""
APPROACH_DISTANCE = 0.03

CASE = {
    "name": "three-seams",
    "robot": "puma560",
    "paths": [
        {"name": "left", "start": [0.05, 0.08, 0], "segments": [{"line": {"to": [0.15, 0.08, 0]}}]},
        {
            "name": "right",
            "start": [0.05, 0.10, 0],
            "segments": [{"line": {"to": [0.15, 0.10, 0]}}],
            "reversible": False,
        },
        {
            "name": "corner",
            "start": [0.05, 0.20, 0],
            "segments": [{"line": {"to": [0.20, 0.20, 0]}}, {"line": {"to": [0.20, 0.15, 0]}}],
        },
    ],
    "approach": APPROACH_DISTANCE,
    "home": [-1.2, -1.0, -0.2, 0.0, -1.8, -1.5],
    "task": {
        "rated_speed": 0.02,
        "corner_speed": 0.015,
        "tolerance": 0.0005,
        "sample_time": 0.004,
        "tool_rpy": [3.141592653589793, 0, 0],
    },
}
FORCED = Sequence(visits=(Visit(2, True), Visit(0, False), Visit(1, False)), cost=0.0, exact=False)


@pytest.fixture(scope="module")
def case():
    return load_case_text(yaml.safe_dump(CASE, sort_keys=False))


@pytest.fixture(scope="module")
def cycle(case):
    return plan(case, X, sequence=FORCED)


def _placed(point: np.ndarray) -> np.ndarray:
    T = placement_transform(X)
    return T[:3, :3] @ point + T[:3, 3]


@pytest.mark.parametrize(
    "segments",
    [
        (LineSpec(np.array([0.1, 0, 0])), LineSpec(np.array([0.1, 0.1, 0]))),
        (
            LineSpec(np.array([0.1, 0, 0])),
            ArcSpec(np.array([0.1, 0.05, 0]), np.array([0, 0, 1.0]), np.pi / 2),
            PointsSpec(np.array([[0.12, 0.06, 0], [0.13, 0.08, 0.01], [0.13, 0.1, 0.02]])),
        ),
        (ArcSpec(np.array([0.0, 0.05, 0]), np.array([0, 0, 1.0]), 2 * np.pi),),
    ],
)
def test_reversed_segments_trace_the_same_path_backwards(segments) -> None:
    start = np.zeros(3)
    forward = NominalPath.from_specs(start, segments)
    back_start, back_segments = reversed_segments(start, segments)
    backward = NominalPath.from_specs(back_start, back_segments)
    assert backward.length == pytest.approx(forward.length, rel=1e-9)
    points = backward.polyline(0.004)
    assert np.allclose(points[0], forward.polyline(0.004)[-1], atol=1e-12)
    s_back, own = backward.project(points)
    s_forward, distance = forward.project(points)
    assert np.max(own) < 1e-9 and np.max(distance) < 1e-9  # the same curve
    inside = (s_back > 1e-6) & (s_back < backward.length - 1e-6)
    assert np.max(np.abs(s_forward[inside] + s_back[inside] - forward.length)) < 1e-9


def test_the_cycle_is_feasible_and_labelled(cycle, case) -> None:
    assert cycle.success, cycle.message
    kinds = [piece.kind for piece in cycle.spans]
    # home → (air, approach, seam, retract) per seam → home
    assert kinds == [AIR, APPROACH, "seam", RETRACT] * 3 + [AIR]
    for piece in cycle.spans:
        labels = set(cycle.segment[piece.first + 1 : piece.last + 1])
        assert labels == {piece.label}
    assert [s.name for s in cycle.seams] == ["corner", "left", "right"]
    assert cycle.duration == pytest.approx(cycle.seam_time + cycle.air_time)
    assert cycle.seam_time == pytest.approx(sum(s.plan.duration for s in cycle.seams))
    # the first and last samples are home
    assert np.array_equal(cycle.trajectory.q[0], case.sequencing.home)
    assert np.array_equal(cycle.trajectory.q[-1], case.sequencing.home)


def test_each_air_move_ends_exactly_at_the_next_approach_pose(cycle, case) -> None:
    q = cycle.trajectory.q
    pieces = cycle.spans
    seams = iter(cycle.seams)
    for before, after in itertools.pairwise(pieces):
        if before.kind != AIR:
            continue
        seam = next(seams)
        assert after.kind == APPROACH
        assert np.array_equal(q[before.last], seam.q_approach)
        start = seam.plan.trajectory.q[0]
        T_approach = forward_kinematics(case.robot, q[before.last])
        T_start = forward_kinematics(case.robot, start)
        expected = T_start[:3, 3] - APPROACH_DISTANCE * T_start[:3, 2]
        assert np.max(np.abs(T_approach[:3, 3] - expected)) < 1e-9
        assert np.max(np.abs(T_approach[:3, :3] - T_start[:3, :3])) < 1e-9
        assert np.array_equal(q[after.last], start)  # the approach lands on the seam start


def test_every_sample_is_within_every_joint_limit(cycle, case) -> None:
    robot = case.robot
    trajectory = cycle.trajectory
    for kind, bound in (("qd", robot.v_max), ("qdd", robot.a_max), ("qddd", robot.j_max)):
        assert np.all(np.abs(getattr(trajectory, kind)) <= bound * (1 + 1e-9)), kind
    assert cycle.approach_deviation < 1e-3  # joint-space approach stays near the tool axis


def test_reversing_a_seam_reverses_its_travel_in_the_output(cycle, case) -> None:
    position = cycle.trajectory.tool_position
    corner = next(p for p in cycle.spans if p.label == "corner")
    left = next(p for p in cycle.spans if p.label == "left")
    assert corner.reversed and not left.reversed
    # reversed: the corner seam starts at its written end and ends at its written start
    assert np.linalg.norm(position[corner.first] - _placed(np.array([0.20, 0.15, 0]))) < 1e-6
    assert np.linalg.norm(position[corner.last] - _placed(np.array([0.05, 0.20, 0]))) < 1e-6
    assert np.linalg.norm(position[left.first] - _placed(np.array([0.05, 0.08, 0]))) < 1e-6
    # the same seam forward: the travel direction flips
    again = plan(
        case, X, sequence=replace(FORCED, visits=(Visit(2, False), Visit(0, True), Visit(1, False)))
    )
    forward = next(p for p in again.spans if p.label == "corner")
    assert not forward.reversed
    travel = (
        again.trajectory.tool_position[forward.last] - again.trajectory.tool_position[forward.first]
    )
    back = position[corner.last] - position[corner.first]
    assert np.allclose(travel, -back, atol=1e-6)


def test_the_written_cycle_rechecks_from_its_segment_column(cycle, case, tmp_path: Path) -> None:
    file = tmp_path / "trajectory.csv"
    write_plan_csv(cycle, file)
    t, q = read_trajectory_csv(file, case.robot.n_dof)
    segment = read_segments(file)
    assert np.array_equal(q, cycle.trajectory.q)
    assert list(segment) == list(cycle.segment)
    report = check(case, X, q, float(t[1] - t[0]), segment=segment)
    assert report.success
    assert report.max_tracking_error == pytest.approx(cycle.check.max_tracking_error)
    # a seam missing from the labels is a coverage violation naming it
    relabelled = np.where(segment == "left", "air", segment)
    report = check(case, X, q, float(t[1] - t[0]), segment=relabelled)
    assert not report.success
    assert any("seam left is not welded" in v.message for v in report.violations)


def test_the_checker_names_the_seam_whose_tracking_fails(cycle, case) -> None:
    q = cycle.trajectory.q.copy()
    left = next(p for p in cycle.spans if p.label == "left")
    middle = (left.first + left.last) // 2
    q[middle - 2 : middle + 3, 1] += 2e-3  # about 1 mm off the seam, vertically
    report = check(case, X, q, cycle.trajectory.sample_time, segment=cycle.segment)
    tracking = [v for v in report.violations if v.limit == "tracking"]
    assert tracking and tracking[0].message.startswith("seam left: ")
    assert left.first * cycle.trajectory.sample_time <= tracking[0].t_first


def test_optimize_never_reverses_a_seam_that_may_not_be_reversed(case) -> None:
    cycle = plan(case, X)
    assert cycle.success, cycle.message
    assert cycle.sequence.exact
    right = next(v for v in cycle.sequence.visits if v.seam == 1)
    assert not right.reversed
    given = plan(case, X, sequence=Sequence(tuple(Visit(i, False) for i in range(3)), 0.0, False))
    assert cycle.duration <= given.duration + 1e-9


def test_a_colliding_air_move_goes_through_a_via_above_the_seam_it_leaves() -> None:
    data = copy.deepcopy(CASE)
    data["paths"] = [
        {"name": "near", "start": [0.05, 0.05, 0], "segments": [{"line": {"to": [0.15, 0.05, 0]}}]},
        {"name": "far", "start": [0.15, 0.25, 0], "segments": [{"line": {"to": [0.05, 0.25, 0]}}]},
    ]
    fence = {"size": [0.4, 0.01, 0.06], "pose": [0.1, 0.15, -0.05, 0, 0, 0]}
    data["cell"] = {"clearance": 0.005, "workpiece": [{"name": "fence", "box": fence}]}
    fenced = load_case_text(yaml.safe_dump(data, sort_keys=False))
    given = Sequence((Visit(0, False), Visit(1, False)), 0.0, False)
    cycle = plan(fenced, X, sequence=given)
    robot = fenced.robot
    between = cycle.spans[4]
    assert between.kind == AIR and between.via is not None
    # the direct move would have gone through the fence
    near = cycle.seams[0]
    direct = plan_air_move(
        near.q_retract, cycle.seams[1].q_approach, robot.v_max, robot.a_max, robot.j_max, 0.004
    )
    geometry = CellGeometry.from_cell(fenced.cell, robot)
    assert check_cell(geometry, robot, direct.q, 0.004, placement_transform(X)).violations
    # the via is a sample, VIA_LIFT beyond the retract pose along the tool axis
    q = cycle.trajectory.q[between.first : between.last + 1]
    assert np.any(np.all(q == between.via, axis=1))
    T_end = forward_kinematics(robot, near.plan.trajectory.q[-1])
    T_via = forward_kinematics(robot, between.via)
    lifted = T_end[:3, 3] - (APPROACH_DISTANCE + VIA_LIFT) * T_end[:3, 2]
    assert np.max(np.abs(T_via[:3, 3] - lifted)) < 1e-9


def test_a_single_path_case_is_one_seam_span_of_its_plan() -> None:
    single = load_case(CASES / "bracket-weld.yaml")
    planned = plan(single, single.bounds.example)
    assert planned.success, planned.message
    n = planned.trajectory.n_samples
    assert [(p.kind, p.first, p.last) for p in planned.spans] == [("seam", 0, n - 1)]
    assert planned.seam_time == planned.duration and planned.air_time == 0.0
    assert set(planned.segment) == {"bracket-weld"} and len(planned.segment) == n
    assert planned.seams[0].plan.trajectory is planned.trajectory
    assert planned.seam_checks == (planned.check,)


def test_an_approach_joins_one_seam_with_moves() -> None:
    single = load_case(CASES / "bracket-weld.yaml")
    X_single = single.bounds.example
    alone = plan(single, X_single)
    moved = plan(replace(single, sequencing=Sequencing(approach=0.01)), X_single)
    assert moved.success, moved.message
    assert [p.kind for p in moved.spans] == [APPROACH, "seam", RETRACT]
    seam = moved.spans[1]
    assert np.allclose(moved.trajectory.q[seam.first : seam.last + 1], alone.trajectory.q)
    assert moved.seam_time == pytest.approx(alone.duration, abs=1e-9)
    assert moved.air_time > 0.0


def spun_case(left: dict, corner: dict):
    """The left and corner seams of CASE, each with its own tool (frame part, CASE's rpy)."""
    data = copy.deepcopy(CASE)
    rpy = data["task"]["tool_rpy"]
    left_seam, _, corner_seam = data["paths"]
    left_seam["task"] = {"tool": {"frame": "part", "rpy": rpy, **left}}
    corner_seam["task"] = {"tool": {"frame": "part", "rpy": rpy, **corner}}
    data["paths"] = [left_seam, corner_seam]
    return load_case_text(yaml.safe_dump(data, sort_keys=False))


def _written_spins(cycle, case, out: Path) -> tuple[dict, np.ndarray, np.ndarray]:
    """result.json, the spin column and the segment column of a cycle written to ``out``."""
    write_plan_files(cycle, case, out)
    header = (out / "trajectory.csv").read_text(encoding="utf-8").splitlines()[0].split(",")
    table = np.loadtxt(
        out / "trajectory.csv", delimiter=",", skiprows=1, usecols=range(len(header) - 1)
    )
    summary = json.loads((out / "result.json").read_text(encoding="utf-8"))
    return summary, table[:, header.index("spin")], read_segments(out / "trajectory.csv")


LEFT_FIRST = Sequence(visits=(Visit(0, False), Visit(1, False)), cost=0.0, exact=False)


@pytest.mark.parametrize("reverse", [False, True])
def test_a_chosen_constant_spin_reaches_the_trajectory_and_result(reverse, tmp_path: Path) -> None:
    case = spun_case({"spin": "free", "spin_range": [-0.4, 0.4]}, {"spin_value": -0.1})
    order = Sequence(visits=(Visit(0, reverse), Visit(1, False)), cost=0.0, exact=False)
    cycle = plan(case, X, sequence=order, spins=(np.array([0.25]), None))
    assert cycle.success, cycle.message
    summary, spin, segment = _written_spins(cycle, case, tmp_path)
    # a constant spin is the same in both directions; the fixed seam keeps its spin_value
    assert np.all(spin[segment == "left"] == 0.25)
    assert np.all(spin[segment == "corner"] == -0.1)
    assert np.all(spin[np.isin(segment, [AIR, APPROACH, RETRACT])] == 0.0)
    seams = {seam["name"]: seam for seam in summary["seams"]}
    assert seams["left"]["spin"] == {"value": 0.25} and seams["left"]["reversed"] is reverse
    assert seams["corner"]["spin"] == {"value": -0.1}
    # the middle of the range by default
    middle = plan(case, X, sequence=LEFT_FIRST)
    assert np.all(middle.trajectory.spin[middle.segment == "left"] == 0.0)


def test_a_spin_profile_is_reversed_with_its_seam() -> None:
    case = spun_case({}, {"spin": "free-varying", "spin_range": [-0.5, 0.5], "spin_rate": 5.0})
    tool = case.seams[1].task.tool
    variables = np.r_[-0.3, np.linspace(1.0, -0.2, tool.n_spin - 1)]  # rises, then falls a bit
    runs = {}
    for reverse in (False, True):
        order = Sequence(visits=(Visit(0, False), Visit(1, reverse)), cost=0.0, exact=False)
        cycle = plan(case, X, sequence=order, spins=(None, variables))
        assert cycle.success, cycle.message
        corner = cycle.segment == "corner"  # (its first sample is the approach's last)
        runs[reverse] = (cycle.trajectory.s[corner], cycle.trajectory.spin[corner])
        assert cycle.seams[1].reversed is reverse
    s_forward, spin_forward = runs[False]
    s_back, spin_back = runs[True]
    forward = tool.profile(variables, float(s_forward[-1]))
    assert np.ptp(spin_forward) > 0.2  # the profile varies
    assert np.allclose(spin_forward, forward.value(s_forward), atol=1e-12)
    # welded end to start, every point of the seam keeps its spin: spin_back(s) = spin(L - s)
    assert np.allclose(spin_back, forward.value(s_back[-1] - s_back), atol=1e-9)
    assert spin_back[-1] == pytest.approx(-0.3, abs=1e-12)  # ends where the forward run starts


def test_one_spin_per_seam_or_a_clear_error() -> None:
    case = spun_case({"spin": "free"}, {})
    with pytest.raises(CaseError, match="one spin per seam"):
        plan(case, X, spins=(np.array([0.1]),))


@pytest.mark.parametrize("reverse", [False, True])
def test_a_closed_seam_rechecks_in_the_direction_it_was_welded(reverse, tmp_path: Path) -> None:
    data = copy.deepcopy(CASE)
    loop = {
        "name": "loop",
        "start": [0.13, 0.15, 0],
        "segments": [{"arc": {"center": [0.1, 0.15, 0], "normal": [0, 0, 1], "angle": 2 * np.pi}}],
    }
    data["paths"] = [data["paths"][0], loop]
    case = load_case_text(yaml.safe_dump(data, sort_keys=False))
    order = Sequence(visits=(Visit(0, False), Visit(1, reverse)), cost=0.0, exact=False)
    cycle = plan(case, X, sequence=order)
    assert cycle.success, cycle.message
    file = tmp_path / "trajectory.csv"
    write_plan_csv(cycle, file)
    _, q = read_trajectory_csv(file, case.robot.n_dof)
    segment = read_segments(file)
    pieces = spans_from_segments(case, X, q, segment)
    assert [p.reversed for p in pieces if p.kind == "seam"] == [False, reverse]
    assert check(case, X, q, case.task.sample_time, segment=segment).success
