"""Compiled recursive Newton–Euler inverse dynamics over a generic serial chain.

Conventions are those of :mod:`trackplan.robots.dynamics_parameters`: joint i at
``T_parent_joint[i]`` in the child frame of joint i-1, turning about ``axis[i]``; link
inertials in the child frames. Every quantity of the recursion is kept in the child frame of
its link (Luh, Walker and Paul's "outward" form), so no world-frame transform is built.

Samples are processed in blocks of :data:`BLOCK`: each joint's step of the recursion runs over
the block's samples in a flat loop whose only memory is one joint segment of a work array at
compile-time offsets, which LLVM turns into SIMD code (4 samples per AVX2 instruction). Sine
and cosine use the fdlibm kernels after a Cody–Waite reduction (≤ 1 ulp from libm for
``|q| ≤ 1e5`` rad; libm beyond), so that they vectorise too. Per-robot constants (rotation
parts, first moments, inertias about the joint origins) are packed once, by
:func:`trackplan.robots.dynamics.rne.kernel_constants`, into the columns named below.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from trackplan.robots._kernels import REDUCTION_LIMIT, sincos

BLOCK = 32
"""Samples per block (16–64 measure alike; 32 was fastest on AVX2)."""

# Columns of the per-joint constant table (n, N_CONSTANTS).
ROT_FIXED = 0
"""9 columns: ``R_fixed · u uᵀ``, row-major.

``R(q) = ROT_FIXED + cos q · ROT_COS + sin q · ROT_SIN``.
"""
ROT_COS = 9
"""9 columns: ``R_fixed · (I − u uᵀ)``."""
ROT_SIN = 18
"""9 columns: ``R_fixed · [u]×``."""
ORIGIN = 27
"""3 columns: the joint's origin in the previous child frame, m."""
AXIS = 30
"""3 columns: the unit joint axis."""
MASS = 33
"""The link's mass, kg."""
MOMENT = 34
"""3 columns: first moment ``m c`` in the child frame, kg·m."""
INERTIA = 37
"""6 columns: inertia about the joint origin, ``Ixx, Iyy, Izz, Ixy, Iyz, Ixz``, kg·m²."""
ARMATURE = 43
"""``G² Jm``, kg·m²."""
VISCOUS = 44
"""``G² B``, N·m·s/rad."""
COULOMB_POS = 45
"""``|G| Tc+``, N·m."""
COULOMB_NEG = 46
"""``|G| Tc−``, N·m."""
N_CONSTANTS = 47

# Rows of a joint's segment of the work array, each BLOCK samples long.
_R = 0  # 9 rows: rotation of the child frame in the previous one, row-major
_F = 9  # 6 rows: the link's own wrench about its origin (force, moment)
_Q = 15  # q, q̇, q̈, cos q, sin q
_QD = 16
_QDD = 17
_COS = 18
_SIN = 19
_S = 20  # 9 rows: ω, ω̇, linear acceleration of the origin (gravity included), child frame
_W = 29  # 6 rows: wrench that this link and those after it need, at its origin
_TAU = 35
_ROWS = 36
SEGMENT = _ROWS * BLOCK


@njit(cache=True, nogil=True, fastmath={"contract"})
def _sincos(seg: np.ndarray) -> None:
    """Cosine and sine of a segment's ``q`` row into its cos and sin rows."""
    exotic = False
    for b in range(BLOCK):
        if not abs(seg[_Q * BLOCK + b]) <= REDUCTION_LIMIT:
            exotic = True
    if exotic:
        for b in range(BLOCK):
            seg[_COS * BLOCK + b] = np.cos(seg[_Q * BLOCK + b])
            seg[_SIN * BLOCK + b] = np.sin(seg[_Q * BLOCK + b])
        return
    for b in range(BLOCK):
        cos_q, sin_q = sincos(seg[_Q * BLOCK + b])
        seg[_COS * BLOCK + b] = cos_q
        seg[_SIN * BLOCK + b] = sin_q


@njit(cache=True, nogil=True, fastmath={"contract", "reassoc"})
def _forward(seg: np.ndarray, prev: np.ndarray, K: np.ndarray, i: int) -> None:
    """Joint i's outward step: its rotation, motion and the link's own wrench."""
    f00, f01, f02 = K[i, ROT_FIXED], K[i, ROT_FIXED + 1], K[i, ROT_FIXED + 2]
    f10, f11, f12 = K[i, ROT_FIXED + 3], K[i, ROT_FIXED + 4], K[i, ROT_FIXED + 5]
    f20, f21, f22 = K[i, ROT_FIXED + 6], K[i, ROT_FIXED + 7], K[i, ROT_FIXED + 8]
    c00, c01, c02 = K[i, ROT_COS], K[i, ROT_COS + 1], K[i, ROT_COS + 2]
    c10, c11, c12 = K[i, ROT_COS + 3], K[i, ROT_COS + 4], K[i, ROT_COS + 5]
    c20, c21, c22 = K[i, ROT_COS + 6], K[i, ROT_COS + 7], K[i, ROT_COS + 8]
    s00, s01, s02 = K[i, ROT_SIN], K[i, ROT_SIN + 1], K[i, ROT_SIN + 2]
    s10, s11, s12 = K[i, ROT_SIN + 3], K[i, ROT_SIN + 4], K[i, ROT_SIN + 5]
    s20, s21, s22 = K[i, ROT_SIN + 6], K[i, ROT_SIN + 7], K[i, ROT_SIN + 8]
    px, py, pz = K[i, ORIGIN], K[i, ORIGIN + 1], K[i, ORIGIN + 2]
    ux, uy, uz = K[i, AXIS], K[i, AXIS + 1], K[i, AXIS + 2]
    m = K[i, MASS]
    hx, hy, hz = K[i, MOMENT], K[i, MOMENT + 1], K[i, MOMENT + 2]
    Ixx, Iyy, Izz = K[i, INERTIA], K[i, INERTIA + 1], K[i, INERTIA + 2]
    Ixy, Iyz, Ixz = K[i, INERTIA + 3], K[i, INERTIA + 4], K[i, INERTIA + 5]
    for b in range(BLOCK):
        c = seg[_COS * BLOCK + b]
        s = seg[_SIN * BLOCK + b]
        r00 = f00 + c * c00 + s * s00
        r01 = f01 + c * c01 + s * s01
        r02 = f02 + c * c02 + s * s02
        r10 = f10 + c * c10 + s * s10
        r11 = f11 + c * c11 + s * s11
        r12 = f12 + c * c12 + s * s12
        r20 = f20 + c * c20 + s * s20
        r21 = f21 + c * c21 + s * s21
        r22 = f22 + c * c22 + s * s22
        seg[(_R + 0) * BLOCK + b] = r00
        seg[(_R + 1) * BLOCK + b] = r01
        seg[(_R + 2) * BLOCK + b] = r02
        seg[(_R + 3) * BLOCK + b] = r10
        seg[(_R + 4) * BLOCK + b] = r11
        seg[(_R + 5) * BLOCK + b] = r12
        seg[(_R + 6) * BLOCK + b] = r20
        seg[(_R + 7) * BLOCK + b] = r21
        seg[(_R + 8) * BLOCK + b] = r22
        w0 = prev[(_S + 0) * BLOCK + b]
        w1 = prev[(_S + 1) * BLOCK + b]
        w2 = prev[(_S + 2) * BLOCK + b]
        e0 = prev[(_S + 3) * BLOCK + b]
        e1 = prev[(_S + 4) * BLOCK + b]
        e2 = prev[(_S + 5) * BLOCK + b]
        # acceleration of this joint's origin, previous frame: a + ω̇ × p + ω × (ω × p)
        cx = w1 * pz - w2 * py
        cy = w2 * px - w0 * pz
        cz = w0 * py - w1 * px
        ax = prev[(_S + 6) * BLOCK + b] + e1 * pz - e2 * py + w1 * cz - w2 * cy
        ay = prev[(_S + 7) * BLOCK + b] + e2 * px - e0 * pz + w2 * cx - w0 * cz
        az = prev[(_S + 8) * BLOCK + b] + e0 * py - e1 * px + w0 * cy - w1 * cx
        # into the child frame: x_child = Rᵀ x_prev
        wx = r00 * w0 + r10 * w1 + r20 * w2
        wy = r01 * w0 + r11 * w1 + r21 * w2
        wz = r02 * w0 + r12 * w1 + r22 * w2
        ex = r00 * e0 + r10 * e1 + r20 * e2
        ey = r01 * e0 + r11 * e1 + r21 * e2
        ez = r02 * e0 + r12 * e1 + r22 * e2
        vx = r00 * ax + r10 * ay + r20 * az
        vy = r01 * ax + r11 * ay + r21 * az
        vz = r02 * ax + r12 * ay + r22 * az
        # ω̇_i = Rᵀ ω̇ + u q̈ + (Rᵀ ω) × u q̇;  ω_i = Rᵀ ω + u q̇
        dq = seg[_QD * BLOCK + b]
        ddq = seg[_QDD * BLOCK + b]
        ex += ux * ddq + (wy * uz - wz * uy) * dq
        ey += uy * ddq + (wz * ux - wx * uz) * dq
        ez += uz * ddq + (wx * uy - wy * ux) * dq
        wx += ux * dq
        wy += uy * dq
        wz += uz * dq
        seg[(_S + 0) * BLOCK + b] = wx
        seg[(_S + 1) * BLOCK + b] = wy
        seg[(_S + 2) * BLOCK + b] = wz
        seg[(_S + 3) * BLOCK + b] = ex
        seg[(_S + 4) * BLOCK + b] = ey
        seg[(_S + 5) * BLOCK + b] = ez
        seg[(_S + 6) * BLOCK + b] = vx
        seg[(_S + 7) * BLOCK + b] = vy
        seg[(_S + 8) * BLOCK + b] = vz
        # the link's wrench at its origin: f = m a + ω̇ × h + ω × (ω × h),
        # n = I_o ω̇ + ω × (I_o ω) + h × a, with h = m c the first moment
        cx = wy * hz - wz * hy
        cy = wz * hx - wx * hz
        cz = wx * hy - wy * hx
        seg[(_F + 0) * BLOCK + b] = m * vx + ey * hz - ez * hy + wy * cz - wz * cy
        seg[(_F + 1) * BLOCK + b] = m * vy + ez * hx - ex * hz + wz * cx - wx * cz
        seg[(_F + 2) * BLOCK + b] = m * vz + ex * hy - ey * hx + wx * cy - wy * cx
        Lx = Ixx * wx + Ixy * wy + Ixz * wz
        Ly = Ixy * wx + Iyy * wy + Iyz * wz
        Lz = Ixz * wx + Iyz * wy + Izz * wz
        seg[(_F + 3) * BLOCK + b] = (
            Ixx * ex + Ixy * ey + Ixz * ez + wy * Lz - wz * Ly + hy * vz - hz * vy
        )
        seg[(_F + 4) * BLOCK + b] = (
            Ixy * ex + Iyy * ey + Iyz * ez + wz * Lx - wx * Lz + hz * vx - hx * vz
        )
        seg[(_F + 5) * BLOCK + b] = (
            Ixz * ex + Iyz * ey + Izz * ez + wx * Ly - wy * Lx + hx * vy - hy * vx
        )


@njit(cache=True, nogil=True, fastmath={"contract", "reassoc"})
def _backward(seg: np.ndarray, after: np.ndarray, K: np.ndarray, i: int) -> None:
    """Joint i's inward step below the last joint: the wrench from link i outward (its own
    and the next link's), and the joint torque."""
    # the next link's wrench into this frame, moment carried to this origin
    px, py, pz = K[i + 1, ORIGIN], K[i + 1, ORIGIN + 1], K[i + 1, ORIGIN + 2]
    for b in range(BLOCK):
        r00 = after[(_R + 0) * BLOCK + b]
        r01 = after[(_R + 1) * BLOCK + b]
        r02 = after[(_R + 2) * BLOCK + b]
        r10 = after[(_R + 3) * BLOCK + b]
        r11 = after[(_R + 4) * BLOCK + b]
        r12 = after[(_R + 5) * BLOCK + b]
        r20 = after[(_R + 6) * BLOCK + b]
        r21 = after[(_R + 7) * BLOCK + b]
        r22 = after[(_R + 8) * BLOCK + b]
        f0 = after[(_W + 0) * BLOCK + b]
        f1 = after[(_W + 1) * BLOCK + b]
        f2 = after[(_W + 2) * BLOCK + b]
        t0 = after[(_W + 3) * BLOCK + b]
        t1 = after[(_W + 4) * BLOCK + b]
        t2 = after[(_W + 5) * BLOCK + b]
        gx = r00 * f0 + r01 * f1 + r02 * f2
        gy = r10 * f0 + r11 * f1 + r12 * f2
        gz = r20 * f0 + r21 * f1 + r22 * f2
        seg[(_W + 0) * BLOCK + b] = seg[(_F + 0) * BLOCK + b] + gx
        seg[(_W + 1) * BLOCK + b] = seg[(_F + 1) * BLOCK + b] + gy
        seg[(_W + 2) * BLOCK + b] = seg[(_F + 2) * BLOCK + b] + gz
        seg[(_W + 3) * BLOCK + b] = (
            seg[(_F + 3) * BLOCK + b] + r00 * t0 + r01 * t1 + r02 * t2 + py * gz - pz * gy
        )
        seg[(_W + 4) * BLOCK + b] = (
            seg[(_F + 4) * BLOCK + b] + r10 * t0 + r11 * t1 + r12 * t2 + pz * gx - px * gz
        )
        seg[(_W + 5) * BLOCK + b] = (
            seg[(_F + 5) * BLOCK + b] + r20 * t0 + r21 * t1 + r22 * t2 + px * gy - py * gx
        )
    _joint_torque(seg, K, i)


@njit(cache=True, nogil=True, fastmath={"contract", "reassoc"})
def _joint_torque(seg: np.ndarray, K: np.ndarray, i: int) -> None:
    """Joint i's torque from the wrench at its origin, with armature and friction."""
    ux, uy, uz = K[i, AXIS], K[i, AXIS + 1], K[i, AXIS + 2]
    armature, viscous = K[i, ARMATURE], K[i, VISCOUS]
    coulomb_pos, coulomb_neg = K[i, COULOMB_POS], K[i, COULOMB_NEG]
    for b in range(BLOCK):
        dq = seg[_QD * BLOCK + b]
        coulomb = coulomb_pos if dq > 0.0 else (coulomb_neg if dq < 0.0 else 0.0)
        seg[_TAU * BLOCK + b] = (
            ux * seg[(_W + 3) * BLOCK + b]
            + uy * seg[(_W + 4) * BLOCK + b]
            + uz * seg[(_W + 5) * BLOCK + b]
            + armature * seg[_QDD * BLOCK + b]
            + viscous * dq
            + coulomb
        )


@njit(cache=True, nogil=True)
def rne_kernel(
    K: np.ndarray,
    gravity: np.ndarray,
    q: np.ndarray,
    qd: np.ndarray,
    qdd: np.ndarray,
    out: np.ndarray,
) -> None:
    """Joint torques ``τ = RNE(q, q̇, q̈) + armature·q̈ + viscous·q̇ + Coulomb(q̇)``.

    Parameters
    ----------
    K
        Per-joint constants, shape (n, :data:`N_CONSTANTS`), columns as named in this module.
    gravity
        Gravity in the base frame, shape (3,), m/s².
    q, qd, qdd
        Joint states, shape (N, n), rad, rad/s, rad/s².
    out
        Torques, shape (N, n), N·m (written).
    """
    n_samples, n = q.shape
    work = np.zeros((n + 1, SEGMENT))  # segment 0: the base at rest, accelerating against g
    for b in range(BLOCK):
        for a in range(3):
            work[0, (_S + 6 + a) * BLOCK + b] = -gravity[a]
    for start in range(0, n_samples, BLOCK):
        m = min(BLOCK, n_samples - start)
        for i in range(n):
            seg = work[i + 1]
            for b in range(m):
                seg[_Q * BLOCK + b] = q[start + b, i]
                seg[_QD * BLOCK + b] = qd[start + b, i]
                seg[_QDD * BLOCK + b] = qdd[start + b, i]
            for b in range(m, BLOCK):  # padding of the last block
                seg[_Q * BLOCK + b] = 0.0
                seg[_QD * BLOCK + b] = 0.0
                seg[_QDD * BLOCK + b] = 0.0
            _sincos(seg)
        for i in range(n):
            _forward(work[i + 1], work[i], K, i)
        last = work[n]  # the last link's wrench is its own
        for k in range(6):
            for b in range(BLOCK):
                last[(_W + k) * BLOCK + b] = last[(_F + k) * BLOCK + b]
        _joint_torque(last, K, n - 1)
        for i in range(n - 2, -1, -1):
            _backward(work[i + 1], work[i + 2], K, i)
        for b in range(m):
            for i in range(n):
                out[start + b, i] = work[i + 1, _TAU * BLOCK + b]
