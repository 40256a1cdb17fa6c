"""The robots' link capsules in the cell: built-in models, self-collision, planted collisions."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from trackplan.cell.check import check_cell
from trackplan.cell.model import Body, Cell, Shape
from trackplan.cell.robot_bodies import builtin_link_capsules
from trackplan.cell.screening import CellGeometry
from trackplan.frames import pose_matrix
from trackplan.io.case_file import load_case
from trackplan.io.robot_file import builtin_names, builtin_robot, load_robot
from trackplan.planning.plan import plan
from trackplan.robots.kinematics import joint_frames

REPO = Path(__file__).resolve().parents[2]
TS = 0.01
HALF_PI = np.pi / 2
HOME = {
    # Franka's "ready" pose (franka_ros franka_control/config/start_pose.yaml)
    "franka_panda": [0.0, -HALF_PI / 2, 0.0, -3 * HALF_PI / 2, 0.0, HALF_PI, HALF_PI / 2],
    # KUKA's HOME: A2 = -90° (upper arm up), A3 = +90° (forearm level)
    "kuka_kr6_r700_sixx": [0.0, -HALF_PI, HALF_PI, 0.0, HALF_PI, 0.0],
    "kuka_kr10_r1420": [0.0, -HALF_PI, HALF_PI, 0.0, HALF_PI, 0.0],
    # the UR arms upright, wrist 1 turned down
    "ur5": [0.0, -HALF_PI, 0.0, -HALF_PI, 0.0, 0.0],
    "ur5e": [0.0, -HALF_PI, 0.0, -HALF_PI, 0.0, 0.0],
    "ur10e": [0.0, -HALF_PI, 0.0, -HALF_PI, 0.0, 0.0],
    # ABB, Fanuc: q = 0 is the upright home; wrist bent
    "abb_irb1600": [0.0, 0.0, 0.0, 0.0, HALF_PI, 0.0],
    "abb_irb2400": [0.0, 0.0, 0.0, 0.0, HALF_PI, 0.0],
    "fanuc_m20ia": [0.0, 0.0, 0.0, 0.0, HALF_PI, 0.0],
    # FANUC CRX: q = 0 is upright too (upper arm up, forearm level)
    "fanuc_crx10ia_l": [0.0, 0.0, 0.0, 0.0, HALF_PI, 0.0],
    "puma560": [0.0, 0.0, 0.0, 0.0, HALF_PI, 0.0],
    # the S-R-S arms: shoulder forward, elbow bent 90°, wrist bent back (the iiwa's A4 and
    # the SIA10D's U turn about -y)
    "kuka_iiwa14": [0.0, 0.5, 0.0, -HALF_PI, 0.0, 1.0, 0.0],
    "yaskawa_sia10d": [0.0, 0.5, 0.0, -HALF_PI, 0.0, -1.0, 0.0],
    # Kinova's Home of the Gen3: 0°, 15°, 180°, -130°, 0°, 55°, 90°
    "kinova_gen3": list(np.radians([0.0, 15.0, 180.0, -130.0, 0.0, 55.0, 90.0])),
}


@pytest.mark.parametrize("name", builtin_names())
def test_no_builtin_collides_with_itself_at_zero_and_home(name: str) -> None:
    robot = builtin_robot(name)
    geometry = CellGeometry.from_cell(Cell(), robot)
    assert len(geometry.self_pairs) > 0
    q = np.array([np.zeros(robot.n_dof), HOME[name]])
    report = check_cell(geometry, robot, q, TS, np.eye(4))
    assert report.success, report.violations[0].message
    assert report.min_clearance > Cell().clearance


def kuka_sweep() -> np.ndarray:
    """KR6 R700 sixx at HOME, joint 1 sweeping 90°, shape (100, 6)."""
    q = np.tile(HOME["kuka_kr6_r700_sixx"], (100, 1))
    q[:, 0] = np.linspace(-HALF_PI / 2, HALF_PI / 2, 100)
    return q


def test_planted_obstacle_hits_a_urdf_robots_forearm() -> None:
    robot = builtin_robot("kuka_kr6_r700_sixx")
    q = kuka_sweep()
    links = builtin_link_capsules(robot)
    forearm = links.name.index("link_4")
    frames = joint_frames(robot, q[50])
    T = frames[links.frame[forearm]]
    middle = T[:3, :3] @ links.segment[forearm].mean(axis=0) + T[:3, 3]
    ball = Body("ball", Shape.SPHERE, pose_matrix(middle, np.eye(3)), [0.03, 0.0, 0.0])
    geometry = CellGeometry.from_cell(Cell(obstacles=(ball,), clearance=0.01), robot)
    report = check_cell(geometry, robot, q, TS, np.eye(4))
    assert not report.success
    worst = min(report.violations, key=lambda v: v.worst)
    assert worst.message.startswith("collision: link_4 hits ball")
    # the ball's centre is on the capsule's axis: 55 mm + 30 mm deep (coal, exactly)
    assert worst.worst == pytest.approx(-(0.055 + 0.03), abs=1e-6)
    assert worst.t_first <= 50 * TS <= worst.t_last
    # 0.5 m above the forearm the same sweep is clear
    T_above = pose_matrix(middle + np.array([0.0, 0.0, 0.5]), np.eye(3))
    above = Body("ball", Shape.SPHERE, T_above, [0.03, 0.0, 0.0])
    clear = CellGeometry.from_cell(Cell(obstacles=(above,), clearance=0.01), robot)
    assert check_cell(clear, robot, q, TS, np.eye(4)).success


TWO_LINK_URDF = """<?xml version="1.0"?>
<robot name="two-link">
  <link name="base"><collision><origin xyz="0 0 0.05"/>
    <geometry><cylinder radius="0.08" length="0.1"/></geometry></collision></link>
  <link name="upper"><collision><origin xyz="0.2 0 0" rpy="0 1.5707963267948966 0"/>
    <geometry><cylinder radius="0.04" length="0.4"/></geometry></collision></link>
  <link name="fore"><collision><origin xyz="0.15 0 0"/>
    <geometry><box size="0.3 0.06 0.04"/></geometry></collision></link>
  <link name="tip"/>
  <joint name="j1" type="revolute"><parent link="base"/><child link="upper"/>
    <origin xyz="0 0 0.3"/><axis xyz="0 0 1"/>
    <limit lower="-3" upper="3" velocity="2" effort="1"/></joint>
  <joint name="j2" type="revolute"><parent link="upper"/><child link="fore"/>
    <origin xyz="0.4 0 0"/><axis xyz="0 0 1"/>
    <limit lower="-3" upper="3" velocity="2" effort="1"/></joint>
  <joint name="flange" type="fixed"><parent link="fore"/><child link="tip"/>
    <origin xyz="0.3 0 0"/></joint>
</robot>
"""


def test_planted_obstacle_hits_capsules_fitted_to_urdf_collisions(tmp_path: Path) -> None:
    """A sphere on the forearm box's sweep (URDF <collision> elements, fitted capsules)."""
    (tmp_path / "arm.urdf").write_text(TWO_LINK_URDF, encoding="utf-8")
    robot = load_robot(tmp_path / "arm.urdf", assume_limits=True)
    assert robot.collision is not None and robot.collision.name == ("base", "upper", "fore")
    q = np.zeros((60, 2))
    q[:, 0] = np.linspace(0.0, HALF_PI, 60)
    # at q1 = π/4 the box's far end (0.7 m out, 0.3 m up) is at 45°
    point = [0.7 * np.cos(np.pi / 4), 0.7 * np.sin(np.pi / 4), 0.3]
    ball = Body("ball", Shape.SPHERE, pose_matrix(point, np.eye(3)), [0.02, 0.0, 0.0])
    geometry = CellGeometry.from_cell(Cell(obstacles=(ball,)), robot)
    report = check_cell(geometry, robot, q, TS, np.eye(4))
    assert not report.success
    assert report.violations[0].message.startswith("collision: fore hits ball")
    assert report.violations[0].t_first <= 30 * TS <= report.violations[0].t_last
    # just beyond the capsule (the box's half diagonal 0.036 m past its end) it is clear
    beyond = [0.7 + 0.036 + 0.03, 0.0, 0.3]
    ball = Body("ball", Shape.SPHERE, pose_matrix(beyond, np.eye(3)), [0.02, 0.0, 0.0])
    clear = CellGeometry.from_cell(Cell(obstacles=(ball,)), robot)
    assert check_cell(clear, robot, q, TS, np.eye(4)).success


def test_folded_kuka_collides_with_itself() -> None:
    """Joint 3 folds the forearm back onto the upper arm: link_4 against link_2."""
    robot = builtin_robot("kuka_kr6_r700_sixx")
    q = np.tile(HOME["kuka_kr6_r700_sixx"], (50, 1))
    q[:, 2] = np.linspace(HALF_PI, robot.q_max[2], 50)
    report = check_cell(CellGeometry.from_cell(Cell(), robot), robot, q, TS, np.eye(4))
    assert not report.success
    hits = {v.message.split(" hits ")[0].removeprefix("collision: ") for v in report.violations}
    assert "link_4" in hits or "link_2" in hits
    assert report.violations[0].t_first > 0.0  # clear at HOME, colliding once folded


def test_cell_case_on_a_kuka_checks_its_links(tmp_path: Path) -> None:
    text = (REPO / "cases" / "kuka-weld.yaml").read_text(encoding="utf-8")
    pillar = "{name: pillar, box: {size: [0.1, 0.1, 2], pose: [-0.5, 0, 0, 0, 0, 0]}}"
    cell = f"cell:\n  obstacles:\n    - {pillar}\n"
    file = tmp_path / "kuka-cell.yaml"
    file.write_text(text + cell, encoding="utf-8")
    case = load_case(file)
    assert case.cell is not None and case.cell.links is None
    geometry = CellGeometry.from_cell(case.cell, case.robot)
    checked = {who for who, other in geometry.pair_names() if other == "pillar"}
    assert checked == {"link_1", "link_2", "link_3", "link_4", "link_5"}  # the base stands


# Optimised placements of the shipped cases on the built-in arms (``trackplan optimize
# cases/NAME.yaml``, default settings; the README's for bracket-weld). The least distance
# between non-adjacent links along each plan, as measured: kuka-weld 29.2 mm (link_2, link_4),
# ur5e-glue 29.4 mm (base_link, link_2), seam-weld-fixed 33.7 mm (link_2, link_4), ur5-bead
# 11.9 mm (base, link 2: the upper arm swinging past the base), bracket-weld 11.7 mm (same).
SHIPPED_PLANS = {
    "kuka-weld": [0.3147, -0.0547, 0.0948, 0.0057, -0.1603, -0.0140],
    "ur5e-glue": [-0.2961, -0.4990, 0.2686, -0.2244, 0.0992, 2.4809],
    "seam-weld-fixed": [0.5241, 0.2063, 0.0498, -0.2943, 0.2999, 2.4350],
    "ur5-bead": [0.5961, -0.2199, -0.2935, -0.0136, -0.4994, -0.1238],
    "bracket-weld": [0.4676, -0.1793, -0.2823, 0.3, 0.0577, -2.1158],
}


@pytest.mark.slow
@pytest.mark.parametrize("case_name", sorted(SHIPPED_PLANS))
def test_shipped_plans_keep_clear_of_self_collision(case_name: str) -> None:
    case = load_case(REPO / "cases" / f"{case_name}.yaml")
    result = plan(case, np.array(SHIPPED_PLANS[case_name]))
    assert result.success
    robot = case.robot
    geometry = CellGeometry.from_cell(Cell(), robot)
    report = check_cell(geometry, robot, result.trajectory.q, TS, np.eye(4))
    assert report.success and report.min_clearance > Cell().clearance
