"""The robot as it looks in the 3D view: URDF meshes, else capsule solids, never lines."""

from __future__ import annotations

import dataclasses
import json
import time
from pathlib import Path

import numpy as np
import pytest

from trackplan.case import Case
from trackplan.io.urdf_robot import robot_from_urdf_file
from trackplan.planning.result import PlanResult
from trackplan.report.robot_solids import (
    CAPSULES_TRACE,
    LINES_NOTE,
    MESH_PAGE_BYTES,
    MESHES_TRACE,
    SOLIDS_TRACE,
    TOOL_SOLIDS_TRACE,
    mesh_budget,
    robot_look,
)
from trackplan.report.robot_view import ROBOT_TRACE, robot_view_spec
from trackplan.report.scene import frame_indices
from trackplan.robots.collision import Capsules
from trackplan.robots.model import Robot
from trackplan.robots.visuals import MAX_TRIANGLES, n_triangles

URDF = Path(__file__).resolve().parents[1] / "fixtures" / "meshed_robot" / "meshed_robot.urdf"
N_FRAMES = 40
RENDER_AGAIN = """async (id) => {
    const gd = document.getElementById(id);
    const div = document.createElement('div');
    div.style.width = '1200px';
    div.style.height = '720px';
    document.body.appendChild(div);
    const start = performance.now();
    await Plotly.newPlot(div, gd.data, gd.layout);
    await Plotly.addFrames(div, gd._transitionData._frames);
    return performance.now() - start;
}"""


@pytest.fixture(scope="module")
def meshed_robot() -> Robot:
    """The fixture arm: the PUMA 560's chain with STL visual meshes."""
    return robot_from_urdf_file(URDF, assume_limits=True)


@pytest.fixture(scope="module")
def meshed_case(corner: Case, meshed_robot: Robot) -> Case:
    """The corner case with the meshed arm (the same chain: the corner trajectory fits)."""
    return dataclasses.replace(corner, robot=meshed_robot)


def _meshes(view: dict) -> list[dict]:
    return [t for t in view["data"] if t["type"] == "mesh3d" and t["name"].startswith("robot")]


def _fk(robot: Robot, q: np.ndarray) -> list[np.ndarray]:
    """The chain frames 0..n written out: T_0_i = Π origin_j · Rz(q_j) (every axis z)."""
    frames = [np.eye(4)]
    for origin, angle in zip(robot.origins, q, strict=True):
        c, s = np.cos(angle), np.sin(angle)
        rz = np.array([[c, -s, 0, 0], [s, c, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1.0]])
        frames.append(frames[-1] @ origin @ rz)
    return frames


def test_the_urdf_meshes_are_drawn_in_their_colours_under_the_budget(meshed_case, corner_result):
    view = robot_view_spec(corner_result, meshed_case, n_frames=N_FRAMES)
    meshes = _meshes(view)
    assert meshes[0]["name"] == MESHES_TRACE
    assert {t["color"] for t in meshes} == {"#595e66", "#e6730d", "#f2991a", "#333340"}
    triangles = sum(len(t["i"]) for t in meshes)
    assert triangles == n_triangles(meshed_case.robot.visuals)  # 1088: under the budget
    assert triangles <= mesh_budget(N_FRAMES) <= MAX_TRIANGLES
    # no line through the joints: markers only
    robot = next(t for t in view["data"] if t["name"] == ROBOT_TRACE)
    assert robot["mode"] == "markers"
    # the meshes' share of the page over all frames stays under its budget
    ids = [view["data"].index(t) for t in meshes]
    animated = view["frames"][0]["traces"]
    sent = sum(
        len(json.dumps(frame["data"][animated.index(i)], separators=(",", ":")))
        for frame in view["frames"]
        for i in ids
    )
    assert sent <= MESH_PAGE_BYTES


def test_a_tighter_page_budget_decimates_the_meshes(meshed_case, corner_result):
    idx = frame_indices(corner_result.trajectory.n_samples, 150)
    from trackplan.report.machine_view import arm_frames

    frames = arm_frames(meshed_case, corner_result.trajectory.q[idx])
    page_bytes = 600_000
    look = robot_look(meshed_case, frames, page_bytes)
    assert look.kind == "meshes"
    assert 0.3 * mesh_budget(150, page_bytes) < look.triangles <= mesh_budget(150, page_bytes)
    assert look.triangles < n_triangles(meshed_case.robot.visuals)
    compact = (",", ":")  # as the page writes them
    sent = sum(
        len(json.dumps(build(k), separators=compact)) for build in look.builders for k in range(150)
    )
    assert sent <= page_bytes


def test_the_meshes_move_with_the_joints(meshed_case, corner_result):
    view = robot_view_spec(corner_result, meshed_case, n_frames=N_FRAMES)
    upper_arm = next(t for t in _meshes(view) if t["color"] == "#e6730d")  # link l2 alone
    ids = view["frames"][0]["traces"]
    column = ids.index(view["data"].index(upper_arm))
    visual = next(v for v in meshed_case.robot.visuals if v.name == "l2")
    idx = frame_indices(corner_result.trajectory.n_samples, N_FRAMES)
    for k in (0, N_FRAMES // 2, N_FRAMES - 1):
        drawn = view["frames"][k]["data"][column]
        xyz = np.column_stack([drawn["x"], drawn["y"], drawn["z"]])
        T = _fk(meshed_case.robot, corner_result.trajectory.q[idx[k]])[visual.frame]
        expected = visual.vertices @ T[:3, :3].T + T[:3, 3]
        np.testing.assert_allclose(xyz, expected, atol=6e-4)  # rounded to 1 mm
    first, last = (view["frames"][k]["data"][column] for k in (0, N_FRAMES - 1))
    assert np.max(np.abs(np.subtract(first["x"], last["x"]))) > 0.01  # it moved


def test_a_builtin_robot_is_drawn_as_capsule_solids(corner, corner_result):
    view = robot_view_spec(corner_result, corner, n_frames=6)
    solids = [t for t in view["data"] if t["name"] == SOLIDS_TRACE]
    assert len(solids) == 1 and solids[0]["type"] == "mesh3d" and solids[0]["opacity"] == 1.0
    assert len(solids[0]["i"]) > 7 * 100  # seven capsules, ~160 triangles each
    lines = [
        t
        for t in view["data"]
        if t["type"] == "scatter3d" and "lines" in t["mode"] and t["name"].startswith("robot")
    ]
    assert lines == []  # no line figure of the arm
    names = {t["name"] for t in view["data"]}
    assert {"base frame (x, y, z)", "part frame (x, y, z)", "tool frame (x, y, z)"} <= names


def test_a_robot_without_meshes_or_capsules_keeps_a_line_and_says_so(corner, corner_result):
    bare = dataclasses.replace(corner, robot=dataclasses.replace(corner.robot, collision=None))
    view = robot_view_spec(corner_result, bare, n_frames=6)
    robot = next(t for t in view["data"] if t["name"] == ROBOT_TRACE)
    assert robot["mode"] == "lines+markers" and robot["line"]["width"] >= 10
    assert robot["legendgrouptitle"]["text"] == LINES_NOTE
    assert not [t for t in view["data"] if t["type"] == "mesh3d"]


def test_the_camera_holds_the_robot_solids(meshed_case, corner_result):
    view = robot_view_spec(corner_result, meshed_case, n_frames=N_FRAMES)
    scene = view["layout"]["scene"]
    limits = np.array([scene[f"{axis}axis"]["range"] for axis in "xyz"])
    ids = view["frames"][0]["traces"]
    for trace in _meshes(view):
        column = ids.index(view["data"].index(trace))
        for frame in view["frames"]:
            drawn = frame["data"][column]
            xyz = np.column_stack([drawn["x"], drawn["y"], drawn["z"]])
            assert np.all(xyz >= limits[:, 0] - 1e-9) and np.all(xyz <= limits[:, 1] + 1e-9)


@pytest.mark.browser
@pytest.mark.slow  # about 10 s: a report written and opened in Chromium
def test_a_meshed_robot_report_opens_fast_without_errors(
    tmp_path, meshed_case: Case, corner_result: PlanResult
):
    sync_api = pytest.importorskip(
        "playwright.sync_api", reason="BROWSER TEST SKIPPED: the playwright package is missing"
    )
    from tests.docs.screenshots import CHROMIUM, CHROMIUM_ARGS
    from trackplan.report import VIEW_ID
    from trackplan.report.run_report import write_run_report

    if not CHROMIUM.exists():
        pytest.skip(f"BROWSER TEST SKIPPED: no Chromium at {CHROMIUM}; run `make browser`")
    _, report = write_run_report(corner_result, meshed_case, tmp_path, None, None)
    with sync_api.sync_playwright() as playwright:
        browser = playwright.chromium.launch(executable_path=str(CHROMIUM), args=CHROMIUM_ARGS)
        page = browser.new_page(viewport={"width": 1400, "height": 1000})
        problems: list[str] = []
        page.on("console", lambda m: problems.append(m.text) if m.type == "error" else None)
        page.on("pageerror", lambda error: problems.append(str(error)))
        start = time.perf_counter()
        page.goto(report.as_uri())
        page.wait_for_function(
            f"() => {{ const gd = document.getElementById('{VIEW_ID}');"
            " return gd && gd._fullData && gd._transitionData"
            " && gd._transitionData._frames.length > 0; }",
            timeout=60_000,
        )
        loaded = time.perf_counter() - start
        triangles = page.evaluate(
            f"() => document.getElementById('{VIEW_ID}').data"
            ".filter((t) => t.type === 'mesh3d' && t.name.startsWith('robot'))"
            ".map((t) => t.i.length)"
        )
        # the view's own opening time: its figure and frames drawn again into a new div
        # (the page's load adds parsing plotly.js, the same for every report)
        rendered = page.evaluate(RENDER_AGAIN, VIEW_ID) / 1e3
        browser.close()
    assert sum(triangles) == n_triangles(meshed_case.robot.visuals)
    assert not problems, problems
    assert rendered <= 2.0, f"the 3D view took {rendered:.2f} s to open (page {loaded:.2f} s)"
    assert report.stat().st_size < 12e6


def test_in_a_cell_the_meshes_keep_the_checked_capsules_a_click_away(meshed_robot, corner):
    from trackplan.io.case_file import load_case
    from trackplan.robots.kinematics import joint_frames

    cell_case = load_case(Path(__file__).resolve().parents[2] / "cases" / "paper-corner-cell.yaml")
    assert cell_case.cell is not None
    torch = Capsules(np.zeros(1), [[[0.0, 0.0, -0.2], [0.0, 0.0, 0.0]]], [0.02], ("torch",))
    cell_case = dataclasses.replace(cell_case, cell=dataclasses.replace(cell_case.cell, tool=torch))
    robot = dataclasses.replace(meshed_robot, collision=corner.robot.collision)
    case = dataclasses.replace(cell_case, robot=robot)
    q = np.zeros((3, robot.n_dof))
    look = robot_look(case, joint_frames(robot, q))
    traces = [build(0) for build in look.builders]
    by_name = {t["name"]: t for t in traces}
    assert by_name[MESHES_TRACE].get("visible", True) is True
    assert by_name[CAPSULES_TRACE]["visible"] == "legendonly"  # what the check measures
    assert by_name[TOOL_SOLIDS_TRACE].get("visible", True) is True
    # without meshes the capsules are the robot's look, opaque
    plain = robot_look(cell_case, joint_frames(cell_case.robot, q))
    assert plain.kind == "capsules"
    names = [build(0)["name"] for build in plain.builders]
    assert names == [SOLIDS_TRACE, TOOL_SOLIDS_TRACE]
