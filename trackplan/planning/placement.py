"""Placement of the path's definition frame in the robot base frame (Eq. 4).

Conventions (design.md): ``R = Rz(yaw) · Ry(pitch) · Rx(roll)`` (fixed axes) and
``T_X = Trans(x, y, z) · RPY(roll, pitch, yaw)``.
"""

from __future__ import annotations

import numpy as np


def rpy_matrix(rpy: np.ndarray) -> np.ndarray:
    """Rotation matrices from roll, pitch, yaw.

    Parameters
    ----------
    rpy
        Angles (roll, pitch, yaw), shape (..., 3), rad.

    Returns
    -------
    numpy.ndarray
        Shape (..., 3, 3): ``Rz(yaw) @ Ry(pitch) @ Rx(roll)``.
    """
    rpy = np.asarray(rpy, dtype=float)
    cr, sr = np.cos(rpy[..., 0]), np.sin(rpy[..., 0])
    cp, sp = np.cos(rpy[..., 1]), np.sin(rpy[..., 1])
    cy, sy = np.cos(rpy[..., 2]), np.sin(rpy[..., 2])
    R = np.empty((*rpy.shape[:-1], 3, 3))
    R[..., 0, 0] = cy * cp
    R[..., 0, 1] = cy * sp * sr - sy * cr
    R[..., 0, 2] = cy * sp * cr + sy * sr
    R[..., 1, 0] = sy * cp
    R[..., 1, 1] = sy * sp * sr + cy * cr
    R[..., 1, 2] = sy * sp * cr - cy * sr
    R[..., 2, 0] = -sp
    R[..., 2, 1] = cp * sr
    R[..., 2, 2] = cp * cr
    return R


def rpy_from_matrix(R: np.ndarray) -> np.ndarray:
    """Roll, pitch, yaw of rotation matrices (inverse of :func:`rpy_matrix`).

    Parameters
    ----------
    R
        Rotation matrices, shape (..., 3, 3).

    Returns
    -------
    numpy.ndarray
        Shape (..., 3), rad, pitch in [-π/2, π/2].
    """
    R = np.asarray(R, dtype=float)
    pitch = np.arcsin(np.clip(-R[..., 2, 0], -1.0, 1.0))
    roll = np.arctan2(R[..., 2, 1], R[..., 2, 2])
    yaw = np.arctan2(R[..., 1, 0], R[..., 0, 0])
    return np.stack([roll, pitch, yaw], axis=-1)


def placement_transform(X: np.ndarray) -> np.ndarray:
    """``T_base_part`` of placements X = (x, y, z, roll, pitch, yaw) (Eq. 4).

    Parameters
    ----------
    X
        Placements, shape (..., 6), metres and radians.

    Returns
    -------
    numpy.ndarray
        Shape (..., 4, 4).
    """
    X = np.asarray(X, dtype=float)
    T = np.zeros((*X.shape[:-1], 4, 4))
    T[..., :3, :3] = rpy_matrix(X[..., 3:])
    T[..., :3, 3] = X[..., :3]
    T[..., 3, 3] = 1.0
    return T


def pose_matrix(position: np.ndarray, rotation: np.ndarray) -> np.ndarray:
    """Homogeneous transforms from positions and rotations.

    Parameters
    ----------
    position
        Shape (..., 3), m.
    rotation
        Shape (..., 3, 3), broadcast against ``position``.

    Returns
    -------
    numpy.ndarray
        Shape (..., 4, 4).
    """
    position = np.asarray(position, dtype=float)
    rotation = np.asarray(rotation, dtype=float)
    shape = np.broadcast_shapes(position.shape[:-1], rotation.shape[:-2])
    T = np.zeros((*shape, 4, 4))
    T[..., :3, :3] = rotation
    T[..., :3, 3] = position
    T[..., 3, 3] = 1.0
    return T
