"""Programs built by hand for the URScript tests: targets from joint vectors through the
robot's forward kinematics, so that every target's pose and joints agree."""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from trackplan.io.robot_file import builtin_robot
from trackplan.programs.model import (
    Budget,
    CircularMove,
    JointMove,
    LinearMove,
    MotionForm,
    Program,
    Section,
    SplineMove,
    Target,
)
from trackplan.robots.controller import ControllerConvention
from trackplan.robots.kinematics import forward_kinematics
from trackplan.robots.model import Robot

UR_SOURCE = (
    "Universal Robots e-Series: joints as ur_description (UniversalRobots/"
    "Universal_Robots_ROS2_Description, config/<robot>/default_kinematics.yaml), the "
    "controller's Base = the DH base frame of this URDF (ur_macro.xacro, base_link-base_"
    "fixed_joint), 500 Hz servo (Universal_Robots_Client_Library, rtde_client.h)"
)

START = np.array([0.3, -1.9, 1.7, -1.4, -1.57, 0.2])
"""A UR configuration with the tool pointing down in front of the robot, rad."""


def ur_convention(cycle: float | None = 0.002) -> ControllerConvention:
    """The UR controller convention of the built-in ur5e/ur10e: identity joints, the
    model base is the controller's Base, the e-Series cycle."""
    return ControllerConvention(
        vendor="ur",
        signs=np.ones(6),
        offsets=np.zeros(6),
        cycle=cycle,
        source=UR_SOURCE,
    )


def ur_robot(name: str = "ur5e", cycle: float | None = 0.002) -> Robot:
    """A built-in UR with a 0.15 m tool tilted 10° and its controller convention."""
    tool = np.eye(4)
    tool[:3, 3] = [0.01, 0.0, 0.15]
    angle = np.radians(10.0)
    tool[:3, :3] = [
        [np.cos(angle), 0, np.sin(angle)],
        [0, 1, 0],
        [-np.sin(angle), 0, np.cos(angle)],
    ]
    return replace(builtin_robot(name), controller=ur_convention(cycle), T_flange_tool=tool)


def placement() -> np.ndarray:
    """The part frame in the robot model's base: 0.1 m up, turned 30° about z, m."""
    frame = np.eye(4)
    c, s = np.cos(np.radians(30.0)), np.sin(np.radians(30.0))
    frame[:3, :3] = [[c, -s, 0], [s, c, 0], [0, 0, 1]]
    frame[:3, 3] = [0.05, -0.02, 0.1]
    return frame


def target(robot: Robot, q: np.ndarray) -> Target:
    """The target of model joints ``q``: the TCP in the part frame and the joints."""
    q = np.asarray(q, dtype=float)
    pose = np.linalg.inv(placement()) @ forward_kinematics(robot, q)
    return Target(pose=pose, joints=robot.convention.to_controller(q), model_joints=q)


def joint_move(robot: Robot, q: np.ndarray, **kwargs: float) -> JointMove:
    """A joint move to model joints ``q``."""
    q = np.asarray(q, dtype=float)
    kwargs.setdefault("speed", 0.25)
    return JointMove(joints=robot.convention.to_controller(q), model_joints=q, **kwargs)


def walk(n: int, step: float = 0.01, seed: int = 1) -> np.ndarray:
    """``n`` joint vectors walking from :data:`START` in small random steps, (n, 6), rad."""
    rng = np.random.default_rng(seed)
    return START + np.cumsum(rng.uniform(-step, step, (n, 6)), axis=0)


def program(
    robot: Robot,
    sections: tuple[Section, ...],
    *,
    name: str = "weld_cell",
    motion: MotionForm = "cartesian",
    sample_time: float = 0.004,
    period: float | None = None,
    vendor: str = "ur",
) -> Program:
    """A program of ``sections`` for ``robot``, its frames from :func:`placement`."""
    return Program(
        name=name,
        motion=motion,
        robot=robot.name,
        vendor=vendor,
        n_dof=robot.n_dof,
        base=robot.convention.world_from_base(placement()),
        tool=robot.T_flange_tool,
        sections=sections,
        header=("trackplan test", "case: hand-built", f"robot: {robot.name}"),
        sample_time=sample_time,
        period=period,
        budget=Budget(tolerance=5e-4, tracking_error=1e-4, chord_error=1e-4, zone=2e-4)
        if motion == "cartesian"
        else None,
        v_max=robot.v_max,
    )


def cartesian_program(robot: Robot, **kwargs: object) -> Program:
    """Start, a seam of a line, an arc and a spline, an air move and a second seam."""
    q = walk(16)
    start = Section(kind="start", label="start", moves=(joint_move(robot, q[0]),))
    seam = Section(
        kind="seam",
        label="seam_1",
        moves=(
            LinearMove(target=target(robot, q[1]), speed=0.01, zone=2e-4),
            CircularMove(
                via=target(robot, q[2]), target=target(robot, q[3]), speed=0.01, zone=2e-4
            ),
            SplineMove(
                targets=tuple(target(robot, q[k]) for k in range(4, 10)), speed=0.012, zone=1e-4
            ),
        ),
    )
    air = Section(kind="air", label="air", moves=(joint_move(robot, q[11], speed=0.5, zone=0.0),))
    seam_2 = Section(
        kind="seam",
        label="seam_2",
        moves=tuple(
            LinearMove(target=target(robot, q[k]), speed=0.008, zone=2e-4 if k < 15 else 0.0)
            for k in range(12, 16)
        ),
    )
    return program(robot, (start, seam, air, seam_2), **kwargs)  # type: ignore[arg-type]


def joint_program(robot: Robot, n: int = 40, period: float = 0.008, **kwargs: object) -> Program:
    """Start, then ``n`` timed joint moves (the sampled trajectory) of ``period`` s."""
    q = walk(n + 1, step=0.002)
    start = Section(kind="start", label="start", moves=(joint_move(robot, q[0]),))
    samples = Section(
        kind="seam",
        label="seam_1",
        moves=tuple(joint_move(robot, q[k], speed=1.0, duration=period) for k in range(1, n + 1)),
    )
    kwargs.setdefault("sample_time", 0.004)
    return program(robot, (start, samples), motion="joint", period=period, **kwargs)  # type: ignore[arg-type]
