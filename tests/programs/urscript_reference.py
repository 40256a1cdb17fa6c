"""Universal Robots' conventions, written once from their definitions, independently of the
URScript writer (``trackplan.writers.urscript``); the tests compare the writer with them.

URScript has no configuration fields: a pose ``p[x, y, z, rx, ry, rz]`` carries no arm
branch, so the program reaches the start with ``movej`` on the planned joints and the
controller keeps the branch from there. What a program must get right instead is:

- the pose convention: position in m and ``(rx, ry, rz)`` an axis-angle rotation vector,
  unit axis times the angle in rad (URScript manual, module motion: "In a pose, the first 3
  coordinates is a position vector and the last 3 an axis-angle");
- ``pose_trans(p_from, p_from_to)``: the pose ``p_from_to`` given in the frame ``p_from``,
  i.e. the product of the two transforms (URScript manual, ``pose_trans``);
- the base frame: ur_description's ``base_link`` is turned by π about z from the
  controller's "Base" (UniversalRobots/Universal_Robots_ROS2_Description,
  ``urdf/ur_macro.xacro``, joint ``base_link-base_fixed_joint``, rpy ``0 0 pi``);
- the joint count and the controller step: 6 joints, ``servoj`` every 0.002 s on e-Series
  and 0.008 s on CB3 (Universal Robots, "ServoJ command" support article).
"""

from __future__ import annotations

import numpy as np

E_SERIES_CYCLE = 0.002
"""UR e-Series controller step, s (500 Hz)."""

CB3_CYCLE = 0.008
"""UR CB3 controller step, s (125 Hz)."""

BASE_FROM_BASE_LINK = np.array(
    [[-1.0, 0.0, 0.0, 0.0], [0.0, -1.0, 0.0, 0.0], [0.0, 0.0, 1.0, 0.0], [0.0, 0.0, 0.0, 1.0]]
)
"""ur_description's ``base`` (the controller's Base) in ``base_link``: Rz(π)."""


def rotation_from_vector(vector: np.ndarray) -> np.ndarray:
    """The rotation of an axis-angle vector (Rodrigues' formula), shape (3, 3)."""
    v = np.asarray(vector, dtype=float)
    angle = float(np.linalg.norm(v))
    if angle < 1e-15:
        return np.eye(3)
    x, y, z = v / angle
    k = np.array([[0.0, -z, y], [z, 0.0, -x], [-y, x, 0.0]])
    rotation: np.ndarray = np.eye(3) + np.sin(angle) * k + (1.0 - np.cos(angle)) * (k @ k)
    return rotation


def vector_from_rotation(rotation: np.ndarray) -> np.ndarray:
    """The axis-angle vector of a rotation, angle in [0, π], shape (3,).

    The angle from the trace, the axis from the skew part; near π (skew part vanishing)
    from the largest diagonal entry of ``(R + I) / 2 = a·aᵀ``.
    """
    R = np.asarray(rotation, dtype=float)
    angle = float(np.arccos(np.clip((np.trace(R) - 1.0) / 2.0, -1.0, 1.0)))
    skew = np.array([R[2, 1] - R[1, 2], R[0, 2] - R[2, 0], R[1, 0] - R[0, 1]])
    if angle < 1e-12:
        return np.zeros(3)
    if np.pi - angle > 1e-4:
        return angle * skew / (2.0 * np.sin(angle))
    outer = (R + np.eye(3)) / 2.0
    i = int(np.argmax(np.diag(outer)))
    axis = outer[:, i] / np.sqrt(outer[i, i])
    if axis @ skew < 0.0:
        axis = -axis
    return angle * axis


def pose_matrix(values: np.ndarray) -> np.ndarray:
    """The transform of a URScript pose ``[x, y, z, rx, ry, rz]`` (m, rad), shape (4, 4)."""
    values = np.asarray(values, dtype=float)
    pose = np.eye(4)
    pose[:3, :3] = rotation_from_vector(values[3:])
    pose[:3, 3] = values[:3]
    return pose


def pose_trans(p_from: np.ndarray, p_from_to: np.ndarray) -> np.ndarray:
    """URScript's ``pose_trans`` on (4, 4) transforms: ``p_from · p_from_to``."""
    composed: np.ndarray = np.asarray(p_from) @ np.asarray(p_from_to)
    return composed


def base_from_rep103(pose_in_base_link: np.ndarray) -> np.ndarray:
    """A pose given in ur_description's ``base_link`` (REP-103: x forward), expressed in
    the controller's Base: ``Rz(π)⁻¹ · pose``; x and y change sign."""
    expressed: np.ndarray = np.linalg.inv(BASE_FROM_BASE_LINK) @ pose_in_base_link
    return expressed


def rotation_angle(a: np.ndarray, b: np.ndarray) -> float:
    """The angle between two rotations, rad."""
    relative = np.asarray(a)[:3, :3].T @ np.asarray(b)[:3, :3]
    return float(np.arccos(np.clip((np.trace(relative) - 1.0) / 2.0, -1.0, 1.0)))
