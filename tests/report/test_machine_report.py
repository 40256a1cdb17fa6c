"""The report of a welding cell: the track and the positioner in the joint plots, the 3D view
and the summary.

The machine is the corner case's PUMA560 on a track along x with a two-axis tilt-rotate
positioner beside it (a test chain: tilt about −y 0.38 m up, rotate about −z 0.15 m above
the tilt axis); the result is the corner result with the two external axes added to its
joint vector (a track ramp and two positioner sweeps). The positioner's frames and the
part's pose are recomputed here from the chain's numbers with scipy's rotations, not with
the code under test.
"""

from __future__ import annotations

import dataclasses
import re
from types import SimpleNamespace

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from trackplan.case import Case
from trackplan.cell.model import Body, Cell, Shape
from trackplan.check_report import DownhandFigures
from trackplan.derivatives import backward_derivatives
from trackplan.planning.result import PlanResult, Trajectory
from trackplan.report.html import write_report
from trackplan.report.html_result import downhand_rows, external_axes_table
from trackplan.report.joints_plot import joints_figure
from trackplan.report.machine_view import (
    POSITIONER_CAPSULES_TRACE,
    POSITIONER_TRACE,
    RAIL_TRACE,
    WORKPIECE_TRACE,
)
from trackplan.report.robot_view import (
    NOMINAL_TRACE,
    PATH_TRACE,
    ROBOT_TRACE,
    robot_view_spec,
)
from trackplan.report.scene import frame_indices, nominal_polyline
from trackplan.robots.collision import Capsules
from trackplan.robots.machine import Machine, Positioner, Track
from trackplan.robots.model import Robot

ROUNDING = 2e-5  # m: the view rounds coordinates to 10 µm
PART_ROUNDING = 2e-4  # m: and the moving part's, sent in every frame, to 0.1 mm
TRACK_AXIS = np.array([1.0, 0.0, 0.0])
TRACK_RANGE = (-0.5, 1.5)  # m
POSITIONER_POSE = np.array([0.9, -0.6, 0.0, 0.0, 0.0, 0.4])  # m, rad
TILT_HEIGHT, TABLE_HEIGHT = 0.38, 0.15  # m
BOX = np.array([0.3, 0.2, 0.02])  # workpiece half extents, m
N_FRAMES = 9


def _translation(xyz) -> np.ndarray:
    T = np.eye(4)
    T[:3, 3] = xyz
    return T


def _tilt_rotate() -> Robot:
    """A two-axis tilt-rotate positioner chain with two link capsules."""
    return Robot(
        name="test tilt-rotate",
        origins=np.stack([_translation([0, 0, TILT_HEIGHT]), _translation([0, 0, TABLE_HEIGHT])]),
        axes=np.array([[0.0, -1.0, 0.0], [0.0, 0.0, -1.0]]),
        q_min=np.array([-2.3, -6.3]),
        q_max=np.array([2.3, 6.3]),
        v_max=np.array([1.5, 2.0]),
        a_max=np.array([3.0, 4.0]),
        j_max=np.array([30.0, 40.0]),
        joint_names=("tilt", "rotate"),
        collision=Capsules(
            frame=np.array([0, 1]),
            segment=np.array([[[0, 0, 0], [0, 0, TILT_HEIGHT]], [[0, 0, 0], [0, 0, 0.05]]]),
            radius=np.array([0.1, 0.25]),
            name=("column", "table"),
        ),
    )


def _pose(X: np.ndarray) -> np.ndarray:
    """(x, y, z, roll, pitch, yaw) as a transform: R = Rz(yaw) Ry(pitch) Rx(roll)."""
    T = _translation(X[:3])
    T[:3, :3] = Rotation.from_euler("xyz", X[3:]).as_matrix()
    return T


def _positioner_points(e: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Base, joint and flange origins (4, 3) and the flange (4, 4) in the cell, by hand."""
    T = _pose(POSITIONER_POSE)
    points = [T[:3, 3]]
    for height, axis, angle in (
        (TILT_HEIGHT, [0, -1, 0], e[0]),
        (TABLE_HEIGHT, [0, 0, -1], e[1]),
    ):
        turn = np.eye(4)
        turn[:3, :3] = Rotation.from_rotvec(angle * np.array(axis, dtype=float)).as_matrix()
        T = T @ _translation([0, 0, height]) @ turn
        points.append(T[:3, 3])
    points.append(T[:3, 3])
    return np.array(points), T


@pytest.fixture(scope="module")
def cell_case(corner: Case) -> Case:
    """The corner case on the track, its part (a plate) on the positioner."""
    return dataclasses.replace(
        corner,
        track=Track(TRACK_AXIS, *TRACK_RANGE, velocity=1.0, acceleration=2.0, jerk=20.0),
        positioner=Positioner(_tilt_rotate(), POSITIONER_POSE, model="test"),
        cell=Cell(
            workpiece=(Body("plate", Shape.BOX, np.eye(4), BOX),),
            links=Capsules.empty(),
        ),
    )


def with_external_axes(result: PlanResult, machine: Machine) -> Trajectory:
    """The result's trajectory with a track ramp and two positioner sweeps appended to its
    joint vector (the machine's), its derivatives and tool points recomputed."""
    old = result.trajectory
    u = np.linspace(0.0, 1.0, old.n_samples)
    smooth = u**3 * (10 - 15 * u + 6 * u**2)
    external = np.column_stack([1.2 * smooth - 0.2, 0.8 * np.sin(np.pi * u), 3.0 * smooth])
    q = np.hstack([old.q, external])
    qd, qdd, qddd = backward_derivatives(q, old.sample_time)
    return Trajectory(
        sample_time=old.sample_time,
        t=old.t,
        s=old.s,
        q=q,
        qd=qd,
        qdd=qdd,
        qddd=qddd,
        tool_position=machine.T_carrier_tool(q)[:, :3, 3],
        speed=old.speed,
    )


@pytest.fixture(scope="module")
def cell_result(cell_case: Case, corner_result: PlanResult) -> PlanResult:
    """The corner result with a track ramp and two positioner sweeps in its joint vector."""
    machine = cell_case.machine
    assert isinstance(machine, Machine)
    trajectory = with_external_axes(corner_result, machine)
    return dataclasses.replace(corner_result, trajectory=trajectory)


@pytest.fixture(scope="module")
def view(cell_result: PlanResult, cell_case: Case) -> dict:
    return robot_view_spec(cell_result, cell_case, n_frames=N_FRAMES)


def _animated(view: dict, name: str) -> list[dict]:
    """The trace called ``name`` in every animation frame."""
    ids = [i for i, trace in enumerate(view["data"]) if trace["name"] == name]
    assert len(ids) == 1, f"{name}: {len(ids)} traces"
    frames = view["frames"]
    assert all(ids[0] in frame["traces"] for frame in frames), f"{name} is not animated"
    return [frame["data"][frame["traces"].index(ids[0])] for frame in frames]


def _points(trace: dict) -> np.ndarray:
    return np.column_stack([np.array(trace[a], dtype=float) for a in "xyz"])


def _frame_q(result: PlanResult, view: dict) -> np.ndarray:
    """The joint vector of each animation frame (evenly spread samples, as labelled)."""
    idx = frame_indices(result.trajectory.n_samples, N_FRAMES)
    times = np.array([float(step["label"]) for step in view["layout"]["sliders"][0]["steps"]])
    np.testing.assert_allclose(result.trajectory.t[idx], times, atol=0.005)
    return result.trajectory.q[idx]


def test_positioner_trace_follows_its_axes(view, cell_result):
    q = _frame_q(cell_result, view)
    traces = _animated(view, POSITIONER_TRACE)
    assert len(traces) == N_FRAMES
    for trace, qk in zip(traces, q, strict=True):
        expected, _ = _positioner_points(qk[7:])
        np.testing.assert_allclose(_points(trace), expected, atol=ROUNDING)
    # it moves: the flange halfway (tilted) is not where it was at the start
    assert np.linalg.norm(_points(traces[N_FRAMES // 2])[-1] - _points(traces[0])[-1]) > 0.01


def test_part_rides_on_the_flange(view, cell_result, cell_case):
    """The nominal seam of each frame is T_cell_flange(q) · T(X) · p for points p of the
    nominal path, and the plate's corners are the same transform of the box's corners."""
    q = _frame_q(cell_result, view)
    T_X = _pose(cell_result.placement)
    nominal = nominal_polyline(cell_case)
    corners = np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)]) * BOX
    plates = _animated(view, WORKPIECE_TRACE)
    for qk, seam, plate in zip(q, _animated(view, NOMINAL_TRACE), plates, strict=True):
        T = _positioner_points(qk[7:])[1] @ T_X
        back = (_points(seam) - T[:3, 3]) @ T[:3, :3]  # into the part frame
        nearest = np.min(np.linalg.norm(back[:, None] - nominal[None], axis=2), axis=1)
        assert np.max(nearest) < PART_ROUNDING
        np.testing.assert_allclose(back[0], cell_case.start, atol=PART_ROUNDING)
        np.testing.assert_allclose(back[-1], nominal[-1], atol=PART_ROUNDING)
        np.testing.assert_allclose(
            _points(plate), corners @ T[:3, :3].T + T[:3, 3], atol=PART_ROUNDING
        )
    assert "i" in plates[0] and "i" not in plates[1]  # triangles once


def test_planned_path_is_the_carrier_relative_tcp_moved_with_the_flange(view, cell_result):
    q = _frame_q(cell_result, view)
    tcp = cell_result.trajectory.tool_position
    for qk, path in zip(q, _animated(view, PATH_TRACE), strict=True):
        T = _positioner_points(qk[7:])[1]
        back = (_points(path) - T[:3, 3]) @ T[:3, :3]
        nearest = np.min(np.linalg.norm(back[:, None] - tcp[None], axis=2), axis=1)
        assert np.max(nearest) < PART_ROUNDING


def test_arm_base_rides_the_track_and_the_rail_is_drawn(view, cell_result):
    q = _frame_q(cell_result, view)
    for qk, robot in zip(q, _animated(view, ROBOT_TRACE), strict=True):
        np.testing.assert_allclose(_points(robot)[0], qk[6] * TRACK_AXIS, atol=ROUNDING)
    (rail,) = [trace for trace in view["data"] if trace["name"] == RAIL_TRACE]
    np.testing.assert_allclose(_points(rail), np.outer(TRACK_RANGE, TRACK_AXIS), atol=ROUNDING)
    assert RAIL_TRACE not in {name for frame in view["frames"] for name in frame["traces"]}


def test_positioner_capsules_move_with_it(view):
    capsules = _animated(view, POSITIONER_CAPSULES_TRACE)
    first, last = _points(capsules[0]), _points(capsules[N_FRAMES // 2])
    assert first.shape == last.shape and len(first) > 0
    assert np.max(np.linalg.norm(first - last, axis=1)) > 0.01


def test_external_axes_are_plotted_with_their_units(cell_result, cell_case):
    figure = joints_figure(cell_result, cell_case)
    axes = np.array(figure.axes).reshape(4, 9)
    expected = {
        6: ("track [m]", "[m/s]", "[m/s²]", "[m/s³]"),
        7: ("tilt [rad]", "[rad/s]", "[rad/s²]", "[rad/s³]"),
        8: ("rotate [rad]", "[rad/s]", "[rad/s²]", "[rad/s³]"),
    }
    series = (
        cell_result.trajectory.q,
        cell_result.trajectory.qd,
        cell_result.trajectory.qdd,
        cell_result.trajectory.qddd,
    )
    for column, titles in expected.items():
        for row, title in enumerate(titles):
            ax = axes[row, column]
            assert ax.get_title(loc="left") == title
            name = title.split()[0] if row == 0 else titles[0].split()[0]
            (line,) = [li for li in ax.get_lines() if li.get_label() == name]
            np.testing.assert_allclose(line.get_ydata(), series[row][:, column])
    limits = [li.get_ydata()[0] for li in axes[0, 6].get_lines() if li.get_gid() == "limit"]
    assert limits == list(TRACK_RANGE)
    limits = [li.get_ydata()[0] for li in axes[1, 7].get_lines() if li.get_gid() == "limit"]
    assert limits == [-1.5, 1.5]
    assert axes[0, 0].get_title(loc="left") == "joint 1"


def test_summary_lists_the_external_axes(tmp_path, cell_result, cell_case):
    table = external_axes_table(cell_result, cell_case)
    q = cell_result.trajectory.q
    for name, kind in (("track", "track"), ("tilt", "positioner"), ("rotate", "positioner")):
        assert f"<th>{name}</th><td>{kind}</td>" in re.sub(r' class="[^"]*"', "", table)
    assert "[-0.2, 1] m" in table and "[0, 3] rad" in table
    peak = np.max(np.abs(cell_result.trajectory.qd[:, 6]))
    assert f"{peak:.4g} m/s" in table
    assert np.isclose(q[:, 6].min(), -0.2) and np.isclose(q[:, 6].max(), 1.0)
    page = write_report(cell_result, cell_case, tmp_path, plots=[], n_frames=4).read_text()
    assert "External axes" in page and RAIL_TRACE in page and POSITIONER_TRACE in page
    case_part = page.split('id="case"')[1].split('id="result"')[0]
    assert "Track and positioner" in case_part
    assert "[-0.5, 1.5] m" in case_part and "test" in case_part and "tilt" in case_part


def test_downhand_figures_shown_when_the_result_has_them(cell_case):
    figures = DownhandFigures(
        max_slope=0.05, max_rotation=0.12, slope=0.1745, rotation=0.1745, share=0.75
    )
    result = SimpleNamespace(check=SimpleNamespace(downhand=figures))
    rows = dict(downhand_rows(result, cell_case))
    assert rows["largest downhand slope"].startswith("0.05 rad (2.865°")
    assert rows["largest downhand rotation"].startswith("0.12 rad (6.875°")
    assert rows["samples downhand"] == "75 %"
    assert downhand_rows(SimpleNamespace(check=SimpleNamespace(downhand=None)), cell_case) == []


def test_arm_only_report_has_no_external_axes(corner, corner_result):
    view = robot_view_spec(corner_result, corner, n_frames=4)
    names = {trace["name"] for trace in view["data"]}
    assert not names & {RAIL_TRACE, POSITIONER_TRACE, POSITIONER_CAPSULES_TRACE, WORKPIECE_TRACE}
    # the fixed part's path and frame are static; the robot (joints, capsule solids), the
    # tool frame's three axes and the trail are animated
    animated = [view["data"][i]["name"] for i in view["frames"][0]["traces"]]
    assert animated == [
        ROBOT_TRACE,
        "robot (link capsules)",
        *["tool frame (x, y, z)"] * 3,
        "tool trail",
    ]
    assert external_axes_table(corner_result, corner) == ""
    assert downhand_rows(corner_result, corner) == []


def test_track_alone_moves_the_base_and_keeps_the_part_still(corner, corner_result):
    track = Track(TRACK_AXIS, *TRACK_RANGE, velocity=1.0, acceleration=2.0, jerk=20.0)
    case = dataclasses.replace(corner, track=track)
    machine = case.machine
    assert isinstance(machine, Machine)
    old = corner_result.trajectory
    t = np.linspace(-0.3, 0.9, old.n_samples)
    q = np.hstack([old.q, t[:, None]])
    derivatives = backward_derivatives(q, old.sample_time)
    trajectory = dataclasses.replace(
        old,
        q=q,
        qd=derivatives[0],
        qdd=derivatives[1],
        qddd=derivatives[2],
        tool_position=machine.T_carrier_tool(q)[:, :3, 3],
    )
    result = dataclasses.replace(corner_result, trajectory=trajectory)
    view = robot_view_spec(result, case, n_frames=N_FRAMES)
    alone = robot_view_spec(corner_result, corner, n_frames=N_FRAMES)
    idx = frame_indices(old.n_samples, N_FRAMES)
    on_track = _animated(view, ROBOT_TRACE)
    for k, (moved, still) in enumerate(zip(on_track, _animated(alone, ROBOT_TRACE), strict=True)):
        shift = t[idx[k]] * TRACK_AXIS
        np.testing.assert_allclose(_points(moved), _points(still) + shift, atol=ROUNDING)
    names = {trace["name"] for trace in view["data"]}
    assert RAIL_TRACE in names and POSITIONER_TRACE not in names
    (nominal,) = [trace for trace in view["data"] if trace["name"] == NOMINAL_TRACE]
    (still_nominal,) = [trace for trace in alone["data"] if trace["name"] == NOMINAL_TRACE]
    assert nominal == still_nominal  # the part does not move with the track


def test_margins_name_the_external_axes(cell_result, cell_case):
    from trackplan.report.html_result import margins_table

    margins = {"position": np.linspace(0.1, 0.9, 9), "velocity": np.linspace(0.2, 0.6, 9)}
    check = dataclasses.replace(
        cell_result.check, joint_margins=margins, binding={"velocity": (7, 1.25)}
    )
    result = dataclasses.replace(cell_result, check=check)
    html = re.sub(r' class="[^"]*"', "", margins_table(result, cell_case))
    header = html.split("</thead>")[0]
    assert "<th>joint 6</th><th>track</th><th>tilt</th><th>rotate</th>" in header
    assert "velocity [rad/s, m/s]" in html
    assert "track at t = 1.25 s" in html
