"""KUKA KRL programs (``--format krl``): ``NAME.src`` with ``NAME.dat`` for a KR C4 / KSS 8.

:func:`render_krl` prints a :class:`~trackplan.programs.model.Program` as KRL text;
:class:`KrlWriter` writes the files of an export. See ``docs/export-krl.md``.

Layout (what a KUKA integrator reads in KUKA's own programs): the ``.src`` holds the
motions, the ``.dat`` (``DEFDAT``) holds every point as a ``DECL E6POS XPn`` or
``DECL E6AXIS XJn`` and the program's frames as ``DECL FRAME``, so a point can be touched up
by name on the pendant. A long program is split into parts ``NAME_P1`` … ``NAME_Pk``, one
``.src``/``.dat`` pair each (each file stays small, which is what the split is for), called
in order from ``NAME.src``. Units: mm, degrees, m/s (``$VEL.CP``), % (``$VEL_AXIS``).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from trackplan.errors import CaseError
from trackplan.programs.model import (
    CircularMove,
    ExternalAxis,
    JointMove,
    LinearMove,
    Move,
    Program,
    Section,
    SplineMove,
    Target,
    split_program,
)
from trackplan.programs.names import ascii_comment, program_identifier
from trackplan.robots.model import Robot
from trackplan.writers.drivable import Drives, check_drivable
from trackplan.writers.external import language_values, unit_names
from trackplan.writers.krl_config import frame_values, real, status_turn
from trackplan.writers.protocol import write_text_files
from trackplan.writers.source import ExportSource

# RoboDK's KUKA KRC4 post-processor (KUKA_KRC4.py, MAX_LINES_X_PROG) starts a new .src
# after 1400 lines; KUKA publishes no limit (docs/export-krl.md).
DEFAULT_MAX_POINTS = 1000
"""Targets per part: a part then writes about 1,100 lines of ``.src`` (motions, speed and
zone changes), below the page length integrators' post-processors keep
(``docs/export-krl.md``)."""

MAX_NAME = 24
"""KRL's longest program (module) name."""

KRL = Drives(
    format="krl",
    language="KRL",
    vendors=("kuka", "generic"),
    min_axes=1,
    max_external=6,
    coordinated=True,
)
"""KRL drives KUKA and generic robots of up to six axes (A1 … A6) and up to six external
axes (E1 … E6), a positioner in coordinated motion (``EK``). Sources
(``docs/export-krl.md``): visose/Robots ``KRLPostProcessor.cs`` (``E1 …`` in the point
aggregates, ``$BASE = EK(MACHINE_DEF[i].ROOT, MACHINE_DEF[i].MECH_TYPE, frame)``,
``$ACT_EX_AX``, ``$VEL_EXTAX``); robot-forum.com thread 40359."""

MAX_AXES = 6
"""Robot axes A1 … A6 of an E6AXIS."""

POSITIONER_MACHINE = 2
"""``MACHINE_DEF[2]``: the positioner's external kinematics in the controller's machine
data (``MACHINE_DEF[1]`` is the robot). The index is the controller's configuration: the
header states it, and an integrator changes it where the cell's differs."""

KEYWORDS = frozenset(
    """AND ANIN ANOUT B_AND B_NOT B_OR B_EXOR BOOL BRAKE C_DIS C_ORI C_PTP C_SPL C_VEL CASE
    CAST_FROM CAST_TO CHAR CIRC CIRC_REL CONST CONTINUE DECL DEF DEFAULT DEFDAT DEFFCT DELAY
    DO ELSE END ENDDAT ENDFCT ENDFOR ENDIF ENDLOOP ENDSPLINE ENDSWITCH ENDWHILE ENUM EXIT
    EXOR EXT EXTFCT FALSE FOR GLOBAL GOTO HALT IF IMPORT INT INTERRUPT IS LIN LIN_REL LOOP
    MAXIMUM MINIMUM MOD NOT OR PRIO PTP PTP_REL PTP_SPLINE PUBLIC REAL REPEAT RESUME RETURN
    SCIRC SEC SIGNAL SLIN SPL SPLINE SPTP STRUC SWITCH THEN TIME_BLOCK TO TRIGGER TRUE UNTIL
    WAIT WHEN WHILE WITH""".split()
)
"""KRL's reserved words: a program may not be called by one of them."""

DIGITS_MM = 4
"""Decimals of X, Y, Z (mm): 1e-4 mm, below KRL's REAL (32-bit) resolution at 1 m."""
DIGITS_DEG = 6
"""Decimals of A, B, C and of axis angles (deg): 1e-6° (1.7e-8 rad)."""


def krl_name(name: str) -> str:
    """``name`` as a KRL module name: letters, digits, ``_``, a letter first, ≤ 24
    characters, case kept (KRL does not tell case apart), not a reserved word.

    Raises
    ------
    CaseError
        When nothing valid is left, or the result is a KRL keyword (key ``--name``).
    """
    identifier = program_identifier(name, max_length=MAX_NAME, key="--name")
    if identifier.upper() in KEYWORDS:
        raise CaseError(
            f"{identifier!r} is a KRL keyword and cannot name a program: give another --name",
            key="--name",
        )
    return identifier


def part_names(name: str, n_parts: int) -> tuple[str, ...]:
    """The names of ``n_parts`` parts: ``NAME_P1`` …, the stem cut so each fits 24."""
    suffix_length = len(f"_P{n_parts}")
    stem = name[: MAX_NAME - suffix_length].rstrip("_") or name[0]
    return tuple(f"{stem}_P{index}" for index in range(1, n_parts + 1))


def render_krl(program: Program, *, robot: Robot, max_points: int | None = None) -> dict[str, str]:
    """The KRL files of a program.

    Parameters
    ----------
    program
        The program (SI units, controller joints).
    robot
        The program's robot: its kinematics and convention give Status and Turn.
    max_points
        Targets per part; None: :data:`DEFAULT_MAX_POINTS`.

    Returns
    -------
    dict[str, str]
        File name → text (``\\n`` line ends, ASCII): ``NAME.src``, ``NAME.dat`` and, when
        split, ``NAME_Pi.src`` / ``NAME_Pi.dat``.

    Raises
    ------
    CaseError
        For a robot KRL cannot drive, a name that cannot be made valid, or fewer than 2
        points per part.
    """
    check_drivable(program, KRL)
    name = krl_name(program.name)
    if max_points is not None and max_points < 2:
        raise CaseError(
            f"--max-points must be at least 2 (targets per part), got {max_points}",
            key="--max-points",
        )
    parts = split_program(program, max_points or DEFAULT_MAX_POINTS)
    configurations = _configurations(program, robot)
    main = _Module(name, configurations, program.external_axes)
    main.data.append(f"DECL FRAME TPBASE={{{_frame(program.base)}}}")
    main.data.append(f"DECL FRAME TPTOOL={{{_frame(program.tool)}}}")
    main.code.extend(f"; {line}" for line in _header(program, len(parts)))
    main.code.extend([";FOLD INI", "  BAS(#INITMOV, 0)", ";ENDFOLD (INI)"])
    main.code.extend(_base_lines(program))
    main.code.extend(["$TOOL = TPTOOL", "$IPO_MODE = #BASE"])
    files: dict[str, str] = {}
    if len(parts) == 1:
        main.add_sections(parts[0].sections, program.n_dof)
    else:
        for part, part_name in zip(parts, part_names(name, len(parts)), strict=True):
            main.code.append(f"{part_name}( )")
            module = _Module(part_name, configurations, program.external_axes)
            module.code.append(f"; part {part.index} of {len(parts)} of {name}")
            module.add_sections(part.sections, program.n_dof)
            files.update(module.files())
    return {**main.files(), **files}


@dataclass
class _Module:
    """One ``.src``/``.dat`` pair being written, with the speeds and zone set so far."""

    name: str
    configurations: dict[int, tuple[int, int]]
    external: tuple[ExternalAxis, ...] = ()
    code: list[str] = field(default_factory=list)
    data: list[str] = field(default_factory=list)
    n_points: int = 0
    vel_cp: str | None = None
    vel_axis: str | None = None
    cdis: str | None = None

    def files(self) -> dict[str, str]:
        """``NAME.src`` and ``NAME.dat``."""
        src = ["&ACCESS RVP", "&REL 1", f"DEF {self.name}( )", *self.code, "END", ""]
        dat = ["&ACCESS RVP", "&REL 1", f"DEFDAT {self.name}", *self.data, "ENDDAT", ""]
        return {f"{self.name}.src": "\n".join(src), f"{self.name}.dat": "\n".join(dat)}

    def add_sections(self, sections: tuple[Section, ...], n_dof: int) -> None:
        """Every move of ``sections``, each section under a comment line."""
        for section in sections:
            self.code.append(f"; {ascii_comment(section.kind)}: {ascii_comment(section.label)}")
            moves = section.moves
            start = 0
            while start < len(moves):
                end = start
                while end < len(moves) and _timed(moves[end]):
                    end += 1
                if end > start:
                    self.timed_block(
                        [m for m in moves[start:end] if isinstance(m, JointMove)], n_dof
                    )
                    start = end
                else:
                    self.move(moves[start], n_dof)
                    start += 1

    def point(self, kind: str, values: str) -> str:
        """Declare a point in the ``.dat``; its name."""
        self.n_points += 1
        name = f"X{'J' if kind == 'E6AXIS' else 'P'}{self.n_points}"
        self.data.append(f"DECL {kind} {name}={{{values}}}")
        return name

    def axis_point(self, joints: np.ndarray, external: np.ndarray) -> str:
        """An E6AXIS of controller joints (rad) and external axes (m, rad)."""
        values = ",".join(
            f"A{i + 1} {real(v, DIGITS_DEG)}" for i, v in enumerate(np.rad2deg(joints))
        )
        return self.point("E6AXIS", values + self.external_values(external))

    def pose_point(self, target: Target) -> str:
        """An E6POS of a Cartesian target, with Status and Turn when known, and its
        external axes."""
        values = _frame(target.pose)
        if id(target) in self.configurations:
            status, turn = self.configurations[id(target)]
            values += f",S {status},T {turn}"
        return self.point("E6POS", values + self.external_values(target.external))

    def external_values(self, external: np.ndarray) -> str:
        """``,E1 …,E2 …`` of the external axes: a track in mm, rotary axes in degrees
        (empty without external axes)."""
        if not self.external:
            return ""
        values = language_values(self.external, external)
        return "".join(
            f",E{i + 1} {real(v, DIGITS_MM if axis.unit == 'm' else DIGITS_DEG)}"
            for i, (axis, v) in enumerate(zip(self.external, values, strict=True))
        )

    def set_speed(self, speed: float) -> None:
        """``$VEL.CP`` (m/s) when it changes."""
        text = real(speed, 6)
        if text != self.vel_cp:
            self.code.append(f"$VEL.CP = {text}")
            self.vel_cp = text

    def set_axis_speed(self, share: float, n_dof: int) -> None:
        """``$VEL_AXIS[i]`` (% of each axis' rated speed) when it changes."""
        text = _percent(share)
        if text != self.vel_axis:
            self.code.extend(f"$VEL_AXIS[{i}] = {text}" for i in range(1, n_dof + 1))
            self.code.extend(f"$VEL_EXTAX[{i}] = {text}" for i in range(1, len(self.external) + 1))
            self.vel_axis = text

    def approximation(self, zone: float, suffix: str = "C_DIS") -> str:
        """`` C_DIS`` after setting ``$APO.CDIS`` (mm) for a blended end, else nothing."""
        if zone <= 0.0:
            return ""
        text = real(1000.0 * zone, DIGITS_MM)
        if text != self.cdis:
            self.code.append(f"$APO.CDIS = {text}")
            self.cdis = text
        return f" {suffix}"

    def move(self, move: Move, n_dof: int) -> None:
        """One untimed move: PTP, LIN, CIRC or a SPLINE block."""
        if isinstance(move, JointMove):
            self.set_axis_speed(move.speed, n_dof)
            point = self.axis_point(move.joints, move.external)
            self.code.append(f"PTP {point}{self.approximation(move.zone)}")
        elif isinstance(move, LinearMove):
            self.set_speed(move.speed)
            point = self.pose_point(move.target)
            self.code.append(f"LIN {point}{self.approximation(move.zone)}")
        elif isinstance(move, CircularMove):
            self.set_speed(move.speed)
            via, end = self.pose_point(move.via), self.pose_point(move.target)
            self.code.append(f"CIRC {via}, {end}{self.approximation(move.zone)}")
        else:
            self.set_speed(move.speed)
            names = [self.pose_point(target) for target in move.targets]
            suffix = self.approximation(move.zone, "C_SPL")
            self.code.extend(["SPLINE", *(f"  SPL {p}" for p in names), f"ENDSPLINE{suffix}"])

    def timed_block(self, moves: list[JointMove], n_dof: int) -> None:
        """Timed joint moves as SPTP segments of one ``PTP_SPLINE`` block."""
        self.set_axis_speed(moves[0].speed, n_dof)
        lines = []
        for move in moves:
            point = self.axis_point(move.joints, move.external)
            text = _percent(move.speed)
            extra = ", ".join(
                [f"$VEL_AXIS[{i}] = {text}" for i in range(1, n_dof + 1)]
                + [f"$VEL_EXTAX[{i}] = {text}" for i in range(1, len(self.external) + 1)]
            )
            lines.append(f"  SPTP {point}" + (f" WITH {extra}" if text != self.vel_axis else ""))
        suffix = self.approximation(moves[-1].zone, "C_SPL")
        self.code.extend(["PTP_SPLINE", *lines, f"ENDSPLINE{suffix}"])


def _configurations(program: Program, robot: Robot) -> dict[int, tuple[int, int]]:
    """Status and Turn of every Cartesian target, by the target's id (6-axis robots)."""
    targets: list[Target] = []
    for move in program.moves():
        if isinstance(move, LinearMove):
            targets.append(move.target)
        elif isinstance(move, CircularMove):
            targets.extend([move.via, move.target])
        elif isinstance(move, SplineMove):
            targets.extend(move.targets)
    if not targets or program.n_dof != MAX_AXES:
        return {}
    status, turn = status_turn(robot, np.stack([target.joints for target in targets]))
    return {
        id(target): (int(s), int(t)) for target, s, t in zip(targets, status, turn, strict=True)
    }


def _timed(move: Move) -> bool:
    """True for a joint move the program times (``--motion joint``)."""
    return isinstance(move, JointMove) and move.duration is not None


def _base_lines(program: Program) -> list[str]:
    """The ``$BASE`` of the program: the part frame, or with a positioner (Cartesian
    form) the part frame on the positioner's flange, moved with it by the external
    kinematics ``EK`` (coordinated motion); the joint form moves axes only and sets no
    base then."""
    if not program.coordinated:
        return ["$BASE = TPBASE"]
    if program.motion == "joint":
        return []
    machine = f"MACHINE_DEF[{POSITIONER_MACHINE}]"
    return [
        f"$BASE = EK({machine}.ROOT, {machine}.MECH_TYPE, TPBASE)",
        f"$ACT_EX_AX = {len(program.external_axes)}",
    ]


def _external_header(program: Program) -> list[str]:
    """The header lines on the external axes (none for an arm alone)."""
    axes = program.external_axes
    if not axes:
        return []
    units = unit_names(axes)
    mapping = ", ".join(
        f"E{i + 1} = {axis.name} ({unit})"
        for i, (axis, unit) in enumerate(zip(axes, units, strict=True))
    )
    lines = [
        f"external axes: {mapping}; $EX_AX_NUM and the machine data must map them so "
        "(track first, then the positioner's axes)"
    ]
    if program.coordinated and program.motion == "cartesian":
        lines.append(
            f"TPBASE is the part frame on the positioner's flange; $BASE = EK(...) couples "
            f"it to the positioner's kinematics MACHINE_DEF[{POSITIONER_MACHINE}] "
            "(coordinated motion): set the index to the cell's positioner"
        )
    elif program.coordinated:
        lines.append("TPBASE is the part frame on the positioner's flange (not used by PTP)")
    return lines


def _header(program: Program, n_parts: int) -> list[str]:
    """The header comment lines (ASCII, without the ``;``)."""
    lines = [ascii_comment(line) for line in program.header]
    where = (
        "on the positioner's flange"
        if program.coordinated
        else "in $WORLD (with $ROBROOT = $WORLD)"
    )
    lines.append(
        f"KRL: $BASE = the part frame {where}, $TOOL = the TCP in "
        "$FLANGE; X Y Z mm, A B C deg with R = Rz(A) Ry(B) Rx(C)"
    )
    if program.motion == "joint":
        period = f"{program.period:g} s" if program.period else "the sample time"
        lines.append(
            f"KRL times the moves itself: SPTP at the programmed axis speed, not every {period}"
        )
    elif program.n_dof == MAX_AXES:
        lines.append(
            "S, T: KUKA Status and Turn of the planned joints; LIN, CIRC and SPL keep the "
            "start's, so the PTP to the planned joints holds the branch"
        )
    lines.extend(_external_header(program))
    if n_parts > 1:
        lines.append(f"parts: {n_parts}, called in order")
    return lines


def _frame(T: np.ndarray) -> str:
    """``X …,Y …,Z …,A …,B …,C …`` of a pose (m) in mm and degrees."""
    values = frame_values(T)
    digits = (DIGITS_MM,) * 3 + (DIGITS_DEG,) * 3
    return ",".join(
        f"{key} {real(v, d)}" for key, v, d in zip("XYZABC", values, digits, strict=True)
    )


def _percent(share: float) -> str:
    """A joint speed share as KRL's integer percent, 1 … 100."""
    return str(int(min(100, max(1, round(100.0 * share)))))


@dataclass(frozen=True)
class KrlWriter:
    """The ``krl`` export: a folder of ``.src``/``.dat`` files (ASCII, CRLF line ends)."""

    name: str = "krl"
    suffix: str = ".src"
    default_file: str = "krl"
    folder: bool = True

    def write(self, source: ExportSource, folder: Path, **options: Any) -> tuple[str, ...]:
        """Write the program's files into ``folder``; their names.

        Options: ``motion`` (``cartesian``/``joint``), ``name``, ``period`` (s), ``force``,
        ``max_points``.
        """
        texts = render_krl(
            source.program_of(options), robot=source.robot, max_points=options.get("max_points")
        )
        return write_text_files(folder, texts, line_end="\r\n")


__all__ = [
    "DEFAULT_MAX_POINTS",
    "KEYWORDS",
    "MAX_NAME",
    "KrlWriter",
    "krl_name",
    "part_names",
    "render_krl",
]
