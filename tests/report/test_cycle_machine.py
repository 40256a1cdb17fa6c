"""The report of a cycle of several seams on a track and a positioner: the 3D view moves the
positioner, the part on it, every seam and move with the flange and the robot on its
carriage over the whole cycle; the joints plot shows the external axes over the cycle.

The cell is the one of ``test_machine_report.py`` (the corner case's PUMA560 on a track
along x, a plate on a two-axis tilt-rotate positioner), its corner path split into two
seams joined by an air move: seam ``a`` (the first line), an air move, seam ``b`` (the
second line, welded end to start). The flange's pose is recomputed by hand with scipy's
rotations (``_positioner_points``), not with the code under test.
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from tests.report.conftest import CORNER
from tests.report.test_machine_report import (
    BOX,
    PART_ROUNDING,
    POSITIONER_POSE,
    TRACK_AXIS,
    TRACK_RANGE,
    _pose,
    _positioner_points,
    _tilt_rotate,
    with_external_axes,
)
from trackplan.case import Case, Seam
from trackplan.cell.model import Body, Cell, Shape
from trackplan.paths.nominal import NominalPath
from trackplan.paths.specs import LineSpec
from trackplan.planning.result import AIR, SEAM, PlanResult, Span
from trackplan.report.cycle_view import cycle_view_spec
from trackplan.report.joints_plot import joints_figure
from trackplan.report.machine_view import (
    PART_POINTS,
    POSITIONER_CAPSULES_TRACE,
    POSITIONER_TRACE,
    RAIL_TRACE,
    WORKPIECE_TRACE,
)
from trackplan.report.robot_view import NOMINAL_TRACE, PATH_TRACE, ROBOT_TRACE, robot_view_spec
from trackplan.report.scene import DRAWING_STEP, frame_indices
from trackplan.robots.collision import Capsules
from trackplan.robots.machine import Machine, Positioner, Track

N_FRAMES = 9
SEAM_A, SEAM_B, AIR_MOVES = "seam a", "seam b (reversed)", "air moves"


@pytest.fixture(scope="module")
def cycle_case(corner: Case) -> Case:
    """Two seams of the corner path on a plate, on the positioner, the robot on the track."""
    task = corner.task
    seams = (
        Seam("a", CORNER[0], (LineSpec(to=CORNER[1]),), task),
        Seam("b", CORNER[1], (LineSpec(to=CORNER[2]),), task),
    )
    return dataclasses.replace(
        corner,
        paths=seams,
        track=Track(TRACK_AXIS, *TRACK_RANGE, velocity=1.0, acceleration=2.0, jerk=20.0),
        positioner=Positioner(_tilt_rotate(), POSITIONER_POSE, model="test"),
        cell=Cell(workpiece=(Body("plate", Shape.BOX, np.eye(4), BOX),), links=Capsules.empty()),
    )


@pytest.fixture(scope="module")
def cycle_result(cycle_case: Case, corner_result: PlanResult) -> PlanResult:
    """The corner result with a track ramp and two positioner sweeps, cut into seam a
    (first third), an air move (second third) and seam b (last third)."""
    machine = cycle_case.machine
    assert isinstance(machine, Machine)
    trajectory = with_external_axes(corner_result, machine)
    n = trajectory.n_samples
    k1, k2 = n // 3, 2 * n // 3
    spans = (
        Span(kind=SEAM, label="a", first=0, last=k1, seam=0),
        Span(kind=AIR, label=AIR, first=k1, last=k2),
        Span(kind=SEAM, label="b", first=k2, last=n - 1, seam=1, reversed=True),
    )
    return dataclasses.replace(corner_result, trajectory=trajectory, spans=spans)


@pytest.fixture(scope="module")
def view(cycle_result: PlanResult, cycle_case: Case) -> dict:
    return cycle_view_spec(
        robot_view_spec(cycle_result, cycle_case, n_frames=N_FRAMES), cycle_result, cycle_case
    )


def _animated(view: dict, name: str) -> list[dict]:
    """The trace called ``name`` in every animation frame (it must be animated)."""
    ids = [i for i, trace in enumerate(view["data"]) if trace["name"] == name]
    assert len(ids) == 1, f"{name}: {len(ids)} traces"
    frames = view["frames"]
    assert all(ids[0] in frame["traces"] for frame in frames), f"{name} is not animated"
    return [frame["data"][frame["traces"].index(ids[0])] for frame in frames]


def _points(trace: dict) -> np.ndarray:
    return np.column_stack([np.array(trace[a], dtype=float) for a in "xyz"])


def _flanges(result: PlanResult) -> list[np.ndarray]:
    """The flange in the cell at each animation frame's sample, by hand."""
    idx = frame_indices(result.trajectory.n_samples, N_FRAMES)
    return [_positioner_points(q[7:])[1] for q in result.trajectory.q[idx]]


def _nearest(points: np.ndarray, reference: np.ndarray) -> np.ndarray:
    """Distance of each point (M, 3) to the nearest point of ``reference`` (K, 3), m."""
    return np.min(np.linalg.norm(points[:, None] - reference[None], axis=2), axis=1)


def test_the_seams_and_moves_ride_on_the_flange_over_the_cycle(view, cycle_result):
    tcp = cycle_result.trajectory.tool_position  # relative to the flange
    spans = {span.label: span for span in cycle_result.spans}
    for name, span in ((SEAM_A, spans["a"]), (AIR_MOVES, spans[AIR]), (SEAM_B, spans["b"])):
        own = tcp[span.first : span.last + 1]
        drawn = _animated(view, name)
        for T, trace in zip(_flanges(cycle_result), drawn, strict=True):
            back = (_points(trace) - T[:3, 3]) @ T[:3, :3]  # into the flange frame
            assert np.max(_nearest(back, own)) < PART_ROUNDING, name
            np.testing.assert_allclose(back[[0, -1]], own[[0, -1]], atol=PART_ROUNDING)
        first, middle = _points(drawn[0]), _points(drawn[N_FRAMES // 2])
        assert np.max(np.linalg.norm(first - middle, axis=1)) > 0.05, f"{name} stands still"


def test_each_seams_nominal_path_rides_with_the_part(view, cycle_result, cycle_case):
    T_X = _pose(cycle_result.placement)
    for seam in cycle_case.seams:
        nominal = NominalPath.from_specs(seam.start, seam.segments).polyline(DRAWING_STEP)
        for T, trace in zip(
            _flanges(cycle_result), _animated(view, f"{NOMINAL_TRACE}: {seam.name}"), strict=True
        ):
            T_part = T @ T_X
            back = (_points(trace) - T_part[:3, 3]) @ T_part[:3, :3]  # into the part frame
            assert np.max(_nearest(back, nominal)) < PART_ROUNDING
            np.testing.assert_allclose(back[[0, -1]], nominal[[0, -1]], atol=PART_ROUNDING)


def test_the_machine_is_drawn_over_the_whole_cycle(view, cycle_result):
    names = [trace["name"] for trace in view["data"]]
    # the one path of a single seam is replaced by the cycle's lines
    assert PATH_TRACE not in names and NOMINAL_TRACE not in names
    idx = frame_indices(cycle_result.trajectory.n_samples, N_FRAMES)
    q = cycle_result.trajectory.q[idx]
    positioner = _animated(view, POSITIONER_TRACE)
    for qk, trace in zip(q, positioner, strict=True):
        np.testing.assert_allclose(
            _points(trace), _positioner_points(qk[7:])[0], atol=PART_ROUNDING
        )
    plates = _animated(view, WORKPIECE_TRACE)
    assert np.max(np.abs(_points(plates[0]) - _points(plates[-1]))) > 0.05
    assert len(_animated(view, POSITIONER_CAPSULES_TRACE)) == N_FRAMES
    # the robot rides the track, its joints still each frame's first trace
    for qk, frame in zip(q, view["frames"], strict=True):
        robot = frame["data"][0]
        assert robot["name"] == ROBOT_TRACE
        np.testing.assert_allclose(_points(robot)[0], qk[6] * TRACK_AXIS, atol=2e-5)
    assert names.count(RAIL_TRACE) == 1
    # every frame updates the same traces, each frame's data in their order
    for frame in view["frames"]:
        assert [view["data"][i]["name"] for i in frame["traces"]] == [
            trace["name"] for trace in frame["data"]
        ]


def test_the_moving_lines_keep_the_single_seams_share_of_the_page(view):
    lines = [SEAM_A, SEAM_B, AIR_MOVES, f"{NOMINAL_TRACE}: a", f"{NOMINAL_TRACE}: b"]
    for frame in range(N_FRAMES):
        points = sum(len(_animated(view, name)[frame]["x"]) for name in lines)
        assert points <= 2 * PART_POINTS + 3 * len(lines)  # each line thinned, its last kept


def test_the_joints_plot_shows_the_external_axes_over_the_cycle(cycle_result, cycle_case):
    figure = joints_figure(cycle_result, cycle_case)
    axes = np.array(figure.axes).reshape(4, 9)
    titles = [axes[0, column].get_title(loc="left") for column in (6, 7, 8)]
    assert titles == ["track [m]", "tilt [rad]", "rotate [rad]"]
    limits = [li.get_ydata()[0] for li in axes[0, 6].get_lines() if li.get_gid() == "limit"]
    assert limits == list(TRACK_RANGE)
    (track,) = [li for li in axes[0, 6].get_lines() if li.get_label() == "track"]
    np.testing.assert_allclose(track.get_ydata(), cycle_result.trajectory.q[:, 6])
    # the air move is a grey band on the external axes' panels too
    air = cycle_result.spans[1]
    t = cycle_result.trajectory.t
    (band,) = [c for c in axes[0, 8].collections if c.get_gid() == "move"]
    x = np.concatenate([path.vertices[:, 0] for path in band.get_paths()])
    np.testing.assert_allclose([x.min(), x.max()], t[[air.first, air.last]], atol=1e-9)


@pytest.mark.browser
@pytest.mark.slow  # about 10 s: the report written (its PNGs) and opened in Chromium
def test_the_cycle_report_on_a_positioner_animates_without_errors(
    tmp_path, cycle_result, cycle_case
):
    sync_api = pytest.importorskip(
        "playwright.sync_api", reason="BROWSER TEST SKIPPED: the playwright package is missing"
    )
    from tests.docs.screenshots import CHROMIUM, CHROMIUM_ARGS
    from trackplan.report import VIEW_ID
    from trackplan.report.robot_view import frame_name
    from trackplan.report.run_report import write_run_report

    if not CHROMIUM.exists():
        pytest.skip(f"BROWSER TEST SKIPPED: no Chromium at {CHROMIUM}; run `make browser`")
    _, report = write_run_report(
        cycle_result, cycle_case, tmp_path, None, None, parallel=False, n_frames=N_FRAMES
    )
    drawn = (
        "(name) => { const t = document.getElementById('" + VIEW_ID + "').data"
        ".find((t) => t.name === name); return [Array.from(t.x), Array.from(t.y),"
        " Array.from(t.z)]; }"
    )
    with sync_api.sync_playwright() as playwright:
        browser = playwright.chromium.launch(executable_path=str(CHROMIUM), args=CHROMIUM_ARGS)
        page = browser.new_page(viewport={"width": 1400, "height": 1000})
        page.set_default_timeout(120_000)
        problems: list[str] = []
        page.on("console", lambda m: problems.append(m.text) if m.type == "error" else None)
        page.on("pageerror", lambda error: problems.append(str(error)))
        page.goto(report.as_uri())
        page.wait_for_function(
            f"() => {{ const gd = document.getElementById('{VIEW_ID}');"
            " return gd && gd._transitionData && gd._transitionData._frames.length > 0; }"
        )
        names = page.evaluate(f"() => document.getElementById('{VIEW_ID}').data.map((t) => t.name)")
        before = {
            name: np.array(page.evaluate(drawn, name)).T for name in (SEAM_A, POSITIONER_TRACE)
        }
        later = N_FRAMES - 2
        page.evaluate(
            "async ([id, name]) => { await Plotly.animate(document.getElementById(id), [name],"
            " {mode: 'immediate', frame: {duration: 0, redraw: true},"
            " transition: {duration: 0}}); }",
            [VIEW_ID, frame_name(later)],
        )
        after = {name: np.array(page.evaluate(drawn, name)).T for name in before}
        browser.close()
    assert not problems, problems
    assert {SEAM_A, SEAM_B, AIR_MOVES, POSITIONER_TRACE, WORKPIECE_TRACE, RAIL_TRACE} <= set(names)
    for name, start in before.items():
        assert np.max(np.abs(after[name] - start)) > 0.01, f"{name} did not move"
    seam = _animated(_view_of(cycle_result, cycle_case), SEAM_A)[later]
    np.testing.assert_allclose(after[SEAM_A], _points(seam), atol=1e-9)


def _view_of(result: PlanResult, case: Case) -> dict:
    return cycle_view_spec(robot_view_spec(result, case, n_frames=N_FRAMES), result, case)


def test_a_cycle_on_a_track_alone_keeps_its_seams_still_and_moves_the_base(
    cycle_case, cycle_result
):
    on_track = dataclasses.replace(cycle_case, positioner=None)
    q = cycle_result.trajectory.q[:, :7]  # the arm's joints and the track
    machine = on_track.machine
    assert isinstance(machine, Machine)
    result = dataclasses.replace(
        cycle_result,
        trajectory=dataclasses.replace(
            cycle_result.trajectory, q=q, tool_position=machine.T_carrier_tool(q)[:, :3, 3]
        ),
    )
    view = _view_of(result, on_track)
    animated = set(view["frames"][0]["traces"])
    by_name = {trace["name"]: i for i, trace in enumerate(view["data"])}
    for name in (SEAM_A, SEAM_B, AIR_MOVES, f"{NOMINAL_TRACE}: a", RAIL_TRACE):
        assert by_name[name] not in animated, f"{name} moves without a positioner"
    span = result.spans[0]
    seam = _points(view["data"][by_name[SEAM_A]])
    own = result.trajectory.tool_position[span.first : span.last + 1]
    assert np.max(_nearest(seam, own)) < 2e-5
    idx = frame_indices(result.trajectory.n_samples, N_FRAMES)
    for qk, frame in zip(q[idx], view["frames"], strict=True):
        np.testing.assert_allclose(_points(frame["data"][0])[0], qk[6] * TRACK_AXIS, atol=2e-5)
