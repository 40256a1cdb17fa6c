"""Robot files: round trips through YAML, the example file, and robot names in case files."""

from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np
import pytest

from tests.conftest import replace_dh
from trackplan.cli import main
from trackplan.errors import CaseError
from trackplan.frames import pose_matrix, rpy_matrix
from trackplan.io.robot_file import (
    builtin_robot,
    is_robot_file,
    load_robot,
    load_robot_spec,
    load_robot_text,
    robot_to_yaml,
)
from trackplan.robots.builtin import DH_ROBOTS, puma560
from trackplan.robots.model import DH_COLUMNS, Robot

ROBOTS = Path(__file__).resolve().parents[2] / "robots"
ARRAYS = ("dh", "origins", "axes", "T_tip", "q_min", "q_max", "v_max", "a_max", "j_max")


def assert_same_robot(actual: Robot, expected: Robot, atol: float = 0.0) -> None:
    """Same name, source, DH table, limits and tool."""
    assert (actual.name, actual.source) == (expected.name, expected.source)
    for key in ARRAYS:
        np.testing.assert_array_equal(getattr(actual, key), getattr(expected, key), err_msg=key)
    np.testing.assert_allclose(actual.T_flange_tool, expected.T_flange_tool, rtol=0, atol=atol)


@pytest.mark.parametrize("name", sorted(DH_ROBOTS))
def test_builtin_robots_round_trip_exactly(tmp_path: Path, name: str) -> None:
    robot = builtin_robot(name)
    file = tmp_path / f"{name}.yaml"
    file.write_text(robot_to_yaml(robot), encoding="utf-8")
    assert_same_robot(load_robot(file), robot)


def test_robot_with_a_tool_round_trips(rng: np.random.Generator) -> None:
    base = puma560()
    for _ in range(20):
        xyz = rng.uniform(-0.2, 0.2, 3)
        rpy = rng.uniform([-np.pi, -np.pi / 2, -np.pi], [np.pi, np.pi / 2, np.pi])
        robot = replace_dh(base, T_flange_tool=pose_matrix(xyz, rpy_matrix(rpy)))
        assert_same_robot(load_robot_text(robot_to_yaml(robot)), robot, atol=1e-12)


def test_example_robot_file_is_the_builtin_puma560() -> None:
    file = ROBOTS / "puma560.yaml"
    assert file.read_text(encoding="utf-8") == robot_to_yaml(puma560())
    assert_same_robot(load_robot(file), puma560())


def test_tool_and_offset_default_to_zero() -> None:
    robot = load_robot_text(
        "name: one\njoints:\n  - {d: 0.1, a: 0.2, alpha: 0, position: [-1, 1],"
        " velocity: 1, acceleration: 2, jerk: 3}\n"
    )
    assert robot.n_dof == 1 and not robot.has_tool
    np.testing.assert_array_equal(robot.dh[:, DH_COLUMNS.index("offset")], [0.0])
    np.testing.assert_array_equal([robot.q_min[0], robot.q_max[0]], [-1.0, 1.0])


def test_robot_names_and_files_in_case_files(tmp_path: Path) -> None:
    assert not is_robot_file("puma560")
    assert is_robot_file("arm.yaml") and is_robot_file("robots/arm") and is_robot_file("ARM.YML")
    assert load_robot_spec("UR5", tmp_path).name == "ur5"
    (tmp_path / "robots").mkdir()
    (tmp_path / "robots" / "arm.yaml").write_text(robot_to_yaml(puma560()), encoding="utf-8")
    assert_same_robot(load_robot_spec("robots/arm.yaml", tmp_path), puma560())
    with pytest.raises(CaseError) as error:
        load_robot_spec("kuka", tmp_path, case_file="case.yaml")
    assert (error.value.file, error.value.key) == ("case.yaml", "robot")


def test_errors_inside_a_robot_file_name_that_file(tmp_path: Path) -> None:
    file = tmp_path / "arm.yaml"
    file.write_text(robot_to_yaml(puma560()).replace("jerk: 20.0}", "jerk: 20.0, weight: 3}", 1))
    with pytest.raises(CaseError) as error:
        load_robot(file)
    assert error.value.file == str(file)
    assert error.value.key == "joints[3].weight"
    assert "unknown key" in error.value.message


PUMA_YAML = robot_to_yaml(puma560())


@pytest.mark.parametrize(
    ("old", "new", "message"),
    [
        # a link is a number or a name: the message names the key, not pydantic's union member
        ("link: 2,", "link: 2.5,", "collision[3].link: expected a link number (0 = base, i ="),
        ("link: 2,", "link: true,", "collision[3].link: expected a link number"),
        ("link: 2,", "link: '',", "collision[3].link: expected a link number"),
        ("link: 2,", "link: [2],", "collision[3].link: expected a link number"),
        # physical values in their ranges (docs/files.md#ranges)
        ("{d: 0.0, a: 0.0,", "{d: 1e300, a: 0.0,", "joints[0].d: expected a number ≤ 1000, got"),
        ("a: 0.4318,", "a: -1e300,", "joints[1].a: expected a number ≥ -1000, got -1e+300"),
        ("alpha: 0.0,", "alpha: 1e300,", "joints[1].alpha: expected a number ≤ 1000, got"),
        ("velocity: 8.0,", "velocity: 1e300,", "joints[0].velocity: expected a number ≤ 1e+06"),
        ("jerk: 30.0}", "jerk: 1e7}", "joints[0].jerk: expected a number ≤ 1e+06, got 10000000"),
        ("jerk: 30.0}", "jerk: 1e-300}", "joints[0].jerk: expected a number ≥ 0.001, got 1e-300"),
        ("velocity: 8.0,", "velocity: 0,", "joints[0].velocity: expected a number > 0, got 0"),
        ("radius: 0.09}", "radius: 1e300}", "collision[0].radius: expected a number ≤ 1000"),
    ],
)
def test_bad_robot_file_values_are_one_line(
    capsys: pytest.CaptureFixture[str], tmp_path: Path, old: str, new: str, message: str
) -> None:
    assert old in PUMA_YAML
    file = tmp_path / "arm.yaml"
    file.write_text(PUMA_YAML.replace(old, new, 1), encoding="utf-8")
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # no numpy RuntimeWarning on the way
        code = main(["robots", str(file)])
    err = capsys.readouterr().err
    assert code == 2 and err.count("\n") == 1, err
    assert err.startswith(f"{file}: {message}"), err
