"""Sampled curves: segmented into a few lines and arcs within tolerance, then blended."""

from __future__ import annotations

from itertools import pairwise

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from trackplan.paths import NominalPath, PointsSpec, build_path, fit_polyline
from trackplan.paths.curves import Arc, Line, end_jet, start_jet, turning_angle
from trackplan.paths.fitting import biarc, fit_deviation, vertex_tangents
from trackplan.paths.pieces import chain, evaluate_pieces
from trackplan.paths.planned import FIT_SHARE

RHO = 1e-3


def _helix(n: int) -> np.ndarray:
    angle = np.linspace(0.0, 4 * np.pi, n)
    return np.c_[0.1 * np.cos(angle) - 0.1, 0.1 * np.sin(angle), 0.02 * angle]


def _sine(n: int) -> np.ndarray:
    x = np.linspace(0.0, 0.5, n)
    return np.c_[x, np.zeros(n), 0.05 * np.sin(2 * np.pi * x / 0.25)]


def _polyline_distance(points: np.ndarray, vertices: np.ndarray) -> np.ndarray:
    """Distance (N,) of ``points`` (N, 3) from the polyline through ``vertices`` (K, 3)."""
    start, chord = vertices[:-1], np.diff(vertices, axis=0)
    rel = points[:, None, :] - start[None]
    along = np.clip(np.sum(rel * chord, axis=-1) / np.sum(chord * chord, axis=-1), 0.0, 1.0)
    return np.linalg.norm(rel - along[..., None] * chord, axis=-1).min(axis=1)


@pytest.mark.parametrize("curve", [_helix, _sine], ids=["helix", "sine"])
def test_smooth_samples_become_a_few_tangent_primitives(curve):
    vertices = curve(201)  # the current point and 200 samples
    fit = fit_polyline(vertices, FIT_SHARE * RHO)
    assert len(fit.curves) <= 30  # 200 points: at most 15 biarcs
    assert fit.spans[0, 0] == 0
    assert fit.spans[-1, 1] == 200
    for curve_k, bound in zip(fit.curves, fit.deviation, strict=True):
        points = curve_k.evaluate(np.linspace(0.0, curve_k.length, 1001)).position
        assert _polyline_distance(points, vertices).max() <= bound + 1e-12
        assert bound <= FIT_SHARE * RHO
    for a, b in pairwise(fit.curves):
        np.testing.assert_allclose(end_jet(a).position, start_jet(b).position, atol=1e-15)
        assert turning_angle(end_jet(a).tangent[0], start_jet(b).tangent[0]) < 1e-9  # G1


@pytest.mark.parametrize("curve", [_helix, _sine], ids=["helix", "sine"])
def test_sampled_curve_path_is_smooth_and_within_tolerance(curve):
    vertices = curve(201)
    nominal = NominalPath.from_specs(vertices[0], [PointsSpec(vertices[1:])])
    path = build_path(nominal, RHO)
    assert path.stops == ()
    assert len(path.pieces) < 60
    sample = path.sample(np.linspace(0.0, path.length, 40_001))
    assert nominal.project(sample.position)[1].max() <= RHO
    # G2 everywhere: no curvature jumps between consecutive samples beyond |dκ/ds| h.
    h = path.length / 40_000
    steps = np.linalg.norm(np.diff(sample.curvature, axis=0), axis=1)
    rate = np.linalg.norm(sample.curvature_derivative, axis=1)
    assert np.all(steps <= 1.01 * h * np.maximum(rate[:-1], rate[1:]) + 1e-9)


def test_sharp_corner_in_samples_stays_a_blended_corner():
    leg = np.linspace(0.0, 0.1, 21)
    vertices = np.vstack([np.c_[leg, 0 * leg, 0 * leg], np.c_[0.1 + 0 * leg, 0 * leg, leg][1:]])
    fit = fit_polyline(vertices, FIT_SHARE * RHO)
    assert [type(c) for c in fit.curves] == [Line, Line]
    np.testing.assert_array_equal(fit.spans, [[0, 20], [20, 40]])
    nominal = NominalPath.from_specs(vertices[0], [PointsSpec(vertices[1:])])
    path = build_path(nominal, RHO)
    assert [piece.kind for piece in path.pieces] == ["line", "blend", "line"]
    blend = path.pieces[1]
    sample = path.sample(np.linspace(blend.s_start, blend.s_end, 2001))
    assert nominal.project(sample.position)[1].max() <= 0.95 * RHO


def test_collinear_samples_are_one_line_and_circle_samples_one_arc():
    t = np.linspace(0.0, 1.0, 50)
    line = fit_polyline(np.c_[t, 2 * t, -t], 1e-6)
    assert len(line.curves) == 1
    assert isinstance(line.curves[0], Line)
    angle = np.linspace(0.0, 2.0, 60)
    vertices = np.c_[0.3 * np.cos(angle), 0.3 * np.sin(angle), 0 * angle]
    # The polyline (the nominal path) is 43 µm inside the circle between samples.
    assert len(fit_polyline(vertices, 4e-5).curves) > 1
    arc = fit_polyline(vertices, 5e-5)
    assert len(arc.curves) == 1
    assert isinstance(arc.curves[0], Arc)
    assert arc.curves[0].radius == pytest.approx(0.3, rel=1e-12)


def _deviation_oracle(curves, vertices: np.ndarray) -> tuple[float, float]:
    """The bound of fit_deviation in plain numpy, piece by piece (the former implementation)."""
    pieces = chain(curves)
    projections = [curve.project(vertices) for curve in curves]
    distance = np.min([d for _, d in projections], axis=0)
    nearest = np.argmin([d for _, d in projections], axis=0)
    sigma = np.choose(
        nearest, [p.s_start + s for p, (s, _) in zip(pieces, projections, strict=True)]
    )
    total = pieces[-1].s_end
    sigma = np.clip(np.maximum.accumulate(sigma), 0.0, total)
    sigma[0], sigma[-1] = 0.0, total
    fraction = np.linspace(0.0, 1.0, 5)
    grid = sigma[:-1, None] + (sigma[1:] - sigma[:-1])[:, None] * fraction
    points = evaluate_pieces(pieces, grid.ravel())[0].position.reshape(*grid.shape, 3)
    starts = vertices[:-1, None, :]
    chords = (vertices[1:] - vertices[:-1])[:, None, :]
    along = np.sum((points - starts) * chords, axis=-1) / np.sum(chords * chords, axis=-1)
    foot = starts + np.clip(along, 0.0, 1.0)[..., None] * chords
    gap = np.linalg.norm(points - foot, axis=-1)
    step = (sigma[1:] - sigma[:-1]) / 4
    kappa = max((1.0 / c.radius for c in curves if isinstance(c, Arc)), default=0.0)
    sagitta = np.zeros_like(step)
    if kappa > 0.0:
        sagitta = (1.0 - np.cos(0.5 * np.minimum(kappa * step, np.pi))) / kappa
    bound = np.maximum(gap[:, :-1], gap[:, 1:]) + sagitta[:, None]
    return float(distance.max()), float(bound.max())


@settings(max_examples=60, deadline=None, derandomize=True)
@given(
    st.integers(3, 400),
    st.floats(0.02, 0.5),
    st.floats(-0.2, 0.2),
    st.floats(0.0, 2e-4),
    st.integers(0, 2**32 - 1),
)
def test_deviation_kernel_agrees_with_numpy(n, radius, rise, noise, seed):
    rng = np.random.default_rng(seed)
    angle = np.linspace(0.0, rng.uniform(0.1, 3.0), n)
    vertices = np.c_[radius * np.cos(angle), radius * np.sin(angle), rise * angle]
    vertices += noise * rng.standard_normal(vertices.shape)
    t0, t1 = vertex_tangents(vertices)[[0, -1]]
    curves = biarc(vertices[0], t0, vertices[-1], t1)
    if not curves:
        curves = [Line.between(vertices[0], vertices[-1])]
    expected = _deviation_oracle(curves, vertices)
    np.testing.assert_allclose(fit_deviation(curves, vertices), expected, rtol=1e-9, atol=1e-15)
    # With a limit, the work may stop early, but only when the limit is exceeded.
    limit = 0.5 * max(expected)
    assert max(fit_deviation(curves, vertices, limit)) > limit


@settings(max_examples=25, deadline=None, derandomize=True)
@given(
    st.integers(20, 1500),
    st.floats(0.03, 0.3),
    st.floats(0.0, 0.1),
    st.floats(0.5, 12.0),
    st.floats(0.0, 5e-5),
    st.integers(0, 2**32 - 1),
)
def test_fit_holds_the_tolerance_both_ways(n, radius, rise, turn, noise, seed):
    """Any sampled helix, noisy or not: the fit stays within the fitting share of ρ."""
    rng = np.random.default_rng(seed)
    angle = np.linspace(0.0, turn, n)
    vertices = np.c_[radius * np.cos(angle), radius * np.sin(angle), rise * angle]
    vertices += noise * rng.standard_normal(vertices.shape)
    tolerance = FIT_SHARE * RHO
    fit = fit_polyline(vertices, tolerance)
    assert fit.spans[0, 0] == 0 and fit.spans[-1, 1] == n - 1
    pieces = chain(fit.curves)
    s = np.linspace(0.0, pieces[-1].s_end, 20 * n)
    points = evaluate_pieces(pieces, s)[0].position
    nearest_on_polyline = _polyline_distance(points, vertices) if n <= 600 else None
    if nearest_on_polyline is not None:
        assert nearest_on_polyline.max() <= fit.deviation.max() + 1e-12
    assert np.all(fit.deviation <= tolerance)
    vertex_distance = np.min([curve.project(vertices)[1] for curve in fit.curves], axis=0)
    assert vertex_distance.max() <= tolerance
