"""Free profiles: nodes over the path parameter, bounds per node, a rate bound, derivatives."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.interpolate import BSpline

from trackplan.profiles import (
    FreeProfile,
    Profile,
    clamped_knots,
    increment_spans,
    profile_values,
)
from trackplan.tool import SpinMode, ToolSpec

EXACT = 1e-12
"""Tolerance of values that scipy and trackplan compute by the same recursion, in unit."""


@pytest.mark.parametrize("k", [4, 6, 9])
@pytest.mark.parametrize("order", [0, 1, 2])
def test_values_and_derivatives_are_scipys_for_many_profiles_at_once(k, order):
    rng = np.random.default_rng(k)
    length = 1.7
    coefficients = rng.uniform(-1.0, 1.0, (3, k))
    s = np.linspace(0.0, length, 101)
    values = profile_values(coefficients, s, length, order)
    assert values.shape == (3, s.size)
    for row, c in zip(values, coefficients, strict=True):
        spline = BSpline(clamped_knots(k, length), c, 3)
        # derivative magnitudes grow with 1/span^order: scale the tolerance with them
        expected = spline.derivative(order)(s) if order else spline(s)
        np.testing.assert_allclose(row, expected, atol=EXACT * (k / length) ** order * 10)
        one = Profile(c, length).derivative(s, order)
        np.testing.assert_allclose(one, expected, atol=EXACT * (k / length) ** order * 10)


def test_a_constant_profile_has_zero_derivatives():
    profile = Profile.constant(0.4, 2.0)
    s = np.linspace(0.0, 2.0, 5)
    np.testing.assert_array_equal(profile.value(s), np.full(5, 0.4))
    np.testing.assert_array_equal(profile.rate(s), np.zeros(5))
    np.testing.assert_array_equal(profile.derivative(s, 2), np.zeros(5))
    assert profile.max_rate == 0.0
    assert profile.as_dict() == {"value": 0.4}


def test_derivative_order_above_two_is_refused():
    with pytest.raises(ValueError, match="order 3"):
        profile_values(np.zeros((1, 6)), np.zeros(3), 1.0, order=3)


@pytest.mark.parametrize("nodes", [-1, 2, 3])
def test_node_counts_without_a_cubic_spline_are_refused(nodes):
    with pytest.raises(ValueError, match="0, 1 or at least 4 nodes"):
        FreeProfile(nodes, np.asarray(-1.0), np.asarray(1.0), rate=1.0)


@pytest.mark.parametrize("rate", [0.0, np.inf])
def test_a_varying_profile_needs_a_finite_rate(rate):
    with pytest.raises(ValueError, match="finite rate"):
        FreeProfile(6, np.asarray(-1.0), np.asarray(1.0), rate=rate)


@settings(max_examples=40, deadline=None, derandomize=True)
@given(
    variables=st.lists(st.floats(-1, 1), min_size=7, max_size=7),
    rate=st.floats(0.5, 50.0),
    length=st.floats(0.05, 3.0),
)
def test_per_node_bounds_and_the_rate_hold_for_any_variables(variables, rate, length):
    lower = np.array([-1.0, -0.5, 0.0, 0.0, -0.2, -1.0, -2.0])
    upper = lower + np.array([2.0, 1.0, 0.5, 0.1, 0.4, 2.0, 4.0])
    free = FreeProfile(7, lower, upper, rate=rate)
    lo, hi = free.bounds()
    x = lo + 0.5 * (np.array(variables) + 1.0) * (hi - lo)
    c = free.coefficients(x[None], length)[0]
    # each node is within its bounds, or as near them as the rate allows from the one before
    reach = rate * increment_spans(7, length)
    step = np.diff(c)
    assert lower[0] <= c[0] <= upper[0]
    assert np.all(np.abs(step) <= reach * (1 + 1e-12))
    below, above = c[1:] < lower[1:], c[1:] > upper[1:]
    np.testing.assert_allclose(step[below], reach[below], rtol=1e-12)
    np.testing.assert_allclose(step[above], -reach[above], rtol=1e-12)
    assert free.outside_bounds(c) == bool(below.any() or above.any())
    profile = free.profile(x, length)
    assert profile.max_rate <= rate * (1 + 1e-9)
    s = np.linspace(0.0, length, 801)
    assert np.abs(profile.rate(s)).max() <= rate * (1 + 1e-9)
    np.testing.assert_allclose(free.values(x[None], s, length)[0], profile.value(s), atol=EXACT)


def test_variables_round_trip_through_the_nodes():
    free = FreeProfile(6, np.asarray(-3.0), np.asarray(3.0), rate=1.0)
    x = np.array([[0.5, 0.2, -0.4, 0.9, -1.0, 0.0]])
    np.testing.assert_allclose(free.variables(free.coefficients(x, 1.5), 1.5), x, atol=EXACT)


def test_fixed_and_constant_profiles():
    fixed = FreeProfile(0, np.asarray(-1.0), np.asarray(1.0), fixed=0.3)
    assert fixed.n_variables == 0
    assert [b.shape for b in fixed.bounds()] == [(0,), (0,)]
    np.testing.assert_array_equal(fixed.coefficients(np.zeros((2, 0)), 1.0), [[0.3], [0.3]])
    constant = FreeProfile(1, np.asarray(-1.0), np.asarray(2.0))
    assert constant.profile(None, 1.0).as_dict() == {"value": 0.5}


def test_other_node_counts_are_held_to_uniform_bounds_only():
    uniform = FreeProfile(6, np.asarray(-1.0), np.asarray(1.0), rate=1.0)
    assert not uniform.outside_bounds(np.zeros(9))
    assert uniform.outside_bounds(np.array([0.0, 1.1, 0.0, 0.0]))
    per_node = FreeProfile(4, np.array([-1.0, -1.0, 0.0, 0.0]), np.ones(4), rate=1.0)
    assert per_node.outside_bounds(np.zeros(5))
    assert per_node.outside_bounds(np.array([0.0, 0.0, -0.5, 0.0]))
    assert not per_node.outside_bounds(np.array([-0.5, -0.5, 0.5, 0.0]))


@pytest.mark.parametrize(
    ("mode", "nodes"), [(SpinMode.FIXED, 0), (SpinMode.FREE, 1), (SpinMode.FREE_VARYING, 6)]
)
def test_the_tools_spin_is_a_free_profile(mode, nodes):
    spec = ToolSpec(spin=mode, spin_value=0.2, spin_range=(-1.0, 2.0), spin_rate=3.0)
    free = spec.spin_profile
    assert isinstance(free, FreeProfile)
    assert free.nodes == spec.n_spin == nodes
    assert free.fixed == 0.2 and free.rate == 3.0
    np.testing.assert_array_equal(free.lower, np.full(max(nodes, 1), -1.0))
    np.testing.assert_array_equal(free.upper, np.full(max(nodes, 1), 2.0))
    x = np.linspace(-0.5, 0.5, nodes)[None]
    np.testing.assert_array_equal(spec.spin_coefficients(x, 0.8), free.coefficients(x, 0.8))
