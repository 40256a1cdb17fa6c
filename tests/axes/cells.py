"""Test machines and seams for the external axes' tests (own chains, not the built-ins)."""

from __future__ import annotations

import math

import numpy as np

from trackplan.io.robot_file import builtin_robot
from trackplan.paths.path_geometry import PathGeometry
from trackplan.paths.specs import ArcSpec, LineSpec, PointsSpec
from trackplan.robots.machine import Machine, Positioner, Track
from trackplan.robots.model import Robot
from trackplan.tool.spec import ToolFrame, ToolSpec

TOLERANCE = 5e-4
"""The seams' path tolerance, m."""


def _translation(x: float, y: float, z: float) -> np.ndarray:
    T = np.eye(4)
    T[:3, 3] = x, y, z
    return T


def tilt_rotate_chain(rotate_range: float = 200.0) -> Robot:
    """A two-axis tilt-rotate positioner with the Yaskawa MotoPos D500's numbers: tilt about
    −y 0.380 m above the base, table rotation about −z crossing it, table face 0.150 m up
    (ros-industrial/motoman, motoman_motopos_d500_support/urdf/motopos_d500_macro.xacro);
    ranges ±135° and ±200°, speeds 80 and 160 °/s from the same file; acceleration and jerk
    assumed. ``rotate_range``: the rotate axis's ± range, degrees."""
    return Robot(
        name="test-tilt-rotate",
        origins=np.stack([_translation(0.0, 0.0, 0.380), np.eye(4)]),
        axes=np.array([[0.0, -1.0, 0.0], [0.0, 0.0, -1.0]]),
        q_min=np.radians([-135.0, -rotate_range]),
        q_max=np.radians([135.0, rotate_range]),
        v_max=np.radians([80.0, 160.0]),
        a_max=np.array([5.0, 10.0]),
        j_max=np.array([50.0, 100.0]),
        T_tip=_translation(0.0, 0.0, 0.150),
        joint_names=("tilt", "rotate"),
    )


def turntable_chain() -> Robot:
    """A one-axis turntable about +z, table face 0.5 m up, ±360°."""
    return Robot(
        name="test-turntable",
        origins=np.stack([_translation(0.0, 0.0, 0.5)]),
        axes=np.array([[0.0, 0.0, 1.0]]),
        q_min=np.radians([-360.0]),
        q_max=np.radians([360.0]),
        v_max=np.radians([90.0]),
        a_max=np.array([5.0]),
        j_max=np.array([50.0]),
        joint_names=("turn",),
    )


def head_stock_chain() -> Robot:
    """A one-axis head-stock turning the part about the horizontal +x axis 0.8 m up,
    ±360° (the two-axis head-tailstock's drive)."""
    return Robot(
        name="test-head-stock",
        origins=np.stack([_translation(0.0, 0.0, 0.8)]),
        axes=np.array([[1.0, 0.0, 0.0]]),
        q_min=np.radians([-360.0]),
        q_max=np.radians([360.0]),
        v_max=np.radians([90.0]),
        a_max=np.array([5.0]),
        j_max=np.array([50.0]),
        joint_names=("spin",),
    )


def machine(
    chain: Robot | None = None,
    pose: tuple[float, ...] = (0.8, 0.0, -0.6, 0.0, 0.0, 0.0),
    track: Track | None = None,
) -> Machine:
    """A UR5e with the positioner ``chain`` at ``pose`` in the cell, and ``track``."""
    positioner = None if chain is None else Positioner(chain, np.array(pose, dtype=float))
    return Machine(builtin_robot("ur5e"), track, positioner)


def seam_tool() -> ToolSpec:
    """The seam frame with the segments' own weld normals."""
    return ToolSpec(frame=ToolFrame.SEAM)


def pipe_fillet(radius: float = 0.06) -> PathGeometry:
    """A 360° fillet round a pipe standing on a plate (the pipe's axis +z of the part
    frame): an arc whose weld normal is the 45° bisector of the plate's normal and the
    pipe's outward radial, carried round the arc."""
    arc = ArcSpec(
        np.zeros(3), np.array([0.0, 0.0, 1.0]), 2 * math.pi, weld_normal=np.array([1.0, 0, 1])
    )
    return PathGeometry.build(np.array([radius, 0.0, 0.0]), [arc], TOLERANCE)


def pipe_butt(radius: float = 0.08) -> PathGeometry:
    """A circumferential butt weld round a pipe (axis +z of the part frame): the weld
    normal is the pipe's outward radial, carried round the arc."""
    arc = ArcSpec(
        np.zeros(3), np.array([0.0, 0.0, 1.0]), 2 * math.pi, weld_normal=np.array([1.0, 0, 0])
    )
    return PathGeometry.build(np.array([radius, 0.0, 0.0]), [arc], TOLERANCE)


def saddle_points(
    branch: float = 0.05, main: float = 0.1, count: int = 96
) -> tuple[np.ndarray, np.ndarray]:
    """The saddle where a branch pipe (radius ``branch``, axis z) meets a main pipe (radius
    ``main``, axis x) at 90°: points (count + 1, 3) from φ = 0 round to 2π and the weld
    normals there, the bisector of the two pipes' outward normals."""
    phi = np.linspace(0.0, 2 * math.pi, count + 1)
    x, y = branch * np.cos(phi), branch * np.sin(phi)
    z = np.sqrt(main**2 - y**2)
    points = np.column_stack([x, y, z])
    outward_branch = np.column_stack([np.cos(phi), np.sin(phi), 0 * phi])
    outward_main = np.column_stack([0 * phi, y, z]) / main
    normal = outward_branch + outward_main
    return points, normal / np.linalg.norm(normal, axis=1, keepdims=True)


def saddle(branch: float = 0.05, main: float = 0.1, count: int = 96) -> PathGeometry:
    """The saddle as a points segment with a normal per point."""
    points, normals = saddle_points(branch, main, count)
    spec = PointsSpec(points[1:], normals[1:], start_normal=normals[0])
    return PathGeometry.build(points[0], [spec], TOLERANCE)


def plate_line(
    length: float = 0.3, direction: tuple[float, float, float] = (1, 0, 0)
) -> PathGeometry:
    """A straight seam on a plate (normal +z of the part frame)."""
    to = length * np.asarray(direction, dtype=float) / np.linalg.norm(direction)
    return PathGeometry.build(np.zeros(3), [LineSpec(to)], TOLERANCE)


def plate_tool() -> ToolSpec:
    """The seam frame with the plate's normal +z."""
    return ToolSpec(frame=ToolFrame.SEAM, normal=np.array([0.0, 0.0, 1.0]))
