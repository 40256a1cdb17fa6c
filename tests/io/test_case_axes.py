"""The welding-cell keys of a case file: ``positioner``, ``track``, ``downhand`` and
``weave`` parsed into the shared types, every bad value refused as one located line
(exit 2) by ``validate`` and ``plan``."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from tests.io.test_case_file import validate_fails, write_case
from trackplan.cli import main
from trackplan.errors import CaseError
from trackplan.io.case_file import load_case
from trackplan.robots.machine import Machine
from trackplan.tool.weave import WeavePattern, WeavePlane

NORMAL_TOOL = {"frame": "seam", "normal": [0, 0, 1]}
"""A task tool with a weld normal (what ``downhand`` needs)."""
TRACK = {"axis": [2, 0, 0], "position": [0.0, 4.0], "velocity": 1.0, "acceleration": 2.0}
TRACK["jerk"] = 20.0
WEAVE = {"pattern": "trapezoid", "amplitude": 0.002, "frequency": 2.0, "dwell": 0.05}
SEAMS = [
    {"name": "a", "start": [0, 0, 0], "segments": [{"line": {"to": [0.3, 0, 0]}}]},
    {"name": "b", "start": [0, 0.1, 0], "segments": [{"line": {"to": [0.3, 0.1, 0]}}]},
]


def seams(task_b: dict[str, Any] | None = None) -> list[dict[str, Any]]:
    """Two seams; the second with its own task when given."""
    both = [dict(seam) for seam in SEAMS]
    if task_b is not None:
        both[1]["task"] = task_b
    return both


def several(changes: dict[str, Any]) -> dict[str, Any]:
    """Changes that replace the case's path by two seams."""
    return {"path": None, **changes}


def write(folder: Path, changes: dict[str, Any]) -> Path:
    """A case file: BASE with ``changes``; a ``path: None`` change drops the path."""
    file = write_case(folder, {k: v for k, v in changes.items() if v is not None})
    if changes.get("path", 0) is None:
        text = file.read_text(encoding="utf-8")
        start = text.index("path:")
        end = text.index("task:")
        file.write_text(text[:start] + text[end:], encoding="utf-8")
    return file


# --------------------------------------------------------------------------- parsing


def test_a_positioner_with_a_fixed_pose_is_the_builtin_chain_at_that_pose(tmp_path: Path) -> None:
    pose = [1.2, -0.4, 0.0, 0.0, 0.0, 0.5]
    case = load_case(write(tmp_path, {"positioner": {"model": "two-axis-500", "pose": pose}}))
    positioner = case.positioner
    assert positioner is not None and positioner.model == "two-axis-500"
    assert positioner.chain.joint_names == ("tilt", "rotate")
    np.testing.assert_array_equal(positioner.pose, pose)
    assert positioner.lower is None and positioner.upper is None
    assert isinstance(case.machine, Machine)
    assert case.machine.joint_names[-2:] == ("tilt", "rotate")


def test_a_pose_mapping_gives_the_centre_and_the_bounds(tmp_path: Path) -> None:
    pose = {"x": [1.0, 1.4], "y": -0.5, "yaw": [-0.5, 0.3]}
    case = load_case(write(tmp_path, {"positioner": {"model": "two-axis-500", "pose": pose}}))
    positioner = case.positioner
    assert positioner is not None and positioner.lower is not None
    # left-out keys are 0 and fixed; a scalar is fixed; [min, max] is searched from the centre
    np.testing.assert_allclose(positioner.pose, [1.2, -0.5, 0, 0, 0, -0.1], atol=1e-15)
    np.testing.assert_array_equal(positioner.lower, [1.0, -0.5, 0, 0, 0, -0.5])
    np.testing.assert_array_equal(positioner.upper, [1.4, -0.5, 0, 0, 0, 0.3])
    np.testing.assert_array_equal(positioner.searched, [0, 5])


def test_a_pose_mapping_of_fixed_values_is_a_fixed_pose(tmp_path: Path) -> None:
    pose = {"x": 1.0, "z": 0.2}
    case = load_case(write(tmp_path, {"positioner": {"model": "one-axis-turntable", "pose": pose}}))
    assert case.positioner is not None and case.positioner.lower is None
    np.testing.assert_array_equal(case.positioner.pose, [1.0, 0, 0.2, 0, 0, 0])


def test_the_track_is_parsed_with_a_unit_axis(tmp_path: Path) -> None:
    case = load_case(write(tmp_path, {"track": TRACK}))
    track = case.track
    assert track is not None
    np.testing.assert_array_equal(track.axis, [1.0, 0.0, 0.0])
    assert (track.lower, track.upper) == (0.0, 4.0)
    assert (track.velocity, track.acceleration, track.jerk) == (1.0, 2.0, 20.0)
    assert case.machine.joint_names[-1] == "track"


def test_downhand_is_parsed_with_a_tool_normal(tmp_path: Path) -> None:
    changes = {"task.tool": NORMAL_TOOL, "downhand": {"slope": 0.1, "rotation": 0.2}}
    case = load_case(write(tmp_path, changes))
    assert case.downhand is not None
    assert (case.downhand.slope, case.downhand.rotation) == (0.1, 0.2)


def test_downhand_defaults_to_ten_degrees(tmp_path: Path) -> None:
    case = load_case(write(tmp_path, {"task.tool": NORMAL_TOOL, "downhand": {}}))
    assert case.downhand is not None
    assert case.downhand.slope == pytest.approx(math.radians(10.0), abs=1e-15)
    assert case.downhand.rotation == pytest.approx(math.radians(10.0), abs=1e-15)


def test_downhand_takes_the_weld_normals_of_the_segments(tmp_path: Path) -> None:
    path = {
        "start": [0.1, 0, 0],
        "segments": [
            {"arc": {"center": [0, 0, 0], "normal": [0, 0, 1], "angle": 3.0}},
            {"points": [[-0.1, 0.0, 0.0, 0, 0, 1], [-0.1, -0.1, 0.0, 0, 0, 1]]},
        ],
    }
    path["segments"][0]["arc"]["weld_normal"] = [1, 0, 1]
    changes = {"path": path, "task.tool": {"frame": "seam"}, "downhand": {"slope": 0.1}}
    assert load_case(write(tmp_path, changes)).downhand is not None


def test_no_key_leaves_the_case_as_it_was(tmp_path: Path) -> None:
    case = load_case(write(tmp_path, {}))
    assert (case.positioner, case.track, case.downhand, case.task.weave) == (None,) * 4
    assert case.machine is case.robot


def test_the_weave_of_the_task_and_of_a_seam(tmp_path: Path) -> None:
    own = {"pattern": "sine", "plane": "tool", "amplitude": 0.003, "frequency": 1.5}
    changes = several({"paths": seams({"weave": own}), "task.weave": WEAVE})
    case = load_case(write(tmp_path, changes))
    first, second = (seam.task.weave for seam in case.seams)
    assert first is not None and second is not None
    assert (first.pattern, first.plane) == (WeavePattern.TRAPEZOID, WeavePlane.SEAM)
    assert (first.amplitude, first.frequency, first.dwell) == (0.002, 2.0, 0.05)
    assert (second.pattern, second.plane) == (WeavePattern.SINE, WeavePlane.TOOL)
    assert (second.amplitude, second.frequency, second.dwell) == (0.003, 1.5, 0.0)
    assert case.task.weave == first


def test_a_seam_turns_the_weave_off_with_null(tmp_path: Path) -> None:
    changes = several({"paths": seams({"weave": None}), "task.weave": WEAVE})
    case = load_case(write(tmp_path, changes))
    assert case.seams[0].task.weave is not None and case.seams[1].task.weave is None
    # a seam task without a weave key keeps the case's weave
    changes = several({"paths": seams({"rated_speed": 0.1}), "task.weave": WEAVE})
    case = load_case(write(tmp_path, changes))
    assert case.seams[1].task.weave == case.seams[0].task.weave


def test_validate_summarises_the_keys(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    pose = {"x": [1.0, 1.4], "yaw": [-0.5, 0.5]}
    changes = {
        "positioner": {"model": "two-axis-500", "pose": pose},
        "track": TRACK,
        "task.tool": NORMAL_TOOL,
        "downhand": {"slope": 0.1745},
        "task.weave": WEAVE,
    }
    assert main(["validate", str(write(tmp_path, changes))]) == 0
    out = capsys.readouterr().out
    assert "positioner two-axis-500: 2 axes (tilt, rotate)" in out
    assert "searching x, yaw" in out
    assert "track     along [1, 0, 0], [0, 4] m" in out
    assert "downhand  slope ≤ 9.998°" in out
    assert "weave     test-case: trapezoid in the seam plane, 2 mm to each side, 2 Hz" in out


# --------------------------------------------------------------------------- bad values

BAD = [
    ({"positioner": {"model": "three-axis-9"}}, "positioner.model: unknown positioner"),
    ({"positioner": {"pose": [0] * 6}}, "positioner.model"),
    ({"positioner": {"model": "two-axis-500", "pose": [0] * 5}}, "positioner.pose"),
    ({"positioner": {"model": "two-axis-500", "pose": "here"}}, "positioner.pose"),
    (
        {"positioner": {"model": "two-axis-500", "pose": {"yaw": [0.5, -0.5]}}},
        "positioner.pose.yaw: expected [min, max] with min ≤ max",
    ),
    ({"positioner": {"model": "two-axis-500", "pose": {"yaw": "a"}}}, "positioner.pose.yaw"),
    ({"positioner": {"model": "two-axis-500", "pose": {"w": 1}}}, "positioner.pose.w"),
    ({"positioner": {"model": "two-axis-500", "color": 1}}, "positioner.color"),
    ({"track": {**TRACK, "axis": [0, 0, 0]}}, "track.axis: expected a non-zero direction"),
    ({"track": {**TRACK, "position": [4, 0]}}, "track.position: expected [min, max]"),
    ({"track": {**TRACK, "velocity": 0}}, "track.velocity"),
    ({"track": {**TRACK, "acceleration": -2}}, "track.acceleration"),
    ({"track": {k: v for k, v in TRACK.items() if k != "jerk"}}, "track.jerk"),
    ({"task.tool": NORMAL_TOOL, "downhand": {"slope": 10}}, "downhand.slope: expected an angle"),
    ({"task.tool": NORMAL_TOOL, "downhand": {"rotation": -0.1}}, "downhand.rotation"),
    ({"downhand": {"slope": 0.1}}, "downhand: needs the weld's normal"),
    ({"task.tool_rpy": [3.14159, 0, 0], "downhand": {}}, "path.segments[0] has none"),
    ({"task.weave": {"amplitude": 0.002}}, "task.weave.frequency"),
    ({"task.weave": {**WEAVE, "pattern": "zigzag"}}, "task.weave.pattern"),
    ({"task.weave": {**WEAVE, "plane": "floor"}}, "task.weave.plane"),
    ({"task.weave": {**WEAVE, "amplitude": 2}}, "task.weave.amplitude: expected at most 0.05 m"),
    ({"task.weave": {**WEAVE, "amplitude": 0}}, "task.weave.amplitude"),
    ({"task.weave": {**WEAVE, "frequency": 500}}, "task.weave.frequency: expected at most 125 Hz"),
    ({"task.weave": {**WEAVE, "dwell": 0.25}}, "task.weave.dwell: expected less than half"),
    ({"task.weave": {**WEAVE, "pattern": "sine"}}, "task.weave.dwell: a dwell needs pattern"),
    ({"task.weave": {**WEAVE, "dwell": -1}}, "task.weave.dwell"),
    (several({"paths": seams({"weave": {**WEAVE, "dwell": 1}})}), "paths[1].task.weave.dwell"),
    (
        several({"paths": seams({"tool": NORMAL_TOOL}), "downhand": {}}),
        "downhand: needs the weld's normal: give task.tool.normal (or normals) with frame: "
        "seam, or a weld normal on every segment (paths[0].segments[0] has none)",
    ),
]


@pytest.mark.parametrize(("changes", "expected"), BAD)
def test_a_bad_value_is_one_line_naming_the_key(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], changes: dict[str, Any], expected: str
) -> None:
    file = write(tmp_path, changes)
    line = validate_fails(capsys, str(file))
    assert line.startswith(f"{file}: "), line
    assert expected in line, line
    with pytest.raises(CaseError):
        load_case(file)


@pytest.mark.parametrize(("changes", "expected"), [BAD[0], BAD[4], BAD[8], BAD[15], BAD[23]])
def test_plan_refuses_a_bad_value_as_one_line(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], changes: dict[str, Any], expected: str
) -> None:
    file = write(tmp_path, changes)
    code = main(["plan", str(file), "--out", str(tmp_path / "run"), "--no-report"])
    err = capsys.readouterr().err
    assert code == 2 and "Traceback" not in err
    lines = err.strip().splitlines()
    assert len(lines) == 1 and expected in lines[0], err


# --------------------------------------------------------------------------- objective


def test_external_weights_weigh_the_external_axes_in_the_travel(tmp_path: Path) -> None:
    case = load_case(write(tmp_path, {"track": TRACK, "objective": {"external_weights": [0.5]}}))
    np.testing.assert_array_equal(case.objective.external_weights, [0.5])
    assert case.travel_weights[-1] == 0.5
    assert len(case.travel_weights) == case.machine.n_dof
    plain = load_case(write(tmp_path, {"track": TRACK}))
    assert plain.travel_weights[-1] == 0.0  # by default only the arm's travel counts


@pytest.mark.parametrize(
    ("changes", "expected"),
    [
        (
            {"track": TRACK, "objective": {"external_weights": [0.5, 1.0]}},
            "objective.external_weights: expected 1 weights (the track, then the "
            "positioner's axes), got 2",
        ),
        (
            {"objective": {"external_weights": [0.5]}},
            "objective.external_weights: weights the external axes' travel, and the case "
            "has no track or positioner",
        ),
        (
            {"track": TRACK, "objective": {"kind": "copper"}},
            "objective.kind: copper needs",
        ),
    ],
)
def test_objective_against_the_external_axes_is_one_line(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], changes: dict[str, Any], expected: str
) -> None:
    line = validate_fails(capsys, str(write(tmp_path, changes)))
    assert expected in line
