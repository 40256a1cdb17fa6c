"""KUKA's Status and Turn, written once from the vendor's definition for the tests.

Independent of :mod:`trackplan.writers.krl_config`: the wrist root point is the origin of
link frame 5 (where the wrist axes meet on the KUKA URDFs and the PUMA's DH frames), the A1
coordinate system is ``$ROBROOT`` turned about axis 1 by A1 (Rodrigues), and bit 1 uses
KUKA's joint-angle form "A3 ≥ φ", with φ the A3 at which the wrist root point lies on the
line through axes 2 and 3. Sources: ``docs/export-krl.md``.
"""

from __future__ import annotations

import numpy as np

from trackplan.robots.kinematics import axis_frames, joint_frames
from trackplan.robots.model import Robot


def _rotation(axis: np.ndarray, angle: float) -> np.ndarray:
    """Rodrigues: the rotation by ``angle`` (rad) about the unit ``axis``."""
    k = axis / np.linalg.norm(axis)
    cross = np.array([[0, -k[2], k[1]], [k[2], 0, -k[0]], [-k[1], k[0], 0]])
    return np.eye(3) + np.sin(angle) * cross + (1 - np.cos(angle)) * cross @ cross


def _wrap(angle: float) -> float:
    """An angle in [−π, π)."""
    return float((angle + np.pi) % (2 * np.pi) - np.pi)


def status_turn_reference(robot: Robot, theta: np.ndarray) -> tuple[int, int]:
    """KUKA ``S`` and ``T`` of controller joints ``theta`` (rad, 6 axes)."""
    convention = robot.convention
    theta = np.asarray(theta, dtype=float)
    turn = sum(1 << i for i in range(6) if np.rad2deg(theta[i]) < 0.0)
    to_root = np.linalg.inv(convention.world)

    def in_root(point: np.ndarray) -> np.ndarray:
        result: np.ndarray = (to_root @ np.append(point, 1.0))[:3]
        return result

    q = convention.to_model(theta)
    wrist = in_root(joint_frames(robot, q)[5, :3, 3])
    # bit 0: x of the wrist root point in the A1 coordinate system
    axes = axis_frames(robot, q)
    a1 = convention.signs[0] * (to_root[:3, :3] @ axes[1, :3, 2])
    p1 = in_root(axes[1, :3, 3])
    turned = _rotation(a1, theta[0])
    origin = p1 + turned @ (np.zeros(3) - p1)
    x_a1 = float((wrist - origin) @ (turned @ np.array([1.0, 0.0, 0.0])))
    overhead = x_a1 < 0.0
    # bit 1: A3 >= phi, phi from the geometry at A3 = 0
    straight = theta.copy()
    straight[2] = 0.0
    q0 = convention.to_model(straight)
    axes0 = axis_frames(robot, q0)
    p2, p3 = axes0[2, :3, 3], axes0[3, :3, 3]
    a3 = convention.signs[2] * axes0[3, :3, 2]
    w0 = joint_frames(robot, q0)[5, :3, 3]
    upper = p3 - p2
    fore = w0 - p3
    upper -= (upper @ a3) * a3
    fore -= (fore @ a3) * a3
    delta0 = np.arctan2(np.cross(upper, fore) @ a3, upper @ fore)  # the bend at A3 = 0
    phi = -delta0
    elbow = _wrap(theta[2] - phi) >= 0.0
    flip = _wrap(theta[4]) < 0.0
    return int(overhead) + 2 * int(elbow) + 4 * int(flip), int(turn)


__all__ = ["status_turn_reference"]
