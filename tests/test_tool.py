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
    spin_knots,
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
