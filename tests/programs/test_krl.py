"""KRL export: programs built by hand, printed by the writer, read back by the test parser."""

from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from tests.programs.krl_parser import abc_rotation, parse_krl
from tests.programs.krl_reference import status_turn_reference
from tests.programs.parsed import ParsedProgram, ParsedTarget
from tests.programs.programs import joint_form, joint_move, make_target, program, vendor_robot
from tests.programs.roundtrip import (
    ANGLE_TOLERANCE,
    POSITION_TOLERANCE,
    assert_matches_plan,
    assert_same_targets,
    frame_difference,
    rotation_angle,
    target_pairs,
)
from tests.programs.stand_in import stand_in
from trackplan.errors import CaseError
from trackplan.frames import placement_transform
from trackplan.io.robot_file import builtin_robot
from trackplan.programs.model import (
    CircularMove,
    LinearMove,
    Program,
    Section,
    SplineMove,
    Target,
)
from trackplan.robots.builtin import puma560
from trackplan.robots.controller import ControllerConvention
from trackplan.robots.kinematics import forward_kinematics
from trackplan.robots.model import Robot
from trackplan.writers.krl import MAX_NAME, KrlWriter, krl_name, render_krl
from trackplan.writers.krl_config import abc_from_matrix, frame_values, status_turn

KUKA_SOURCE = "ros-industrial kuka_experimental: q = A * pi/180, base_link = $ROBROOT"


def kuka(name: str = "kuka_kr6_r700_sixx") -> Robot:
    """A KUKA robot of the library with its controller convention (identity, kuka)."""
    convention = ControllerConvention(
        vendor="kuka", signs=np.ones(6), offsets=np.zeros(6), source=KUKA_SOURCE
    )
    tool = placement_transform(np.array([0.01, -0.02, 0.15, 0.1, -0.2, 0.3]))
    return vendor_robot(name, convention, tool)


BASE = placement_transform(np.array([0.45, -0.1, 0.2, 0.0, 0.0, 0.7]))
HEADER = ("trackplan test", "case: by hand", "form: cartesian")


def target(robot: Robot, q_deg: list[float]) -> Target:
    """The target of model joints ``q_deg`` (degrees) in the part frame :data:`BASE`."""
    return make_target(robot, np.deg2rad(q_deg), BASE)


def cartesian_program(robot: Robot, name: str = "seam_demo") -> Program:
    """A start, a seam of lines, an arc and a spline, an air move and a second seam."""
    poses = [
        [0, -80, 100, 0, 70, 0],
        [5, -78, 98, 2, 72, -3],
        [10, -75, 95, 4, 75, -6],
        [15, -72, 92, 6, 74, -9],
        [20, -70, 90, 8, 73, -12],
        [25, -69, 88, 10, -70, 160],
        [-30, -100, 60, -20, -40, 30],
    ]
    t = [target(robot, q) for q in poses]
    seam = Section(
        kind="seam",
        label="seam 1",
        moves=(
            LinearMove(target=t[1], speed=0.02, zone=0.0005),
            CircularMove(via=t[2], target=t[3], speed=0.02, zone=0.0005),
            SplineMove(targets=(t[4], t[5]), speed=0.015, zone=0.0003),
        ),
    )
    air_move = joint_move(robot, np.deg2rad(poses[6]), speed=0.3)
    air = Section(kind="air", label="air", moves=(air_move,))
    second = Section(
        kind="seam",
        label="seam 2",
        moves=(LinearMove(target=target(robot, [-28, -98, 62, -18, -42, 28]), speed=0.01),),
    )
    start_move = joint_move(robot, np.deg2rad(poses[0]), speed=0.2)
    start = Section(kind="start", label="start", moves=(start_move,))
    sections = (start, seam, air, second)
    return program(robot, sections, base=BASE, name=name, header=HEADER)


def joint_program(robot: Robot) -> Program:
    """The joint form: a PTP to the start, then timed joint samples."""
    q = np.linspace([0, -80, 100, 0, 70, 0], [20, -70, 90, 8, 73, -12], 6)
    speeds = [0.5, 0.5, 0.5, 0.8, 0.8]
    return joint_form(
        robot,
        np.deg2rad(q),
        period=0.004,
        start_speed=0.2,
        speed=speeds,
        base=BASE,
        name="seam_demo",
        header=HEADER,
    )


def assert_reads_back(prog: Program, parsed: ParsedProgram, robot: Robot) -> None:
    """The shared round trip (spline points as SPLINE), the frames as KRL prints them
    (1e-7) and S and T of every Cartesian target as the oracle's."""
    assert_matches_plan(parsed, prog, robot, spline_as="spline")
    np.testing.assert_allclose(parsed.base, prog.base, atol=1e-7)
    np.testing.assert_allclose(parsed.tool, prog.tool, atol=1e-7)
    if robot.n_dof == 6:
        for got, want in target_pairs(parsed, prog):
            if want.pose is not None:
                s, t = status_turn_reference(robot, want.joints)
                assert got.config == {"S": s, "T": t}


@pytest.mark.parametrize("name", ["kuka_kr6_r700_sixx", "kuka_kr10_r1420"])
def test_cartesian_program_reads_back(name: str) -> None:
    robot = kuka(name)
    prog = cartesian_program(robot)
    files = render_krl(prog, robot=robot)
    assert sorted(files) == ["seam_demo.dat", "seam_demo.src"]
    parsed = parse_krl(files)
    assert parsed.name == "seam_demo"
    assert_reads_back(prog, parsed, robot)
    kinds: dict[str, ParsedTarget] = {}
    for parsed_target in parsed.targets:
        kinds.setdefault(parsed_target.kind, parsed_target)
    assert kinds["linear"].speed == pytest.approx(0.02)
    assert kinds["linear"].zone == pytest.approx(0.0005)
    assert kinds["spline"].speed == pytest.approx(0.015) and kinds["spline"].zone == 0.0
    splines = [t for t in parsed.targets if t.kind == "spline"]
    assert splines[-1].zone == pytest.approx(0.0003)  # ENDSPLINE C_SPL
    assert parsed.targets[0].speed == pytest.approx(0.2)  # the PTP start, $VEL_AXIS 20 %
    assert parsed.targets[-1].zone == 0.0 and parsed.targets[-1].speed == pytest.approx(0.01)
    assert "trackplan test" in parsed.header


def test_joint_program_reads_back() -> None:
    robot = kuka()
    prog = joint_program(robot)
    files = render_krl(prog, robot=robot)
    parsed = parse_krl(files)
    assert_reads_back(prog, parsed, robot)
    assert "PTP_SPLINE" in files["seam_demo.src"] and "SPTP XJ2" in files["seam_demo.src"]
    assert [t.speed for t in parsed.targets] == pytest.approx([0.2, 0.5, 0.5, 0.5, 0.8, 0.8])
    assert any("KRL times the moves itself" in line for line in parsed.header)


def test_puma560_generic_reads_back() -> None:
    robot = dataclasses.replace(
        puma560(), T_flange_tool=placement_transform(np.array([0, 0, 0.1, 0, 0, 0]))
    )
    prog = cartesian_program(robot)
    files = render_krl(prog, robot=robot)
    assert_reads_back(prog, parse_krl(files), robot)


def long_spline_program(robot: Robot) -> Program:
    """The Cartesian program with a spline of seven points."""
    base = cartesian_program(robot, name="a_rather_long_program_name_for_krl")
    q = np.linspace([20, -70, 90, 8, 73, -12], [30, -60, 80, 10, 70, -20], 8)[1:]
    spline = SplineMove(targets=tuple(target(robot, list(row)) for row in q), speed=0.01)
    seam = Section(kind="seam", label="long", moves=(spline,))
    return dataclasses.replace(base, sections=(*base.sections, seam))


@pytest.mark.parametrize("max_points", [2, 3, 5])
@pytest.mark.parametrize("form", ["cartesian", "joint"])
def test_split_program_reads_back_as_the_unsplit_one(max_points: int, form: str) -> None:
    robot = kuka()
    prog = long_spline_program(robot)
    if form == "joint":
        prog = dataclasses.replace(joint_program(robot), name=prog.name)
    whole = parse_krl(render_krl(prog, robot=robot))
    files = render_krl(prog, robot=robot, max_points=max_points)
    parts = sorted(name for name in files if "_P" in name and name.endswith(".src"))
    assert len(parts) >= 2
    assert all(len(Path(name).stem) <= MAX_NAME for name in files)
    split = parse_krl(files)
    assert split.name == whole.name == "a_rather_long_program_na"
    assert_same_targets(split, whole)
    assert {t.part for t in split.targets} == {Path(p).stem for p in parts}
    assert_reads_back(prog, split, robot)


def test_status_and_turn_known_poses() -> None:
    """KUKA's home (0, -90, 90, 0, 0, 0) is S 'B010', T 'B000010'; the A3-A4 offset of the
    KR6 R700 (35 mm over 365 mm) moves the elbow threshold to A3 = 5.48 deg."""
    robot = kuka()
    joints = np.deg2rad(
        [
            [0, -90, 90, 0, 0, 0],
            [0, -90, 5, 0, 30, 0],
            [0, -90, 6, 0, 30, 0],
            [0, -90, -30, 0, -30, 0],
        ]
    )
    status, turn = status_turn(robot, joints)
    assert status.tolist() == [2, 0, 2, 1 + 4]
    assert turn.tolist() == [2, 2, 2, 2 + 4 + 16]
    for row, s, t in zip(joints, status, turn, strict=True):
        assert status_turn_reference(robot, row) == (s, t)


def test_home_flange_is_b90() -> None:
    """With a null tool at KUKA's home the flange reads A 0, B 90, C 0 (tool0 = $FLANGE)."""
    robot = builtin_robot("kuka_kr6_r700_sixx")
    values = frame_values(forward_kinematics(robot, np.deg2rad([0, -90, 90, 0, 0, 0])))
    np.testing.assert_allclose(values[3:], [0.0, 90.0, 0.0], atol=1e-6)


@given(
    angles=st.lists(st.floats(-np.pi, np.pi), min_size=3, max_size=3),
    gimbal=st.sampled_from([None, np.pi / 2, -np.pi / 2, np.pi / 2 - 1e-7]),
)
@settings(max_examples=200, deadline=None)
def test_abc_round_trip(angles: list[float], gimbal: float | None) -> None:
    """Random rotations (and B at or near ±90 deg) → A, B, C → the parser's matrix."""
    a, b, c = angles
    if gimbal is not None:
        b = gimbal
    R = abc_rotation(*np.rad2deg([a, b, c]))
    abc = abc_from_matrix(R)
    assert -np.pi / 2 <= abc[1] <= np.pi / 2
    printed = np.round(np.rad2deg(abc), 6)  # the digits the writer prints
    assert rotation_angle(abc_rotation(*printed), R) < ANGLE_TOLERANCE / 10


def test_printed_digits_survive_krl_real() -> None:
    """KRL REAL is 32-bit: the printed values, rounded to float32, still meet the tolerances."""
    robot = kuka()
    prog = cartesian_program(robot)
    parsed = parse_krl(render_krl(prog, robot=robot))
    for got, want in target_pairs(parsed, prog):
        if got.pose is None:
            continue
        values = frame_values(got.pose).astype(np.float32).astype(float)
        pose = np.eye(4)
        pose[:3, :3] = abc_rotation(*values[3:])
        pose[:3, 3] = values[:3] / 1000
        assert want.pose is not None
        distance, angle = frame_difference(pose, want.pose)
        assert distance < POSITION_TOLERANCE and angle < ANGLE_TOLERANCE


@pytest.mark.parametrize(
    ("asked", "written"),
    [
        ("Naht_ü 3", "Naht_u_3"),
        ("x" * 40, "x" * MAX_NAME),
        ("MixedCase", "MixedCase"),
        ("12_seam-left", "seam_left"),
    ],
)
def test_names(asked: str, written: str) -> None:
    assert krl_name(asked) == written
    robot = kuka()
    files = render_krl(cartesian_program(robot, name=asked), robot=robot)
    assert set(files) == {f"{written}.src", f"{written}.dat"}
    assert f"DEF {written}( )" in files[f"{written}.src"]
    assert f"DEFDAT {written}" in files[f"{written}.dat"]


@pytest.mark.parametrize("asked", ["123", "---", "lin", "End"])
def test_names_refused(asked: str) -> None:
    robot = kuka()
    with pytest.raises(CaseError, match="--name"):
        render_krl(cartesian_program(robot, name=asked), robot=robot)


def test_refuses_other_vendors_and_joint_counts() -> None:
    robot = kuka()
    prog = cartesian_program(robot)
    with pytest.raises(CaseError) as error:
        render_krl(dataclasses.replace(prog, vendor="abb"), robot=robot)
    assert error.value.key == "--format"
    assert "has an ABB controller: use --format rapid" in error.value.message
    with pytest.raises(CaseError, match="7 joints"):
        render_krl(dataclasses.replace(prog, n_dof=7), robot=robot)


def test_refuses_fewer_than_two_points_per_part() -> None:
    robot = kuka()
    with pytest.raises(CaseError) as error:
        render_krl(cartesian_program(robot), robot=robot, max_points=1)
    assert error.value.key == "--max-points"


def test_writer_writes_ascii_crlf_files(tmp_path: Path) -> None:
    robot = kuka()
    prog = cartesian_program(robot)
    asked: dict[str, object] = {}

    def build(**options: object) -> Program:
        asked.update(options)
        return dataclasses.replace(prog, header=("case: Schweißnaht ≤ 0.5 mm",))

    source = stand_in(build, robot)
    writer = KrlWriter()
    names = writer.write(source, tmp_path, motion="cartesian", name="demo", max_points=4)
    assert asked == {"motion": "cartesian", "name": "demo", "period": None, "force": False}
    assert set(names) == {p.name for p in tmp_path.iterdir()}
    assert "seam_demo.src" in names and any("_P2" in n for n in names)
    for file in tmp_path.iterdir():
        raw = file.read_bytes()
        raw.decode("ascii")
        assert b"\r\n" in raw and b"\n" not in raw.replace(b"\r\n", b"")
    main = (tmp_path / "seam_demo.src").read_text(encoding="ascii")
    assert "; case: Schweissnaht <= 0.5 mm" in main
    files = {p.name: p.read_text(encoding="ascii") for p in tmp_path.iterdir()}
    assert_reads_back(prog, parse_krl(files), robot)


def flipped() -> Robot:
    """The KR6 under a made-up convention: signs, offsets and a moved world."""
    convention = ControllerConvention(
        vendor="generic",
        signs=np.array([-1.0, 1.0, -1.0, -1.0, 1.0, -1.0]),
        offsets=np.array([0.0, -np.pi / 2, 0.3, 0.0, 0.0, np.pi]),
        world=placement_transform(np.array([0.1, 0.0, 0.4, 0.0, 0.0, np.pi])),
    )
    return dataclasses.replace(kuka(), controller=convention)


@pytest.mark.parametrize("name", ["kuka_kr6_r700_sixx", "kuka_kr10_r1420", "puma560", "flipped"])
def test_status_turn_matches_the_reference(name: str) -> None:
    """The writer's Status and Turn equal the oracle's on random joints within the limits."""
    robots = {"puma560": puma560, "flipped": flipped}
    robot = robots[name]() if name in robots else kuka(name)

    @given(st.lists(st.floats(0.0, 1.0), min_size=6, max_size=6))
    @settings(max_examples=150, deadline=None)
    def check(fractions: list[float]) -> None:
        q = robot.q_min + np.array(fractions) * (robot.q_max - robot.q_min)
        theta = robot.convention.to_controller(q)
        status, turn = status_turn(robot, theta[None, :])
        assert (int(status[0]), int(turn[0])) == status_turn_reference(robot, theta)

    check()


def test_convention_and_world_round_trip() -> None:
    """Joints in the controller's convention and frames in its world read back as planned."""
    robot = flipped()
    for prog in (cartesian_program(robot), joint_program(robot)):
        assert_reads_back(prog, parse_krl(render_krl(prog, robot=robot)), robot)


def test_five_axis_robot_writes_no_status_turn() -> None:
    """A five-joint robot: E6AXIS A1 … A5, E6POS without S and T (defined for six axes)."""
    d, a = np.array([0.3, 0.0, 0.0, 0.0, 0.1]), np.array([0.05, 0.4, 0.35, 0.0, 0.0])
    robot = Robot.from_dh(
        name="five",
        d=d,
        a=a,
        alpha=np.array([np.pi / 2, 0.0, 0.0, np.pi / 2, 0.0]),
        offset=np.zeros(5),
        q_min=-np.full(5, np.pi),
        q_max=np.full(5, np.pi),
        v_max=np.ones(5),
        a_max=np.ones(5),
        j_max=np.ones(5),
    )
    start = Section(
        kind="start",
        label="start",
        moves=(joint_move(robot, np.deg2rad([0, 40, -60, 10, 5]), speed=0.5),),
    )
    seam = Section(
        kind="seam",
        label="seam",
        moves=(LinearMove(target=target(robot, [5, 42, -62, 12, 5]), speed=0.05),),
    )
    prog = program(robot, (start, seam), base=BASE, name="seam_demo", header=HEADER)
    files = render_krl(prog, robot=robot)
    assert "A5 5.0}" in files["seam_demo.dat"] and ",S " not in files["seam_demo.dat"]
    parsed = parse_krl(files)
    assert_reads_back(prog, parsed, robot)
    assert parsed.targets[1].config == {}
