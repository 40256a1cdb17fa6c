"""A case file's ``tcp`` key: the tool centre point in the flange, for this case, on any arm.

``tcp: {xyz: [x, y, z], rpy: [roll, pitch, yaw]}`` (m, rad) gives
``T_flange_tcp = Trans(xyz) · RPY(rpy)`` with ``RPY = Rz(yaw) · Ry(pitch) · Rx(roll)``, the
same convention as a robot file's ``tool``. It replaces the robot's own ``T_flange_tool``
(built-in arm or robot file), so that everything downstream (IK, the cell's tool bodies,
dynamics, the report, the exports) reads the case's TCP from ``case.robot``; ``docs/files.md``
describes the key, ``docs/tool.md`` how it relates to the robot file's ``tool`` and to
``task.tool``.
"""

from __future__ import annotations

import dataclasses
import math
from typing import Any

import numpy as np

from trackplan.frames import pose_matrix, rpy_matrix
from trackplan.io.robot_bounds import MAX_LENGTH
from trackplan.io.yaml_input import Problem, StrictModel, Vec3, list_default, show
from trackplan.robots.model import Robot

TCP_KEY = "tcp"
"""The case file's key of the TCP."""


class TcpModel(StrictModel):
    """``tcp``: the TCP in the flange, ``Trans(xyz) · RPY(rpy)`` (m, rad)."""

    xyz: Vec3 = list_default(0.0, 0.0, 0.0)
    rpy: Vec3 = list_default(0.0, 0.0, 0.0)


def tcp_problems(tcp: TcpModel | None) -> list[Problem]:
    """Problems of a case's ``tcp`` after the schema (which requires three finite numbers
    each, every one within ± :data:`~trackplan.io.robot_bounds.MAX_LENGTH`): the offset's
    length within :data:`~trackplan.io.robot_bounds.MAX_LENGTH` too."""
    if tcp is None or math.hypot(*tcp.xyz) <= MAX_LENGTH:
        return []
    return [
        (
            (TCP_KEY, "xyz"),
            f"expected a TCP at most {MAX_LENGTH:g} m from the flange, got "
            f"{math.hypot(*tcp.xyz):.6g} m for {show(tcp.xyz)}: xyz is in metres",
        )
    ]


def misplaced_tool(data: Any) -> list[Problem]:
    """A top-level ``tool`` key: the TCP is ``tcp`` (``task.tool`` is the tool's
    orientation to the seam), said in one line rather than as an unknown key."""
    if not isinstance(data, dict) or "tool" not in data:
        return []
    return [
        (
            ("tool",),
            "unknown key: give the tool centre point in the flange as tcp: {xyz, rpy} "
            "(m, rad); the tool's orientation to the seam is task.tool",
        )
    ]


def tcp_matrix(tcp: TcpModel) -> np.ndarray:
    """``T_flange_tcp = Trans(xyz) · RPY(rpy)``, shape (4, 4)."""
    return pose_matrix(np.array(tcp.xyz, dtype=float), rpy_matrix(np.array(tcp.rpy, dtype=float)))


def with_tcp(robot: Robot, tcp: TcpModel | None) -> tuple[Robot, np.ndarray | None]:
    """The robot carrying the case's TCP, and the robot's own tool it replaced.

    Returns
    -------
    robot
        ``robot`` unchanged when ``tcp`` is None, else a copy whose ``T_flange_tool`` is
        :func:`tcp_matrix` of it.
    robot_tool
        None when ``tcp`` is None, else the robot's own ``T_flange_tool`` (shape (4, 4);
        the identity for a robot without a tool): :attr:`trackplan.case.Case.robot_tool`.
    """
    if tcp is None:
        return robot, None
    own = np.array(robot.T_flange_tool, dtype=float)
    own.flags.writeable = False
    return dataclasses.replace(robot, T_flange_tool=tcp_matrix(tcp)), own
