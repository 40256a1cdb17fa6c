"""Screening kernel against the exact library (coal) on random capsule–primitive pairs."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from trackplan.cell import _kernels
from trackplan.cell.exact import ExactDistance
from trackplan.cell.model import Body, Shape
from trackplan.frames import pose_matrix, rpy_matrix

PRIMITIVES = (Shape.PLANE, Shape.BOX, Shape.CYLINDER, Shape.SPHERE, Shape.CAPSULE)
N_PAIRS = 2_000  # per primitive: 10,000 in all
TOLERANCE = 1e-6  # m


def random_pair(rng: np.random.Generator, shape: Shape):
    """A random body near the origin and a capsule (end points, radius) around it."""
    size = rng.uniform(0.02, 0.4, 3)
    T = pose_matrix(rng.uniform(-0.3, 0.3, 3), rpy_matrix(rng.uniform(-np.pi, np.pi, 3)))
    a = rng.uniform(-0.6, 0.6, 3)
    b = a + rng.uniform(-0.5, 0.5, 3)
    return Body("body", shape, T, size), a, b, float(rng.uniform(0.0, 0.1))


def screened(body: Body, a: np.ndarray, b: np.ndarray, radius: float) -> float:
    T_body_world = np.ascontiguousarray(np.linalg.inv(body.T_frame_body)[:3])
    return _kernels.capsule_body(a, b, radius, int(body.shape), body.size, T_body_world)


@pytest.mark.parametrize("shape", PRIMITIVES, ids=lambda s: s.name.lower())
def test_screening_matches_exact_library(shape: Shape) -> None:
    rng = np.random.default_rng(int(shape) + 11)
    oracle = ExactDistance()
    pairs = [random_pair(rng, shape) for _ in range(N_PAIRS)]
    a = np.array([p[1] for p in pairs])
    b = np.array([p[2] for p in pairs])
    radius = np.array([p[3] for p in pairs])
    T_body_world = np.array([np.linalg.inv(p[0].T_frame_body)[:3] for p in pairs])
    kernel = _kernels.capsule_body_batch(
        a,
        b,
        radius,
        np.full(N_PAIRS, int(shape)),
        np.array([p[0].size for p in pairs]),
        np.ascontiguousarray(T_body_world),
    )
    exact = np.array([oracle.capsule_body(*p[1:], p[0], np.eye(4)) for p in pairs])
    apart = exact > 0.0
    assert apart.sum() > N_PAIRS // 4 and (~apart).sum() > 0  # both cases are exercised
    # apart: the same distance; overlapping: both say so
    np.testing.assert_allclose(kernel[apart], exact[apart], atol=TOLERANCE, rtol=0)
    assert np.all(kernel[~apart] <= TOLERANCE)


@settings(max_examples=60, deadline=None)
@given(
    shape=st.sampled_from(PRIMITIVES),
    seed=st.integers(0, 2**32 - 1),
    stretch=st.floats(0.0, 1.0),
)
def test_screening_property(shape: Shape, seed: int, stretch: float) -> None:
    """Any pair, including degenerate capsules (a point) and long ones, agrees with coal."""
    body, a, b, radius = random_pair(np.random.default_rng(seed), shape)
    b = a + stretch * (b - a)
    exact = ExactDistance().capsule_body(a, b, radius, body, np.eye(4))
    kernel = screened(body, a, b, radius)
    if exact > 0.0:
        assert kernel == pytest.approx(exact, abs=TOLERANCE)
    else:
        assert kernel <= TOLERANCE


def test_capsule_capsule_matches_exact_library() -> None:
    rng = np.random.default_rng(5)
    oracle = ExactDistance()
    for _ in range(500):
        p0, q0 = rng.uniform(-0.5, 0.5, (2, 3))
        p1, q1 = p0 + rng.uniform(-0.4, 0.4, 3), q0 + rng.uniform(-0.4, 0.4, 3)
        r0, r1 = rng.uniform(0.0, 0.08, 2)
        exact = oracle.capsule_capsule(p0, p1, r0, q0, q1, r1)
        kernel = _kernels.segment_segment(p0, p1, q0, q1) - r0 - r1
        if exact > 0.0:
            assert kernel == pytest.approx(exact, abs=TOLERANCE)
        else:
            assert kernel <= TOLERANCE


def test_parallel_segments() -> None:
    """Parallel axes (the degenerate case of the closest-point solve)."""
    p0, p1 = np.array([0.0, 0, 0]), np.array([1.0, 0, 0])
    q0, q1 = np.array([0.5, 0.3, 0]), np.array([1.5, 0.3, 0])
    assert _kernels.segment_segment(p0, p1, q0, q1) == pytest.approx(0.3)
    q0, q1 = np.array([1.2, 0.4, 0]), np.array([2.0, 0.4, 0])
    assert _kernels.segment_segment(p0, p1, q0, q1) == pytest.approx(np.hypot(0.2, 0.4))
