"""Programs built by hand for the language tests, from joint vectors through the robot's
forward kinematics, so that every target's pose and joints agree.

Each language's tests lay out their own moves (the speeds, zones and shapes they assert);
the robot under a test's convention, the targets, the joint moves, the program around the
sections and the joint form are built here, once, the way
:func:`trackplan.programs.build_program` states them: a Cartesian target is the TCP in the
part frame, the program's ``base`` is the part frame in the controller's world, joints are
in the controller's convention, the model's beside them.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import replace
from typing import Any

import numpy as np
from scipy.spatial.transform import Rotation

from trackplan.io.robot_file import builtin_robot
from trackplan.programs.model import JointMove, MotionForm, Program, Section, Target
from trackplan.robots.controller import ControllerConvention
from trackplan.robots.kinematics import forward_kinematics
from trackplan.robots.model import Robot


def transform(xyz: Sequence[float], rotvec_deg: Sequence[float] = (0.0, 0.0, 0.0)) -> np.ndarray:
    """A 4×4 transform from a translation (m) and a rotation vector (degrees)."""
    T = np.eye(4)
    T[:3, :3] = Rotation.from_rotvec(np.radians(rotvec_deg)).as_matrix()
    T[:3, 3] = xyz
    return T


def vendor_robot(
    name: str, convention: ControllerConvention | None, tool: np.ndarray | None = None
) -> Robot:
    """The built-in robot ``name`` under the test's own ``convention`` (None keeps the
    robot file's) with the TCP ``tool`` in the flange, (4, 4), m (None keeps the file's)."""
    robot = builtin_robot(name)
    if convention is not None:
        robot = replace(robot, controller=convention)
    if tool is not None:
        robot = replace(robot, T_flange_tool=tool)
    return robot


def make_target(robot: Robot, q: np.ndarray, base: np.ndarray) -> Target:
    """The target of model joints ``q`` (n,), rad: the TCP (forward kinematics, the
    robot's tool included) in the part frame ``base`` (the part in the controller's world,
    (4, 4), m), and the joints in the controller's convention."""
    q = np.asarray(q, dtype=float)
    convention = robot.convention
    world_tcp = convention.world_from_base(forward_kinematics(robot, q))
    return Target(
        pose=np.linalg.inv(base) @ world_tcp, joints=convention.to_controller(q), model_joints=q
    )


def joint_move(robot: Robot, q: np.ndarray, **fields: Any) -> JointMove:
    """A joint move to model joints ``q`` (n,), rad; ``fields`` are the move's (speed,
    zone, duration)."""
    q = np.asarray(q, dtype=float)
    return JointMove(joints=robot.convention.to_controller(q), model_joints=q, **fields)


def program(
    robot: Robot,
    sections: tuple[Section, ...],
    *,
    base: np.ndarray,
    name: str = "weld_cell",
    motion: MotionForm = "cartesian",
    header: tuple[str, ...] = ("trackplan test",),
    sample_time: float = 0.004,
    **fields: Any,
) -> Program:
    """The program of ``sections`` for ``robot``: its vendor, joint count, joint rates and
    tool, the part frame ``base`` (4, 4), m; ``fields`` are further Program fields
    (period, budget, feasible, vendor)."""
    arguments: dict[str, Any] = {
        "vendor": robot.convention.vendor,
        "v_max": robot.v_max,
        **fields,
    }
    return Program(
        name=name,
        motion=motion,
        robot=robot.name,
        n_dof=robot.n_dof,
        base=base,
        tool=robot.T_flange_tool,
        sections=sections,
        header=header,
        sample_time=sample_time,
        **arguments,
    )


def joint_form(
    robot: Robot,
    samples: np.ndarray,
    *,
    period: float,
    start_speed: float,
    speed: float | Sequence[float] = 1.0,
    **fields: Any,
) -> Program:
    """The joint form: a joint move to ``samples[0]`` at ``start_speed``, then one move of
    ``period`` s to each further sample (model joints, (m, n), rad) at ``speed`` (one for
    all, or one a timed move); ``fields`` as :func:`program`'s."""
    samples = np.asarray(samples, dtype=float)
    speeds = np.broadcast_to(np.asarray(speed, dtype=float), (len(samples) - 1,))
    timed = tuple(
        joint_move(robot, q, speed=float(v), duration=period)
        for q, v in zip(samples[1:], speeds, strict=True)
    )
    sections = (
        Section(
            kind="start", label="start", moves=(joint_move(robot, samples[0], speed=start_speed),)
        ),
        Section(kind="seam", label="seam 1", moves=timed),
    )
    return program(robot, sections, motion="joint", period=period, **fields)


__all__ = ["joint_form", "joint_move", "make_target", "program", "transform", "vendor_robot"]
