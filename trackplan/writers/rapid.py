"""ABB RAPID: a :class:`~trackplan.programs.model.Program` as one module ``NAME.mod``.

The module holds the header comment, the tool (``PERS tooldata``, tframe = the TCP) and
the work object (``PERS wobjdata``, uframe = the placement; with a positioner the object
frame, moved by its mechanical unit), the speeds and zones of the
program as ``LOCAL CONST speeddata`` / ``zonedata``, ``PROC main()`` and, when the program
is split, ``LOCAL PROC partK()`` called in order from ``main``. Targets are written inline:
``jointtarget`` ``[[j1..j6],[eax]]`` in degrees, ``robtarget``
``[[x,y,z],[q1..q4],[cf1,cf4,cf6,cfx],[eax]]`` in mm in the work object, ``eax`` the
external axes (mm, degrees) and ``9E+09`` for the unused ones. Files are
ASCII (a subset of the ISO 8859-1 the controller reads). See ``docs/export-rapid.md``.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from trackplan.errors import CaseError
from trackplan.programs.model import (
    CircularMove,
    JointMove,
    LinearMove,
    Move,
    Program,
    SplineMove,
    Target,
    split_program,
)
from trackplan.programs.names import ascii_comment, program_identifier
from trackplan.robots.model import Robot
from trackplan.writers.drivable import Drives, check_drivable
from trackplan.writers.external import language_values, unit_names
from trackplan.writers.protocol import write_text_files
from trackplan.writers.rapid_config import confdata, number, numbers, quaternion
from trackplan.writers.source import ExportSource

DEFAULT_MAX_POINTS = 5000
"""Targets per procedure. ABB publishes no limit on a routine's length; the controller's
program memory bounds the module. 5000 is what RoboDK's ABB post-processor puts in one
program (``MAX_LINES_X_PROG``), and keeps each procedure small enough to open on the
FlexPendant."""

MAX_IDENTIFIER = 32
"""Longest RAPID identifier (RAPID overview, *Basic elements: identifiers*)."""

RAPID = Drives(
    format="rapid",
    language="RAPID",
    vendors=("abb", "generic"),
    max_external=6,
    coordinated=True,
)
"""RAPID drives ABB and generic six-axis arms (a generic robot as an ABB arm would), with
up to six external axes (``eax_a`` … ``eax_f``, ``9E9`` unused), a positioner in
coordinated motion (``wobjdata`` ``ufprog`` FALSE, ``ufmec``; RAPID reference *wobjdata*,
visose/Robots ``RapidPostProcessor.cs``)."""

MECHANICAL_UNIT = "STN_1"
"""The positioner's mechanical unit, which moves the work object (``wobjdata.ufmec``; the
name of ABB's own example of a coordinated work object, MultiMove application manual
3HAC021272-001, *Coordinated work objects*). The header states it; an integrator renames
it to the cell's unit."""

N_AXES = 6
"""Robot axes of a ``robjoint``; the confdata here is defined for six-axis arms."""

UNUSED = "9E+09"
"""An external axis that is not used (RAPID's ``9E9``)."""

JOINT_BLEND = 0.0003
"""m: the zone between timed joint moves whose plan does not stop there (ABB's ``z0``:
0.3 mm), so that the samples blend instead of stopping at each."""

JOINT_SPEED = "[250,30,5000,1000]"
"""speeddata ``tpv_joint`` of the move to the start, whose starting point the program
cannot know (250 mm/s, 30°/s: a slow approach); timed joint moves name it too, and their
``\\T`` replaces it."""

MM = 4
"""Decimals of mm (0.0001 mm)."""
DEG = 6
"""Decimals of joint degrees (1e-6° ≈ 1.7e-8 rad)."""
QUAT = 9
"""Decimals of quaternion components (1e-9: < 1e-7°)."""

RESERVED = frozenset(
    """ALIAS AND BACKWARD CASE CONNECT CONST DEFAULT DIV DO ELSE ELSEIF ENDFOR ENDFUNC ENDIF
    ENDMODULE ENDPROC ENDRECORD ENDTEST ENDTRAP ENDWHILE ERROR EXIT FALSE FOR FROM FUNC GOTO
    IF INOUT LOCAL MOD MODULE NOSTEPIN NOT NOVIEW OR PERS PROC RAISE READONLY RECORD RETRY
    RETURN STEP SYSMODULE TEST THEN TO TRAP TRUE TRYNEXT UNDO VAR VIEWONLY WHILE WITH XOR
    MAIN""".split()
)
"""RAPID's reserved words (RAPID kernel reference) and ``main``: a module of such a name
gets ``_prg`` appended; a name ``partK`` does too, to stay apart from the part routines."""


@dataclass(frozen=True)
class _Names:
    """Identifiers of the module's data."""

    module: str
    tool: str
    wobj: str


def render_rapid(
    program: Program, *, robot: Robot, max_points: int | None = None
) -> dict[str, str]:
    """The RAPID module of a program.

    Parameters
    ----------
    program
        The program (SI units, controller joints).
    robot
        The robot it was planned for (geometry for ``cfx``, payload for ``tload``).
    max_points
        Targets per procedure (≥ 2); None: :data:`DEFAULT_MAX_POINTS`.

    Returns
    -------
    dict[str, str]
        ``{"NAME.mod": text}``.

    Raises
    ------
    CaseError
        For a robot RAPID cannot drive (not ABB or generic, not six axes), a name that
        cannot be made an identifier, or fewer than 2 points per procedure (keys
        ``--format``, ``--name``, ``--max-points``).
    """
    check_drivable(program, RAPID)
    name = _module_name(program.name)
    names = _Names(
        module=name, tool=f"tool_{name}"[:MAX_IDENTIFIER], wobj=f"wobj_{name}"[:MAX_IDENTIFIER]
    )
    if max_points is not None and max_points < 2:
        raise CaseError(
            f"--max-points must be at least 2 targets per procedure, got {max_points}",
            key="--max-points",
        )
    parts = split_program(program, max_points or DEFAULT_MAX_POINTS)
    data = _Data()
    robtargets = _robtargets(program, robot)
    bodies: list[list[str]] = []
    previous: np.ndarray | None = None
    all_moves = [move for part in parts for section in part.sections for move in section.moves]
    index = 0
    for part in parts:
        lines: list[str] = []
        for section in part.sections:
            lines.append(f"! {ascii_comment(section.kind)}: {ascii_comment(section.label)}")
            for move in section.moves:
                following = all_moves[index + 1] if index + 1 < len(all_moves) else None
                lines.extend(
                    _move_lines(move, following, previous, program, robtargets, names, data)
                )
                previous = _end_joints(move)
                index += 1
        bodies.append(lines)
    text = _module_text(program, robot, names, data, bodies)
    return {f"{name}.mod": text}


def _module_name(asked: str) -> str:
    """The program name as a RAPID identifier that is no reserved word or routine name."""
    name = program_identifier(asked, max_length=MAX_IDENTIFIER, key="--name")
    if name.upper() in RESERVED or re.fullmatch(r"part\d+", name, flags=re.IGNORECASE):
        name = f"{name[: MAX_IDENTIFIER - 4]}_prg"
    return name


class _Data:
    """The speeds and zones a module declares, by their printed values."""

    def __init__(self) -> None:
        self.speeds: dict[str, str] = {}
        self.zones: dict[str, str] = {}

    def speed(self, v_tcp: float) -> str:
        """Name of the speeddata of a TCP speed, m/s."""
        mm_s = number(v_tcp * 1000.0, 3)
        if mm_s not in self.speeds:
            # v_ori, v_leax, v_reax as ABB's predefined v5 … v7000 (500°/s, 5000 mm/s,
            # 1000°/s): the TCP speed governs the move.
            self.speeds[mm_s] = f"[{mm_s},500,5000,1000]"
        return "tpv_" + mm_s.replace(".", "_")

    def zone(self, radius: float) -> str:
        """Name of the zonedata of a TCP zone radius, m (``fine`` for 0)."""
        if radius <= 0.0:
            return "fine"
        mm = number(radius * 1000.0, 3)
        if mm not in self.zones:
            size = float(mm)
            ori = number(0.1 * size, 4)
            # [finep, pzone_tcp, pzone_ori, pzone_eax, zone_ori, zone_leax, zone_reax]:
            # the orientation and external-axis zones no larger than the TCP zone.
            self.zones[mm] = f"[FALSE,{mm},{mm},{mm},{ori},{mm},{ori}]"
        return "tpz_" + mm.replace(".", "_")


def _move_lines(
    move: Move,
    following: Move | None,
    previous: np.ndarray | None,
    program: Program,
    robtargets: dict[int, str],
    names: _Names,
    data: _Data,
) -> list[str]:
    """The instructions of one move."""
    tool = f"{names.tool}\\WObj:={names.wobj}"
    if isinstance(move, JointMove):
        target = f"[[{numbers(np.degrees(move.joints), DEG)}],{_extjoint(program, move.external)}]"
        zone = move.zone
        if move.duration is not None:
            if zone <= 0.0 and isinstance(following, JointMove) and following.duration:
                zone = JOINT_BLEND
            speed = f"tpv_joint\\T:={number(move.duration, 6)}"
        elif previous is not None and program.v_max.size == program.n_dof:
            speed = f"tpv_joint\\T:={number(_joint_time(move, previous, program), 6)}"
        else:
            speed = "tpv_joint"
        return [f"MoveAbsJ {target},{speed},{data.zone(zone)},{tool};"]
    if isinstance(move, LinearMove):
        speed_name, zone_name = data.speed(move.speed), data.zone(move.zone)
        return [f"MoveL {robtargets[id(move.target)]},{speed_name},{zone_name},{tool};"]
    if isinstance(move, CircularMove):
        via, end = robtargets[id(move.via)], robtargets[id(move.target)]
        return [f"MoveC {via},{end},{data.speed(move.speed)},{data.zone(move.zone)},{tool};"]
    # SplineMove: RAPID has no spline move; lines through its points, blended.
    speed_name, zone_name = data.speed(move.speed), data.zone(move.zone)
    return [
        f"MoveL {robtargets[id(target)]},{speed_name},{zone_name},{tool};"
        for target in move.targets
    ]


def _robtargets(program: Program, robot: Robot) -> dict[int, str]:
    """``[[x,y,z],[q1..q4],[cf1,cf4,cf6,cfx],[9E+09 × 6]]`` (mm) of every Cartesian target,
    by ``id`` of the target, computed for all targets at once."""
    targets: list[Target] = []
    for move in program.moves():
        if isinstance(move, LinearMove):
            targets.append(move.target)
        elif isinstance(move, CircularMove):
            targets.extend((move.via, move.target))
        elif isinstance(move, SplineMove):
            targets.extend(move.targets)
    if not targets:
        return {}
    poses = np.stack([target.pose for target in targets])
    conf = confdata(
        robot,
        np.stack([target.joints for target in targets]),
        np.stack([target.model_joints for target in targets]),
    )
    orients = quaternion(poses[:, :3, :3])
    return {
        id(target): f"[[{numbers(pose[:3, 3] * 1000.0, MM)}],[{numbers(orient, QUAT)}],"
        f"[{','.join(str(int(c)) for c in fields)}],{_extjoint(program, target.external)}]"
        for target, pose, orient, fields in zip(targets, poses, orients, conf, strict=True)
    }


def _extjoint(program: Program, external: np.ndarray) -> str:
    """``extjoint`` ``[eax_a, …, eax_f]``: the external axes in order (a track in mm,
    rotary axes in degrees), ``9E+09`` for the axes not used."""
    axes = program.external_axes
    values = language_values(axes, external)
    written = [
        number(v, MM if axis.unit == "m" else DEG) for axis, v in zip(axes, values, strict=True)
    ]
    return f"[{','.join(written + [UNUSED] * (6 - len(written)))}]"


def _joint_time(move: JointMove, previous: np.ndarray, program: Program) -> float:
    """Time of a joint move at its share of each joint's rated velocity (the external
    axes' included), s."""
    rated = np.concatenate([program.v_max, [axis.v_max for axis in program.external_axes]])
    travel = np.abs(_end_joints(move) - previous)
    return float(np.max(travel / (move.speed * rated))) or 0.001


def _end_joints(move: Move) -> np.ndarray:
    """Model joints and external axes where a move ends."""
    if isinstance(move, JointMove):
        end_joints, external = move.model_joints, move.external
    else:
        end = move.targets[-1] if isinstance(move, SplineMove) else move.target
        end_joints, external = end.model_joints, end.external
    return np.concatenate([np.asarray(end_joints, dtype=float), np.asarray(external, float)])


def _pose(transform: np.ndarray) -> str:
    """RAPID ``pose`` ``[[x,y,z],[q1..q4]]`` of a transform (mm)."""
    position = numbers(transform[:3, 3] * 1000.0, MM)
    return f"[[{position}],[{numbers(quaternion(transform[:3, :3]), QUAT)}]]"


def _external_header(program: Program) -> list[str]:
    """The header lines on the external axes (none for an arm alone)."""
    axes = program.external_axes
    if not axes:
        return []
    mapping = ", ".join(
        f"eax_{letter} = {axis.name} ({unit})"
        for letter, axis, unit in zip("abcdef", axes, unit_names(axes), strict=False)
    )
    lines = [f"extjoint: {mapping}; 9E+09 for the others (the controller's axis order)"]
    if program.coordinated:
        lines.append(
            f'the work object moves with mechanical unit "{MECHANICAL_UNIT}" (ufprog FALSE, '
            "ufmec; coordinated motion): its user frame is the unit's flange from the system "
            "parameters, its object frame the part there; rename the unit to the cell's"
        )
    return lines


def _tload(program: Program, robot: Robot) -> tuple[str, str]:
    """``loaddata`` of the tool and a comment on where it comes from."""
    payload = robot.dynamics.payload if robot.dynamics is not None else None
    if payload is None or payload.mass <= 0.0:
        return (
            "[0.001,[0,0,0.001],[1,0,0,0],0,0,0]",
            "tload: no payload in the case: set the tool's mass, centre of gravity and "
            "inertia (LoadIdentify) before running",
        )
    cog = program.tool @ np.append(np.asarray(payload.com, dtype=float), 1.0)
    moments, axes = np.linalg.eigh(np.asarray(payload.inertia, dtype=float))
    if np.linalg.det(axes) < 0.0:
        axes[:, 0] *= -1.0
    aom = quaternion(program.tool[:3, :3] @ axes)
    return (
        f"[{number(payload.mass, 4)},[{numbers(cog[:3] * 1000.0, MM)}],"
        f"[{numbers(aom, QUAT)}],{numbers(moments, 6)}]",
        "tload: the case's payload (mass kg, centre of gravity mm in tool0, inertia kg*m2)",
    )


def _module_text(
    program: Program, robot: Robot, names: _Names, data: _Data, bodies: list[list[str]]
) -> str:
    """The module's text."""
    tload, tload_note = _tload(program, robot)
    lines = [f"MODULE {names.module}"]
    header = [
        *program.header,
        f"form: {program.motion}; robot: {program.robot} ({program.vendor}); "
        f"{program.n_points} targets in {len(bodies)} part(s)",
        "units: mm, degrees; orientations as quaternions [q1,q2,q3,q4], q1 the scalar",
        "confdata [cf1,cf4,cf6,cfx] from the planned joints; ConfL/ConfJ \\On and the "
        "MoveAbsJ to the planned start hold the planned branch",
    ]
    header.extend(_external_header(program))
    if not program.feasible:
        header.append("WARNING: the run is NOT feasible (written with --force)")
    lines.extend(f"  ! {ascii_comment(line)}".rstrip() for line in header)
    lines.append(f"  ! {ascii_comment(tload_note)}")
    lines.append(
        f"  PERS tooldata {names.tool}:=[TRUE,{_pose(program.tool)},{tload}];",
    )
    identity = "[[0,0,0],[1,0,0,0]]"
    if program.coordinated:
        # a positioner moves the work object: ufprog FALSE, ufmec its mechanical unit;
        # the user frame is then the unit's, from the system parameters, and the part
        # on its flange is the object frame (RAPID reference, wobjdata)
        frames = f'FALSE,"{MECHANICAL_UNIT}",{identity},{_pose(program.base)}'
    else:
        frames = f'TRUE,"",{_pose(program.base)},{identity}'
    lines.append(f"  PERS wobjdata {names.wobj}:=[FALSE,{frames}];")
    lines.append(f"  LOCAL CONST speeddata tpv_joint:={JOINT_SPEED};")
    for mm_s, value in data.speeds.items():
        lines.append(f"  LOCAL CONST speeddata tpv_{mm_s.replace('.', '_')}:={value};")
    for mm, value in data.zones.items():
        lines.append(f"  LOCAL CONST zonedata tpz_{mm.replace('.', '_')}:={value};")
    lines.append("")
    lines.append("  PROC main()")
    lines.append("    ConfJ \\On;")
    lines.append("    ConfL \\On;")
    if len(bodies) == 1:
        lines.extend(f"    {line}" for line in bodies[0])
    else:
        lines.extend(f"    part{k};" for k in range(1, len(bodies) + 1))
    lines.append("  ENDPROC")
    if len(bodies) > 1:
        for k, body in enumerate(bodies, start=1):
            lines.append("")
            lines.append(f"  LOCAL PROC part{k}()")
            lines.extend(f"    {line}" for line in body)
            lines.append("  ENDPROC")
    lines.append("ENDMODULE")
    return "\n".join(lines) + "\n"


class RapidWriter:
    """The ``rapid`` export format: one ABB RAPID module in a folder."""

    name = "rapid"
    suffix = ".mod"
    default_file = "rapid"
    folder = True

    def write(self, source: ExportSource, folder: Path, **options: Any) -> tuple[str, ...]:
        """Build the program from the run, render it and write ``NAME.mod`` (ASCII).

        Parameters
        ----------
        source
            The export source: ``source.program(motion=, name=, period=, force=)`` builds
            the :class:`Program`; ``source.run.case.robot`` is the robot.
        folder
            A fresh folder to write into.
        **options
            ``motion`` (``cartesian``), ``name``, ``period``, ``force``, ``max_points``.

        Returns
        -------
        tuple[str, ...]
            The names of the files written.
        """
        texts = render_rapid(
            source.program_of(options), robot=source.robot, max_points=options.get("max_points")
        )
        return write_text_files(folder, texts)


__all__ = ["DEFAULT_MAX_POINTS", "RapidWriter", "render_rapid"]
