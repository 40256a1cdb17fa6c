"""Batched forward kinematics and geometric Jacobian of DH chains.

Every function takes configurations of any leading shape ``(..., n)``.
"""

from __future__ import annotations

import numpy as np

from trackplan.robots.model import Robot


def link_transforms(robot: Robot, q: np.ndarray) -> np.ndarray:
    """DH link transforms ``A_i(q_i)``.

    Parameters
    ----------
    robot
        The robot.
    q
        Joint positions, shape (..., n), rad.

    Returns
    -------
    numpy.ndarray
        Shape (..., n, 4, 4): ``A_i = Rz(q_i + offset_i) Tz(d_i) Tx(a_i) Rx(alpha_i)``.
    """
    q = np.asarray(q, dtype=float)
    theta = q + robot.offset
    ct, st = np.cos(theta), np.sin(theta)
    ca, sa = np.cos(robot.alpha), np.sin(robot.alpha)
    A = np.zeros((*q.shape, 4, 4))
    A[..., 0, 0] = ct
    A[..., 0, 1] = -st * ca
    A[..., 0, 2] = st * sa
    A[..., 0, 3] = robot.a * ct
    A[..., 1, 0] = st
    A[..., 1, 1] = ct * ca
    A[..., 1, 2] = -ct * sa
    A[..., 1, 3] = robot.a * st
    A[..., 2, 1] = sa
    A[..., 2, 2] = ca
    A[..., 2, 3] = robot.d
    A[..., 3, 3] = 1.0
    return A


def joint_frames(robot: Robot, q: np.ndarray) -> np.ndarray:
    """Frames of the chain in the base frame: base, DH frames 1..n, then the tool.

    Parameters
    ----------
    q
        Joint positions, shape (..., n), rad.

    Returns
    -------
    numpy.ndarray
        Shape (..., n + 2, 4, 4): ``[I, T_0_1, …, T_0_n, T_0_n · T_flange_tool]``.
    """
    A = link_transforms(robot, q)
    n = robot.n_dof
    frames = np.empty((*A.shape[:-3], n + 2, 4, 4))
    frames[..., 0, :, :] = np.eye(4)
    for i in range(n):
        frames[..., i + 1, :, :] = frames[..., i, :, :] @ A[..., i, :, :]
    frames[..., n + 1, :, :] = frames[..., n, :, :] @ robot.T_flange_tool
    return frames


def forward_kinematics(robot: Robot, q: np.ndarray) -> np.ndarray:
    """Tool pose in the base frame, ``T_base_tool``.

    Parameters
    ----------
    q
        Joint positions, shape (..., n), rad.

    Returns
    -------
    numpy.ndarray
        Shape (..., 4, 4).
    """
    return joint_frames(robot, q)[..., -1, :, :]


def jacobian(robot: Robot, q: np.ndarray) -> np.ndarray:
    """Geometric Jacobian at the tool point, expressed in the base frame.

    Rows are (v_x, v_y, v_z, ω_x, ω_y, ω_z): ``[v; ω] = J(q) · q̇``.

    Parameters
    ----------
    q
        Joint positions, shape (..., n), rad.

    Returns
    -------
    numpy.ndarray
        Shape (..., 6, n).
    """
    frames = joint_frames(robot, q)
    z = frames[..., :-2, :3, 2]  # axis of joint i is z of frame i-1: (..., n, 3)
    origins = frames[..., :-2, :3, 3]
    p_tool = frames[..., -1, :3, 3]
    J = np.empty((*frames.shape[:-3], 6, robot.n_dof))
    J[..., :3, :] = np.swapaxes(np.cross(z, p_tool[..., None, :] - origins), -1, -2)
    J[..., 3:, :] = np.swapaxes(z, -1, -2)
    return J
