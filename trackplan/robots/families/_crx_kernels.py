"""Compiled kernels of the CRX family's IK: every solution of a pose, by one angle.

The model (:mod:`trackplan.robots.families.crx`) is the OPW arm with an offset wrist::

    R = Rz(θ1) Ry(θ2 + θ3) Rz(θ4) Ry(θ5) Rz(θ6)
    O5 = Rz(θ1) [(a1, b, c1) + Ry(θ2) (0, 0, c2) + Ry(θ2 + θ3) (a2, 0, c3)]
    O6 = O5 + l5 · a5,  a5 = Rz(θ1) Ry(θ2 + θ3) Rz(θ4) e_y   (the axis of joint 5)
    flange = O6 + c4 · R e_z

The pose fixes the axis of joint 6 (``a6 = R e_z`` through ``O6``); ``a5 = R (sin θ6,
cos θ6, 0)`` is perpendicular to it, so θ6 = t alone places ``O5(t) = O6 − l5 a5(t)``
on a circle about the axis of joint 6 (M. Abbes, G. Poisson, "Geometric Approach for
Inverse Kinematics of the FANUC CRX Collaborative Robot", Robotics 13(6):91, 2024). For
each t, the arm's position IK puts joints 1–3 so that the axis of joint 4 (``a4``) passes
through ``O5``: per shoulder two elbows, ``f±(t) = a4 · a5``, and a solution is a root of
one of them (joint 4 then turns ``a5`` into place exactly). Their product, multiplied by
``4ρ⁴k⁴``,

    F(t) = (ρ² − c2² + k²)² (P·g)² − (4 c2² ρ² − (c2² + ρ² − k²)²) (P⊥·g)²

(``P`` the point ``O5`` in the arm plane from joint 2, ``ρ = |P|``, ``k² = a2² + c3²``,
``g`` the component of ``a5`` the forearm direction sees, ``P⊥ = (P_w, −P_u)``), times
``X² + Y²`` of O5, is smooth in t also where the elbow stretches (F > 0 out of reach) and,
when a1 = b = a2 = 0, where O5 passes axis 1 (it is then a polynomial in O5 and a5). Its
roots are found by :func:`~trackplan.robots.families._crx_roots._roots` (a grid of
:data:`N_SAMPLES` values of t, sign changes refined to 1e-13 rad, hidden pairs, clusters
sampled finer); each root becomes the joints of the elbow(s) that vanish there (polished by
Newton steps on that arm's own residual where F has a double root), each checked by the
model's FK (:data:`FK_TOL`).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from trackplan.robots.families._crx_roots import (
    _MAX_ROOTS,
    _MAX_TODO,
    C_A1,
    C_A2,
    C_B,
    C_BX,
    C_BY,
    C_C1,
    C_C2,
    C_C3,
    C_C4,
    C_DUAL,
    C_L5,
    C_SIGN,
    C_SIZE,
    C_THETA0,
    C_TOL,
    _arm_point,
    _roots,
    _shoulder,
)
from trackplan.robots.families._kernels import wrap

N_MAX = 16
"""Most solutions of a pose (8 roots of F per shoulder pair; Abbes & Poisson 2024)."""

N_SAMPLES = 96
"""Grid points of t = θ6 on [0, 2π) at which F is sampled to bracket its roots."""

FK_TOL = 1e-9
"""Largest FK error of a returned solution: position (m) and rotation matrix entries."""

ARM_TOL = 1e-6
"""Largest residual a4 · a5 of an arm at a root of F for the arm to be polished and tried."""


@njit(cache=True, error_model="numpy")
def _joints(
    g: np.ndarray,
    R: np.ndarray,
    O6: np.ndarray,
    t: float,
    shoulder: int,
    elbow: int,
    theta: np.ndarray,
) -> tuple[bool, float]:  # pragma: no cover - compiled
    """The model angles θ (6,) of one shoulder and elbow at the angle t, and that arm's
    residual ``a4 · a5`` (zero at a solution); False when that arm does not exist there."""
    ct, st = math.cos(t), math.sin(t)
    X, Y, Z, a5x, a5y, a5z = _arm_point(g, R, O6, ct, st)
    c1, s1, pu, pw, ok = _shoulder(g, X, Y, Z, shoulder)
    if not ok:
        return False, math.nan
    a2, c2, c3 = g[C_A2], g[C_C2], g[C_C3]
    rho2 = pu * pu + pw * pw
    if rho2 == 0.0:
        return False, math.nan
    rho = math.sqrt(rho2)
    k2 = a2 * a2 + c3 * c3
    along = (c2 * c2 + rho2 - k2) / (2.0 * rho)  # O3 along P, from joint 2
    h2 = c2 * c2 - along * along
    if h2 < -1e-9 * c2 * c2:
        return False, math.nan
    h = math.sqrt(max(h2, 0.0)) * (1.0 if elbow == 0 else -1.0)
    eu, ew = pu / rho, pw / rho
    o3u = along * eu + h * ew
    o3w = along * ew - h * eu
    du, dw = pu - o3u, pw - o3w
    # sin and cos of θ23 from the forearm d = (du, dw), |d| = k
    s23 = (du * c3 - dw * a2) / k2
    c23 = (dw * c3 + du * a2) / k2
    # w = (Rz(θ1) Ry(θ23))ᵀ a5; its z (a4 · a5) vanishes at a solution of this arm
    A1 = c1 * a5x + s1 * a5y
    wz = s23 * A1 + c23 * a5z
    if abs(wz) > 1e-6:
        return False, math.nan
    wx = c23 * A1 - s23 * a5z
    wy = -s1 * a5x + c1 * a5y
    t1 = math.atan2(s1, c1)
    t2 = math.atan2(o3u, o3w)
    t23 = math.atan2(s23, c23)
    t4 = math.atan2(-wx, wy)
    c4, s4 = math.cos(t4), math.sin(t4)
    # v = (Rz(θ1) Ry(θ23) Rz(θ4))ᵀ a6
    a6x, a6y, a6z = R[0, 2], R[1, 2], R[2, 2]
    A6 = c1 * a6x + s1 * a6y
    B6 = -s1 * a6x + c1 * a6y
    ux = c23 * A6 - s23 * a6z
    uz = s23 * A6 + c23 * a6z
    vx = c4 * ux + s4 * B6
    t5 = math.atan2(vx, uz)
    theta[0], theta[1], theta[2] = t1, t2, t23 - t2
    theta[3], theta[4], theta[5] = t4, t5, t
    return True, wz


@njit(cache=True, error_model="numpy")
def _polish(
    g: np.ndarray,
    R: np.ndarray,
    O6: np.ndarray,
    t: float,
    shoulder: int,
    elbow: int,
    theta: np.ndarray,
) -> tuple[float, bool]:  # pragma: no cover - compiled
    """A root t of F made a root of its own arm's residual ``a4 · a5`` by a few
    safeguarded Newton steps (a root of F where both elbows vanish at once is a double
    root of F, known to only about 1e-8 rad; each elbow's residual has a simple root
    there), θ (6,) set at it; False when that arm is not a solution near t."""
    ok, w = _joints(g, R, O6, t, shoulder, elbow, theta)
    if not ok or abs(w) > ARM_TOL:
        return t, False
    for _ in range(8):
        if abs(w) < 1e-16:
            break
        ok, w_h = _joints(g, R, O6, t + 1e-7, shoulder, elbow, theta)
        if not ok or w_h == w:
            break
        t_new = t - w * 1e-7 / (w_h - w)
        if abs(t_new - t) > 1e-4:
            break
        ok, w_new = _joints(g, R, O6, t_new, shoulder, elbow, theta)
        if not ok or abs(w_new) >= abs(w):
            break
        t, w = t_new, w_new
    ok, w = _joints(g, R, O6, t, shoulder, elbow, theta)
    return t, ok


@njit(cache=True, error_model="numpy")
def crx_forward(g: np.ndarray, theta: np.ndarray, T: np.ndarray) -> None:  # pragma: no cover
    """The model's flange pose (module docstring) at angles θ (6,), into T (4, 4), without
    the base shift."""
    c1, s1 = math.cos(theta[0]), math.sin(theta[0])
    c2, s2 = math.cos(theta[1]), math.sin(theta[1])
    t23 = theta[1] + theta[2]
    c23, s23 = math.cos(t23), math.sin(t23)
    c4, s4 = math.cos(theta[3]), math.sin(theta[3])
    c5, s5 = math.cos(theta[4]), math.sin(theta[4])
    c6, s6 = math.cos(theta[5]), math.sin(theta[5])
    x = g[C_A1] + g[C_C2] * s2 + g[C_A2] * c23 + g[C_C3] * s23
    z = g[C_C1] + g[C_C2] * c2 - g[C_A2] * s23 + g[C_C3] * c23
    l5, c4_ = g[C_L5], g[C_C4]
    # R = Rz1 · Ry23 · Rz4 · Ry5 · Rz6, one row at a time in scalars
    for i in range(3):
        if i == 0:
            f0, f1, f2 = c1 * c23, -s1, c1 * s23
        elif i == 1:
            f0, f1, f2 = s1 * c23, c1, s1 * s23
        else:
            f0, f1, f2 = -s23, 0.0, c23
        h0 = c4 * f0 + s4 * f1  # row of F4 = F3 · Rz4
        h1 = -s4 * f0 + c4 * f1
        k0 = c5 * h0 - s5 * f2  # row of F5 = F4 · Ry5
        k2 = s5 * h0 + c5 * f2
        T[i, 0] = c6 * k0 + s6 * h1
        T[i, 1] = -s6 * k0 + c6 * h1
        T[i, 2] = k2
        T[i, 3] = l5 * h1 + c4_ * k2
        T[3, i] = 0.0
    T[3, 3] = 1.0
    T[0, 3] += c1 * x - s1 * g[C_B]
    T[1, 3] += s1 * x + c1 * g[C_B]
    T[2, 3] += z


@njit(cache=True, error_model="numpy", inline="always")
def _fk_error(
    g: np.ndarray, theta: np.ndarray, R: np.ndarray, p: np.ndarray, T: np.ndarray
) -> float:  # pragma: no cover
    """Largest |entry| of the model's flange pose at θ minus (R, p) (positions m)."""
    crx_forward(g, theta, T)
    err = 0.0
    for i in range(3):
        err = max(err, abs(T[i, 3] - p[i]))
        for k in range(3):
            err = max(err, abs(T[i, k] - R[i, k]))
    return err


@njit(cache=True, error_model="numpy", nogil=True)
def crx_solve(
    g: np.ndarray,
    tail_inv: np.ndarray,
    T_in: np.ndarray,
    cos_t: np.ndarray,
    sin_t: np.ndarray,
    q: np.ndarray,
    valid: np.ndarray,
    angle: np.ndarray,
) -> None:  # pragma: no cover - compiled
    """Kernel: every IK solution of poses T_in (N, 4, 4), m, into q (N, 16, 6) (rad in
    (−π, π], NaN past the found ones), valid (N, 16) and angle (N, 16) (the root θ6 in
    [0, 2π) each solution came from), found ones first, by root angle then shoulder
    then elbow. ``cos_t``, ``sin_t``: the sampling grid of t (:data:`N_SAMPLES`,).
    """
    n_poses = T_in.shape[0]
    m = cos_t.shape[0]
    F = np.empty(m)
    roots = np.empty((2, _MAX_ROOTS))
    n_roots = np.zeros(2, dtype=np.int64)
    R = np.empty((3, 3))
    p = np.empty(3)
    O6 = np.empty(3)
    theta = np.empty(6)
    Tm = np.empty((4, 4))
    cand = np.empty((4 * 2 * _MAX_ROOTS, 6))
    cand_t = np.empty(4 * 2 * _MAX_ROOTS)
    cand_k = np.empty(4 * 2 * _MAX_ROOTS, dtype=np.int64)
    qj = np.empty(6)
    dual = g[C_DUAL] > 0.5
    tol = g[C_TOL]
    theta0 = g[C_THETA0:C_SIGN]
    sign = g[C_SIGN:C_SIZE]
    grid = np.arange(m) * (2.0 * math.pi / m)
    todo = np.empty((_MAX_TODO, 2))
    for i in range(n_poses):
        # the model's flange pose: T · tail_inv, less the base shift
        for r in range(3):
            for c in range(3):
                R[r, c] = (
                    T_in[i, r, 0] * tail_inv[0, c]
                    + T_in[i, r, 1] * tail_inv[1, c]
                    + T_in[i, r, 2] * tail_inv[2, c]
                )
            p[r] = (
                T_in[i, r, 0] * tail_inv[0, 3]
                + T_in[i, r, 1] * tail_inv[1, 3]
                + T_in[i, r, 2] * tail_inv[2, 3]
                + T_in[i, r, 3]
            )
        p[0] -= g[C_BX]
        p[1] -= g[C_BY]
        for r in range(3):
            O6[r] = p[r] - g[C_C4] * R[r, 2]
        n_search = 1 if dual else 2
        for s in range(n_search):
            n_roots[s] = _roots(g, R, O6, s, grid, cos_t, sin_t, F, roots[s], todo)
        n_cand = 0
        for s in range(n_search):
            for k in range(n_roots[s]):
                t = roots[s, k]
                for sh in range(2):
                    if not dual and sh != s:
                        continue
                    for e in range(2):
                        ok, w = _joints(g, R, O6, t, sh, e, theta)
                        if not ok or abs(w) > ARM_TOL:
                            continue
                        t_arm = t
                        if not _fk_error(g, theta, R, p, Tm) <= tol:
                            # a double root of F: polish on this arm's own residual
                            t_arm, ok = _polish(g, R, O6, t, sh, e, theta)
                            if not ok or not _fk_error(g, theta, R, p, Tm) <= tol:
                                continue
                        for j in range(6):
                            qj[j] = wrap((theta[j] - theta0[j]) * sign[j])
                        same = False
                        for c in range(n_cand):
                            close = True
                            for j in range(6):
                                if abs(wrap(cand[c, j] - qj[j])) > 1e-6:
                                    close = False
                                    break
                            if close:
                                same = True
                                break
                        if same:
                            continue
                        cand[n_cand] = qj
                        cand_t[n_cand] = t_arm
                        cand_k[n_cand] = 2 * sh + e
                        n_cand += 1
        # order by (root angle, shoulder, elbow): insertion sort of at most a few dozen
        for a in range(1, n_cand):
            b = a
            while b > 0 and (
                cand_t[b - 1] > cand_t[b]
                or (cand_t[b - 1] == cand_t[b] and cand_k[b - 1] > cand_k[b])
            ):
                cand_t[b - 1], cand_t[b] = cand_t[b], cand_t[b - 1]
                cand_k[b - 1], cand_k[b] = cand_k[b], cand_k[b - 1]
                for j in range(6):
                    cand[b - 1, j], cand[b, j] = cand[b, j], cand[b - 1, j]
                b -= 1
        n_out = min(n_cand, q.shape[1])
        for k in range(q.shape[1]):
            if k < n_out:
                for j in range(6):
                    q[i, k, j] = cand[k, j]
                valid[i, k] = True
                angle[i, k] = cand_t[k]
            else:
                for j in range(6):
                    q[i, k, j] = math.nan
                valid[i, k] = False
                angle[i, k] = math.nan
