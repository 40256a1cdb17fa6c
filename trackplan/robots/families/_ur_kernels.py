"""Compiled kernels of the UR family's closed-form IK.

:func:`ur_solve` works pose by pose: the arctangent arguments of the eight branches
(:func:`_ur_arguments`), their arctangents, the joints (:func:`_ur_assemble`).
:func:`ur_solve_branch` runs the same operations for one branch only, reading rotations
and positions, and can hold missed poses and wind the joints near a reference
(:func:`~trackplan.robots.families._kernels.hold_and_wind`). The Python API is
:mod:`trackplan.robots.families.ur`.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from trackplan.robots.families._kernels import (
    AUX_SIZE,
    BLOCK,
    N_BRANCHES,
    REACH_TOL,
    WRIST_SINGULAR,
    atan2,
    atan2_all,
    hold_and_wind,
    unit,
    unreachable,
    wrap,
    wrist_entry,
    wrist_frame,
)

# UR geometry vector.
U_D1, U_A2, U_A3, U_D4, U_D5, U_D6, U_BX, U_BY, U_C60, U_S60 = range(10)
U_THETA0 = 10
U_SIGN = 16
U_SIZE = 22
# UR arctangent slots: per shoulder θ1, θ5, θ6, θ2+θ3+θ4 (wrist 0); per (shoulder, wrist)
# pair p = 2·shoulder + wrist the elbow magnitude |θ3| and θ2 of elbow 0 and 1.
U_TH1, U_TH5, U_TH6, U_TH234 = 0, 2, 4, 6
U_PHI, U_TH2 = 8, 12
U_N_ANGLES = 20


@njit(cache=True, error_model="numpy", inline="always")
def _ur_arguments(
    g: np.ndarray,
    tail_inv: np.ndarray,
    T: np.ndarray,
    Y: np.ndarray,
    X: np.ndarray,
    valid: np.ndarray,
    aux: np.ndarray,
    shoulders: tuple[int, int],
    wrists: tuple[int, int],
    elbows: tuple[int, int],
) -> None:  # pragma: no cover - compiled
    """Kernel: one pose's UR arctangent arguments (20,), reachability (8,), aux (8, 5).

    T is the pose (4, 4). Only the branches of shoulders ``range(*shoulders)``, wrists
    ``range(*wrists)`` and elbows ``range(*elbows)`` are worked out (all eight: ``(0, 2)``
    each); the slots of the others are left as they were.
    """
    d1 = g[U_D1]
    a2 = g[U_A2]
    a3 = g[U_A3]
    d4 = g[U_D4]
    d5 = g[U_D5]
    d6 = g[U_D6]
    unreachable(valid, aux, 0, N_BRANCHES)
    w00, w01, w02, w03, w10, w11, w12, w13, w20, w21, w22, w23 = wrist_frame(T, tail_inv)
    px = w03 - d6 * w02 - g[U_BX]
    py = w13 - d6 * w12 - g[U_BY]
    pz = w23 - d6 * w22
    rho2 = px * px + py * py - d4 * d4
    if rho2 < -REACH_TOL:
        return
    r0 = math.sqrt(max(rho2, 0.0))
    for shoulder in range(shoulders[0], shoulders[1]):
        r = r0 if shoulder == 0 else -r0
        c1, s1 = unit(px * r - py * d4, py * r + px * d4)
        Y[U_TH1 + shoulder] = s1
        X[U_TH1 + shoulder] = c1
        # z1 = (s1, −c1, 0): the direction of the parallel axes 2, 3, 4; the wrist
        # vector z1 × z6 has the norm |sin θ5| (accurate near 0, unlike √(1 − c5²)).
        c5 = s1 * w02 - c1 * w12
        wx = -c1 * w22
        wy = -s1 * w22
        wz = s1 * w12 + c1 * w02
        s5 = math.sqrt(wx * wx + wy * wy + wz * wz)
        Y[U_TH5 + shoulder] = s5
        X[U_TH5 + shoulder] = c5
        zx = s1 * w00 - c1 * w10
        zy = s1 * w01 - c1 * w11
        if s5 > WRIST_SINGULAR:
            c6, s6 = unit(zx, -zy)
        else:
            c6 = g[U_C60]
            s6 = g[U_S60]
        Y[U_TH6 + shoulder] = s6
        X[U_TH6 + shoulder] = c6
        # x4 = c5 (c6 x6 − s6 y6) − s5 z6 for wrist 0 (it reverses for wrist 1).
        x4x = c5 * (c6 * w00 - s6 * w01) - s5 * w02
        x4y = c5 * (c6 * w10 - s6 * w11) - s5 * w12
        x4z = c5 * (c6 * w20 - s6 * w21) - s5 * w22
        Y[U_TH234 + shoulder] = x4z
        X[U_TH234 + shoulder] = c1 * x4x + s1 * x4y
        for wrist in range(wrists[0], wrists[1]):
            sgn = 1.0 if wrist == 0 else -1.0
            # z4 = x4 × z1 with z1 = (s1, −c1, 0); O4 = P05 − d5 z4.
            z4x = sgn * (x4z * c1)
            z4y = sgn * (x4z * s1)
            z4z = sgn * (-x4x * c1 - x4y * s1)
            ox = px - d5 * z4x
            oy = py - d5 * z4y
            oz = pz - d5 * z4z
            u = c1 * ox + s1 * oy
            v = oz - d1
            c3 = (u * u + v * v - a2 * a2 - a3 * a3) / (2.0 * a2 * a3)
            if abs(c3) > 1.0 + REACH_TOL:
                continue
            c3 = min(max(c3, -1.0), 1.0)
            s3m = math.sqrt((1.0 - c3) * (1.0 + c3))
            pair = 2 * shoulder + wrist
            Y[U_PHI + pair] = s3m
            X[U_PHI + pair] = c3
            for elbow in range(elbows[0], elbows[1]):
                s3 = s3m if elbow == 0 else -s3m
                vx = a2 + a3 * c3
                vy = a3 * s3
                Y[U_TH2 + 2 * pair + elbow] = v * vx - u * vy
                X[U_TH2 + 2 * pair + elbow] = u * vx + v * vy
                br = 4 * shoulder + 2 * elbow + wrist
                valid[br] = True
                aux[br, 0] = r0
                aux[br, 1] = s3m
                aux[br, 2] = wx
                aux[br, 3] = wy
                aux[br, 4] = wz


@njit(cache=True, error_model="numpy", inline="always")
def _ur_joints(
    g: np.ndarray, a: np.ndarray, br: int, q: np.ndarray, theta: np.ndarray
) -> None:  # pragma: no cover - compiled
    """Kernel: the joint angles q (6,) of UR branch ``br`` from the pose's arctangents
    a (20,) (the branch reaches the pose); theta (6,) is scratch."""
    th0 = g[U_THETA0 : U_THETA0 + 6]
    sign = g[U_SIGN : U_SIGN + 6]
    shoulder = (br >> 2) & 1
    elbow = (br >> 1) & 1
    wrist = br & 1
    pair = 2 * shoulder + wrist
    flip = math.pi if wrist == 1 else 0.0
    theta[0] = a[U_TH1 + shoulder]
    theta[1] = a[U_TH2 + 2 * pair + elbow]
    theta[2] = a[U_PHI + pair] if elbow == 0 else -a[U_PHI + pair]
    theta[3] = a[U_TH234 + shoulder] + flip - theta[1] - theta[2]
    theta[4] = a[U_TH5 + shoulder] if wrist == 0 else -a[U_TH5 + shoulder]
    theta[5] = a[U_TH6 + shoulder] + flip
    for j in range(6):
        q[j] = sign[j] * wrap(theta[j] - th0[j])


@njit(cache=True, error_model="numpy", inline="always")
def _ur_assemble(
    g: np.ndarray, a: np.ndarray, valid: np.ndarray, q: np.ndarray, theta: np.ndarray
) -> None:  # pragma: no cover - compiled
    """Kernel: one pose's joint angles q (8, 6) of the eight UR branches from its
    arctangents a (20,); theta (6,) is scratch."""
    for br in range(N_BRANCHES):
        if not valid[br]:
            for j in range(6):
                q[br, j] = np.nan
            continue
        _ur_joints(g, a, br, q[br], theta)


@njit(cache=True, error_model="numpy", nogil=True)
def ur_solve(
    g: np.ndarray,
    tail_inv: np.ndarray,
    T: np.ndarray,
    q: np.ndarray,
    valid: np.ndarray,
    aux: np.ndarray,
) -> None:  # pragma: no cover - compiled
    """Kernel: all eight UR branches of poses T (N, 4, 4): q (N, 8, 6), valid (N, 8),
    aux (N, 8, 5); an ``aux`` of shape (1, 8, 5) is scratch (branch quantities not kept)."""
    theta = np.empty(6)
    Y = np.zeros(U_N_ANGLES)
    X = np.ones(U_N_ANGLES)
    angles = np.empty(U_N_ANGLES)
    for k in range(T.shape[0]):
        ak = aux[k if aux.shape[0] > 1 else 0]
        _ur_arguments(g, tail_inv, T[k], Y, X, valid[k], ak, (0, 2), (0, 2), (0, 2))
        atan2_all(Y, X, angles)
        _ur_assemble(g, angles, valid[k], q[k], theta)


@njit(cache=True, error_model="numpy")
def ur_solve_branch(
    g: np.ndarray,
    tail_inv: np.ndarray,
    R: np.ndarray,
    p: np.ndarray,
    branch: int,
    q: np.ndarray,
    valid: np.ndarray,
    branch_aux: np.ndarray,
    s: np.ndarray,
    s_grid: np.ndarray,
    q_grid: np.ndarray,
) -> None:  # pragma: no cover - compiled
    """Kernel: UR branch ``branch`` of poses with rotations R (N, 3, 3) (or one, (1, 3,
    3)) and positions p (N, 3): q (N, 6), NaN where not valid (N,), and its branch
    quantities branch_aux (N, 5) (a ``branch_aux`` of shape (1, 5) is scratch); the same
    operations as :func:`ur_solve` on that branch alone. With a reference grid (s_grid
    (G,) not empty), the joints are then held and wound by :func:`hold_and_wind`.

    Blocks of :data:`BLOCK` poses in three flat passes, as :func:`opw_solve_branch`: the
    expressions of :func:`_ur_arguments` for one shoulder, wrist and elbow, the
    arctangents, the joints.
    """
    d1 = g[U_D1]
    a2 = g[U_A2]
    a3 = g[U_A3]
    d4 = g[U_D4]
    d5 = g[U_D5]
    d6 = g[U_D6]
    bx = g[U_BX]
    by = g[U_BY]
    c60 = g[U_C60]
    s60 = g[U_S60]
    shoulder = (branch >> 2) & 1
    elbow = (branch >> 1) & 1
    wrist = branch & 1
    pair = 2 * shoulder + wrist
    r_sign = 1.0 if shoulder == 0 else -1.0
    sgn = 1.0 if wrist == 0 else -1.0
    s3_sign = 1.0 if elbow == 0 else -1.0
    keep = branch_aux.shape[0] > 1
    n_poses = p.shape[0]
    one_rotation = R.shape[0] == 1
    P = np.zeros((12, BLOCK))
    Y = np.zeros((6, BLOCK))  # θ1, θ5, θ6, θ2+θ3+θ4, |θ3|, θ2 arguments
    X = np.ones((6, BLOCK))
    A = np.empty((6, BLOCK))
    aux = np.empty((AUX_SIZE, BLOCK))
    ok = np.empty(BLOCK, dtype=np.bool_)
    theta = np.empty(6)
    angles = np.empty(U_N_ANGLES)
    slots = (
        U_TH1 + shoulder,
        U_TH5 + shoulder,
        U_TH6 + shoulder,
        U_TH234 + shoulder,
        U_PHI + pair,
        U_TH2 + 2 * pair + elbow,
    )
    for start in range(0, n_poses, BLOCK):
        m = min(BLOCK, n_poses - start)
        for b in range(m):
            Rk = R[0 if one_rotation else start + b]
            for i in range(3):
                for c in range(3):
                    P[4 * i + c, b] = Rk[i, c]
                P[4 * i + 3, b] = p[start + b, i]
        for b in range(BLOCK):
            w00 = wrist_entry(P, b, 0, 0, tail_inv)
            w01 = wrist_entry(P, b, 0, 1, tail_inv)
            w02 = wrist_entry(P, b, 0, 2, tail_inv)
            w03 = wrist_entry(P, b, 0, 3, tail_inv)
            w10 = wrist_entry(P, b, 1, 0, tail_inv)
            w11 = wrist_entry(P, b, 1, 1, tail_inv)
            w12 = wrist_entry(P, b, 1, 2, tail_inv)
            w13 = wrist_entry(P, b, 1, 3, tail_inv)
            w20 = wrist_entry(P, b, 2, 0, tail_inv)
            w21 = wrist_entry(P, b, 2, 1, tail_inv)
            w22 = wrist_entry(P, b, 2, 2, tail_inv)
            w23 = wrist_entry(P, b, 2, 3, tail_inv)
            px = w03 - d6 * w02 - bx
            py = w13 - d6 * w12 - by
            pz = w23 - d6 * w22
            rho2 = px * px + py * py - d4 * d4
            r0 = math.sqrt(max(rho2, 0.0))
            r = r_sign * r0
            c1, s1 = unit(px * r - py * d4, py * r + px * d4)
            c5 = s1 * w02 - c1 * w12
            wx = -c1 * w22
            wy = -s1 * w22
            wz = s1 * w12 + c1 * w02
            s5 = math.sqrt(wx * wx + wy * wy + wz * wz)
            zx = s1 * w00 - c1 * w10
            zy = s1 * w01 - c1 * w11
            c6u, s6u = unit(zx, -zy)
            singular = not s5 > WRIST_SINGULAR
            c6 = c60 if singular else c6u
            s6 = s60 if singular else s6u
            x4x = c5 * (c6 * w00 - s6 * w01) - s5 * w02
            x4y = c5 * (c6 * w10 - s6 * w11) - s5 * w12
            x4z = c5 * (c6 * w20 - s6 * w21) - s5 * w22
            z4x = sgn * (x4z * c1)
            z4y = sgn * (x4z * s1)
            z4z = sgn * (-x4x * c1 - x4y * s1)
            ox = px - d5 * z4x
            oy = py - d5 * z4y
            oz = pz - d5 * z4z
            u = c1 * ox + s1 * oy
            v = oz - d1
            c3 = (u * u + v * v - a2 * a2 - a3 * a3) / (2.0 * a2 * a3)
            ok[b] = not (rho2 < -REACH_TOL or abs(c3) > 1.0 + REACH_TOL)
            c3 = min(max(c3, -1.0), 1.0)
            s3m = math.sqrt((1.0 - c3) * (1.0 + c3))
            s3 = s3_sign * s3m
            vx = a2 + a3 * c3
            vy = a3 * s3
            Y[0, b] = s1
            X[0, b] = c1
            Y[1, b] = s5
            X[1, b] = c5
            Y[2, b] = s6
            X[2, b] = c6
            Y[3, b] = x4z
            X[3, b] = c1 * x4x + s1 * x4y
            Y[4, b] = s3m
            X[4, b] = c3
            Y[5, b] = v * vx - u * vy
            X[5, b] = u * vx + v * vy
            aux[0, b] = r0
            aux[1, b] = s3m
            aux[2, b] = wx
            aux[3, b] = wy
            aux[4, b] = wz
        for e in range(6):
            for b in range(BLOCK):
                A[e, b] = atan2(Y[e, b], X[e, b])
        for b in range(m):
            k = start + b
            row = k if keep else 0
            valid[k] = ok[b]
            if not ok[b]:
                for j in range(AUX_SIZE):
                    branch_aux[row, j] = np.nan
                for j in range(6):
                    q[k, j] = np.nan
                continue
            for j in range(AUX_SIZE):
                branch_aux[row, j] = aux[j, b]
            for e in range(6):
                angles[slots[e]] = A[e, b]
            _ur_joints(g, angles, branch, q[k], theta)
    if s_grid.shape[0] > 0:
        hold_and_wind(q, valid, s, s_grid, q_grid)
