"""Compiled kernels of the closed-form IK families (OPW and UR).

One fused kernel per family (:func:`opw_solve`, :func:`ur_solve`) takes poses and writes
their eight branches: the arguments (Y, X) of every arctangent go into a small buffer,
:func:`atan2` evaluates the buffer (a compiled, branch-free arctangent that LLVM
vectorises; libm's scalar ``atan2`` and numpy's ``arctan2`` cost about 25 ns each and
dominated the former three-pass design), and the joint values are assembled from the
angles. :func:`opw_solve` does each of the three in a flat pass over blocks of
:data:`BLOCK` poses that vectorises (the four arms' arguments side by side, unreachable
arms computed through and marked); :func:`ur_solve` works pose by pose. No array of the
batch's size is allocated besides the outputs. A one-branch kernel
per family (:func:`opw_solve_branch`, :func:`ur_solve_branch`) runs the same operations for
the arm of one branch only (6 arctangents a pose instead of 20): a planned trajectory's
samples need only the branch chosen on the planning grid. It takes blocks of
:data:`BLOCK` poses in flat passes that vectorise (arguments, arctangents, joints), reads
rotations and positions rather than (4, 4) poses, and can hold missed poses and wind the
joints near a reference in the same call (:func:`hold_and_wind`). The Python APIs are
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


# Arctangent: octant reduction to |s| ≤ tan(π/8), then atan(s) = s + s·z·P(z), z = s²,
# P a degree-11 Chebyshev fit of (atan √z − √z) / z^{3/2} on [0, 0.175] (error 1.5e-18;
# fitted with mpmath at 50 digits). Angles k·π/4 are split into hi + lo parts. Within
# 2 ulp of the correctly rounded arctangent (mean 0.07 ulp), the same signed zeros and
# quadrants as C's atan2, NaN in → NaN out.
TAN_PI_8 = 0.41421356237309503
TAN_3PI_8 = 2.414213562373095
PI_4_HI, PI_4_LO = 0.7853981633974483, 3.061616997868383e-17
PI_2_HI, PI_2_LO = 1.5707963267948966, 6.123233995736766e-17
PI3_4_HI, PI3_4_LO = 2.356194490192345, 9.184850993605148e-17
PI_HI, PI_LO = 3.141592653589793, 1.2246467991473532e-16
P0, P1, P2, P3 = (
    -0.3333333333333333,
    0.1999999999999976,
    -0.14285714285648926,
    0.1111111110410365,
)
P4, P5, P6, P7 = (
    -0.09090908701696371,
    0.0769229489243801,
    -0.06666398527043488,
    0.05878628988060137,
)
P8, P9, P10, P11 = (
    -0.05228266918352639,
    0.04541715636079406,
    -0.034319069932567094,
    0.016009822553531047,
)


@njit(cache=True, error_model="numpy", inline="always")
def atan2(y: float, x: float) -> float:  # pragma: no cover - compiled
    """The angle of the vector (x, y), rad in [−π, π], as C's ``atan2`` to 2 ulp."""
    ax = abs(x)
    ay = abs(y)
    neg = math.copysign(1.0, x) < 0.0
    if ay > TAN_3PI_8 * ax:
        num = -ax
        den = ay
        hi = PI_2_HI
        lo = PI_2_LO
    elif ay > TAN_PI_8 * ax:
        num = ay - ax
        den = ay + ax
        hi = PI3_4_HI if neg else PI_4_HI
        lo = PI3_4_LO if neg else PI_4_LO
    else:
        num = ay
        den = ax
        hi = PI_HI if neg else 0.0
        lo = PI_LO if neg else 0.0
    s = num / den if den != 0.0 else num  # den = 0 only for x = y = 0 (or NaN y)
    if neg:
        s = -s
    z = s * s
    z2 = z * z
    z4 = z2 * z2
    p = (
        ((P0 + P1 * z) + (P2 + P3 * z) * z2)
        + ((P4 + P5 * z) + (P6 + P7 * z) * z2) * z4
        + ((P8 + P9 * z) + (P10 + P11 * z) * z2) * (z4 * z4)
    )
    return math.copysign(hi + (s + (s * z * p + lo)), y)


@njit(cache=True, error_model="numpy", inline="always")
def _atan2_all(Y: np.ndarray, X: np.ndarray, angles: np.ndarray) -> None:  # pragma: no cover
    """Kernel: ``angles ← atan2(Y, X)`` elementwise over a small buffer."""
    for j in range(Y.shape[0]):
        angles[j] = atan2(Y[j], X[j])


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
def _wrist_frame(
    T: np.ndarray, tail_inv: np.ndarray
) -> tuple[float, ...]:  # pragma: no cover - compiled
    """The first three rows of ``T · tail_inv``, row by row (12 scalars)."""
    return (
        T[0, 0] * tail_inv[0, 0]
        + T[0, 1] * tail_inv[1, 0]
        + T[0, 2] * tail_inv[2, 0]
        + T[0, 3] * tail_inv[3, 0],
        T[0, 0] * tail_inv[0, 1]
        + T[0, 1] * tail_inv[1, 1]
        + T[0, 2] * tail_inv[2, 1]
        + T[0, 3] * tail_inv[3, 1],
        T[0, 0] * tail_inv[0, 2]
        + T[0, 1] * tail_inv[1, 2]
        + T[0, 2] * tail_inv[2, 2]
        + T[0, 3] * tail_inv[3, 2],
        T[0, 0] * tail_inv[0, 3]
        + T[0, 1] * tail_inv[1, 3]
        + T[0, 2] * tail_inv[2, 3]
        + T[0, 3] * tail_inv[3, 3],
        T[1, 0] * tail_inv[0, 0]
        + T[1, 1] * tail_inv[1, 0]
        + T[1, 2] * tail_inv[2, 0]
        + T[1, 3] * tail_inv[3, 0],
        T[1, 0] * tail_inv[0, 1]
        + T[1, 1] * tail_inv[1, 1]
        + T[1, 2] * tail_inv[2, 1]
        + T[1, 3] * tail_inv[3, 1],
        T[1, 0] * tail_inv[0, 2]
        + T[1, 1] * tail_inv[1, 2]
        + T[1, 2] * tail_inv[2, 2]
        + T[1, 3] * tail_inv[3, 2],
        T[1, 0] * tail_inv[0, 3]
        + T[1, 1] * tail_inv[1, 3]
        + T[1, 2] * tail_inv[2, 3]
        + T[1, 3] * tail_inv[3, 3],
        T[2, 0] * tail_inv[0, 0]
        + T[2, 1] * tail_inv[1, 0]
        + T[2, 2] * tail_inv[2, 0]
        + T[2, 3] * tail_inv[3, 0],
        T[2, 0] * tail_inv[0, 1]
        + T[2, 1] * tail_inv[1, 1]
        + T[2, 2] * tail_inv[2, 1]
        + T[2, 3] * tail_inv[3, 1],
        T[2, 0] * tail_inv[0, 2]
        + T[2, 1] * tail_inv[1, 2]
        + T[2, 2] * tail_inv[2, 2]
        + T[2, 3] * tail_inv[3, 2],
        T[2, 0] * tail_inv[0, 3]
        + T[2, 1] * tail_inv[1, 3]
        + T[2, 2] * tail_inv[2, 3]
        + T[2, 3] * tail_inv[3, 3],
    )


@njit(cache=True, error_model="numpy", inline="always")
def _wrist_entry(
    P: np.ndarray, b: int, r: int, c: int, tail_inv: np.ndarray
) -> float:  # pragma: no cover - compiled
    """Kernel: entry (r, c) of ``T · tail_inv`` for pose b of a block P (12, BLOCK), summed
    in :func:`_wrist_frame`'s order."""
    return (
        P[4 * r, b] * tail_inv[0, c]
        + P[4 * r + 1, b] * tail_inv[1, c]
        + P[4 * r + 2, b] * tail_inv[2, c]
        + P[4 * r + 3, b] * tail_inv[3, c]
    )


BLOCK = 32
"""Poses per block of :func:`opw_solve` and :func:`opw_solve_branch`: each pass over a
block is a flat loop over its poses that LLVM turns into SIMD code."""


@njit(cache=True, error_model="numpy", inline="always")
def _unreachable(
    valid: np.ndarray, aux: np.ndarray, first: int, stop: int
) -> None:  # pragma: no cover
    """Kernel: mark branches first … stop − 1 of one pose unreachable.

    Their arctangent slots keep finite values of an earlier pose and are not read.
    """
    for br in range(first, stop):
        valid[br] = False
        for j in range(AUX_SIZE):
            aux[br, j] = np.nan


@njit(cache=True, error_model="numpy", inline="always")
def _opw_joints(
    g: np.ndarray, a: np.ndarray, arm: int, flip: int, q: np.ndarray
) -> None:  # pragma: no cover - compiled
    """Kernel: the joint angles q (6,) of OPW branch ``2·arm + flip`` from the pose's
    arctangents a (20,) (the arm reaches the pose)."""
    psi = g[O_PSI]
    t0 = g[O_THETA0 : O_THETA0 + 6]
    sg = g[O_SIGN : O_SIGN + 6]
    shoulder = arm >> 1
    th1 = sg[0] * wrap(a[O_TH1 + shoulder] - t0[0])
    th2 = sg[1] * wrap(a[O_TH2 + arm] - t0[1])
    phi = a[O_PHI + shoulder]
    th3 = (phi if shoulder == (arm & 1) else -phi) - psi - t0[2]
    th3 = sg[2] * wrap(th3)
    slot = O_WRIST + 3 * arm
    th4 = a[slot] - t0[3]
    th5 = a[slot + 1]
    th6 = a[slot + 2] - t0[5]
    q[0] = th1
    q[1] = th2
    q[2] = th3
    if flip == 0:
        q[3] = sg[3] * wrap(th4)
        q[4] = sg[4] * wrap(th5 - t0[4])
        q[5] = sg[5] * wrap(th6)
    else:
        q[3] = sg[3] * wrap(th4 + math.pi)
        q[4] = sg[4] * wrap(-th5 - t0[4])
        q[5] = sg[5] * wrap(th6 + math.pi)


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

    Blocks of :data:`BLOCK` poses in three flat passes, as :func:`opw_solve_branch`: the
    arctangent arguments of the four arms (20 a pose; unreachable arms computed through
    and marked), their arctangents, the joints of the eight branches. The arm and wrist
    expressions are written out here and in :func:`opw_solve_branch` alike: shared through
    inlined helpers, the blocked loops measured 10–15 % slower.
    """
    a1 = g[O_A1]
    b_off = g[O_B]
    c1 = g[O_C1]
    c2 = g[O_C2]
    c4 = g[O_C4]
    kappa = g[O_KAPPA]
    cpsi = g[O_CPSI]
    spsi = g[O_SPSI]
    bx = g[O_BX]
    by = g[O_BY]
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
    psi = g[O_PSI]
    t0 = g[O_THETA0 : O_THETA0 + 6]
    signs = g[O_SIGN : O_SIGN + 6]
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
                    W[4 * i + c, b] = _wrist_entry(P, b, i, c, tail_inv)
            cx = W[3, b] - c4 * W[2, b] - bx
            cy = W[7, b] - c4 * W[6, b] - by
            C[0, b] = cx
            C[1, b] = cy
            C[2, b] = W[11, b] - c4 * W[10, b]
            C[3, b] = cx * cx + cy * cy - b_off * b_off
        for shoulder in range(2):
            for b in range(BLOCK):
                cx = C[0, b]
                cy = C[1, b]
                r2 = C[3, b]
                r = math.sqrt(max(r2, 0.0))
                xr = r if shoulder == 0 else -r
                c1_, s1_ = unit(cx * xr + cy * b_off, cy * xr - cx * b_off)
                dx = xr - a1
                dz = C[2, b] - c1
                K = (dx * dx + dz * dz - c2 * c2 - kappa * kappa) / (2.0 * c2 * kappa)
                ok[shoulder, b] = not (r2 < -REACH_TOL or abs(K) > 1.0 + REACH_TOL)
                K = min(max(K, -1.0), 1.0)
                Y[O_TH1 + shoulder, b] = s1_
                X[O_TH1 + shoulder, b] = c1_
                Y[O_PHI + shoulder, b] = math.sqrt((1.0 - K) * (1.0 + K))
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
                    w00 = W[0, b]
                    w02 = W[2, b]
                    w10 = W[4, b]
                    w12 = W[6, b]
                    w20 = W[8, b]
                    w22 = W[10, b]
                    s1_ = Y[O_TH1 + shoulder, b]
                    c1_ = X[O_TH1 + shoulder, b]
                    sphi = Y[O_PHI + shoulder, b]
                    K = X[O_PHI + shoulder, b]
                    dx = S[1, b]
                    dz = S[2, b]
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
                    Y[O_TH2 + arm, b] = s2_
                    X[O_TH2 + arm, b] = c2_
                    Y[slot, b] = s4_
                    X[slot, b] = c4_
                    Y[slot + 1, b] = s5
                    X[slot + 1, b] = c5
                    Y[slot + 2, b] = n10
                    X[slot + 2, b] = c5 * n00 - s5 * m20
                    arm_aux[row, b] = S[0, b]
                    arm_aux[row + 1, b] = sphi
                    arm_aux[row + 2, b] = z1 * w22 - c23 * w12
                    arm_aux[row + 3, b] = c23 * w02 - z0 * w22
                    arm_aux[row + 4, b] = z0 * w12 - z1 * w02
        for e in range(O_N_ANGLES):
            for b in range(BLOCK):
                A[e, b] = atan2(Y[e, b], X[e, b])
        for arm in range(4):
            shoulder = arm >> 1
            phi_sign = 1.0 if shoulder == (arm & 1) else -1.0
            slot = O_WRIST + 3 * arm
            row = 12 * arm
            for b in range(BLOCK):  # _opw_joints of both flips, side by side
                th1 = signs[0] * wrap(A[O_TH1 + shoulder, b] - t0[0])
                th2 = signs[1] * wrap(A[O_TH2 + arm, b] - t0[1])
                th3 = signs[2] * wrap(phi_sign * A[O_PHI + shoulder, b] - psi - t0[2])
                th4 = A[slot, b] - t0[3]
                th5 = A[slot + 1, b]
                th6 = A[slot + 2, b] - t0[5]
                Q[row, b] = th1
                Q[row + 1, b] = th2
                Q[row + 2, b] = th3
                Q[row + 3, b] = signs[3] * wrap(th4)
                Q[row + 4, b] = signs[4] * wrap(th5 - t0[4])
                Q[row + 5, b] = signs[5] * wrap(th6)
                Q[row + 6, b] = th1
                Q[row + 7, b] = th2
                Q[row + 8, b] = th3
                Q[row + 9, b] = signs[3] * wrap(th4 + math.pi)
                Q[row + 10, b] = signs[4] * wrap(-th5 - t0[4])
                Q[row + 11, b] = signs[5] * wrap(th6 + math.pi)
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


@njit(cache=True, error_model="numpy", inline="always")
def _interval(grid: np.ndarray, x: float, guess: int) -> int:  # pragma: no cover - compiled
    """Kernel: ``numpy.searchsorted(grid, x, side="right") - 1`` for a strictly increasing
    grid (G,): the interval [grid[i], grid[i + 1]) holding x, −1 before the grid, G − 1
    from its end on (and for NaN). The interval ``guess`` and the next one are tried
    first (samples in order move by at most one), then a bisection."""
    n_grid = grid.shape[0]
    for i in (guess, guess + 1):
        if 0 <= i < n_grid - 1 and grid[i] <= x < grid[i + 1]:
            return i
    lo = 0
    hi = n_grid
    while lo < hi:
        mid = (lo + hi) >> 1
        if x < grid[mid]:
            hi = mid
        else:
            lo = mid + 1
    return lo - 1


@njit(cache=True, error_model="numpy")
def hold_and_wind(
    q: np.ndarray, valid: np.ndarray, s: np.ndarray, s_grid: np.ndarray, q_grid: np.ndarray
) -> None:  # pragma: no cover - compiled
    """Kernel: one branch's joints held over the poses it misses and wound, in place.

    A pose the branch does not reach takes the joints of the reachable pose before it (the
    first reachable one before them all); every joint is then moved by the multiple of 2π
    that brings it nearest the reference, the linear interpolation of ``q_grid`` at ``s``
    (``numpy.interp``'s formula, its end values outside the grid). With no reachable pose
    the joints stay as they are (NaN).

    Parameters
    ----------
    q
        Joint positions, shape (M, n), rad (changed in place).
    valid
        Shape (M,), bool: the branch reaches the pose.
    s
        Where each pose lies, shape (M,).
    s_grid, q_grid
        Reference: strictly increasing abscissae (G,) and the joints there (G, n), rad.
    """
    n_poses, n = q.shape
    n_grid = s_grid.shape[0]
    two_pi = 2.0 * math.pi
    held = np.empty(n)
    first = -1
    for m in range(n_poses):
        if valid[m]:
            first = m
            break
    for j in range(n):
        held[j] = q[first, j] if first >= 0 else np.nan
    i = -1
    for m in range(n_poses):
        if first < 0 or valid[m]:
            for j in range(n):
                held[j] = q[m, j]
        x = s[m]
        i = _interval(s_grid, x, i)
        for j in range(n):
            if i < 0:
                reference = q_grid[0, j]
            elif i >= n_grid - 1:
                reference = q_grid[n_grid - 1, j]
            else:
                slope = (q_grid[i + 1, j] - q_grid[i, j]) / (s_grid[i + 1] - s_grid[i])
                reference = slope * (x - s_grid[i]) + q_grid[i, j]
            q[m, j] = held[j] - two_pi * np.rint((held[j] - reference) / two_pi)


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
    arguments (the expressions of :func:`opw_solve` for one shoulder and elbow,
    unreachable poses computed through and marked), their arctangents, the joints.
    """
    a1 = g[O_A1]
    b_off = g[O_B]
    c1 = g[O_C1]
    c2 = g[O_C2]
    c4 = g[O_C4]
    kappa = g[O_KAPPA]
    cpsi = g[O_CPSI]
    spsi = g[O_SPSI]
    bx = g[O_BX]
    by = g[O_BY]
    c40 = g[O_C40]
    s40 = g[O_S40]
    shoulder = (branch >> 2) & 1
    elbow = (branch >> 1) & 1
    arm = 2 * shoulder + elbow
    flip = branch & 1
    xr_sign = 1.0 if shoulder == 0 else -1.0
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
    angles = np.empty(O_N_ANGLES)
    slots = (O_TH1 + shoulder, O_PHI + shoulder, O_TH2 + arm)
    wrist = O_WRIST + 3 * arm
    for start in range(0, n_poses, BLOCK):
        m = min(BLOCK, n_poses - start)
        for b in range(m):
            Rk = R[0 if one_rotation else start + b]
            for i in range(3):
                for c in range(3):
                    P[4 * i + c, b] = Rk[i, c]
                P[4 * i + 3, b] = p[start + b, i]
        for b in range(BLOCK):
            w00 = P[0, b] * tail_inv[0, 0] + P[1, b] * tail_inv[1, 0]
            w00 = w00 + P[2, b] * tail_inv[2, 0] + P[3, b] * tail_inv[3, 0]
            w02 = P[0, b] * tail_inv[0, 2] + P[1, b] * tail_inv[1, 2]
            w02 = w02 + P[2, b] * tail_inv[2, 2] + P[3, b] * tail_inv[3, 2]
            w03 = P[0, b] * tail_inv[0, 3] + P[1, b] * tail_inv[1, 3]
            w03 = w03 + P[2, b] * tail_inv[2, 3] + P[3, b] * tail_inv[3, 3]
            w10 = P[4, b] * tail_inv[0, 0] + P[5, b] * tail_inv[1, 0]
            w10 = w10 + P[6, b] * tail_inv[2, 0] + P[7, b] * tail_inv[3, 0]
            w12 = P[4, b] * tail_inv[0, 2] + P[5, b] * tail_inv[1, 2]
            w12 = w12 + P[6, b] * tail_inv[2, 2] + P[7, b] * tail_inv[3, 2]
            w13 = P[4, b] * tail_inv[0, 3] + P[5, b] * tail_inv[1, 3]
            w13 = w13 + P[6, b] * tail_inv[2, 3] + P[7, b] * tail_inv[3, 3]
            w20 = P[8, b] * tail_inv[0, 0] + P[9, b] * tail_inv[1, 0]
            w20 = w20 + P[10, b] * tail_inv[2, 0] + P[11, b] * tail_inv[3, 0]
            w22 = P[8, b] * tail_inv[0, 2] + P[9, b] * tail_inv[1, 2]
            w22 = w22 + P[10, b] * tail_inv[2, 2] + P[11, b] * tail_inv[3, 2]
            w23 = P[8, b] * tail_inv[0, 3] + P[9, b] * tail_inv[1, 3]
            w23 = w23 + P[10, b] * tail_inv[2, 3] + P[11, b] * tail_inv[3, 3]
            cx = w03 - c4 * w02 - bx
            cy = w13 - c4 * w12 - by
            cz = w23 - c4 * w22
            r2 = cx * cx + cy * cy - b_off * b_off
            r = math.sqrt(max(r2, 0.0))
            xr = xr_sign * r
            c1_, s1_ = unit(cx * xr + cy * b_off, cy * xr - cx * b_off)
            dx = xr - a1
            dz = cz - c1
            K = (dx * dx + dz * dz - c2 * c2 - kappa * kappa) / (2.0 * c2 * kappa)
            ok[b] = not (r2 < -REACH_TOL or abs(K) > 1.0 + REACH_TOL)
            K = min(max(K, -1.0), 1.0)
            sphi = math.sqrt((1.0 - K) * (1.0 + K))
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
            Y[0, b] = s1_
            X[0, b] = c1_
            Y[1, b] = sphi
            X[1, b] = K
            Y[2, b] = s2_
            X[2, b] = c2_
            Y[3, b] = s4_
            X[3, b] = c4_
            Y[4, b] = s5
            X[4, b] = c5
            Y[5, b] = n10
            X[5, b] = c5 * n00 - s5 * m20
            aux[0, b] = r
            aux[1, b] = sphi
            aux[2, b] = z1 * w22 - c23 * w12
            aux[3, b] = c23 * w02 - z0 * w22
            aux[4, b] = z0 * w12 - z1 * w02
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
            angles[slots[0]] = A[0, b]
            angles[slots[1]] = A[1, b]
            angles[slots[2]] = A[2, b]
            angles[wrist] = A[3, b]
            angles[wrist + 1] = A[4, b]
            angles[wrist + 2] = A[5, b]
            _opw_joints(g, angles, arm, flip, q[k])
    if s_grid.shape[0] > 0:
        hold_and_wind(q, valid, s, s_grid, q_grid)


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
    _unreachable(valid, aux, 0, N_BRANCHES)
    w00, w01, w02, w03, w10, w11, w12, w13, w20, w21, w22, w23 = _wrist_frame(T, tail_inv)
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
        _atan2_all(Y, X, angles)
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
            w00 = _wrist_entry(P, b, 0, 0, tail_inv)
            w01 = _wrist_entry(P, b, 0, 1, tail_inv)
            w02 = _wrist_entry(P, b, 0, 2, tail_inv)
            w03 = _wrist_entry(P, b, 0, 3, tail_inv)
            w10 = _wrist_entry(P, b, 1, 0, tail_inv)
            w11 = _wrist_entry(P, b, 1, 1, tail_inv)
            w12 = _wrist_entry(P, b, 1, 2, tail_inv)
            w13 = _wrist_entry(P, b, 1, 3, tail_inv)
            w20 = _wrist_entry(P, b, 2, 0, tail_inv)
            w21 = _wrist_entry(P, b, 2, 1, tail_inv)
            w22 = _wrist_entry(P, b, 2, 2, tail_inv)
            w23 = _wrist_entry(P, b, 2, 3, tail_inv)
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
