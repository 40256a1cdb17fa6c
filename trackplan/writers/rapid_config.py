"""ABB RAPID data fields: ``confdata``, quaternions and numbers as RAPID writes them.

``confdata [cf1, cf4, cf6, cfx]`` (RAPID reference manual, data type *confdata*):
cf1, cf4 and cf6 are the quadrants of axes 1, 4 and 6 — quadrant 0 is 0° to 90° from the
zero position, 1 is 90° to 180°, −1 is 0° to −90° — so ``cfN = floor(θN / 90°)`` on the
controller's joint values. For a six-axis arm, cfx numbers the eight arm configurations as
``4·(wrist centre behind axis 1) + 2·(wrist centre behind the lower arm) + 1·(axis 5
negative)`` (the manual's table of cfx 0…7, reproduced in CEAD-group/py-opw-kinematics
``AXIS_CONFIGURATION.md``; RoboDK's ABB post-processor sums the same bits). The wrist
centre is the intersection of axes 4, 5 and 6; "behind axis 1" is the far side of the
plane through axis 1 parallel to axis 2, "behind the lower arm" the far side of the plane
through axes 2 and 3; "in front" is the side the wrist centre is on at the zero of the
controller's joints (where an ABB arm reads ``[0, 0, 0, 0]``). See ``docs/export-rapid.md``.
"""

from __future__ import annotations

import numpy as np
from scipy.spatial.transform import Rotation

from trackplan.robots.kinematics import axis_frames
from trackplan.robots.model import Robot
from trackplan.robots.wrist import wrist_centres
from trackplan.writers.numbers import fixed

_SIDE_TOLERANCE = 1e-12
"""m: a reference side closer than this to its plane counts as in front."""


def quadrants(theta: np.ndarray) -> np.ndarray:
    """RAPID quadrant numbers of joint angles: ``floor(θ / 90°)``.

    Parameters
    ----------
    theta
        Controller joint angles, shape (...,), rad.

    Returns
    -------
    numpy.ndarray
        Integers, shape (...,).
    """
    degrees = np.degrees(np.asarray(theta, dtype=float))
    # A value printed as 90.000000 must not fall into the quadrant below it.
    return np.floor(np.round(degrees, 9) / 90.0).astype(int)


def wrist_centres_and_frames(robot: Robot, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The wrist centre and the axis frames of model joints ``q``.

    The wrist centre is where axes 4 and 5 meet (:func:`~trackplan.robots.wrist.wrist_centres`).

    Parameters
    ----------
    robot
        A six-axis robot.
    q
        Model joints, shape (N, 6), rad.

    Returns
    -------
    tuple[numpy.ndarray, numpy.ndarray]
        Wrist centres in the base frame, shape (N, 3), m; axis frames, shape (N, 8, 4, 4).
    """
    frames = axis_frames(robot, q)
    return wrist_centres(frames), frames


def _sides(robot: Robot, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Signed distances of the wrist centre from the axis-1 plane and the lower-arm plane.

    Returns
    -------
    tuple[numpy.ndarray, numpy.ndarray]
        Shape (N,) each, m; positive on the side of ``cross(z2, z1)`` and
        ``cross(z2, lower arm)``.
    """
    wrist, frames = wrist_centres_and_frames(robot, q)
    o1, z1 = frames[:, 1, :3, 3], frames[:, 1, :3, 2]
    o2, z2 = frames[:, 2, :3, 3], frames[:, 2, :3, 2]
    o3 = frames[:, 3, :3, 3]
    forward = np.cross(z2, z1)
    forward /= np.linalg.norm(forward, axis=1, keepdims=True)
    arm = o3 - o2
    arm -= np.einsum("ij,ij->i", arm, z2)[:, None] * z2
    arm /= np.linalg.norm(arm, axis=1, keepdims=True)
    across = np.cross(z2, arm)
    axis1 = np.einsum("ij,ij->i", wrist - o1, forward)
    lower_arm = np.einsum("ij,ij->i", wrist - o2, across)
    return axis1, lower_arm


def confdata(robot: Robot, joints: np.ndarray, model_joints: np.ndarray) -> np.ndarray:
    """``[cf1, cf4, cf6, cfx]`` of planned joints, as ABB defines them.

    Parameters
    ----------
    robot
        The six-axis robot (its geometry and controller convention).
    joints
        Controller joints, shape (N, 6), rad (for the quadrants and axis 5's sign).
    model_joints
        The same joints in the model's convention, shape (N, 6), rad (for the geometry).

    Returns
    -------
    numpy.ndarray
        Integers, shape (N, 4).
    """
    joints = np.atleast_2d(np.asarray(joints, dtype=float))
    model_joints = np.atleast_2d(np.asarray(model_joints, dtype=float))
    zero = robot.convention.to_model(np.zeros((1, robot.n_dof)))
    ref1, ref2 = _sides(robot, zero)
    sign1 = -1.0 if ref1[0] < -_SIDE_TOLERANCE else 1.0
    sign2 = -1.0 if ref2[0] < -_SIDE_TOLERANCE else 1.0
    axis1, lower_arm = _sides(robot, model_joints)
    behind_axis1 = (sign1 * axis1 < 0.0).astype(int)
    behind_arm = (sign2 * lower_arm < 0.0).astype(int)
    negative5 = (np.round(np.degrees(joints[:, 4]), 9) < 0.0).astype(int)
    cfx = 4 * behind_axis1 + 2 * behind_arm + negative5
    return np.column_stack(
        [quadrants(joints[:, 0]), quadrants(joints[:, 3]), quadrants(joints[:, 5]), cfx]
    )


def quaternion(rotation: np.ndarray) -> np.ndarray:
    """RAPID ``orient`` of a rotation: unit ``[q1, q2, q3, q4]``, q1 the scalar, q1 ≥ 0.

    Parameters
    ----------
    rotation
        Rotation matrix, shape (..., 3, 3).

    Returns
    -------
    numpy.ndarray
        Shape (..., 4).
    """
    xyzw = Rotation.from_matrix(np.asarray(rotation, dtype=float)).as_quat()
    q = np.concatenate([xyzw[..., 3:], xyzw[..., :3]], axis=-1)
    q /= np.linalg.norm(q, axis=-1, keepdims=True)
    # q and −q are the same rotation: RAPID's convention here is q1 ≥ 0; with q1 = 0 the
    # first non-zero component is made positive so that the text is unique.
    flip = q[..., 0] < 0.0
    on_plane = q[..., 0] == 0.0
    first = np.take_along_axis(q, np.argmax(q != 0.0, axis=-1)[..., None], axis=-1)[..., 0]
    flip |= on_plane & (first < 0.0)
    q[flip] *= -1.0
    return q


def number(value: float, decimals: int) -> str:
    """A RAPID ``num`` literal: fixed point, trailing zeros dropped, never ``-0``."""
    return fixed(value, decimals, keep=0)


def numbers(values: np.ndarray, decimals: int) -> str:
    """Comma-separated :func:`number` literals."""
    return ",".join(number(float(v), decimals) for v in np.ravel(values))


__all__ = ["confdata", "number", "numbers", "quadrants", "quaternion", "wrist_centres"]
