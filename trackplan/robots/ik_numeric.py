"""Numerical inverse kinematics of any serial chain: damped Newton (Levenberg–Marquardt).

The pose error of a configuration q for a target ``T_base_tool`` is
``e = (p_target − p(q), log(R_target · R(q)ᵀ))``, position (m) and orientation as a
rotation vector in the base frame (rad), the quantities the geometric Jacobian maps
joint increments to. Each iteration solves ``(JᵀJ + μ I) Δq = Jᵀ e`` (or the equivalent
6 × 6 system ``Δq = Jᵀ (J Jᵀ + μ I)⁻¹ e`` for chains of more than six joints), caps the
largest joint step at ``MAX_NEWTON_STEP`` (:mod:`trackplan.robots._kernels`), and keeps
the step only when the error decreases. The damping is ``μ = ν |e|²``
(Levenberg–Marquardt after Sugihara): it vanishes with the error, so the last
iterations are Gauss–Newton and converge quadratically; ν shrinks tenfold after a kept
step and grows tenfold after a rejected one. A pose counts as solved when the position
error is at most ``tol`` metres and the orientation error at most ``tol`` radians.

A warm start (a squared error below 1e-4, about 10 mm or 10 mrad) on a square Jacobian
first takes undamped Gauss–Newton steps (the 6 × 6 system solved by Gaussian elimination
with partial pivoting), each kept only while the error falls; :func:`track_poses` solves
poses from references within a few mrad of the solution this way (the trajectory's samples
from the grid's joint path), two steps a pose.

The compiled kernels (forward kinematics with the Jacobian, the pose error, one damped
solve, a Newton solve of one pose) live in :mod:`trackplan.robots._ik_kernels`, shared with
:mod:`trackplan.robots.path_ik` and :mod:`trackplan.robots.resolved_rate`.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from trackplan.errors import CaseError
from trackplan.robots._ik_kernels import newton_batch, track_batch
from trackplan.robots.model import Robot


@dataclass(frozen=True, eq=False)
class NumericIK:
    """Result of :func:`solve_ik_numeric` for a batch of poses.

    Attributes
    ----------
    q
        Joint positions, shape (..., n), rad; continuous from the seed (not wrapped).
        The last iterate where ``success`` is False.
    success
        Shape (...,), bool: both errors are within the tolerance.
    n_iter
        Iterations used (steps tried), shape (...,), int.
    position_error
        Distance of the tool point from the target, shape (...,), m.
    orientation_error
        Angle of the rotation from the reached to the target orientation, shape (...,), rad.
    """

    q: np.ndarray
    success: np.ndarray
    n_iter: np.ndarray
    position_error: np.ndarray
    orientation_error: np.ndarray


def chain_arrays(robot: Robot) -> tuple[np.ndarray, np.ndarray]:
    """The robot in the layout of the kernels (fresh, writable arrays: one compiled variant).

    Returns
    -------
    chain
        Shape (n, 4, 4): :attr:`Robot.kernel_chain`, every joint turning about z.
    tail
        Shape (4, 4): the fixed transform from the last joint frame to the tool.
    """
    chain, tail = robot.kernel_chain
    return np.array(chain, dtype=float, order="C"), np.array(tail, dtype=float, order="C")


def solve_ik_numeric(
    robot: Robot,
    T_base_tool: np.ndarray,
    q_seed: np.ndarray,
    *,
    tol: float = 1e-10,
    max_iter: int = 100,
) -> NumericIK:
    """Solve the IK of tool poses by damped Newton from seed configurations.

    Parameters
    ----------
    robot
        Any DH chain.
    T_base_tool
        Target tool poses in the base frame, shape (..., 4, 4), metres.
    q_seed
        Start configurations, shape (..., n), rad; broadcast against the poses' leading axes.
    tol
        Position (m) and orientation (rad) tolerance.
    max_iter
        Most iterations per pose.

    Returns
    -------
    NumericIK
        Arrays of the broadcast leading shape.

    Raises
    ------
    CaseError
        When the shapes do not fit the robot or do not broadcast.
    """
    T, seed, lead = check_poses_and_joints(robot, T_base_tool, q_seed, "q_seed")
    n = robot.n_dof
    T_flat = np.ascontiguousarray(T.reshape(-1, 4, 4))
    pose_index = np.broadcast_to(np.arange(T_flat.shape[0]).reshape(T.shape[:-2]), lead).ravel()
    q = np.ascontiguousarray(np.broadcast_to(seed, (*lead, n)).reshape(-1, n)).copy()
    count = q.shape[0]
    success = np.empty(count, dtype=np.bool_)
    n_iter = np.empty(count, dtype=np.int64)
    errors = np.empty((count, 2))
    newton_batch(
        *chain_arrays(robot),
        T_flat,
        np.ascontiguousarray(pose_index),
        q,
        float(tol),
        int(max_iter),
        success,
        n_iter,
        errors,
    )
    return NumericIK(
        q.reshape(*lead, n),
        success.reshape(lead),
        n_iter.reshape(lead),
        errors[:, 0].reshape(lead),
        errors[:, 1].reshape(lead),
    )


DEFAULT_FREE_JOINT = 2
"""The joint (0-based) a 7-joint arm's numeric IK holds as its redundancy parameter by
default: joint 3, the upper-arm roll of the S-R-S-like arms (iiwa, Gen3, SIA10D) and the
Panda's third joint. Held, it leaves a 6R chain with a full-rank 6 × 6 Jacobian over most
of the workspace (the shoulder and the wrist keep their three axes each), and its value
swings the elbow about the shoulder–wrist line, as the arm angle does."""


NEWTON_TOL = 1e-10
"""Position (m) and orientation (rad) tolerance of every Newton solve of the path IK: the
tracked families' branches and the samples they are solved at. The checker derives its
tool-point tolerance and speed slack from it (``planning/check_task.py``)."""


def track_poses(
    robot: Robot,
    R_base_tool: np.ndarray,
    p_base_tool: np.ndarray,
    q_ref: np.ndarray,
    free: np.ndarray | None = None,
    *,
    free_joint: int = DEFAULT_FREE_JOINT,
    tol: float = NEWTON_TOL,
    max_iter: int = 100,
) -> tuple[np.ndarray, np.ndarray]:
    """Solve poses from nearby reference configurations (warm starts), compiled, batched.

    Each pose is solved by Newton from its own reference (e.g. the planning grid's joint
    path interpolated at the sample, within a few mrad): undamped Gauss–Newton steps on
    the square Jacobian while the error falls, damped steps otherwise (see the module).

    Parameters
    ----------
    robot
        Any chain of 5 to 7 or more joints.
    R_base_tool
        Tool rotations, shape (N, 3, 3), or one for every pose, (3, 3).
    p_base_tool
        Tool positions in the base frame, shape (N, 3), m.
    q_ref
        Reference configurations, shape (N, n), rad.
    free
        A 7-joint arm's redundancy: joint ``free_joint`` held at ``free[i]`` at pose i,
        shape (N,), rad; None holds no joint (a 7-joint arm then takes minimum-norm steps).
    free_joint
        The held joint, 0-based (default :data:`DEFAULT_FREE_JOINT`).
    tol, max_iter
        Position (m) and orientation (rad) tolerance; most iterations per pose.

    Returns
    -------
    q
        Shape (N, n), rad, continuous with ``q_ref`` (not wrapped); the last iterate where
        not ok.
    ok
        Shape (N,), bool: both errors within ``tol``.

    Raises
    ------
    CaseError
        When a shape does not fit.
    """
    n = robot.n_dof
    p = np.ascontiguousarray(p_base_tool, dtype=float)
    R = np.ascontiguousarray(R_base_tool, dtype=float)
    R = R.reshape(1, 3, 3) if R.shape == (3, 3) else R
    reference = np.ascontiguousarray(q_ref, dtype=float)
    count = p.shape[0] if p.ndim == 2 else -1
    if p.ndim != 2 or p.shape[1] != 3:
        raise CaseError(f"p_base_tool must have shape (N, 3), got {p.shape}")
    if R.ndim != 3 or R.shape[1:] != (3, 3) or R.shape[0] not in (1, count):
        raise CaseError(f"R_base_tool must have shape ({count}, 3, 3) or (3, 3), got {R.shape}")
    if reference.shape != (count, n):
        raise CaseError(f"q_ref must have shape ({count}, {n}), got {reference.shape}")
    if free is None:
        locked, held = -1, np.empty(0)
    else:
        held = np.ascontiguousarray(free, dtype=float)
        if held.shape != (count,):
            raise CaseError(f"free must have shape ({count},), got {held.shape}")
        if not 0 <= free_joint < n:
            raise CaseError(f"free_joint must be a joint index in [0, {n - 1}], got {free_joint}")
        locked = int(free_joint)
    q = np.empty((count, n))
    ok = np.empty(count, dtype=np.bool_)
    track_batch(
        *chain_arrays(robot), R, p, reference, locked, held, float(tol), int(max_iter), q, ok
    )
    return q, ok


def check_poses_and_joints(
    robot: Robot, T_base_tool: np.ndarray, q: np.ndarray, q_name: str, path: bool = False
) -> tuple[np.ndarray, np.ndarray, tuple[int, ...]]:
    """Check poses (..., 4, 4) (``path``: (..., M, 4, 4)) against joints (..., n).

    Returns
    -------
    T, q
        The inputs as float arrays.
    lead
        The broadcast leading shape (without M).

    Raises
    ------
    CaseError
        When a shape is wrong or the leading shapes do not broadcast.
    """
    T = np.asarray(T_base_tool, dtype=float)
    joints = np.asarray(q, dtype=float)
    n = robot.n_dof
    pose_axes = 3 if path else 2
    expected = "(..., M, 4, 4)" if path else "(..., 4, 4)"
    if T.ndim < pose_axes or T.shape[-2:] != (4, 4):
        raise CaseError(f"T_base_tool must have shape {expected}, got {T.shape}")
    if joints.ndim < 1 or joints.shape[-1] != n:
        raise CaseError(f"{q_name} must have shape (..., {n}), got {joints.shape}")
    try:
        lead = np.broadcast_shapes(T.shape[:-pose_axes], joints.shape[:-1])
    except ValueError:
        raise CaseError(f"poses {T.shape} and {q_name} {joints.shape} do not broadcast") from None
    return T, joints, lead
