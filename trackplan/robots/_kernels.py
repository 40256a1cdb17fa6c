"""Compiled kernels of the robot package: chain kinematics and the path IK analysis.

The Python APIs are :mod:`trackplan.robots.kinematics` and
:mod:`trackplan.robots.path_ik`. A chain is given in the layout of
:attr:`trackplan.robots.model.Robot.kernel_chain`: ``chain`` (n, 4, 4) and ``tail``
(4, 4), every joint turning about z, ``T = Π (C_i · Rz(q_i)) · tail``.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit


@njit(cache=True, error_model="numpy", inline="always")
def chain_step(T: np.ndarray, C: np.ndarray, c: float, s: float) -> None:  # pragma: no cover
    """Kernel: ``T ← T · C · Rz(θ)`` in place for a (3, 4) or (4, 4) T, with c, s of θ."""
    for r in range(3):
        t0 = T[r, 0]
        t1 = T[r, 1]
        t2 = T[r, 2]
        x = t0 * C[0, 0] + t1 * C[1, 0] + t2 * C[2, 0]
        y = t0 * C[0, 1] + t1 * C[1, 1] + t2 * C[2, 1]
        T[r, 3] += t0 * C[0, 3] + t1 * C[1, 3] + t2 * C[2, 3]
        T[r, 2] = t0 * C[0, 2] + t1 * C[1, 2] + t2 * C[2, 2]
        T[r, 0] = x * c + y * s
        T[r, 1] = y * c - x * s


@njit(cache=True, error_model="numpy", inline="always")
def apply_tail(T: np.ndarray, tail: np.ndarray, out: np.ndarray) -> None:  # pragma: no cover
    """Kernel: ``out ← T · tail`` for (3, 4) rows, out (4, 4) with the last row set."""
    for r in range(3):
        for c in range(4):
            out[r, c] = T[r, 0] * tail[0, c] + T[r, 1] * tail[1, c] + T[r, 2] * tail[2, c]
        out[r, 3] += T[r, 3]
    out[3, 0] = 0.0
    out[3, 1] = 0.0
    out[3, 2] = 0.0
    out[3, 3] = 1.0


FK_BLOCK = 32
"""Poses per block of :func:`fk_flat`: each step of the chain runs over a block's poses in
a flat loop that LLVM turns into SIMD code."""

_TWO_OVER_PI = 6.36619772367581382433e-01
_PIO2_1 = 1.57079632673412561417e00  # first 33 bits of π/2
_PIO2_2 = 6.07710050630396597660e-11  # next 33 bits
_PIO2_3 = 2.02226624871116645580e-21  # next 33 bits
_S1 = -1.66666666666666324348e-01
_S2 = 8.33333333332248946124e-03
_S3 = -1.98412698298579493134e-04
_S4 = 2.75573137070700676789e-06
_S5 = -2.50507602534068634195e-08
_S6 = 1.58969099521155010221e-10
_C1 = 4.16666666666666019037e-02
_C2 = -1.38888888888741095749e-03
_C3 = 2.48015872894767294178e-05
_C4 = -2.75573143513906633035e-07
_C5 = 2.08757232129817482790e-09
_C6 = -1.13596475577881948265e-11
REDUCTION_LIMIT = 1.0e5
"""rad: beyond it the three-part reduction of :func:`sincos` loses bits (use libm)."""


@njit(cache=True, error_model="numpy", inline="always")
def sincos(x: float) -> tuple[float, float]:  # pragma: no cover - compiled
    """Kernel: (cos x, sin x) by the fdlibm kernels after a Cody–Waite reduction, within
    1 ulp of libm for ``|x| ≤`` :data:`REDUCTION_LIMIT`; branch-free, so that a loop of
    it vectorises (libm's scalar calls do not)."""
    k = np.floor(x * _TWO_OVER_PI + 0.5)
    r = ((x - k * _PIO2_1) - k * _PIO2_2) - k * _PIO2_3  # |r| <= π/4
    z = r * r
    zz = z * z
    sin_r = r + r * z * (_S1 + z * (_S2 + z * (_S3 + z * (_S4 + z * (_S5 + z * _S6)))))
    tail = z * (_C1 + z * (_C2 + z * _C3)) + zz * zz * (_C4 + z * (_C5 + z * _C6))
    half = 0.5 * z
    head = 1.0 - half
    cos_r = head + (((1.0 - head) - half) + z * tail)
    quadrant = k - 4.0 * np.floor(0.25 * k)
    odd = quadrant == 1.0 or quadrant == 3.0
    sin_abs = cos_r if odd else sin_r
    cos_abs = sin_r if odd else cos_r
    sin_x = -sin_abs if quadrant >= 2.0 else sin_abs
    cos_x = -cos_abs if (quadrant == 1.0 or quadrant == 2.0) else cos_abs
    return cos_x, sin_x


@njit(cache=True, error_model="numpy")
def chain_block(
    chain: np.ndarray,
    angle: np.ndarray,
    m: int,
    cos: np.ndarray,
    sin: np.ndarray,
    T: np.ndarray,
) -> None:  # pragma: no cover - compiled
    """Kernel: ``T ← Π (C_i · Rz(θ_i))`` of a block of :data:`FK_BLOCK` configurations.

    ``angle`` (n, FK_BLOCK) holds joint i of configuration b at ``[i, b]`` (the first ``m``
    columns are used); ``cos`` and ``sin`` (n, FK_BLOCK) are scratch; ``T`` (12, FK_BLOCK)
    receives row r, column c of configuration b's (3, 4) transform at ``[4 r + c, b]``.
    The sines and cosines by :func:`sincos` (libm for a block with an angle beyond
    :data:`REDUCTION_LIMIT`), each product ``T ← T · C · Rz(θ)`` over the block's
    configurations in a flat loop that vectorises.
    """
    n_dof = angle.shape[0]
    exotic = False
    for i in range(n_dof):
        for b in range(m):
            if not abs(angle[i, b]) <= REDUCTION_LIMIT:
                exotic = True
    for i in range(n_dof):
        x_i = angle[i]
        cos_i = cos[i]
        sin_i = sin[i]
        for b in range(FK_BLOCK):
            cos_i[b], sin_i[b] = sincos(x_i[b])
        if exotic:
            for b in range(m):
                cos_i[b] = math.cos(x_i[b])
                sin_i[b] = math.sin(x_i[b])
    for e in range(12):
        value = 1.0 if e == 0 or e == 5 or e == 10 else 0.0
        for b in range(FK_BLOCK):
            T[e, b] = value
    for i in range(n_dof):
        C = chain[i]
        c00, c01, c02, c03 = C[0, 0], C[0, 1], C[0, 2], C[0, 3]
        c10, c11, c12, c13 = C[1, 0], C[1, 1], C[1, 2], C[1, 3]
        c20, c21, c22, c23 = C[2, 0], C[2, 1], C[2, 2], C[2, 3]
        cos_i = cos[i]
        sin_i = sin[i]
        for r in range(3):
            T0 = T[4 * r]
            T1 = T[4 * r + 1]
            T2 = T[4 * r + 2]
            T3 = T[4 * r + 3]
            for b in range(FK_BLOCK):
                t0 = T0[b]
                t1 = T1[b]
                t2 = T2[b]
                x = t0 * c00 + t1 * c10 + t2 * c20
                y = t0 * c01 + t1 * c11 + t2 * c21
                T3[b] += t0 * c03 + t1 * c13 + t2 * c23
                T2[b] = t0 * c02 + t1 * c12 + t2 * c22
                T0[b] = x * cos_i[b] + y * sin_i[b]
                T1[b] = y * cos_i[b] - x * sin_i[b]


@njit(cache=True, error_model="numpy")
def fk_flat(chain: np.ndarray, tail: np.ndarray, q: np.ndarray) -> np.ndarray:  # pragma: no cover
    """Kernel: tool poses of a flat batch, q (N, n) → T (N, 4, 4).

    Blocks of :data:`FK_BLOCK` poses (:func:`chain_block`), then the tail.
    """
    n_poses, n_dof = q.shape
    out = np.empty((n_poses, 4, 4))
    angle = np.zeros((n_dof, FK_BLOCK))
    cos = np.empty((n_dof, FK_BLOCK))
    sin = np.empty((n_dof, FK_BLOCK))
    T = np.empty((12, FK_BLOCK))  # T[4 r + c, b]: row r, column c of pose b's transform
    for start in range(0, n_poses, FK_BLOCK):
        m = min(FK_BLOCK, n_poses - start)
        for b in range(m):
            for i in range(n_dof):
                angle[i, b] = q[start + b, i]
        chain_block(chain, angle, m, cos, sin, T)
        for b in range(m):
            pose = out[start + b]
            for r in range(3):
                t0 = T[4 * r, b]
                t1 = T[4 * r + 1, b]
                t2 = T[4 * r + 2, b]
                for c in range(4):
                    pose[r, c] = t0 * tail[0, c] + t1 * tail[1, c] + t2 * tail[2, c]
                pose[r, 3] += T[4 * r + 3, b]
            pose[3, 0] = 0.0
            pose[3, 1] = 0.0
            pose[3, 2] = 0.0
            pose[3, 3] = 1.0
    return out


@njit(cache=True, error_model="numpy")
def frames_flat(
    chain: np.ndarray, tail: np.ndarray, links: np.ndarray, q: np.ndarray
) -> np.ndarray:  # pragma: no cover - compiled
    """Kernel: base, link and tool frames of a flat batch, q (N, n) → (N, n + 2, 4, 4).

    Link frame i is the chain's frame after joint i (z along the joint's axis) times
    ``links[i]`` (n, 4, 4).
    """
    n_poses, n_dof = q.shape
    out = np.zeros((n_poses, n_dof + 2, 4, 4))
    T = np.empty((3, 4))
    for k in range(n_poses):
        T[:] = 0.0
        T[0, 0] = T[1, 1] = T[2, 2] = 1.0
        for r in range(4):
            out[k, 0, r, r] = 1.0
        for i in range(n_dof):
            chain_step(T, chain[i], math.cos(q[k, i]), math.sin(q[k, i]))
            apply_tail(T, links[i], out[k, i + 1])
        apply_tail(T, tail, out[k, n_dof + 1])
    return out


MAX_NEWTON_STEP = 0.5
"""Largest change of any joint in one Newton iteration, rad: keeps the solution near the seed."""

_NU_START = 1.0  # damping μ = ν · |e|² + μ_min: vanishes with the error (quadratic convergence)
_MU_MIN = 1e-15
_NU_MAX = 1e12  # ν this large means the error cannot decrease: a local minimum


def work_size(n_dof: int) -> int:
    """Length of the scratch vector :func:`newton_into` needs for an n-joint chain."""
    m = min(n_dof, 6)
    return 2 * 16 + 2 * 6 * n_dof + 2 * 6 + 3 * n_dof + m * m + m + 6 * n_dof


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
def newton_into(
    chain: np.ndarray,
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
    fk_jacobian_into(chain, tool, q, T, J, axes)
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
        fk_jacobian_into(chain, tool, q_try, T_try, J_try, axes)
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


# Kinds of switch, in the order of the per-branch report.
NONE, SHOULDER, ELBOW, WRIST, SINGULAR, JUMP = range(6)
# Per-branch integer report: first problem, first unreachable pose, number unreachable,
# first switch, its kind, its joint (jumps), number of switches, first pose outside the
# limits, its joint.
I_FIRST, I_UNREACH, I_N_UNREACH, I_SWITCH, I_KIND, I_JOINT, I_N_SWITCH = range(7)
I_LIMIT, I_LIMIT_JOINT = 7, 8
N_INT = 9
# Per-branch float report: margin (rad), the jump (rad), the joint value outside (rad).
F_MARGIN, F_STEP, F_VALUE = range(3)
N_FLOAT = 3


@njit(cache=True, error_model="numpy")
def room_bounds(
    q_all: np.ndarray, valid: np.ndarray, q_min: np.ndarray, q_max: np.ndarray
) -> np.ndarray:  # pragma: no cover - compiled
    """Kernel: an upper bound of each branch's path margin from its poses one at a time.

    A joint value θ fits its limits by at most ``max_k min(θ + 2πk − q_min, q_max − θ −
    2πk)``, reached at the k nearest the centre of the range. The continuous path through
    a branch's poses, shifted by one multiple of 2π per joint, has no more margin than its
    worst pose (:func:`analyse_paths`): the smallest of these over the poses and joints
    bounds the branch's margin from above (up to the round-off of the unwrapping).
    A branch that misses a pose is not usable: −inf.

    Parameters
    ----------
    q_all, valid
        Closed-form solutions (B, M, 8, n), rad, and their validity (B, M, 8).
    q_min, q_max
        Joint limits, shape (n,), rad.

    Returns
    -------
    numpy.ndarray
        Shape (B, 8), rad.
    """
    n_cand, n_poses, n_branch, n = q_all.shape
    two_pi = 2.0 * math.pi
    bound = np.full((n_cand, n_branch), np.inf)
    for b in range(n_cand):
        for m in range(n_poses):
            for k in range(n_branch):
                if not valid[b, m, k]:
                    bound[b, k] = -np.inf
                    continue
                for j in range(n):
                    theta = q_all[b, m, k, j]
                    middle = 0.5 * (q_min[j] + q_max[j])
                    shift = two_pi * math.floor((middle - theta) / two_pi + 0.5)
                    room = min(theta + shift - q_min[j], q_max[j] - theta - shift)
                    if room < bound[b, k]:
                        bound[b, k] = room
    return bound


@njit(cache=True, error_model="numpy")
def numeric_paths(
    chain: np.ndarray,
    tool: np.ndarray,
    T: np.ndarray,
    seeds: np.ndarray,
    coarse: np.ndarray,
    tol: float,
    march_iter: int,
    fine_iter: int,
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:  # pragma: no cover - compiled
    """Kernel: numerical joint paths from seeds, marched coarsely then solved everywhere.

    Parameters
    ----------
    chain, tool
        From :func:`trackplan.robots.ik_numeric.chain_arrays`.
    T
        Tool poses, shape (B, M, 4, 4).
    seeds
        Seed per candidate and branch, shape (B, K, n), rad.
    coarse
        Poses to march through, shape (B, M), bool (first and last included).
    tol, march_iter, fine_iter
        Newton tolerance (m and rad) and iteration limits of the march and the fine solve.

    Returns
    -------
    q, reach, magnitude, crossing
        Shapes (B, K, M, n), (B, K, M) (Newton converged), (B, K, M, 1): |det J| (or the
        manipulability when n ≠ 6), and (B, K, M) int8: SINGULAR where det J changes sign.
    """
    n_cand, n_poses = T.shape[0], T.shape[1]
    n_k, n = seeds.shape[1], seeds.shape[2]
    q = np.empty((n_cand, n_k, n_poses, n))
    reach = np.empty((n_cand, n_k, n_poses), dtype=np.bool_)
    magnitude = np.empty((n_cand, n_k, n_poses, 1))
    crossing = np.zeros((n_cand, n_k, n_poses), dtype=np.int8)
    work = np.empty(work_size_kernel(n))
    current = np.empty(n)
    T_k = np.empty((4, 4))
    J = np.empty((6, n))
    axes = np.empty((n, 6))
    square = np.empty((6, 6))
    previous_coarse = np.empty(n_poses, dtype=np.int64)
    next_coarse = np.empty(n_poses, dtype=np.int64)
    for b in range(n_cand):
        last = 0
        for m in range(n_poses):
            if coarse[b, m]:
                last = m
            previous_coarse[m] = last
        for m in range(n_poses - 1, -1, -1):
            if coarse[b, m]:
                last = m
            next_coarse[m] = last
        for k in range(n_k):
            path = q[b, k]
            for j in range(n):
                current[j] = seeds[b, k, j]
            for m in range(n_poses):  # march the coarse poses with warm starts
                if coarse[b, m]:
                    for j in range(n):
                        path[m, j] = current[j]
                    ok = newton_into(chain, tool, T[b, m], path[m], tol, march_iter, work)[0]
                    reach[b, k, m] = ok
                    if ok:
                        for j in range(n):
                            current[j] = path[m, j]
                    else:
                        for j in range(n):
                            path[m, j] = current[j]
            for m in range(n_poses):  # every pose, from the interpolated coarse path
                if not coarse[b, m]:
                    m0 = previous_coarse[m]
                    m1 = next_coarse[m]
                    w = (m - m0) / (m1 - m0)
                    for j in range(n):
                        path[m, j] = (1.0 - w) * path[m0, j] + w * path[m1, j]
                    solved = newton_into(chain, tool, T[b, m], path[m], tol, fine_iter, work)
                    reach[b, k, m] = solved[0]
            previous = 0.0
            for m in range(n_poses):
                fk_jacobian_into(chain, tool, path[m], T_k, J, axes)
                det = singularity_measure(J, square)
                magnitude[b, k, m, 0] = abs(det)
                if m > 0 and n == 6 and reach[b, k, m] and reach[b, k, m - 1]:
                    if det * previous <= 0.0:
                        crossing[b, k, m] = SINGULAR
                previous = det
    return q, reach, magnitude, crossing


@njit(cache=True, error_model="numpy")
def singularity_measure(J: np.ndarray, square: np.ndarray) -> float:  # pragma: no cover - compiled
    """Kernel: det J for a 6 × 6 Jacobian, else sqrt(det(J Jᵀ)); ``square`` is (6, 6) scratch."""
    n = J.shape[1]
    for i in range(6):
        for j in range(6):
            if n == 6:
                square[i, j] = J[i, j]
            else:
                acc = 0.0
                for c in range(n):
                    acc += J[i, c] * J[j, c]
                square[i, j] = acc
    det = 1.0
    for col in range(6):  # Gaussian elimination with partial pivoting
        pivot = col
        for r in range(col + 1, 6):
            if abs(square[r, col]) > abs(square[pivot, col]):
                pivot = r
        if square[pivot, col] == 0.0:
            return 0.0
        if pivot != col:
            det = -det
            for c in range(6):
                square[col, c], square[pivot, c] = square[pivot, c], square[col, c]
        det *= square[col, col]
        for r in range(col + 1, 6):
            factor = square[r, col] / square[col, col]
            for c in range(col, 6):
                square[r, c] -= factor * square[col, c]
    return det if n == 6 else math.sqrt(abs(det))


@njit(cache=True, error_model="numpy")
def analyse_paths(
    q: np.ndarray,
    reach: np.ndarray,
    magnitude: np.ndarray,
    channel_kind: np.ndarray,
    crossing: np.ndarray,
    q_min: np.ndarray,
    q_max: np.ndarray,
    max_step: np.ndarray,
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:  # pragma: no cover
    """Kernel: make each path continuous, find its switches, fit it into the limits.

    q (B, K, M, n) is modified in place: unreachable poses repeat the previous reachable
    configuration, angles are unwrapped along M and each joint is shifted by the
    multiple of 2π that centres its range in the limits as well as integers allow. A
    joint whose range exceeds its travel by more than 2π has several such windings; they
    are enumerated (``windings``) and the one with the largest margin is kept.

    Returns
    -------
    switch
        Shape (B, K, M), bool.
    report
        Shape (B, K, N_INT), int64 (see the ``_I_*`` indices).
    values
        Shape (B, K, N_FLOAT): margin, jump size, joint value outside the limits (rad).
    windings
        Shape (B, K, n), int64: how many 2π windings of each joint's path fit inside its
        limits (0 when none does).
    winding
        Shape (B, K, n), int64: which of them is kept, counted from the lowest (0 when
        none fits).
    """
    n_cand, n_k, n_poses, n = q.shape
    two_pi = 2.0 * math.pi
    switch = np.zeros((n_cand, n_k, n_poses), dtype=np.bool_)
    report = np.full((n_cand, n_k, N_INT), -1, dtype=np.int64)
    values = np.zeros((n_cand, n_k, N_FLOAT))
    windings = np.zeros((n_cand, n_k, n), dtype=np.int64)
    winding = np.zeros((n_cand, n_k, n), dtype=np.int64)
    low = np.empty(n)
    high = np.empty(n)
    offset = np.empty(n)
    for b in range(n_cand):
        for k in range(n_k):
            path = q[b, k]
            ok = reach[b, k]
            rep = report[b, k]
            val = values[b, k]
            rep[I_N_UNREACH] = 0
            rep[I_N_SWITCH] = 0
            first = -1
            for m in range(n_poses):
                if ok[m]:
                    first = m
                    break
                if rep[I_UNREACH] < 0:
                    rep[I_UNREACH] = m
                rep[I_N_UNREACH] += 1
            if first < 0:
                val[F_MARGIN] = -np.inf
                rep[I_FIRST] = 0
                continue
            for m in range(first):
                for j in range(n):
                    path[m, j] = path[first, j]
            for m in range(first + 1, n_poses):
                if not ok[m]:
                    if rep[I_UNREACH] < 0:
                        rep[I_UNREACH] = m
                    rep[I_N_UNREACH] += 1
                    for j in range(n):
                        path[m, j] = path[m - 1, j]
                    continue
                for j in range(n):
                    step = path[m, j] - path[m - 1, j]
                    step -= two_pi * math.floor(step / two_pi + 0.5)
                    path[m, j] = path[m - 1, j] + step
                    if ok[m - 1] and abs(step) > max_step[j] and not switch[b, k, m]:
                        note_switch(rep, val, switch[b, k], m, int(JUMP), j, abs(step))
                if crossing[b, k, m] != NONE and ok[m - 1]:
                    note_switch(
                        rep, val, switch[b, k], m, int(crossing[b, k, m]), int(NO_JOINT), 0.0
                    )
            for c in range(magnitude.shape[3]):
                note_minima(magnitude[b, k, :, c], ok, int(channel_kind[c]), rep, val, switch[b, k])
            for j in range(n):
                low[j] = np.inf
                high[j] = -np.inf
            for m in range(n_poses):
                if ok[m]:
                    for j in range(n):
                        low[j] = min(low[j], path[m, j])
                        high[j] = max(high[j], path[m, j])
            fit_limits(
                path, ok, q_min, q_max, rep, val, windings[b, k], winding[b, k], low, high, offset
            )
    return switch, report, values, windings, winding


@njit(cache=True, error_model="numpy", nogil=True)
def analyse_closed_form(
    q_all: np.ndarray,
    valid: np.ndarray,
    aux: np.ndarray,
    candidates: np.ndarray,
    q_min: np.ndarray,
    q_max: np.ndarray,
    max_step: np.ndarray,
    q: np.ndarray,
    reach: np.ndarray,
    switch: np.ndarray,
    report: np.ndarray,
    values: np.ndarray,
    windings: np.ndarray,
    winding: np.ndarray,
) -> None:  # pragma: no cover - compiled
    """Kernel: :func:`analyse_paths` of the closed-form solutions' candidate branches, in
    one pass per path written once.

    The outputs are those of gathering each candidate branch's joints, reach and branch
    quantities from all eight branches' solutions and analysing the gathered paths with
    :func:`analyse_paths` (channels shoulder, elbow, wrist; a wrist crossing where the
    wrist vector reverses between two reached poses), bit for bit, without the gathered
    (B, K, M, ·) arrays: each path is unwrapped as it is read, its branch measures go to a
    small scratch. Releases the GIL: threads may analyse separate candidates at once.

    Parameters
    ----------
    q_all, valid, aux
        Closed-form solutions (B, M, 8, n), rad, validity (B, M, 8) and branch quantities
        (B, M, 8, 5): shoulder and elbow measures, wrist vector.
    candidates
        Branches per candidate, shape (B, K).
    q_min, q_max, max_step
        Joint limits and the largest step that is not a jump, shape (n,), rad.
    q, reach, switch, report, values, windings, winding
        Outputs: the analysed paths (B, K, M, n), rad; reach (B, K, M) and switch
        (B, K, M) bool; the reports (B, K, N_INT) and (B, K, N_FLOAT); windings and winding
        (B, K, n) (see :func:`analyse_paths`). Every entry is written.
    """
    n_cand, n_poses, _, n = q_all.shape
    n_k = candidates.shape[1]
    two_pi = 2.0 * math.pi
    mag = np.empty((3, n_poses))
    low = np.empty(n)
    high = np.empty(n)
    offset = np.empty(n)
    steps = np.empty(n)
    for b in range(n_cand):
        for k in range(n_k):
            branch = candidates[b, k]
            path = q[b, k]
            ok = reach[b, k]
            sw = switch[b, k]
            rep = report[b, k]
            val = values[b, k]
            for i in range(N_INT):
                rep[i] = -1
            for i in range(N_FLOAT):
                val[i] = 0.0
            for j in range(n):
                windings[b, k, j] = 0
                winding[b, k, j] = 0
            rep[I_N_UNREACH] = 0
            rep[I_N_SWITCH] = 0
            first = -1
            for m in range(n_poses):
                reached = valid[b, m, branch]
                ok[m] = reached
                sw[m] = False
                x = aux[b, m, branch, 2]
                y = aux[b, m, branch, 3]
                z = aux[b, m, branch, 4]
                mag[0, m] = aux[b, m, branch, 0]
                mag[1, m] = aux[b, m, branch, 1]
                mag[2, m] = math.sqrt(x * x + y * y + z * z)
                if reached:
                    if first < 0:
                        first = m
                else:
                    if rep[I_UNREACH] < 0:
                        rep[I_UNREACH] = m
                    rep[I_N_UNREACH] += 1
            if first < 0:
                for m in range(n_poses):
                    for j in range(n):
                        path[m, j] = q_all[b, m, branch, j]
                val[F_MARGIN] = -np.inf
                rep[I_FIRST] = 0
                continue
            for m in range(first + 1):
                for j in range(n):
                    path[m, j] = q_all[b, first, branch, j]
            for j in range(n):
                low[j] = path[first, j]
                high[j] = path[first, j]
            for m in range(first + 1, n_poses):
                if not ok[m]:
                    for j in range(n):
                        path[m, j] = path[m - 1, j]
                    continue
                jump = False
                for j in range(n):
                    before = path[m - 1, j]
                    step = q_all[b, m, branch, j] - before
                    step -= two_pi * np.floor(step / two_pi + 0.5)
                    steps[j] = step
                    value = before + step
                    path[m, j] = value
                    low[j] = min(low[j], value)
                    high[j] = max(high[j], value)
                    jump |= abs(step) > max_step[j]
                if jump and ok[m - 1]:
                    for j in range(n):
                        step = steps[j]
                        if abs(step) > max_step[j] and not sw[m]:
                            note_switch(rep, val, sw, m, int(JUMP), j, abs(step))
                if ok[m - 1]:
                    x = aux[b, m, branch, 2]
                    y = aux[b, m, branch, 3]
                    z = aux[b, m, branch, 4]
                    dot = (
                        x * aux[b, m - 1, branch, 2]
                        + y * aux[b, m - 1, branch, 3]
                        + z * aux[b, m - 1, branch, 4]
                    )
                    if dot <= 0.0:
                        note_switch(rep, val, sw, m, int(WRIST), int(NO_JOINT), 0.0)
            note_minima(mag[0], ok, int(SHOULDER), rep, val, sw)
            note_minima(mag[1], ok, int(ELBOW), rep, val, sw)
            note_minima(mag[2], ok, int(WRIST), rep, val, sw)
            fit_limits(
                path, ok, q_min, q_max, rep, val, windings[b, k], winding[b, k], low, high, offset
            )


@njit(cache=True, error_model="numpy")
def note_minima(
    mag: np.ndarray, ok: np.ndarray, kind: int, rep: np.ndarray, val: np.ndarray, switch: np.ndarray
) -> None:  # pragma: no cover - compiled
    """Kernel: note a switch of ``kind`` where a branch measure mag (M,) has a local minimum
    no larger than its change to a neighbour (it reaches about zero between the poses)."""
    for m in range(1, mag.shape[0] - 1):
        if not (ok[m - 1] and ok[m] and ok[m + 1]):
            continue
        left = mag[m - 1] - mag[m]
        right = mag[m + 1] - mag[m]
        if left >= 0.0 and right >= 0.0 and (left > 0.0 or right > 0.0):
            if mag[m] <= max(left, right):  # reaches ~0 between poses
                at = m + 1 if left > right else m
                note_switch(rep, val, switch, at, int(kind), int(NO_JOINT), 0.0)


@njit(cache=True, error_model="numpy")
def fit_limits(
    path: np.ndarray,
    ok: np.ndarray,
    q_min: np.ndarray,
    q_max: np.ndarray,
    rep: np.ndarray,
    val: np.ndarray,
    windings: np.ndarray,
    winding: np.ndarray,
    low: np.ndarray,
    high: np.ndarray,
    offset: np.ndarray,
) -> None:  # pragma: no cover - compiled
    """Kernel: shift each joint of a continuous path (M, n) in place by the multiple of 2π
    that centres it in the limits, count its windings (n,) and keep the one of largest
    margin, and complete the branch's report (margin, first pose outside, first problem).

    low and high (n,) are the smallest and largest joint values of the reached poses;
    offset (n,) is scratch.
    """
    n_poses, n = path.shape
    two_pi = 2.0 * math.pi
    margin = np.inf
    for j in range(n):
        centre = ((q_min[j] + q_max[j]) - (low[j] + high[j])) / (2.0 * two_pi)
        best = 0.0
        best_margin = -np.inf
        for up in range(2):
            shift = math.floor(centre) + up
            room = min(low[j] + two_pi * shift - q_min[j], q_max[j] - high[j] - two_pi * shift)
            if room > best_margin:
                best_margin = room
                best = shift
        offset[j] = two_pi * best
        margin = min(margin, best_margin)
        lowest = math.ceil((q_min[j] - low[j]) / two_pi)
        highest = math.floor((q_max[j] - high[j]) / two_pi)
        if highest >= lowest:
            windings[j] = highest - lowest + 1
            winding[j] = int(best) - lowest
    for m in range(n_poses):
        for j in range(n):
            path[m, j] += offset[j]
    val[F_MARGIN] = margin
    if margin < 0.0:
        for m in range(n_poses):
            if not ok[m]:
                continue
            for j in range(n):
                if path[m, j] < q_min[j] or path[m, j] > q_max[j]:
                    rep[I_LIMIT] = m
                    rep[I_LIMIT_JOINT] = j
                    val[F_VALUE] = path[m, j]
                    break
            if rep[I_LIMIT] >= 0:
                break
    first_problem = n_poses
    for index in (I_UNREACH, I_SWITCH, I_LIMIT):
        if rep[index] >= 0:
            first_problem = min(first_problem, rep[index])
    rep[I_FIRST] = first_problem if first_problem < n_poses else -1


NO_JOINT = -1
"""``joint`` of a switch that is not a joint's jump."""


@njit(cache=True, error_model="numpy")
def note_switch(
    rep: np.ndarray, val: np.ndarray, switch: np.ndarray, m: int, kind: int, joint: int, step: float
) -> None:  # pragma: no cover - compiled
    """Kernel: record a switch at pose m in one branch's report.

    Its callers pass ``kind`` and ``joint`` through ``int()`` (as :func:`note_minima`'s pass
    ``kind``): a constant argument would compile a version of it per value.
    """
    if not switch[m]:
        switch[m] = True
        rep[I_N_SWITCH] += 1
    first = rep[I_SWITCH]
    if first < 0 or m < first or (m == first and rep[I_KIND] == JUMP and kind != JUMP):
        rep[I_SWITCH] = m  # the earliest switch; at one pose a singularity explains a jump
        rep[I_KIND] = kind
        rep[I_JOINT] = joint
        val[F_STEP] = step
