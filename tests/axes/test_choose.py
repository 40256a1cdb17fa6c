"""The positioner's and the track's profiles along a seam (trackplan.axes.choose).

Every downhand check here recomputes the angles with its own forward kinematics of the
test positioner (tilt about −y, then rotation about −z) and the seams' exact normals and
tangents, not with the code under test.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from tests.axes import cells
from trackplan.axes.choose import AxesFailure, choose_axes
from trackplan.axes.figures import downhand_figures
from trackplan.axes.profile import AxesProfile
from trackplan.axes.rules import Downhand
from trackplan.errors import CaseError
from trackplan.frames import placement_transform
from trackplan.paths.path_geometry import PathGeometry
from trackplan.robots.machine import Track
from trackplan.status import Status

RULE = Downhand(slope=math.radians(10.0), rotation=math.radians(10.0))
POSE = np.array([0.8, 0.0, -0.6, 0.0, 0.0, 0.3])
"""The positioner's base in the cell: beside the arm, turned 0.3 rad about z."""
ANGLE_TOL = 2e-3
"""Allowance of the independent angles over the rule, rad: the saddle's normals are
interpolated between its points (about 1e-3 rad from the exact bisector) and the planned
path rounds the points within the tolerance."""


def _rx(a: np.ndarray) -> np.ndarray:
    c, s, o, i = np.cos(a), np.sin(a), np.zeros_like(a), np.ones_like(a)
    return np.stack([i, o, o, o, c, -s, o, s, c], -1).reshape(*np.shape(a), 3, 3)


def _ry(a: np.ndarray) -> np.ndarray:
    c, s, o, i = np.cos(a), np.sin(a), np.zeros_like(a), np.ones_like(a)
    return np.stack([c, o, s, o, i, o, -s, o, c], -1).reshape(*np.shape(a), 3, 3)


def _rz(a: np.ndarray) -> np.ndarray:
    c, s, o, i = np.cos(a), np.sin(a), np.zeros_like(a), np.ones_like(a)
    return np.stack([c, -s, o, s, c, o, o, o, i], -1).reshape(*np.shape(a), 3, 3)


def _table_rotation(pose: np.ndarray, tilt: np.ndarray, rotate: np.ndarray) -> np.ndarray:
    """The table's rotation in the cell: the pose's roll-pitch-yaw, a turn of ``tilt`` about
    −y, then of ``rotate`` about −z (the D500's layout), shape (M, 3, 3)."""
    R_pose = _rz(pose[5]) @ _ry(pose[4]) @ _rx(pose[3])
    return R_pose @ _ry(-tilt) @ _rz(-rotate)


def _exact_normal(kind: str, position: np.ndarray) -> np.ndarray:
    """The exact weld normal (M, 3) of the pipe fillet or the saddle at points of its path
    (part frame): the bisector of the two faces' outward normals."""
    phi = np.arctan2(position[:, 1], position[:, 0])
    radial = np.column_stack([np.cos(phi), np.sin(phi), 0 * phi])
    if kind == "pipe":
        other = np.tile([0.0, 0.0, 1.0], (len(phi), 1))
    else:
        other = np.column_stack([0 * phi, position[:, 1], position[:, 2]])
        other /= np.linalg.norm(other, axis=1, keepdims=True)
    normal = radial + other
    return normal / np.linalg.norm(normal, axis=1, keepdims=True)


def _independent_angles(
    kind: str, geometry: PathGeometry, X: np.ndarray, profile: AxesProfile, s: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """Slope and rotation (M,) rad of the seam under the profile, recomputed."""
    sample = geometry.planned.sample(s)
    normal = _exact_normal(kind, sample.position)
    tangent = sample.tangent  # the planned path's: a polyline's blended corners included
    R_X = placement_transform(X)[:3, :3]
    e = profile.values(s)
    R = _table_rotation(POSE, e[:, 0], e[:, 1]) @ R_X
    n_z = np.einsum("mk,mk->m", R[:, 2, :], normal)
    t_z = np.einsum("mk,mk->m", R[:, 2, :], tangent)
    return np.arcsin(np.abs(t_z)), np.arccos(np.clip(n_z, -1.0, 1.0))


def _measure(profile: AxesProfile, s: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    return (
        np.abs(profile.derivative(s, 1)).max(axis=0),
        np.abs(profile.derivative(s, 2)).max(axis=0),
    )


@pytest.fixture(scope="module")
def two_axis():
    return cells.machine(cells.tilt_rotate_chain(), POSE)


def test_pipe_fillet_is_held_downhand_by_tilt_and_rotation(two_axis):
    """The pipe on the table (X = 0, its axis on the rotation axis): a constant 45° tilt
    and a full turn of the rotate axis, wound into its ±200° range; downhand at every
    sample (slope and rotation ≤ 10°, in fact below 0.1°)."""
    geometry = cells.pipe_fillet()
    X = np.zeros(6)
    profile = choose_axes(two_axis, geometry, cells.seam_tool(), X, RULE)
    assert isinstance(profile, AxesProfile) and profile.n_axes == 2
    s = np.linspace(0.0, geometry.planned.length, 4001)
    slope, rotation = _independent_angles("pipe", geometry, X, profile, s)
    assert slope.max() <= math.radians(0.1) and rotation.max() <= math.radians(0.1)
    e = profile.values(s)
    np.testing.assert_allclose(np.abs(e[:, 0]), math.pi / 4, atol=1e-3)
    assert np.ptp(e[:, 1]) == pytest.approx(2 * math.pi, abs=1e-3)
    assert np.all(e >= two_axis.positioner.chain.q_min) and np.all(
        e <= two_axis.positioner.chain.q_max
    )
    rate, curvature = _measure(profile, s)
    assert rate[1] == pytest.approx(2 * math.pi / geometry.planned.length, rel=1e-3)
    assert curvature.max() < 1.0  # a straight ramp in s: no wiggles


def test_saddle_is_held_downhand_with_both_axes_moving(two_axis):
    """The saddle (a 50 mm branch on a 100 mm main pipe): the table turns a full turn and
    the tilt rocks with it; every sample within the rule, by the independent angles."""
    geometry = cells.saddle()
    X = np.zeros(6)
    profile = choose_axes(two_axis, geometry, cells.seam_tool(), X, RULE)
    assert isinstance(profile, AxesProfile)
    s = np.linspace(0.0, geometry.planned.length, 4001)
    slope, rotation = _independent_angles("saddle", geometry, X, profile, s)
    assert slope.max() <= RULE.slope + ANGLE_TOL
    assert rotation.max() <= RULE.rotation + ANGLE_TOL
    e = profile.values(s)
    assert np.ptp(e[:, 0]) > math.radians(1.0) and np.ptp(e[:, 1]) > math.radians(300.0)
    # the least motion the 10° bounds leave room for: the exact "straight up" motion's
    # largest |d²e/ds²| is 300 and 400 rad/m² (finite differences of the closed form); the
    # chosen profile's is far below (a fit of the exact motion alone reaches 433 on the tilt)
    _, curvature = _measure(profile, s)
    assert np.all(curvature <= 0.2 * np.array([300.0, 400.0]))


def test_straight_seam_on_a_plate_needs_no_motion(two_axis):
    """The plate flat on the table: the positioner holds still at 0 (its hold value)."""
    geometry = cells.plate_line()
    profile = choose_axes(two_axis, geometry, cells.plate_tool(), np.zeros(6), RULE)
    assert isinstance(profile, AxesProfile)
    assert [p.coefficients.tolist() for p in profile.profiles] == [[0.0], [0.0]]


def test_a_tilted_plate_gets_one_constant_tilt(two_axis):
    """The plate tilted by 30° on the table: one constant pose of the positioner puts it
    flat (no motion along the seam), checked independently."""
    geometry = cells.plate_line()
    X = np.array([0.0, 0.0, 0.0, 0.0, math.radians(30.0), 0.0])
    profile = choose_axes(two_axis, geometry, cells.plate_tool(), X, RULE)
    assert isinstance(profile, AxesProfile)
    assert all(len(p.coefficients) == 1 for p in profile.profiles)
    e = profile.values(np.zeros(1))
    R = _table_rotation(POSE, e[:, 0], e[:, 1]) @ placement_transform(X)[:3, :3]
    assert (R[0] @ [0.0, 0.0, 1.0])[2] >= math.cos(RULE.rotation)


def test_a_head_stock_keeps_a_butt_weld_on_top_of_a_lying_pipe():
    """One horizontal axis (the chain's +x) under a pipe lying along it (X turns the
    pipe's axis onto x): the radial weld normal is made exactly vertical at every sample
    by a full turn, the travel direction horizontal; checked with own rotations."""
    machine = cells.machine(cells.head_stock_chain(), (0.8, 0.0, -0.6, 0.0, 0.0, 0.0))
    geometry = cells.pipe_butt()
    X = np.array([0.0, 0.0, 0.0, 0.0, math.pi / 2, 0.0])
    profile = choose_axes(machine, geometry, cells.seam_tool(), X, RULE)
    assert isinstance(profile, AxesProfile) and profile.n_axes == 1
    s = np.linspace(0.0, geometry.planned.length, 2001)
    sample = geometry.planned.sample(s)
    radial = sample.position / np.linalg.norm(sample.position, axis=1, keepdims=True)
    R = _rx(profile.values(s)[:, 0]) @ _ry(np.array(math.pi / 2))
    n_z = np.einsum("mk,mk->m", R[:, 2, :], radial)
    t_z = np.einsum("mk,mk->m", R[:, 2, :], sample.tangent)
    assert np.arccos(np.clip(n_z, -1.0, 1.0)).max() < math.radians(0.5)
    assert np.arcsin(np.abs(t_z)).max() < math.radians(0.5)
    assert np.ptp(profile.values(s)) == pytest.approx(2 * math.pi, abs=1e-2)


def test_a_turntable_cannot_make_a_tilted_normal_vertical():
    machine = cells.machine(cells.turntable_chain())
    geometry = cells.pipe_fillet()
    failure = choose_axes(machine, geometry, cells.seam_tool(), np.zeros(6), RULE)
    assert isinstance(failure, AxesFailure)
    assert failure.status is Status.LIMITS_VIOLATED
    assert failure.message == (
        "downhand: the weld normal stays 45.0° from straight up at s = 0.000–"
        f"{geometry.planned.length:.3f} m (rotation ≤ 10.0°): the positioner's axes cannot "
        "turn it further"
    )
    assert (failure.s_from, failure.s_to) == (0.0, pytest.approx(geometry.planned.length))
    assert failure.reached == pytest.approx(math.pi / 4, abs=1e-6)


def test_a_turntable_names_only_the_stretch_that_leans_too_far():
    """A seam that runs flat, then up a 30° ramp: the turntable fails on the ramp only."""
    from trackplan.paths.specs import LineSpec

    rise = math.tan(math.radians(30.0)) * 0.2
    geometry = PathGeometry.build(
        np.zeros(3),
        [LineSpec(np.array([0.2, 0.0, 0.0])), LineSpec(np.array([0.4, 0.0, rise]))],
        cells.TOLERANCE,
    )
    machine = cells.machine(cells.turntable_chain())
    failure = choose_axes(machine, geometry, cells.plate_tool(), np.zeros(6), RULE)
    assert isinstance(failure, AxesFailure)
    assert "the travel direction stays" in failure.message
    start, end = (float(v) for v in failure.message.split("s = ")[1].split(" m")[0].split("–"))
    assert 0.19 < start < 0.2 and end == pytest.approx(geometry.planned.length, abs=1e-3)


def test_without_a_positioner_the_pipe_cannot_be_downhand():
    failure = choose_axes(
        cells.machine(None), cells.pipe_fillet(), cells.seam_tool(), np.zeros(6), RULE
    )
    assert isinstance(failure, AxesFailure)
    assert failure.message.endswith("there is no positioner to turn the part")


def test_without_downhand_the_positioner_holds_still(two_axis):
    profile = choose_axes(two_axis, cells.pipe_fillet(), cells.seam_tool(), np.zeros(6), None)
    assert isinstance(profile, AxesProfile)
    assert [p.coefficients.tolist() for p in profile.profiles] == [[0.0], [0.0]]


def test_downhand_without_a_weld_normal_is_a_case_error(two_axis):
    from trackplan.tool.spec import ToolSpec

    with pytest.raises(CaseError, match="needs a weld normal") as err:
        choose_axes(two_axis, cells.plate_line(), ToolSpec(), np.zeros(6), RULE)
    assert err.value.key == "downhand"


def test_figures_agree_with_the_independent_angles(two_axis):
    geometry = cells.saddle()
    X = np.array([0.01, -0.02, 0.0, 0.3, -0.2, 0.5])
    profile = choose_axes(two_axis, geometry, cells.seam_tool(), X, RULE)
    assert isinstance(profile, AxesProfile)
    s = np.linspace(0.0, geometry.planned.length, 501)
    q = np.zeros((len(s), two_axis.n_dof))
    q[:, two_axis.n_arm :] = profile.values(s)
    slope, rotation = downhand_figures(two_axis, q, geometry, cells.seam_tool(), X, s)
    own_slope, own_rotation = _independent_angles("saddle", geometry, X, profile, s)
    np.testing.assert_allclose(slope, own_slope, atol=ANGLE_TOL)
    np.testing.assert_allclose(rotation, own_rotation, atol=ANGLE_TOL)


@pytest.fixture(scope="module")
def endless():
    """The two-axis positioner with a ±400° rotate axis: every full-circle seam fits."""
    return cells.machine(cells.tilt_rotate_chain(rotate_range=400.0), POSE)


@settings(max_examples=10, deadline=None)
@given(
    xy=st.tuples(st.floats(-0.05, 0.05), st.floats(-0.05, 0.05)),
    rpy=st.tuples(st.floats(-0.6, 0.6), st.floats(-0.6, 0.6), st.floats(-math.pi, math.pi)),
    kind=st.sampled_from(["pipe", "saddle"]),
)
def test_any_placement_on_the_two_axis_positioner_is_held_downhand(endless, xy, rpy, kind):
    """The two-axis positioner turns any normal up (a tilt within ±135°) and its ±400°
    rotate axis holds a full turn from any start: the fitted profile meets the rule at every
    sample, by the independent angles, inside the axes' ranges."""
    geometry = cells.pipe_fillet() if kind == "pipe" else cells.saddle(count=48)
    X = np.array([*xy, 0.0, *rpy])
    profile = choose_axes(endless, geometry, cells.seam_tool(), X, RULE)
    assert isinstance(profile, AxesProfile)
    s = np.linspace(0.0, geometry.planned.length, 2001)
    slope, rotation = _independent_angles(kind, geometry, X, profile, s)
    assert slope.max() <= RULE.slope + ANGLE_TOL
    assert rotation.max() <= RULE.rotation + ANGLE_TOL
    e = profile.values(s)
    chain = endless.positioner.chain
    assert np.all(e >= chain.q_min - 1e-12) and np.all(e <= chain.q_max + 1e-12)


def test_a_full_turn_that_starts_badly_is_out_of_the_rotate_range(two_axis):
    """On the ±200° rotate axis a saddle whose start needs the table at 102° must sweep
    to 462°: no whole turn brings that into the range, and the verdict says so."""
    X = np.array([0.01, -0.02, 0.0, 0.3, -0.2, -1.0])
    failure = choose_axes(two_axis, cells.saddle(), cells.seam_tool(), X, RULE)
    assert isinstance(failure, AxesFailure) and failure.status is Status.POSITION_LIMITS
    assert failure.message.startswith(
        "downhand: the positioner's axis rotate must turn from 102.2° to 462.2° (a sweep of "
        "360.0°) at s = 0.000–0.320 m"
    )
    assert failure.message.endswith("inside its range [-200.0°, 200.0°]")


# --------------------------------------------------------------------------- the track


def _track(lower: float = 0.0, upper: float = 4.0) -> Track:
    return Track(np.array([1.0, 0.0, 0.0]), lower, upper, 1.0, 2.0, 20.0)


def test_a_3_m_seam_along_a_4_m_track_is_a_smooth_ramp():
    """The base abreast of the TCP: t(s) = x_start + s, exactly (a cubic spline holds a
    line), with dt/ds = 1 and no curvature."""
    machine = cells.machine(None, track=_track())
    geometry = cells.plate_line(3.0)
    X = np.array([0.5, 0.4, 0.0, 0.0, 0.0, 0.0])
    profile = choose_axes(machine, geometry, cells.plate_tool(), X, None)
    assert isinstance(profile, AxesProfile) and profile.n_axes == 1
    s = np.linspace(0.0, 3.0, 1001)
    np.testing.assert_allclose(profile.values(s)[:, 0], 0.5 + s, atol=1e-9)
    rate, curvature = _measure(profile, s)
    assert rate[0] == pytest.approx(1.0, abs=1e-9) and curvature[0] < 1e-6


def test_the_track_stops_smoothly_at_its_end():
    """A seam running 1 m past the track's end: the profile stays inside the range (the
    coefficients' hull) and bends smoothly (bounded second derivative)."""
    machine = cells.machine(None, track=_track(0.0, 2.0))
    geometry = cells.plate_line(3.0)
    profile = choose_axes(machine, geometry, cells.plate_tool(), np.zeros(6), None)
    assert isinstance(profile, AxesProfile)
    s = np.linspace(0.0, 3.0, 3001)
    t = profile.values(s)[:, 0]
    assert t.min() >= 0.0 and t.max() <= 2.0
    assert t[-1] == pytest.approx(2.0, abs=5e-3) and t[1000] == pytest.approx(1.0, abs=0.05)
    rate, curvature = _measure(profile, s)
    assert rate[0] <= 1.3 and curvature[0] < 20.0


def test_the_track_comes_first_and_follows_the_turning_part():
    """Track and positioner together: the track's profile first; with the pipe turning
    under the torch the weld point stays nearly still in the cell, and so does the track."""
    machine = cells.machine(cells.tilt_rotate_chain(), POSE, track=_track(-1.0, 3.0))
    geometry = cells.pipe_fillet()
    profile = choose_axes(machine, geometry, cells.seam_tool(), np.zeros(6), RULE)
    assert isinstance(profile, AxesProfile) and profile.n_axes == 3
    s = np.linspace(0.0, geometry.planned.length, 1001)
    e = profile.values(s)
    T = placement_transform(POSE)
    p = (T[:3, :3] @ _rz(0.0 * s[:1])[0] @ [0.0, 0.0, 0.0]) + T[:3, 3]
    assert np.ptp(e[:, 0]) < 0.1 * 2 * 0.06 + 0.02  # far less than the pipe's diameter
    assert abs(float(np.mean(e[:, 0])) - p[0]) < 0.25  # near the positioner's x


def test_a_normal_that_swings_through_the_rotate_axis_keeps_one_smooth_branch(two_axis):
    """A seam along x whose normal swings across it (in the y-z plane) from −40° through
    straight up to +40°: the two closed-form branches meet where the tilt passes 0, and
    the least motion is to tilt through it with the table's rotation still (not to flip
    the table by 180° there)."""
    from trackplan.paths.specs import PointsSpec

    x = np.linspace(0.0, 0.2, 21)
    lean = np.radians(np.linspace(-40.0, 40.0, 21))
    normals = np.column_stack([0 * x, np.sin(lean), np.cos(lean)])
    points = np.column_stack([x, 0 * x, 0 * x])
    geometry = PathGeometry.build(
        points[0], [PointsSpec(points[1:], normals[1:], start_normal=normals[0])], 5e-4
    )
    profile = choose_axes(two_axis, geometry, cells.seam_tool(), np.zeros(6), RULE)
    assert isinstance(profile, AxesProfile)
    s = np.linspace(0.0, geometry.planned.length, 2001)
    e = profile.values(s)
    assert np.ptp(e[:, 1]) < math.radians(1.0)  # the table does not turn
    assert np.ptp(e[:, 0]) > math.radians(40.0)  # the tilt takes the swing
    R = _table_rotation(POSE, e[:, 0], e[:, 1])
    lean_s = np.interp(geometry.planned.sample(s).position[:, 0], x, lean)
    n = np.column_stack([0 * s, np.sin(lean_s), np.cos(lean_s)])
    rotation = np.arccos(np.clip(np.einsum("mk,mk->m", R[:, 2, :], n), -1.0, 1.0))
    assert rotation.max() <= RULE.rotation + 0.02  # the normal's interpolation: ≈ 1°/mm


@pytest.mark.parametrize("degrees", [2.0, 5.0])
def test_a_tighter_rule_is_met_as_tightly(two_axis, degrees):
    """The saddle under a rule of 2° and 5°: the profile follows "straight up" more
    closely, every sample within the rule by the independent angles."""
    rule = Downhand(slope=math.radians(degrees), rotation=math.radians(degrees))
    geometry = cells.saddle()
    profile = choose_axes(two_axis, geometry, cells.seam_tool(), np.zeros(6), rule)
    assert isinstance(profile, AxesProfile)
    s = np.linspace(0.0, geometry.planned.length, 4001)
    slope, rotation = _independent_angles("saddle", geometry, np.zeros(6), profile, s)
    assert slope.max() <= rule.slope + ANGLE_TOL
    assert rotation.max() <= rule.rotation + ANGLE_TOL


def test_a_climb_steeper_than_the_slope_bound_trades_rotation_for_slope(two_axis):
    """A seam climbing 14° across a plate whose normal is +z (the normal not square to the
    travel): with the normal straight up the travel slopes 14°, over the 10° bound; the
    positioner leans the part back by 4 to 10° instead, both angles within the rule."""
    from trackplan.paths.specs import LineSpec

    climb = math.radians(14.0)
    to = np.array([0.2, 0.0, 0.2 * math.tan(climb)])
    geometry = PathGeometry.build(np.zeros(3), [LineSpec(to)], cells.TOLERANCE)
    X = np.zeros(6)
    profile = choose_axes(two_axis, geometry, cells.plate_tool(), X, RULE)
    assert isinstance(profile, AxesProfile)
    s = np.linspace(0.0, geometry.planned.length, 501)
    e = profile.values(s)
    R = _table_rotation(POSE, e[:, 0], e[:, 1])
    t = to / np.linalg.norm(to)
    slope = np.arcsin(np.abs(R[:, 2, :] @ t))
    rotation = np.arccos(np.clip(R[:, 2, :] @ [0.0, 0.0, 1.0], -1.0, 1.0))
    assert slope.max() <= RULE.slope and rotation.max() <= RULE.rotation


def test_the_shipped_pipe_fillet_case_is_held_downhand(two_axis):
    """cases/pipe-fillet.yaml as the case loader reads it (its arc's weld_normal, the
    seam-frame tool with a drag angle) on the two-axis positioner, pipe on the table."""
    from tests.conftest import CASES
    from trackplan.io.case_file import load_case

    case = load_case(CASES / "pipe-fillet.yaml")
    geometry = PathGeometry.from_case(case)
    profile = choose_axes(two_axis, geometry, case.task.tool, np.zeros(6), RULE)
    assert isinstance(profile, AxesProfile)
    s = np.linspace(0.0, geometry.planned.length, 2001)
    slope, rotation = _independent_angles("pipe", geometry, np.zeros(6), profile, s)
    assert slope.max() <= RULE.slope and rotation.max() <= RULE.rotation
