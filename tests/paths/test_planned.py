"""The planned path: pieces, arc length, sampling smoothness, zones, stops and modes."""

from __future__ import annotations

from itertools import pairwise

import numpy as np
import pytest

from trackplan.paths import ArcSpec, LineSpec, NominalPath, PointsSpec, build_path

RHO = 1e-3
Y = np.array([0.0, 1.0, 0.0])


def _nominal(*segments, start=(0.0, 0.0, 0.0)) -> NominalPath:
    return NominalPath.from_specs(np.asarray(start, dtype=float), list(segments))


@pytest.fixture(scope="module")
def paper_corner() -> NominalPath:
    """The paper's corner case: (0,0,0) → (0.5,0,0) → (0.3,0,0.5)."""
    return _nominal(LineSpec(np.array([0.5, 0, 0])), LineSpec(np.array([0.3, 0, 0.5])))


@pytest.fixture(scope="module")
def mixed() -> NominalPath:
    """Line, tangent arc (G1), line, arc at 45° (G0), sampled curve: every junction kind."""
    lines_and_arcs = [
        LineSpec(np.array([0.2, 0.0, 0.0])),
        ArcSpec(np.array([0.2, 0.0, 0.1]), -Y, np.pi / 2),
        LineSpec(np.array([0.3, 0.0, 0.2])),
        ArcSpec(np.array([0.4, 0.0, 0.3]), Y, 1.0),
    ]
    end = _nominal(*lines_and_arcs).pieces[-1].curve.end
    t = np.linspace(0.0, 0.1, 41)[1:]
    samples = end + np.c_[-t, 0.02 * np.sin(30 * t), t**2]
    return _nominal(*lines_and_arcs, PointsSpec(samples))


@pytest.fixture(scope="module")
def mixed_path(mixed):
    return build_path(mixed, RHO)


def test_paper_corner_numbers(paper_corner):
    path = build_path(paper_corner, RHO)
    assert [piece.kind for piece in path.pieces] == ["line", "blend", "line"]
    assert [piece.straight for piece in path.pieces] == [True, False, True]
    first, blend, last = path.pieces
    setback = 0.5 - first.length
    # The numbers quoted in docs/paths.md.
    assert setback == pytest.approx(3.61e-3, abs=0.01e-3)
    assert blend.length == pytest.approx(5.05e-3, abs=0.01e-3)
    sample = path.sample(np.linspace(blend.s_start, blend.s_end, 4001))
    peak = np.linalg.norm(sample.curvature, axis=1).max()
    assert peak == pytest.approx(483, abs=1.0)
    deviation = paper_corner.project(sample.position)[1].max()
    assert 0.94 * RHO < deviation <= 0.95 * RHO
    assert path.zones == (
        (0.0, first.s_end, "straight"),
        (blend.s_start, blend.s_end, "curved"),
        (last.s_start, path.length, "straight"),
    )
    assert path.stops == ()
    assert path.nominal is paper_corner


def test_length_is_the_sum_of_pieces_and_zones_cover_it(mixed_path):
    assert mixed_path.length == pytest.approx(sum(p.length for p in mixed_path.pieces), rel=1e-15)
    for a, b in pairwise(mixed_path.pieces):
        assert b.s_start == a.s_end
    zones = mixed_path.zones
    assert zones[0][0] == 0.0
    assert zones[-1][1] == mixed_path.length
    for (_, end, kind), (start, _, next_kind) in pairwise(zones):
        assert end == start
        assert kind != next_kind


def test_every_junction_is_blended_and_the_path_stays_within_tolerance(mixed, mixed_path):
    kinds = [piece.kind for piece in mixed_path.pieces]
    assert kinds[:7] == ["line", "blend", "arc", "blend", "line", "blend", "arc"]
    assert mixed_path.stops == ()
    s = np.linspace(0.0, mixed_path.length, 100_001)
    assert mixed.project(mixed_path.sample(s).position)[1].max() <= RHO


def test_samples_are_at_their_arc_length(mixed_path):
    s = np.linspace(0.0, mixed_path.length, 200_001)
    sample = mixed_path.sample(s)
    chords = np.linalg.norm(np.diff(sample.position, axis=0), axis=1)
    np.testing.assert_allclose(np.cumsum(chords), s[1:], rtol=0, atol=1e-9)
    np.testing.assert_allclose(np.linalg.norm(sample.tangent, axis=1), 1.0, rtol=1e-14)
    np.testing.assert_allclose(np.sum(sample.tangent * sample.curvature, axis=1), 0, atol=1e-9)


def test_points_are_the_samples_positions_and_tangents_to_the_bit(mixed_path):
    """Lines, arcs, blends and fitted pieces; in order and shuffled; on the junctions and
    at NaN."""
    kinds = {piece.kind for piece in mixed_path.pieces}
    assert kinds == {"line", "arc", "blend"}
    junctions = [piece.s_start for piece in mixed_path.pieces]
    s = np.linspace(-1e-10, mixed_path.length + 1e-10, 20_001)
    s = np.sort(np.concatenate([s, junctions, [np.nan]]))
    shuffled = np.random.default_rng(5).permutation(s)
    for values in (s, shuffled):
        sample = mixed_path.sample(values)
        s_path, position, tangent = mixed_path.points(values)
        np.testing.assert_array_equal(s_path, sample.s)
        np.testing.assert_array_equal(position, sample.position)
        np.testing.assert_array_equal(tangent, sample.tangent)
    with pytest.raises(ValueError, match="outside the path"):
        mixed_path.points(np.array([-1e-6]))


def test_derivatives_match_finite_differences(mixed_path):
    h = 1e-7
    s = np.linspace(h, mixed_path.length - h, 997)
    mid, plus, minus = (mixed_path.sample(x) for x in (s, s + h, s - h))
    same = (plus.piece == minus.piece) & (plus.piece == mid.piece)
    pairs = [
        ("position", "tangent"),
        ("tangent", "curvature"),
        ("curvature", "curvature_derivative"),
    ]
    for value, derivative in pairs:
        numeric = (getattr(plus, value) - getattr(minus, value)) / (2 * h)
        exact = getattr(mid, derivative)
        scale = np.abs(exact).max()
        np.testing.assert_allclose(numeric[same], exact[same], atol=1e-5 * max(scale, 1.0))


def test_third_differences_show_no_noise_across_blends(mixed_path):
    # Backward differences at a constant step, as downstream checks do: the third
    # difference is a weighted mean of d³p/ds³ over its stencil, so each component must lie
    # in the range of the analytic d³p/ds³ over the stencil. Arc-length jitter of 1e-12 m
    # would leave it by ~1 m/s³ per (m/s)³; the allowance here is 1e-6 of the peak.
    ds = 1.5e-4
    for blend in (piece for piece in mixed_path.pieces if piece.kind == "blend"):
        lo = max(0.0, blend.s_start - 20 * ds)
        s = lo + ds * np.arange(int((min(mixed_path.length, blend.s_end + 20 * ds) - lo) / ds))
        third = np.diff(mixed_path.sample(s).position, 3, axis=0) / ds**3
        fine = mixed_path.sample(np.linspace(s[0], s[-1], 30 * (len(s) - 1) + 1))
        exact = fine.curvature_derivative
        allowance = 1e-6 * np.abs(exact).max()
        for k in range(len(third)):
            window = exact[30 * k : 30 * (k + 3) + 1]
            assert np.all(third[k] >= window.min(axis=0) - allowance)
            assert np.all(third[k] <= window.max(axis=0) + allowance)


def test_circle_of_the_paper():
    path = build_path(_nominal(ArcSpec(np.array([0.0, 0.0, -0.2]), Y, 2 * np.pi)), RHO)
    assert path.length == pytest.approx(2 * np.pi * 0.2, rel=1e-15)
    assert [piece.kind for piece in path.pieces] == ["arc"]
    assert path.zones == ((0.0, path.length, "curved"),)
    sample = path.sample(np.linspace(0.0, path.length, 101))
    np.testing.assert_allclose(np.linalg.norm(sample.position - [0, 0, -0.2], axis=1), 0.2)
    np.testing.assert_allclose(sample.position[:, 1], 0.0, atol=1e-16)
    np.testing.assert_allclose(sample.position[-1], 0.0, atol=1e-15)


def test_smooth_junctions_are_not_blended():
    collinear = _nominal(LineSpec(np.array([0.1, 0, 0])), LineSpec(np.array([0.3, 0, 0])))
    same_circle = _nominal(
        ArcSpec(np.array([0.0, 0.0, -0.2]), Y, 1.0), ArcSpec(np.array([0.0, 0.0, -0.2]), Y, 2.0)
    )
    for nominal in (collinear, same_circle):
        path = build_path(nominal, RHO)
        assert [piece.kind for piece in path.pieces] == [p.kind for p in nominal.pieces]


def test_reversal_is_a_stop():
    nominal = _nominal(LineSpec(np.array([0.2, 0, 0])), LineSpec(np.array([0.05, 0, 0])))
    path = build_path(nominal, RHO)
    assert [piece.kind for piece in path.pieces] == ["line", "line"]
    assert path.stops == pytest.approx((0.2,))
    sample = path.sample(np.array([0.2]))
    np.testing.assert_allclose(sample.position[0], [0.2, 0, 0])


def test_paper_mode_rounds_only_line_corners(mixed):
    path = build_path(mixed, RHO, mode="paper")
    kinds = [piece.kind for piece in path.pieces]
    assert "blend" not in kinds
    # Line → tangent arc → line is left as is; the sharp line → arc junction is a stop.
    assert kinds[:4] == ["line", "arc", "line", "arc"]
    assert path.stops[0] == pytest.approx(path.pieces[3].s_start)
    assert path.mode == "paper"


def test_sample_rejects_arc_lengths_off_the_path(paper_corner):
    path = build_path(paper_corner, RHO)
    with pytest.raises(ValueError, match="outside the path"):
        path.sample(np.array([path.length + 1e-6]))
    ends = path.sample(np.array([-1e-12, path.length + 1e-12]))
    np.testing.assert_allclose(ends.position, [[0, 0, 0], [0.3, 0, 0.5]], atol=1e-15)
    np.testing.assert_array_equal(ends.piece, [0, 2])


def test_bad_arguments(paper_corner):
    with pytest.raises(ValueError, match="tolerance"):
        build_path(paper_corner, 0.0)
    with pytest.raises(ValueError, match="mode"):
        build_path(paper_corner, RHO, mode="round")
