"""report.html: one self-contained offline page with tables, plots and the 3D view."""

from __future__ import annotations

import json
import re

import numpy as np
import pytest

from tests.report.conftest import REPORT_FRAMES
from trackplan.report import VIEW_ID, robot_view_figure, write_plots, write_report
from trackplan.report.plotly_html import frames_element_id
from trackplan.report.robot_view import ROBOT_TRACE, TRAIL_TRACE, frame_name
from trackplan.report.scene import chain_points, frame_indices

EMBEDDED_PNG = re.compile(r'<img[^>]*\bsrc="data:image/png;base64,[A-Za-z0-9+/=]+"')


def plotly_call(page: str, function: str) -> list:
    """The JSON arguments after the div id of ``Plotly.<function>('robot-view', ...)``."""
    match = re.search(rf"Plotly\.{function}\(\s*['\"]{VIEW_ID}['\"],\s*", page)
    assert match, f"no Plotly.{function} call for {VIEW_ID}"
    decoder = json.JSONDecoder()
    args, position = [], match.end()
    while page[position] in "[{":
        value, position = decoder.raw_decode(page, position)
        args.append(value)
        position = re.compile(r"\s*,?\s*").match(page, position).end()
    return args


def page_frames(page: str) -> list:
    """The animation frames of the 3D view: the JSON element added after the first drawing."""
    match = re.search(
        rf'<script type="application/json" id="{frames_element_id(VIEW_ID)}">(.*?)</script>',
        page,
        re.DOTALL,
    )
    assert match, "no animation frames in the page"
    return json.loads(match.group(1))


@pytest.fixture(scope="module")
def page(report_file) -> str:
    return report_file.read_text(encoding="utf-8")


def test_report_is_offline(page):
    assert not re.search(r"<script[^>]*\bsrc\s*=", page, re.IGNORECASE)
    assert not re.search(r"<link[^>]*\bhref\s*=\s*[\"']https?://", page, re.IGNORECASE)
    assert not re.search(r"<img[^>]*\bsrc\s*=\s*[\"']https?://", page, re.IGNORECASE)
    assert len(EMBEDDED_PNG.findall(page)) == 4  # joints, path, speed, convergence
    # plotly.js itself is embedded, once
    assert len(re.findall(r"^\* plotly\.js v\d", page, re.MULTILINE)) == 1


def test_report_has_the_view_with_frames_and_slider(page):
    assert f'id="{VIEW_ID}"' in page
    data, layout = plotly_call(page, "newPlot")[:2]
    names = [trace.get("name") for trace in data]
    assert ROBOT_TRACE in names and TRAIL_TRACE in names
    frames = page_frames(page)
    assert len(frames) == REPORT_FRAMES
    assert [f["name"] for f in frames] == [frame_name(k) for k in range(REPORT_FRAMES)]
    (slider,) = layout["sliders"]
    assert len(slider["steps"]) == REPORT_FRAMES
    assert slider["steps"][-1]["args"][0] == [frame_name(REPORT_FRAMES - 1)]
    labels = [button["label"] for button in layout["updatemenus"][0]["buttons"]]
    assert any("play" in label for label in labels) and any("pause" in label for label in labels)


def test_report_tables(page, corner_result):
    for text in (
        "paper-corner",
        "puma560",
        "limits_violated",
        corner_result.check.violations[0].message,
        "joint 4 velocity",  # the slow-down
        "toppra",
        "Margins",
        "best_X",
        "cmaes",
        "-56.0 %",  # joint 6 jerk margin
    ):
        assert text in page, text


def test_robot_view_animates_the_dh_chain(corner, corner_result):
    figure = robot_view_figure(corner_result, corner, n_frames=25)
    assert len(figure.frames) == 25
    names = [trace.name for trace in figure.data]
    robot_index, trail_index = names.index(ROBOT_TRACE), names.index(TRAIL_TRACE)
    idx = frame_indices(corner_result.trajectory.n_samples, 25)
    for k in (0, 12, 24):
        frame = figure.frames[k]
        # the robot (its joints, then its solids), the tool frame and the trail
        assert list(frame.traces) == list(range(robot_index, trail_index + 1))
        robot = frame.data[0]
        expected = chain_points(corner.robot, corner_result.trajectory.q[idx[k]])
        drawn = np.column_stack([robot.x, robot.y, robot.z])
        np.testing.assert_allclose(drawn, expected, atol=1e-5)
        assert len(frame.data[-1].x) == k + 1  # the trail grows with time
    ranges = [figure.layout.scene[f"{axis}axis"].range for axis in "xyz"]
    widths = [high - low for low, high in ranges]
    np.testing.assert_allclose(widths, widths[0])


def test_report_without_a_trajectory(tmp_path, corner, unreachable_result):
    plots = write_plots(unreachable_result, corner, tmp_path)
    page = write_report(unreachable_result, corner, tmp_path, plots).read_text(encoding="utf-8")
    assert "No trajectory to show" in page
    assert unreachable_result.message in page
    assert len(EMBEDDED_PNG.findall(page)) == 3
    assert "Plotly.newPlot" not in page


def test_report_shows_torque_margins_and_energy(page, corner_result):
    """The PUMA560 has dynamics: a torque row in the margins and the energy figures."""
    energy = corner_result.energy
    assert energy is not None
    assert "torque [N·m]" in page
    assert "copper loss" in page and energy.copper_loss_unit in page
    assert f"(joint {energy.peak_torque_joint})" in page


def test_view_base_and_part_frames_differ_in_colour_and_legend(corner, corner_result):
    """In the 3D view the two frames' axes were the same red, green and blue: each frame
    now has its own colours and dash, and one legend entry of its own."""
    from trackplan.report.robot_view import robot_view_spec

    traces = robot_view_spec(corner_result, corner, n_frames=4)["data"]
    frames = {}
    for name in ("base frame", "part frame"):
        axes = [t for t in traces if t.get("legendgroup") == name]
        assert len(axes) == 3
        frames[name] = axes
        legend = [t for t in axes if t["showlegend"]]
        assert len(legend) == 1 and legend[0]["name"].startswith(name)
    base_colours = {t["line"]["color"] for t in frames["base frame"]}
    part_colours = {t["line"]["color"] for t in frames["part frame"]}
    assert len(base_colours) == len(part_colours) == 3
    assert not base_colours & part_colours
    assert {t["line"].get("dash", "solid") for t in frames["base frame"]} == {"solid"}
    assert {t["line"].get("dash", "solid") for t in frames["part frame"]} == {"dash"}


def _table_after(page: str, heading: str) -> list[list[str]]:
    """The rows (header row first) of the first table after ``heading``, cell texts."""
    start = page.index(heading)
    table = page[page.index("<table", start) : page.index("</table>", start)]
    rows = re.findall(r"<tr>(.*?)</tr>", table)
    return [
        [re.sub(r"<[^>]+>", "", c) for c in re.findall(r"<t[hd][^>]*>(.*?)</t[hd]>", row)]
        for row in rows
    ]


def test_placement_search_tables_have_named_columns(corner, corner_result):
    """The search's figures were printed as raw dicts ("name = puma560, joints = 6, …",
    "placement = x = 0.15, y = 0, …"): they are tables with named columns, units in the
    headers, and the robot block, already in the Case section, is not repeated."""
    from trackplan.report.html import report_page

    info = {
        "robot": {"name": "puma560", "joints": 6, "parameters": {"a1": -0.0, "a2": 0.0203}},
        "optimizer": {
            "method": "multistart",
            "seed": 0,
            "evaluations": 3464,
            "generations": 70,
            "stop_reason": "converged",
            "runs": 1,
            "wall_time_s": 141.606351361,
            "status": "feasible",
            "message": "feasible placement found in 3464 evaluations",
            "fitness": 0.7896407537987621,
            "rejected_candidates": [[0.1, 0.2, 0.3, 0.0, 0.1, 0.2]],
        },
        "initial": {
            "placement": {"x": 0.150333, "y": 0.0, "z": 0.0, "roll": 0.0, "pitch": 0.0, "yaw": 0.0},
            "feasible": True,
            "status": "feasible",
            "message": "feasible: every limit met",
            "objective": 1.5098382877706558,
            "violations": [],
        },
    }
    page = report_page(corner_result, corner, [], "", None, info)
    section = page[page.index('<section id="result">') :]
    for raw in ("name = puma560", "placement = x =", "rejected_candidates", "wall_time_s", "{"):
        assert raw not in section, raw
    search = _table_after(section, "<h3>Placement search</h3>")
    assert search[0] == [
        "method",
        "seed",
        "runs",
        "generations",
        "evaluations",
        "wall time [s]",
        "best fitness",
        "stopped",
    ]
    assert search[1] == ["multistart", "0", "1", "70", "3464", "141.6", "0.789641", "converged"]
    placements = _table_after(section, "<h4>Placements</h4>")
    assert placements[0] == [
        "placement",
        "x [m]",
        "y [m]",
        "z [m]",
        "roll [rad]",
        "pitch [rad]",
        "yaw [rad]",
        "verdict",
        "J",
    ]
    before, after, rejected = placements[1:]
    assert before[0].startswith("before") and before[1:3] == ["0.1503", "0"]
    assert before[7:] == ["feasible", "1.50984"]
    assert after[0].startswith("after") and after[7] == corner_result.status.value
    assert after[1] == f"{corner_result.placement[0]:.4g}"
    assert rejected[0].startswith("rejected") and rejected[1:4] == ["0.1", "0.2", "0.3"]


def test_key_figures_give_the_top_speed_when_no_sample_runs_at_the_rated_speed(
    corner, corner_result
):
    """ "rated speed fraction 0.0 %" for a speed curve that cruises at 99.9 % of the rated
    speed said nothing: the key figures give the top speed against the rated speed."""
    import dataclasses

    from trackplan.report.html import report_page

    trajectory = dataclasses.replace(
        corner_result.trajectory, speed=0.999 * corner_result.trajectory.speed
    )
    below = dataclasses.replace(corner_result, rated_speed_fraction=0.0, trajectory=trajectory)
    figures = dict(
        row[:2] for row in _table_after(report_page(below, corner, [], ""), "<h3>Key figures</h3>")
    )
    assert "rated speed fraction" not in figures
    top = 1e3 * float(trajectory.speed.max())
    share = 100 * top / (1e3 * corner.task.rated_speed)
    assert figures["top speed"] == f"{top:.4g} mm/s ({share:.1f} % of v_r)"
    figures = dict(
        row[:2]
        for row in _table_after(report_page(corner_result, corner, [], ""), "<h3>Key figures</h3>")
    )
    assert figures["rated speed fraction"] == f"{100 * corner_result.rated_speed_fraction:.1f} %"
    assert "top speed" not in figures


def test_key_figures_state_the_weave_reached(corner, corner_result):
    """A weaving plan's key figures carry one row with the weave reached; others none."""
    import dataclasses

    from trackplan.report.html import report_page
    from trackplan.tool.weave import WeaveReached

    woven = dataclasses.replace(
        corner_result, weave=WeaveReached(0.0019998, 2.0004, "triangle", "seam")
    )
    figures = dict(
        row[:2] for row in _table_after(report_page(woven, corner, [], ""), "<h3>Key figures</h3>")
    )
    assert figures["weave reached"] == "2 mm at 2 Hz (triangle, plane seam)"
    figures = dict(
        row[:2]
        for row in _table_after(report_page(corner_result, corner, [], ""), "<h3>Key figures</h3>")
    )
    assert "weave reached" not in figures
