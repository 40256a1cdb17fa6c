"""Curves: exact lines and arcs, the arc-length parametrised quintic blend."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from trackplan.paths.curves import (
    Arc,
    CurveJet,
    Line,
    QuinticBlend,
    end_jet,
    start_jet,
)


def _corner_blend(turn_deg: float, setback: float, shape: float) -> QuinticBlend:
    """The quintic blend of a line–line corner at (0.3, 0.1, 0.2) turning by ``turn_deg``."""
    corner = np.array([0.3, 0.1, 0.2])
    t_in = np.array([1.0, 0.0, 0.0])
    turn = np.radians(turn_deg)
    t_out = np.array([np.cos(turn), np.sin(turn), 0.0])
    zero = np.zeros((1, 3))
    start = CurveJet((corner - setback * t_in)[None], t_in[None], zero, zero)
    end = CurveJet((corner + setback * t_out)[None], t_out[None], zero, zero)
    return QuinticBlend.from_hermite(start, end, shape * setback)


def test_arc_reproduces_the_right_handed_rotation(rng):
    for _ in range(20):
        center, start = rng.normal(size=3), rng.normal(size=3)
        normal = rng.normal(size=3)
        angle = rng.uniform(-7.0, 7.0)
        arc = Arc.from_rotation(start, center, normal, angle)
        fractions = np.linspace(0.0, 1.0, 9)
        axis = normal / np.linalg.norm(normal)
        expected = center + Rotation.from_rotvec(np.outer(fractions * angle, axis)).apply(
            start - center
        )
        got = arc.evaluate(fractions * arc.length).position
        np.testing.assert_allclose(got, expected, atol=1e-12)
        assert arc.length == pytest.approx(abs(angle) * arc.radius)


def test_arc_derivatives_are_the_circle_s():
    arc = Arc.from_rotation(np.zeros(3), np.array([0.0, 0.0, -0.2]), np.array([0, 1.0, 0]), 2)
    sigma = np.linspace(0.0, arc.length, 11)
    jet = arc.evaluate(sigma)
    np.testing.assert_allclose(np.linalg.norm(jet.tangent, axis=1), 1.0)
    np.testing.assert_allclose(np.linalg.norm(jet.curvature, axis=1), 5.0)
    np.testing.assert_allclose(jet.curvature_derivative, -25.0 * jet.tangent, atol=1e-12)
    np.testing.assert_allclose(
        jet.position + 0.04 * jet.curvature, np.tile([0.0, 0.0, -0.2], (11, 1)), atol=1e-15
    )


@pytest.mark.parametrize("curve_kind", ["line", "arc"])
def test_projection_matches_brute_force(rng, curve_kind):
    if curve_kind == "line":
        curve: Line | Arc = Line.between(np.array([0.1, 0.2, 0.3]), np.array([0.4, -0.1, 0.5]))
    else:
        curve = Arc.from_rotation(np.array([0.3, 0, 0]), np.zeros(3), np.array([0.2, 0.1, 1]), 4)
    points = curve.start + rng.normal(scale=0.3, size=(200, 3))
    sigma, distance = curve.project(points)
    dense = np.linspace(0.0, curve.length, 200_001)
    cloud = curve.evaluate(dense).position
    gaps = np.linalg.norm(points[:, None, :] - cloud[None, ::20, :], axis=-1)
    np.testing.assert_array_less(distance, gaps.min(axis=1) + 1e-12)
    near = curve.evaluate(sigma).position
    np.testing.assert_allclose(np.linalg.norm(points - near, axis=1), distance, atol=1e-12)


def test_trimmed_pieces_are_the_same_curve():
    arc = Arc.from_rotation(np.array([0.3, 0, 0]), np.zeros(3), np.array([0, 0, 1.0]), 2.0)
    line = Line.between(np.zeros(3), np.array([1.0, 2.0, 2.0]))
    for curve in (arc, line):
        part = curve.trimmed(0.1, 0.2)
        assert part.length == pytest.approx(curve.length - 0.3)
        sigma = np.linspace(0.0, part.length, 7)
        np.testing.assert_allclose(
            part.evaluate(sigma).position, curve.evaluate(sigma + 0.1).position, atol=1e-15
        )


@pytest.mark.parametrize(("turn_deg", "shape"), [(5, 1.8), (112, 1.4), (175, 0.2)])
def test_blend_derivatives_match_finite_differences(turn_deg, shape):
    blend = _corner_blend(turn_deg, 0.004, shape)
    sigma = np.linspace(0.0, blend.length, 41)[1:-1]
    h = 1e-6 * blend.length
    plus, minus, mid = blend.evaluate(sigma + h), blend.evaluate(sigma - h), blend.evaluate(sigma)
    for k in range(3):
        numeric = (plus[k] - minus[k]) / (2 * h)
        scale = np.abs(mid[k + 1]).max()
        np.testing.assert_allclose(numeric, mid[k + 1], atol=1e-6 * scale)
    np.testing.assert_allclose(np.linalg.norm(mid.tangent, axis=1), 1.0, rtol=1e-14)


@pytest.mark.parametrize(("turn_deg", "shape"), [(112, 1.4), (175, 0.2)])
def test_blend_arc_length_is_exact(turn_deg, shape):
    blend = _corner_blend(turn_deg, 0.004, shape)
    s = np.linspace(0.0, blend.length, 100_001)
    position = blend.evaluate(s).position
    chords = np.linalg.norm(np.diff(position, axis=0), axis=1)
    # A chord is shorter than its arc by κ²h³/24: summed at h = L / 1e5 that is < 1e-12 m.
    np.testing.assert_allclose(np.cumsum(chords), s[1:], rtol=0, atol=1e-12)
    u = blend.parameter(s[::250])
    np.testing.assert_allclose(blend.arc_length(u), s[::250], rtol=0, atol=1e-17)


def test_blend_matches_its_hermite_data():
    blend = _corner_blend(90, 0.01, 1.5)
    first, last = start_jet(blend), end_jet(blend)
    np.testing.assert_allclose(first.tangent[0], [1, 0, 0], atol=1e-15)
    np.testing.assert_allclose(last.tangent[0], [0, 1, 0], atol=1e-15)
    np.testing.assert_allclose(first.curvature[0], 0, atol=1e-12)
    np.testing.assert_allclose(last.curvature[0], 0, atol=1e-12)
    np.testing.assert_allclose(blend.end, [0.3, 0.11, 0.2], atol=1e-16)


@pytest.mark.parametrize(("turn_deg", "shape"), [(5, 1.8), (112, 1.4), (175, 0.2)])
def test_blend_parameter_kernel_equals_the_numpy_newton_solve(turn_deg, shape):
    """The compiled per-point solve against the vectorised one it replaced: the cubic
    Hermite start on the panel table, then Newton for all points until every step is
    below 1e-9, then one more."""
    blend = _corner_blend(turn_deg, 0.004, shape)
    sigma = np.concatenate([[-1e-3, 0.0], np.random.default_rng(3).uniform(0, blend.length, 500)])
    sigma = np.concatenate([sigma, [blend.length, blend.length + 1e-3]])
    target = np.clip(sigma, 0.0, blend.length)
    table_u, table_s = blend._breaks, blend._cumulative
    slope = 1.0 / blend.speed(table_u)
    k = np.clip(np.searchsorted(table_s, target, side="right") - 1, 0, table_s.size - 2)
    width = table_s[k + 1] - table_s[k]
    x = (target - table_s[k]) / width
    u = (
        (2 * x**3 - 3 * x**2 + 1) * table_u[k]
        + (x**3 - 2 * x**2 + x) * width * slope[k]
        + (-2 * x**3 + 3 * x**2) * table_u[k + 1]
        + (x**3 - x**2) * width * slope[k + 1]
    )
    for _ in range(30):
        step = (blend.arc_length(u) - target) / blend.speed(u)
        u = np.clip(u - step, 0.0, 1.0)
        if np.abs(step).max() < 1e-9:
            u = np.clip(u - (blend.arc_length(u) - target) / blend.speed(u), 0.0, 1.0)
            break
    np.testing.assert_allclose(blend.parameter(sigma), u, rtol=0, atol=1e-15)
