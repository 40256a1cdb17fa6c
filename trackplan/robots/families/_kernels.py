"""Compiled kernels of the closed-form IK families (OPW and UR).

Each solver runs a batch of poses in chunks through three passes: a compiled pass writes
the arguments (Y, X) of every arctangent, numpy's SIMD ``arctan2`` evaluates them (about
8× faster than libm's scalar atan2, which dominates a scalar kernel), and a compiled pass
assembles the eight branches. The Python APIs are
:mod:`trackplan.robots.families.opw` and :mod:`trackplan.robots.families.ur`.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

N_BRANCHES = 8
AUX_SIZE = 5
REACH_TOL = 1e-12  # how far past a stretched arm or into the shoulder cylinder still counts
WRIST_SINGULAR = 1e-12  # |sin θ5| below which θ4 is set, not solved

# OPW geometry vector.
(O_A1, O_A2, O_B, O_C1, O_C2, O_C3, O_C4, O_KAPPA, O_CPSI, O_SPSI, O_PSI) = range(11)
O_BX, O_BY, O_C40, O_S40 = 11, 12, 13, 14
O_THETA0 = 15  # six zero offsets θ0 follow, then six signs
O_SIGN = 21
O_SIZE = 27
# OPW arctangent slots: θ1 per shoulder, φ = θ3 + ψ magnitude per shoulder, θ2 per arm
# a = 2·shoulder + elbow, then θ4, θ5, θ6 per arm.
O_TH1, O_PHI, O_TH2, O_WRIST = 0, 2, 4, 8
O_N_ANGLES = 20


@njit(cache=True, error_model="numpy", inline="always")
def unit(c: float, s: float) -> tuple[float, float]:  # pragma: no cover - compiled
    """(cos, sin) of the angle of the vector (c, s); (1, 0) for the zero vector."""
    norm = math.sqrt(c * c + s * s)
    if norm > 0.0:
        return c / norm, s / norm
    return 1.0, 0.0


@njit(cache=True, error_model="numpy", inline="always")
def wrap(x: float) -> float:  # pragma: no cover - compiled
    """Angle in (−π, π]."""
    if -math.pi < x <= math.pi:
        return x
    return x + 2.0 * math.pi * math.floor((math.pi - x) / (2.0 * math.pi))


@njit(cache=True, error_model="numpy", inline="always")
def _wrist_frame(T: np.ndarray, tail_inv: np.ndarray, w: np.ndarray) -> None:  # pragma: no cover
    """Kernel: ``w ← T · tail_inv`` (first three rows)."""
    for i in range(3):
        for j in range(4):
            w[i, j] = (
                T[i, 0] * tail_inv[0, j]
                + T[i, 1] * tail_inv[1, j]
                + T[i, 2] * tail_inv[2, j]
                + T[i, 3] * tail_inv[3, j]
            )


@njit(cache=True, error_model="numpy", inline="always")
def _zyz_arguments(
    r0: np.ndarray,
    r1: np.ndarray,
    r2: np.ndarray,
    w: np.ndarray,
    c40: float,
    s40: float,
    Y: np.ndarray,
    X: np.ndarray,
    slot: int,
) -> None:  # pragma: no cover - compiled
    """Kernel: arctangent arguments of θ4, θ5, θ6 with ``M = Rᵀ w = Rz(θ4) Ry(θ5) Rz(θ6)``.

    r0, r1, r2 are the columns of R (3,); w the target rotation (first 3 columns used).
    Where |sin θ5| is below :data:`WRIST_SINGULAR`, θ4 is set to the angle (c40, s40).
    """
    m00 = r0[0] * w[0, 0] + r0[1] * w[1, 0] + r0[2] * w[2, 0]
    m02 = r0[0] * w[0, 2] + r0[1] * w[1, 2] + r0[2] * w[2, 2]
    m10 = r1[0] * w[0, 0] + r1[1] * w[1, 0] + r1[2] * w[2, 0]
    m12 = r1[0] * w[0, 2] + r1[1] * w[1, 2] + r1[2] * w[2, 2]
    m20 = r2[0] * w[0, 0] + r2[1] * w[1, 0] + r2[2] * w[2, 0]
    m22 = r2[0] * w[0, 2] + r2[1] * w[1, 2] + r2[2] * w[2, 2]
    s5 = math.sqrt(m02 * m02 + m12 * m12)
    c5 = m22
    if s5 > WRIST_SINGULAR:
        c4 = m02 / s5
        s4 = m12 / s5
    else:
        c4 = c40
        s4 = s40
    # θ6 from Ry(−θ5) Rz(−θ4) M = Rz(θ6): exact for any θ4 once θ5 is exact.
    n00 = c4 * m00 + s4 * m10
    n10 = -s4 * m00 + c4 * m10
    Y[slot] = s4
    X[slot] = c4
    Y[slot + 1] = s5
    X[slot + 1] = c5
    Y[slot + 2] = n10
    X[slot + 2] = c5 * n00 - s5 * m20


@njit(cache=True, error_model="numpy", inline="always")
def _unreachable(
    Y: np.ndarray, X: np.ndarray, valid: np.ndarray, aux: np.ndarray, first: int, stop: int
) -> None:  # pragma: no cover - compiled
    """Kernel: mark branches first … stop − 1 of one pose unreachable (harmless arctangents)."""
    for j in range(Y.shape[0]):
        if first == 0 and stop == N_BRANCHES:
            Y[j] = 0.0
            X[j] = 1.0
    for br in range(first, stop):
        valid[br] = False
        for j in range(AUX_SIZE):
            aux[br, j] = np.nan


@njit(cache=True, error_model="numpy")
def opw_arguments(
    g: np.ndarray,
    tail_inv: np.ndarray,
    T: np.ndarray,
    Y: np.ndarray,
    X: np.ndarray,
    valid: np.ndarray,
    aux: np.ndarray,
) -> None:  # pragma: no cover - compiled
    """Kernel: OPW arctangent arguments (N, 20), reachability (N, 8), aux (N, 8, 5).

    An ``aux`` of shape (1, 8, 5) is scratch: the branch quantities are not kept.
    """
    a1 = g[O_A1]
    b = g[O_B]
    c1 = g[O_C1]
    c2 = g[O_C2]
    c4 = g[O_C4]
    kappa = g[O_KAPPA]
    cpsi = g[O_CPSI]
    spsi = g[O_SPSI]
    w = np.empty((3, 4))
    x3 = np.empty(3)
    y3 = np.empty(3)
    z3 = np.empty(3)
    for k in range(T.shape[0]):
        Yk = Y[k]
        Xk = X[k]
        _wrist_frame(T[k], tail_inv, w)
        cx = w[0, 3] - c4 * w[0, 2] - g[O_BX]
        cy = w[1, 3] - c4 * w[1, 2] - g[O_BY]
        cz = w[2, 3] - c4 * w[2, 2]
        r2 = cx * cx + cy * cy - b * b
        ak = aux[k if aux.shape[0] > 1 else 0]
        if r2 < -REACH_TOL:
            _unreachable(Yk, Xk, valid[k], ak, 0, N_BRANCHES)
            continue
        r = math.sqrt(max(r2, 0.0))
        for shoulder in range(2):
            xr = r if shoulder == 0 else -r
            c1_, s1_ = unit(cx * xr + cy * b, cy * xr - cx * b)
            Yk[O_TH1 + shoulder] = s1_
            Xk[O_TH1 + shoulder] = c1_
            dx = xr - a1
            dz = cz - c1
            K = (dx * dx + dz * dz - c2 * c2 - kappa * kappa) / (2.0 * c2 * kappa)
            if abs(K) > 1.0 + REACH_TOL:
                _unreachable(Yk, Xk, valid[k], ak, 4 * shoulder, 4 * shoulder + 4)
                continue
            K = min(max(K, -1.0), 1.0)
            sphi = math.sqrt((1.0 - K) * (1.0 + K))
            Yk[O_PHI + shoulder] = sphi
            Xk[O_PHI + shoulder] = K
            for elbow in range(2):
                arm = 2 * shoulder + elbow
                sg = 1.0 if shoulder == elbow else -1.0
                vx = c2 + kappa * K
                vy = kappa * sg * sphi
                c2_, s2_ = unit(dz * vx + dx * vy, dx * vx - dz * vy)
                Yk[O_TH2 + arm] = s2_
                Xk[O_TH2 + arm] = c2_
                c3_ = K * cpsi + sg * sphi * spsi
                s3_ = sg * sphi * cpsi - K * spsi
                c23 = c2_ * c3_ - s2_ * s3_
                s23 = s2_ * c3_ + c2_ * s3_
                # R_0_3 = Rz(θ1) Ry(θ2 + θ3), by columns.
                x3[0] = c1_ * c23
                x3[1] = s1_ * c23
                x3[2] = -s23
                y3[0] = -s1_
                y3[1] = c1_
                y3[2] = 0.0
                z3[0] = c1_ * s23
                z3[1] = s1_ * s23
                z3[2] = c23
                _zyz_arguments(x3, y3, z3, w, g[O_C40], g[O_S40], Yk, Xk, O_WRIST + 3 * arm)
                wx = z3[1] * w[2, 2] - z3[2] * w[1, 2]
                wy = z3[2] * w[0, 2] - z3[0] * w[2, 2]
                wz = z3[0] * w[1, 2] - z3[1] * w[0, 2]
                for flip in range(2):
                    br = 2 * arm + flip
                    valid[k, br] = True
                    ak[br, 0] = r
                    ak[br, 1] = sphi
                    ak[br, 2] = wx
                    ak[br, 3] = wy
                    ak[br, 4] = wz


@njit(cache=True, error_model="numpy")
def opw_assemble(
    g: np.ndarray, angles: np.ndarray, valid: np.ndarray, q: np.ndarray
) -> None:  # pragma: no cover - compiled
    """Kernel: joint angles q (N, 8, 6) of the eight OPW branches from the arctangents."""
    psi = g[O_PSI]
    t0 = g[O_THETA0 : O_THETA0 + 6]
    sg = g[O_SIGN : O_SIGN + 6]
    for k in range(angles.shape[0]):
        a = angles[k]
        for arm in range(4):
            shoulder = arm >> 1
            b0 = 2 * arm
            if not valid[k, b0]:
                for j in range(6):
                    q[k, b0, j] = np.nan
                    q[k, b0 + 1, j] = np.nan
                continue
            th1 = sg[0] * wrap(a[O_TH1 + shoulder] - t0[0])
            th2 = sg[1] * wrap(a[O_TH2 + arm] - t0[1])
            phi = a[O_PHI + shoulder]
            th3 = (phi if shoulder == (arm & 1) else -phi) - psi - t0[2]
            th3 = sg[2] * wrap(th3)
            slot = O_WRIST + 3 * arm
            th4 = a[slot] - t0[3]
            th5 = a[slot + 1]
            th6 = a[slot + 2] - t0[5]
            q[k, b0, 0] = th1
            q[k, b0, 1] = th2
            q[k, b0, 2] = th3
            q[k, b0, 3] = sg[3] * wrap(th4)
            q[k, b0, 4] = sg[4] * wrap(th5 - t0[4])
            q[k, b0, 5] = sg[5] * wrap(th6)
            q[k, b0 + 1, 0] = th1
            q[k, b0 + 1, 1] = th2
            q[k, b0 + 1, 2] = th3
            q[k, b0 + 1, 3] = sg[3] * wrap(th4 + math.pi)
            q[k, b0 + 1, 4] = sg[4] * wrap(-th5 - t0[4])
            q[k, b0 + 1, 5] = sg[5] * wrap(th6 + math.pi)


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


@njit(cache=True, error_model="numpy")
def ur_arguments(
    g: np.ndarray,
    tail_inv: np.ndarray,
    T: np.ndarray,
    Y: np.ndarray,
    X: np.ndarray,
    valid: np.ndarray,
    aux: np.ndarray,
) -> None:  # pragma: no cover - compiled
    """Kernel: UR arctangent arguments (N, 20), reachability (N, 8), aux (N, 8, 5) or
    (1, 8, 5) scratch."""
    d1 = g[U_D1]
    a2 = g[U_A2]
    a3 = g[U_A3]
    d4 = g[U_D4]
    d5 = g[U_D5]
    d6 = g[U_D6]
    w = np.empty((3, 4))
    for k in range(T.shape[0]):
        Yk = Y[k]
        Xk = X[k]
        ak = aux[k if aux.shape[0] > 1 else 0]
        _unreachable(Yk, Xk, valid[k], ak, 0, N_BRANCHES)
        _wrist_frame(T[k], tail_inv, w)
        px = w[0, 3] - d6 * w[0, 2] - g[U_BX]
        py = w[1, 3] - d6 * w[1, 2] - g[U_BY]
        pz = w[2, 3] - d6 * w[2, 2]
        rho2 = px * px + py * py - d4 * d4
        if rho2 < -REACH_TOL:
            continue
        r0 = math.sqrt(max(rho2, 0.0))
        for shoulder in range(2):
            r = r0 if shoulder == 0 else -r0
            c1, s1 = unit(px * r - py * d4, py * r + px * d4)
            Yk[U_TH1 + shoulder] = s1
            Xk[U_TH1 + shoulder] = c1
            # z1 = (s1, −c1, 0): the direction of the parallel axes 2, 3, 4; the wrist
            # vector z1 × z6 has the norm |sin θ5| (accurate near 0, unlike √(1 − c5²)).
            c5 = s1 * w[0, 2] - c1 * w[1, 2]
            wx = -c1 * w[2, 2]
            wy = -s1 * w[2, 2]
            wz = s1 * w[1, 2] + c1 * w[0, 2]
            s5 = math.sqrt(wx * wx + wy * wy + wz * wz)
            Yk[U_TH5 + shoulder] = s5
            Xk[U_TH5 + shoulder] = c5
            zx = s1 * w[0, 0] - c1 * w[1, 0]
            zy = s1 * w[0, 1] - c1 * w[1, 1]
            if s5 > WRIST_SINGULAR:
                c6, s6 = unit(zx, -zy)
            else:
                c6 = g[U_C60]
                s6 = g[U_S60]
            Yk[U_TH6 + shoulder] = s6
            Xk[U_TH6 + shoulder] = c6
            # x4 = c5 (c6 x6 − s6 y6) − s5 z6 for wrist 0 (it reverses for wrist 1).
            x4x = c5 * (c6 * w[0, 0] - s6 * w[0, 1]) - s5 * w[0, 2]
            x4y = c5 * (c6 * w[1, 0] - s6 * w[1, 1]) - s5 * w[1, 2]
            x4z = c5 * (c6 * w[2, 0] - s6 * w[2, 1]) - s5 * w[2, 2]
            Yk[U_TH234 + shoulder] = x4z
            Xk[U_TH234 + shoulder] = c1 * x4x + s1 * x4y
            for wrist in range(2):
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
                Yk[U_PHI + pair] = s3m
                Xk[U_PHI + pair] = c3
                for elbow in range(2):
                    s3 = s3m if elbow == 0 else -s3m
                    vx = a2 + a3 * c3
                    vy = a3 * s3
                    Yk[U_TH2 + 2 * pair + elbow] = v * vx - u * vy
                    Xk[U_TH2 + 2 * pair + elbow] = u * vx + v * vy
                    br = 4 * shoulder + 2 * elbow + wrist
                    valid[k, br] = True
                    ak[br, 0] = r0
                    ak[br, 1] = s3m
                    ak[br, 2] = wx
                    ak[br, 3] = wy
                    ak[br, 4] = wz


@njit(cache=True, error_model="numpy")
def ur_assemble(
    g: np.ndarray, angles: np.ndarray, valid: np.ndarray, q: np.ndarray
) -> None:  # pragma: no cover - compiled
    """Kernel: joint angles q (N, 8, 6) of the eight UR branches from the arctangents."""
    th0 = g[U_THETA0 : U_THETA0 + 6]
    sign = g[U_SIGN : U_SIGN + 6]
    theta = np.empty(6)
    for k in range(angles.shape[0]):
        a = angles[k]
        for br in range(N_BRANCHES):
            if not valid[k, br]:
                for j in range(6):
                    q[k, br, j] = np.nan
                continue
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
                q[k, br, j] = sign[j] * wrap(theta[j] - th0[j])
