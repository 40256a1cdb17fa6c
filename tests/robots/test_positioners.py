"""Built-in positioners and positioner files: the library's chains against their sources
(an independent rotation of the published origins and axes), what a positioner file may
not be, the ``trackplan positioners`` command and the Python API."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import yaml
from scipy.spatial.transform import Rotation

import trackplan
from tests.io.test_case_file import validate_fails, write_case
from trackplan.cell._kernels import segment_segment
from trackplan.cli import main
from trackplan.errors import CaseError
from trackplan.io.case_file import load_case
from trackplan.io.positioner_file import (
    MAX_POSITIONER_AXES,
    builtin_positioner,
    load_positioner,
    positioner_names,
)
from trackplan.io.robot_file import builtin_names, builtin_robot, robot_to_yaml
from trackplan.robots.kinematics import forward_kinematics, joint_frames

LIBRARY = ("head-tailstock", "one-axis-turntable", "skyhook-500", "two-axis-500")
# the acceleration time of each: the MH(T)185 manual's 0.3 s, else the robots' assumed 0.25 s
ACCELERATION_TIME = {"head-tailstock": 0.3}


def rotation(axis: list[float], angle: float) -> np.ndarray:
    """The rotation by ``angle`` about the unit ``axis`` (scipy), shape (3, 3)."""
    return Rotation.from_rotvec(np.array(axis, dtype=float) * angle).as_matrix()


# --------------------------------------------------------------------------- the library


def test_the_library_lists_the_four_positioners_and_no_robot_among_them() -> None:
    assert positioner_names() == LIBRARY
    assert not set(LIBRARY) & set(builtin_names())


@pytest.mark.parametrize("name", LIBRARY)
def test_each_builtin_positioner_states_its_source_and_assumptions(name: str) -> None:
    chain = builtin_positioner(name)
    assert chain.name == name and 1 <= chain.n_dof <= MAX_POSITIONER_AXES
    assert "ros-industrial/motoman" in chain.source
    assert any("jerk" in note and "assumed" in note for note in chain.assumptions)
    # the rated velocity in the acceleration time (assumed 0.25 s unless published), the
    # acceleration in 0.1 s (assumed)
    np.testing.assert_allclose(
        chain.a_max, chain.v_max / ACCELERATION_TIME.get(name, 0.25), rtol=1e-4
    )
    np.testing.assert_allclose(chain.j_max, chain.a_max / 0.1, rtol=1e-4)
    assert chain.collision is not None and len(chain.collision) >= 10
    assert not chain.has_tool


def test_two_axis_500_is_the_motopos_d500_of_its_source() -> None:
    chain = builtin_positioner("two-axis-500")
    # motopos_d500_macro.xacro: joint_1 ±2.3561 rad at 1.3962 rad/s, joint_2 ±3.4906 at 2.7925
    np.testing.assert_array_equal(chain.q_max, [2.3561, 3.4906])
    np.testing.assert_array_equal(chain.q_min, [-2.3561, -3.4906])
    np.testing.assert_array_equal(chain.v_max, [1.3962, 2.7925])
    for tilt, turn in [(0.0, 0.0), (np.pi / 2, 0.0), (0.4, -1.1), (-2.0, 3.0)]:
        # joint_1 at 0.380 about -y, joint_2 at its origin about -z, tool0 0.150 along z
        R = rotation([0, -1, 0], tilt) @ rotation([0, 0, -1], turn)
        expected = np.eye(4)
        expected[:3, :3] = R
        expected[:3, 3] = [0, 0, 0.380] + R @ [0, 0, 0.150]
        T = forward_kinematics(chain, np.array([tilt, turn]))
        np.testing.assert_allclose(T, expected, atol=1e-12)
    # the table face 0.530 m up at zero; tilted a quarter turn, it faces -x at the axis height
    np.testing.assert_allclose(
        forward_kinematics(chain, np.array([np.pi / 2, 0.0]))[:3, 2:],
        [[-1, -0.15], [0, 0], [0, 0.38]],
        atol=1e-12,
    )


@pytest.mark.parametrize("name", ["two-axis-500", "one-axis-turntable"])
def test_the_d500s_drives_have_the_motopos_data_sheets_ranges_and_speeds(name: str) -> None:
    chain = builtin_positioner(name)
    assert "MOTOPOS-D500B-A00" in chain.source and "KAE-C945-431G" in chain.source
    # data sheet p. 7, MOTOPOS-D500B-A00: tilted axis ±135° at 80 °/s, rotation ±200° at 160 °/s
    # (the xacro rounds the radians to 4 decimals: 0.01° at most)
    sheet = {"tilt": (135.0, 80.0), "rotate": (200.0, 160.0)}
    for i, joint in enumerate(chain.joint_names):
        np.testing.assert_allclose(np.degrees(chain.q_max[i]), sheet[joint][0], atol=0.01)
        np.testing.assert_allclose(np.degrees(-chain.q_min[i]), sheet[joint][0], atol=0.01)
        np.testing.assert_allclose(np.degrees(chain.v_max[i]), sheet[joint][1], atol=0.01)


def test_head_tailstock_has_the_mh185_headstocks_range_and_speed() -> None:
    chain = builtin_positioner("head-tailstock")
    assert "motoman_motopos_mh185_rotisserie_support" in chain.source
    # manual 168961-1CD, Table 3-1: 12.4 rpm, rated acceleration time 0.3 s; the URDF of
    # pull request 317: joint_1 within ±2π rad
    np.testing.assert_allclose(chain.q_max, [2 * np.pi], atol=5e-5)
    np.testing.assert_allclose(chain.q_min, [-2 * np.pi], atol=5e-5)
    np.testing.assert_allclose(chain.v_max, [12.4 / 60 * 2 * np.pi], atol=5e-5)
    np.testing.assert_allclose(np.degrees(chain.v_max), [74.4], atol=5e-3)
    np.testing.assert_allclose(chain.a_max, [12.4 / 60 * 2 * np.pi / 0.3], rtol=1e-4)
    # the faceplate: 0.100 m out along the horizontal spindle (+x), 0.900 m up, z along +x
    for angle in (0.0, 1.2, -3.0):
        R = rotation([1, 0, 0], angle) @ rotation([0, 1, 0], np.pi / 2)
        expected = np.eye(4)
        expected[:3, :3] = R
        expected[:3, 3] = [0.100, 0, 0.900]
        T = forward_kinematics(chain, np.array([angle]))
        np.testing.assert_allclose(T, expected, atol=1e-12)


def test_skyhook_500_is_the_motopos_d500b_c00_of_its_data_sheet() -> None:
    chain = builtin_positioner("skyhook-500")
    assert chain.joint_names == ("tilt", "rotate")
    assert "MOTOPOS-D500B-C00" in chain.source and "KAE-C945-431G" in chain.source
    # data sheet p. 8: tilted axis ±180° at 1.92 rad/s, rotation axis ±360° at 2.18 rad/s
    np.testing.assert_allclose(chain.q_max, np.radians([180.0, 360.0]), atol=5e-5)
    np.testing.assert_allclose(chain.q_min, np.radians([-180.0, -360.0]), atol=5e-5)
    np.testing.assert_allclose(chain.v_max, [1.92, 2.18], atol=1e-12)
    # (its °/s are rounded: 2.18 rad/s is 124.9 °/s, within 0.1 of the 125 it prints)
    np.testing.assert_allclose(np.degrees(chain.v_max), [110.0, 125.0], atol=0.1)
    for tilt, turn in [(0.0, 0.0), (np.pi / 2, 0.0), (0.4, -1.1), (-2.9, 5.0)]:
        # drawing: tilted axis +x 0.665 m up; table face 0.390 m below it, turning about its z
        R = rotation([1, 0, 0], tilt) @ rotation([0, 0, 1], turn)
        expected = np.eye(4)
        expected[:3, :3] = R
        expected[:3, 3] = [0, 0, 0.665] + rotation([1, 0, 0], tilt) @ [0, 0, -0.390]
        T = forward_kinematics(chain, np.array([tilt, turn]))
        np.testing.assert_allclose(T, expected, atol=1e-12)
    # at zero the table faces up 0.275 m above the floor; tilted a quarter turn about +x its
    # face looks along +y at the axis height, 0.390 m from the axis
    np.testing.assert_allclose(
        forward_kinematics(chain, np.zeros(2))[:3, 2:], [[0, 0], [0, 0], [1, 0.275]], atol=1e-12
    )
    np.testing.assert_allclose(
        forward_kinematics(chain, np.array([np.pi / 2, 0.0]))[:3, 2:],
        [[0, 0], [-1, 0.39], [0, 0.665]],
        atol=1e-12,
    )


def base_table_gaps(name: str, n_tilt: int, n_turn: int) -> list[float]:
    """Gaps (m) between a built-in positioner's base capsules (frame 0) and its table's
    (frame 2) on an n_tilt × n_turn grid over both axis ranges."""
    chain = builtin_positioner(name)
    capsules = chain.collision
    assert capsules is not None
    base = np.flatnonzero(capsules.frame == 0)
    table = np.flatnonzero(capsules.frame == 2)
    gaps = []
    for tilt in np.linspace(chain.q_min[0], chain.q_max[0], n_tilt):
        for turn in np.linspace(chain.q_min[1], chain.q_max[1], n_turn):
            frames = joint_frames(chain, np.array([tilt, turn]))
            ends = np.einsum("kij,kpj->kpi", frames[capsules.frame, :3, :3], capsules.segment)
            ends += frames[capsules.frame, :3, 3][:, None, :]
            gaps += [
                segment_segment(*ends[i], *ends[j]) - capsules.radius[i] - capsules.radius[j]
                for i in base
                for j in table
            ]
    return gaps


def test_the_skyhook_table_stays_clear_of_its_drive_housing_over_the_axis_ranges() -> None:
    gaps = base_table_gaps("skyhook-500", 13, 9)
    assert min(gaps) > 0.45  # docs/positioner.md: 0.52 m at the closest


@pytest.mark.parametrize(
    ("name", "axis", "origin", "flange_z"),
    [
        ("one-axis-turntable", [0, 0, 1], [0, 0, 0.380], [0, 0, 1]),
        ("head-tailstock", [1, 0, 0], [0, 0, 0.900], [1, 0, 0]),
    ],
)
def test_a_one_axis_positioner_turns_its_flange_about_its_axis(
    name: str, axis: list[float], origin: list[float], flange_z: list[float]
) -> None:
    chain = builtin_positioner(name)
    zero = forward_kinematics(chain, np.zeros(1))
    np.testing.assert_allclose(zero[:3, 2], flange_z, atol=1e-12)
    for angle in (0.7, -2.5):
        T = forward_kinematics(chain, np.array([angle]))
        R = rotation(axis, angle)
        np.testing.assert_allclose(T[:3, :3], R @ zero[:3, :3], atol=1e-12)
        np.testing.assert_allclose(T[:3, 3], origin + R @ (zero[:3, 3] - origin), atol=1e-12)


def test_a_builtin_positioner_name_is_not_a_robot() -> None:
    with pytest.raises(CaseError, match="unknown positioner 'puma560'"):
        builtin_positioner("puma560")


# --------------------------------------------------------------------------- positioner files

URDF = """<?xml version="1.0"?>
<robot name="small">
  <link name="base_link"/>
  {links}
  <link name="tool0"/>
  {joints}
  <joint name="flange" type="fixed">
    <parent link="link_{n}"/><child link="tool0"/>
    <origin xyz="0 0 0.1" rpy="0 0 0"/>
  </joint>
</robot>
"""


def write_positioner(folder: Path, axes: int = 1, **changes: object) -> Path:
    """A positioner file and its URDF: ``axes`` revolute joints about z, 0.2 m apart."""
    links = "\n".join(f'<link name="link_{i + 1}"/>' for i in range(axes))
    joints = "\n".join(
        f'<joint name="j{i + 1}" type="revolute">'
        f'<parent link="{"base_link" if i == 0 else f"link_{i}"}"/><child link="link_{i + 1}"/>'
        '<origin xyz="0 0 0.2" rpy="0 0 0"/><axis xyz="0 0 1"/>'
        '<limit lower="-3" upper="3" effort="100" velocity="2"/></joint>'
        for i in range(axes)
    )
    (folder / "small.urdf").write_text(
        URDF.format(links=links, joints=joints, n=axes), encoding="utf-8"
    )
    data: dict[str, object] = {
        "name": "small",
        "urdf": "small.urdf",
        "tip_link": "tool0",
        "limits": {"acceleration": [8.0] * axes, "jerk": [80.0] * axes},
        "source": "a test",
        "collision": [{"link": "link_1", "from": [0, 0, 0], "to": [0, 0, 0.1], "radius": 0.1}],
    }
    data.update(changes)
    file = folder / "small.yaml"
    file.write_text(yaml.safe_dump(data), encoding="utf-8")
    return file


def test_a_positioner_file_is_read_by_the_robot_file_reader(tmp_path: Path) -> None:
    chain = load_positioner(write_positioner(tmp_path, axes=2))
    assert chain.joint_names == ("j1", "j2") and chain.source == "a test"
    np.testing.assert_array_equal(chain.a_max, [8.0, 8.0])
    np.testing.assert_array_equal(chain.j_max, [80.0, 80.0])
    np.testing.assert_allclose(forward_kinematics(chain, np.zeros(2))[:3, 3], [0, 0, 0.5])
    assert chain.collision is not None and len(chain.collision) == 1


def test_a_case_names_a_positioner_file_relative_to_itself(tmp_path: Path) -> None:
    (tmp_path / "cell").mkdir()
    write_positioner(tmp_path / "cell")
    case = load_case(write_case(tmp_path, {"positioner": {"model": "cell/small.yaml"}}))
    assert case.positioner is not None and case.positioner.chain.joint_names == ("j1",)
    assert case.positioner.model == "cell/small.yaml"


@pytest.mark.parametrize(
    ("make", "expected"),
    [
        (lambda d: write_positioner(d, axes=4), "tip_link: a positioner has 1 to 3 axes, this"),
        (
            lambda d: write_positioner(d, tool={"xyz": [0, 0, 0.1], "rpy": [0, 0, 0]}),
            "tool: a positioner has no tool",
        ),
        (
            lambda d: write_positioner(d, limits={"acceleration": [8.0]}),
            "a URDF gives no jerk limits",
        ),
        (
            lambda d: write_positioner(d, limits={"acceleration": [8.0, 8.0], "jerk": [80.0]}),
            "limits.acceleration: expected 1 entries",
        ),
    ],
)
def test_what_a_positioner_cannot_be_is_one_line(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], make: object, expected: str
) -> None:
    file = make(tmp_path)  # type: ignore[operator]
    with pytest.raises(CaseError, match=None) as raised:
        load_positioner(file)
    assert expected in raised.value.one_line()
    case = write_case(tmp_path, {"positioner": {"model": "small.yaml"}})
    line = validate_fails(capsys, str(case))
    assert expected in line and str(file) in line, line


def test_assume_limits_fills_a_positioners_missing_limits(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    write_positioner(tmp_path, limits={})
    case = write_case(tmp_path, {"positioner": {"model": "small.yaml"}})
    chain = load_case(case, assume_limits=True).positioner.chain  # type: ignore[union-attr]
    np.testing.assert_allclose(chain.a_max, [2.0 / 0.25], rtol=1e-12)
    np.testing.assert_allclose(chain.j_max, [2.0 / 0.25 / 0.1], rtol=1e-12)
    assert main(["validate", "--assume-limits", str(case)]) == 0
    assert main(["positioners", "--assume-limits", str(tmp_path / "small.yaml")]) == 0
    assert "assumption: acceleration" in capsys.readouterr().out


def test_a_dh_robot_file_or_a_bare_urdf_is_no_positioner(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    (tmp_path / "arm.yaml").write_text(robot_to_yaml(builtin_robot("puma560")), encoding="utf-8")
    case = write_case(tmp_path, {"positioner": {"model": "arm.yaml"}})
    line = validate_fails(capsys, str(case))
    assert "arm.yaml: urdf: a positioner file points at a URDF" in line, line
    write_positioner(tmp_path)
    case = write_case(tmp_path, {"positioner": {"model": "small.urdf"}})
    line = validate_fails(capsys, str(case))
    assert "positioner.model: small.urdf: a positioner is a positioner file (.yaml)" in line
    with pytest.raises(CaseError, match="not a bare URDF"):
        load_positioner(tmp_path / "small.urdf")


def test_a_missing_positioner_file_is_reported_at_the_case_key(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    case = write_case(tmp_path, {"positioner": {"model": "nowhere/pos.yaml"}})
    line = validate_fails(capsys, str(case))
    assert f"{case}: positioner.model: " in line and "pos.yaml" in line, line


# --------------------------------------------------------------------------- CLI and API


def test_the_positioners_command_lists_the_library(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["positioners"]) == 0
    out = capsys.readouterr().out
    for name in LIBRARY:
        assert name in out
    assert "[-135, 135], [-200, 200]" in out and "80, 160" in out


def test_the_positioners_command_shows_one(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    assert main(["positioners", "two-axis-500"]) == 0
    out = capsys.readouterr().out
    assert "tilt" in out and "rotate" in out
    assert "flange (carrier frame) from the last axis: xyz 0 0 0.15 m" in out
    assert "assumption: acceleration and jerk limits are assumed" in out
    assert main(["positioners", str(write_positioner(tmp_path))]) == 0
    assert "small (1 joints)" in capsys.readouterr().out


def test_the_positioners_command_refuses_an_unknown_name(
    capsys: pytest.CaptureFixture[str],
) -> None:
    assert main(["positioners", "nope"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "positioner.model: unknown positioner 'nope'" in err[0], err


def test_the_api_serves_positioners(tmp_path: Path) -> None:
    chain = trackplan.builtin_positioner("two-axis-500")
    assert chain.joint_names == ("tilt", "rotate")
    assert trackplan.load_positioner(write_positioner(tmp_path)).name == "small"


def test_the_d500_foot_stays_clear_of_its_table_over_the_axis_ranges() -> None:
    gaps = base_table_gaps("two-axis-500", 19, 13)
    assert min(gaps) > 0.02  # docs/positioner.md: 2.6 cm at the closest
