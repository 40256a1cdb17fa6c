"""Case files: the shipped cases load, defaults apply, and every kind of bad input is one
clear line from ``trackplan validate`` with exit code 2."""

from __future__ import annotations

import copy
from pathlib import Path
from typing import Any

import numpy as np
import pytest
import yaml

from tests.conftest import CASES
from trackplan.case import Case
from trackplan.cli import main
from trackplan.errors import CaseError
from trackplan.io.case_file import PAPER_WEIGHTS, load_case, load_case_text, load_points_csv
from trackplan.io.robot_file import robot_to_yaml
from trackplan.paths.specs import ArcSpec, LineSpec, PointsSpec
from trackplan.robots.builtin import puma560

BASE: dict[str, Any] = {
    "name": "test-case",
    "robot": "puma560",
    "path": {
        "start": [0, 0, 0],
        "segments": [{"line": {"to": [0.5, 0, 0]}}, {"line": {"to": [0.3, 0, 0.5]}}],
    },
    "task": {"rated_speed": 0.15},
}


def write_case(
    folder: Path, changes: dict[str, Any] | None = None, name: str = "case.yaml"
) -> Path:
    """Write BASE with ``changes`` applied ({"task.rated_speed": 0, ...}) and return the file."""
    data = copy.deepcopy(BASE)
    for key, value in (changes or {}).items():
        *parents, last = key.split(".")
        node = data
        for parent in parents:
            node = node.setdefault(parent, {})
        node[last] = value
    file = folder / name
    file.write_text(yaml.safe_dump(data, sort_keys=False), encoding="utf-8")
    return file


def validate_fails(capsys: pytest.CaptureFixture[str], *args: str) -> str:
    """Run ``trackplan validate ARGS``, check it fails as bad input, return the error line."""
    code = main(["validate", *args])
    captured = capsys.readouterr()
    assert code == 2
    assert "Traceback" not in captured.err
    lines = captured.err.strip().splitlines()
    assert len(lines) == 1, captured.err
    return lines[0]


# --------------------------------------------------------------------------- good input


@pytest.mark.parametrize("name", ["paper-line", "paper-circle", "paper-corner"])
def test_paper_cases_load_with_the_paper_settings(name: str) -> None:
    case = load_case(CASES / f"{name}.yaml")
    assert isinstance(case, Case)
    assert case.name == name
    assert case.robot.name == "puma560"
    np.testing.assert_array_equal(case.start, [0, 0, 0])
    assert (case.task.rated_speed, case.task.corner_speed) == (0.15, 0.15)
    assert (case.task.tolerance, case.task.sample_time) == (0.001, 0.001)
    np.testing.assert_allclose(case.task.tool.rpy, [-np.pi / 2, 0, 0])
    np.testing.assert_array_equal(case.bounds.lower, [-0.87] * 3 + [-1.57] * 3)
    np.testing.assert_array_equal(case.bounds.upper, [0.87] * 3 + [1.57] * 3)
    np.testing.assert_allclose(np.square(case.bounds.reach), [0.0226, 0.7289], atol=1e-6)
    np.testing.assert_array_equal(case.objective.weights, PAPER_WEIGHTS)
    assert (case.optimizer.method, case.optimizer.population, case.optimizer.seed) == (
        "multistart",
        30,
        0,
    )
    assert case.source == str(CASES / f"{name}.yaml")


def test_paper_case_geometry() -> None:
    line = load_case(CASES / "paper-line.yaml").segments
    assert len(line) == 1 and isinstance(line[0], LineSpec)
    np.testing.assert_array_equal(line[0].to, [0.3, 0, 0.5])
    (arc,) = load_case(CASES / "paper-circle.yaml").segments
    assert isinstance(arc, ArcSpec)
    np.testing.assert_array_equal(arc.center, [0, 0, -0.2])
    assert abs(arc.normal[1]) == 1.0 and arc.angle == pytest.approx(2 * np.pi)
    corner = load_case(CASES / "paper-corner.yaml").segments
    np.testing.assert_array_equal(
        [s.to for s in corner if isinstance(s, LineSpec)], [[0.5, 0, 0], [0.3, 0, 0.5]]
    )


def test_ur5_bead_reads_its_points_file() -> None:
    case = load_case(CASES / "ur5-bead.yaml")
    assert case.robot.name == "ur5"
    kinds = [type(segment) for segment in case.segments]
    assert {LineSpec, ArcSpec, PointsSpec} <= set(kinds)
    points = next(s for s in case.segments if isinstance(s, PointsSpec)).points
    assert points.shape == (11, 3)
    np.testing.assert_allclose(points[-1], [0.13, 0.26, 0.0])


@pytest.mark.parametrize("robot", ["kuka_kr6_r700_sixx", "ur10e"])
def test_default_position_range_is_the_robots_reach(tmp_path: Path, robot: str) -> None:
    case = load_case(write_case(tmp_path, {"robot": robot}))
    reach = np.floor(case.robot.reach * 100.0) / 100.0
    assert reach > 1.0  # bigger than the PUMA560's 0.87 m
    np.testing.assert_array_equal(case.bounds.lower, [-reach] * 3 + [-1.57] * 3)
    np.testing.assert_array_equal(case.bounds.upper, [reach] * 3 + [1.57] * 3)


def test_example_outside_the_default_range_names_it(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    file = write_case(tmp_path, {"placement": {"example": [0.9, 0, 0, 0, 0, 0]}})
    line = validate_fails(capsys, str(file))
    assert "placement.example" in line and "[-0.87, 0.87]" in line


def test_defaults(tmp_path: Path) -> None:
    case = load_case(write_case(tmp_path))
    assert case.task.corner_speed == case.task.rated_speed == 0.15
    assert (case.task.tolerance, case.task.sample_time, case.task.timing) == (
        0.001,
        0.001,
        "smooth",
    )
    np.testing.assert_array_equal(case.task.tool.rpy, [0, 0, 0])
    np.testing.assert_array_equal(case.bounds.lower, [-0.87] * 3 + [-1.57] * 3)
    assert case.bounds.reach == (0.150333, 0.853756) and case.bounds.example is None
    np.testing.assert_array_equal(case.objective.weights, PAPER_WEIGHTS)
    assert (case.objective.time_weight, case.objective.penalty) == (0.0, "graded")
    assert case.objective.flat_penalty == 1.0e6
    assert (case.optimizer.method, case.optimizer.population, case.optimizer.budget) == (
        "multistart",
        30,
        None,
    )


def test_default_weights_of_a_robot_that_is_not_six_joints(tmp_path: Path) -> None:
    text = robot_to_yaml(puma560()).replace("name: puma560", "name: arm5")
    text = text.split("\ncollision:")[0]  # its link capsules: up to link 6
    text = text[: text.rindex("  - {")]  # drop the last joint
    (tmp_path / "arm5.yaml").write_text(text, encoding="utf-8")
    case = load_case(write_case(tmp_path, {"robot": "arm5.yaml"}))
    assert case.robot.n_dof == 5
    np.testing.assert_array_equal(case.objective.weights, np.ones(5))


def test_yaml_12_floats_and_integers_are_numbers(tmp_path: Path) -> None:
    file = write_case(tmp_path)
    file.write_text(file.read_text().replace("rated_speed: 0.15", "rated_speed: 15e-2"))
    assert load_case(file).task.rated_speed == 0.15
    assert load_case(write_case(tmp_path, {"task.rated_speed": 1})).task.rated_speed == 1.0


def test_load_case_text_without_a_file() -> None:
    case = load_case_text(yaml.safe_dump(BASE))
    assert case.source is None and case.name == "test-case"
    with pytest.raises(CaseError) as error:
        load_case_text("name: [")
    assert error.value.file is None and "line 1" in str(error.value)


def test_points_csv_skips_comments_and_a_header(tmp_path: Path) -> None:
    csv = tmp_path / "seam.csv"
    csv.write_text("# a seam\nx, y, z\n0.1,0,0\n\n0.2, 0.1, 0\n", encoding="utf-8")
    np.testing.assert_array_equal(load_points_csv(csv), [[0.1, 0, 0], [0.2, 0.1, 0]])


def test_the_earliest_problem_in_the_file_is_reported(
    capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    file = write_case(tmp_path, {"task.tolerance": -1, "placement": {"x": [1, -1]}, "name": 3})
    assert "name: expected a string, got 3" in validate_fails(capsys, str(file))
    file = write_case(tmp_path, {"task.tolerance": -1, "placement": {"x": [1, -1]}})
    assert "task.tolerance" in validate_fails(capsys, str(file))


# ------------------------------------------------------------------ bad input, one test each


def test_unknown_key(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    line = validate_fails(capsys, str(write_case(tmp_path, {"task.rated_sped": 0.1})))
    assert "case.yaml: task.rated_sped: unknown key; did you mean 'rated_speed'?" in line


def test_wrong_type(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    line = validate_fails(capsys, str(write_case(tmp_path, {"task.rated_speed": "fast"})))
    assert "case.yaml: task.rated_speed: expected a number, got 'fast'" in line


@pytest.mark.parametrize(
    ("value", "key"),
    [
        (".nan", "task.rated_speed"),
        (".inf", "task.rated_speed"),
        ("-.inf", "task.tolerance"),
        (".NaN", "path.start[1]"),
    ],
)
def test_non_finite_number(
    capsys: pytest.CaptureFixture[str], tmp_path: Path, value: str, key: str
) -> None:
    if key == "path.start[1]":
        file = write_case(tmp_path, {"path.start": [0, "NAN", 0]})
        file.write_text(file.read_text().replace("NAN", value))
    else:
        file = write_case(tmp_path, {key: "NAN"})
        file.write_text(file.read_text().replace("NAN", value))
    line = validate_fails(capsys, str(file))
    assert f"case.yaml: {key}: expected a finite number, got " in line


@pytest.mark.parametrize(
    ("key", "value"),
    [
        ("rated_speed", 0),
        ("rated_speed", -0.1),
        ("corner_speed", 0),
        ("sample_time", -0.001),
    ],
)
def test_non_positive_speed_tolerance_or_sample_time(
    capsys: pytest.CaptureFixture[str], tmp_path: Path, key: str, value: float
) -> None:
    line = validate_fails(capsys, str(write_case(tmp_path, {f"task.{key}": value})))
    assert f"case.yaml: task.{key}: expected a number > 0, got {value}" in line


def test_zero_length_line(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    segments = [{"line": {"to": [0.5, 0, 0]}}, {"line": {"to": [0.5, 0, 0]}}]
    line = validate_fails(capsys, str(write_case(tmp_path, {"path.segments": segments})))
    assert "case.yaml: path.segments[1].line.to: " in line and "zero length" in line


def test_arc_of_zero_radius(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    arc = {"arc": {"center": [0, 0, 0], "normal": [0, 1, 0], "angle": 1.0}}
    line = validate_fails(capsys, str(write_case(tmp_path, {"path.segments": [arc]})))
    assert "case.yaml: path.segments[0].arc.center: " in line and "zero radius" in line


def test_arc_with_zero_normal(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    arc = {"arc": {"center": [0, 0, -0.2], "normal": [0, 0, 0], "angle": 1.0}}
    line = validate_fails(capsys, str(write_case(tmp_path, {"path.segments": [arc]})))
    assert "case.yaml: path.segments[0].arc.normal: " in line and "non-zero" in line


def test_arc_normal_not_perpendicular_to_the_radius(
    capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    arc = {"arc": {"center": [0, 0, -0.2], "normal": [0, 0.1, 1], "angle": 1.0}}
    segments = [{"line": {"to": [0.5, 0, 0]}}, {"line": {"to": [0, 0, 0]}}, arc]
    line = validate_fails(capsys, str(write_case(tmp_path, {"path.segments": segments})))
    assert "case.yaml: path.segments[2].arc.normal: " in line and "not perpendicular" in line


def test_arc_of_zero_angle(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    arc = {"arc": {"center": [0, 0, -0.2], "normal": [0, 1, 0], "angle": 0}}
    line = validate_fails(capsys, str(write_case(tmp_path, {"path.segments": [arc]})))
    assert "case.yaml: path.segments[0].arc.angle: " in line and "non-zero" in line


def test_consecutive_duplicate_points(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    points = {"points": [[0.1, 0, 0], [0.2, 0.01, 0], [0.2, 0.01, 0], [0.3, 0, 0]]}
    line = validate_fails(capsys, str(write_case(tmp_path, {"path.segments": [points]})))
    assert "case.yaml: path.segments[0].points[2]: " in line and "repeats point 1" in line


def test_bounds_with_min_above_max(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    line = validate_fails(capsys, str(write_case(tmp_path, {"placement": {"x": [0.5, -0.5]}})))
    assert "case.yaml: placement.x: expected [min, max] with min ≤ max, got [0.5, -0.5]" in line


@pytest.mark.parametrize("reach", [[0.8, 0.2], [-0.1, 0.8]])
def test_reach_min_above_max_or_negative(
    capsys: pytest.CaptureFixture[str], tmp_path: Path, reach: list[float]
) -> None:
    line = validate_fails(capsys, str(write_case(tmp_path, {"placement": {"reach": reach}})))
    assert "case.yaml: placement.reach: expected [min, max] distances with 0 ≤ min ≤ max" in line


def test_weights_of_the_wrong_length(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    file = write_case(tmp_path, {"objective": {"weights": [0.3, 0.2, 0.2, 0.1, 0.1]}})
    line = validate_fails(capsys, str(file))
    assert (
        "case.yaml: objective.weights: expected 6 weights (one per joint of puma560), got 5" in line
    )


def test_negative_weight(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    file = write_case(tmp_path, {"objective": {"weights": [0.3, 0.2, -0.2, 0.1, 0.1, 0.1]}})
    line = validate_fails(capsys, str(file))
    assert "case.yaml: objective.weights[2]: expected a number ≥ 0, got -0.2" in line


def test_unknown_robot_name(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    line = validate_fails(capsys, str(write_case(tmp_path, {"robot": "puma650"})))
    assert "case.yaml: robot: unknown robot 'puma650': use one of abb_irb1600, " in line
    assert "puma560, ur10e, ur5, ur5e, yaskawa_sia10d or a path to a robot file" in line


def test_missing_case_file(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    line = validate_fails(capsys, str(tmp_path / "nowhere.yaml"))
    assert line == f"{tmp_path / 'nowhere.yaml'}: case file not found"


@pytest.mark.parametrize("kind", ["directory", "binary"])
def test_unreadable_case_file(
    capsys: pytest.CaptureFixture[str], tmp_path: Path, kind: str
) -> None:
    file = tmp_path / "case.yaml"
    if kind == "directory":
        file.mkdir()
    else:
        file.write_bytes(b"name: \xff\xfe\n")
    line = validate_fails(capsys, str(file))
    assert "case.yaml" in line and ("is a directory" in line or "not UTF-8" in line)


def test_missing_robot_file(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    line = validate_fails(capsys, str(write_case(tmp_path, {"robot": "robots/arm.yaml"})))
    assert f"case.yaml: robot: robot file {str(tmp_path / 'robots/arm.yaml')!r} not found" in line


def test_missing_points_file(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    file = write_case(tmp_path, {"path.segments": [{"points": {"file": "seam.csv"}}]})
    line = validate_fails(capsys, str(file))
    assert "case.yaml: path.segments[0].points.file: points file" in line
    assert "seam.csv' not found" in line


def test_bad_row_in_points_file(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    (tmp_path / "seam.csv").write_text("0.1,0,0\n0.2,zero,0\n", encoding="utf-8")
    file = write_case(tmp_path, {"path.segments": [{"points": {"file": "seam.csv"}}]})
    line = validate_fails(capsys, str(file))
    assert (
        "seam.csv: line 2: expected three finite numbers x,y,z separated by commas, got 'zero'"
        " in '0.2,zero,0'"
    ) in line


def test_yaml_syntax_error(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    file = tmp_path / "case.yaml"
    file.write_text(
        "name: broken\npath:\n  start: [0, 0, 0\ntask: {rated_speed: 0.1}\n", encoding="utf-8"
    )
    line = validate_fails(capsys, str(file))
    assert "case.yaml: YAML syntax error at line 4, column 5: expected ',' or ']'" in line
    assert "(while parsing a flow sequence at line 3, column 10)" in line


def test_duplicate_key(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    file = write_case(tmp_path)
    file.write_text(file.read_text() + "name: again\n")
    line = validate_fails(capsys, str(file))
    assert "case.yaml: YAML syntax error at line" in line and "duplicate key 'name'" in line


@pytest.mark.parametrize(
    ("key", "missing"), [("name", "name"), ("task", "task.rated_speed"), ("path", "path.start")]
)
def test_missing_required_key(
    capsys: pytest.CaptureFixture[str], tmp_path: Path, key: str, missing: str
) -> None:
    data = copy.deepcopy(BASE)
    if key == "name":
        del data["name"]
    elif key == "task":
        data["task"] = {"tolerance": 0.001}
    else:
        del data["path"]["start"]
    file = tmp_path / "case.yaml"
    file.write_text(yaml.safe_dump(data), encoding="utf-8")
    assert f"case.yaml: {missing}: required key is missing" in validate_fails(capsys, str(file))


def test_empty_segments(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    line = validate_fails(capsys, str(write_case(tmp_path, {"path.segments": []})))
    assert "case.yaml: path.segments: expected at least 1 entry, got 0" in line


def test_segment_with_two_kinds(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    segment = {"line": {"to": [1, 0, 0]}, "points": [[1, 1, 0], [2, 1, 0]]}
    line = validate_fails(capsys, str(write_case(tmp_path, {"path.segments": [segment]})))
    assert (
        "case.yaml: path.segments[0]: expected exactly one of line, arc, points, got line, points"
        in line
    )


def test_vector_of_the_wrong_length(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    line = validate_fails(capsys, str(write_case(tmp_path, {"path.start": [0, 0]})))
    assert "case.yaml: path.start: expected 3 numbers [x, y, z], got 2: [0, 0]" in line


def test_robot_file_with_bad_position_limits(
    capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    text = robot_to_yaml(puma560()).replace(
        "position: [-2.356194490192345, 2.356194490192345]", "position: [1.0, -1.0]", 1
    )
    (tmp_path / "arm.yaml").write_text(text, encoding="utf-8")
    line = validate_fails(capsys, str(write_case(tmp_path, {"robot": "arm.yaml"})))
    assert (
        "arm.yaml: joints[1].position: expected [min, max] with min < max, got [1.0, -1.0]" in line
    )


@pytest.mark.parametrize(
    ("limit", "value"), [("velocity", "0.0"), ("acceleration", "-12.0"), ("jerk", "0")]
)
def test_robot_file_with_non_positive_limits(
    capsys: pytest.CaptureFixture[str], tmp_path: Path, limit: str, value: str
) -> None:
    old = {
        "velocity": "velocity: 10.0",
        "acceleration": "acceleration: 12.0",
        "jerk": "jerk: 40.0",
    }[limit]
    text = robot_to_yaml(puma560()).replace(old, f"{limit}: {value}", 1)
    (tmp_path / "arm.yaml").write_text(text, encoding="utf-8")
    line = validate_fails(capsys, str(write_case(tmp_path, {"robot": "arm.yaml"})))
    assert f"arm.yaml: joints[1].{limit}: expected a number > 0, got {value}" in line


@pytest.mark.parametrize("tolerance", [1e-300, 5e-7, 0, -0.001])
def test_a_tolerance_below_a_micrometre_is_one_line(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], tolerance: float
) -> None:
    """A tolerance of 1e-300 m validated and then asked ``plan`` for some 23 GB."""
    file = write_case(tmp_path, {"task.tolerance": tolerance})
    line = validate_fails(capsys, str(file))
    assert line == f"{file}: task.tolerance: expected a number ≥ 1e-06, got {tolerance}"


def test_a_micrometre_tolerance_loads() -> None:
    text = (CASES / "paper-corner.yaml").read_text()
    text = text.replace("tolerance: 0.001 ", "tolerance: 1.0e-6 ")
    assert "1.0e-6" in text
    assert load_case_text(text, "micro.yaml", CASES).task.tolerance == 1e-6
