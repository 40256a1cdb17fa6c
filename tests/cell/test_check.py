"""The cell check: planted collisions, self-collision, the tool's allowed contact, the search."""

from __future__ import annotations

import ast
import dataclasses
from pathlib import Path

import numpy as np
import pytest

from trackplan.cell.check import check_cell, pair_distances
from trackplan.cell.exact import ExactDistance
from trackplan.cell.model import Body, Capsules, Cell, Shape
from trackplan.cell.screening import CellGeometry, clip_tool_segment
from trackplan.frames import pose_matrix, rpy_matrix
from trackplan.io.case_file import load_case
from trackplan.paths.path_geometry import PathGeometry
from trackplan.planning.checker import check_trajectory
from trackplan.robots.builtin import puma560, ur5
from trackplan.robots.kinematics import forward_kinematics, joint_frames
from trackplan.search.fitness import PlacementFitness
from trackplan.search.screening import code
from trackplan.search.space import SearchSpace
from trackplan.status import Status

REPO = Path(__file__).resolve().parents[2]
CELL_CASE = REPO / "cases" / "paper-corner-cell.yaml"
TS = 0.01


def swing() -> np.ndarray:
    """A PUMA560 motion: joint 1 sweeps 90° with the arm stretched forwards, shape (100, 6)."""
    q = np.zeros((100, 6))
    q[:, 0] = np.linspace(0.0, np.pi / 2, 100)
    q[:, 2] = -np.pi / 2  # forearm along the upper arm: elbow straight out
    return q


def test_planted_obstacle_in_a_links_path_is_caught() -> None:
    robot = puma560()
    q = swing()
    elbow = joint_frames(robot, q[50])[3, :3, 3]  # the elbow half way through the sweep
    ball = Body("ball", Shape.SPHERE, pose_matrix(elbow, np.eye(3)), [0.05, 0.0, 0.0])
    geometry = CellGeometry.from_cell(Cell(obstacles=(ball,), clearance=0.01), robot)
    report = check_cell(geometry, robot, q, TS, np.eye(4))
    assert not report.success
    hits = {v.message.split(" hits ")[0].removeprefix("collision: ") for v in report.violations}
    assert "link 2" in hits
    worst = min(report.violations, key=lambda v: v.worst)
    assert worst.limit == "collision" and worst.worst < -0.05  # the ball sits on the arm's axis
    assert worst.t_first <= 50 * TS <= worst.t_last
    assert "ball" in worst.message and "mm deep" in worst.message
    assert report.min_clearance == pytest.approx(worst.worst)
    # moved out of the way (1 m above the shoulder), the same motion is clear
    away = dataclasses.replace(ball, T_frame_body=pose_matrix([0.0, 0.0, 1.0], np.eye(3)))
    clear = CellGeometry.from_cell(Cell(obstacles=(away,), clearance=0.01), robot)
    report = check_cell(clear, robot, q, TS, np.eye(4))
    assert report.success and report.min_clearance > 0.01


def test_self_collision_is_caught() -> None:
    """Folded configurations where non-adjacent links overlap, cross-checked with coal."""
    robot = puma560()
    geometry = CellGeometry.from_cell(Cell(), robot)
    rng = np.random.default_rng(3)
    q = rng.uniform(robot.q_min, robot.q_max, (4000, 6))
    frames = joint_frames(robot, q)
    _, own = geometry.screen(frames, np.eye(4))
    folded = np.flatnonzero(own.min(axis=1) < -0.02)
    assert len(folded) > 0
    k = int(folded[0])
    p = int(np.argmin(own[k]))
    i, j = geometry.self_pairs[p]
    caps = geometry.capsules
    ends = [
        caps.segment[c] @ frames[k, caps.frame[c], :3, :3].T + frames[k, caps.frame[c], :3, 3]
        for c in (i, j)
    ]
    exact = ExactDistance().capsule_capsule(*ends[0], caps.radius[i], *ends[1], caps.radius[j])
    assert exact < 0.0
    report = check_cell(geometry, robot, q[k : k + 1], TS, np.eye(4))
    assert not report.success
    assert all(v.limit == "collision" for v in report.violations)
    named = f"{caps.name[i]} hits {caps.name[j]}"
    assert any(named in v.message for v in report.violations)


def test_neighbouring_links_are_not_checked() -> None:
    geometry = CellGeometry.from_cell(Cell(), puma560())
    frames = geometry.capsules.frame
    bodies = np.unique(frames)
    rank = np.searchsorted(bodies, frames)
    i, j = geometry.self_pairs.T
    assert np.all(np.abs(rank[i] - rank[j]) > 1)
    # the wrist (frame 6) neighbours the forearm (frame 3): links 4, 5 carry no capsule
    assert not any({frames[a], frames[b]} == {3, 6} for a, b in geometry.self_pairs)


def tool_cell(contact: float, clearance: float = 0.005) -> tuple[Cell, np.ndarray, np.ndarray]:
    """A torch (axis from 15 cm behind the TCP to the TCP) whose tip rests on a workpiece."""
    robot = puma560()
    q = np.array([[0.3, -0.4, 0.2, 0.1, 0.6, 0.2]])
    T_tcp = forward_kinematics(robot, q)[0]
    # a 10 cm block in front of the TCP along the tool axis, its face through the TCP
    T_block = T_tcp @ pose_matrix([0.0, 0.0, 0.05], np.eye(3))
    block = Body("part", Shape.BOX, T_block, [0.1, 0.1, 0.05])
    torch = Capsules([0], [[[0.0, 0.0, -0.15], [0.0, 0.0, 0.0]]], [0.01], ("torch",))
    shoulder = Capsules([1], [[[0.0, 0.0, -0.05], [0.0, 0.0, 0.05]]], [0.05], ("link 1",))
    cell = Cell(
        workpiece=(block,), tool=torch, links=shoulder, clearance=clearance, tool_contact=contact
    )
    return cell, q, np.eye(4)


def test_tool_may_touch_the_workpiece_within_tool_contact() -> None:
    robot = puma560()
    cell, q, T_part = tool_cell(contact=0.02)
    report = check_cell(CellGeometry.from_cell(cell, robot), robot, q, TS, T_part)
    assert report.success
    # the clipped torch ends 2 cm behind the face: 2 cm − 1 cm radius from the part
    assert report.min_clearance == pytest.approx(0.01, abs=1e-6)


def test_tool_touching_beyond_tool_contact_is_a_collision() -> None:
    robot = puma560()
    cell, q, T_part = tool_cell(contact=0.0)
    report = check_cell(CellGeometry.from_cell(cell, robot), robot, q, TS, T_part)
    assert not report.success
    assert report.violations[0].limit == "collision"
    assert "torch hits part" in report.violations[0].message


def test_clip_tool_segment() -> None:
    segment = np.array([[0.0, 0.0, -0.2], [0.0, 0.0, 0.0]])
    np.testing.assert_allclose(clip_tool_segment(segment, 0.05), [[0, 0, -0.2], [0, 0, -0.05]])
    np.testing.assert_allclose(
        clip_tool_segment(segment[::-1], 0.05), [[0, 0, -0.05], [0, 0, -0.2]]
    )
    assert clip_tool_segment(segment, 0.3) is None


def test_exact_check_agrees_with_screening_on_the_cell_case() -> None:
    """Along a real trajectory the exact re-measures equal the screened distances."""
    case = load_case(CELL_CASE)
    robot = case.robot
    q = swing()
    geometry = CellGeometry.from_cell(case.cell, robot)
    frames = joint_frames(robot, q)
    T_part = pose_matrix([0.3, 0.2, 0.1], rpy_matrix([0.2, 0.1, 0.3]))
    screened = pair_distances(geometry, frames, T_part, exact=False)
    exact = pair_distances(geometry, frames, T_part)
    apart = exact > 0
    np.testing.assert_allclose(exact[apart], screened[apart], atol=1e-6)


def test_search_grades_colliding_candidates() -> None:
    """The unconstrained optimum collides; the search marks it and ranks it by the shortfall."""
    case = load_case(CELL_CASE)
    geometry = PathGeometry.from_case(case)
    space = SearchSpace.from_bounds(case.bounds)
    optimum = np.array([[0.2191, 0.1099, 0.0023, 0.0001, 0.3293, 1.1243]])
    with_cell = PlacementFitness(case, space, geometry, "smooth").evaluate(optimum)
    without = PlacementFitness(
        dataclasses.replace(case, cell=None), space, geometry, "smooth"
    ).evaluate(optimum)
    assert without.feasible[0]
    assert not with_cell.feasible[0]
    assert with_cell.finding[0] == code(Status.COLLISION)
    assert 0.25 < with_cell.violation[0] < 0.5


@pytest.mark.parametrize(
    ("robot", "home"),
    [
        (puma560(), [0.0, 0.0, 0.0, 0.0, 0.0, 0.0]),
        (ur5(), [0.0, -np.pi / 2, 0.0, -np.pi / 2, 0.0, 0.0]),
    ],
    ids=["puma560", "ur5"],
)
def test_builtin_capsules_keep_the_default_clearance_at_home(robot, home) -> None:
    geometry = CellGeometry.from_cell(Cell(), robot)
    _, own = geometry.screen(joint_frames(robot, np.array([home])), np.eye(4))
    assert own.min() > Cell().clearance


def test_checker_status_is_collision_when_only_the_clearance_breaks() -> None:
    """A smooth sweep within every joint limit through a planted ball: status COLLISION."""
    robot = puma560()
    n = 400
    u = np.linspace(0.0, 1.0, n)
    q = np.zeros((n, 6))
    q[:, 0] = np.pi / 2 * u**3 * (10.0 - 15.0 * u + 6.0 * u**2)  # rest to rest, 4 s
    q[:, 2] = -np.pi / 2
    elbow = joint_frames(robot, q[n // 2])[3, :3, 3]
    ball = Body("ball", Shape.SPHERE, pose_matrix(elbow, np.eye(3)), [0.05, 0.0, 0.0])
    geometry = CellGeometry.from_cell(Cell(obstacles=(ball,), clearance=0.01), robot)
    report = check_trajectory(robot, q, TS, cell=geometry)
    assert {v.limit for v in report.violations} == {"collision"}, [
        v.message for v in report.violations
    ]
    assert report.status is Status.COLLISION and not report.success
    assert report.cell is not None and report.cell.status is Status.COLLISION
    assert report.task_margins["clearance"] < 0


def test_cell_modules_import_no_higher_layer() -> None:
    """cell/ sits below planning: none of its modules imports planning or anything above."""
    higher = (
        "trackplan.jointpath",
        "trackplan.timing",
        "trackplan.planning",
        "trackplan.search",
        "trackplan.study",
        "trackplan.outputs",
        "trackplan.report",
        "trackplan.cli",
    )
    found = []
    for file in sorted((REPO / "trackplan" / "cell").rglob("*.py")):
        for node in ast.walk(ast.parse(file.read_text(encoding="utf-8"))):
            names = []
            if isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
                names = [node.module]
            elif isinstance(node, ast.Import):
                names = [alias.name for alias in node.names]
            found += [
                f"{file.name}:{node.lineno} {name}"
                for name in names
                if any(name == top or name.startswith(top + ".") for top in higher)
            ]
    assert not found
