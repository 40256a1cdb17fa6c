"""Compiled kernels of the S-R-S family's closed-form IK (arm angle ψ given per pose).

The equations (:mod:`trackplan.robots.families.srs`) are written once, as scalar helpers
that both kernels inline: :func:`srs_centre` (the wrist centre relative to the shoulder,
the elbow angle's cosine and the reference plane), :func:`srs_arm` (the arctangent
arguments of one elbow sign at the pose's arm angle) and :func:`srs_joints` (the seven
joints of a branch from the arctangents). :func:`srs_solve` writes the eight branches of
each pose; :func:`srs_solve_branch` runs the same operations for one branch only and can
hold missed poses and wind the joints near a reference
(:func:`~trackplan.robots.families._kernels.hold_and_wind`). Both work on blocks of
:data:`~trackplan.robots.families._kernels.BLOCK` poses in three flat passes that
vectorise: the arctangent arguments, the arctangents, the joints.

Per pose: 13 arctangents for the eight branches (θ4 once; θ1, θ2, θ3, θ5, θ6, θ7 per
elbow sign; the shoulder and wrist flips ``(θ + π, −θ, θ + π)`` need none), 7 for one.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from trackplan.robots._kernels import sincos
from trackplan.robots.families._kernels import (
    AUX_SIZE,
    BLOCK,
    N_BRANCHES,
    REACH_TOL,
    WRIST_SINGULAR,
    atan2,
    hold_and_wind,
    unit,
    wrap,
    wrist_entry,
)

# S-R-S geometry vector: the four lengths, the base shift, d_se², d_ew², 2·d_se·d_ew,
# (cos, sin) of θ1 and θ5 at q = 0 (the shoulder and wrist singularities), θ0, signs.
(S_DBS, S_DSE, S_DEW, S_DWF, S_BX, S_BY, S_DSE2, S_DEW2, S_2DD) = range(9)
S_C10, S_S10, S_C50, S_S50 = 9, 10, 11, 12
S_THETA0 = 13  # seven zero offsets θ0 follow, then seven signs
S_SIGN = 20
S_SIZE = 27
N_JOINTS = 7
N_ARGS = 6  # arctangents per elbow sign: θ1, θ2, θ3, θ5, θ6, θ7
PSI_LIMIT = 1.0e5
"""rad: arm angles beyond it (or NaN) reach no pose (the compiled sine's reduction limit)."""

SRSGeometry = tuple[float, float, float, float, float, float, float, float, float]
"""(d_bs, d_se, d_ew, d_wf, bx, by, d_se², d_ew², 2·d_se·d_ew)."""


@njit(cache=True, error_model="numpy", inline="always")
def srs_geometry(g: np.ndarray) -> SRSGeometry:  # pragma: no cover - compiled
    """The arm equations' scalars of the geometry vector g (:data:`S_SIZE`,)."""
    return (
        g[S_DBS], g[S_DSE], g[S_DEW], g[S_DWF], g[S_BX], g[S_BY],
        g[S_DSE2], g[S_DEW2], g[S_2DD],
    )  # fmt: skip


@njit(cache=True, error_model="numpy", inline="always")
def srs_centre(
    geo: SRSGeometry, w02: float, w03: float, w12: float, w13: float, w22: float, w23: float
) -> tuple[bool, float, float, float, float, float, float, float, float, float]:  # pragma: no cover
    """The pose's arm quantities common to all branches.

    From the wrist frame ``T · tail_inv`` (its entries w_rc): the shoulder→wrist unit
    vector u, the elbow's (cos θ4, |sin θ4|) clipped to the circle, (cos α, sin α) of
    the angle α ≥ 0 between the upper arm and u, and the reference plane's normal b°
    (horizontal, ⊥ u: the elbow axis of the arm with θ3 = 0) as (cos θ1°, sin θ1°).

    Returns
    -------
    tuple
        (reached, ux, uy, uz, c4, s4m, cα, sα, c1r, s1r): ``reached`` is False
        when the wrist centre is out of the arm's annulus by more than
        :data:`REACH_TOL` (or on the shoulder).
    """
    dbs, dse, dew, dwf, bx, by, dse2, dew2, two_dd = geo
    wx = w03 - dwf * w02 - bx
    wy = w13 - dwf * w12 - by
    wz = w23 - dwf * w22 - dbs
    L2 = wx * wx + wy * wy + wz * wz
    L = math.sqrt(L2)
    c4 = (L2 - dse2 - dew2) / two_dd
    reached = not (abs(c4) > 1.0 + REACH_TOL or L <= REACH_TOL)
    c4 = min(max(c4, -1.0), 1.0)
    s4m = math.sqrt((1.0 - c4) * (1.0 + c4))
    inv_l = 1.0 / L if L > 0.0 else 0.0
    ux = wx * inv_l
    uy = wy * inv_l
    uz = wz * inv_l if L > 0.0 else 1.0
    ca = (dse + dew * c4) * inv_l
    sa = dew * s4m * inv_l
    c1r, s1r = unit(wx, wy)
    return reached, ux, uy, uz, c4, s4m, ca, sa, c1r, s1r


@njit(cache=True, error_model="numpy", inline="always")
def srs_arm(
    c10: float,
    s10: float,
    c50: float,
    s50: float,
    ux: float,
    uy: float,
    uz: float,
    c4: float,
    s4m: float,
    sgn: float,
    ca: float,
    sa: float,
    c1r: float,
    s1r: float,
    cpsi: float,
    spsi: float,
    w00: float,
    w01: float,
    w02: float,
    w10: float,
    w11: float,
    w12: float,
    w20: float,
    w21: float,
    w22: float,
) -> tuple[float, ...]:  # pragma: no cover - compiled
    """The arctangent arguments and branch quantities of one elbow sign at arm angle ψ.

    ``sgn`` is the elbow's sign (+1 for elbow bit 0: sin θ4 = sgn · s4m ≥ 0); (c10, s10) and
    (c50, s50) are θ1's and θ5's (cos, sin) at q = 0, used at the shoulder and wrist
    singularities (|sin θ2|, |sin θ6| ≤ :data:`WRIST_SINGULAR`).

    The elbow axis is ``b = Rot(u, ψ) b°``; the upper arm ``a = u cos α ∓ Rot(u, ψ) n sin
    α`` (n = b° × u; − for elbow bit 0), so that ``R03 = [b × a, b, a]``; the forearm
    ``f = sin θ4 (b × a) + cos θ4 a`` and ``R04 = [c4 (b × a) − s4 a, b, f]``; the wrist's
    ``R47 = R04ᵀ R07`` gives θ5, θ6, θ7 as Z-Y-Z angles, ``R03`` gives θ1, θ2, θ3.

    Returns
    -------
    tuple of float
        (y, x) of θ1, θ2, θ3, θ5, θ6, θ7 (12 values), then |sin θ2|, the wrist vector
        f × z7 (3 values): 16 values.
    """
    # Reference elbow axis b° = (−s1r, c1r, 0) and n = b° × u.
    nx = c1r * uz
    ny = s1r * uz
    nz = -s1r * uy - c1r * ux
    # Rotated by ψ about u: n_ψ = n cψ + b° sψ, b = b° cψ − n sψ.
    npx = nx * cpsi - s1r * spsi
    npy = ny * cpsi + c1r * spsi
    npz = nz * cpsi
    bx = -s1r * cpsi - nx * spsi
    by = c1r * cpsi - ny * spsi
    bz = -nz * spsi
    s4 = sgn * s4m
    k = sgn * sa
    ax = ux * ca - k * npx
    ay = uy * ca - k * npy
    az = uz * ca - k * npz
    # c = b × a = R03 e_x
    cx = by * az - bz * ay
    cy = bz * ax - bx * az
    cz = bx * ay - by * ax
    s2 = math.sqrt(ax * ax + ay * ay)
    c2 = az
    shoulder_singular = not s2 > WRIST_SINGULAR
    c1u, s1u = unit(ax, ay)
    c1 = c10 if shoulder_singular else c1u
    s1 = s10 if shoulder_singular else s1u
    y3 = -s1 * cx + c1 * cy
    x3 = c2 * (c1 * cx + s1 * cy) - s2 * cz
    # Forearm f = R04 e_z and g = R04 e_x.
    fx = s4 * cx + c4 * ax
    fy = s4 * cy + c4 * ay
    fz = s4 * cz + c4 * az
    gx = c4 * cx - s4 * ax
    gy = c4 * cy - s4 * ay
    gz = c4 * cz - s4 * az
    m11 = gx * w00 + gy * w10 + gz * w20
    m13 = gx * w02 + gy * w12 + gz * w22
    m21 = bx * w00 + by * w10 + bz * w20
    m23 = bx * w02 + by * w12 + bz * w22
    m31 = fx * w00 + fy * w10 + fz * w20
    m33 = fx * w02 + fy * w12 + fz * w22
    s6 = math.sqrt(m13 * m13 + m23 * m23)
    c6 = m33
    wrist_singular = not s6 > WRIST_SINGULAR
    c5u, s5u = unit(m13, m23)
    c5 = c50 if wrist_singular else c5u
    s5 = s50 if wrist_singular else s5u
    y7 = -s5 * m11 + c5 * m21
    x7 = c6 * (c5 * m11 + s5 * m21) - s6 * m31
    return (
        s1, c1, s2, c2, y3, x3,
        s5, c5, s6, c6, y7, x7,
        s2,
        fy * w22 - fz * w12,
        fz * w02 - fx * w22,
        fx * w12 - fy * w02,
    )  # fmt: skip


SRSJoints = tuple[float, ...]
"""(θ0 of the seven joints, their seven signs), 14 values."""


@njit(cache=True, error_model="numpy", inline="always")
def srs_joint_constants(g: np.ndarray) -> SRSJoints:  # pragma: no cover - compiled
    """The joint assembly's scalars of the geometry vector g (:data:`S_SIZE`,)."""
    t, s = S_THETA0, S_SIGN
    return (
        g[t], g[t + 1], g[t + 2], g[t + 3], g[t + 4], g[t + 5], g[t + 6],
        g[s], g[s + 1], g[s + 2], g[s + 3], g[s + 4], g[s + 5], g[s + 6],
    )  # fmt: skip


@njit(cache=True, error_model="numpy", inline="always")
def srs_joints(
    jc: SRSJoints,
    th1: float,
    th2: float,
    th3: float,
    th4: float,
    th5: float,
    th6: float,
    th7: float,
    shoulder: int,
    wrist: int,
) -> tuple[float, float, float, float, float, float, float]:  # pragma: no cover - compiled
    """The seven joints (rad, in (−π, π]) of one branch from the arctangents of its elbow
    sign (θ4 with that sign); ``shoulder``/``wrist`` 1 flip to ``(θ + π, −θ, θ + π)``."""
    fs = math.pi if shoulder == 1 else 0.0
    ss = -1.0 if shoulder == 1 else 1.0
    fw = math.pi if wrist == 1 else 0.0
    sw = -1.0 if wrist == 1 else 1.0
    return (
        jc[7] * wrap(th1 + fs - jc[0]),
        jc[8] * wrap(ss * th2 - jc[1]),
        jc[9] * wrap(th3 + fs - jc[2]),
        jc[10] * wrap(th4 - jc[3]),
        jc[11] * wrap(th5 + fw - jc[4]),
        jc[12] * wrap(sw * th6 - jc[5]),
        jc[13] * wrap(th7 + fw - jc[6]),
    )


@njit(cache=True, error_model="numpy", nogil=True)
def srs_solve(
    g: np.ndarray,
    tail_inv: np.ndarray,
    T: np.ndarray,
    free: np.ndarray,
    q: np.ndarray,
    valid: np.ndarray,
    aux: np.ndarray,
) -> None:  # pragma: no cover - compiled
    """Kernel: all eight S-R-S branches of poses T (N, 4, 4) at arm angles free (N,), rad:
    q (N, 8, 7), valid (N, 8), aux (N, 8, 5); an ``aux`` of shape (1, 8, 5) is scratch.

    Blocks of :data:`BLOCK` poses in three flat passes: the arctangent arguments of both
    elbow signs (13 a pose; unreachable poses, and arm angles that are NaN or beyond
    :data:`PSI_LIMIT`, computed through and marked), their arctangents, the joints of the
    eight branches.
    """
    geo = srs_geometry(g)
    jc = srs_joint_constants(g)
    c10, s10, c50, s50 = g[S_C10], g[S_S10], g[S_C50], g[S_S50]
    dse = g[S_DSE]
    keep = aux.shape[0] > 1
    n_poses = T.shape[0]
    n_angles = 1 + 2 * N_ARGS
    P = np.zeros((12, BLOCK))
    Y = np.zeros((n_angles, BLOCK))
    X = np.ones((n_angles, BLOCK))
    A = np.empty((n_angles, BLOCK))
    F = np.zeros(BLOCK)
    arm_aux = np.empty((2 * AUX_SIZE, BLOCK))  # per elbow sign
    ok = np.empty(BLOCK, dtype=np.bool_)
    for start in range(0, n_poses, BLOCK):
        m = min(BLOCK, n_poses - start)
        for b in range(m):
            Tk = T[start + b]
            for i in range(3):
                for c in range(4):
                    P[4 * i + c, b] = Tk[i, c]
            F[b] = free[start + b]
        for b in range(BLOCK):
            w00 = wrist_entry(P, b, 0, 0, tail_inv)
            w01 = wrist_entry(P, b, 0, 1, tail_inv)
            w02 = wrist_entry(P, b, 0, 2, tail_inv)
            w10 = wrist_entry(P, b, 1, 0, tail_inv)
            w11 = wrist_entry(P, b, 1, 1, tail_inv)
            w12 = wrist_entry(P, b, 1, 2, tail_inv)
            w20 = wrist_entry(P, b, 2, 0, tail_inv)
            w21 = wrist_entry(P, b, 2, 1, tail_inv)
            w22 = wrist_entry(P, b, 2, 2, tail_inv)
            reached, ux, uy, uz, c4, s4m, ca, sa, c1r, s1r = srs_centre(
                geo,
                w02,
                wrist_entry(P, b, 0, 3, tail_inv),
                w12,
                wrist_entry(P, b, 1, 3, tail_inv),
                w22,
                wrist_entry(P, b, 2, 3, tail_inv),
            )
            cpsi, spsi = sincos(F[b])
            ok[b] = reached and abs(F[b]) <= PSI_LIMIT
            Y[0, b] = s4m
            X[0, b] = c4
            for elbow in range(2):
                sgn = 1.0 if elbow == 0 else -1.0
                out = srs_arm(
                    c10, s10, c50, s50, ux, uy, uz, c4, s4m, sgn, ca, sa, c1r, s1r, cpsi, spsi,
                    w00, w01, w02, w10, w11, w12, w20, w21, w22,
                )  # fmt: skip
                base = 1 + N_ARGS * elbow
                for e in range(N_ARGS):
                    Y[base + e, b] = out[2 * e]
                    X[base + e, b] = out[2 * e + 1]
                row = AUX_SIZE * elbow
                arm_aux[row, b] = dse * out[12]
                arm_aux[row + 1, b] = s4m
                arm_aux[row + 2, b] = out[13]
                arm_aux[row + 3, b] = out[14]
                arm_aux[row + 4, b] = out[15]
        for e in range(n_angles):
            for b in range(BLOCK):
                A[e, b] = atan2(Y[e, b], X[e, b])
        for b in range(m):
            k = start + b
            row = k if keep else 0
            for br in range(N_BRANCHES):
                reached = ok[b]
                valid[k, br] = reached
                elbow = (br >> 1) & 1
                for j in range(AUX_SIZE):
                    aux[row, br, j] = arm_aux[AUX_SIZE * elbow + j, b] if reached else np.nan
                if not reached:
                    for j in range(N_JOINTS):
                        q[k, br, j] = np.nan
                    continue
                base = 1 + N_ARGS * elbow
                joints = srs_joints(
                    jc,
                    A[base, b],
                    A[base + 1, b],
                    A[base + 2, b],
                    A[0, b] if elbow == 0 else -A[0, b],
                    A[base + 3, b],
                    A[base + 4, b],
                    A[base + 5, b],
                    (br >> 2) & 1,
                    br & 1,
                )
                for j in range(N_JOINTS):
                    q[k, br, j] = joints[j]


@njit(cache=True, error_model="numpy")
def srs_solve_branch(
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
    """Kernel: S-R-S branch ``branch`` of poses with rotations R (N, 3, 3) (or one, (1, 3,
    3)), positions p (N, 3) and arm angles free (N,): q (N, 7), NaN where not valid (N,),
    and its branch quantities branch_aux (N, 5) (a ``branch_aux`` of shape (1, 5) is
    scratch); the same operations as :func:`srs_solve` on that branch alone. With a
    reference grid (s_grid (G,) not empty), the joints are then held and wound by
    :func:`hold_and_wind`.
    """
    geo = srs_geometry(g)
    jc = srs_joint_constants(g)
    c10, s10, c50, s50 = g[S_C10], g[S_S10], g[S_C50], g[S_S50]
    dse = g[S_DSE]
    shoulder = (branch >> 2) & 1
    elbow = (branch >> 1) & 1
    wrist = branch & 1
    keep = branch_aux.shape[0] > 1
    n_poses = p.shape[0]
    one_rotation = R.shape[0] == 1
    n_angles = 1 + N_ARGS
    P = np.zeros((12, BLOCK))
    Y = np.zeros((n_angles, BLOCK))
    X = np.ones((n_angles, BLOCK))
    A = np.empty((n_angles, BLOCK))
    F = np.zeros(BLOCK)
    aux = np.empty((AUX_SIZE, BLOCK))
    ok = np.empty(BLOCK, dtype=np.bool_)
    for start in range(0, n_poses, BLOCK):
        m = min(BLOCK, n_poses - start)
        for b in range(m):
            Rk = R[0 if one_rotation else start + b]
            for i in range(3):
                for c in range(3):
                    P[4 * i + c, b] = Rk[i, c]
                P[4 * i + 3, b] = p[start + b, i]
            F[b] = free[start + b]
        for b in range(BLOCK):
            w00 = wrist_entry(P, b, 0, 0, tail_inv)
            w01 = wrist_entry(P, b, 0, 1, tail_inv)
            w02 = wrist_entry(P, b, 0, 2, tail_inv)
            w10 = wrist_entry(P, b, 1, 0, tail_inv)
            w11 = wrist_entry(P, b, 1, 1, tail_inv)
            w12 = wrist_entry(P, b, 1, 2, tail_inv)
            w20 = wrist_entry(P, b, 2, 0, tail_inv)
            w21 = wrist_entry(P, b, 2, 1, tail_inv)
            w22 = wrist_entry(P, b, 2, 2, tail_inv)
            reached, ux, uy, uz, c4, s4m, ca, sa, c1r, s1r = srs_centre(
                geo,
                w02,
                wrist_entry(P, b, 0, 3, tail_inv),
                w12,
                wrist_entry(P, b, 1, 3, tail_inv),
                w22,
                wrist_entry(P, b, 2, 3, tail_inv),
            )
            cpsi, spsi = sincos(F[b])
            sgn = 1.0 if elbow == 0 else -1.0
            out = srs_arm(
                c10, s10, c50, s50, ux, uy, uz, c4, s4m, sgn, ca, sa, c1r, s1r, cpsi, spsi,
                w00, w01, w02, w10, w11, w12, w20, w21, w22,
            )  # fmt: skip
            ok[b] = reached and abs(F[b]) <= PSI_LIMIT
            Y[0, b] = s4m
            X[0, b] = c4
            for e in range(N_ARGS):
                Y[1 + e, b] = out[2 * e]
                X[1 + e, b] = out[2 * e + 1]
            aux[0, b] = dse * out[12]
            aux[1, b] = s4m
            aux[2, b] = out[13]
            aux[3, b] = out[14]
            aux[4, b] = out[15]
        for e in range(n_angles):
            for b in range(BLOCK):
                A[e, b] = atan2(Y[e, b], X[e, b])
        for b in range(m):
            k = start + b
            row = k if keep else 0
            valid[k] = ok[b]
            if not ok[b]:
                for j in range(AUX_SIZE):
                    branch_aux[row, j] = np.nan
                for j in range(N_JOINTS):
                    q[k, j] = np.nan
                continue
            for j in range(AUX_SIZE):
                branch_aux[row, j] = aux[j, b]
            joints = srs_joints(
                jc,
                A[1, b],
                A[2, b],
                A[3, b],
                A[0, b] if elbow == 0 else -A[0, b],
                A[4, b],
                A[5, b],
                A[6, b],
                shoulder,
                wrist,
            )
            for j in range(N_JOINTS):
                q[k, j] = joints[j]
    if s_grid.shape[0] > 0:
        hold_and_wind(q, valid, s, s_grid, q_grid)
