"""Programs built by hand for the RAPID tests: targets from joint vectors through the
robot's forward kinematics, so that every target's pose and joints agree."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import yaml
from scipy.spatial.transform import Rotation

from trackplan.errors import CaseError
from trackplan.io.robot_file import builtin_robot, library_robots, load_robot_text
from trackplan.programs.model import (
    CircularMove,
    JointMove,
    LinearMove,
    Move,
    Program,
    Section,
    SplineMove,
    Target,
)
from trackplan.robots.controller import ControllerConvention
from trackplan.robots.kinematics import forward_kinematics
from trackplan.robots.model import Robot

IRB2400_CONVENTION = ControllerConvention(
    vendor="abb",
    signs=np.ones(6),
    offsets=np.zeros(6),
    # abb_driver (ros-industrial/abb, removed in 4879186; abb_joint_downloader_node.cpp):
    # linkage_transform(..., +1) "POSITIVE factor for joint->motor": θ3 = q3 + q2.
    coupling=(2, 1, 1.0),
    source="ros-industrial/abb: abb_driver J23_coupled (IRB 2400: true)",
)
"""The IRB 2400's parallel arm: the controller's axis 3 is q3 + q2."""

IRB1600_CONVENTION = ControllerConvention(
    vendor="abb",
    signs=np.ones(6),
    offsets=np.zeros(6),
    source="ros-industrial/abb_experimental #155: J23_coupled false (serial arm)",
)


def transform(
    xyz: tuple[float, float, float], rotvec_deg: tuple[float, float, float]
) -> np.ndarray:
    """A 4×4 transform from a translation (m) and a rotation vector (degrees)."""
    T = np.eye(4)
    T[:3, :3] = Rotation.from_rotvec(np.radians(rotvec_deg)).as_matrix()
    T[:3, 3] = xyz
    return T


TOOL = transform((0.02, -0.01, 0.18), (0.0, 25.0, 5.0))
"""A TCP in the flange."""

BASE = transform((1.1, 0.3, 0.2), (0.0, 0.0, 30.0))
"""The part frame in the controller's world."""


def library_robot(name: str) -> Robot:
    """A built-in robot; its ``controller:`` block is left out where the robot-file schema
    does not know it yet (it lands with the export core), so these tests run either way."""
    try:
        return builtin_robot(name)
    except CaseError as error:
        if "controller" not in str(error):
            raise
    path = library_robots()[name]
    data = yaml.safe_load(path.read_text(encoding="utf-8"))
    data.pop("controller")
    return load_robot_text(yaml.safe_dump(data), str(path))


def abb_robot(name: str, *, tool: np.ndarray = TOOL) -> Robot:
    """A built-in ABB robot with its controller convention built in Python."""
    convention = IRB2400_CONVENTION if name == "abb_irb2400" else IRB1600_CONVENTION
    return replace(library_robot(name), controller=convention, T_flange_tool=tool)


def puma(*, tool: np.ndarray = TOOL) -> Robot:
    """The PUMA560, identity convention (generic)."""
    return replace(builtin_robot("puma560"), T_flange_tool=tool)


def make_target(robot: Robot, q: np.ndarray, base: np.ndarray = BASE) -> Target:
    """The target of model joints ``q``: the TCP in the part frame, controller joints."""
    q = np.asarray(q, dtype=float)
    convention = robot.convention
    world_tcp = convention.world_from_base(forward_kinematics(robot, q))
    return Target(
        pose=np.linalg.inv(base) @ world_tcp, joints=convention.to_controller(q), model_joints=q
    )


def joint_move(robot: Robot, q: np.ndarray, **kwargs: float) -> JointMove:
    q = np.asarray(q, dtype=float)
    return JointMove(joints=robot.convention.to_controller(q), model_joints=q, **kwargs)


def program(
    robot: Robot,
    sections: tuple[Section, ...],
    *,
    name: str = "weld_cell",
    motion: str = "cartesian",
    period: float | None = None,
    feasible: bool = True,
) -> Program:
    convention = robot.convention
    return Program(
        name=name,
        motion=motion,  # type: ignore[arg-type]
        robot=robot.name,
        vendor=convention.vendor,
        n_dof=robot.n_dof,
        base=BASE,
        tool=robot.T_flange_tool,
        sections=sections,
        header=(
            "trackplan 0.0 test",
            f"case: hand-built; robot: {robot.name}",
            "tolerance: chord 0.1 mm + zone 0.5 mm ≤ 1.0 mm − tracking 0.2 mm",
        ),
        sample_time=0.004,
        period=period,
        feasible=feasible,
        v_max=robot.v_max,
    )


def cartesian_program(robot: Robot, q0: np.ndarray, *, name: str = "weld_cell") -> Program:
    """A start move, a seam (line, arc, spline, line to a stop), an air move and a second
    seam, from joint vectors around ``q0``."""
    q0 = np.asarray(q0, dtype=float)
    steps = np.array([0.02, 0.015, -0.01, 0.03, -0.02, 0.04])

    def t(k: float) -> Target:
        return make_target(robot, q0 + k * steps)

    seam_a: tuple[Move, ...] = (
        LinearMove(target=t(1), speed=0.02, zone=0.0005),
        CircularMove(via=t(1.5), target=t(2), speed=0.02, zone=0.0005),
        SplineMove(targets=(t(2.3), t(2.6), t(3.0)), speed=0.015, zone=0.0002),
        LinearMove(target=t(4), speed=0.02, zone=0.0),
    )
    q_air = q0 + np.array([0.2, -0.05, 0.05, 0.1, 0.1, -0.2])
    seam_b: tuple[Move, ...] = (
        LinearMove(target=make_target(robot, q_air + steps), speed=0.01, zone=0.0),
    )
    return program(
        robot,
        (
            Section(kind="start", label="start", moves=(joint_move(robot, q0, speed=0.3),)),
            Section(kind="seam", label="seam A", moves=seam_a),
            Section(kind="air", label="air", moves=(joint_move(robot, q_air, speed=0.5),)),
            Section(kind="seam", label="seam B", moves=seam_b),
        ),
        name=name,
    )


def joint_program(robot: Robot, q0: np.ndarray, *, n: int = 12, period: float = 0.012) -> Program:
    """The joint form: a start move, then ``n`` timed samples."""
    q0 = np.asarray(q0, dtype=float)
    samples = q0 + np.linspace(0.0, 1.0, n)[:, None] * np.array([0.1, -0.05, 0.08, 0.2, 0.1, -0.3])
    moves = tuple(joint_move(robot, q, speed=1.0, duration=period) for q in samples[1:])
    return program(
        robot,
        (
            Section(kind="start", label="start", moves=(joint_move(robot, q0, speed=0.3),)),
            Section(kind="seam", label="seam A", moves=moves),
        ),
        motion="joint",
        period=period,
    )


def expected_targets(prog: Program) -> list[tuple[str, object]]:
    """(kind, Target or JointMove) in the order RAPID writes them (a spline as lines)."""
    out: list[tuple[str, object]] = []
    for move in prog.moves():
        if isinstance(move, JointMove):
            out.append(("joint", move))
        elif isinstance(move, LinearMove):
            out.append(("linear", move.target))
        elif isinstance(move, CircularMove):
            out.extend([("circular_via", move.via), ("circular_end", move.target)])
        else:
            out.extend(("linear", target) for target in move.targets)
    return out
