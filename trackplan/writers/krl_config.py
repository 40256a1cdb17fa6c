"""KUKA conventions for KRL programs: A, B, C angles, Status and Turn, KRL number literals.

Angles: a KRL FRAME / E6POS orientation is ``R = Rz(A) · Ry(B) · Rx(C)`` in degrees (the
same matrix as trackplan's yaw, pitch, roll). Status ``S`` and Turn ``T``
(``docs/export-krl.md`` gives the definitions, their sources and what is verified):

- ``T`` bit i (value 2^i) is set when axis A(i+1) < 0°.
- ``S`` bit 0 (1): the wrist root point (where the wrist axes meet) has a negative x in
  the A1 coordinate system, i.e. ``$ROBROOT`` turned with axis 1 (the overhead area).
- ``S`` bit 1 (2): A3 ≥ φ, the angle at which the wrist root point lies on the line through
  axes 2 and 3 (0° when axes 3 and 4 intersect); computed geometrically: the forearm is
  turned positively about A3 from the stretched arm.
- ``S`` bit 2 (4): A5 < 0° (A5 taken in [−180°, 180°)).
"""

# Sources (docs/export-krl.md): A, B, C: RoboDK/RoboDK-API robomath.py KUKA_2_Pose.
# T: Beckhoff TF5200 (ISG kernel) "Status & Turn (IS, IT)"; RoboDK KUKA_KRC4_Config.py.
# S bit 0: KUKA's expert programming manual as quoted in robot-forum.com thread 7173;
# SINUMERIK ONE programming manual 12/2019 p. 710. S bits 1 and 2: SINUMERIK p. 710 and
# the TF5200 pages (an isg-stuttgart.de copy states the opposite sign of bit 2).

from __future__ import annotations

import numpy as np

from trackplan.frames import rpy_from_matrix
from trackplan.robots.kinematics import axis_frames
from trackplan.robots.model import Robot
from trackplan.robots.wrist import wrist_centres
from trackplan.writers.numbers import fixed


def abc_from_matrix(R: np.ndarray) -> np.ndarray:
    """KUKA A, B, C of rotation matrices (``R = Rz(A) · Ry(B) · Rx(C)``): the reversed
    :func:`~trackplan.frames.rpy_from_matrix`.

    Parameters
    ----------
    R
        Rotations, shape (..., 3, 3).

    Returns
    -------
    numpy.ndarray
        (A, B, C), shape (..., 3), rad; B in [−π/2, π/2]; at B = ±π/2, C = 0.
    """
    return rpy_from_matrix(R)[..., ::-1]


def frame_values(T: np.ndarray) -> np.ndarray:
    """The six values of a KRL FRAME: X, Y, Z in mm and A, B, C in degrees.

    Parameters
    ----------
    T
        Poses, shape (..., 4, 4), m.

    Returns
    -------
    numpy.ndarray
        Shape (..., 6).
    """
    T = np.asarray(T, dtype=float)
    return np.concatenate(
        [1000.0 * T[..., :3, 3], np.rad2deg(abc_from_matrix(T[..., :3, :3]))], axis=-1
    )


def wrist_points(robot: Robot, q: np.ndarray) -> np.ndarray:
    """Wrist root points (:func:`~trackplan.robots.wrist.wrist_centres`) of model joints
    ``q``, shape (k, 6), rad; shape (k, 3), m, in the model's base frame."""
    return wrist_centres(axis_frames(robot, q))


def status_turn(robot: Robot, joints: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """KUKA Status and Turn of controller joints.

    Parameters
    ----------
    robot
        A robot of 6 joints; its :attr:`~trackplan.robots.model.Robot.convention` maps
        controller joints to the model and places ``$ROBROOT`` (the controller's world).
    joints
        Controller joints, shape (k, 6), rad.

    Returns
    -------
    tuple[numpy.ndarray, numpy.ndarray]
        S and T, each shape (k,), int.
    """
    convention = robot.convention
    theta = np.atleast_2d(np.asarray(joints, dtype=float))
    turn = ((theta < 0.0) * (2 ** np.arange(theta.shape[1]))).sum(axis=1)
    # bit 0: the wrist root point in the A1 system = the point with A1 = 0, in $ROBROOT
    at_zero = theta.copy()
    at_zero[:, 0] = 0.0
    wrist_zero = wrist_points(robot, convention.to_model(at_zero))
    homogeneous = np.concatenate([wrist_zero, np.ones((len(theta), 1))], axis=1)
    in_root = np.einsum("ij,kj->ki", np.linalg.inv(convention.world), homogeneous)
    overhead = in_root[:, 0] < 0.0
    # bit 1: the forearm turned positively about A3 from the line through A2 and A3
    q = convention.to_model(theta)
    frames = axis_frames(robot, q)
    p2, p3 = frames[:, 2, :3, 3], frames[:, 3, :3, 3]
    a3 = convention.signs[2] * frames[:, 3, :3, 2]
    bend = np.einsum("ki,ki->k", np.cross(p3 - p2, wrist_points(robot, q) - p3), a3)
    elbow = bend >= 0.0
    # bit 2: A5 < 0 in [-180°, 180°)
    a5 = np.mod(theta[:, 4] + np.pi, 2.0 * np.pi) - np.pi
    flip = a5 < 0.0
    status = overhead.astype(int) + 2 * elbow.astype(int) + 4 * flip.astype(int)
    return status, turn.astype(int)


def real(value: float, digits: int) -> str:
    """A KRL REAL literal with at most ``digits`` decimals and at least one (``-0`` → ``0``):
    ``"12.5"``, ``"-0.000123"``, ``"100.0"``."""
    return fixed(value, digits, keep=1)


__all__ = [
    "abc_from_matrix",
    "frame_values",
    "real",
    "status_turn",
    "wrist_points",
]
