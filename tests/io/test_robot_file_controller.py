"""The ``controller:`` block of robot files (DH and URDF forms)."""

from __future__ import annotations

import typing
from pathlib import Path

import numpy as np
import pytest

from trackplan.errors import CaseError
from trackplan.frames import pose_matrix, rpy_matrix
from trackplan.io.robot_file import LIBRARY_DIR, load_robot, load_robot_text, robot_to_yaml
from trackplan.io.robot_schema import ControllerModel
from trackplan.robots.builtin import puma560
from trackplan.robots.controller import VENDORS

FANUC_LIKE = """
controller:
  vendor: fanuc
  signs: [1, 1, -1, 1, 1, 1]
  offsets: [0, 0, 0.5, 0, 0, 0]
  coupling: {joint: 3, driver: 2, factor: -1}
  world: {xyz: [0, 0, 0.525], rpy: [0, 0, 3.141592653589793]}
  cycle: 0.002
  source: "a test: not FANUC's numbers"
"""


def _puma_text(block: str) -> str:
    return robot_to_yaml(puma560()) + block


def test_a_dh_robot_reads_its_controller_block() -> None:
    robot = load_robot_text(_puma_text(FANUC_LIKE))
    convention = robot.controller
    assert convention is not None and robot.convention is convention
    assert convention.vendor == "fanuc" and convention.cycle == 0.002
    np.testing.assert_array_equal(convention.signs, [1, 1, -1, 1, 1, 1])
    np.testing.assert_array_equal(convention.offsets, [0, 0, 0.5, 0, 0, 0])
    assert convention.coupling == (2, 1, -1.0)  # 0-based inside
    world = pose_matrix(np.array([0, 0, 0.525]), rpy_matrix(np.array([0, 0, np.pi])))
    np.testing.assert_allclose(convention.world, world, rtol=0, atol=1e-15)
    assert convention.source == "a test: not FANUC's numbers"
    # θ3 = −q3 + 0.5 − q2
    theta = convention.to_controller(np.array([0.1, 0.2, 0.3, 0.4, 0.5, 0.6]))
    assert theta[2] == pytest.approx(-0.3 + 0.5 - 0.2, abs=1e-15)


def test_the_defaults_are_the_identity() -> None:
    robot = load_robot_text(_puma_text("controller: {vendor: kuka}\n"))
    assert robot.controller is not None and robot.controller.vendor == "kuka"
    assert robot.controller.is_identity and robot.controller.cycle is None
    assert load_robot_text(_puma_text("")).controller is None


def test_the_vendors_of_the_schema_are_the_conventions() -> None:
    vendor = ControllerModel.model_fields["vendor"].annotation
    assert typing.get_args(vendor) == VENDORS


@pytest.mark.parametrize(
    ("block", "key", "message"),
    [
        ("{vendor: yaskawa}", "controller.vendor", "'kuka', 'abb', 'fanuc', 'ur' or 'generic'"),
        ("{vendor: abb, signs: [1, 1, 1]}", "controller.signs", "expected 6 entries"),
        ("{vendor: abb, signs: [1, 1, 2, 1, 1, 1]}", "controller.signs[2]", "1 or -1, got 2"),
        ("{vendor: abb, offsets: [0, 0]}", "controller.offsets", "expected 6 entries"),
        (
            "{vendor: abb, coupling: {joint: 7, driver: 2, factor: 1}}",
            "controller.coupling.joint",
            "expected a joint number 1..6, got 7",
        ),
        (
            "{vendor: abb, coupling: {joint: 3, driver: 0, factor: 1}}",
            "controller.coupling.driver",
            "expected a joint number 1..6, got 0",
        ),
        (
            "{vendor: abb, coupling: {joint: 3, driver: 3, factor: 1}}",
            "controller.coupling.driver",
            "the driver must differ from joint 3",
        ),
        (
            "{vendor: abb, coupling: {joint: 3, driver: 2, factor: .inf}}",
            "controller.coupling.factor",
            "finite",
        ),
        ("{vendor: abb, cycle: 0}", "controller.cycle", "expected a number > 0, got 0"),
        ("{vendor: abb, zero: 1}", "controller.zero", ""),
    ],
)
def test_a_bad_controller_block_is_one_line(block: str, key: str, message: str) -> None:
    with pytest.raises(CaseError) as error:
        load_robot_text(_puma_text(f"controller: {block}\n"), file="arm.yaml")
    text = str(error.value)
    assert "\n" not in text and text.startswith(f"arm.yaml: {key}"), text
    assert message in text


def test_the_controller_block_round_trips() -> None:
    robot = load_robot_text(_puma_text(FANUC_LIKE))
    text = robot_to_yaml(robot)
    assert "\ncontroller:\n  vendor: fanuc\n  signs: [1.0, 1.0, -1.0, 1.0, 1.0, 1.0]\n" in text
    again = load_robot_text(text).controller
    assert again is not None and robot.controller is not None
    for key in ("vendor", "coupling", "cycle", "source"):
        assert getattr(again, key) == getattr(robot.controller, key)
    np.testing.assert_array_equal(again.signs, robot.controller.signs)
    np.testing.assert_array_equal(again.offsets, robot.controller.offsets)
    np.testing.assert_allclose(again.world, robot.controller.world, rtol=0, atol=1e-15)
    plain = load_robot_text(robot_to_yaml(load_robot_text(_puma_text("controller: {vendor: ur}"))))
    assert plain.controller is not None and plain.controller.is_identity
    assert "signs" not in robot_to_yaml(plain)  # defaults are not written


def test_a_urdf_robot_file_reads_its_controller_block(tmp_path: Path) -> None:
    library = LIBRARY_DIR / "kuka_kr6_r700_sixx.yaml"
    text = library.read_text().replace(
        "urdf: kuka_kr6_r700_sixx.urdf", f"urdf: {LIBRARY_DIR / 'kuka_kr6_r700_sixx.urdf'}"
    )
    file = tmp_path / "kr6.yaml"
    file.write_text(text.split("\ncontroller:")[0] + FANUC_LIKE.replace("fanuc", "kuka"))
    robot = load_robot(file)
    assert robot.controller is not None and robot.controller.coupling == (2, 1, -1.0)
    file.write_text(text.split("\ncontroller:")[0] + "\ncontroller: {vendor: kuka, signs: [1]}\n")
    with pytest.raises(CaseError, match=r"controller\.signs: expected 6 entries"):
        load_robot(file)
