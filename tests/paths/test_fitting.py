"""Sampled curves: segmented into a few lines and arcs within tolerance, then blended."""

from __future__ import annotations

from itertools import pairwise

import numpy as np
import pytest

from trackplan.paths import NominalPath, PointsSpec, build_path, fit_polyline
from trackplan.paths.geometry import Arc, Line, end_jet, start_jet, turning_angle
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
