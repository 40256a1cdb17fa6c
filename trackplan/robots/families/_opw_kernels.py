"""Compiled kernels of the OPW family's closed-form IK: the equations written once.

The OPW solution (Brandstötter et al.; docs/robots.md) is written once, as scalar
helpers that both kernels inline: :func:`opw_centre` (the wrist centre),
:func:`opw_shoulder` (θ1 and the elbow angle φ of one shoulder), :func:`opw_arm`
(θ2 and the wrist's arctangent arguments of one arm) and :func:`opw_joints` (the six
joints of one branch from the arctangents). :func:`opw_solve` takes poses and writes their
eight branches; :func:`opw_solve_branch` runs the same operations for the arm of one
branch only (6 arctangents a pose instead of 20): a planned trajectory's samples need
only the branch chosen on the planning grid; it reads rotations and positions rather than
(4, 4) poses, and can hold missed poses and wind the joints near a reference in the same
call (:func:`~trackplan.robots.families._kernels.hold_and_wind`). Both work on blocks of
:data:`~trackplan.robots.families._kernels.BLOCK` poses in three flat passes that
vectorise (the arctangent arguments, unreachable arms computed through and marked; their
arctangents; the joints). The Python API is :mod:`trackplan.robots.families.opw`.
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
    hold_and_wind,
    unit,
    wrap,
    wrist_entry,
)

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


OPWGeometry = tuple[float, float, float, float, float, float, float, float, float, float]
"""(a1, b, c1, c2, c4, κ, cos ψ, sin ψ, bx, by): the scalars of the geometry vector that
the arm equations read, unpacked once per kernel call."""


@njit(cache=True, error_model="numpy", inline="always")
def opw_geometry(g: np.ndarray) -> OPWGeometry:  # pragma: no cover - compiled
    """The arm equations' scalars of the geometry vector g (:data:`O_SIZE`,)."""
    return (
        g[O_A1],
        g[O_B],
        g[O_C1],
        g[O_C2],
        g[O_C4],
        g[O_KAPPA],
        g[O_CPSI],
        g[O_SPSI],
        g[O_BX],
        g[O_BY],
    )


@njit(cache=True, error_model="numpy", inline="always")
def opw_centre(
    geo: OPWGeometry, w02: float, w03: float, w12: float, w13: float, w22: float, w23: float
) -> tuple[float, float, float, float]:  # pragma: no cover - compiled
    """The wrist centre (cx, cy, cz), m, and r² = cx² + cy² − b², m², of the wrist frame
    ``T · tail_inv`` (its entries w_rc)."""
    b_off, c4, bx, by = geo[1], geo[4], geo[8], geo[9]
    cx = w03 - c4 * w02 - bx
    cy = w13 - c4 * w12 - by
    cz = w23 - c4 * w22
    return cx, cy, cz, cx * cx + cy * cy - b_off * b_off


@njit(cache=True, error_model="numpy", inline="always")
def opw_shoulder(
    geo: OPWGeometry, cx: float, cy: float, cz: float, r2: float, shoulder: int
) -> tuple[bool, float, float, float, float, float, float, float]:  # pragma: no cover
    """One shoulder's quantities: (reached, cos θ1, sin θ1, K = cos φ, sin φ ≥ 0, r, dx,
    dz); φ = θ3 + ψ, K clipped to [−1, 1] (``reached`` is False when it was outside by
    more than :data:`REACH_TOL`, or the centre is inside the shoulder cylinder)."""
    a1, b_off, c1, c2, kappa = geo[0], geo[1], geo[2], geo[3], geo[5]
    r = math.sqrt(max(r2, 0.0))
    xr = r if shoulder == 0 else -r
    c1_, s1_ = unit(cx * xr + cy * b_off, cy * xr - cx * b_off)
    dx = xr - a1
    dz = cz - c1
    K = (dx * dx + dz * dz - c2 * c2 - kappa * kappa) / (2.0 * c2 * kappa)
    reached = not (r2 < -REACH_TOL or abs(K) > 1.0 + REACH_TOL)
    K = min(max(K, -1.0), 1.0)
    return reached, c1_, s1_, K, math.sqrt((1.0 - K) * (1.0 + K)), r, dx, dz


@njit(cache=True, error_model="numpy", inline="always")
def opw_arm(
    geo: OPWGeometry,
    c40: float,
    s40: float,
    c1_: float,
    s1_: float,
    K: float,
    sphi: float,
    dx: float,
    dz: float,
    sg: float,
    w00: float,
    w02: float,
    w10: float,
    w12: float,
    w20: float,
    w22: float,
) -> tuple[float, ...]:  # pragma: no cover - compiled
    """One arm's arctangent arguments and wrist vector.

    ``sg`` is +1 when shoulder and elbow bits are equal, else −1; (c40, s40) is θ4's
    (cos, sin) used at the wrist singularity (|sin θ5| ≤ :data:`WRIST_SINGULAR`).

    Returns
    -------
    tuple of float
        (y, x) of θ2, θ4, θ5 and θ6 (8 values), then the wrist vector (3 values).
    """
    c2, kappa, cpsi, spsi = geo[3], geo[5], geo[6], geo[7]
    vx = c2 + kappa * K
    vy = kappa * sg * sphi
    c2_, s2_ = unit(dz * vx + dx * vy, dx * vx - dz * vy)
    c3_ = K * cpsi + sg * sphi * spsi
    s3_ = sg * sphi * cpsi - K * spsi
    c23 = c2_ * c3_ - s2_ * s3_
    s23 = s2_ * c3_ + c2_ * s3_
    x0 = c1_ * c23
    x1 = s1_ * c23
    z0 = c1_ * s23
    z1 = s1_ * s23
    m00 = x0 * w00 + x1 * w10 + -s23 * w20
    m02 = x0 * w02 + x1 * w12 + -s23 * w22
    m10 = -s1_ * w00 + c1_ * w10 + 0.0 * w20
    m12 = -s1_ * w02 + c1_ * w12 + 0.0 * w22
    m20 = z0 * w00 + z1 * w10 + c23 * w20
    m22 = z0 * w02 + z1 * w12 + c23 * w22
    s5 = math.sqrt(m02 * m02 + m12 * m12)
    c5 = m22
    singular = not s5 > WRIST_SINGULAR
    c4_ = c40 if singular else m02 / s5
    s4_ = s40 if singular else m12 / s5
    n00 = c4_ * m00 + s4_ * m10
    n10 = -s4_ * m00 + c4_ * m10
    return (
        s2_,
        c2_,
        s4_,
        c4_,
        s5,
        c5,
        n10,
        c5 * n00 - s5 * m20,
        z1 * w22 - c23 * w12,
        c23 * w02 - z0 * w22,
        z0 * w12 - z1 * w02,
    )


OPWJoints = tuple[float, ...]
"""(ψ, θ0 of the six joints, their six signs), 13 values: the joint assembly's constants."""


@njit(cache=True, error_model="numpy", inline="always")
def opw_joint_constants(g: np.ndarray) -> OPWJoints:  # pragma: no cover - compiled
    """The joint assembly's scalars of the geometry vector g (:data:`O_SIZE`,)."""
    t, s = O_THETA0, O_SIGN
    return (
        g[O_PSI],
        g[t], g[t + 1], g[t + 2], g[t + 3], g[t + 4], g[t + 5],
        g[s], g[s + 1], g[s + 2], g[s + 3], g[s + 4], g[s + 5],
    )  # fmt: skip


@njit(cache=True, error_model="numpy", inline="always")
def opw_joints(
    jc: OPWJoints,
    th1: float,
    th2: float,
    phi: float,
    th4: float,
    th5: float,
    th6: float,
    phi_sign: float,
) -> tuple[float, ...]:  # pragma: no cover - compiled
    """The joints (rad) of one OPW arm's two branches from its arctangents (θ1, θ2, φ,
    θ4, θ5, θ6); ``jc`` from :func:`opw_joint_constants`; ``phi_sign`` is +1 when the
    shoulder and elbow bits are equal, else −1.

    Returns
    -------
    tuple of float
        q1, q2, q3 (both branches), then q4, q5, q6 of wrist bit 0, then of wrist bit 1
        (9 values). Both at once and with no branch, so that a flat loop over poses
        vectorises.
    """
    psi, t0, t1, t2, t3, t4, t5 = jc[0], jc[1], jc[2], jc[3], jc[4], jc[5], jc[6]
    g0, g1, g2, g3, g4, g5 = jc[7], jc[8], jc[9], jc[10], jc[11], jc[12]
    th4 = th4 - t3
    th6 = th6 - t5
    return (
        g0 * wrap(th1 - t0),
        g1 * wrap(th2 - t1),
        g2 * wrap(phi_sign * phi - psi - t2),
        g3 * wrap(th4),
        g4 * wrap(th5 - t4),
        g5 * wrap(th6),
        g3 * wrap(th4 + math.pi),
        g4 * wrap(-th5 - t4),
        g5 * wrap(th6 + math.pi),
    )


@njit(cache=True, error_model="numpy", nogil=True)
def opw_solve(
    g: np.ndarray,
    tail_inv: np.ndarray,
    T: np.ndarray,
    q: np.ndarray,
    valid: np.ndarray,
    aux: np.ndarray,
) -> None:  # pragma: no cover - compiled
    """Kernel: all eight OPW branches of poses T (N, 4, 4): q (N, 8, 6), valid (N, 8),
    aux (N, 8, 5); an ``aux`` of shape (1, 8, 5) is scratch (branch quantities not kept).

    Blocks of :data:`BLOCK` poses in three flat passes: the arctangent arguments of the
    four arms (20 a pose; :func:`opw_centre` once, :func:`opw_shoulder` per shoulder,
    :func:`opw_arm` per arm; unreachable arms computed through and marked), their
    arctangents, the joints of the eight branches (:func:`opw_joints`).
    """
    geo = opw_geometry(g)
    jc = opw_joint_constants(g)
    c40 = g[O_C40]
    s40 = g[O_S40]
    keep = aux.shape[0] > 1
    n_poses = T.shape[0]
    P = np.zeros((12, BLOCK))  # the pose's first three rows, one row per entry
    Y = np.zeros((O_N_ANGLES, BLOCK))
    X = np.ones((O_N_ANGLES, BLOCK))
    A = np.empty((O_N_ANGLES, BLOCK))
    W = np.empty((12, BLOCK))  # the first three rows of T · tail_inv
    C = np.empty((4, BLOCK))  # the wrist centre (x, y, z) and r², per pose
    S = np.empty((3, BLOCK))  # r, dx, dz of the shoulder at hand
    arm_aux = np.empty((4 * AUX_SIZE, BLOCK))  # per arm: r, sin φ, wrist vector
    ok = np.empty((2, BLOCK), dtype=np.bool_)  # per shoulder
    Q = np.empty((6 * N_BRANCHES, BLOCK))  # the joints, branch by branch
    for start in range(0, n_poses, BLOCK):
        m = min(BLOCK, n_poses - start)
        for b in range(m):
            Tk = T[start + b]
            for i in range(3):
                for c in range(4):
                    P[4 * i + c, b] = Tk[i, c]
        for b in range(BLOCK):
            for i in range(3):
                for c in range(4):
                    W[4 * i + c, b] = wrist_entry(P, b, i, c, tail_inv)
            cx, cy, cz, r2 = opw_centre(geo, W[2, b], W[3, b], W[6, b], W[7, b], W[10, b], W[11, b])
            C[0, b] = cx
            C[1, b] = cy
            C[2, b] = cz
            C[3, b] = r2
        for shoulder in range(2):
            for b in range(BLOCK):
                reached, c1_, s1_, K, sphi, r, dx, dz = opw_shoulder(
                    geo, C[0, b], C[1, b], C[2, b], C[3, b], shoulder
                )
                ok[shoulder, b] = reached
                Y[O_TH1 + shoulder, b] = s1_
                X[O_TH1 + shoulder, b] = c1_
                Y[O_PHI + shoulder, b] = sphi
                X[O_PHI + shoulder, b] = K
                S[0, b] = r
                S[1, b] = dx
                S[2, b] = dz
            for elbow in range(2):
                arm = 2 * shoulder + elbow
                sg = 1.0 if shoulder == elbow else -1.0
                slot = O_WRIST + 3 * arm
                row = AUX_SIZE * arm
                for b in range(BLOCK):
                    out = opw_arm(
                        geo,
                        c40,
                        s40,
                        X[O_TH1 + shoulder, b],
                        Y[O_TH1 + shoulder, b],
                        X[O_PHI + shoulder, b],
                        Y[O_PHI + shoulder, b],
                        S[1, b],
                        S[2, b],
                        sg,
                        W[0, b],
                        W[2, b],
                        W[4, b],
                        W[6, b],
                        W[8, b],
                        W[10, b],
                    )
                    Y[O_TH2 + arm, b] = out[0]
                    X[O_TH2 + arm, b] = out[1]
                    Y[slot, b] = out[2]
                    X[slot, b] = out[3]
                    Y[slot + 1, b] = out[4]
                    X[slot + 1, b] = out[5]
                    Y[slot + 2, b] = out[6]
                    X[slot + 2, b] = out[7]
                    arm_aux[row, b] = S[0, b]
                    arm_aux[row + 1, b] = Y[O_PHI + shoulder, b]
                    arm_aux[row + 2, b] = out[8]
                    arm_aux[row + 3, b] = out[9]
                    arm_aux[row + 4, b] = out[10]
        for e in range(O_N_ANGLES):
            for b in range(BLOCK):
                A[e, b] = atan2(Y[e, b], X[e, b])
        for arm in range(4):
            shoulder = arm >> 1
            phi_sign = 1.0 if shoulder == (arm & 1) else -1.0
            slot = O_WRIST + 3 * arm
            row = 12 * arm
            for b in range(BLOCK):  # both wrist bits side by side
                joints = opw_joints(
                    jc,
                    A[O_TH1 + shoulder, b],
                    A[O_TH2 + arm, b],
                    A[O_PHI + shoulder, b],
                    A[slot, b],
                    A[slot + 1, b],
                    A[slot + 2, b],
                    phi_sign,
                )
                Q[row, b] = joints[0]
                Q[row + 1, b] = joints[1]
                Q[row + 2, b] = joints[2]
                Q[row + 3, b] = joints[3]
                Q[row + 4, b] = joints[4]
                Q[row + 5, b] = joints[5]
                Q[row + 6, b] = joints[0]
                Q[row + 7, b] = joints[1]
                Q[row + 8, b] = joints[2]
                Q[row + 9, b] = joints[6]
                Q[row + 10, b] = joints[7]
                Q[row + 11, b] = joints[8]
        for b in range(m):
            k = start + b
            row = k if keep else 0
            for br in range(N_BRANCHES):
                reached = ok[br >> 2, b]
                valid[k, br] = reached
                for j in range(AUX_SIZE):
                    aux[row, br, j] = arm_aux[AUX_SIZE * (br >> 1) + j, b] if reached else np.nan
                for j in range(6):
                    q[k, br, j] = Q[6 * br + j, b] if reached else np.nan


@njit(cache=True, error_model="numpy")
def opw_solve_branch(
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
    """Kernel: OPW branch ``branch`` of poses with rotations R (N, 3, 3) (or one, (1, 3,
    3)) and positions p (N, 3): q (N, 6), NaN where not valid (N,), and its branch
    quantities branch_aux (N, 5) (a ``branch_aux`` of shape (1, 5) is scratch); the same
    operations as :func:`opw_solve` on that branch alone. With a reference grid (s_grid
    (G,) not empty), the joints are then held and wound by :func:`hold_and_wind`.

    Blocks of :data:`BLOCK` poses, in three flat passes each: the arm's arctangent
    arguments (:func:`opw_centre`, :func:`opw_shoulder` and :func:`opw_arm` of one
    shoulder and elbow, unreachable poses computed through and marked), their
    arctangents, the joints (:func:`opw_joints`).
    """
    geo = opw_geometry(g)
    jc = opw_joint_constants(g)
    c40 = g[O_C40]
    s40 = g[O_S40]
    shoulder = (branch >> 2) & 1
    elbow = (branch >> 1) & 1
    flip = branch & 1
    sg = 1.0 if shoulder == elbow else -1.0
    keep = branch_aux.shape[0] > 1
    n_poses = p.shape[0]
    one_rotation = R.shape[0] == 1
    P = np.zeros((12, BLOCK))  # the pose's first three rows, one row per entry
    Y = np.zeros((6, BLOCK))  # θ1, φ, θ2, θ4, θ5, θ6 arguments
    X = np.ones((6, BLOCK))
    A = np.empty((6, BLOCK))
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
        for b in range(BLOCK):
            w00 = wrist_entry(P, b, 0, 0, tail_inv)
            w02 = wrist_entry(P, b, 0, 2, tail_inv)
            w10 = wrist_entry(P, b, 1, 0, tail_inv)
            w12 = wrist_entry(P, b, 1, 2, tail_inv)
            w20 = wrist_entry(P, b, 2, 0, tail_inv)
            w22 = wrist_entry(P, b, 2, 2, tail_inv)
            cx, cy, cz, r2 = opw_centre(
                geo,
                w02,
                wrist_entry(P, b, 0, 3, tail_inv),
                w12,
                wrist_entry(P, b, 1, 3, tail_inv),
                w22,
                wrist_entry(P, b, 2, 3, tail_inv),
            )
            reached, c1_, s1_, K, sphi, r, dx, dz = opw_shoulder(geo, cx, cy, cz, r2, shoulder)
            out = opw_arm(
                geo, c40, s40, c1_, s1_, K, sphi, dx, dz, sg, w00, w02, w10, w12, w20, w22
            )
            ok[b] = reached
            Y[0, b] = s1_
            X[0, b] = c1_
            Y[1, b] = sphi
            X[1, b] = K
            for e in range(4):
                Y[2 + e, b] = out[2 * e]
                X[2 + e, b] = out[2 * e + 1]
            aux[0, b] = r
            aux[1, b] = sphi
            aux[2, b] = out[8]
            aux[3, b] = out[9]
            aux[4, b] = out[10]
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
            joints = opw_joints(jc, A[0, b], A[2, b], A[1, b], A[3, b], A[4, b], A[5, b], sg)
            wrist = 3 + 3 * flip
            q[k, 0] = joints[0]
            q[k, 1] = joints[1]
            q[k, 2] = joints[2]
            q[k, 3] = joints[wrist]
            q[k, 4] = joints[wrist + 1]
            q[k, 5] = joints[wrist + 2]
    if s_grid.shape[0] > 0:
        hold_and_wind(q, valid, s, s_grid, q_grid)
