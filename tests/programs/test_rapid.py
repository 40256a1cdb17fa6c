"""ABB RAPID export: programs built by hand, written by the RAPID writer, read back by the
test parser (which does not import the writer) and compared with the program."""

from __future__ import annotations

import math
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.spatial.transform import Rotation

from tests.programs.parsed import ParsedProgram
from tests.programs.programs import joint_move, make_target, program
from tests.programs.rapid_parser import (
    Name,
    parse_modules,
    parse_rapid,
    pose_matrix,
    quaternion_matrix,
)
from tests.programs.rapid_programs import (
    BASE,
    IRB1600_CONVENTION,
    IRB2400_CONVENTION,
    abb_robot,
    cartesian_program,
    joint_program,
    puma,
)
from tests.programs.rapid_reference import reference_confdata
from tests.programs.roundtrip import (
    ANGLE_TOLERANCE,
    JOINT_TOLERANCE,
    POSITION_TOLERANCE,
    assert_joint_timing,
    assert_matches_plan,
    assert_same_targets,
    rotation_angle,
    target_pairs,
)
from tests.programs.stand_in import stand_in
from trackplan.errors import CaseError
from trackplan.io.robot_file import builtin_robot
from trackplan.programs.model import JointMove, LinearMove, Program, Section, SplineMove
from trackplan.robots.controller import ControllerConvention
from trackplan.robots.dynamics_parameters import Payload
from trackplan.robots.kinematics import forward_kinematics
from trackplan.robots.model import Robot
from trackplan.writers.rapid import DEFAULT_MAX_POINTS, RapidWriter, render_rapid
from trackplan.writers.rapid_config import confdata, number, quaternion

Q_IRB2400 = np.array([0.2, 0.3, -0.2, 0.5, 0.8, -0.4])
Q_IRB1600 = np.array([-0.4, 0.2, -0.3, -1.2, -0.7, 2.0])
Q_PUMA = np.array([0.3, -0.6, 0.4, 0.2, 0.9, -0.5])


def assert_round_trip(parsed: ParsedProgram, prog: Program, robot: Robot) -> None:
    """The shared round trip (spline points as lines), every timed MoveAbsJ's \\T as
    planned (1e-9 s) and the confdata of every target as the oracle's."""
    assert_matches_plan(parsed, prog, robot, spline_as="linear")
    assert_joint_timing(parsed, prog, speed=None, duration=1e-9)
    for read, item in target_pairs(parsed, prog):
        if item.pose is not None:
            cf1, cf4, cf6, cfx = reference_confdata(robot, item.model_joints)
            assert read.config == {"cf1": cf1, "cf4": cf4, "cf6": cf6, "cfx": cfx}


def text_of(files: dict[str, str]) -> str:
    (text,) = files.values()
    return text


@pytest.mark.parametrize(
    ("robot", "q0"),
    [
        (abb_robot("abb_irb2400"), Q_IRB2400),
        (abb_robot("abb_irb1600"), Q_IRB1600),
        (puma(), Q_PUMA),
    ],
    ids=["irb2400", "irb1600", "puma560"],
)
def test_cartesian_program_reads_back_as_planned(robot: Robot, q0: np.ndarray) -> None:
    prog = cartesian_program(robot, q0)
    files = render_rapid(prog, robot=robot)
    assert list(files) == ["weld_cell.mod"]
    parsed = parse_rapid(files)
    assert parsed.name == "weld_cell"
    assert_round_trip(parsed, prog, robot)
    # Speeds (m/s) and zones (m) as planned; a stop is fine (zone 0).
    linear = [t for t in parsed.targets if t.kind == "linear"]
    assert linear[0].speed == pytest.approx(0.02) and linear[0].zone == pytest.approx(0.0005)
    assert linear[-1].zone == 0.0 and linear[-1].speed == pytest.approx(0.01)
    text = text_of(files)
    assert "ConfL \\On;" in text and "ConfJ \\On;" in text
    assert text.index("ConfL \\On;") < text.index("MoveAbsJ [")


def test_spline_becomes_blended_lines_with_its_zone() -> None:
    robot = abb_robot("abb_irb2400")
    prog = cartesian_program(robot, Q_IRB2400)
    parsed = parse_rapid(render_rapid(prog, robot=robot))
    spline_targets = parsed.targets[4:7]  # joint, linear, via, end, then the spline
    assert [t.kind for t in spline_targets] == ["linear"] * 3
    assert all(t.zone == pytest.approx(0.0002) for t in spline_targets)
    assert all(t.speed == pytest.approx(0.015) for t in spline_targets)


def test_header_names_the_form_and_is_ascii() -> None:
    robot = abb_robot("abb_irb2400")
    files = render_rapid(cartesian_program(robot, Q_IRB2400), robot=robot)
    text = text_of(files)
    text.encode("ascii")
    parsed = parse_rapid(files)
    assert "trackplan 0.0 test" in parsed.header
    assert any("<= 1.0 mm - tracking" in line for line in parsed.header)
    assert any(line.startswith("form: cartesian") for line in parsed.header)


def test_parallel_arm_axis_3_counts_q2_plus_q3() -> None:
    robot = abb_robot("abb_irb2400")
    prog = cartesian_program(robot, Q_IRB2400)
    parsed = parse_rapid(render_rapid(prog, robot=robot))
    start = parsed.targets[0].joints
    assert start[2] == pytest.approx(Q_IRB2400[2] + Q_IRB2400[1], abs=JOINT_TOLERANCE)
    assert start[1] == pytest.approx(Q_IRB2400[1], abs=JOINT_TOLERANCE)
    assert IRB2400_CONVENTION.to_model(start) == pytest.approx(Q_IRB2400, abs=JOINT_TOLERANCE)


@pytest.mark.parametrize(
    ("robot", "q0"),
    [(abb_robot("abb_irb1600"), Q_IRB1600), (puma(), Q_PUMA)],
    ids=["irb1600", "puma560"],
)
def test_joint_form_is_timed_moveabsj(robot: Robot, q0: np.ndarray) -> None:
    prog = joint_program(robot, q0, period=0.012)
    files = render_rapid(prog, robot=robot)
    parsed = parse_rapid(files)
    assert_round_trip(parsed, prog, robot)
    timed = parsed.targets[1:]
    assert all(t.duration == pytest.approx(0.012) for t in timed)
    # The samples blend; the plan stops at the end.
    assert all(t.zone is not None and t.zone > 0.0 for t in timed[:-1])
    assert timed[-1].zone == 0.0
    assert "\\T:=0.012" in text_of(files)


def test_air_move_is_timed_at_its_share_of_the_joint_rates() -> None:
    robot = abb_robot("abb_irb2400")
    prog = cartesian_program(robot, Q_IRB2400)
    parsed = parse_rapid(render_rapid(prog, robot=robot))
    (air,) = [t for t in parsed.targets[1:] if t.kind == "joint"]
    moves = list(prog.moves())
    air_move = moves[5]
    assert isinstance(air_move, JointMove)
    before = moves[4]
    assert isinstance(before, LinearMove)
    travel = np.abs(air_move.model_joints - before.target.model_joints)
    assert air.duration == pytest.approx(np.max(travel / (0.5 * robot.v_max)), rel=1e-5)
    # The move to the start has no starting point: a speed, not a time.
    assert parsed.targets[0].duration is None


def test_split_program_reads_back_as_the_unsplit_one() -> None:
    robot = abb_robot("abb_irb2400")
    prog = cartesian_program(robot, Q_IRB2400)
    whole = parse_rapid(render_rapid(prog, robot=robot))
    files = render_rapid(prog, robot=robot, max_points=3)
    split = parse_rapid(files)
    parts = {t.part for t in split.targets}
    assert len(parts) == math.ceil(prog.n_points / 3) and "main" not in parts
    assert len(whole.targets) == prog.n_points
    assert_same_targets(split, whole)
    assert_round_trip(split, prog, robot)
    text = text_of(files)
    assert text.count("LOCAL PROC part") == len(parts)
    assert text.index("part1;") < text.index("part2;")


def test_joint_form_split_keeps_every_sample_once() -> None:
    robot = abb_robot("abb_irb1600")
    prog = joint_program(robot, Q_IRB1600, n=25)
    split = parse_rapid(render_rapid(prog, robot=robot, max_points=4))
    assert_round_trip(split, prog, robot)
    assert DEFAULT_MAX_POINTS >= 2


@pytest.mark.parametrize(
    ("asked", "written"),
    [
        ("weld_cell", "weld_cell"),
        ("Naht ü-1 (rechts)", "Naht_u_1_rechts"),
        ("2nd seam", "nd_seam"),
        ("a" * 40, "a" * 32),
        ("main", "main_prg"),
        ("Module", "Module_prg"),
        ("part2", "part2_prg"),
    ],
)
def test_program_name_is_a_rapid_identifier(asked: str, written: str) -> None:
    robot = abb_robot("abb_irb1600")
    prog = replace(cartesian_program(robot, Q_IRB1600), name=asked)
    files = render_rapid(prog, robot=robot)
    assert list(files) == [f"{written}.mod"]
    assert text_of(files).startswith(f"MODULE {written}\n")
    parsed = parse_rapid(files)
    assert parsed.name == written
    assert len(written) <= 32
    # The data names stay identifiers of at most 32 characters.
    for word in ("tool_", "wobj_"):
        declared = next(line for line in text_of(files).splitlines() if f" {word}" in line)
        name = declared.split()[2].split(":=")[0]
        assert len(name) <= 32


def test_a_name_that_cannot_be_made_valid_is_refused() -> None:
    robot = abb_robot("abb_irb1600")
    prog = replace(cartesian_program(robot, Q_IRB1600), name="123 ---")
    with pytest.raises(CaseError) as error:
        render_rapid(prog, robot=robot)
    assert "--name" in str(error.value)


def test_a_robot_of_another_vendor_is_refused() -> None:
    robot = abb_robot("abb_irb1600")
    prog = replace(cartesian_program(robot, Q_IRB1600), vendor="kuka", robot="kuka_kr10")
    with pytest.raises(CaseError, match="RAPID drives ABB or generic robots") as error:
        render_rapid(prog, robot=robot)
    assert "--format" in str(error.value)
    assert "\n" not in str(error.value)


def test_too_many_joints_are_refused() -> None:
    robot = abb_robot("abb_irb1600")
    prog = replace(cartesian_program(robot, Q_IRB1600), n_dof=7)
    with pytest.raises(CaseError, match=r"RAPID drives 6 robot axes, and robot .* has 7 joints"):
        render_rapid(prog, robot=robot)


def test_fewer_than_two_points_per_procedure_are_refused() -> None:
    robot = abb_robot("abb_irb1600")
    with pytest.raises(CaseError, match="at least 2 targets per procedure, got 1"):
        render_rapid(cartesian_program(robot, Q_IRB1600), robot=robot, max_points=1)


def test_a_spline_longer_than_a_part_is_split_without_loss() -> None:
    robot = abb_robot("abb_irb2400")
    prog = joint_program(robot, Q_IRB2400, n=4)
    steps = np.linspace(0.0, 0.3, 9)[1:, None] * np.array([0.1, 0.05, -0.05, 0.2, 0.1, 0.1])
    spline = SplineMove(
        targets=tuple(make_target(robot, Q_IRB2400 + step, BASE) for step in steps), speed=0.02
    )
    prog = replace(
        prog,
        motion="cartesian",
        sections=(
            *prog.sections,
            Section(kind="seam", label="curve", moves=(spline,)),
            Section(kind="air", label="air", moves=(joint_move(robot, Q_IRB2400, speed=0.5),)),
        ),
    )
    split = parse_rapid(render_rapid(prog, robot=robot, max_points=3))
    assert_round_trip(split, prog, robot)
    # The timed samples still blend; the air move after the split spline is timed.
    assert split.targets[-1].duration is not None


def test_unfeasible_run_written_with_force_says_so() -> None:
    robot = abb_robot("abb_irb1600")
    prog = replace(cartesian_program(robot, Q_IRB1600), feasible=False)
    parsed = parse_rapid(render_rapid(prog, robot=robot))
    assert any("NOT feasible" in line for line in parsed.header)


def test_payload_sets_the_tool_load() -> None:
    robot = puma()
    assert robot.dynamics is not None
    payload = Payload(
        mass=2.5, com=np.array([0.0, 0.01, 0.05]), inertia=np.diag([0.01, 0.02, 0.03])
    )
    loaded = replace(robot, dynamics=replace(robot.dynamics, payload=payload))
    text = text_of(render_rapid(cartesian_program(loaded, Q_PUMA), robot=loaded))
    tool_line = next(line for line in text.splitlines() if "PERS tooldata" in line)
    load = tool_line.split("]],[", 1)[1]
    mass, rest = load.split(",", 1)
    assert float(mass) == 2.5
    cog = np.array([float(v) for v in rest[1:].split("]", 1)[0].split(",")])
    expected = (loaded.T_flange_tool @ np.array([0.0, 0.01, 0.05, 1.0]))[:3] * 1000.0
    assert cog == pytest.approx(expected, abs=1e-3)
    no_load = text_of(render_rapid(cartesian_program(robot, Q_PUMA), robot=robot))
    assert "set the tool's mass" in no_load


def test_writer_writes_the_module_into_the_folder(tmp_path: Path) -> None:
    robot = abb_robot("abb_irb2400")
    asked: dict[str, object] = {}

    def build(**options: object):
        asked.update(options)
        return cartesian_program(robot, Q_IRB2400, name=str(options["name"]))

    source = stand_in(build, robot)
    writer = RapidWriter()
    assert (writer.name, writer.suffix, writer.default_file, writer.folder) == (
        "rapid",
        ".mod",
        "rapid",
        True,
    )
    written = writer.write(source, tmp_path, name="cell 7", motion="cartesian")
    assert written == ("cell_7.mod",)
    assert asked == {"motion": "cartesian", "name": "cell 7", "period": None, "force": False}
    text = (tmp_path / "cell_7.mod").read_bytes().decode("ascii")
    assert parse_rapid({"cell_7.mod": text}).name == "cell_7"


# --- confdata -----------------------------------------------------------------------------


@pytest.mark.parametrize("name", ["abb_irb2400", "abb_irb1600"])
def test_confdata_at_the_zero_pose_is_zero(name: str) -> None:
    robot = abb_robot(name)
    zeros = np.zeros((1, 6))
    assert confdata(robot, zeros, zeros).tolist() == [[0, 0, 0, 0]]
    assert reference_confdata(robot, np.zeros(6)) == (0, 0, 0, 0)


@pytest.mark.parametrize(
    ("joints_deg", "expected"),
    [
        # py-opw-kinematics' axis-configuration tests (MIT), IRB 1660 joints: cfx 5 and 4
        # (wrist behind axis 1; axis 5 negative / positive); cf1, cf4, cf6 by quadrant.
        ([-103.1, -85.03, 19.06, -70.19, -35.87, 185.01], (-2, -1, 2, 5)),
        ([-103.1, -85.03, 19.06, 109.81, 35.87, 5.01], (-2, 1, 0, 4)),
        # Forearm folded up past the lower arm: wrist centre behind the lower arm.
        ([0.0, 0.0, -100.0, 0.0, 30.0, 0.0], (0, 0, 0, 2)),
        # ... and further, behind axis 1 too.
        ([0.0, 0.0, -120.0, 0.0, 30.0, 0.0], (0, 0, 0, 6)),
        # Quadrant edges: 90° is quadrant 1, just below 0° is quadrant −1.
        ([90.0, 0.0, 0.0, -0.001, 10.0, 270.0], (1, -1, 3, 0)),
    ],
)
def test_confdata_by_abb_definition(joints_deg: list[float], expected: tuple) -> None:
    robot = abb_robot("abb_irb1600")
    q = np.radians(joints_deg)
    assert tuple(confdata(robot, q[None], q[None])[0]) == expected
    assert reference_confdata(robot, q) == expected


def test_confdata_agrees_with_the_oracle_over_random_joints() -> None:
    rng = np.random.default_rng(7)
    for robot in (abb_robot("abb_irb2400"), abb_robot("abb_irb1600"), puma()):
        q = rng.uniform(-np.pi, np.pi, size=(200, 6))
        theta = robot.convention.to_controller(q)
        mine = confdata(robot, theta, q)
        reference = np.array([reference_confdata(robot, row) for row in q])
        assert np.array_equal(mine, reference)
        # All eight arm configurations occur.
        assert len(set(mine[:, 3].tolist())) == 8


# --- quaternions and numbers --------------------------------------------------------------


@settings(max_examples=200, deadline=None)
@given(st.integers(min_value=0, max_value=2**32 - 1))
def test_quaternion_round_trip(seed: int) -> None:
    matrix = Rotation.random(random_state=seed).as_matrix()
    q = quaternion(matrix)
    assert q[0] >= 0.0
    assert np.linalg.norm(q) == pytest.approx(1.0, abs=1e-12)
    printed = [float(number(float(v), 9)) for v in q]
    assert rotation_angle(quaternion_matrix(printed), matrix) < ANGLE_TOLERANCE / 100


@settings(max_examples=100, deadline=None)
@given(st.floats(min_value=-3000.0, max_value=3000.0, allow_nan=False))
def test_numbers_print_within_the_tolerance(value: float) -> None:
    text = number(value, 4)
    assert abs(float(text) - value) <= 5e-5
    assert text != "-0"


def test_half_turn_quaternion_has_a_unique_sign() -> None:
    flip = np.diag([1.0, -1.0, -1.0])  # π about x: q1 = 0
    assert quaternion(flip) == pytest.approx([0.0, 1.0, 0.0, 0.0])
    assert quaternion(np.diag([-1.0, -1.0, 1.0])) == pytest.approx([0.0, 0.0, 0.0, 1.0])


# --- public example programs --------------------------------------------------------------

# Written for these tests in the syntax of ABB's RAPID reference manual (MoveL, MoveC,
# MoveAbsJ with \T, predefined v/z data, tool0, named CONST targets, a PERS wobjdata, a
# procedure call). Public code (open_abb, MIT) is read further below; the complete
# RAPID programs found in the code corpora carry no licence, so none is quoted.
MANUAL_STYLE = """
MODULE Demo
  ! cell demo
  PERS tooldata tPen:=[TRUE,[[0,0,100],[1,0,0,0]],[1,[0,0,1],[1,0,0,0],0,0,0]];
  TASK PERS wobjdata wTable:=[FALSE,TRUE,"",[[300,-175,1],[1,0,0,0]],[[0,0,0],[1,0,0,0]]];
  CONST robtarget p10:=[[425,25,308],[0,-0.707106781,0.707106781,0],[0,0,0,0],
    [9E+09,9E+09,9E+09,9E+09,9E+09,9E+09]];
  CONST robtarget p20:=[[425,325,308],[0,-0.707106781,0.707106781,0],[0,0,-1,0],
    [9E+09,9E+09,9E+09,9E+09,9E+09,9E+09]];
  CONST robtarget p30:=[[25,325,308],[0,-0.707106781,0.707106781,0],[0,0,-1,0],
    [9E+09,9E+09,9E+09,9E+09,9E+09,9E+09]];
  CONST jointtarget home:=[[0,0,0,0,30,0],[9E9,9E9,9E9,9E9,9E9,9E9]];
  PROC main()
    ConfL \\Off;
    MoveAbsJ home, v1000, fine, tool0;
    draw;
    MoveAbsJ home, v500 \\T:=2.5, z10, tool0;
  ENDPROC
  PROC draw()
    movel p10, v100, z1, tPen \\WObj:=wTable;
    MoveC p20, p30, v200\\V:=250, z5, tPen\\WObj:=wTable;
    MoveL p10, v100, fine, tPen\\WObj:=wTable;
  ENDPROC
ENDMODULE
"""


def test_parser_reads_a_program_in_the_manuals_syntax() -> None:
    parsed = parse_rapid({"Demo.mod": MANUAL_STYLE})
    assert parsed.name == "Demo" and parsed.header == ["cell demo"]
    assert [t.kind for t in parsed.targets] == [
        "joint",
        "linear",
        "circular_via",
        "circular_end",
        "linear",
        "joint",
    ]
    assert [t.part for t in parsed.targets] == ["main"] + ["draw"] * 4 + ["main"]
    assert parsed.base[:3, 3] == pytest.approx([0.3, -0.175, 0.001])
    assert parsed.tool[:3, 3] == pytest.approx([0.0, 0.0, 0.1])
    assert parsed.targets[0].joints == pytest.approx(np.radians([0, 0, 0, 0, 30, 0]))
    line = parsed.targets[1]
    assert line.pose is not None
    assert line.pose[:3, 3] == pytest.approx([0.425, 0.025, 0.308])
    assert line.speed == pytest.approx(0.1) and line.zone == pytest.approx(0.001)
    assert parsed.targets[3].config == {"cf1": 0, "cf4": 0, "cf6": -1, "cfx": 0}
    assert parsed.targets[3].speed == pytest.approx(0.25)  # \V overrides v200
    assert parsed.targets[4].zone == 0.0
    assert parsed.targets[5].duration == pytest.approx(2.5)


def test_targets_are_the_planned_tcp_for_a_moved_base() -> None:
    robot = abb_robot("abb_irb2400")
    moved = BASE.copy()
    moved[:3, 3] += [0.05, -0.02, 0.01]
    target = make_target(robot, Q_IRB2400, moved)
    prog = program(
        robot,
        (
            Section(kind="start", label="start", moves=()),
            Section(kind="seam", label="s", moves=(LinearMove(target=target, speed=0.01),)),
        ),
        base=moved,
    )
    parsed = parse_rapid(render_rapid(prog, robot=robot))
    assert parsed.base[:3, 3] == pytest.approx(moved[:3, 3], abs=POSITION_TOLERANCE)
    world = forward_kinematics(robot, Q_IRB2400)
    assert (parsed.base @ parsed.targets[0].pose)[:3, 3] == pytest.approx(
        world[:3, 3], abs=POSITION_TOLERANCE
    )


def test_parser_reads_an_optional_argument_after_a_comma() -> None:
    # ros-industrial/abb (BSD-3-Clause), abb_driver/rapid/ROS_motion.mod, writes
    #   MoveAbsJ target, move_speed, \T:=trajectory{current_index}.duration, stop_mode, tool0;
    # with a comma before \T; the same form with literal data:
    text = (
        "MODULE Ros\n  CONST jointtarget target:=[[1,2,3,4,5,6],[9E9,9E9,9E9,9E9,9E9,9E9]];\n"
        "  PROC main()\n    MoveAbsJ target, v10, \\T:=0.25, z10, tool0;\n  ENDPROC\nENDMODULE\n"
    )
    (target,) = parse_rapid({"Ros.mod": text}).targets
    assert target.duration == pytest.approx(0.25) and target.zone == pytest.approx(0.01)
    assert target.joints == pytest.approx(np.radians([1, 2, 3, 4, 5, 6]))


@pytest.mark.parametrize(
    ("name", "convention"),
    [("abb_irb2400", IRB2400_CONVENTION), ("abb_irb1600", IRB1600_CONVENTION)],
)
def test_library_controller_block_is_the_sourced_convention(
    name: str, convention: ControllerConvention
) -> None:
    try:
        controller = builtin_robot(name).controller
    except CaseError:
        pytest.skip("the robot-file schema of controller: is not on this branch")
    if controller is None:
        pytest.skip("the robot file has no controller: block on this branch")
    assert controller.vendor == "abb"
    assert np.array_equal(controller.signs, convention.signs)
    assert np.array_equal(controller.offsets, convention.offsets)
    assert controller.coupling == convention.coupling
    assert np.allclose(controller.world, np.eye(4))
    assert controller.source


# Lines quoted from robotics/open_abb, RAPID/SERVER.mod (MIT License, Copyright (c) 2015
# robotics), in their order; the lines between them are left out and the Move lines
# indented less.
OPEN_ABB = r"""MODULE SERVER

!////////////////
!GLOBAL VARIABLES
!////////////////

!//Robot configuration
PERS tooldata currentTool := [TRUE,[[0,0,0],[1,0,0,0]],[0.001,[0,0,0.001],[1,0,0,0],0,0,0]];
PERS wobjdata currentWobj := [FALSE,TRUE,"",[[0,0,0],[1,0,0,0]],[[0,0,0],[1,0,0,0]]];
PERS speeddata currentSpeed;
PERS zonedata currentZone;
PERS bool startLog:=TRUE;
PERS string ipController:= "127.0.0.1"; !local IP for testing in simulation
PERS num serverPort:= 5000;
VAR robtarget cartesianTarget;
VAR jointtarget jointsTarget;
VAR robtarget circPoint;
CONST num SERVER_OK := 1;
PROC main()
    ConfL \Off;
    SingArea \Wrist;
    MoveL cartesianTarget, currentSpeed, currentZone, currentTool \WObj:=currentWobj ;
    MoveAbsJ jointsTarget, currentSpeed, currentZone, currentTool \Wobj:=currentWobj;
    MoveC circPoint, cartesianTarget, currentSpeed, currentZone, currentTool \WObj:=currentWobj ;
ENDPROC
ENDMODULE
"""


def test_parser_reads_public_declarations_and_instructions() -> None:
    (module,) = parse_modules(OPEN_ABB)
    assert module.name == "SERVER"
    tool, wobj = module.data["currenttool"], module.data["currentwobj"]
    assert tool[0] is True and np.allclose(pose_matrix(tool[1]), np.eye(4))
    assert tool[2][0] == pytest.approx(0.001)
    assert wobj[:3] == [False, True, ""] and np.allclose(pose_matrix(wobj[3]), np.eye(4))
    assert module.data["currentspeed"] is None and module.data["serverport"] == 5000.0
    assert module.data["iPController".lower()] == "127.0.0.1"
    calls = module.procs["main"]
    assert [call.name for call in calls] == ["ConfL", "SingArea", "MoveL", "MoveAbsJ", "MoveC"]
    assert calls[0].options == {"off": True} and calls[1].options == {"wrist": True}
    move_c = calls[4]
    assert [arg.text for arg in move_c.args] == [
        "circPoint",
        "cartesianTarget",
        "currentSpeed",
        "currentZone",
        "currentTool",
    ]
    assert all(isinstance(call.options["wobj"], Name) for call in calls[2:])
