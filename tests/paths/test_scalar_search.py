"""Brent's root finder and bounded minimiser against scipy.optimize (the oracle): same floats."""

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.optimize import brentq, minimize_scalar

from trackplan.paths import blending
from trackplan.paths.blending import g2_blend
from trackplan.paths.curves import Line
from trackplan.paths.scalar_search import find_root, minimize_bounded

coefficient = st.floats(-3.0, 3.0, allow_nan=False)


@settings(max_examples=60, deadline=None, derandomize=True)
@given(coefficient, coefficient, st.floats(0.1, 5.0), st.floats(1e-12, 1e-3))
def test_root_is_brentq(c1: float, c2: float, shift: float, xtol: float) -> None:
    """A cubic with one sign change on the bracket: the same root as brentq, bit for bit."""

    def f(x: float) -> float:
        return (x - shift) * (1.0 + c1 * c1 + (c2 * x) ** 2) + 0.1 * math.sin(3.0 * x)

    a, b = shift - 2.0, shift + 3.0
    if np.sign(f(a)) == np.sign(f(b)):
        return
    assert find_root(f, a, b, xtol) == brentq(f, a, b, xtol=xtol)


def test_root_needs_a_bracket() -> None:
    with pytest.raises(ValueError, match="opposite signs"):
        find_root(lambda x: x * x + 1.0, -1.0, 1.0)


@settings(max_examples=60, deadline=None, derandomize=True)
@given(coefficient, coefficient, st.floats(-2.0, 2.0), st.floats(1e-6, 1e-1))
def test_minimum_is_minimize_scalar(c1: float, c2: float, centre: float, xatol: float) -> None:
    """Smooth and kinked functions, minimum inside or at a bound: the same point as
    minimize_scalar(method="bounded")."""

    def f(x: float) -> float:
        return (x - centre) ** 2 + c1 * math.cos(2.0 * x) + abs(c2) * abs(x - 0.3)

    expected = minimize_scalar(f, bounds=(-1.5, 2.5), method="bounded", options={"xatol": xatol})
    assert minimize_bounded(f, -1.5, 2.5, xatol) == expected.x


@pytest.mark.parametrize("turn", [0.3, 1.2, 2.4, 3.0])
def test_blend_as_with_scipy(monkeypatch: pytest.MonkeyPatch, turn: float) -> None:
    """Corner blends found with these solvers equal those found with scipy's."""
    incoming = Line.between(np.zeros(3), np.array([0.5, 0.0, 0.0]))
    corner = np.array([0.5, 0.0, 0.0])
    outgoing = Line.between(corner, corner + 0.4 * np.array([np.cos(turn), 0.0, np.sin(turn)]))
    ours = g2_blend(incoming, outgoing, budget=1e-3, reach=0.2)
    monkeypatch.setattr(blending, "find_root", lambda f, a, b, xtol: brentq(f, a, b, xtol=xtol))
    monkeypatch.setattr(
        blending,
        "minimize_bounded",
        lambda f, low, high, xatol: (
            minimize_scalar(f, bounds=(low, high), method="bounded", options={"xatol": xatol}).x
        ),
    )
    theirs = g2_blend(incoming, outgoing, budget=1e-3, reach=0.2)
    assert (ours.setback, ours.shape, ours.deviation) == (
        theirs.setback,
        theirs.shape,
        theirs.deviation,
    )
    np.testing.assert_array_equal(ours.blend.offsets, theirs.blend.offsets)
