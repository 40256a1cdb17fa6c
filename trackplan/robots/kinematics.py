"""Batched forward kinematics and geometric Jacobian of serial chains.

Every function takes configurations of any leading shape ``(..., n)``. The chain is
the model's :attr:`~trackplan.robots.model.Robot.kernel_chain`: every joint turns about
the z axis of its frame.
"""

from __future__ import annotations

import numpy as np

from trackplan._kernels import read_only
from trackplan.robots._kernels import fk_flat, frames_flat
from trackplan.robots.model import Robot


def joint_frames(robot: Robot, q: np.ndarray) -> np.ndarray:
    """Frames of the chain in the base frame: base, links 1..n, then the tool.

    Link frame i moves with link i: for a robot built from a DH table it is DH frame i (at
    the link's far end), for a URDF chain the child link frame of joint i
    (:attr:`Robot.link_frames`).

    Parameters
    ----------
    robot
        The robot.
    q
        Joint positions, shape (..., n), rad.

    Returns
    -------
    numpy.ndarray
        Shape (..., n + 2, 4, 4): ``[I, T_0_1, …, T_0_n, T_base_tool]``.
    """
    return _frames(robot, q, robot.link_frames)


def axis_frames(robot: Robot, q: np.ndarray) -> np.ndarray:
    """Base, joint-axis frames 1..n and the tool: frame i has its origin on joint i's axis
    and its z column along the axis (after the joint's rotation).

    Parameters
    ----------
    robot
        The robot.
    q
        Joint positions, shape (..., n), rad.

    Returns
    -------
    numpy.ndarray
        Shape (..., n + 2, 4, 4).
    """
    return _frames(robot, q, np.broadcast_to(np.eye(4), (robot.n_dof, 4, 4)))


def _frames(robot: Robot, q: np.ndarray, links: np.ndarray) -> np.ndarray:
    """Frames through the compiled kernel, with ``links`` (n, 4, 4) after each joint."""
    q = np.asarray(q, dtype=float)
    chain, tail = robot.kernel_chain
    flat = np.ascontiguousarray(q.reshape(-1, robot.n_dof))
    frames = frames_flat(
        read_only(chain), read_only(tail), read_only(np.ascontiguousarray(links)), read_only(flat)
    )
    return frames.reshape(*q.shape[:-1], robot.n_dof + 2, 4, 4)


def forward_kinematics(robot: Robot, q: np.ndarray) -> np.ndarray:
    """Tool pose in the base frame, ``T_base_tool``.

    Parameters
    ----------
    robot
        The robot.
    q
        Joint positions, shape (..., n), rad.

    Returns
    -------
    numpy.ndarray
        Shape (..., 4, 4).
    """
    q = np.asarray(q, dtype=float)
    chain, tail = robot.kernel_chain
    flat = np.ascontiguousarray(q.reshape(-1, robot.n_dof))
    T = fk_flat(read_only(chain), read_only(tail), read_only(flat))
    return T.reshape(*q.shape[:-1], 4, 4)


def jacobian(robot: Robot, q: np.ndarray) -> np.ndarray:
    """Geometric Jacobian at the tool point, expressed in the base frame.

    Rows are (v_x, v_y, v_z, ω_x, ω_y, ω_z): ``[v; ω] = J(q) · q̇``.

    Parameters
    ----------
    robot
        The robot.
    q
        Joint positions, shape (..., n), rad.

    Returns
    -------
    numpy.ndarray
        Shape (..., 6, n).
    """
    frames = axis_frames(robot, q)
    z = frames[..., 1:-1, :3, 2]  # joint i turns about z of its axis frame: (..., n, 3)
    origins = frames[..., 1:-1, :3, 3]
    p_tool = frames[..., -1, :3, 3]
    J = np.empty((*frames.shape[:-3], 6, robot.n_dof))
    J[..., :3, :] = np.swapaxes(np.cross(z, p_tool[..., None, :] - origins), -1, -2)
    J[..., 3:, :] = np.swapaxes(z, -1, -2)
    return J
