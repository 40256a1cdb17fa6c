"""Corner blends: the G2 blend's deviation bound and continuity; the paper's Eq. 10 arc.

Random junctions are drawn with hypothesis (derandomized): two pieces, each a line or an
arc, meeting at a random angle (a corner of 5° to 175°) or tangentially (a G1 junction
whose curvature jumps), randomly placed in space, with ρ from 0.1 mm to 10 mm.
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from trackplan.paths import (
    ArcSpec,
    LineSpec,
    NominalPath,
    Path,
    build_path,
    corrected_corner_radius,
    paper_corner_angle,
    paper_corner_radius,
)
from trackplan.paths.blending import tangent_corner_arc
from trackplan.paths.curves import end_jet, start_jet

PROPERTY = settings(max_examples=40, deadline=None, derandomize=True)


def _frame(seed: int) -> np.ndarray:
    """A random rotation matrix (3, 3)."""
    q, _ = np.linalg.qr(np.random.default_rng(seed).normal(size=(3, 3)))
    return q * np.sign(np.linalg.det(q))  # a rotation, not a reflection


def _segment(kind: str, tangent: np.ndarray, side: np.ndarray, length: float, radius: float):
    """A segment leaving the current point (the origin) along ``tangent``."""
    if kind == "line":
        return LineSpec(length * tangent)
    angle = min(length / radius, 3.0)
    return ArcSpec(radius * side, np.cross(tangent, side), angle)


@st.composite
def junctions(draw, kinds=("line", "arc"), corner=None):
    """Specs of a two-piece path meeting at the origin, and ρ."""
    first, second = draw(st.sampled_from(kinds)), draw(st.sampled_from(kinds))
    turn_deg = draw(st.floats(5.0, 175.0)) if corner is None else corner
    if not draw(st.booleans()) and corner is None and "arc" in (first, second):
        turn_deg = 0.0  # tangent: a G1 junction
    turn = np.radians(turn_deg)
    lengths = [draw(st.floats(0.01, 0.5)) for _ in range(2)]
    radii = [draw(st.floats(0.01, 0.5)) for _ in range(2)]
    roll = [draw(st.floats(0.0, 2 * np.pi)) for _ in range(2)]
    rho = draw(st.floats(1e-4, 1e-2))
    frame = _frame(draw(st.integers(0, 2**31)))
    offset = np.asarray(draw(st.lists(st.floats(-0.5, 0.5), min_size=3, max_size=3)))

    def across(tangent: np.ndarray, angle: float) -> np.ndarray:
        side = np.cross(tangent, [0.3, 0.5, 0.8])
        side /= np.linalg.norm(side)
        return np.cos(angle) * side + np.sin(angle) * np.cross(tangent, side)

    t_in = np.array([1.0, 0.0, 0.0])
    t_out = np.array([np.cos(turn), np.sin(turn), 0.0])
    # The incoming piece is built backwards from the junction, then reversed.
    back = _segment(first, -t_in, across(-t_in, roll[0]), lengths[0], radii[0])
    start = NominalPath.from_specs(np.zeros(3), [back]).pieces[0].curve.end
    forward = _segment(second, t_out, across(t_out, roll[1]), lengths[1], radii[1])
    incoming = LineSpec(np.zeros(3))
    if isinstance(back, ArcSpec):
        incoming = ArcSpec(back.center, back.normal, -back.angle)

    def place(p: np.ndarray) -> np.ndarray:
        return frame @ p + offset

    def moved(spec):
        if isinstance(spec, LineSpec):
            return LineSpec(place(spec.to))
        return ArcSpec(place(spec.center), frame @ spec.normal, spec.angle)

    return place(start), [moved(incoming), moved(forward)], rho


def _blend(path: Path):
    (index,) = [k for k, piece in enumerate(path.pieces) if piece.kind == "blend"]
    return index, path.pieces[index]


def _check_blend(start, specs, rho) -> None:
    nominal = NominalPath.from_specs(start, specs)
    path = build_path(nominal, rho)
    index, blend = _blend(path)
    # Deviation: the blend, densely sampled, stays within ρ of the nominal path.
    s = np.linspace(blend.s_start, blend.s_end, 4001)
    sample = path.sample(s)
    assert nominal.project(sample.position)[1].max() <= rho
    # G2: position, unit tangent and curvature vector match both neighbours.
    neighbours = [(path.pieces[index - 1], blend), (blend, path.pieces[index + 1])]
    for before, after in neighbours:
        left, right = end_jet(before.curve), start_jet(after.curve)
        for a, b in zip(left[:3], right[:3], strict=False):
            np.testing.assert_allclose(a, b, rtol=0, atol=1e-9)
    # Curvature is continuous along the blend: steps bounded by |dκ/ds| h.
    h = s[1] - s[0]
    kappa = sample.curvature
    rate = np.linalg.norm(sample.curvature_derivative, axis=1)
    steps = np.linalg.norm(np.diff(kappa, axis=0), axis=1)
    assert np.all(steps <= 1.01 * h * np.maximum(rate[:-1], rate[1:]) + 1e-9 * rate.max())


@PROPERTY
@given(junctions(kinds=("line",)))
def test_line_corner_blend_is_g2_within_tolerance(case):
    _check_blend(*case)


@PROPERTY
@given(junctions())
def test_line_and_arc_junction_blend_is_g2_within_tolerance(case):
    _check_blend(*case)


@PROPERTY
@given(junctions(kinds=("arc",)))
def test_arc_junction_blend_is_g2_within_tolerance(case):
    _check_blend(*case)


def test_blend_is_nearly_as_round_as_the_largest_tangent_arc():
    # With the legs long enough, the G2 blend's peak curvature is within 15 % of the
    # curvature of the largest tangent arc within ρ (which is only G1).
    for turn_deg in (20.0, 60.0, 90.0, 120.0, 160.0):
        turn = np.radians(turn_deg)
        specs = [
            LineSpec(np.array([1.0, 0, 0])),
            LineSpec(np.array([1 + np.cos(turn), 0, np.sin(turn)])),
        ]
        rho = 1e-3
        path = build_path(NominalPath.from_specs(np.zeros(3), specs), rho)
        _, blend = _blend(path)
        sample = path.sample(np.linspace(blend.s_start, blend.s_end, 2001))
        peak = np.linalg.norm(sample.curvature, axis=1).max()
        arc_curvature = 1.0 / corrected_corner_radius(np.pi - turn, rho)
        assert arc_curvature < peak < 1.15 * arc_curvature


def _arc_deviation(turn: float, radius: float) -> float:
    legs = [
        LineSpec(np.array([1.0, 0, 0])),
        LineSpec(np.array([1 + np.cos(turn), np.sin(turn), 0])),
    ]
    nominal = NominalPath.from_specs(np.zeros(3), legs)
    arc, _ = tangent_corner_arc(nominal.curves[0], nominal.curves[1], radius)
    points = arc.evaluate(np.linspace(0.0, arc.length, 20001)).position
    return float(nominal.project(points)[1].max())


@PROPERTY
@given(st.floats(5.0, 175.0), st.floats(1e-4, 1e-2))
def test_paper_radius_deviates_twice_the_tolerance(turn_deg, rho):
    beta = np.pi - np.radians(turn_deg)
    paper = _arc_deviation(np.radians(turn_deg), paper_corner_radius(beta, rho))
    corrected = _arc_deviation(np.radians(turn_deg), corrected_corner_radius(beta, rho))
    assert paper == pytest.approx(2 * rho, rel=1e-6)
    assert corrected == pytest.approx(rho, rel=1e-6)


def test_paper_mode_reproduces_eq_10_on_the_paper_corner():
    corner = np.array([0.5, 0, 0])
    end = np.array([0.3, 0, 0.5])
    nominal = NominalPath.from_specs(np.zeros(3), [LineSpec(corner), LineSpec(end)])
    rho = 1e-3
    path = build_path(nominal, rho, mode="paper")
    assert [piece.kind for piece in path.pieces] == ["line", "arc", "line"]
    beta = paper_corner_angle(np.zeros(3), corner, end)
    assert path.pieces[1].curve.radius == pytest.approx(2 * rho / (1 - np.sin(beta / 2)))
    arc = path.pieces[1]
    # An odd count puts a sample on the arc's midpoint, where the deviation peaks.
    s = np.concatenate(
        [np.linspace(0.0, path.length, 10_001), np.linspace(arc.s_start, arc.s_end, 2001)]
    )
    assert nominal.project(path.sample(s).position)[1].max() == pytest.approx(2 * rho, rel=1e-9)
