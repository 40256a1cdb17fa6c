"""The tool orientation: seam frame conventions, spin profiles, the blend-zone bound."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.interpolate import BSpline
from scipy.spatial.transform import Rotation

from tests.conftest import CASES
from trackplan.frames import rpy_matrix
from trackplan.io.case_file import load_case
from trackplan.paths.path_geometry import PathGeometry
from trackplan.planning.plan import plan
from trackplan.planning.tool_zones import nominal_tangents, transition_zones
from trackplan.planning.tracking import locate_on_nominal
from trackplan.tool import (
    SPIN_COEFFICIENTS,
    SpinMode,
    SpinProfile,
    ToolFrame,
    ToolOrientation,
    ToolSpec,
    rotation_angle,
    rotation_z,
    spin_knots,
    spun,
    tool_axis_twist,
)

AXIS_EXACT = 1e-6
"""Tool axis error allowed outside transition zones, rad."""


@pytest.fixture(scope="module")
def corner_geometry():
    return PathGeometry.from_case(load_case(CASES / "paper-corner.yaml"))


@pytest.fixture(scope="module")
def circle_geometry():
    return PathGeometry.from_case(load_case(CASES / "paper-circle-seam-free.yaml"))


def test_seam_frame_at_the_circle_start_is_the_papers_tool(circle_geometry):
    spec = load_case(CASES / "paper-circle-seam-fixed.yaml").task.tool
    tangent = circle_geometry.planned.sample(np.array([0.0])).tangent
    R = spec.base_rotations(tangent)[0]
    np.testing.assert_allclose(R, rpy_matrix([-np.pi / 2, 0, 0]), atol=1e-12)


def test_the_circle_turns_the_tool_once_about_its_axis(circle_geometry):
    spec = load_case(CASES / "paper-circle-seam-fixed.yaml").task.tool
    s = np.linspace(0.0, circle_geometry.planned.length, 400)
    R = spec.base_rotations(circle_geometry.planned.sample(s).tangent)
    np.testing.assert_allclose(R[:, :, 2], np.tile([0.0, 1.0, 0.0], (400, 1)), atol=1e-12)
    assert abs(tool_axis_twist(R)[-1]) == pytest.approx(2 * np.pi, rel=1e-9)


@settings(max_examples=30, deadline=None, derandomize=True)
@given(
    tangent=st.tuples(*[st.floats(-1, 1)] * 3).filter(lambda v: np.linalg.norm(v) > 0.1),
    normal=st.tuples(*[st.floats(-1, 1)] * 3).filter(lambda v: np.linalg.norm(v) > 0.1),
    angles=st.tuples(*[st.floats(-np.pi, np.pi)] * 3),
)
def test_seam_rotation_matches_scipy(tangent, normal, angles):
    t = np.array(tangent) / np.linalg.norm(tangent)
    n = np.array(normal)
    n_perp = n - (n @ t) * t
    if np.linalg.norm(n_perp) < 0.05 * np.linalg.norm(n):
        return
    work, travel, spin = angles
    spec = ToolSpec(frame=ToolFrame.SEAM, normal=n, work_angle=work, travel_angle=travel)
    z = -n_perp / np.linalg.norm(n_perp)
    seam = np.column_stack([t, np.cross(z, t), z])
    expected = seam @ Rotation.from_euler("XYZ", [work, travel, spin]).as_matrix()
    tool = ToolOrientation(spec, SpinProfile.constant(spin, 1.0))
    np.testing.assert_allclose(tool.rotations(np.zeros(1), t[None])[0], expected, atol=1e-12)


def test_spin_profile_is_scipys_clamped_cubic_spline():
    rng = np.random.default_rng(3)
    coefficients = rng.uniform(-1, 1, SPIN_COEFFICIENTS)
    profile = SpinProfile(coefficients, 2.0)
    s = np.linspace(0.0, 2.0, 57)
    spline = BSpline(spin_knots(SPIN_COEFFICIENTS, 2.0), coefficients, 3)
    np.testing.assert_allclose(profile.value(s), spline(s), atol=1e-12)
    np.testing.assert_allclose(profile.rate(s), spline.derivative()(s), atol=1e-12)
    assert profile.value(np.array([0.0, 2.0])) == pytest.approx(coefficients[[0, -1]])


@settings(max_examples=40, deadline=None, derandomize=True)
@given(
    variables=st.lists(st.floats(-1, 1), min_size=SPIN_COEFFICIENTS, max_size=SPIN_COEFFICIENTS),
    rate=st.floats(0.5, 50.0),
    low=st.floats(-4.0, 0.0),
    width=st.floats(0.1, 8.0),
    length=st.floats(0.05, 3.0),
)
def test_free_varying_spin_stays_in_range_and_rate(variables, rate, low, width, length):
    spec = ToolSpec(spin=SpinMode.FREE_VARYING, spin_range=(low, low + width), spin_rate=rate)
    lo, hi = spec.spin_bounds()
    x = lo + 0.5 * (np.array(variables) + 1.0) * (hi - lo)
    profile = spec.profile(x, length)
    s = np.linspace(0.0, length, 2001)
    spin, slope = profile.value(s), profile.rate(s)
    assert spin.min() >= low - 1e-9 and spin.max() <= low + width + 1e-9
    assert np.abs(slope).max() <= rate * (1 + 1e-9)
    assert profile.max_rate <= rate * (1 + 1e-9)


def test_spin_variables_round_trip():
    spec = ToolSpec(spin=SpinMode.FREE_VARYING, spin_range=(-3.0, 3.0), spin_rate=1.0)
    x = np.array([[0.5, 0.2, -0.4, 0.9, -1.0, 0.0]])
    c = spec.spin_coefficients(x, 1.5)
    np.testing.assert_allclose(spec.spin_variables(c, 1.5), x)


@settings(max_examples=10, deadline=None, derandomize=True)
@given(
    normal=st.sampled_from([(0.0, 1.0, 0.0), (0.0, 1.0, 0.3), (0.2, -1.0, 0.1)]),
    work=st.floats(-0.8, 0.8),
    travel=st.floats(-0.5, 0.5),
    spin=st.floats(-3.0, 3.0),
)
def test_tool_axis_is_exact_outside_transition_zones_and_bounded_inside(
    corner_geometry, normal, work, travel, spin
):
    spec = ToolSpec(
        frame=ToolFrame.SEAM, normal=np.array(normal), work_angle=work, travel_angle=travel
    )
    planned, nominal = corner_geometry.planned, corner_geometry.nominal
    s = np.sort(np.random.default_rng(7).uniform(0.0, planned.length, 4000))  # off the grid
    sample = planned.sample(s)
    tool = ToolOrientation.choose(spec, corner_geometry)
    R = replace(tool, spin=SpinProfile.constant(spin, planned.length)).rotations(s, sample.tangent)
    s_nominal, _, piece = locate_on_nominal(nominal, sample.position, sample.tangent, 1e-3)
    R_spec = spec.base_rotations(nominal_tangents(nominal, s_nominal, piece))
    error = np.arccos(np.clip(np.einsum("ni,ni->n", R[:, :, 2], R_spec[:, :, 2]), -1, 1))
    zones = transition_zones(spec, corner_geometry, 1e-3)
    inside = np.zeros(len(s), dtype=bool)
    for s0, s1, bound in zones:
        zone = (s_nominal >= s0) & (s_nominal <= s1)
        assert error[zone].max(initial=0.0) <= bound
        inside |= zone
    assert error[~inside].max() <= AXIS_EXACT
    assert inside.mean() < 0.2  # the zones stay near the corner


def test_transition_zone_covers_the_corner_within_the_frame_turn(corner_geometry):
    # with the normal across the corner's plane the frame turns about the tool axis only
    across = ToolSpec(frame=ToolFrame.SEAM, normal=np.array([0.0, 1.0, 0.0]))
    assert len(transition_zones(across, corner_geometry, 1e-3)) == 0
    spec = ToolSpec(frame=ToolFrame.SEAM, normal=np.array([0.0, 1.0, 0.3]))
    zones = transition_zones(spec, corner_geometry, 1e-3)
    a, b, c = np.array([0, 0, 0.0]), np.array([0.5, 0, 0]), np.array([0.3, 0, 0.5])
    t_in, t_out = (b - a) / np.linalg.norm(b - a), (c - b) / np.linalg.norm(c - b)
    turn = np.arccos(t_in @ t_out)
    (corner,) = [zone for zone in zones if zone[0] < 0.5 < zone[1]]
    # planned and nominal frames agree at the zone ends and each turns by `turn` across it
    assert 0.1 * turn < corner[2] <= 2 * turn
    assert corner[1] - corner[0] < 0.1


def test_part_frame_has_no_transition_bound(corner_geometry):
    spec = ToolSpec.part(np.array([-np.pi / 2, 0, 0]))
    assert transition_zones(spec, corner_geometry, 1e-3)[:, 2] == pytest.approx(0.0)
    R = spec.base_rotations(np.eye(3))
    assert rotation_angle(R, np.broadcast_to(rpy_matrix([-np.pi / 2, 0, 0]), R.shape)).max() < 1e-12
    assert replace(spec, spin=SpinMode.FREE).n_spin == 1


# Per-segment normals (task.tool.normals).

TWO_FACES = CASES / "bracket-two-faces.yaml"


def _segment_seam_axis(normals, nominal, s_nominal, piece, tangent_of):
    """The spec's tool axis at zero spin, built here from first principles: each sample's
    segment normal made perpendicular to the nominal tangent (z_s = −n), then the work and
    travel rotations applied with scipy."""
    t = tangent_of(nominal, s_nominal, piece)
    n = np.asarray(normals, dtype=float)[nominal.segment_index[piece]]
    n = n - np.einsum("mk,mk->m", n, t)[:, None] * t
    z = -n / np.linalg.norm(n, axis=1, keepdims=True)
    return np.stack([t, np.cross(z, t), z], axis=-1)


def _collinear_geometry():
    from trackplan.io.case_file import load_case_text

    text = """
name: collinear
path:
  start: [0, 0, 0]
  segments:
    - line: {to: [0.1, 0, 0]}
    - line: {to: [0.2, 0, 0]}
    - line: {to: [0.2, 0.1, 0]}
task:
  rated_speed: 0.02
  tolerance: 0.0005
"""
    return PathGeometry.from_case(load_case_text(text, file="collinear.yaml"))


@pytest.fixture(scope="module")
def two_faces_geometry():
    return PathGeometry.from_case(load_case(TWO_FACES))


@pytest.fixture(scope="module")
def collinear_geometry():
    return _collinear_geometry()


def _unit_across(rng, tangent):
    """A random unit vector at least 20° away from ±tangent."""
    while True:
        n = rng.normal(size=3)
        n /= np.linalg.norm(n)
        if abs(n @ tangent) < np.cos(np.radians(20)):
            return n


@settings(max_examples=8, deadline=None, derandomize=True)
@given(
    seed=st.integers(0, 10_000),
    which=st.sampled_from(["corner", "two faces", "collinear"]),
    work=st.floats(-0.8, 0.8),
    travel=st.floats(-0.5, 0.5),
)
def test_segment_normals_are_exact_outside_transition_zones_and_bounded_inside(
    corner_geometry, two_faces_geometry, collinear_geometry, seed, which, work, travel
):
    geometry = {
        "corner": corner_geometry,
        "two faces": two_faces_geometry,
        "collinear": collinear_geometry,
    }[which]
    planned, nominal = geometry.planned, geometry.nominal
    rng = np.random.default_rng(seed)
    normals = []
    for segment in range(len(nominal.segments)):
        first = np.flatnonzero(nominal.segment_index == segment)[0]
        tangent = nominal.pieces[first].curve.evaluate(np.zeros(1)).tangent[0]
        normals.append(_unit_across(rng, tangent) * rng.uniform(0.5, 2.0))
    spec = ToolSpec(
        frame=ToolFrame.SEAM, normals=np.array(normals), work_angle=work, travel_angle=travel
    )
    s = np.sort(rng.uniform(0.0, planned.length, 4000))
    sample = planned.sample(s)
    R = ToolOrientation.choose(spec, geometry).base_rotations(s, sample.tangent)
    s_nominal, _, piece = locate_on_nominal(nominal, sample.position, sample.tangent, 1e-3)
    R_seam = _segment_seam_axis(normals, nominal, s_nominal, piece, nominal_tangents)
    R_spec = R_seam @ Rotation.from_euler("XY", [work, travel]).as_matrix()  # Rx(work)·Ry(travel)
    error = np.arccos(np.clip(np.einsum("ni,ni->n", R[:, :, 2], R_spec[:, :, 2]), -1, 1))
    zones = transition_zones(spec, geometry, 1e-3)
    inside = np.zeros(len(s), dtype=bool)
    for s0, s1, bound in zones:
        zone = (s_nominal >= s0) & (s_nominal <= s1)
        assert error[zone].max(initial=0.0) <= bound
        inside |= zone
    assert error[~inside].max() <= AXIS_EXACT
    # a zone per junction, each within 2 cm of it
    junctions = [nominal.pieces[k].s_start for k in range(1, len(nominal.pieces))]
    assert len(zones) <= len(junctions)
    for s0, s1, _ in zones:
        assert any(s0 - 0.02 < j < s1 + 0.02 for j in junctions) and s1 - s0 < 0.04


@pytest.mark.parametrize("name", ["two faces", "collinear"])
def test_a_normal_jump_is_blended_smoothly(two_faces_geometry, collinear_geometry, name):
    """Across a junction where the normal jumps the tool turns continuously: on a 10 µm
    grid the tool axis never steps by more than the smooth step's peak rate allows."""
    geometry = two_faces_geometry if name == "two faces" else collinear_geometry
    normals = [[0, 0, 1], [-1, 0, 0]] if name == "two faces" else [[0, 0, 1], [0, -1, 1], [0, 0, 1]]
    spec = ToolSpec(frame=ToolFrame.SEAM, normals=np.array(normals, dtype=float))
    tool = ToolOrientation.choose(spec, geometry)
    assert tool.normals is not None and len(tool.normals.windows) == len(normals) - 1
    planned = geometry.planned
    s = np.arange(0.0, planned.length, 1e-5)
    axis = tool.base_rotations(s, planned.sample(s).tangent)[:, :, 2]
    step = np.arccos(np.clip(np.einsum("mi,mi->m", axis[1:], axis[:-1]), -1, 1))
    assert step.max() < 0.02  # no jump anywhere (a sharp 90° corner blend turns it fastest)
    normal = tool.normals(s)
    step = np.arccos(np.clip(np.einsum("mi,mi->m", normal[1:], normal[:-1]), -1, 1))
    jump = np.pi / 2 if name == "two faces" else np.pi / 4
    for s0, s1, *_ in tool.normals.windows:
        # the smooth step's slope peaks at 15/8: the jump spread over the window
        inside = (s[1:] > s0) & (s[:-1] < s1)
        assert step[inside].max() < 2 * 15 / 8 * jump * 1e-5 / (s1 - s0)
        assert step[inside].sum() == pytest.approx(jump, rel=1e-3)
        assert 1e-3 < s1 - s0 < 0.03
    assert step.sum() == pytest.approx(jump * len(tool.normals.windows), rel=1e-3)
    # away from the junctions the tool points into each segment's face (normals ⊥ tangents)
    middle = np.array([0.5 * (p.s_start + p.s_end) for p in geometry.nominal.pieces])
    unit = np.array(normals, dtype=float) / np.linalg.norm(normals, axis=1, keepdims=True)
    axis = tool.base_rotations(middle, planned.sample(middle).tangent)[:, :, 2]
    np.testing.assert_allclose(axis, -unit[geometry.nominal.segment_index], atol=1e-12)


def test_two_faces_case_plans_feasibly_and_checks():
    from trackplan.planning.plan import check

    case = load_case(TWO_FACES)
    assert case.task.tool.normals is not None and len(case.task.tool.normals) == 2
    X = case.bounds.example
    result = plan(case, X, spin=np.array([-2.3905]))
    assert result.success, result.message
    report = check(case, X, result.trajectory.q, case.task.sample_time)
    assert report.success
    # the tool turns from one face's normal to the other's: about 90° across the bend
    assert 1.0 < report.max_orientation_error < 1.5


def test_spinning_rotations_elementwise_is_the_matrix_product():
    rng = np.random.default_rng(7)
    R = Rotation.random(500, random_state=8).as_matrix()
    angle = rng.uniform(-4.0, 4.0, 500)
    np.testing.assert_allclose(spun(R, angle), R @ rotation_z(angle), rtol=0, atol=4e-16)
    np.testing.assert_allclose(spun(R[0], angle), R[0] @ rotation_z(angle), rtol=0, atol=4e-16)
