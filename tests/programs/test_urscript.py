"""URScript programs read back by the test parser and compared with the program written.

Tolerances (issue 28): a Cartesian target within 0.01 mm and 0.001° of the program's, a
joint value within 1e-6 rad, a time within 1e-9 s.
"""

from __future__ import annotations

import re
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from tests.programs.parsed import ParsedProgram
from tests.programs.programs import joint_move, make_target
from tests.programs.roundtrip import (
    ANGLE_TOLERANCE,
    JOINT_TOLERANCE,
    POSITION_TOLERANCE,
    assert_joint_timing,
    assert_matches_plan,
    assert_matches_program,
    assert_same_targets,
    expected_targets,
    rotation_angle,
)
from tests.programs.stand_in import stand_in
from tests.programs.urscript_parser import parse_urscript
from tests.programs.urscript_programs import (
    START,
    cartesian_program,
    joint_program,
    part_base,
    placement,
    ur_program,
    ur_robot,
)
from tests.programs.urscript_reference import (
    BASE_FROM_BASE_LINK,
    E_SERIES_CYCLE,
    base_from_rep103,
    pose_matrix,
    vector_from_rotation,
)
from trackplan.errors import CaseError
from trackplan.io.robot_file import builtin_robot
from trackplan.programs.model import (
    CircularMove,
    JointMove,
    LinearMove,
    Program,
    Section,
    SplineMove,
    Target,
)
from trackplan.robots.controller import ControllerConvention
from trackplan.robots.kinematics import forward_kinematics
from trackplan.robots.model import Robot
from trackplan.writers.urscript import (
    DEFAULT_MAX_POINTS,
    UrscriptWriter,
    render_urscript,
    urscript_name,
)
from trackplan.writers.urscript_geometry import (
    BLEND_SHARE,
    least_common_multiple,
    pose_literal,
    rotation_vector,
)


def assert_reads_back(prog: Program, parsed: ParsedProgram, robot: Robot | None) -> None:
    """The shared round trip (spline points as lines; against the plan's forward
    kinematics unless ``robot`` is None), no configuration fields, every joint move's
    speed (1e-6) and time (1e-9 s) as the program's."""
    if robot is None:
        assert_matches_program(parsed, prog, spline_as="linear")
    else:
        assert_matches_plan(parsed, prog, robot, spline_as="linear")
    assert_joint_timing(parsed, prog, speed=1e-6, duration=1e-9)
    assert all(read.config == {} for read in parsed.targets)  # URScript poses carry none


@pytest.mark.parametrize("name", ["ur5e", "ur10e"])
def test_cartesian_program_reads_back(name: str) -> None:
    robot = ur_robot(name)
    prog = cartesian_program(robot)
    files = render_urscript(prog, robot=robot)
    assert list(files) == ["weld_cell.script"]
    parsed = parse_urscript(files)
    assert parsed.name == "weld_cell"
    # the world TCP of each target is the planned TCP: base · pose = FK(q) in the Base
    assert_reads_back(prog, parsed, robot)


def test_start_is_a_joint_move_on_the_planned_joints_and_says_the_branch_is_kept() -> None:
    robot = ur_robot()
    prog = cartesian_program(robot)
    text = render_urscript(prog, robot=robot)["weld_cell.script"]
    parsed = parse_urscript({"weld_cell.script": text})
    first = parsed.targets[0]
    assert first.kind == "joint" and first.joints is not None
    np.testing.assert_allclose(first.joints, robot.convention.to_controller(START + 0), atol=0.05)
    start_move = prog.sections[0].moves[0]
    assert isinstance(start_move, JointMove)
    np.testing.assert_allclose(first.joints, start_move.joints, atol=JOINT_TOLERANCE)
    assert "keeps the arm's branch" in text
    assert text.index("keeps the arm's branch") < text.index("movej(")


def test_speeds_and_blend_radii() -> None:
    robot = ur_robot()
    prog = cartesian_program(robot)
    parsed = parse_urscript(render_urscript(prog, robot=robot))
    moves = [m for m in prog.moves()]
    linear = [t for t in parsed.targets if t.kind in ("linear", "circular_end")]
    speeds = [
        m.speed
        for m in moves
        for _ in range(len(m.targets) if isinstance(m, SplineMove) else 1)
        if not isinstance(m, JointMove)
    ]
    assert [t.speed for t in linear] == pytest.approx(speeds, abs=1e-9)
    # every blend radius: at most the move's zone and 40 % of each neighbouring distance
    points = [  # in the Base: a joint target's TCP by forward kinematics
        parsed.base @ t.pose
        if t.pose is not None
        else forward_kinematics(robot, robot.convention.to_model(t.joints))
        for t in parsed.targets
    ]
    waypoints = [
        (t, p) for t, p in zip(parsed.targets, points, strict=True) if t.kind != "circular_via"
    ]
    for k, (read, _) in enumerate(waypoints):
        assert read.zone is not None and read.zone >= 0.0
        for j in (k - 1, k + 1):
            if 0 <= j < len(waypoints) and read.zone > 0:
                here, there = waypoints[k][1], waypoints[j][1]
                distance = np.linalg.norm(here[:3, 3] - there[:3, 3])
                assert read.zone <= BLEND_SHARE * distance + 1e-9
    assert waypoints[-1][0].zone == 0.0
    zones = [m.zone for m in moves if isinstance(m, LinearMove)]
    assert max(t.zone or 0.0 for t in linear) <= max(zones)


def test_a_large_zone_is_cut_so_that_blends_do_not_overlap() -> None:
    robot = ur_robot()
    prog = cartesian_program(robot)
    sections = tuple(
        replace(
            s,
            moves=tuple(
                replace(m, zone=0.05) if isinstance(m, LinearMove | SplineMove) else m
                for m in s.moves
            ),
        )
        for s in prog.sections
    )
    parsed = parse_urscript(render_urscript(replace(prog, sections=sections), robot=robot))
    positions = [
        (parsed.base @ t.pose)[:3, 3]
        for t in parsed.targets
        if t.kind == "linear" and t.pose is not None
    ]
    zones = [t.zone for t in parsed.targets if t.kind == "linear"]
    for k in range(1, len(positions) - 1):
        assert zones[k] is not None and zones[k] > 0.0
        assert zones[k] + (zones[k + 1] or 0.0) < np.linalg.norm(positions[k + 1] - positions[k])


def test_joint_form_reads_back() -> None:
    robot = ur_robot()
    prog = joint_program(robot, n=30, period=0.008)
    text = render_urscript(prog, robot=robot)["weld_cell.script"]
    parsed = parse_urscript({"weld_cell.script": text})
    assert_reads_back(prog, parsed, robot)
    assert [t.duration for t in parsed.targets[1:]] == pytest.approx([0.008] * 30)
    assert text.count("servoj(") == 30 and "lookahead_time=0.1, gain=300" in text
    assert "a=0, v=0, t=0.008" in text


@pytest.mark.parametrize("motion", ["cartesian", "joint"])
def test_a_split_program_reads_back_as_the_unsplit_one(motion: str) -> None:
    robot = ur_robot()
    prog = cartesian_program(robot) if motion == "cartesian" else joint_program(robot, n=25)
    whole = parse_urscript(render_urscript(prog, robot=robot))
    files = render_urscript(prog, robot=robot, max_points=4)
    split = parse_urscript(files)
    text = files["weld_cell.script"]
    n_parts = text.count("  def weld_cell_part")
    assert n_parts >= 4
    calls = [
        line.strip()
        for line in text.splitlines()
        if re.fullmatch(r"weld_cell_part\d+\(\)", line.strip())
    ]
    assert calls == [f"weld_cell_part{k}()" for k in range(1, n_parts + 1)]
    assert_same_targets(split, whole)
    assert {t.part for t in split.targets} == {f"weld_cell_part{k}" for k in range(1, n_parts + 1)}
    assert_reads_back(prog, split, robot)


def test_default_max_points_keeps_a_short_program_in_one_function() -> None:
    robot = ur_robot()
    text = render_urscript(joint_program(robot, n=50), robot=robot)["weld_cell.script"]
    assert "_part1" not in text and DEFAULT_MAX_POINTS >= 1000


@pytest.mark.parametrize(
    ("asked", "written"),
    [
        ("weld cell #1", "weld_cell_1"),
        ("Naht_ü-Ecke", "Naht_u_Ecke"),
        ("CamelCase_Program", "CamelCase_Program"),
        ("a" * 60, "a" * 60),
        ("movel", "movel_program"),
        ("part", "part_program"),
        ("3 seams", "seams"),
    ],
)
def test_program_names(asked: str, written: str) -> None:
    assert urscript_name(asked) == written
    robot = ur_robot()
    files = render_urscript(cartesian_program(robot, name=asked), robot=robot)
    assert list(files) == [f"{written}.script"]
    assert parse_urscript(files).name == written


def test_a_name_that_cannot_be_made_valid_is_refused() -> None:
    robot = ur_robot()
    with pytest.raises(CaseError) as error:
        render_urscript(cartesian_program(robot, name="123 !!"), robot=robot)
    assert error.value.key == "--name" and "\n" not in str(error.value)


def test_a_robot_that_is_not_a_ur_is_refused() -> None:
    puma = builtin_robot("puma560")
    assert puma.convention.vendor == "generic"
    q = np.zeros(6)
    prog = Program(
        name="p",
        motion="cartesian",
        robot=puma.name,
        vendor=puma.convention.vendor,
        n_dof=6,
        base=np.eye(4),
        tool=np.eye(4),
        sections=(
            Section(
                kind="start", label="start", moves=(JointMove(joints=q, model_joints=q, speed=0.2),)
            ),
        ),
        header=(),
        sample_time=0.004,
    )
    with pytest.raises(CaseError) as error:
        render_urscript(prog, robot=puma)
    message = str(error.value)
    assert error.value.key == "--format" and "\n" not in message
    assert "puma560" in message and "controller: vendor is ur" in message
    with pytest.raises(CaseError, match="--format krl"):
        render_urscript(replace(prog, vendor="kuka", robot="kr6"))


def test_a_robot_of_other_than_six_joints_is_refused() -> None:
    robot = ur_robot()
    prog = replace(cartesian_program(robot), n_dof=7)
    with pytest.raises(CaseError, match="7 joints") as error:
        render_urscript(prog, robot=robot)
    assert error.value.key == "--format"


@pytest.mark.parametrize(
    ("sample_time", "period", "cycle", "works"),
    [(0.003, 0.003, 0.002, 0.006), (0.004, 0.004, 0.008, 0.008), (0.005, 0.005, 0.002, 0.01)],
)
def test_a_period_off_the_controller_cycle_is_refused_naming_one_that_works(
    sample_time: float, period: float, cycle: float, works: float
) -> None:
    robot = ur_robot(cycle=cycle)
    prog = joint_program(robot, n=5, period=period, sample_time=sample_time)
    with pytest.raises(CaseError) as error:
        render_urscript(prog, robot=robot)
    assert error.value.key == "--period" and "\n" not in str(error.value)
    assert f"--period {works:g} " in str(error.value)
    fixed = joint_program(robot, n=5, period=works, sample_time=sample_time)
    assert parse_urscript(render_urscript(fixed, robot=robot)).targets[-1].duration == works


def test_least_common_multiple() -> None:
    assert least_common_multiple(0.003, 0.002) == pytest.approx(0.006)
    assert least_common_multiple(0.008, 0.002) == pytest.approx(0.008)
    assert least_common_multiple(0.0025, 0.002) == pytest.approx(0.01)


def test_the_cycle_defaults_to_the_e_series_step_with_a_header_note() -> None:
    robot = ur_robot(cycle=None)
    text = render_urscript(joint_program(robot, n=3, period=0.004), robot=robot)
    header = parse_urscript(text).header
    assert any("0.002 s cycle (assumed" in line for line in header)
    assert E_SERIES_CYCLE == 0.002
    with pytest.raises(CaseError):
        render_urscript(joint_program(robot, n=3, period=0.003, sample_time=0.003), robot=robot)
    text = render_urscript(joint_program(ur_robot(), n=3, period=0.004), robot=ur_robot())
    assert not any("assumed" in line for line in parse_urscript(text).header)


def test_the_header_comes_first_and_states_units_and_frames() -> None:
    robot = ur_robot()
    parsed = parse_urscript(render_urscript(cartesian_program(robot), robot=robot))
    header = "\n".join(parsed.header)
    for words in ("trackplan test", "robot: ur5e", "units: m, rad", "rotation vector", "set_tcp"):
        assert words in header


UR_DESCRIPTION_CHAINS = {  # x y z, roll pitch yaw: shoulder, upper_arm, forearm, wrist_1..3
    "ur5e": [
        ([0, 0, 0.1625], [0, 0, 0]),
        ([0, 0, 0], [1.570796327, 0, 0]),
        ([-0.425, 0, 0], [0, 0, 0]),
        ([-0.3922, 0, 0.1333], [0, 0, 0]),
        ([0, -0.0997, 0], [1.570796327, 0, 0]),
        ([0, 0.0996, 0], [1.570796326589793, np.pi, np.pi]),
    ],
    "ur10e": [
        ([0, 0, 0.1807], [0, 0, 0]),
        ([0, 0, 0], [1.570796327, 0, 0]),
        ([-0.6127, 0, 0], [0, 0, 0]),
        ([-0.57155, 0, 0.17415], [0, 0, 0]),
        ([0, -0.11985, 0], [1.570796327, 0, 0]),
        ([0, 0.11655, 0], [1.570796326589793, np.pi, np.pi]),
    ],
}
"""UniversalRobots/Universal_Robots_ROS2_Description, config/<robot>/default_kinematics.yaml
(the z of wrist_2 and wrist_3, about -2e-11 m, left out)."""


@pytest.mark.parametrize("name", ["ur5e", "ur10e"])
def test_the_builtin_urs_root_is_the_controller_base(name: str) -> None:
    """ur_description's chain (urdf/ur_macro.xacro: from base_link through the π turn of
    base_link_inertia, the six joints, then flange and tool0) expressed in its ``base``
    frame (the controller's Base) equals the built-in robot's forward kinematics: the
    built-in's root is UR's Base and its joints are UR's, so its controller convention is
    the identity."""
    from scipy.spatial.transform import Rotation

    def frame(xyz: list[float], rpy: list[float]) -> np.ndarray:
        out = np.eye(4)
        out[:3, :3] = Rotation.from_euler("xyz", rpy).as_matrix()
        out[:3, 3] = xyz
        return out

    chain = UR_DESCRIPTION_CHAINS[name]
    robot = builtin_robot(name)
    rng = np.random.default_rng(3)
    for q in rng.uniform(-np.pi, np.pi, (20, 6)):
        pose = frame([0, 0, 0], [0, 0, np.pi])
        for (xyz, rpy), angle in zip(chain, q, strict=True):
            pose = pose @ frame(xyz, rpy) @ frame([0, 0, 0], [0, 0, angle])
        pose = (
            pose
            @ frame([0, 0, 0], [0, -np.pi / 2, -np.pi / 2])
            @ frame([0, 0, 0], [np.pi / 2, 0, np.pi / 2])
        )
        in_base = base_from_rep103(pose)
        np.testing.assert_allclose(in_base, forward_kinematics(robot, q), atol=1e-8)


def test_a_world_turned_by_pi_reads_back_in_the_controller_base() -> None:
    """A UR modelled in ur_description's base_link: the convention's world is Rz(π), the
    program's base is the part frame in UR's Base and the TCP read back is FK in the Base."""
    robot = ur_robot()
    turned = replace(
        robot,
        controller=ControllerConvention(
            vendor="ur",
            signs=np.ones(6),
            offsets=np.zeros(6),
            world=BASE_FROM_BASE_LINK,
            cycle=0.002,
        ),
    )
    prog = cartesian_program(turned)
    parsed = parse_urscript(render_urscript(prog, robot=turned))
    np.testing.assert_allclose(parsed.base, base_from_rep103(placement()), atol=POSITION_TOLERANCE)
    read = parsed.targets[1]
    assert read.pose is not None
    planned = base_from_rep103(forward_kinematics(turned, prog_joints(prog, 1)))
    world = parsed.base @ read.pose
    np.testing.assert_allclose(world[:3, 3], planned[:3, 3], atol=POSITION_TOLERANCE)
    assert rotation_angle(world, planned) <= ANGLE_TOLERANCE


def prog_joints(prog: Program, index: int) -> np.ndarray:
    """Model joints of the ``index``-th expected target."""
    return expected_targets(prog)[index].model_joints


@pytest.mark.parametrize("sweep", [1.2, -1.2, 5.2, -5.2])
def test_movec_mode_follows_the_planned_orientation(sweep: float) -> None:
    """Arcs of ±69° and ±298° (either way round, less and more than half a turn)."""
    robot = ur_robot()
    start_q = START
    start = make_target(robot, start_q, part_base(robot))
    centre = start.pose[:3, 3] + np.array([0.0, 0.05, 0.0])

    def on_arc(angle: float, turn: bool) -> Target:
        rotation = rotation_z(angle)
        pose = np.eye(4)
        pose[:3, 3] = centre + rotation @ (start.pose[:3, 3] - centre)
        pose[:3, :3] = rotation @ start.pose[:3, :3] if turn else start.pose[:3, :3]
        return Target(pose=pose, joints=start.joints, model_joints=start.model_joints)

    for turn, mode in ((True, 1), (False, 0)):
        arc = CircularMove(via=on_arc(sweep / 2, turn), target=on_arc(sweep, turn), speed=0.01)
        line = LinearMove(target=start, speed=0.01)
        sections = (
            Section(kind="start", label="start", moves=(joint_move(robot, start_q, speed=0.25),)),
            Section(kind="seam", label="arc", moves=(line, arc)),
        )
        text = render_urscript(ur_program(robot, sections), robot=robot)["weld_cell.script"]
        assert f"mode={mode})" in text
        assert_reads_back(ur_program(robot, sections), parse_urscript({"w.script": text}), None)


def rotation_z(angle: float) -> np.ndarray:
    """Rotation about z, (3, 3)."""
    c, s = np.cos(angle), np.sin(angle)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


rotations = st.lists(st.floats(-1.0, 1.0), min_size=4, max_size=4).filter(
    lambda q: float(np.linalg.norm(q)) > 1e-3
)


@settings(max_examples=200, deadline=None)
@given(rotations, st.lists(st.floats(-2.0, 2.0), min_size=3, max_size=3))
def test_pose_literals_read_back_by_the_reference(
    quaternion: list[float], position: list[float]
) -> None:
    from scipy.spatial.transform import Rotation

    pose = np.eye(4)
    pose[:3, :3] = Rotation.from_quat(quaternion).as_matrix()
    pose[:3, 3] = position
    literal = pose_literal(pose)
    values = [float(v) for v in literal[2:-1].split(",")]
    read = pose_matrix(np.array(values))
    np.testing.assert_allclose(read[:3, 3], position, atol=1e-8)
    assert rotation_angle(read, pose) <= 1e-7
    vector = rotation_vector(pose[:3, :3])
    assert np.linalg.norm(vector) <= np.pi + 1e-12
    reference = vector_from_rotation(pose[:3, :3])
    if np.pi - np.linalg.norm(reference) > 1e-3:  # away from π the vector is unique
        np.testing.assert_allclose(vector, reference, atol=1e-7)


def test_urs_own_example_program_reads() -> None:
    """Excerpts of a program PolyScope wrote: UniversalRobots/URScript_Examples,
    execution-time/timing_debug.script, lines 1-24, 47-53 and 111-126 (BSD 3-Clause
    License, Copyright (c) 2025, Universal Robots A/S)."""
    text = UR_EXAMPLE
    parsed = parse_urscript({"timing_debug.script": text})
    assert parsed.name == "timing_debug"
    np.testing.assert_array_equal(parsed.tool, np.eye(4))
    assert [t.kind for t in parsed.targets] == ["joint", "joint"]
    first, second = parsed.targets
    assert first.joints is not None and second.joints is not None and first.pose is not None
    np.testing.assert_allclose(first.joints[:2], [0.9892310279703125, -1.296460068061041])
    np.testing.assert_allclose(second.joints[5], -0.5750561449615539)
    np.testing.assert_allclose(first.pose[:3, 3], [-0.12, -0.43, 0.14])
    assert first.speed == pytest.approx(1.0471975511965976)
    assert first.part == "timing_debug"


UR_EXAMPLE = """def timing_debug():
  global _hidden_verificationVariable=0
  modbus_add_signal("0.0.0.0", 255, 0, 0, "MODBUS_1", False)
  modbus_set_signal_update_frequency("MODBUS_1", 10)
  set_tool_communication(False, 115200, 0, 1, 1.5, 3.5)
  set_tool_output_mode(0)
  set_tool_digital_output_mode(0, 1)
  set_tool_digital_output_mode(1, 1)
  set_tool_voltage(0)
  set_safety_mode_transition_hardness(1)
  tool_wrench_limit_disable()
  set_target_payload(0.000000, [0.000000, 0.000000, 0.000000], [0.000000, 0.000000, 0.000000, 0.000000, 0.000000, 0.000000])
  set_standard_analog_input_domain(0, 1)
  set_standard_analog_input_domain(1, 1)
  set_tool_analog_input_domain(0, 1)
  set_tool_analog_input_domain(1, 1)
  set_analog_outputdomain(0, 0)
  set_analog_outputdomain(1, 0)
  set_input_actions_to_default()
  set_runstate_standard_digital_outputs([0])
  set_runstate_standard_digital_output_to_value(0, 1)
  set_tcp(p[0.0,0.0,0.0,0.0,0.0,0.0])
  set_gravity([0.0, 0.0, 9.82])
  motion_version_set(2)
  global Waypoint_1_p=p[-.120000000000, -.430000000000, .140000000000, .000000000000, 3.110000000000, .040000000000]
  global Waypoint_1_q=[0.9892310279703125, -1.296460068061041, 2.2867423437378296, -2.521884721667198, -1.5557272368626922, -0.5743656761333984]
  global Waypoint_2_p=p[-.119999999955, -.429999999932, .203392313557, .000000000002, 3.109999999999, .039999999999]
  global Waypoint_2_q=[0.9894024051141934, -1.446808357413257, 2.231179687468959, -2.3159682978010947, -1.5544916765992953, -0.5750561449615539]
  $ 2 "BeforeStart"
  $ 3 "var_4≔4"
  global var_4=4
  while (True):
    $ 11 "Robot Program"
    $ 12 "Set idbg28=0"
    write_output_integer_register(28, 0)
    $ 13 "MoveJ"
    $ 14 "Set idbg28=idbg28+1"
    write_output_integer_register(28, read_output_integer_register(28)+1)
    $ 15 "Waypoint_1" "breakAfter"
    movej(get_inverse_kin(Waypoint_1_p, qnear=Waypoint_1_q), a=1.3962634015954636, v=1.0471975511965976)
    $ 16 "Set idbg28=idbg28+1"
    write_output_integer_register(28, read_output_integer_register(28)+1)
    $ 17 "Waypoint_2" "breakAfter"
    movej(get_inverse_kin(Waypoint_2_p, qnear=Waypoint_2_q), a=1.3962634015954636, v=1.0471975511965976)
  end
end
"""  # noqa: E501


def test_the_writer_writes_ascii_files_into_the_folder(tmp_path: Path) -> None:
    robot = ur_robot()
    asked: dict[str, object] = {}

    def build(**options: object) -> Program:
        asked.update(options)
        return cartesian_program(robot, name="Naht ü")

    source = stand_in(build, robot)
    writer = UrscriptWriter()
    assert (writer.name, writer.suffix, writer.default_file, writer.folder) == (
        "urscript",
        ".script",
        "urscript",
        True,
    )
    names = writer.write(source, tmp_path, motion="cartesian", max_points=5)
    assert names == ("Naht_u.script",)
    assert asked == {"motion": "cartesian", "name": None, "period": None, "force": False}
    text = (tmp_path / "Naht_u.script").read_text(encoding="ascii")
    assert text.startswith("def Naht_u():\n  # Naht_u:") and text.endswith("\nend\n")
    assert parse_urscript({"Naht_u.script": text}).targets


@pytest.mark.parametrize("motion", ["cartesian", "joint"])
def test_the_text_is_what_urcontrol_takes_from_a_socket(motion: str) -> None:
    """URScript manual, "Connecting to URControl": extended ASCII only; the script starts
    with ``def`` in the first column, every other line is indented, the last line is
    ``end`` in the first column."""
    robot = ur_robot()
    prog = cartesian_program(robot) if motion == "cartesian" else joint_program(robot)
    header = (*prog.header, "tolerance ≤ 0.5 mm · 1°, case Naht_ü → π")
    sections = tuple(replace(s, label=s.label + "_ü") for s in prog.sections)
    files = render_urscript(
        replace(prog, header=header, sections=sections), robot=robot, max_points=5
    )
    lines = files["weld_cell.script"].splitlines()
    assert lines[0] == "def weld_cell():" and lines[-1] == "end"
    assert all(line.startswith(" ") for line in lines[1:-1])
    assert all(line.isascii() for line in lines)
    read = parse_urscript(files)
    assert "tolerance <= 0.5 mm * 1 deg, case Naht_u -> pi" in read.header


def test_the_reference_pose_trans_is_the_manuals_example() -> None:
    """URScript manual, ``pose_trans``: ``pose_trans(p[.2,.5,.1,1.57,0,0],
    p[.2,.5,.6,1.57,0,0])`` returns ``p[0.4,-0.0996,0.60048,3.14,0.0,0.0]``."""
    from tests.programs.urscript_reference import pose_trans

    result = pose_trans(
        pose_matrix(np.array([0.2, 0.5, 0.1, 1.57, 0, 0])),
        pose_matrix(np.array([0.2, 0.5, 0.6, 1.57, 0, 0])),
    )
    np.testing.assert_allclose(result[:3, 3], [0.4, -0.0996, 0.60048], atol=1e-4)
    np.testing.assert_allclose(vector_from_rotation(result[:3, :3]), [3.14, 0, 0], atol=1e-3)


def test_without_a_robot_joint_moves_do_not_blend_and_the_cycle_is_assumed() -> None:
    robot = ur_robot()
    prog = cartesian_program(robot)
    sections = tuple(
        replace(
            s,
            moves=tuple(replace(m, zone=0.01) if isinstance(m, JointMove) else m for m in s.moves),
        )
        for s in prog.sections
    )
    prog = replace(prog, sections=sections)
    with_robot = parse_urscript(render_urscript(prog, robot=robot))
    without = parse_urscript(render_urscript(prog))
    assert_reads_back(prog, without, robot)
    kinds = [t.kind for t in without.targets]
    air = kinds.index("joint", 1)
    assert without.targets[air].zone == 0.0 and without.targets[air - 1].zone == 0.0
    assert (with_robot.targets[air].zone or 0.0) > 0.0  # with the robot's kinematics it blends
    text = render_urscript(joint_program(robot, n=2))["weld_cell.script"]
    assert "cycle (assumed: the robot states no cycle)" in text
    assert "global a_joint = 1.4" in text


@pytest.mark.parametrize("max_points", [1, 0, -3])
def test_too_few_points_per_part_is_refused_in_one_line(max_points: int) -> None:
    robot = ur_robot()
    with pytest.raises(CaseError) as error:
        render_urscript(cartesian_program(robot), robot=robot, max_points=max_points)
    assert error.value.key == "--max-points" and "at least 2" in str(error.value)


def test_a_header_or_label_with_a_line_break_stays_a_comment() -> None:
    robot = ur_robot()
    prog = cartesian_program(robot)
    sections = tuple(
        replace(s, label=s.label + "\nmovej([9, 9, 9, 9, 9, 9])") for s in prog.sections
    )
    prog = replace(prog, header=("case: two\nlines", *prog.header), sections=sections)
    parsed = parse_urscript(render_urscript(prog, robot=robot))
    assert_reads_back(prog, parsed, robot)
    assert "case: two lines" in parsed.header
