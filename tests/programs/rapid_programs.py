"""The ABB robots and the programs of the RAPID tests, built with
:mod:`tests.programs.programs`."""

from __future__ import annotations

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
    CircularMove,
    LinearMove,
    Move,
    Program,
    Section,
    SplineMove,
    Target,
)
from trackplan.robots.controller import ControllerConvention
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


TOOL = transform((0.02, -0.01, 0.18), (0.0, 25.0, 5.0))
"""A TCP in the flange."""

BASE = transform((1.1, 0.3, 0.2), (0.0, 0.0, 30.0))
"""The part frame in the controller's world."""

HEADER = (
    "trackplan 0.0 test",
    "case: hand-built",
    "tolerance: chord 0.1 mm + zone 0.5 mm ≤ 1.0 mm − tracking 0.2 mm",
)


def abb_robot(name: str, *, tool: np.ndarray = TOOL) -> Robot:
    """A built-in ABB robot with its controller convention built in Python."""
    convention = IRB2400_CONVENTION if name == "abb_irb2400" else IRB1600_CONVENTION
    return vendor_robot(name, convention, tool)


def puma(*, tool: np.ndarray = TOOL) -> Robot:
    """The PUMA560, identity convention (generic)."""
    return vendor_robot("puma560", None, tool)


def cartesian_program(robot: Robot, q0: np.ndarray, *, name: str = "weld_cell") -> Program:
    """A start move, a seam (line, arc, spline, line to a stop), an air move and a second
    seam, from joint vectors around ``q0``."""
    q0 = np.asarray(q0, dtype=float)
    steps = np.array([0.02, 0.015, -0.01, 0.03, -0.02, 0.04])

    def t(k: float) -> Target:
        return make_target(robot, q0 + k * steps, BASE)

    seam_a: tuple[Move, ...] = (
        LinearMove(target=t(1), speed=0.02, zone=0.0005),
        CircularMove(via=t(1.5), target=t(2), speed=0.02, zone=0.0005),
        SplineMove(targets=(t(2.3), t(2.6), t(3.0)), speed=0.015, zone=0.0002),
        LinearMove(target=t(4), speed=0.02, zone=0.0),
    )
    q_air = q0 + np.array([0.2, -0.05, 0.05, 0.1, 0.1, -0.2])
    seam_b: tuple[Move, ...] = (
        LinearMove(target=make_target(robot, q_air + steps, BASE), speed=0.01, zone=0.0),
    )
    return program(
        robot,
        (
            Section(kind="start", label="start", moves=(joint_move(robot, q0, speed=0.3),)),
            Section(kind="seam", label="seam A", moves=seam_a),
            Section(kind="air", label="air", moves=(joint_move(robot, q_air, speed=0.5),)),
            Section(kind="seam", label="seam B", moves=seam_b),
        ),
        base=BASE,
        name=name,
        header=HEADER,
    )


def joint_program(robot: Robot, q0: np.ndarray, *, n: int = 12, period: float = 0.012) -> Program:
    """The joint form: a start move, then ``n`` timed samples."""
    q0 = np.asarray(q0, dtype=float)
    samples = q0 + np.linspace(0.0, 1.0, n)[:, None] * np.array([0.1, -0.05, 0.08, 0.2, 0.1, -0.3])
    return joint_form(robot, samples, period=period, start_speed=0.3, base=BASE, header=HEADER)
