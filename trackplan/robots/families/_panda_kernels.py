"""Compiled kernels of the Panda family's closed-form IK (joint 7 given).

:func:`panda_solve` works pose by pose: the arctangent arguments of the eight branches
(:func:`_panda_arguments`), their arctangents, the joints (:func:`_panda_joints`).
:func:`panda_solve_branch` runs the same operations for one branch only, reading rotations
and positions, and can hold missed poses and wind the joints near a reference
(:func:`~trackplan.robots.families._kernels.hold_and_wind`). The geometry and the branch
labels are described in :mod:`trackplan.robots.families.panda`, the Python API.

Per pose, with θ7 given, DH frame 6 is known (its origin O6 where axes 5 and 6 meet):

1. θ4 from the shoulder–wrist distance ``L = |O6 − p2|`` (p2: where axes 1, 2, 3 meet):
   ``A cos θ4 + B sin θ4 = L² − K``, two solutions (elbow bit).
2. θ6 from ``z5 · (O6 − p2) = c_z(θ4)`` with ``z5 = sin θ6 x6 + cos θ6 y6``, two solutions
   (wrist bit).
3. Frame 3 from the two vectors known in both frame 3 and the base (O6 − p2 and z5); θ1,
   θ2 from axis 3 (two solutions, shoulder bit), θ3 from x3, θ5 from x4 and x5.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from trackplan.robots.families._kernels import (
    AUX_SIZE,
    N_BRANCHES,
    REACH_TOL,
    WRIST_SINGULAR,
    atan2,
    atan2_all,
    hold_and_wind,
    unit,
    unreachable,
    wrap,
)

N_JOINTS = 7
# Panda geometry vector: the lengths, the base position, the θ4 equation's constants
# (K = a4² + a5² + d3² + d5², A = 2(a4 a5 + d3 d5), B = 2(d3 a5 − a4 d5), R = √(A² + B²)),
# cos and sin of θ1 where θ1 is not determined (q1 = 0), joint 7's sign and offset, then
# the offsets θ0 (7) and signs (7).
P_D1, P_D3, P_D5, P_A4, P_A5, P_A7, P_BX, P_BY = range(8)
P_K, P_A, P_B, P_R, P_C10, P_S10 = range(8, 14)
P_THETA0 = 14
P_SIGN = 21
P_SIZE = 28
# Arctangent slots: per elbow θ4; per (elbow, wrist) pair p = 2·elbow + wrist θ6 and the
# shoulder-0 θ1, θ2, θ3 and θ5 (shoulder 1 is (θ1 + π, −θ2, θ3 + π) with the same θ5).
S_TH4 = 0
S_TH6, S_TH1, S_TH2, S_TH3, S_TH5 = 2, 6, 10, 14, 18
S_N_ANGLES = 22


@njit(cache=True, error_model="numpy", inline="always")
def frame7(
    r00: float,
    r01: float,
    r02: float,
    px: float,
    r10: float,
    r11: float,
    r12: float,
    py: float,
    r20: float,
    r21: float,
    r22: float,
    pz: float,
    tail_inv: np.ndarray,
) -> tuple[float, ...]:  # pragma: no cover - compiled
    """The first three rows of ``[R p; 0 1] · tail_inv`` (DH frame 7 in the base), row by
    row (12 scalars)."""
    t = tail_inv
    return (
        r00 * t[0, 0] + r01 * t[1, 0] + r02 * t[2, 0],
        r00 * t[0, 1] + r01 * t[1, 1] + r02 * t[2, 1],
        r00 * t[0, 2] + r01 * t[1, 2] + r02 * t[2, 2],
        r00 * t[0, 3] + r01 * t[1, 3] + r02 * t[2, 3] + px,
        r10 * t[0, 0] + r11 * t[1, 0] + r12 * t[2, 0],
        r10 * t[0, 1] + r11 * t[1, 1] + r12 * t[2, 1],
        r10 * t[0, 2] + r11 * t[1, 2] + r12 * t[2, 2],
        r10 * t[0, 3] + r11 * t[1, 3] + r12 * t[2, 3] + py,
        r20 * t[0, 0] + r21 * t[1, 0] + r22 * t[2, 0],
        r20 * t[0, 1] + r21 * t[1, 1] + r22 * t[2, 1],
        r20 * t[0, 2] + r21 * t[1, 2] + r22 * t[2, 2],
        r20 * t[0, 3] + r21 * t[1, 3] + r22 * t[2, 3] + pz,
    )


@njit(cache=True, error_model="numpy", inline="always")
def _panda_arguments(
    g: np.ndarray,
    w: tuple[float, ...],
    free: float,
    Y: np.ndarray,
    X: np.ndarray,
    valid: np.ndarray,
    aux: np.ndarray,
    elbows: tuple[int, int],
    wrists: tuple[int, int],
) -> None:  # pragma: no cover - compiled
    """Kernel: one pose's Panda arctangent arguments (22,), reachability (8,), aux (8, 5).

    ``w`` is DH frame 7 in the base (:func:`frame7`), ``free`` joint 7's position (rad).
    Only the branches of elbows ``range(*elbows)`` and wrists ``range(*wrists)`` (both
    shoulders) are worked out; the slots of the others are left as they were.
    """
    d1 = g[P_D1]
    d3 = g[P_D3]
    d5 = g[P_D5]
    a4 = g[P_A4]
    a5 = g[P_A5]
    a7 = g[P_A7]
    ca = g[P_A]
    cb = g[P_B]
    cr = g[P_R]
    unreachable(valid, aux, 0, N_BRANCHES)
    w00, w01, w02, w03, w10, w11, w12, w13, w20, w21, w22, w23 = w
    theta7 = g[P_SIGN + 6] * free + g[P_THETA0 + 6]
    c7 = math.cos(theta7)
    s7 = math.sin(theta7)
    # Frame 6: x6 = c7 x7 − s7 y7, y6 = −z7, z6 = s7 x7 + c7 y7; O6 = O7 − a7 x6.
    x6x = c7 * w00 - s7 * w01
    x6y = c7 * w10 - s7 * w11
    x6z = c7 * w20 - s7 * w21
    y6x = -w02
    y6y = -w12
    y6z = -w22
    z6x = s7 * w00 + c7 * w01
    z6y = s7 * w10 + c7 * w11
    z6z = s7 * w20 + c7 * w21
    vx = w03 - a7 * x6x - g[P_BX]  # V = O6 − p2
    vy = w13 - a7 * x6y - g[P_BY]
    vz = w23 - a7 * x6z - d1
    l2 = vx * vx + vy * vy + vz * vz
    if not l2 > 0.0:
        return
    inv_l2 = 1.0 / l2
    inv_l = math.sqrt(inv_l2)
    v6x = vx * x6x + vy * x6y + vz * x6z
    v6y = vx * y6x + vy * y6y + vz * y6z
    rho2 = v6x * v6x + v6y * v6y
    cos4 = (l2 - g[P_K]) / cr  # cos(θ4 − φ4), φ4 = atan2(B, A)
    if abs(cos4) > 1.0 + REACH_TOL:
        return
    cos4 = min(max(cos4, -1.0), 1.0)
    sin4m = math.sqrt((1.0 - cos4) * (1.0 + cos4))
    for elbow in range(elbows[0], elbows[1]):
        sin4 = -sin4m if elbow == 0 else sin4m
        c4 = (ca * cos4 - cb * sin4) / cr
        s4 = (cb * cos4 + ca * sin4) / cr
        Y[S_TH4 + elbow] = s4
        X[S_TH4 + elbow] = c4
        # O6 − p2 = ux x3 + uz z3 and z5 = −s4 x3 + c4 z3 in frame 3.
        ux = a4 + a5 * c4 - d5 * s4
        uz = d3 + a5 * s4 + d5 * c4
        cz = -s4 * ux + c4 * uz  # z5 · (O6 − p2)
        dd = c4 * ux + s4 * uz  # (z5 × (O6 − p2)) · y3
        w2 = rho2 - cz * cz
        if w2 < -REACH_TOL * l2:
            continue
        wm = math.sqrt(max(w2, 0.0))
        # Wrist vector: ±(|rho² − cz²|^½ / L) z6, the sign of dd (it changes only where
        # the measure is zero, and there the path crosses the wrist singularity).
        scale = math.copysign(wm * inv_l, dd)
        for wrist in range(wrists[0], wrists[1]):
            tau = 1.0 if wrist == 0 else -1.0
            pair = 2 * elbow + wrist
            s6 = v6x * cz + tau * v6y * wm
            c6 = v6y * cz - tau * v6x * wm
            Y[S_TH6 + pair] = s6
            X[S_TH6 + pair] = c6
            c6n, s6n = unit(c6, s6)
            z5x = s6n * x6x + c6n * y6x
            z5y = s6n * x6y + c6n * y6y
            z5z = s6n * x6z + c6n * y6z
            x5x = c6n * x6x - s6n * y6x
            x5y = c6n * x6y - s6n * y6y
            x5z = c6n * x6z - s6n * y6z
            nx = z5y * vz - z5z * vy  # z5 × V = dd · y3
            ny = z5z * vx - z5x * vz
            nz = z5x * vy - z5y * vx
            nn = math.sqrt(nx * nx + ny * ny + nz * nz)
            if nn > WRIST_SINGULAR * math.sqrt(l2):
                f = math.copysign(1.0 / nn, dd)
                y3x = nx * f
                y3y = ny * f
                y3z = nz * f
            else:  # axis 5 through p2: frame 3 turns freely about it; take y3 = −x5
                y3x = -x5x
                y3y = -x5y
                y3z = -x5z
            ex = y3y * vz - y3z * vy  # y3 × V
            ey = y3z * vx - y3x * vz
            ez = y3x * vy - y3y * vx
            x3x = (ux * vx + uz * ex) * inv_l2
            x3y = (ux * vy + uz * ey) * inv_l2
            x3z = (ux * vz + uz * ez) * inv_l2
            z3x = (uz * vx - ux * ex) * inv_l2
            z3y = (uz * vy - ux * ey) * inv_l2
            z3z = (uz * vz - ux * ez) * inv_l2
            h = math.sqrt(z3x * z3x + z3y * z3y)  # |sin θ2|
            if h > WRIST_SINGULAR:
                c1 = z3x / h
                s1 = z3y / h
            else:  # axis 3 on axis 1: θ1 is put at q1 = 0 (shoulder 0)
                c1 = g[P_C10]
                s1 = g[P_S10]
            Y[S_TH1 + pair] = s1
            X[S_TH1 + pair] = c1
            Y[S_TH2 + pair] = h
            X[S_TH2 + pair] = z3z
            # x2 = (c1 c2, s1 c2, −s2), z2 = (−s1, c1, 0): θ3 from x3 = c3 x2 + s3 z2.
            Y[S_TH3 + pair] = -s1 * x3x + c1 * x3y
            X[S_TH3 + pair] = (c1 * x3x + s1 * x3y) * z3z - h * x3z
            # x4 = c4 x3 + s4 z3, z4 = −y3: θ5 from x5 = c5 x4 − s5 z4.
            x4x = c4 * x3x + s4 * z3x
            x4y = c4 * x3y + s4 * z3y
            x4z = c4 * x3z + s4 * z3z
            Y[S_TH5 + pair] = y3x * x5x + y3y * x5y + y3z * x5z
            X[S_TH5 + pair] = x4x * x5x + x4y * x5y + x4z * x5z
            for shoulder in range(2):
                br = 4 * shoulder + 2 * elbow + wrist
                valid[br] = True
                aux[br, 0] = h
                aux[br, 1] = sin4m
                aux[br, 2] = scale * z6x
                aux[br, 3] = scale * z6y
                aux[br, 4] = scale * z6z


@njit(cache=True, error_model="numpy", inline="always")
def _panda_joints(
    g: np.ndarray, a: np.ndarray, br: int, free: float, q: np.ndarray
) -> None:  # pragma: no cover - compiled
    """Kernel: the joint angles q (7,) of Panda branch ``br`` from the pose's arctangents
    a (22,) (the branch reaches the pose) and joint 7's position ``free``."""
    shoulder = (br >> 2) & 1
    elbow = (br >> 1) & 1
    wrist = br & 1
    pair = 2 * elbow + wrist
    flip = math.pi if shoulder == 1 else 0.0
    theta1 = a[S_TH1 + pair] + flip
    theta2 = -a[S_TH2 + pair] if shoulder == 1 else a[S_TH2 + pair]
    theta3 = a[S_TH3 + pair] + flip
    th0 = P_THETA0
    sg = P_SIGN
    q[0] = g[sg] * wrap(theta1 - g[th0])
    q[1] = g[sg + 1] * wrap(theta2 - g[th0 + 1])
    q[2] = g[sg + 2] * wrap(theta3 - g[th0 + 2])
    q[3] = g[sg + 3] * wrap(a[S_TH4 + elbow] - g[th0 + 3])
    q[4] = g[sg + 4] * wrap(a[S_TH5 + pair] - g[th0 + 4])
    q[5] = g[sg + 5] * wrap(a[S_TH6 + pair] - g[th0 + 5])
    q[6] = wrap(free)


@njit(cache=True, error_model="numpy", nogil=True)
def panda_solve(
    g: np.ndarray,
    tail_inv: np.ndarray,
    T: np.ndarray,
    free: np.ndarray,
    q: np.ndarray,
    valid: np.ndarray,
    aux: np.ndarray,
) -> None:  # pragma: no cover - compiled
    """Kernel: all eight Panda branches of poses T (N, 4, 4) with joint 7 at free (N,):
    q (N, 8, 7), valid (N, 8), aux (N, 8, 5); an ``aux`` of shape (1, 8, 5) is scratch
    (branch quantities not kept)."""
    Y = np.zeros(S_N_ANGLES)
    X = np.ones(S_N_ANGLES)
    angles = np.empty(S_N_ANGLES)
    for k in range(T.shape[0]):
        Tk = T[k]
        ak = aux[k if aux.shape[0] > 1 else 0]
        w = frame7(
            Tk[0, 0],
            Tk[0, 1],
            Tk[0, 2],
            Tk[0, 3],
            Tk[1, 0],
            Tk[1, 1],
            Tk[1, 2],
            Tk[1, 3],
            Tk[2, 0],
            Tk[2, 1],
            Tk[2, 2],
            Tk[2, 3],
            tail_inv,
        )
        vk = valid[k]
        _panda_arguments(g, w, free[k], Y, X, vk, ak, (0, 2), (0, 2))
        atan2_all(Y, X, angles)
        for br in range(N_BRANCHES):
            if vk[br]:
                _panda_joints(g, angles, br, free[k], q[k, br])
            else:
                for j in range(N_JOINTS):
                    q[k, br, j] = np.nan


@njit(cache=True, error_model="numpy")
def panda_solve_branch(
    g: np.ndarray,
    tail_inv: np.ndarray,
    R: np.ndarray,
    p: np.ndarray,
    free: np.ndarray,
    branch: int,
    q: np.ndarray,
    valid: np.ndarray,
    branch_aux: np.ndarray,
    s: np.ndarray,
    s_grid: np.ndarray,
    q_grid: np.ndarray,
) -> None:  # pragma: no cover - compiled
    """Kernel: Panda branch ``branch`` of poses with rotations R (N, 3, 3) (or one, (1, 3,
    3)), positions p (N, 3) and joint 7 at free (N,): q (N, 7), NaN where not valid (N,),
    and its branch quantities branch_aux (N, 5) (a ``branch_aux`` of shape (1, 5) is
    scratch); the same operations as :func:`panda_solve` on that branch alone (6
    arctangents a pose instead of 22). With a reference grid (s_grid (G,) not empty), the
    joints are then held and wound by :func:`hold_and_wind`.
    """
    elbow = (branch >> 1) & 1
    wrist = branch & 1
    pair = 2 * elbow + wrist
    keep = branch_aux.shape[0] > 1
    one_rotation = R.shape[0] == 1
    Y = np.zeros(S_N_ANGLES)
    X = np.ones(S_N_ANGLES)
    angles = np.zeros(S_N_ANGLES)
    ok = np.empty(N_BRANCHES, dtype=np.bool_)
    aux = np.empty((N_BRANCHES, AUX_SIZE))
    slots = (S_TH4 + elbow, S_TH6 + pair, S_TH1 + pair, S_TH2 + pair, S_TH3 + pair, S_TH5 + pair)
    for k in range(p.shape[0]):
        Rk = R[0 if one_rotation else k]
        w = frame7(
            Rk[0, 0],
            Rk[0, 1],
            Rk[0, 2],
            p[k, 0],
            Rk[1, 0],
            Rk[1, 1],
            Rk[1, 2],
            p[k, 1],
            Rk[2, 0],
            Rk[2, 1],
            Rk[2, 2],
            p[k, 2],
            tail_inv,
        )
        _panda_arguments(g, w, free[k], Y, X, ok, aux, (elbow, elbow + 1), (wrist, wrist + 1))
        row = k if keep else 0
        valid[k] = ok[branch]
        for j in range(AUX_SIZE):
            branch_aux[row, j] = aux[branch, j]
        if not ok[branch]:
            for j in range(N_JOINTS):
                q[k, j] = np.nan
            continue
        for e in slots:
            angles[e] = atan2(Y[e], X[e])
        _panda_joints(g, angles, branch, free[k], q[k])
    if s_grid.shape[0] > 0:
        hold_and_wind(q, valid, s, s_grid, q_grid)
