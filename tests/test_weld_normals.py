"""Weld normals declared on path segments: turning arcs, points with normals (docs/tool.md)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import yaml
from hypothesis import given, settings
from hypothesis import strategies as st

from tests.conftest import CASES
from trackplan.errors import CaseError
from trackplan.frames import placement_transform
from trackplan.io.case_file import load_case
from trackplan.io.points_file import load_points_csv
from trackplan.paths.path_geometry import PathGeometry
from trackplan.paths.specs import PointsSpec
from trackplan.planning.plan import plan
from trackplan.planning.seams import reversed_segments
from trackplan.robots.kinematics import forward_kinematics
from trackplan.tool import ToolOrientation
from trackplan.tool.weld_normal import ArcNormal, PointsNormal

PIPE = CASES / "pipe-fillet.yaml"
WORK_ANGLE_TOL = 1e-4
"""Largest error of the planned tool's work and travel angles against the declared normal,
rad: on the arc the planned orientation is the spec's to rounding (result.json's
max_orientation_error is about 3e-8 rad); the rest allows for FK and the tracking error."""


def _unit(v: np.ndarray) -> np.ndarray:
    return v / np.linalg.norm(v, axis=-1, keepdims=True)


def _rotate_z(v: np.ndarray, angle: np.ndarray) -> np.ndarray:
    c, s = np.cos(angle), np.sin(angle)
    return np.stack([c * v[0] - s * v[1], s * v[0] + c * v[1], np.full_like(angle, v[2])], -1)


# --------------------------------------------------------------------------- interpolation


@settings(max_examples=60, deadline=None)
@given(
    steps=st.lists(st.floats(1e-3, 0.2), min_size=2, max_size=8),
    tilts=st.lists(st.floats(-1.2, 1.2), min_size=8, max_size=8),
    lengths=st.lists(st.floats(0.2, 5.0), min_size=8, max_size=8),
)
def test_points_normal_is_unit_and_exact_at_the_points(steps, tilts, lengths):
    """Normals within 70° of +z, of any length, along a curve: the normalised spline
    equals each point's unit normal there and is unit everywhere it is defined (it stays
    away from zero for evenly spaced points and gentle turns)."""
    k = len(steps)
    x = np.cumsum(steps)
    points = np.stack([x, 0.1 * np.sin(x), np.zeros(k)], axis=1)
    tilt = np.array(tilts[:k])
    normals = (
        np.stack([np.sin(tilt), np.zeros(k), np.cos(tilt)], 1) * np.array(lengths[:k])[:, None]
    )
    field = PointsNormal.from_points(np.zeros(3), PointsSpec(points, normals))
    at_points = _unit(field(points, field.knots))
    np.testing.assert_allclose(at_points, _unit(normals), atol=1e-12)
    sigma = np.linspace(0.0, field.knots[-1], 2000)
    raw = field(np.zeros((len(sigma), 3)), sigma)
    length = np.linalg.norm(raw, axis=1)
    usable = length >= 0.1  # shorter: the case loader refuses the points (a test below)
    np.testing.assert_allclose(np.linalg.norm(_unit(raw[usable]), axis=1), 1.0, atol=1e-14)
    if np.ptp(steps) <= 0.5 * min(steps) and np.ptp(tilt) <= 1.0:  # evenly spaced, gentle
        assert usable.all()


def test_arc_normal_is_the_start_normal_turned_with_the_point():
    from trackplan.paths.specs import ArcSpec

    arc = ArcSpec(np.array([0.1, 0.2, 0.0]), np.array([0, 0, 2.0]), 2 * np.pi)
    start = np.array([0.4, 0.2, 0.0])
    n0 = np.array([1.0, 0.5, 1.0])
    field = ArcNormal.from_arc(start, arc, n0)
    angle = np.linspace(0.0, 2 * np.pi, 37)
    position = arc.center + _rotate_z(start - arc.center, angle)
    np.testing.assert_allclose(field(position, angle), _rotate_z(_unit(n0), angle), atol=1e-14)


def test_turning_normal_on_the_planned_path_is_continuous_and_smooth(tmp_path):
    """A points segment whose normal turns by 60° between its points, after a line with
    the tool's normal: on a 10 µm grid the planned normal never jumps, and its second
    difference (curvature in s) stays bounded, including across the junction window."""
    x = np.linspace(0.02, 0.2, 10)
    rows = np.column_stack(
        [x, np.zeros(10), np.zeros(10), np.sin(3 * x), np.zeros(10), np.cos(3 * x)]
    )
    case = _case(
        tmp_path,
        [{"line": {"to": [0.0, 0.0, 0.0]}}, {"points": rows.tolist()}],
        start=[-0.1, 0.0, 0.0],
    )
    geometry = PathGeometry.from_case(case)
    tool = ToolOrientation.choose(case.task.tool, geometry)
    assert tool.normals is not None
    h = 1e-5
    s = np.arange(0.0, geometry.planned.length, h)
    n = tool.normals(s)
    np.testing.assert_allclose(np.linalg.norm(n, axis=1), 1.0, atol=1e-12)
    step = np.linalg.norm(np.diff(n, axis=0), axis=1)
    assert step.max() < 3.0 * h * 3.0  # |dn/ds| ≤ 3 rad/m from the data, with margin
    second = np.linalg.norm(np.diff(n, 2, axis=0), axis=1) / h**2
    assert second.max() < 2000.0  # bounded: no kink (a kink gives ~ |Δ slope| / h = 3e5)


# --------------------------------------------------------------------------- files


def test_points_file_with_normals_reads_six_columns(tmp_path):
    csv = tmp_path / "seam.csv"
    csv.write_text("x,y,z,nx,ny,nz\n0.1,0,0,0,0,1\n0.2,0,0,0,1,1\n")
    np.testing.assert_array_equal(
        load_points_csv(csv), [[0.1, 0, 0, 0, 0, 1], [0.2, 0, 0, 0, 1, 1]]
    )
    csv.write_text("x,y,z\n0.1,0,0\n0.2,0,0\n")  # today's files are unchanged
    np.testing.assert_array_equal(load_points_csv(csv), [[0.1, 0, 0], [0.2, 0, 0]])


def test_both_readers_take_a_file_with_normals(tmp_path):
    """A line of spaces sends the file to the line-by-line reader: same rows."""
    csv = tmp_path / "seam.csv"
    csv.write_text("# seam\nX, Y, Z, NX, NY, NZ\n0.1,0,0,0,0,1\n   \n0.2, 0, 0, 0, 1, 1\n")
    np.testing.assert_array_equal(
        load_points_csv(csv), [[0.1, 0, 0, 0, 0, 1], [0.2, 0, 0, 0, 1, 1]]
    )
    csv.write_text("x,y,z,nx,ny,nz\n0.1,0,0,0,0,1\n   \n0.2,0,0,0,1\n")
    with pytest.raises(CaseError, match="got 5 values") as err:
        load_points_csv(csv)
    assert "line 4" in err.value.one_line()


def test_six_numbers_without_the_header_are_refused_with_a_hint(tmp_path):
    csv = tmp_path / "seam.csv"
    csv.write_text("0.1,0,0,0,0,1\n0.2,0,0,0,1,1\n")
    with pytest.raises(CaseError, match="header x,y,z,nx,ny,nz") as err:
        load_points_csv(csv)
    assert "line 1" in err.value.one_line()
    csv.write_text("x,y,z,nx,ny,nz\n0.1,0,0,0,0,1\n0.2,0,0\n")
    with pytest.raises(CaseError, match=r"expected six finite numbers .* got 3 values"):
        load_points_csv(csv)


def _case(tmp_path: Path, segments, tool=None, start=(0.0, 0.0, 0.0), name="weld"):
    data = {
        "name": name,
        "robot": "ur5e",
        "path": {"start": list(start), "segments": segments},
        "task": {
            "rated_speed": 0.01,
            "tolerance": 0.0005,
            "tool": tool
            if tool is not None
            else {"frame": "seam", "normal": [0, 0, 1], "work_angle": 0.3},
        },
    }
    file = tmp_path / f"{name}.yaml"
    file.write_text(yaml.safe_dump(data))
    return load_case(file)


def _refusal(tmp_path, segments, tool=None) -> str:
    with pytest.raises(CaseError) as err:
        _case(tmp_path, segments, tool, start=(0.05, 0.0, 0.0))
    return err.value.one_line()


ARC = {"center": [0, 0, 0], "normal": [0, 0, 1], "angle": 3.0}


def test_refusals_name_the_segment(tmp_path):
    start_tangent = [0, 1, 0]  # the arc starts at (0.05, 0, 0) heading +y
    line = _refusal(tmp_path, [{"arc": {**ARC, "weld_normal": start_tangent}}])
    assert "path.segments[0].arc" in line and "parallel to the path tangent" in line
    line = _refusal(tmp_path, [{"arc": {**ARC, "weld_normal": [0, 0, 0]}}])
    assert "path.segments[0].arc.weld_normal" in line and "length" in line
    line = _refusal(
        tmp_path,
        [{"arc": {**ARC, "weld_normal": [1, 0, 1]}}],
        {"frame": "part", "rpy": [3.14, 0, 0]},
    )
    assert "path.segments[0].arc.weld_normal" in line and "frame: seam" in line
    line = _refusal(tmp_path, [{"points": [[0.1, 0, 0, 0, 0, 1], [0.2, 0, 0]]}])
    assert "path.segments[0].points" in line and "not a mix" in line
    line = _refusal(
        tmp_path, [{"points": [[0.1, 0, 0, 0, 0, 1], [0.2, 0, 0, 0, 1, 1], [0.3, 0, 0, 1, 0, 0]]}]
    )
    assert "path.segments[0].points" in line and "parallel" in line
    assert "near its point 2" in line
    line = _refusal(tmp_path, [{"points": [[0.1, 0, 0, 0, 0, 1], [0.2, 0, 0, 0, 0, -1]]}])
    assert "path.segments[0].points" in line and "half a turn" in line
    # a segment without its own normal needs the tool's
    line = _refusal(
        tmp_path,
        [{"arc": {**ARC, "weld_normal": [1, 0, 1]}}, {"line": {"to": [0, 0, 0.1]}}],
        {"frame": "seam"},
    )
    assert "task.tool.frame" in line and "path.segments[1]" in line


def test_every_segment_with_its_own_normal_needs_no_tool_normal(tmp_path):
    case = _case(
        tmp_path,
        [{"arc": {**ARC, "weld_normal": [1, 0, 1]}}],
        {"frame": "seam"},
        start=(0.05, 0.0, 0.0),
    )
    assert case.task.tool.normal is None


def test_a_reversed_seam_carries_its_normals():
    """End to start, each point keeps its normal (arcs: the normal at the arc's end)."""
    from trackplan.paths.specs import ArcSpec

    start = np.array([0.05, 0.0, 0.0])
    arc = ArcSpec(np.zeros(3), np.array([0, 0, 1.0]), 1.0, np.array([1.0, 0, 1.0]))
    points = PointsSpec(
        np.array([[0.1, 0.1, 0], [0.2, 0.1, 0], [0.3, 0.2, 0]], dtype=float),
        np.array([[0, 0, 1], [0, 1, 1], [0, 1, 0.2]], dtype=float),
        np.array([1.0, 0, 1]),
    )
    end, (back_points, back_arc) = reversed_segments(start, (arc, points))
    np.testing.assert_array_equal(end, points.points[-1])
    assert isinstance(back_points, PointsSpec) and back_points.normals is not None
    np.testing.assert_array_equal(back_points.start_normal, points.normals[-1])
    np.testing.assert_array_equal(back_points.normals, [[0, 1, 1], [0, 0, 1], [1, 0, 1]])
    np.testing.assert_allclose(
        back_arc.weld_normal, _rotate_z(np.array([1.0, 0, 1]), np.array(1.0)), atol=1e-15
    )
    # without a start normal, the reversed segment ends on the forward spline's start value
    forward = PointsSpec(points.points, points.normals)
    begin = end_of_arc = _rotate_z(start, np.array(1.0))
    _, (back,) = reversed_segments(end_of_arc, (forward,))
    at_start = PointsNormal.from_points(begin, forward)(begin[None], np.zeros(1))[0]
    np.testing.assert_allclose(back.normals[-1], at_start, rtol=0, atol=1e-15)
    np.testing.assert_array_equal(back.start_normal, points.normals[-1])


# --------------------------------------------------------------------------- plans


def _tool_axes_in_part(case, X, q):
    """The tool axis (z) of each sample in the part frame, from FK of the joints."""
    T_part_base = np.linalg.inv(placement_transform(X))
    T = T_part_base @ forward_kinematics(case.robot, q)
    return T[:, :3, 2], T[:, :3, 3]


@pytest.mark.parametrize("work_angle", [None, 0.25])
def test_pipe_fillet_plans_feasibly_and_holds_the_work_angle_to_the_turning_normal(
    tmp_path, work_angle
):
    """The shipped case (work angle 0) and the same with a work angle of 0.25 rad."""
    case = load_case(PIPE)
    if work_angle is not None:
        data = yaml.safe_load(PIPE.read_text())
        data["task"]["tool"]["work_angle"] = work_angle
        (tmp_path / "pipe.yaml").write_text(yaml.safe_dump(data))
        case = load_case(tmp_path / "pipe.yaml")
    X = case.bounds.example
    result = plan(case, X)
    assert result.success, result.message
    q = result.trajectory.q
    axis, position = _tool_axes_in_part(case, X, q)
    # recomputed here: the weld normal at a point of the circle is the start normal
    # (1, 0, 1)/√2 turned about z by the point's polar angle; the seam tangent is the
    # circle's (counter-clockwise about +z)
    on_seam = np.abs(np.hypot(position[:, 0], position[:, 1]) - 0.06) < 1e-3
    assert on_seam.mean() > 0.99
    phi = np.arctan2(position[on_seam, 1], position[on_seam, 0])
    normal = _rotate_z(_unit(np.array([1.0, 0.0, 1.0])), phi)
    tangent = np.stack([-np.sin(phi), np.cos(phi), np.zeros_like(phi)], 1)
    # the seam frame: x = t, z = -n, y = z × x; the tool axis is
    # (sin β, −sin w cos β, cos w cos β) in it (docs/tool.md): the work angle w is the
    # signed angle from -n to the axis's part across the seam, about the tangent
    y_seam = np.cross(-normal, tangent)
    a = axis[on_seam]
    work = np.arctan2(-np.einsum("mk,mk->m", a, y_seam), np.einsum("mk,mk->m", a, -normal))
    travel = np.arcsin(np.clip(np.einsum("mk,mk->m", axis[on_seam], tangent), -1.0, 1.0))
    spec = case.task.tool
    np.testing.assert_allclose(work, spec.work_angle, atol=WORK_ANGLE_TOL)
    np.testing.assert_allclose(travel, spec.travel_angle, atol=WORK_ANGLE_TOL)
    # the torch goes once round the pipe: the weld normal's azimuth covers the circle
    assert np.ptp(np.unwrap(phi)) > 2 * np.pi - 0.05


def test_points_file_with_a_constant_normal_plans_like_the_constant_normal(tmp_path):
    """The same seam as points: once with task.tool.normal, once with that normal (at
    varying length) on every row of the points file; the plans agree to 1e-9 rad."""
    x = np.linspace(0.01, 0.12, 12)
    points = np.column_stack([x, 0.02 * np.sin(20 * x), np.zeros_like(x)])
    normals = np.array([0.0, 0.3, 1.0]) * np.linspace(1.0, 3.0, len(x))[:, None]
    csv = tmp_path / "seam.csv"
    rows = "\n".join(",".join(f"{v:.17g}" for v in row) for row in np.hstack([points, normals]))
    csv.write_text("x,y,z,nx,ny,nz\n" + rows + "\n")
    (tmp_path / "plain.csv").write_text(
        "x,y,z\n" + "\n".join(",".join(f"{v:.17g}" for v in row) for row in points) + "\n"
    )
    tool = {"frame": "seam", "work_angle": 0.3, "travel_angle": -0.1}
    with_rows = _case(tmp_path, [{"points": {"file": "seam.csv"}}], tool, name="rows")
    constant = _case(
        tmp_path,
        [{"points": {"file": "plain.csv"}}],
        {**tool, "normal": [0.0, 0.3, 1.0]},
        name="constant",
    )
    X = np.array([0.35, -0.25, 0.1, np.pi, 0.0, 0.0])
    a, b = plan(with_rows, X), plan(constant, X)
    assert a.success == b.success
    assert a.trajectory.q.shape == b.trajectory.q.shape
    np.testing.assert_allclose(a.trajectory.q, b.trajectory.q, rtol=0, atol=1e-9)


def test_the_report_describes_weld_normals_without_a_tool_normal():
    """The case section names the segments' own normals (a tool without ``normal`` and
    ``normals`` used to raise a TypeError in the report)."""
    from trackplan.report.html_case import _describe_segment, _tool_text

    case = load_case(PIPE)
    assert case.task.tool.normal is None and case.task.tool.normals is None
    assert "the path segments' own weld normals" in _tool_text(case.task.tool)
    kind, text = _describe_segment(case.segments[0])
    assert kind == "arc" and "weld normal (1, 0, 1) at its start, turning" in text


def test_the_pipe_sampled_in_points_gets_the_turning_normal(tmp_path):
    """The pipe fillet as 72 points with their normals: on the planned path the
    interpolated normal is within 1e-4 rad of the exact turning one (the spline's error
    at a 5° sampling is a few 1e-5 rad), and the plan is feasible."""
    data = yaml.safe_load(PIPE.read_text())
    phi = np.linspace(0.0, 2 * np.pi, 73)[1:]
    rows = np.column_stack(
        [0.06 * np.cos(phi), 0.06 * np.sin(phi), 0 * phi, np.cos(phi), np.sin(phi), 1 + 0 * phi]
    )
    (tmp_path / "pipe.csv").write_text(
        "x,y,z,nx,ny,nz\n" + "\n".join(",".join(f"{v:.15g}" for v in row) for row in rows)
    )
    data["path"]["segments"] = [{"points": {"file": "pipe.csv"}}]
    (tmp_path / "pipe.yaml").write_text(yaml.safe_dump(data))
    case = load_case(tmp_path / "pipe.yaml")
    geometry = PathGeometry.from_case(case)
    tool = ToolOrientation.choose(case.task.tool, geometry)
    assert tool.normals is not None
    s = np.linspace(0.0, geometry.planned.length, 20001)
    position = geometry.planned.sample(s).position
    exact = _rotate_z(_unit(np.array([1.0, 0.0, 1.0])), np.arctan2(position[:, 1], position[:, 0]))
    error = np.arccos(np.clip(np.einsum("mk,mk->m", tool.normals(s), exact), -1.0, 1.0))
    assert error.max() < 1e-4
    assert plan(case, case.bounds.example).success
