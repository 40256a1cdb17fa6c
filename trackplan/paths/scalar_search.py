"""Scalar root finding and bounded minimisation for the corner blends (Brent's methods).

:func:`find_root` is Brent's bracketing root finder as ``scipy.optimize.brentq`` implements
it, and :func:`minimize_bounded` Brent's bounded minimisation as
``scipy.optimize.minimize_scalar(method="bounded")`` does: the same steps in the same
order, so they return the same floats (``tests/paths/test_scalar_search.py`` compares
them). They live here because importing ``scipy.optimize`` took 0.8–0.9 s of CPU under
load on top of everything else ``trackplan optimize`` imports, for two loops that each
blend runs a few dozen times (``docs/benchmarks.md``, "Wall time").
"""

from __future__ import annotations

import math
from collections.abc import Callable

ROOT_XTOL = 2e-12
"""Default absolute tolerance of :func:`find_root` (brentq's)."""
ROOT_RTOL = 4 * 2.220446049250313e-16
"""Relative tolerance of :func:`find_root` (brentq's: 4 machine epsilons)."""
ROOT_ITERATIONS = 100
"""Iterations of :func:`find_root` before it gives up (brentq's)."""
MINIMIZE_EVALUATIONS = 500
"""Evaluations of :func:`minimize_bounded` before it stops (minimize_scalar's)."""


def find_root(f: Callable[[float], float], a: float, b: float, xtol: float = ROOT_XTOL) -> float:
    """A root of ``f`` in the bracket [a, b] (Brent's method, as ``scipy.optimize.brentq``).

    Parameters
    ----------
    f
        A continuous function with ``f(a)`` and ``f(b)`` of opposite signs.
    a, b
        The bracket.
    xtol
        Absolute tolerance; the root is found within ``xtol + 4 eps |x|``.

    Returns
    -------
    float

    Raises
    ------
    ValueError
        When ``f(a)`` and ``f(b)`` have the same sign.
    RuntimeError
        When :data:`ROOT_ITERATIONS` iterations do not converge.
    """
    x_pre, x_cur = float(a), float(b)
    f_pre, f_cur = f(x_pre), f(x_cur)
    if f_pre == 0.0:
        return x_pre
    if f_cur == 0.0:
        return x_cur
    if math.copysign(1.0, f_pre) == math.copysign(1.0, f_cur):
        raise ValueError(f"f({a}) and f({b}) must have opposite signs")
    x_blk = f_blk = s_pre = s_cur = 0.0
    for _ in range(ROOT_ITERATIONS):
        if (
            f_pre != 0.0
            and f_cur != 0.0
            and (math.copysign(1.0, f_pre) != math.copysign(1.0, f_cur))
        ):
            x_blk, f_blk = x_pre, f_pre
            s_pre = s_cur = x_cur - x_pre
        if abs(f_blk) < abs(f_cur):
            x_pre, x_cur, x_blk = x_cur, x_blk, x_cur
            f_pre, f_cur, f_blk = f_cur, f_blk, f_cur
        delta = (xtol + ROOT_RTOL * abs(x_cur)) / 2.0
        s_bis = (x_blk - x_cur) / 2.0
        if f_cur == 0.0 or abs(s_bis) < delta:
            return x_cur
        if abs(s_pre) > delta and abs(f_cur) < abs(f_pre):
            if x_pre == x_blk:  # interpolate
                s_try = -f_cur * (x_cur - x_pre) / (f_cur - f_pre)
            else:  # extrapolate (inverse quadratic)
                d_pre = (f_pre - f_cur) / (x_pre - x_cur)
                d_blk = (f_blk - f_cur) / (x_blk - x_cur)
                s_try = -f_cur * (f_blk * d_blk - f_pre * d_pre) / (d_blk * d_pre * (f_blk - f_pre))
            if 2.0 * abs(s_try) < min(abs(s_pre), 3.0 * abs(s_bis) - delta):
                s_pre, s_cur = s_cur, s_try  # a good short step
            else:
                s_pre = s_cur = s_bis
        else:
            s_pre = s_cur = s_bis
        x_pre, f_pre = x_cur, f_cur
        if abs(s_cur) > delta:
            x_cur += s_cur
        else:
            x_cur += delta if s_bis > 0.0 else -delta
        f_cur = f(x_cur)
    raise RuntimeError(f"no root found in {ROOT_ITERATIONS} iterations in [{a}, {b}]")


def minimize_bounded(f: Callable[[float], float], low: float, high: float, xatol: float) -> float:
    """The minimiser of ``f`` on [low, high] (Brent's golden-section and parabolic steps, as
    ``scipy.optimize.minimize_scalar(method="bounded")``).

    Parameters
    ----------
    f
        The function.
    low, high
        The bounds, ``low ≤ high``.
    xatol
        Absolute tolerance of the minimiser.

    Returns
    -------
    float
        The best point found (a local minimiser; stops after :data:`MINIMIZE_EVALUATIONS`
        evaluations at the latest).
    """
    sqrt_eps = math.sqrt(2.2e-16)
    golden_mean = 0.5 * (3.0 - math.sqrt(5.0))
    a, b = float(low), float(high)
    fulc = a + golden_mean * (b - a)
    nfc = xf = fulc
    rat = e = 0.0
    fx = f(xf)
    n_evaluations = 1
    ffulc = fnfc = fx
    xm = 0.5 * (a + b)
    tol1 = sqrt_eps * abs(xf) + xatol / 3.0
    tol2 = 2.0 * tol1
    while abs(xf - xm) > tol2 - 0.5 * (b - a):
        golden = True
        if abs(e) > tol1:  # try a parabolic fit
            golden = False
            r = (xf - nfc) * (fx - ffulc)
            q = (xf - fulc) * (fx - fnfc)
            p = (xf - fulc) * q - (xf - nfc) * r
            q = 2.0 * (q - r)
            if q > 0.0:
                p = -p
            q = abs(q)
            r, e = e, rat
            if abs(p) < abs(0.5 * q * r) and q * (a - xf) < p < q * (b - xf):
                rat = (p + 0.0) / q
                x = xf + rat
                if (x - a) < tol2 or (b - x) < tol2:
                    rat = tol1 * (_sign(xm - xf) + (xm - xf == 0.0))
            else:
                golden = True
        if golden:
            e = (a - xf) if xf >= xm else (b - xf)
            rat = golden_mean * e
        x = xf + (_sign(rat) + (rat == 0.0)) * max(abs(rat), tol1)
        fu = f(x)
        n_evaluations += 1
        if fu <= fx:
            if x >= xf:
                a = xf
            else:
                b = xf
            fulc, ffulc = nfc, fnfc
            nfc, fnfc = xf, fx
            xf, fx = x, fu
        else:
            if x < xf:
                a = x
            else:
                b = x
            if fu <= fnfc or nfc == xf:
                fulc, ffulc = nfc, fnfc
                nfc, fnfc = x, fu
            elif fu <= ffulc or fulc == xf or fulc == nfc:
                fulc, ffulc = x, fu
        xm = 0.5 * (a + b)
        tol1 = sqrt_eps * abs(xf) + xatol / 3.0
        tol2 = 2.0 * tol1
        if n_evaluations >= MINIMIZE_EVALUATIONS:
            break
    return xf


def _sign(x: float) -> float:
    """-1, 0 or 1 (``numpy.sign`` of a float)."""
    return float((x > 0.0) - (x < 0.0))
