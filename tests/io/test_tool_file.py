"""``task.tool``: the alias, the spec it gives, and one clear line per bad value (exit 2)."""

from __future__ import annotations

import numpy as np
import pytest

from trackplan.cli import ExitCode, main
from trackplan.errors import CaseError
from trackplan.io.case_file import load_case_text
from trackplan.tool import SpinMode, ToolFrame

CASE = """
name: seam-line
path:
  start: [0, 0, 0]
  segments:
    - line: {{to: [0.2, 0, 0]}}
    - line: {{to: [0.2, 0.2, 0]}}
task:
  rated_speed: 0.1
{task}
"""


def _case(task: str):
    return load_case_text(CASE.format(task=task), file="seam.yaml")


def test_tool_rpy_is_the_part_frame_alias():
    old = _case("  tool_rpy: [0.1, 0.2, 0.3]").task.tool
    new = _case("  tool: {frame: part, rpy: [0.1, 0.2, 0.3]}").task.tool
    assert old.frame is new.frame is ToolFrame.PART
    np.testing.assert_array_equal(old.rpy, new.rpy)
    assert old.spin is SpinMode.FIXED and old.n_spin == 0


def test_seam_spec_takes_one_normal_per_segment():
    tool = _case("  tool: {frame: seam, normals: [[0, 0, 2], [0, 0, 1]]}").task.tool
    assert tool.normal is None
    np.testing.assert_array_equal(tool.normals, [[0, 0, 2], [0, 0, 1]])
    np.testing.assert_array_equal(tool.segment_normals(np.array([1, 0])), [[0, 0, 1], [0, 0, 1]])
    assert tool.describe()["normals"] == [[0, 0, 2], [0, 0, 1]]


def test_seam_spec_keys():
    tool = _case(
        "  tool: {frame: seam, normal: [0, 0, 2], work_angle: 0.5, travel_angle: -0.2,"
        " spin: free-varying, spin_range: [-1, 2], spin_rate: 5}"
    ).task.tool
    assert tool.frame is ToolFrame.SEAM and tool.spin is SpinMode.FREE_VARYING
    assert (tool.work_angle, tool.travel_angle, tool.spin_range, tool.spin_rate) == (
        0.5,
        -0.2,
        (-1.0, 2.0),
        5.0,
    )


BAD = {
    "zero normal": (
        "  tool: {frame: seam, normal: [0, 0, 0]}",
        "seam.yaml: task.tool.normal: expected a surface normal of length ≥ 1e-06, got "
        "[0.0, 0.0, 0.0]",
    ),
    "normal too short to have a direction": (
        "  tool: {frame: seam, normal: [0, 0, 1e-300]}",
        "seam.yaml: task.tool.normal: expected a surface normal of length ≥ 1e-06, got "
        "[0.0, 0.0, 1e-300]",
    ),
    "normal among normals too short": (
        "  tool: {frame: seam, normals: [[0, 0, 1], [0, 0, 9e-7]]}",
        "seam.yaml: task.tool.normals[1]: expected a surface normal of length ≥ 1e-06, got "
        "[0.0, 0.0, 9e-07]",
    ),
    "work angle out of range": (
        "  tool: {frame: seam, normal: [0, 0, 1], work_angle: 1e300}",
        "seam.yaml: task.tool.work_angle: expected a number ≤ 1000, got 1e+300",
    ),
    "spin rate out of range": (
        "  tool: {spin: free-varying, spin_rate: 1e300}",
        "seam.yaml: task.tool.spin_rate: expected a number ≤ 1e+06, got 1e+300",
    ),
    "normal along the tangent": (
        "  tool: {frame: seam, normal: [0, 1, 0]}",
        "seam.yaml: task.tool.normal: the normal [0.0, 1.0, 0.0] is parallel to the path "
        "tangent at s = 0.2 m",
    ),
    "spin range reversed": (
        "  tool: {spin: free, spin_range: [1, -1]}",
        "seam.yaml: task.tool.spin_range: expected [min, max] with min ≤ max, rad, got [1.0, -1.0]",
    ),
    "spin rate not positive": (
        "  tool: {spin: free-varying, spin_rate: 0}",
        "seam.yaml: task.tool.spin_rate: expected a rate > 0, rad/m of path, got 0.0",
    ),
    "normal and normals": (
        "  tool: {frame: seam, normal: [0, 0, 1], normals: [[0, 0, 1], [0, 0, 1]]}",
        "seam.yaml: task.tool.normals: give the surface normal once: normal (the whole path) "
        "or normals (one per path segment); remove one of the two",
    ),
    "normals count": (
        "  tool: {frame: seam, normals: [[0, 0, 1], [0, 0, 1], [0, 0, 1]]}",
        "seam.yaml: task.tool.normals: expected 2 normals, one per path segment (2 segments), "
        "got 3",
    ),
    "zero normal among normals": (
        "  tool: {frame: seam, normals: [[0, 0, 1], [0, 0, 0]]}",
        "seam.yaml: task.tool.normals[1]: expected a surface normal of length ≥ 1e-06, got "
        "[0.0, 0.0, 0.0]",
    ),
    "normal along its segment's tangent": (
        "  tool: {frame: seam, normals: [[0, 0, 1], [0, 1, 0]]}",
        "seam.yaml: task.tool.normals[1]: the normal [0.0, 1.0, 0.0] of path.segments[1] is "
        "parallel to the path tangent at s = 0.2 m",
    ),
    "opposite neighbouring normals": (
        "  tool: {frame: seam, normals: [[0, 0, 1], [0, 0, -1]]}",
        "seam.yaml: task.tool.normals[1]: the normals of path.segments[0] and [1] are opposite",
    ),
    "normals with the part frame": (
        "  tool: {frame: part, normals: [[0, 0, 1], [0, 0, 1]]}",
        "seam.yaml: task.tool.normals: normals applies to frame: seam",
    ),
    "tool and tool_rpy": (
        "  tool_rpy: [0, 0, 0]\n  tool: {frame: part}",
        "seam.yaml: task.tool_rpy: give the tool orientation once",
    ),
}


@pytest.mark.parametrize("name", list(BAD))
def test_bad_tool_is_one_line(name):
    task, start = BAD[name]
    with pytest.raises(CaseError) as error:
        _case(task)
    line = error.value.one_line()
    assert "\n" not in line
    assert line.startswith(start), line


@pytest.mark.parametrize("name", list(BAD))
def test_bad_tool_exits_2(name, tmp_path, capsys):
    file = tmp_path / "seam.yaml"
    file.write_text(CASE.format(task=BAD[name][0]))
    assert main(["validate", str(file)]) == ExitCode.BAD_INPUT
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "task.tool" in err
