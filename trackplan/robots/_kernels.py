"""Compiled kernels of chain kinematics: forward kinematics and the frames of every link.

The Python API is :mod:`trackplan.robots.kinematics`; the numerical IK
(:mod:`trackplan.robots._ik_kernels`), the planner's kernels and the dynamics build on
:func:`chain_block`, :func:`chain_step` and :func:`sincos`. A chain is given in the layout of
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
