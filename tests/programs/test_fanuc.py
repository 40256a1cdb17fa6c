"""FANUC TP export: programs built by hand, rendered, and read back by the test parser.

Every target read back must be the program's within 0.01 mm and 0.001° (poses) and 1e-6 rad
(joints); the CONFIG fields must equal the reference definition in ``fanuc_reference``.
"""

from __future__ import annotations

import re
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
import yaml
from hypothesis import given, settings
from hypothesis import strategies as st

import trackplan.robots
from tests.programs.fanuc_parser import parse_fanuc, read_listing, wpr_pose
from tests.programs.fanuc_reference import fanuc_config, turn
from tests.programs.parsed import ParsedProgram
from tests.programs.programs import joint_form, joint_move, make_target, program, vendor_robot
from tests.programs.roundtrip import (
    ANGLE_TOLERANCE,
    JOINT_TOLERANCE,
    POSITION_TOLERANCE,
    assert_joint_timing,
    assert_matches_plan,
    assert_same_targets,
    frame_difference,
    target_pairs,
)
from tests.programs.stand_in import stand_in
from trackplan.errors import CaseError
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
from trackplan.writers.fanuc import (
    COMMENT_WIDTH,
    NAME_LENGTH,
    FanucOptions,
    FanucWriter,
    render_fanuc,
)
from trackplan.writers.fanuc_config import turn_numbers, wpr_from_matrix, xyzwpr

LIBRARY = Path(trackplan.robots.__file__).parent / "library" / "fanuc_m20ia.yaml"

M20IA_WORLD = np.eye(4)
M20IA_WORLD[2, 3] = 0.525
M20IA_CONVENTION = ControllerConvention(
    vendor="fanuc",
    signs=np.ones(6),
    offsets=np.zeros(6),
    coupling=(2, 1, -1.0),
    world=M20IA_WORLD,
    source=(
        "ros-industrial/fanuc: fanuc_m20ia_support robot_interface_streaming_m20ia.launch "
        "(J23_factor 1), fanuc_driver fanuc_joint_streamer_node.cpp (to the controller "
        "J3 = q3 - J23_factor q2), m20ia_macro.xacro (base_link-base: z 0.525 m)"
    ),
)
"""The M-20iA's controller convention, as its robot file's ``controller:`` block states it."""


def frame(xyz: tuple[float, float, float], rpy_deg: tuple[float, float, float]) -> np.ndarray:
    """A pose from a position (m) and W, P, R (deg)."""
    return wpr_pose([*(1000.0 * np.asarray(xyz)), *rpy_deg])


PART_M20IA = frame((1.3, -0.2, 0.3), (0.0, 0.0, 20.0))
PART_PUMA = frame((0.45, 0.1, -0.2), (0.0, 0.0, -10.0))
TOOL = frame((0.01, 0.0, 0.18), (0.0, 30.0, 0.0))


def m20ia(tool: np.ndarray = TOOL) -> Robot:
    """The built-in M-20iA with the tests' controller convention and ``tool``."""
    return vendor_robot("fanuc_m20ia", M20IA_CONVENTION, tool)


def puma() -> Robot:
    """The PUMA560 with :data:`TOOL`: generic vendor, identity convention."""
    return vendor_robot("puma560", None, TOOL)


def target(robot: Robot, part: np.ndarray, q: np.ndarray) -> Target:
    """The target of model joints ``q``: the TCP in the part frame ``part`` (given in the
    model's base)."""
    return make_target(robot, q, robot.convention.world_from_base(part))


def cartesian_program(
    robot: Robot, part: np.ndarray, q0: np.ndarray, *, name: str = "weld_seam", vendor: str = ""
) -> Program:
    """A start, a seam of a line, an arc and a spline, an air move and a second seam."""
    step = np.array([0.02, -0.015, 0.02, 0.05, 0.03, -0.04])
    qs = [q0 + k * step for k in range(14)]
    t = [target(robot, part, q) for q in qs]
    seam_1 = Section(
        kind="seam",
        label="seam 1",
        moves=(
            LinearMove(target=t[1], speed=0.012),
            CircularMove(via=t[2], target=t[3], speed=0.012, zone=0.0005),
            SplineMove(targets=tuple(t[4:9]), speed=0.015, zone=0.0003),
        ),
    )
    air = Section(kind="air", label="air", moves=(joint_move(robot, qs[9], speed=0.3),))
    seam_2 = Section(
        kind="seam",
        label="seam 2",
        moves=(
            LinearMove(target=t[10], speed=0.01),
            LinearMove(target=t[11], speed=0.01, zone=0.0005),
            CircularMove(via=t[12], target=t[13], speed=0.008),
        ),
    )
    start = Section(kind="start", label="start", moves=(joint_move(robot, qs[0], speed=0.25),))
    return program(
        robot,
        (start, seam_1, air, seam_2),
        base=robot.convention.world_from_base(part),
        name=name,
        header=("trackplan test", "case: weld_seam", "verdict: feasible; duration 4.2 s"),
        vendor=vendor or robot.convention.vendor,
    )


def joint_program(robot: Robot, q0: np.ndarray, n: int = 25, period: float = 0.024) -> Program:
    """The joint form: a start move and ``n`` timed samples."""
    samples = q0 + np.outer(np.linspace(0.0, 1.0, n), [0.3, -0.2, 0.25, 1.0, 0.4, -3.5])
    return joint_form(
        robot,
        samples,
        period=period,
        start_speed=0.2,
        base=np.eye(4),
        name="replay",
        header=("trackplan test", "form: joint"),
        sample_time=0.008,
    )


Q0_M20IA = np.array([0.15, 0.35, 0.1, 0.4, -0.9, 0.2])
Q0_PUMA = np.array([0.2, -0.6, 0.4, 0.3, 0.8, -0.2])


def assert_pose_close(actual: np.ndarray, wanted: np.ndarray) -> None:
    distance, angle = frame_difference(actual, wanted)
    assert distance < POSITION_TOLERANCE and angle < ANGLE_TOLERANCE


def assert_reads_back(program: Program, parsed: ParsedProgram, robot: Robot) -> None:
    """The shared round trip (spline points as lines), joint moves' speeds and times as TP
    prints them (0.5 %, 0.5 ms), every CONFIG as the reference's and every TCP speed."""
    assert_matches_plan(parsed, program, robot, spline_as="linear")
    assert_joint_timing(parsed, program, speed=0.005, duration=5e-4)
    for read, wanted in target_pairs(parsed, program):
        if wanted.pose is not None:
            assert read.config == fanuc_config(robot, wanted.model_joints, wanted.joints)
    speeds = [move.speed for move in program.moves() if not isinstance(move, JointMove)]
    read_speeds = [t.speed for t in parsed.targets if t.kind != "joint" and t.speed is not None]
    assert len(read_speeds) >= len(speeds)
    assert set(np.round(read_speeds, 4)) == set(np.round(speeds, 4))


@pytest.mark.parametrize(
    ("make_robot", "part", "q0"),
    [(m20ia, PART_M20IA, Q0_M20IA), (puma, PART_PUMA, Q0_PUMA)],
    ids=["fanuc_m20ia", "puma560"],
)
def test_cartesian_program_reads_back(make_robot, part, q0) -> None:  # type: ignore[no-untyped-def]
    robot = make_robot()
    program = cartesian_program(robot, part, q0)
    files = render_fanuc(program, robot=robot)
    assert list(files) == ["WELD_SEA.ls"]
    parsed = parse_fanuc(files)
    assert parsed.name == "WELD_SEA"
    assert_reads_back(program, parsed, robot)
    assert parsed.header[:3] == [line.replace(";", ",") for line in program.header]


def test_m20ia_joints_follow_the_j2_j3_coupling_and_the_world_at_j2_height() -> None:
    robot = m20ia()
    program = cartesian_program(robot, PART_M20IA, Q0_M20IA)
    start = parse_fanuc(render_fanuc(program, robot=robot)).targets[0]
    assert start.joints is not None
    # FANUC J3 counts from the horizontal: θ3 = q3 − q2 (fanuc_driver, J23_factor 1)
    assert start.joints[2] == pytest.approx(Q0_M20IA[2] - Q0_M20IA[1], abs=JOINT_TOLERANCE)
    assert np.delete(start.joints, 2) == pytest.approx(np.delete(Q0_M20IA, 2), abs=JOINT_TOLERANCE)
    # the user frame is the part in the FANUC world, 0.525 m above the model's base
    assert program.base[2, 3] == pytest.approx(PART_M20IA[2, 3] - 0.525)


@pytest.mark.parametrize(
    ("make_robot", "q0"), [(m20ia, Q0_M20IA), (puma, Q0_PUMA)], ids=["fanuc_m20ia", "puma560"]
)
def test_joint_form_reads_back_as_timed_joint_moves(make_robot, q0) -> None:  # type: ignore[no-untyped-def]
    robot = make_robot()
    program = joint_program(robot, q0)
    files = render_fanuc(program, robot=robot)
    text = files["REPLAY.ls"]
    assert re.search(r":J P\[2\] 0\.024sec CNT100 ;$", text, re.M)
    assert re.search(r":J P\[25\] 0\.024sec FINE ;$", text, re.M)  # stops at the end
    assert "CONFIG" not in text
    parsed = parse_fanuc(files)
    assert_reads_back(program, parsed, robot)
    assert [t.zone for t in parsed.targets[1:]] == [None] * 23 + [0.0]


def test_joints_print_to_a_ten_thousandth_of_a_degree() -> None:
    robot = m20ia()
    q0 = Q0_M20IA + np.array([1e-7, 3.3e-7, -7.7e-7, 2.2e-7, 1e-8, 9.9e-7])
    program = joint_program(robot, q0, n=3)
    text = render_fanuc(program, robot=robot)["REPLAY.ls"]
    assert re.search(r"J1= +\d+\.\d{4} deg", text)
    parsed = parse_fanuc({"REPLAY.ls": text})
    assert parsed.targets[0].joints is not None
    assert np.max(np.abs(parsed.targets[0].joints - program.sections[0].moves[0].joints)) < 1e-6


@pytest.mark.parametrize("max_points", [2, 3, 5, 7])
def test_a_split_program_reads_back_as_the_unsplit_one(max_points: int) -> None:
    robot = m20ia()
    program = cartesian_program(robot, PART_M20IA, Q0_M20IA)
    whole = parse_fanuc(render_fanuc(program, robot=robot))
    files = render_fanuc(program, robot=robot, max_points=max_points)
    assert len(files) > 2
    main, *parts = files
    assert main == "WELD_SEA.ls"
    calls = re.findall(r"CALL (\w+) ;", files[main])
    assert [f"{name}.ls" for name in calls] == parts
    for name in calls:
        assert len(name) <= NAME_LENGTH
        assert re.fullmatch(r"[A-Z][A-Z0-9_]*", name)
    for part in parts:
        assert len(read_listing(files[part]).positions) <= max_points
    split = parse_fanuc(files)
    assert_reads_back(program, split, robot)
    assert_same_targets(split, whole)
    assert [t.part for t in split.targets] == sorted(t.part for t in split.targets)


def test_the_name_is_an_upper_case_tp_name_of_eight_characters() -> None:
    robot = m20ia()
    program = cartesian_program(robot, PART_M20IA, Q0_M20IA, name="Naht ü-3 lang")
    files = render_fanuc(program, robot=robot)
    assert list(files) == ["NAHT_U_3.ls"]
    assert files["NAHT_U_3.ls"].startswith("/PROG  NAHT_U_3\n/ATTR\n")
    assert parse_fanuc(files).name == "NAHT_U_3"


def test_a_name_that_cannot_be_a_tp_name_is_refused() -> None:
    robot = m20ia()
    program = cartesian_program(robot, PART_M20IA, Q0_M20IA, name="1234 !!")
    with pytest.raises(CaseError, match="--name"):
        render_fanuc(program, robot=robot)


def test_a_robot_of_another_vendor_is_refused() -> None:
    robot = m20ia()
    program = cartesian_program(robot, PART_M20IA, Q0_M20IA, vendor="kuka")
    with pytest.raises(CaseError, match=r"TP drives FANUC .* KUKA controller: use --format krl$"):
        render_fanuc(program, robot=robot)


def test_more_joints_than_a_tp_group_is_refused() -> None:
    robot = m20ia()
    program = replace(joint_program(robot, Q0_M20IA, n=3), n_dof=7)
    with pytest.raises(CaseError, match=r"--format: TP drives 1 to 6 robot axes, .* has 7 joints"):
        render_fanuc(program, robot=robot)


def test_cartesian_moves_of_a_robot_without_six_axes_are_refused() -> None:
    robot = m20ia()
    program = replace(cartesian_program(robot, PART_M20IA, Q0_M20IA), n_dof=5)
    with pytest.raises(CaseError, match=r"--format: .*5 joints: use --motion joint"):
        render_fanuc(program, robot=robot)


def test_fewer_than_two_positions_per_file_is_refused() -> None:
    robot = m20ia()
    program = cartesian_program(robot, PART_M20IA, Q0_M20IA)
    with pytest.raises(CaseError, match=r"^--max-points: .*at least 2, got 1"):
        render_fanuc(program, robot=robot, max_points=1)


@pytest.mark.parametrize(
    ("key", "value"), [("uframe", 0), ("utool", 1000), ("register", -1), ("cnt", 101)]
)
def test_frame_register_and_cnt_numbers_out_of_range_are_refused(key: str, value: int) -> None:
    with pytest.raises(CaseError, match=f"^{key}: "):
        FanucOptions(**{key: value})


def test_header_and_comments_stay_within_the_comment_width() -> None:
    robot = m20ia()
    program = cartesian_program(robot, PART_M20IA, Q0_M20IA)
    text = render_fanuc(program, robot=robot, options=FanucOptions(uframe=3, utool=4))[
        "WELD_SEA.ls"
    ]
    comments = re.findall(r"^\s+\d+:  ! (.*) ;$", text, re.M)
    assert comments and all(len(c) <= COMMENT_WIDTH for c in comments)
    assert "UFRAME[3]=PR[9]" in text and "UTOOL[4]=PR[9]" in text
    assert re.search(r"UFRAME_NUM=3 ;\n.*UTOOL_NUM=4 ;", text)
    assert "UF : 3, UT : 4" in text
    assert "e-" not in text and "-0.000 " not in text
    text.encode("ascii")


def test_the_writer_writes_ascii_files_of_the_sources_program(tmp_path: Path) -> None:
    robot = m20ia()
    program = cartesian_program(robot, PART_M20IA, Q0_M20IA)
    asked: dict[str, object] = {}

    def build(**kwargs: object) -> Program:
        asked.update(kwargs)
        return program

    source = stand_in(build, robot)
    writer = FanucWriter()
    names = writer.write(source, tmp_path, max_points=4, uframe=2)
    assert asked == {"motion": "cartesian", "name": None, "period": None, "force": False}
    assert names[0] == "WELD_SEA.ls" and len(names) > 2
    files = {name: (tmp_path / name).read_text(encoding="ascii") for name in names}
    assert_reads_back(program, parse_fanuc(files), robot)
    assert "UFRAME_NUM=2" in files[names[0]]
    assert (writer.name, writer.folder, writer.default_file) == ("fanuc", True, "fanuc")


def test_the_robot_files_controller_block_is_the_tests_convention() -> None:
    block = yaml.safe_load(LIBRARY.read_text()).get("controller")
    if block is None:
        pytest.skip("the robot file has no controller block yet")
    assert block["vendor"] == "fanuc"
    coupling = block["coupling"]
    assert (coupling["joint"] - 1, coupling["driver"] - 1, coupling["factor"]) == (2, 1, -1.0)
    assert block["world"]["xyz"] == [0, 0, 0.525]
    assert block["world"].get("rpy", [0, 0, 0]) == [0, 0, 0]


# --- conventions -------------------------------------------------------------------------


@st.composite
def rotations(draw: st.DrawFn) -> np.ndarray:
    """Random rotations (unit quaternions), and some at the gimbal lock P = ±90°."""
    if draw(st.booleans()):
        w, r = draw(st.floats(-180, 180)), draw(st.floats(-180, 180))
        return wpr_pose([0, 0, 0, w, draw(st.sampled_from([-90.0, 90.0])), r])[:3, :3]
    q = np.array([draw(st.floats(-1, 1)) for _ in range(4)])
    if np.linalg.norm(q) < 1e-3:
        q = np.array([1.0, 0.0, 0.0, 0.0])
    a, b, c, d = q / np.linalg.norm(q)
    return np.array(
        [
            [a * a + b * b - c * c - d * d, 2 * (b * c - a * d), 2 * (b * d + a * c)],
            [2 * (b * c + a * d), a * a - b * b + c * c - d * d, 2 * (c * d - a * b)],
            [2 * (b * d - a * c), 2 * (c * d + a * b), a * a - b * b - c * c + d * d],
        ]
    )


@settings(max_examples=200, deadline=None)
@given(rotations())
def test_w_p_r_compose_back_to_the_rotation(rotation: np.ndarray) -> None:
    w, p, r = wpr_from_matrix(rotation)
    assert -90.0 <= p <= 90.0
    back = wpr_pose([0.0, 0.0, 0.0, w, p, r])[:3, :3]
    # near P = ±90° the angles are ill-conditioned: they compose back within 5e-8 of a
    # rounded rotation matrix (trackplan.frames.GIMBAL_LOCK), far below the 1e-4° printed
    assert np.max(np.abs(back - rotation)) < 1e-7


@settings(max_examples=100, deadline=None)
@given(st.lists(st.floats(-700.0, 700.0), min_size=1, max_size=20))
def test_turn_numbers_count_whole_turns_from_zero(angles: list[float]) -> None:
    assert turn_numbers(np.array(angles)).tolist() == [turn(a) for a in angles]


def test_turn_numbers_at_the_half_turns() -> None:
    angles = np.array([-540.0, -180.0, -179.999, 0.0, 179.999, 180.0, 539.999, 540.0])
    assert turn_numbers(angles).tolist() == [-2, -1, 0, 0, 0, 1, 1, 2]


def test_xyzwpr_of_the_m20ia_zero_pose_is_fanucs() -> None:
    # at all joints zero the M-20iA's faceplate is at X 1085, Z 1040 mm in the FANUC world,
    # W 180, P -90, R 0 (tool0 of ros-industrial fanuc_m20ia_support)
    robot = m20ia(tool=np.eye(4))
    flange = robot.convention.world_from_base(forward_kinematics(robot, np.zeros(6)))
    values = xyzwpr(flange)
    assert values[:3] == pytest.approx([1085.0, 0.0, 1040.0], abs=1e-6)
    assert_pose_close(wpr_pose(list(values)), wpr_pose([1085.0, 0.0, 1040.0, 180.0, -90.0, 0.0]))


def test_config_of_the_m20ia_at_home_is_n_u_t() -> None:
    robot = m20ia()
    q = np.array([0.0, 0.0, 0.0, 0.0, -0.5, 0.0])
    assert fanuc_config(robot, q, robot.convention.to_controller(q)) == {
        "flip": "N",
        "elbow": "U",
        "front": "T",
        "turns": (0, 0, 0),
    }
    # the wrist flipped, the arm reaching over its back, J6 a turn further
    q = np.array([0.0, -1.2, 1.3, 0.0, 0.5, 3.5])
    config = fanuc_config(robot, q, robot.convention.to_controller(q))
    assert (config["flip"], config["front"], config["turns"]) == ("F", "B", (0, 0, 1))


def test_the_writers_config_equals_the_reference_over_random_configurations() -> None:
    robot = m20ia()
    rng = np.random.default_rng(28)
    span = np.minimum(np.abs(robot.q_min), robot.q_max) * 0.95
    qs = rng.uniform(-span, span, size=(60, 6))
    targets = tuple(target(robot, PART_M20IA, q) for q in qs)
    program = replace(
        cartesian_program(robot, PART_M20IA, Q0_M20IA),
        sections=(
            Section(kind="seam", label="random", moves=(SplineMove(targets=targets, speed=0.01),)),
        ),
    )
    parsed = parse_fanuc(render_fanuc(program, robot=robot))
    configs = [t.config for t in parsed.targets]
    assert configs == [fanuc_config(robot, t.model_joints, t.joints) for t in targets]
    assert {c["elbow"] for c in configs} == {"U", "D"}
    assert {c["flip"] for c in configs} == {"F", "N"}


# --- public example programs ---------------------------------------------------------

# KonstantynBely/karelCalibration, src/tp/CAL_DV_XY.ls (MIT licence), lines 1-23 as
# published; the closing "/POS" and "/END" lines are added here.
KAREL_CALIBRATION = """/PROG  CAL_DV_XY
/ATTR
OWNER       = MNEDZA;
COMMENT     = "Calibration XY program";
PROG_SIZE   = 0;
CREATE      = DATE 12-05-25  TIME 10:00:00;
MODIFIED    = DATE 12-05-25  TIME 10:00:00;
FILE_NAME   = CAL_DV_XY;
VERSION     = 0;
LINE_COUNT  = 29;
MEMORY_SIZE = 0;
PROTECT     = READ_WRITE;
/MN
  1:  UTOOL_NUM = 0 ;
  2:  UFRAME_NUM = 0 ;
  3:  PR[10] = LPOS ;
  4:  CALL CALPRXY ;

  5:  J PR[11] 25% FINE ;
  6:  SKIP CONDITION DI[1]=ON ;
  7:  L PR[12] 10mm/sec FINE Skip,LBL[999] ;
  8:  PR[21] = LPOS ;
  9:  J PR[11] 25% FINE ;
/POS
/END
"""

# ros-industrial-attic/robodk_postprocessors, Fanuc_R30iA.py (Apache-2.0): its "syntax
# examples" of /POS records, quoted; the /PROG, /ATTR and /MN lines around them are ours.
ROBODK_RECORDS = """/PROG  EXAMPLE
/ATTR
OWNER		= MNEDITOR;
/MN
   1:J P[1] 20% FINE ;
   2:J P[258] 20% FINE ;
   3:L P[2] 500mm/sec CNT50 ;
   4:C P[8:]
    :  P[2] 100mm/sec FINE ;
/POS
P[1]{
   GP1:
    UF : 1, UT : 1,
    J1=    0.000 deg,    J2=    -40.966 deg,    J3=    43.328 deg,
    J4=    0.000 deg,    J5=    -84.792 deg,    J6=    180.000 deg
};
P[258]{
   GP1:
    UF : 6, UT : 4,
    J1=   -41.180 deg,    J2=   -26.810 deg,    J3=    11.060 deg,
    J4=  -217.400 deg,    J5=    71.740 deg,    J6=    85.790 deg,
    E1=     0.000 deg
};
P[2]{
   GP1:
    UF : 1, UT : 1,        CONFIG : 'F U T, 0, 0, 0',
    X =   564.871  mm,    Y =     0.000  mm,    Z =   571.832  mm,
    W =  -180.000 deg,    P =     0.000 deg,    R =  -180.000 deg
};
P[8:]{
   GP1:
     UF : 9, UT : 8,      CONFIG : 'N D B, 0, 0, 0',
     X =     0.000  mm,   Y =   -10.000  mm,   Z =     0.000  mm,
     W =     0.000 deg,   P =     0.000 deg,   R =     0.000 deg
   GP2:
     UF : 9, UT : 2,
     J1=     0.000 deg,   J2=     0.000 deg
};
/END
"""


def test_the_parser_reads_a_public_calibration_program() -> None:
    listing = read_listing(KAREL_CALIBRATION)
    assert listing.name == "CAL_DV_XY"
    kinds = [kind for kind, _ in listing.statements]
    assert kinds.count("motion") == 3 and kinds.count("call") == 1
    parsed = parse_fanuc({"CAL_DV_XY.ls": KAREL_CALIBRATION}, strict=False)
    assert [t.kind for t in parsed.targets] == ["joint", "linear", "joint"]
    assert [t.speed for t in parsed.targets] == [0.25, 0.01, 0.25]
    assert all(t.zone == 0.0 and t.pose is None for t in parsed.targets)


def test_the_parser_reads_robodks_position_records() -> None:
    parsed = parse_fanuc({"EXAMPLE.ls": ROBODK_RECORDS})
    kinds = [t.kind for t in parsed.targets]
    assert kinds == ["joint", "joint", "linear", "circular_via", "circular_end"]
    first, second, line, via, _ = parsed.targets
    assert first.joints is not None and second.joints is not None
    assert np.degrees(first.joints) == pytest.approx([0, -40.966, 43.328, 0, -84.792, 180])
    assert np.degrees(second.joints[3]) == pytest.approx(-217.4)
    assert line.config == {"flip": "F", "elbow": "U", "front": "T", "turns": (0, 0, 0)}
    assert line.pose is not None
    assert line.pose[:3, 3] == pytest.approx([0.564871, 0.0, 0.571832])
    assert line.pose[:3, :3] == pytest.approx(np.diag([-1.0, 1.0, -1.0]), abs=1e-12)
    assert via.config == {"flip": "N", "elbow": "D", "front": "B", "turns": (0, 0, 0)}
    assert line.zone is None and line.speed == pytest.approx(0.5)
