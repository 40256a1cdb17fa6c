"""Numerical inverse kinematics of any DH chain: damped Newton (Levenberg–Marquardt).

The pose error of a configuration q for a target ``T_base_tool`` is
``e = (p_target − p(q), log(R_target · R(q)ᵀ))``, position (m) and orientation as a
rotation vector in the base frame (rad), the quantities the geometric Jacobian maps
joint increments to. Each iteration solves ``(JᵀJ + μ I) Δq = Jᵀ e`` (or the equivalent
6 × 6 system ``Δq = Jᵀ (J Jᵀ + μ I)⁻¹ e`` for chains of more than six joints), caps the
largest joint step at :data:`MAX_NEWTON_STEP`, and keeps the step only when the error
decreases. The damping is ``μ = ν |e|²`` (Levenberg–Marquardt after Sugihara): it
vanishes with the error, so the last iterations are Gauss–Newton and converge
quadratically; ν shrinks tenfold after a kept step and grows tenfold after a rejected
one. A pose counts as solved when the position error is at most ``tol`` metres and the
orientation error at most ``tol`` radians.

The compiled kernels here (forward kinematics with the Jacobian, the pose error, one
damped solve, a Newton solve of one pose) are shared with
:mod:`trackplan.robots.path_ik` and :mod:`trackplan.robots.resolved_rate`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numba import njit

from trackplan.errors import CaseError
from trackplan.robots.model import Robot

MAX_NEWTON_STEP = 0.5
"""Largest change of any joint in one Newton iteration, rad: keeps the solution near the seed."""

_NU_START = 1.0  # damping μ = ν · |e|² + μ_min: vanishes with the error (quadratic convergence)
_MU_MIN = 1e-15
_NU_MAX = 1e12  # ν this large means the error cannot decrease: a local minimum


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
    dh
        Shape (n, 5): d (m), a (m), cos alpha, sin alpha, offset (rad) of each joint.
    tool
        ``T_flange_tool``, shape (4, 4).
    """
    dh = np.stack([robot.d, robot.a, np.cos(robot.alpha), np.sin(robot.alpha), robot.offset], 1)
    return np.ascontiguousarray(dh), np.array(robot.T_flange_tool, dtype=float, order="C")


def work_size(n_dof: int) -> int:
    """Length of the scratch vector :func:`newton_into` needs for an n-joint chain."""
    m = min(n_dof, 6)
    return 2 * 16 + 2 * 6 * n_dof + 2 * 6 + 3 * n_dof + m * m + m + 6 * n_dof


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
    _newton_batch(
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


work_size_kernel = njit(cache=True, error_model="numpy")(work_size)


@njit(cache=True, error_model="numpy")
def _newton_batch(
    dh: np.ndarray,
    tool: np.ndarray,
    T: np.ndarray,
    pose_index: np.ndarray,
    q: np.ndarray,
    tol: float,
    max_iter: int,
    success: np.ndarray,
    n_iter: np.ndarray,
    errors: np.ndarray,
) -> None:  # pragma: no cover - compiled
    """Kernel: :func:`newton_into` for each row of q (N, n) towards T[pose_index]."""
    work = np.empty(work_size_kernel(dh.shape[0]))
    for k in range(q.shape[0]):
        ok, iters, perr, oerr = newton_into(dh, tool, T[pose_index[k]], q[k], tol, max_iter, work)
        success[k] = ok
        n_iter[k] = iters
        errors[k, 0] = perr
        errors[k, 1] = oerr


@njit(cache=True, error_model="numpy")
def fk_jacobian_into(
    dh: np.ndarray, tool: np.ndarray, q: np.ndarray, T: np.ndarray, J: np.ndarray, axes: np.ndarray
) -> None:  # pragma: no cover - compiled
    """Kernel: tool pose and geometric Jacobian of one configuration.

    Parameters
    ----------
    dh
        From :func:`chain_arrays`, shape (n, 5).
    tool
        ``T_flange_tool``, shape (4, 4).
    q
        Joint positions, shape (n,), rad.
    T
        Output tool pose in the base frame, shape (4, 4).
    J
        Output Jacobian at the tool point, base frame, rows (v, ω), shape (6, n).
    axes
        Scratch, shape (n, 6): joint axes and origins.
    """
    n = dh.shape[0]
    for i in range(4):
        for j in range(4):
            T[i, j] = 1.0 if i == j else 0.0
    for i in range(n):
        for r in range(3):
            axes[i, r] = T[r, 2]
            axes[i, 3 + r] = T[r, 3]
        theta = q[i] + dh[i, 4]
        ct = math.cos(theta)
        st = math.sin(theta)
        d = dh[i, 0]
        a = dh[i, 1]
        ca = dh[i, 2]
        sa = dh[i, 3]
        for r in range(3):
            t0 = T[r, 0]
            t1 = T[r, 1]
            t2 = T[r, 2]
            # Row r of T · Rz(θ) Tz(d) Tx(a) Rx(α).
            T[r, 0] = t0 * ct + t1 * st
            T[r, 1] = (-t0 * st + t1 * ct) * ca + t2 * sa
            T[r, 2] = (t0 * st - t1 * ct) * sa + t2 * ca
            T[r, 3] += a * (t0 * ct + t1 * st) + d * t2
    for r in range(3):
        t0 = T[r, 0]
        t1 = T[r, 1]
        t2 = T[r, 2]
        for c in range(3):
            T[r, c] = t0 * tool[0, c] + t1 * tool[1, c] + t2 * tool[2, c]
        T[r, 3] += t0 * tool[0, 3] + t1 * tool[1, 3] + t2 * tool[2, 3]
    for i in range(n):
        zx = axes[i, 0]
        zy = axes[i, 1]
        zz = axes[i, 2]
        dx = T[0, 3] - axes[i, 3]
        dy = T[1, 3] - axes[i, 4]
        dz = T[2, 3] - axes[i, 5]
        J[0, i] = zy * dz - zz * dy
        J[1, i] = zz * dx - zx * dz
        J[2, i] = zx * dy - zy * dx
        J[3, i] = zx
        J[4, i] = zy
        J[5, i] = zz


@njit(cache=True, error_model="numpy")
def pose_error_into(
    T_target: np.ndarray, T: np.ndarray, e: np.ndarray
) -> tuple[float, float]:  # pragma: no cover - compiled
    """Kernel: pose error ``(p_t − p, log(R_t Rᵀ))`` into e (6,).

    Returns the position error (m) and the orientation error angle (rad).
    """
    for r in range(3):
        e[r] = T_target[r, 3] - T[r, 3]
    # Rotation error R_t Rᵀ: entry (i, j) is row i of R_t dotted with row j of R.
    d00 = T_target[0, 0] * T[0, 0] + T_target[0, 1] * T[0, 1] + T_target[0, 2] * T[0, 2]
    d11 = T_target[1, 0] * T[1, 0] + T_target[1, 1] * T[1, 1] + T_target[1, 2] * T[1, 2]
    d22 = T_target[2, 0] * T[2, 0] + T_target[2, 1] * T[2, 1] + T_target[2, 2] * T[2, 2]
    d01 = T_target[0, 0] * T[1, 0] + T_target[0, 1] * T[1, 1] + T_target[0, 2] * T[1, 2]
    d10 = T_target[1, 0] * T[0, 0] + T_target[1, 1] * T[0, 1] + T_target[1, 2] * T[0, 2]
    d02 = T_target[0, 0] * T[2, 0] + T_target[0, 1] * T[2, 1] + T_target[0, 2] * T[2, 2]
    d20 = T_target[2, 0] * T[0, 0] + T_target[2, 1] * T[0, 1] + T_target[2, 2] * T[0, 2]
    d12 = T_target[1, 0] * T[2, 0] + T_target[1, 1] * T[2, 1] + T_target[1, 2] * T[2, 2]
    d21 = T_target[2, 0] * T[1, 0] + T_target[2, 1] * T[1, 1] + T_target[2, 2] * T[1, 2]
    vx = 0.5 * (d21 - d12)
    vy = 0.5 * (d02 - d20)
    vz = 0.5 * (d10 - d01)
    s = math.sqrt(vx * vx + vy * vy + vz * vz)  # sine of the angle
    c = 0.5 * (d00 + d11 + d22 - 1.0)
    angle = math.atan2(s, c)
    if c > 0.0 or s > 1e-6:
        scale = angle / s if s > 0.0 else 1.0
        e[3] = vx * scale
        e[4] = vy * scale
        e[5] = vz * scale
    else:
        # Near π the skew part vanishes: the axis is the dominant column of (E + Eᵀ)/2 − cI.
        if d00 >= d11 and d00 >= d22:
            ax, ay, az = d00 - c, 0.5 * (d01 + d10), 0.5 * (d02 + d20)
        elif d11 >= d22:
            ax, ay, az = 0.5 * (d01 + d10), d11 - c, 0.5 * (d12 + d21)
        else:
            ax, ay, az = 0.5 * (d02 + d20), 0.5 * (d12 + d21), d22 - c
        norm = math.sqrt(ax * ax + ay * ay + az * az)
        if ax * vx + ay * vy + az * vz < 0.0:
            norm = -norm
        e[3] = angle * ax / norm
        e[4] = angle * ay / norm
        e[5] = angle * az / norm
    return math.sqrt(e[0] * e[0] + e[1] * e[1] + e[2] * e[2]), angle


@njit(cache=True, error_model="numpy")
def damped_solve_into(
    J: np.ndarray, e: np.ndarray, mu: float, dq: np.ndarray, H: np.ndarray, g: np.ndarray
) -> bool:  # pragma: no cover - compiled
    """Kernel: ``dq = (JᵀJ + μI)⁻¹ Jᵀ e`` (n ≤ 6) or ``Jᵀ (JJᵀ + μI)⁻¹ e`` (n > 6).

    H (m, m) and g (m,) are scratch with m = min(n, 6). Returns False when the system is
    not positive definite (μ = 0 at a singularity); dq is then zero.
    """
    n = J.shape[1]
    m = H.shape[0]
    if n <= 6:
        for i in range(n):
            acc = 0.0
            for r in range(6):
                acc += J[r, i] * e[r]
            g[i] = acc
            for j in range(i + 1):
                acc = 0.0
                for r in range(6):
                    acc += J[r, i] * J[r, j]
                H[i, j] = acc
            H[i, i] += mu
    else:
        for i in range(6):
            g[i] = e[i]
            for j in range(i + 1):
                acc = 0.0
                for c in range(n):
                    acc += J[i, c] * J[j, c]
                H[i, j] = acc
            H[i, i] += mu
    # Cholesky H = L Lᵀ in the lower triangle, then two triangular solves into g.
    for j in range(m):
        acc = H[j, j]
        for k in range(j):
            acc -= H[j, k] * H[j, k]
        if not acc > 0.0:
            for i in range(n):
                dq[i] = 0.0
            return False
        H[j, j] = math.sqrt(acc)
        for i in range(j + 1, m):
            acc = H[i, j]
            for k in range(j):
                acc -= H[i, k] * H[j, k]
            H[i, j] = acc / H[j, j]
    for i in range(m):
        acc = g[i]
        for k in range(i):
            acc -= H[i, k] * g[k]
        g[i] = acc / H[i, i]
    for i in range(m - 1, -1, -1):
        acc = g[i]
        for k in range(i + 1, m):
            acc -= H[k, i] * g[k]
        g[i] = acc / H[i, i]
    if n <= 6:
        for i in range(n):
            dq[i] = g[i]
    else:
        for c in range(n):
            acc = 0.0
            for r in range(6):
                acc += J[r, c] * g[r]
            dq[c] = acc
    return True


@njit(cache=True, error_model="numpy")
def newton_into(
    dh: np.ndarray,
    tool: np.ndarray,
    T_target: np.ndarray,
    q: np.ndarray,
    tol: float,
    max_iter: int,
    work: np.ndarray,
) -> tuple[bool, int, float, float]:  # pragma: no cover - compiled
    """Kernel: damped Newton on one pose, q (n,) updated in place from the seed.

    ``work`` is scratch of length :func:`work_size`. Returns (success, iterations,
    position error m, orientation error rad) of the final q.
    """
    n = dh.shape[0]
    m = min(n, 6)
    at = 0
    T = work[at : at + 16].reshape((4, 4))
    at += 16
    T_try = work[at : at + 16].reshape((4, 4))
    at += 16
    J = work[at : at + 6 * n].reshape((6, n))
    at += 6 * n
    J_try = work[at : at + 6 * n].reshape((6, n))
    at += 6 * n
    e = work[at : at + 6]
    at += 6
    e_try = work[at : at + 6]
    at += 6
    q_try = work[at : at + n]
    at += n
    dq = work[at : at + n]
    at += n
    g = work[at : at + n]
    at += n
    H = work[at : at + m * m].reshape((m, m))
    at += m * m + m
    axes = work[at : at + 6 * n].reshape((n, 6))
    fk_jacobian_into(dh, tool, q, T, J, axes)
    perr, oerr = pose_error_into(T_target, T, e)
    cost = perr * perr + oerr * oerr
    nu = _NU_START
    iters = 0
    while iters < max_iter and not (perr <= tol and oerr <= tol):
        iters += 1
        damped_solve_into(J, e, nu * cost + _MU_MIN, dq, H, g)
        largest = 0.0
        for i in range(n):
            largest = max(largest, abs(dq[i]))
        scale = MAX_NEWTON_STEP / largest if largest > MAX_NEWTON_STEP else 1.0
        for i in range(n):
            q_try[i] = q[i] + scale * dq[i]
        fk_jacobian_into(dh, tool, q_try, T_try, J_try, axes)
        perr_try, oerr_try = pose_error_into(T_target, T_try, e_try)
        cost_try = perr_try * perr_try + oerr_try * oerr_try
        if cost_try < cost:
            for i in range(n):
                q[i] = q_try[i]
            for i in range(6):
                e[i] = e_try[i]
                for j in range(n):
                    J[i, j] = J_try[i, j]
            for i in range(4):
                for j in range(4):
                    T[i, j] = T_try[i, j]
            perr, oerr, cost = perr_try, oerr_try, cost_try
            nu = max(0.1 * nu, 1e-6)
        else:
            nu *= 10.0
            if nu > _NU_MAX:
                break
    return (perr <= tol and oerr <= tol), iters, perr, oerr
