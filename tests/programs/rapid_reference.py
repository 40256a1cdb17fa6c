"""ABB's confdata, written once from the joints and the robot's geometry (tests only).

RAPID reference manual, data type *confdata* (its cfx table is reproduced in
CEAD-group/py-opw-kinematics ``AXIS_CONFIGURATION.md``, MIT): cf1, cf4, cf6 are the
quadrants of axes 1, 4, 6 (quadrant 0 = 0° … 90°, −1 = 0° … −90°); for a six-axis arm
cfx = 4·(wrist centre behind axis 1) + 2·(wrist centre behind the lower arm) + (axis 5
negative). This oracle does not import trackplan's writer: it finds the wrist centre on
axes 5 and 6 (the writer uses axes 4 and 5), measures "behind axis 1" against the zero
pose's forward direction turned by axis 1, and "behind the lower arm" as the sign of the
turn from the lower arm to the wrist centre about axis 2.
"""

from __future__ import annotations

import math

import numpy as np

from trackplan.robots.kinematics import axis_frames
from trackplan.robots.model import Robot


def _closest_point(
    o_a: np.ndarray, z_a: np.ndarray, o_b: np.ndarray, z_b: np.ndarray
) -> np.ndarray:
    """The point of line b nearest to line a."""
    # Minimise |o_a + s z_a − o_b − t z_b|² over (s, t).
    matrix = np.array([[z_a @ z_a, -(z_a @ z_b)], [z_a @ z_b, -(z_b @ z_b)]])
    rhs = np.array([(o_b - o_a) @ z_a, (o_b - o_a) @ z_b])
    _, t = np.linalg.lstsq(matrix, rhs, rcond=None)[0]
    return o_b + t * z_b


def _rotate(vector: np.ndarray, axis: np.ndarray, angle: float) -> np.ndarray:
    """Rodrigues' rotation of ``vector`` about the unit ``axis``."""
    return (
        vector * math.cos(angle)
        + np.cross(axis, vector) * math.sin(angle)
        + axis * (axis @ vector) * (1 - math.cos(angle))
    )


def _geometry(robot: Robot, q: np.ndarray) -> dict[str, np.ndarray]:
    frames = axis_frames(robot, np.asarray(q, dtype=float))
    axes = {f"o{i}": frames[i, :3, 3] for i in range(1, 7)}
    axes.update({f"z{i}": frames[i, :3, 2] for i in range(1, 7)})
    axes["wrist"] = _closest_point(axes["o6"], axes["z6"], axes["o5"], axes["z5"])
    return axes


def reference_confdata(robot: Robot, model_joints: np.ndarray) -> tuple[int, int, int, int]:
    """``(cf1, cf4, cf6, cfx)`` of one configuration.

    Parameters
    ----------
    robot
        A six-axis robot with its controller convention.
    model_joints
        Model joints, shape (6,), rad.
    """
    q = np.asarray(model_joints, dtype=float)
    theta_deg = np.degrees(robot.convention.to_controller(q))
    cf1, cf4, cf6 = (math.floor(round(theta_deg[i], 9) / 90.0) for i in (0, 3, 5))
    q_zero = robot.convention.to_model(np.zeros(6))
    zero = _geometry(robot, q_zero)
    now = _geometry(robot, q)
    # Forward at the zero pose: the wrist centre's direction across axis 1, in the plane
    # normal to axis 2; turned with axis 1 by the model's joint 1 travel.
    z1 = zero["z1"]
    forward0 = np.cross(zero["z2"], z1)
    if (zero["wrist"] - zero["o1"]) @ forward0 < 0:
        forward0 = -forward0
    forward = _rotate(forward0, z1, q[0] - q_zero[0])
    behind_axis1 = (now["wrist"] - now["o1"]) @ forward < 0

    def turn(g: dict[str, np.ndarray]) -> float:
        arm = g["o3"] - g["o2"]
        return float(np.cross(arm, g["wrist"] - g["o2"]) @ g["z2"])

    behind_arm = turn(now) * turn(zero) < 0
    negative5 = round(theta_deg[4], 9) < 0
    cfx = 4 * int(behind_axis1) + 2 * int(behind_arm) + int(negative5)
    return int(cf1), int(cf4), int(cf6), cfx


__all__ = ["reference_confdata"]
