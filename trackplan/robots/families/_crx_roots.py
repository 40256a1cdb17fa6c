"""The roots of the CRX family's residual F(θ6): sampling, bracketing, refinement.

F and the model are described in :mod:`trackplan.robots.families._crx_kernels`, which
turns each root into joints. F is sampled on a grid of θ6; each sign change is refined by
Illinois false position (:func:`_refine`); at each sample where |F| is least among its
neighbours without a sign change, a pair of roots closer than the grid step is looked for
by successive parabolic interpolation (:func:`_dip`); an interval where F is tiny against
its neighbours (a cluster of roots near a cusp, Abbes & Poisson 2024) is sampled
:data:`N_SUB` times finer, twice at most (:func:`_roots`).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

# Geometry vector.
(C_A1, C_A2, C_B, C_C1, C_C2, C_C3, C_C4, C_L5, C_BX, C_BY, C_DUAL, C_TOL) = range(12)
C_THETA0 = 12  # six zero offsets θ0 follow, then six signs
C_SIGN = 18
C_SIZE = 24

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
        return float(h2 * K1 * K1 * Pg * Pg - (4.0 * c2 * c2 * rho2 - K2 * K2) * Qh * Qh)
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
    return float((X * X + Y * Y) * (K1 * K1 * Pg * Pg - (4.0 * c2 * c2 * rho2 - K2 * K2) * Qg * Qg))


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

    F is sampled on the grid (``cos_t``, ``sin_t``: its cosines and sines) and scanned
    (:func:`_scan`); each suspicious interval is sampled again at :data:`N_SUB` points
    and scanned, and so once more (three levels: down to 1/(len(grid) · N_SUB²) of a turn).
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
