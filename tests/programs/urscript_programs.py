"""The URs and the programs of the URScript tests, built with
:mod:`tests.programs.programs`."""

from __future__ import annotations

from typing import Any

import numpy as np

from tests.programs.programs import (
    joint_form,
    joint_move,
    make_target,
    program,
    transform,
    vendor_robot,
)
from trackplan.programs.model import (
    Budget,
    CircularMove,
    LinearMove,
    Program,
    Section,
    SplineMove,
    Target,
)
from trackplan.robots.controller import ControllerConvention
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
    return vendor_robot(name, ur_convention(cycle), transform((0.01, 0.0, 0.15), (0, 10, 0)))


def placement() -> np.ndarray:
    """The part frame in the robot model's base: 0.1 m up, turned 30° about z, m."""
    return transform((0.05, -0.02, 0.1), (0.0, 0.0, 30.0))


def part_base(robot: Robot) -> np.ndarray:
    """The program's base: :func:`placement` in the controller's Base, (4, 4), m."""
    return robot.convention.world_from_base(placement())


def header(robot: Robot) -> tuple[str, ...]:
    """The programs' header lines."""
    return ("trackplan test", "case: hand-built", f"robot: {robot.name}")


def walk(n: int, step: float = 0.01, seed: int = 1) -> np.ndarray:
    """``n`` joint vectors walking from :data:`START` in small random steps, (n, 6), rad."""
    rng = np.random.default_rng(seed)
    return START + np.cumsum(rng.uniform(-step, step, (n, 6)), axis=0)


def ur_program(robot: Robot, sections: tuple[Section, ...], **fields: Any) -> Program:
    """A program of ``sections`` for ``robot`` in the part frame :func:`part_base`, with a
    tolerance budget in the ``cartesian`` form; ``fields`` as
    :func:`tests.programs.programs.program`'s."""
    cartesian = fields.get("motion", "cartesian") == "cartesian"
    budget = Budget(tolerance=5e-4, tracking_error=1e-4, chord_error=1e-4, zone=2e-4)
    fields.setdefault("budget", budget if cartesian else None)
    return program(robot, sections, base=part_base(robot), header=header(robot), **fields)


def cartesian_program(robot: Robot, **kwargs: Any) -> Program:
    """Start, a seam of a line, an arc and a spline, an air move and a second seam."""
    q = walk(16)
    base = part_base(robot)

    def target(k: int) -> Target:
        return make_target(robot, q[k], base)

    start = Section(kind="start", label="start", moves=(joint_move(robot, q[0], speed=0.25),))
    seam = Section(
        kind="seam",
        label="seam_1",
        moves=(
            LinearMove(target=target(1), speed=0.01, zone=2e-4),
            CircularMove(via=target(2), target=target(3), speed=0.01, zone=2e-4),
            SplineMove(targets=tuple(target(k) for k in range(4, 10)), speed=0.012, zone=1e-4),
        ),
    )
    air = Section(kind="air", label="air", moves=(joint_move(robot, q[11], speed=0.5, zone=0.0),))
    seam_2 = Section(
        kind="seam",
        label="seam_2",
        moves=tuple(
            LinearMove(target=target(k), speed=0.008, zone=2e-4 if k < 15 else 0.0)
            for k in range(12, 16)
        ),
    )
    return ur_program(robot, (start, seam, air, seam_2), **kwargs)


def joint_program(robot: Robot, n: int = 40, period: float = 0.008, **kwargs: Any) -> Program:
    """Start, then ``n`` timed joint moves (the sampled trajectory) of ``period`` s."""
    samples = walk(n + 1, step=0.002)
    return joint_form(
        robot,
        samples,
        period=period,
        start_speed=0.25,
        base=part_base(robot),
        header=header(robot),
        **kwargs,
    )
