"""Frames: RPY rotations, the placement transform (Eq. 4) and tool poses (Eq. 3).

Conventions (``docs/conventions.md``): ``R = Rz(yaw) · Ry(pitch) · Rx(roll)`` (fixed axes),
``T_X = Trans(x, y, z) · RPY(roll, pitch, yaw)`` places the path's definition frame in the
robot base frame, and the tool pose at path point p is ``T_X · [R_tool p; 0 1]``.

This module sits below ``paths/``, ``timing/`` and ``planning/``: everything that turns
placements into poses imports it, and it imports nothing of trackplan's.
"""

from __future__ import annotations

import numpy as np

from trackplan.errors import CaseError


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
    if rpy.shape == (3,):  # one rotation: the same products on Python floats, without
        # numpy's per-call cost on 0-d arrays (the sines and cosines are numpy's)
        (cr, cp, cy), (sr, sp, sy) = np.cos(rpy).tolist(), np.sin(rpy).tolist()
        return np.array(
            [
                [cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr],
                [sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr],
                [-sp, cp * sr, cp * cr],
            ]
        )
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


GIMBAL_LOCK = 1e-8
"""|cos pitch| below which :func:`rpy_from_matrix` is at the gimbal lock (pitch = ±π/2).

Near the lock the angles are ill-conditioned: the locked branch errs by about twice this
threshold, the regular branch by the matrix's rounding over |cos pitch| (≈ 1e-16 / 1e-8).
1e-8, about √ε, balances the two: 20,000 near-lock rotations built from quaternions
(``tests/test_frames.py``, seed 0) compose back within 2.0e-8, where a threshold of 1e-9
leaves errors of 1e-7."""


def rpy_from_matrix(R: np.ndarray) -> np.ndarray:
    """Roll, pitch, yaw of rotation matrices (inverse of :func:`rpy_matrix`).

    Parameters
    ----------
    R
        Rotation matrices, shape (..., 3, 3).

    Returns
    -------
    numpy.ndarray
        Shape (..., 3), rad, pitch in [-π/2, π/2]. At the gimbal lock (|cos pitch| below
        :data:`GIMBAL_LOCK`) roll is 0 and yaw carries the rotation about the common axis,
        so that the angles compose back to the matrix. The same angles are KUKA's C, B, A
        and FANUC's W, P, R (``docs/export.md``).
    """
    R = np.asarray(R, dtype=float)
    cos_pitch = np.hypot(R[..., 0, 0], R[..., 1, 0])
    pitch = np.arctan2(-R[..., 2, 0], cos_pitch)  # arcsin loses digits near ±π/2
    locked = cos_pitch < GIMBAL_LOCK
    roll = np.where(locked, 0.0, np.arctan2(R[..., 2, 1], R[..., 2, 2]))
    yaw = np.where(
        locked,
        np.arctan2(-R[..., 0, 1], R[..., 1, 1]),
        np.arctan2(R[..., 1, 0], R[..., 0, 0]),
    )
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


def rotate_each(R: np.ndarray, rotations: np.ndarray) -> np.ndarray:
    """``R @ rotations[m]`` for every m, as one (3, 3) × (3, 3M) product per ``R``.

    The same values as the stacked ``R[:, None] @ rotations`` (up to round-off), without
    one small product per matrix.

    Parameters
    ----------
    R
        Shape (B, 3, 3), or (3, 3).
    rotations
        Shape (M, 3, 3).

    Returns
    -------
    numpy.ndarray
        Shape (B, M, 3, 3), or (M, 3, 3) for one ``R``; a strided view.
    """
    R = np.asarray(R, dtype=float)
    columns = np.asarray(rotations, dtype=float).transpose(1, 0, 2).reshape(3, -1)  # [j, 3m+k]
    rotated = (R @ columns).reshape(*R.shape[:-2], 3, -1, 3)  # [..., i, m, k]
    return np.swapaxes(rotated, -3, -2)


def vector_norms(v: np.ndarray) -> np.ndarray:
    """Euclidean lengths of 3-vectors ``v`` (N, 3), shape (N,).

    The same bits as ``np.linalg.norm(v, axis=1)`` (the squares summed in the same order),
    a few times faster: numpy reduces a short last axis slowly.
    """
    x, y, z = v[:, 0], v[:, 1], v[:, 2]
    norm: np.ndarray = np.sqrt(x * x + y * y + z * z)
    return norm


def tool_poses(X: np.ndarray, positions: np.ndarray, R_part_tool: np.ndarray) -> np.ndarray:
    """``T_base_tool = T_X · [R_part_tool  p; 0 1]`` for every placement and path point.

    Parameters
    ----------
    X
        Placements, shape (B, 6) (or (6,)), metres and radians.
    positions
        Path points in the definition frame, shape (M, 3), m.
    R_part_tool
        Tool orientation in the definition frame: one rotation (3, 3), one per point
        (M, 3, 3), or one per placement and point (B, M, 3, 3) (:mod:`trackplan.tool`).

    Returns
    -------
    numpy.ndarray
        Shape (B, M, 4, 4) (or (M, 4, 4) for a single placement).
    """
    X = np.asarray(X, dtype=float)
    R_base_tool, p_base_tool = tool_pose_parts(np.atleast_2d(X), positions, R_part_tool)
    poses = np.empty((*p_base_tool.shape[:2], 4, 4))
    poses[..., :3, :3] = R_base_tool
    poses[..., :3, 3] = p_base_tool
    poses[..., 3, :] = (0.0, 0.0, 0.0, 1.0)
    return poses[0] if X.ndim == 1 else poses


def tool_pose_parts(
    X: np.ndarray, positions: np.ndarray, R_part_tool: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """The rotations and positions of :func:`tool_poses`, without the (…, 4, 4) array.

    Parameters are those of :func:`tool_poses`.

    Returns
    -------
    R_base_tool
        Shape (B, M, 3, 3), or (B, 1, 3, 3) for one ``R_part_tool`` (3, 3) (the rotation
        every point shares); (M or 1, 3, 3) for a single placement.
    p_base_tool
        Shape (B, M, 3), m ((M, 3) for a single placement).
    """
    X = np.asarray(X, dtype=float)
    single = X.ndim == 1
    T_base_part = placement_transform(np.atleast_2d(X))  # (B, 4, 4)
    R = T_base_part[:, :3, :3]
    R_part_tool = np.asarray(R_part_tool, dtype=float)
    if R_part_tool.ndim < 4:
        R_part_tool = R_part_tool.reshape(1, -1, 3, 3)  # (1, 1 or M, 3, 3)
    if R_part_tool.shape[0] == 1:
        rotations = rotate_each(R, R_part_tool[0])
    else:
        rotations = R[:, None] @ R_part_tool
    placed = np.asarray(positions, dtype=float) @ R.transpose(0, 2, 1)  # (B, M, 3)
    placed += T_base_part[:, None, :3, 3]
    return (rotations[0], placed[0]) if single else (rotations, placed)


def as_placement(X: object, key: str = "placement") -> np.ndarray:
    """X as a float array of shape (6,), checked.

    Parameters
    ----------
    X
        (x, y, z, roll, pitch, yaw), metres and radians.
    key
        Where X came from, for the error.

    Raises
    ------
    CaseError
        When X is not six finite numbers.
    """
    try:
        values = np.asarray(X, dtype=float)
    except (TypeError, ValueError):
        raise CaseError(
            f"must be 6 numbers (x, y, z, roll, pitch, yaw), got {X!r}", key=key
        ) from None
    if values.shape != (6,):
        raise CaseError(
            f"must be 6 numbers (x, y, z, roll, pitch, yaw), got shape {values.shape}", key=key
        )
    if not np.all(np.isfinite(values)):
        raise CaseError(f"must be finite, got {values.tolist()}", key=key)
    return values
