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
``g`` the component of ``a5`` the forearm direction sees, ``P⊥ = (P_w, −P_u)``) is smooth
in t, also where the elbow stretches (F > 0 out of reach), so its roots are found by
sampling t on a fixed grid (:data:`N_SAMPLES` points), bracketing each sign change (and the
pair of roots hidden in an interval where |F| has a small local minimum) and refining each
root by the Illinois false-position method to 1e-13 rad; each root becomes the joints of the
elbow(s) that vanish there, each checked by the model's FK (:data:`FK_TOL`).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from trackplan.robots.families._kernels import wrap

# Geometry vector.
(C_A1, C_A2, C_B, C_C1, C_C2, C_C3, C_C4, C_L5, C_BX, C_BY, C_DUAL, C_TOL) = range(12)
C_THETA0 = 12  # six zero offsets θ0 follow, then six signs
C_SIGN = 18
C_SIZE = 24

N_MAX = 16
"""Most solutions of a pose (8 roots of F per shoulder pair; Abbes & Poisson 2024)."""

N_SAMPLES = 96
"""Grid points of t = θ6 on [0, 2π) at which F is sampled to bracket its roots."""

FK_TOL = 1e-9
"""Largest FK error of a returned solution: position (m) and rotation matrix entries."""

ARM_TOL = 1e-6
"""Largest residual a4 · a5 of an arm at a root of F for the arm to be polished and tried."""

ROOT_TOL = 1e-13
"""Width (rad) of the bracket at which a root of F counts as found."""

SUSPICIOUS = 0.05
"""An interval is sampled finer when |F| at one end is below this fraction of |F| around."""

N_SUB = 16
"""Intervals a suspicious interval is cut into (twice at most)."""

TOUCH = 1e-12
"""|F| below this fraction of its largest sampled |F| counts as zero: a double root, where
two solutions meet (a singular pose), is kept; the FK check drops a false one."""

ROOT_SAME = 1e-10
"""Roots of F closer than this (rad) are one (found twice on overlapping intervals)."""

_MAX_ROOTS = 48  # roots of F per shoulder kept (at most 8 expected; room for repeats)
_MAX_TODO = 32  # suspicious intervals sampled finer per shoulder


@njit(cache=True, error_model="numpy", inline="always")
def _arm_point(
    g: np.ndarray, R: np.ndarray, O6: np.ndarray, ct: float, st: float
) -> tuple[float, float, float, float, float, float]:  # pragma: no cover - compiled
    """O5 (X, Y, Z) and a5 (x, y, z) for θ6 with cosine ct and sine st."""
    a5x = st * R[0, 0] + ct * R[0, 1]
    a5y = st * R[1, 0] + ct * R[1, 1]
    a5z = st * R[2, 0] + ct * R[2, 1]
    l5 = g[C_L5]
    return O6[0] - l5 * a5x, O6[1] - l5 * a5y, O6[2] - l5 * a5z, a5x, a5y, a5z


@njit(cache=True, error_model="numpy", inline="always")
def _shoulder(
    g: np.ndarray, X: float, Y: float, Z: float, shoulder: int
) -> tuple[float, float, float, float, bool]:  # pragma: no cover - compiled
    """cos θ1, sin θ1 and the arm-plane point P = (u, w) of O5 from joint 2; False when O5
    lies within the lateral offset b of axis 1 (no θ1)."""
    b = g[C_B]
    h2 = X * X + Y * Y
    d = h2 - b * b
    if d < 0.0 or h2 == 0.0:
        return 1.0, 0.0, 0.0, 0.0, False
    xp = math.sqrt(d)
    if shoulder == 1:
        xp = -xp
    c1 = (xp * X + b * Y) / h2
    s1 = (xp * Y - b * X) / h2
    return c1, s1, xp - g[C_A1], Z - g[C_C1], True


@njit(cache=True, error_model="numpy", inline="always")
def _residual(
    g: np.ndarray, R: np.ndarray, O6: np.ndarray, ct: float, st: float, shoulder: int
) -> float:  # pragma: no cover - compiled
    """F(t) of one shoulder (module docstring) times ``X² + Y²``; NaN where the shoulder
    has no θ1. With a1 = b = a2 = 0 (``dual``) both shoulders share it, and it is a
    polynomial in O5 and a5, smooth also where O5 passes axis 1."""
    X, Y, Z, a5x, a5y, a5z = _arm_point(g, R, O6, ct, st)
    if g[C_DUAL] > 0.5:
        c2, c3 = g[C_C2], g[C_C3]
        h2 = X * X + Y * Y
        pw = Z - g[C_C1]
        rho2 = h2 + pw * pw
        K1 = rho2 - c2 * c2 + c3 * c3
        K2 = c2 * c2 + rho2 - c3 * c3
        Pg = X * a5x + Y * a5y + pw * a5z
        Qh = pw * (X * a5x + Y * a5y) - h2 * a5z
        return h2 * K1 * K1 * Pg * Pg - (4.0 * c2 * c2 * rho2 - K2 * K2) * Qh * Qh
    c1, s1, pu, pw, ok = _shoulder(g, X, Y, Z, shoulder)
    if not ok:
        return math.nan
    a2, c2, c3 = g[C_A2], g[C_C2], g[C_C3]
    A1 = c1 * a5x + s1 * a5y
    gu = c3 * A1 + a2 * a5z
    gw = c3 * a5z - a2 * A1
    rho2 = pu * pu + pw * pw
    k2 = a2 * a2 + c3 * c3
    K1 = rho2 - c2 * c2 + k2
    K2 = c2 * c2 + rho2 - k2
    Pg = pu * gu + pw * gw
    Qg = pw * gu - pu * gw
    return (X * X + Y * Y) * (K1 * K1 * Pg * Pg - (4.0 * c2 * c2 * rho2 - K2 * K2) * Qg * Qg)


@njit(cache=True, error_model="numpy", inline="always")
def _residual_at(
    g: np.ndarray, R: np.ndarray, O6: np.ndarray, t: float, shoulder: int
) -> float:  # pragma: no cover - compiled
    """F at the angle t, rad."""
    return _residual(g, R, O6, math.cos(t), math.sin(t), shoulder)


@njit(cache=True, error_model="numpy")
def _refine(
    g: np.ndarray,
    R: np.ndarray,
    O6: np.ndarray,
    shoulder: int,
    ta: float,
    fa: float,
    tb: float,
    fb: float,
) -> float:  # pragma: no cover - compiled
    """The root of F in [ta, tb] (fa, fb of opposite signs): Illinois false position with
    a bisection every third step when the bracket has not halved since the last."""
    side = 0
    width = tb - ta
    for it in range(100):
        if tb - ta <= ROOT_TOL:
            break
        t = (ta * fb - tb * fa) / (fb - fa)
        if not (ta < t < tb) or (it % 3 == 2 and tb - ta > 0.5 * width):
            t = 0.5 * (ta + tb)
        if it % 3 == 2:
            width = tb - ta
        f = _residual_at(g, R, O6, t, shoulder)
        if f == 0.0 or math.isnan(f):
            return t
        if (f > 0.0) == (fb > 0.0):
            tb, fb = t, f
            if side == 1:
                fa *= 0.5
            side = 1
        else:
            ta, fa = t, f
            if side == -1:
                fb *= 0.5
            side = -1
    return ta if abs(fa) < abs(fb) else tb


@njit(cache=True, error_model="numpy")
def _dip(
    g: np.ndarray,
    R: np.ndarray,
    O6: np.ndarray,
    shoulder: int,
    x0: float,
    x1: float,
    x2: float,
    y0: float,
    y1: float,
    y2: float,
) -> tuple[float, bool]:  # pragma: no cover - compiled
    """Where F, of one sign s at x0 < x1 < x2 (s·y1 below s·y0 and s·y2), crosses zero
    near its least value, by successive parabolic interpolation: (that point, True); or
    (where |F| is least, False) when the parabolas show a minimum of the same sign (no
    root pair there, or a double root where that least |F| is zero)."""
    s = 1.0 if y1 > 0.0 else -1.0
    y0, y1, y2 = s * y0, s * y1, s * y2
    for _ in range(40):
        d0, d2 = x0 - x1, x2 - x1
        e0, e2 = y0 - y1, y2 - y1
        den = e0 * d2 - e2 * d0
        if den == 0.0:
            break
        # vertex of the parabola through the three points, relative to x1
        step = 0.5 * (e0 * d2 * d2 - e2 * d0 * d0) / den
        if abs(step) < 1e-6 * (x2 - x0):  # the vertex at the middle point: look beside it
            step = 1e-3 * (x2 - x0) if y2 < y0 else -1e-3 * (x2 - x0)
        xv = x1 + step
        if not (x0 < xv < x2):
            break
        # the parabola's value at its vertex
        curv = (e0 / d0 - e2 / d2) / (d0 - d2)
        predicted = y1 - curv * step * step
        if predicted > 0.0 and y1 - predicted <= 1e-3 * y1:
            break  # converged to a minimum above zero
        yv = s * _residual_at(g, R, O6, xv, shoulder)
        if yv <= 0.0:
            return xv, True
        if yv >= y1:  # the vertex is no better: narrow the triple around x1
            if xv < x1:
                x0, y0 = xv, yv
            else:
                x2, y2 = xv, yv
        elif xv < x1:
            x2, y2, x1, y1 = x1, y1, xv, yv
        else:
            x0, y0, x1, y1 = x1, y1, xv, yv
        if x2 - x0 < 1e-12:
            break
    return x1, False


@njit(cache=True, error_model="numpy", inline="always")
def _suspicious(fp: float, fa: float, fb: float, fn: float) -> bool:  # pragma: no cover
    """Whether the interval between samples fa and fb (fp before, fn after; NaN where
    there is none) may hide roots the samples do not show: one end is near zero against
    the local size of F (a root cluster near a cusp makes F tiny over a few samples)."""
    size = max(abs(fa), abs(fb))
    if not math.isnan(fp):
        size = max(size, abs(fp))
    if not math.isnan(fn):
        size = max(size, abs(fn))
    return min(abs(fa), abs(fb)) < SUSPICIOUS * size


@njit(cache=True, error_model="numpy")
def _scan(
    g: np.ndarray,
    R: np.ndarray,
    O6: np.ndarray,
    shoulder: int,
    ts: np.ndarray,
    fs: np.ndarray,
    n_pts: int,
    periodic: bool,
    roots: np.ndarray,
    n: int,
    todo: np.ndarray,
    n_todo: int,
    deeper: bool,
    touch: float,
) -> tuple[int, int]:  # pragma: no cover - compiled
    """The roots that samples fs of F at ts (n_pts, ascending) show: each sign change
    refined (:func:`_refine`), each least |F| without a sign change searched for a root
    pair (:func:`_dip`); a suspicious interval (:func:`_suspicious`) is put on ``todo``
    (rows (start, end)) to be sampled finer when ``deeper``, instead of refined here.
    ``periodic``: the last sample is followed by the first (the whole circle). A |F| at
    most ``touch`` counts as zero (a double root, F touching zero, is kept so).

    Returns
    -------
    n, n_todo
        The counts of roots and of intervals to do.
    """
    n_int = n_pts if periodic else n_pts - 1
    for j in range(n_int):
        if n > roots.shape[0] - 4:
            break
        k = (j + 1) % n_pts
        fa, fb = fs[j], fs[k]
        ta = ts[j]
        tb = ts[k] if k > j else ts[k] + 2.0 * math.pi
        if math.isnan(fa) or math.isnan(fb):
            continue
        fp = fs[(j - 1) % n_pts] if (periodic or j > 0) else math.nan
        fn = fs[(j + 2) % n_pts] if (periodic or j + 2 < n_pts) else math.nan
        if deeper and n_todo < todo.shape[0] and _suspicious(fp, fa, fb, fn):
            todo[n_todo, 0], todo[n_todo, 1] = ta, tb
            n_todo += 1
        else:
            if abs(fa) <= touch:  # a root here, or a double root: the FK check decides
                roots[n] = ta
                n += 1
            if (fa > 0.0) != (fb > 0.0):
                roots[n] = _refine(g, R, O6, shoulder, ta, fa, tb, fb)
                n += 1
        # least |F| at sample j without a sign change on either side: a hidden pair?
        if math.isnan(fp) or abs(fa) <= touch or abs(fb) <= touch:
            continue
        if (fp > 0.0) != (fa > 0.0) or (fb > 0.0) != (fa > 0.0):
            continue
        if not (abs(fa) < abs(fp) and abs(fa) <= abs(fb)):
            continue
        lo = ta - (ts[j] - ts[(j - 1) % n_pts]) % (2.0 * math.pi) if periodic else ts[j - 1]
        tm, crossed = _dip(g, R, O6, shoulder, lo, ta, tb, fp, fa, fb)
        fm = _residual_at(g, R, O6, tm, shoulder)
        if not crossed:
            if abs(fm) <= touch:  # a double root (F touches zero)
                roots[n] = tm
                n += 1
            continue
        roots[n] = _refine(g, R, O6, shoulder, lo, fp, tm, fm)
        roots[n + 1] = _refine(g, R, O6, shoulder, tm, fm, tb, fb)
        n += 2
    return n, n_todo


@njit(cache=True, error_model="numpy")
def _roots(
    g: np.ndarray,
    R: np.ndarray,
    O6: np.ndarray,
    shoulder: int,
    grid: np.ndarray,
    cos_t: np.ndarray,
    sin_t: np.ndarray,
    F: np.ndarray,
    roots: np.ndarray,
    todo: np.ndarray,
) -> int:  # pragma: no cover - compiled
    """The distinct roots of F of one shoulder in [0, 2π), ascending, into ``roots``;
    their count.

    F is sampled on the grid (:data:`N_SAMPLES`) and scanned (:func:`_scan`); each
    suspicious interval is sampled again at :data:`N_SUB` points and scanned, and so once
    more (three levels: down to 1/(N_SAMPLES · N_SUB²) of a turn).
    """
    m = cos_t.shape[0]
    for j in range(m):
        F[j] = _residual(g, R, O6, cos_t[j], sin_t[j], shoulder)
    scale = 0.0
    for j in range(m):
        if not math.isnan(F[j]):
            scale = max(scale, abs(F[j]))
    touch = TOUCH * scale
    n, n_todo = _scan(g, R, O6, shoulder, grid, F, m, True, roots, 0, todo, 0, True, touch)
    sub_t = np.empty(N_SUB + 3)
    sub_f = np.empty(N_SUB + 3)
    done = 0
    while done < n_todo:
        ta, tb = todo[done, 0], todo[done, 1]
        level = 1 if tb - ta > 1.5 * (grid[1] - grid[0]) / N_SUB else 2
        done += 1
        for k in range(N_SUB + 3):  # one point beyond each end: dips at the ends too
            sub_t[k] = ta + (tb - ta) * (k - 1) / N_SUB
            sub_f[k] = _residual_at(g, R, O6, sub_t[k], shoulder)
        n, n_todo = _scan(
            g,
            R,
            O6,
            shoulder,
            sub_t,
            sub_f,
            N_SUB + 3,
            False,
            roots,
            n,
            todo,
            n_todo,
            level < 2,
            touch,
        )
    for i in range(n):  # into [0, 2π), ascending, repeats dropped
        roots[i] = roots[i] % (2.0 * math.pi)
    roots[:n].sort()
    kept = 0
    for i in range(n):
        if kept == 0 or roots[i] - roots[kept - 1] > ROOT_SAME:
            roots[kept] = roots[i]
            kept += 1
    return kept


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
