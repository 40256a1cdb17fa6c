"""Rotations of the tool frame: about its z axis (the spin), about x and y, and their angles.

Vectorised over points and candidates; every function takes and returns stacks of 3×3
rotation matrices.
"""

from __future__ import annotations

import numpy as np


def rotation_z(angle: np.ndarray) -> np.ndarray:
    """Rotations about z by ``angle`` (...,), rad, shape (..., 3, 3)."""
    angle = np.asarray(angle, dtype=float)
    c, s = np.cos(angle), np.sin(angle)
    R = np.zeros((*angle.shape, 3, 3))
    R[..., 0, 0] = c
    R[..., 0, 1] = -s
    R[..., 1, 0] = s
    R[..., 1, 1] = c
    R[..., 2, 2] = 1.0
    return R


def spun(R: np.ndarray, angle: np.ndarray) -> np.ndarray:
    """``R @ rotation_z(angle)`` for rotations R (..., 3, 3) and angles (...,), rad.

    Elementwise: the columns ``(c x + s y, c y − s x, z)`` of each R = (x, y, z), without
    a small matrix product per rotation.
    """
    angle = np.asarray(angle, dtype=float)
    c, s = np.cos(angle)[..., None], np.sin(angle)[..., None]
    x, y = R[..., 0], R[..., 1]
    out = np.empty(np.broadcast_shapes(R.shape, (*angle.shape, 3, 3)))
    out[..., 0] = x * c + y * s
    out[..., 1] = y * c - x * s
    out[..., 2] = R[..., 2]
    return out


def rotation_angle(R_a: np.ndarray, R_b: np.ndarray) -> np.ndarray:
    """Angle of ``R_aᵀ R_b`` for rotations (..., 3, 3), shape (...,), rad."""
    trace = np.einsum("...ji,...ji->...", R_a, R_b)
    angle: np.ndarray = np.arccos(np.clip((trace - 1.0) / 2.0, -1.0, 1.0))
    return angle


def rotation_x(angle: float) -> np.ndarray:
    """Rotation about x by ``angle`` (rad), shape (3, 3)."""
    c, s = np.cos(angle), np.sin(angle)
    return np.array([[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]])


def rotation_y(angle: float) -> np.ndarray:
    """Rotation about y by ``angle`` (rad), shape (3, 3)."""
    c, s = np.cos(angle), np.sin(angle)
    return np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]])


def spin_rotations(base: np.ndarray, spins: np.ndarray) -> np.ndarray:
    """``base · Rz(spin)`` for B spin candidates: base (M, 3, 3), spins (B, M) → (B, M, 3, 3)."""
    spun_base: np.ndarray = base[None] @ rotation_z(spins)
    return spun_base


def tool_axis_twist(rotations: np.ndarray) -> np.ndarray:
    """How far the tool turns about its own axis along a sequence of rotations.

    Parameters
    ----------
    rotations
        ``R_part_tool`` at increasing s, shape (M, 3, 3).

    Returns
    -------
    numpy.ndarray
        Cumulative signed rotation about the tool z axis from the first rotation, shape
        (M,), rad.
    """
    relative = np.einsum("mji,mjk->mik", rotations[:-1], rotations[1:])
    step = np.arctan2(relative[:, 1, 0] - relative[:, 0, 1], relative[:, 0, 0] + relative[:, 1, 1])
    return np.concatenate([[0.0], np.cumsum(step)])
