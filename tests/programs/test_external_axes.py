"""External axes (a track, a positioner) in the controller programs: every target's
external values written and read back by each language's own parser, the coordinated base
with a positioner, and the refusals (``docs/export.md``, *External axes*)."""

from __future__ import annotations

import json
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest
import yaml

import trackplan
from tests.programs.external_programs import (
    CARRIER_PART,
    ROTATE,
    TILT,
    TRACK,
    with_external,
    written_units,
)
from tests.programs.fanuc_parser import parse_fanuc
from tests.programs.krl_parser import parse_krl
from tests.programs.parsed import ParsedProgram
from tests.programs.rapid_parser import parse_rapid
from tests.programs.rapid_programs import cartesian_program, joint_program, puma
from tests.programs.roundtrip import POSITION_TOLERANCE, frame_difference, target_pairs
from tests.programs.stand_in import stand_in
from tests.programs.urscript_programs import cartesian_program as ur_cartesian_program
from tests.programs.urscript_programs import ur_robot
from trackplan.errors import CaseError
from trackplan.io.export import TrajectoryTable
from trackplan.programs.model import ExternalAxis, Program
from trackplan.robots.model import Robot
from trackplan.writers import ExportSource
from trackplan.writers.fanuc import render_fanuc
from trackplan.writers.krl import render_krl
from trackplan.writers.rapid import render_rapid
from trackplan.writers.urscript import render_urscript

Q0 = np.array([0.2, -0.6, 0.4, 0.3, 0.8, -0.2])

Render = Callable[[Program, Robot], dict[str, str]]
Parse = Callable[[dict[str, str]], ParsedProgram]

LANGUAGES: dict[str, tuple[Render, Parse, float, float]] = {
    # render, parse, and half the last printed decimal of mm and of degrees
    "krl": (lambda p, r: render_krl(p, robot=r), parse_krl, 0.5e-4, 0.5e-6),
    "rapid": (lambda p, r: render_rapid(p, robot=r), parse_rapid, 0.5e-4, 0.5e-6),
    "fanuc": (lambda p, r: render_fanuc(p, robot=r), parse_fanuc, 0.5e-3, 0.5e-4),
}

TRACK_ONLY = (TRACK,)
TRACK_AND_POSITIONER = (TRACK, TILT, ROTATE)
POSITIONER_ONLY = (TILT, ROTATE)


def source(robot: Robot, motion: str, axes: tuple[ExternalAxis, ...]) -> Program:
    """The hand-built program of one form with ``axes``; with a positioner its base is
    the part on the positioner's flange."""
    program = cartesian_program(robot, Q0) if motion == "cartesian" else joint_program(robot, Q0)
    coordinated = any(axis.kind == "positioner" for axis in axes)
    return with_external(program, axes, base=CARRIER_PART if coordinated else None)


def assert_external_read_back(
    parsed: ParsedProgram, program: Program, mm: float, deg: float
) -> None:
    """Every target read back carries the program's external values, in mm and degrees,
    within the print precision (``mm``, ``deg``: half the last printed decimal)."""
    axes = program.external_axes
    tolerance = np.array([mm if axis.kind == "track" else deg for axis in axes]) * (1 + 1e-9)
    pairs = target_pairs(parsed, program)
    assert pairs
    for k, (got, want) in enumerate(pairs):
        expected = written_units(axes, want.external)
        assert got.external.shape == expected.shape, f"target {k}: {got.external}"
        error = np.abs(got.external - expected)
        assert np.all(error <= tolerance + 1e-12 * np.abs(expected)), (
            f"target {k} ({want.kind}): read {got.external}, wrote {expected}"
        )


CASES = [
    pytest.param(language, motion, axes, id=f"{language}-{motion}-{name}")
    for language in sorted(LANGUAGES)
    for motion in ("cartesian", "joint")
    for name, axes in (
        ("track", TRACK_ONLY),
        ("both", TRACK_AND_POSITIONER),
        ("positioner", POSITIONER_ONLY),
    )
    # TP refuses path moves with a positioner (test_tp_refuses_path_moves_...)
    if not (language == "fanuc" and motion == "cartesian" and name != "track")
]


@pytest.mark.parametrize(("language", "motion", "axes"), CASES)
def test_every_target_carries_its_external_axes(
    language: str, motion: str, axes: tuple[ExternalAxis, ...]
) -> None:
    render, parse, mm, deg = LANGUAGES[language]
    robot = puma()
    program = source(robot, motion, axes)
    parsed = parse(render(program, robot))
    assert_external_read_back(parsed, program, mm, deg)


def test_krl_maps_track_and_positioner_to_e1_e2_e3_in_mm_and_degrees() -> None:
    robot = puma()
    program = source(robot, "joint", TRACK_AND_POSITIONER)
    files = render_krl(program, robot=robot)
    text = "\n".join(files.values())
    first = next(line for line in text.splitlines() if line.startswith("DECL E6AXIS XJ1="))
    assert ",E1 1234.5678," in first  # the track: 1.2345678 m
    assert ",E2 -155.746" in first  # the tilt: -2.7182818 rad
    assert "E4" not in first
    assert "E1 = track (mm), E2 = tilt (deg), E3 = rotate (deg)" in text
    assert "$VEL_EXTAX[3] = " in text and "$VEL_EXTAX[4]" not in text


def test_krl_cartesian_with_a_positioner_couples_the_base_through_ek() -> None:
    robot = puma()
    program = source(robot, "cartesian", TRACK_AND_POSITIONER)
    files = render_krl(program, robot=robot)
    parsed = parse_krl(files)
    assert parsed.coupled == "MACHINE_DEF[2]"
    distance, angle = frame_difference(parsed.base, CARRIER_PART)
    assert distance < POSITION_TOLERANCE and angle < 1e-8
    main = next(text for name, text in files.items() if name.endswith(".src"))
    assert "$BASE = EK(MACHINE_DEF[2].ROOT, MACHINE_DEF[2].MECH_TYPE, TPBASE)" in main
    assert "$ACT_EX_AX = 3" in main
    assert "; KRL: $BASE = the part frame on the positioner's flange," in main


def test_krl_with_a_track_only_keeps_its_fixed_base() -> None:
    robot = puma()
    parsed = parse_krl(render_krl(source(robot, "cartesian", TRACK_ONLY), robot=robot))
    assert parsed.coupled == ""


def test_rapid_with_a_positioner_moves_the_work_object_with_stn_1() -> None:
    robot = puma()
    program = source(robot, "cartesian", TRACK_AND_POSITIONER)
    (text,) = render_rapid(program, robot=robot).values()
    parsed = parse_rapid({"m.mod": text})
    assert parsed.coupled == "STN_1"
    assert (
        'wobjdata wobj_weld_cell:=[FALSE,FALSE,"STN_1",[[0,0,0],[1,0,0,0]],[[50,-20,120],' in text
    )
    distance, angle = frame_difference(parsed.base, CARRIER_PART)
    assert distance < POSITION_TOLERANCE and angle < 1e-8
    robtarget = next(line for line in text.splitlines() if "MoveL [[" in line)
    assert robtarget.count("9E+09") == 3  # eax_d … eax_f unused


def test_rapid_with_a_track_keeps_a_fixed_work_object() -> None:
    robot = puma()
    (text,) = render_rapid(source(robot, "cartesian", TRACK_ONLY), robot=robot).values()
    assert parse_rapid({"m.mod": text}).coupled == ""
    assert 'wobjdata wobj_weld_cell:=[FALSE,TRUE,"",' in text


def test_tp_writes_a_track_as_e1_and_a_positioner_as_group_2() -> None:
    robot = puma()
    files = render_fanuc(source(robot, "joint", TRACK_AND_POSITIONER), robot=robot)
    (text,) = files.values()
    assert "DEFAULT_GROUP\t= 1,1,*,*,*;" in text
    assert "\tE1=     1234.568  mm\n   GP2:\n" in text
    assert parse_fanuc(files).coupled == "GP2"
    (track_only,) = render_fanuc(source(robot, "cartesian", TRACK_ONLY), robot=robot).values()
    assert "DEFAULT_GROUP\t= 1,*,*,*,*;" in track_only and "GP2" not in track_only


def test_tp_refuses_path_moves_with_a_positioner_in_one_line() -> None:
    robot = puma()
    with pytest.raises(CaseError) as raised:
        render_fanuc(source(robot, "cartesian", TRACK_AND_POSITIONER), robot=robot)
    assert raised.value.key == "--motion"
    assert "use --motion joint" in str(raised.value) and "\n" not in str(raised.value)


def test_urscript_refuses_external_axes_in_one_line() -> None:
    robot = ur_robot()
    program = with_external(ur_cartesian_program(robot), TRACK_ONLY)
    with pytest.raises(CaseError) as raised:
        render_urscript(program, robot=robot)
    message = str(raised.value)
    assert raised.value.key == "--format"
    assert "Universal Robots controllers drive no external axes" in message
    assert "track" in message and "\n" not in message


def test_more_external_axes_than_a_language_writes_are_refused() -> None:
    robot = puma()
    axes = (
        TRACK,
        *(ExternalAxis(name=f"p{i}", kind="positioner", unit="rad", v_max=1.0) for i in range(6)),
    )
    program = source(robot, "joint", axes)
    for render in (render_krl, render_rapid):
        with pytest.raises(CaseError, match="at most 6 external axes"):
            render(program, robot=robot)


def test_arm_only_programs_state_no_external_axes() -> None:
    robot = puma()
    program = cartesian_program(robot, Q0)
    text = "\n".join(render_krl(program, robot=robot).values())
    assert "E1" not in text and "EK(" not in text
    (rapid,) = render_rapid(program, robot=robot).values()
    assert "[9E+09,9E+09,9E+09,9E+09,9E+09,9E+09]" in rapid


def test_the_trajectory_exports_carry_every_axis_by_name(tmp_path: Path) -> None:
    """csv, json and ros write the external axes as joints after the arm's, named."""
    names = ("j1", "j2", "j3", "j4", "j5", "j6", "track", "tilt", "rotate")
    k, n = 5, len(names)
    q = np.arange(k * n, dtype=float).reshape(k, n) / 7.0
    table = TrajectoryTable(
        joint_names=names,
        t=np.arange(k) * 0.004,
        q=q,
        qd=q / 2.0,
        qdd=q / 3.0,
        qddd=q / 4.0,
        tool_position=np.zeros((k, 3)),
        speed=np.zeros(k),
    )
    source = ExportSource(table=table)
    csv_file = trackplan.export(source, tmp_path / "t.csv", format="csv")
    rows = np.loadtxt(csv_file, delimiter=",", skiprows=1)
    assert csv_file.read_text().splitlines()[0] == "t," + ",".join(names)
    np.testing.assert_allclose(rows[:, 1:], q, rtol=1e-15)
    content = json.loads(trackplan.export(source, tmp_path / "t.json", format="json").read_text())
    assert content["joint_names"] == list(names)
    np.testing.assert_allclose(content["positions"], q, rtol=1e-15)
    ros_file = trackplan.export(source, tmp_path / "t.yaml", format="ros")
    message = yaml.load(ros_file.read_text(), Loader=getattr(yaml, "CSafeLoader", yaml.SafeLoader))
    assert message["joint_names"] == list(names)
    np.testing.assert_allclose([p["positions"] for p in message["points"]], q, rtol=1e-15)


@pytest.mark.parametrize(
    ("format", "motion", "key"),
    [("urscript", "cartesian", "--format"), ("fanuc", "cartesian", "--motion")],
)
def test_an_export_that_refuses_writes_nothing(
    tmp_path: Path, format: str, motion: str, key: str
) -> None:
    """Through ``trackplan.export``: one CaseError (exit 2 on the command line), no file."""
    robot = ur_robot() if format == "urscript" else puma()

    def build(**_: object) -> Program:
        if format == "urscript":
            return with_external(ur_cartesian_program(robot), TRACK_ONLY)
        return source(robot, motion, TRACK_AND_POSITIONER)

    output = tmp_path / "out"
    with pytest.raises(CaseError) as raised:
        trackplan.export(stand_in(build, robot), output, format=format, motion=motion)
    assert raised.value.key == key
    assert not output.exists() or not any(output.iterdir())


def test_the_json_export_states_each_joints_unit_from_the_runs_axes(tmp_path: Path) -> None:
    """A run whose result.json lists ``axes`` (a track among them): the JSON export gives
    each joint's unit; a run without external axes keeps the JSON as it was."""
    names = ("j1", "j2", "track", "tilt")
    table = TrajectoryTable(
        joint_names=names,
        t=np.zeros(2),
        q=np.zeros((2, 4)),
        qd=np.zeros((2, 4)),
        qdd=np.zeros((2, 4)),
        qddd=np.zeros((2, 4)),
        tool_position=np.zeros((2, 3)),
        speed=np.zeros(2),
    )
    kinds = (("robot", "rad"), ("robot", "rad"), ("track", "m"), ("positioner", "rad"))
    axes = [{"name": n, "kind": k, "unit": u} for n, (k, u) in zip(names, kinds, strict=True)]
    (tmp_path / "result.json").write_text(json.dumps({"axes": axes}))
    written = trackplan.export(
        ExportSource(table=table, folder=tmp_path), tmp_path / "t.json", format="json"
    )
    assert json.loads(written.read_text())["joint_units"] == ["rad", "rad", "m", "rad"]
    (tmp_path / "result.json").write_text(json.dumps({"axes": axes[:2] + axes[3:] * 2}))
    again = trackplan.export(
        ExportSource(table=table, folder=tmp_path), tmp_path / "u.json", format="json"
    )
    assert "joint_units" not in json.loads(again.read_text())
