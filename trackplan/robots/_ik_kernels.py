"""Compiled kernels of the numerical IK: the Jacobian, the pose error and damped Newton.

The Python APIs are :mod:`trackplan.robots.ik_numeric`,
:mod:`trackplan.robots.resolved_rate` and the numerical path IK
(:func:`trackplan.robots._path_kernels.numeric_paths`). A chain is given in the layout of
:attr:`trackplan.robots.model.Robot.kernel_chain` (see :mod:`trackplan.robots._kernels`).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from trackplan.robots._kernels import chain_step

MAX_NEWTON_STEP = 0.5
"""Largest change of any joint in one Newton iteration, rad: keeps the solution near the seed."""

_NU_START = 1.0  # damping μ = ν · |e|² + μ_min: vanishes with the error (quadratic convergence)
_MU_MIN = 1e-15
_NU_MAX = 1e12  # ν this large means the error cannot decrease: a local minimum

FAST_COST = 1e-4
"""Squared pose error (m² + rad²) below which :func:`newton_into` first tries undamped
Gauss–Newton steps on a square Jacobian (about 10 mm or 10 mrad): a warm start."""

FAST_MAX_STEP = 0.05
"""Largest joint change (rad) of an undamped Gauss–Newton step: a larger one comes from an
ill-conditioned Jacobian near a singularity and could leave the reference's solution for
another; the damped iterations take such a pose over."""

_TRACK_STEPS = 5  # evaluations of track_batch's Gauss–Newton before newton_into takes over

_PIVOT_MIN = 1e-12  # |pivot| below it: the square Jacobian counts as singular


def work_size(n_dof: int) -> int:
    """Length of the scratch vector :func:`newton_into` needs for an n-joint chain."""
    m = min(n_dof, 6)
    return 2 * 16 + 2 * 6 * n_dof + 2 * 6 + 3 * n_dof + m * m + m + 6 * n_dof + 6 * 7


work_size_kernel = njit(cache=True, error_model="numpy")(work_size)


@njit(cache=True, error_model="numpy")
def newton_batch(
    chain: np.ndarray,
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
    work = np.empty(work_size_kernel(chain.shape[0]))
    for k in range(q.shape[0]):
        target = T[pose_index[k]]
        ok, iters, perr, oerr = newton_into(chain, tool, target, q[k], tol, max_iter, work)
        success[k] = ok
        n_iter[k] = iters
        errors[k, 0] = perr
        errors[k, 1] = oerr


@njit(cache=True, error_model="numpy")
def fk_jacobian_into(
    chain: np.ndarray,
    tail: np.ndarray,
    q: np.ndarray,
    T: np.ndarray,
    J: np.ndarray,
    axes: np.ndarray,
) -> None:  # pragma: no cover - compiled
    """Kernel: tool pose and geometric Jacobian of one configuration.

    Parameters
    ----------
    chain, tail
        From :func:`chain_arrays`, shapes (n, 4, 4) and (4, 4).
    q
        Joint positions, shape (n,), rad.
    T
        Output tool pose in the base frame, shape (4, 4).
    J
        Output Jacobian at the tool point, base frame, rows (v, ω), shape (6, n).
    axes
        Scratch, shape (n, 6): joint axes and origins.
    """
    n = chain.shape[0]
    for i in range(4):
        for j in range(4):
            T[i, j] = 1.0 if i == j else 0.0
    for i in range(n):
        chain_step(T, chain[i], math.cos(q[i]), math.sin(q[i]))
        for r in range(3):
            axes[i, r] = T[r, 2]
            axes[i, 3 + r] = T[r, 3]
    for r in range(3):
        t0 = T[r, 0]
        t1 = T[r, 1]
        t2 = T[r, 2]
        for c in range(3):
            T[r, c] = t0 * tail[0, c] + t1 * tail[1, c] + t2 * tail[2, c]
        T[r, 3] += t0 * tail[0, 3] + t1 * tail[1, 3] + t2 * tail[2, 3]
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
def square_solve_into(
    J: np.ndarray, e: np.ndarray, locked: int, dq: np.ndarray, A: np.ndarray
) -> bool:  # pragma: no cover - compiled
    """Kernel: the Gauss–Newton step ``dq = J⁻¹ e`` of a square Jacobian.

    J (6, n) is square when n = 6, or n = 7 without the column ``locked`` (≥ 0), whose dq
    is then zero. Gaussian elimination with partial pivoting on A (6, 7) scratch (J and
    e side by side). Returns False (dq unchanged) when a pivot is below 1e-12: a
    singular configuration, left to the damped iterations.
    """
    n = J.shape[1]
    for r in range(6):
        c = 0
        for j in range(n):
            if j != locked:
                A[r, c] = J[r, j]
                c += 1
        A[r, 6] = e[r]
    for col in range(6):
        pivot = col
        best = abs(A[col, col])
        for r in range(col + 1, 6):
            if abs(A[r, col]) > best:
                best = abs(A[r, col])
                pivot = r
        if not best > _PIVOT_MIN:
            return False
        if pivot != col:
            for c in range(col, 7):
                A[col, c], A[pivot, c] = A[pivot, c], A[col, c]
        inv = 1.0 / A[col, col]
        for r in range(col + 1, 6):
            factor = A[r, col] * inv
            for c in range(col + 1, 7):
                A[r, c] -= factor * A[col, c]
    for r in range(5, -1, -1):
        acc = A[r, 6]
        for c in range(r + 1, 6):
            acc -= A[r, c] * A[c, 6]
        A[r, 6] = acc / A[r, r]
    c = 0
    for j in range(n):
        if j == locked:
            dq[j] = 0.0
        else:
            dq[j] = A[c, 6]
            c += 1
    return True


@njit(cache=True, error_model="numpy")
def newton_into(
    chain: np.ndarray,
    tool: np.ndarray,
    T_target: np.ndarray,
    q: np.ndarray,
    tol: float,
    max_iter: int,
    work: np.ndarray,
    locked: int = -1,
) -> tuple[bool, int, float, float]:  # pragma: no cover - compiled
    """Kernel: damped Newton on one pose, q (n,) updated in place from the seed.

    ``work`` is scratch of length :func:`work_size`. ``locked`` ≥ 0 holds that joint at
    its value in q (its Jacobian column is zero: the others solve the pose, a 7-joint
    arm's redundancy given by that joint). Returns (success, iterations, position error
    m, orientation error rad) of the final q.

    A warm start (squared error below :data:`FAST_COST`) on a square Jacobian (n = 6, or
    7 with a joint locked) first takes undamped Gauss–Newton steps
    (:func:`square_solve_into`), each kept only while the error falls and no joint moves
    more than :data:`FAST_MAX_STEP`: from a reference within a few mrad, two steps
    and three evaluations reach 1e-10. Otherwise (or when such a step fails) the damped
    iterations below take over from the last kept configuration.
    """
    n = chain.shape[0]
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
    at += 6 * n
    A = work[at : at + 42].reshape((6, 7))
    fk_jacobian_into(chain, tool, q, T, J, axes)
    if locked >= 0:
        for r in range(6):
            J[r, locked] = 0.0
    perr, oerr = pose_error_into(T_target, T, e)
    cost = perr * perr + oerr * oerr
    iters = 0
    square = n == 6 or (n == 7 and locked >= 0)
    while square and cost <= FAST_COST and iters < max_iter and not (perr <= tol and oerr <= tol):
        if not square_solve_into(J, e, locked, dq, A):
            break
        largest = 0.0
        for i in range(n):
            largest = max(largest, abs(dq[i]))
        if largest > FAST_MAX_STEP:
            break
        iters += 1
        for i in range(n):
            q_try[i] = q[i]
            q[i] += dq[i]
        fk_jacobian_into(chain, tool, q, T, J, axes)
        if locked >= 0:
            for r in range(6):
                J[r, locked] = 0.0
        perr_new, oerr_new = pose_error_into(T_target, T, e)
        cost_new = perr_new * perr_new + oerr_new * oerr_new
        if cost_new < cost:
            perr, oerr, cost = perr_new, oerr_new, cost_new
            continue
        for i in range(n):  # no progress: back to the kept q, damped from there
            q[i] = q_try[i]
        fk_jacobian_into(chain, tool, q, T, J, axes)
        if locked >= 0:
            for r in range(6):
                J[r, locked] = 0.0
        perr, oerr = pose_error_into(T_target, T, e)
        cost = perr * perr + oerr * oerr
        break
    nu = _NU_START
    while iters < max_iter and not (perr <= tol and oerr <= tol):
        iters += 1
        damped_solve_into(J, e, nu * cost + _MU_MIN, dq, H, g)
        largest = 0.0
        for i in range(n):
            largest = max(largest, abs(dq[i]))
        scale = MAX_NEWTON_STEP / largest if largest > MAX_NEWTON_STEP else 1.0
        for i in range(n):
            q_try[i] = q[i] + scale * dq[i]
        fk_jacobian_into(chain, tool, q_try, T_try, J_try, axes)
        if locked >= 0:
            for r in range(6):
                J_try[r, locked] = 0.0
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


@njit(cache=True, error_model="numpy")
def track_batch(
    chain: np.ndarray,
    tool: np.ndarray,
    R: np.ndarray,
    p: np.ndarray,
    q_ref: np.ndarray,
    locked: int,
    free: np.ndarray,
    tol: float,
    max_iter: int,
    q: np.ndarray,
    ok: np.ndarray,
) -> None:  # pragma: no cover - compiled
    """Kernel: Newton on each pose from its reference configuration.

    :func:`gauss_newton_into` first (a square Jacobian: n = 6, or 7 with ``locked``); a
    pose it does not solve is solved by :func:`newton_into` from its reference again.

    Parameters
    ----------
    chain, tool
        From :func:`trackplan.robots.ik_numeric.chain_arrays`.
    R, p
        Tool rotations (N, 3, 3) or one for all (1, 3, 3), and positions (N, 3), m.
    q_ref
        Warm starts, shape (N, n), rad.
    locked, free
        Joint ``locked`` (≥ 0) held at ``free[i]`` (shape (N,), rad) at pose i; −1 and an
        empty ``free``: none held.
    tol, max_iter
        Newton tolerance (m and rad) and iteration limit.
    q, ok
        Outputs (N, n) rad (the last iterate where not ok) and (N,) bool.
    """
    n = chain.shape[0]
    work = np.empty(work_size_kernel(n))
    target = np.zeros((4, 4))
    target[3, 3] = 1.0
    T = np.empty((4, 4))
    J = np.empty((6, n))
    axes = np.empty((n, 6))
    e = np.empty(6)
    A = np.empty((6, 7))
    dq = np.empty(n)
    square = n == 6 or (n == 7 and locked >= 0)
    one_rotation = R.shape[0] == 1
    for i in range(p.shape[0]):
        k = 0 if one_rotation else i
        for r in range(3):
            for c in range(3):
                target[r, c] = R[k, r, c]
            target[r, 3] = p[i, r]
        x = q[i]
        for j in range(n):
            x[j] = q_ref[i, j]
        if locked >= 0:
            x[locked] = free[i]
        solved = square and gauss_newton_into(
            chain, tool, target, x, tol, locked, T, J, axes, e, A, dq
        )
        if not solved:  # from the reference again, damped where needed
            for j in range(n):
                x[j] = q_ref[i, j]
            if locked >= 0:
                x[locked] = free[i]
            solved = newton_into(chain, tool, target, x, tol, max_iter, work, locked)[0]
        ok[i] = solved


@njit(cache=True, error_model="numpy", inline="always")
def gauss_newton_into(
    chain: np.ndarray,
    tool: np.ndarray,
    T_target: np.ndarray,
    q: np.ndarray,
    tol: float,
    locked: int,
    T: np.ndarray,
    J: np.ndarray,
    axes: np.ndarray,
    e: np.ndarray,
    A: np.ndarray,
    dq: np.ndarray,
) -> bool:  # pragma: no cover - compiled
    """Kernel: undamped Gauss–Newton on one pose from a warm start, q (n,) in place.

    At most :data:`_TRACK_STEPS` evaluations; each step is taken only while the squared
    error falls and is below :data:`FAST_COST`, the square Jacobian (n = 6, or 7 without
    column ``locked``) is regular and no joint moves more than :data:`FAST_MAX_STEP`.
    The first phase of :func:`newton_into` without its bookkeeping, for the many poses of
    a path near their references. T (4, 4), J (6, n), axes (n, 6), e (6,), A (6, 7) and
    dq (n,) are scratch.

    Returns
    -------
    bool
        Both errors within ``tol``; when False, q is left where the steps stopped.
    """
    n = chain.shape[0]
    cost = FAST_COST
    for _ in range(_TRACK_STEPS):
        fk_jacobian_into(chain, tool, q, T, J, axes)
        perr, oerr = pose_error_into(T_target, T, e)
        if perr <= tol and oerr <= tol:
            return True
        new_cost = perr * perr + oerr * oerr
        if not new_cost < cost or not square_solve_into(J, e, locked, dq, A):
            return False
        cost = new_cost
        largest = 0.0
        for j in range(n):
            largest = max(largest, abs(dq[j]))
        if largest > FAST_MAX_STEP:
            return False
        for j in range(n):
            q[j] += dq[j]
    return False
