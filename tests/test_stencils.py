"""Local stencils: exact derivatives of quartics, kept inside their interval."""

from __future__ import annotations

import numpy as np

from trackplan.stencils import STENCIL_POINTS, stencil_derivatives, stencil_points


def quartic(x: np.ndarray) -> np.ndarray:
    return 1 + 2 * x + 3 * x**2 + 4 * x**3 + 5 * x**4


def test_stencils_are_exact_for_quartics_at_every_offset():
    h = 1e-3
    lo, hi = 0.0, 0.1
    s = np.array([0.0, 0.0004, 0.05, 0.0996, 0.1])  # both ends: one-sided stencils
    points, offset = stencil_points(s, lo, hi, h)
    assert set(offset.tolist()) >= {0, 2, 4}
    assert points.min() >= lo and points.max() <= hi + 1e-15
    values = quartic(points)[..., None]  # (M, P, 1)
    d1, d2, d3 = stencil_derivatives(values, offset, h)
    x0 = points[np.arange(len(s)), offset]
    np.testing.assert_allclose(d1[:, 0], 2 + 6 * x0 + 12 * x0**2 + 20 * x0**3, rtol=1e-6)
    np.testing.assert_allclose(d2[:, 0], 6 + 24 * x0 + 60 * x0**2, rtol=1e-6)
    np.testing.assert_allclose(d3[:, 0], 24 + 120 * x0, rtol=1e-6)


def test_point_interval_has_zero_derivatives():
    points, offset = stencil_points(np.array([0.3]), 0.3, 0.3, 0.0)
    assert points.shape == (1, STENCIL_POINTS) and np.all(points == 0.3)
    d1, d2, d3 = stencil_derivatives(np.ones((1, STENCIL_POINTS, 2)), offset, 0.0)
    assert not d1.any() and not d2.any() and not d3.any()
