"""FANUC TP programs (``--format fanuc``): ASCII ``.ls`` files for the R-30iA/iB controllers.

:func:`render_fanuc` prints a :class:`~trackplan.programs.model.Program` as TP: ``NAME.ls``
with ``/PROG``, ``/ATTR``, ``/MN``, ``/POS`` and ``/END``; a long program becomes parts
``NAME001.ls`` … called in order with ``CALL`` from ``NAME.ls``. The program assigns its
user frame and tool frame from values written in it (``PR[i,j]=…`` element by element,
then ``UFRAME[n]=PR[i]`` and ``UTOOL[m]=PR[i]``) and selects them with ``UFRAME_NUM`` and
``UTOOL_NUM``. :class:`FanucWriter` writes the files of a run. Conventions, sources and
what the controller does differently from the plan: ``docs/export-fanuc.md``.
"""

from __future__ import annotations

import textwrap
from dataclasses import dataclass, field
from datetime import datetime
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
    Part,
    Program,
    SplineMove,
    Target,
    split_program,
)
from trackplan.programs.names import ascii_comment, program_identifier
from trackplan.robots.model import Robot
from trackplan.run_files import RESULT_FILE
from trackplan.writers.drivable import Drives, check_drivable
from trackplan.writers.external import language_values
from trackplan.writers.fanuc_config import (
    cartesian_record,
    config_strings,
    extended_fields,
    group_block,
    joint_record,
    number,
    xyzwpr,
)
from trackplan.writers.protocol import write_text_files
from trackplan.writers.source import ExportSource

DEFAULT_MAX_POINTS = 5000
"""Positions per ``.ls`` file by default. RoboDK's FANUC post (``Fanuc_R30iA.py``) splits
at 9999 lines, the width of the TP line numbers; 5000 positions leave room for the lines a
part adds (a circular move's two positions on one instruction, comments, frame selection)
and keep each file's upload short."""

NAME_LENGTH = 8
"""Longest program name written: the 8 characters of the older controllers (R-J3), which
the later ones accept too (RoboDK cuts at 10)."""

COMMENT_WIDTH = 20
"""Characters per ``! …`` comment: RoboDK's FANUC post wraps its comments at 20."""

ATTR_COMMENT_LENGTH = 16
"""Characters of the ``/ATTR`` COMMENT (the program comment on the SELECT screen)."""

TP = Drives(
    format="fanuc",
    language="TP",
    vendors=("fanuc", "generic"),
    min_axes=1,
    max_external=6,
)
"""TP drives FANUC and generic robots, J1 … J6 of motion group 1, a track as group 1's
extended axis E1 and a positioner as motion group 2; path moves with a positioner
(coordinated motion) are refused. Layout as controllers write it (``docs/export-fanuc.md``):
``E1= … mm`` after ``R`` (WILDER-SYSTEMS-LLC/git-ftp ``tool_4_dropoff_leave.ls``),
``GP2:`` blocks and ``DEFAULT_GROUP = 1,1,…`` (JuniorNatalin/VASC ``up222.ls``)."""

MAX_AXES = 6
"""Robot axes of motion group 1 written (J1…J6)."""


@dataclass(frozen=True, kw_only=True)
class FanucOptions:
    """Numbers a TP program uses, all overwritten when it runs.

    Attributes
    ----------
    uframe
        The user frame number the program assigns and selects (``UFRAME[uframe]``).
    utool
        The tool frame number (``UTOOL[utool]``).
    register
        The position register the frames are assembled in (``PR[register]``).
    cnt
        The ``CNT`` value of blended Cartesian points (0…100): a share of speed kept
        through the point, not a distance; 0 by default, the least rounding.
    created
        The date written in ``/ATTR`` (CREATE, MODIFIED); None: 2000-01-01 00:00.
    """

    uframe: int = 9
    utool: int = 9
    register: int = 9
    cnt: int = 0
    created: datetime | None = None

    def __post_init__(self) -> None:
        for key in ("uframe", "utool", "register"):
            value = getattr(self, key)
            if not 1 <= value <= 999:
                raise CaseError(f"must be a number from 1 to 999, got {value}", key=key)
        if not 0 <= self.cnt <= 100:
            raise CaseError(f"must be from 0 to 100, got {self.cnt}", key="cnt")


def render_fanuc(
    program: Program,
    *,
    robot: Robot | None = None,
    max_points: int | None = None,
    options: FanucOptions | None = None,
) -> dict[str, str]:
    """The ``.ls`` files of a program.

    Parameters
    ----------
    program
        The program (SI units, controller joints).
    robot
        The robot, for the configuration strings of Cartesian targets (its model geometry);
        needed when the program has Cartesian moves.
    max_points
        Positions per file (default :data:`DEFAULT_MAX_POINTS`); a longer program is split
        into parts called in order from the main file.
    options
        Frame, register and ``CNT`` numbers (:class:`FanucOptions`).

    Returns
    -------
    dict[str, str]
        File name → text (ASCII, ``\\n`` line ends), the main program first.

    Raises
    ------
    CaseError
        For a robot TP cannot drive (a KUKA, ABB or UR robot, more than 6 axes, Cartesian
        moves of a robot without 6 axes), a name that cannot be made a TP name, or fewer
        than 2 positions per file.
    """
    options = options or FanucOptions()
    _check_drivable(program, robot)
    if max_points is not None and max_points < 2:
        raise CaseError(
            f"must be at least 2, got {max_points}: a file holds at least one circular move",
            key="--max-points",
        )
    name = program_identifier(program.name, max_length=NAME_LENGTH, upper=True, key="--name")
    parts = split_program(program, max_points or DEFAULT_MAX_POINTS)
    configs = _configurations(program, robot)
    header = _header_lines(program, options)
    if len(parts) == 1:
        listing = _Listing(external=program.external_axes)
        listing.comments(header)
        listing.instruction("")
        _frame_setup(listing, program, options)
        _part_moves(listing, parts[0], program, configs, options)
        return {f"{name}.ls": listing.text(name, program, options)}
    names = _part_names(name, len(parts))
    files: dict[str, str] = {}
    main = _Listing(external=program.external_axes)
    main.comments(header)
    main.instruction("")
    _frame_setup(main, program, options)
    for part_name in names:
        main.instruction(f"CALL {part_name}")
    files[f"{name}.ls"] = main.text(name, program, options)
    for part, part_name in zip(parts, names, strict=True):
        listing = _Listing(external=program.external_axes)
        listing.comments([f"{name} part {part.index} of {len(parts)}"])
        listing.instruction(f"UFRAME_NUM={options.uframe}")
        listing.instruction(f"UTOOL_NUM={options.utool}")
        _part_moves(listing, part, program, configs, options)
        files[f"{part_name}.ls"] = listing.text(part_name, program, options)
    return files


class FanucWriter:
    """The ``fanuc`` export format: a folder of TP ``.ls`` files.

    ``write(source, folder, **options)`` takes ``motion`` (``cartesian`` or ``joint``),
    ``name``, ``period``, ``force``, ``max_points`` and the :class:`FanucOptions` fields
    (``uframe``, ``utool``, ``register``, ``cnt``).
    """

    name = "fanuc"
    suffix = ".ls"
    default_file = "fanuc"
    folder = True

    def write(self, source: ExportSource, folder: Path, **options: Any) -> tuple[str, ...]:
        """Write the program's ``.ls`` files (ASCII) into ``folder``.

        Returns
        -------
        tuple[str, ...]
            The names of the files written, the main program first.
        """
        fanuc_options = FanucOptions(
            **{
                key: options[key]
                for key in ("uframe", "utool", "register", "cnt")
                if options.get(key) is not None
            },
            created=_run_time(source),
        )
        texts = render_fanuc(
            source.program_of(options),
            robot=source.robot,
            max_points=options.get("max_points"),
            options=fanuc_options,
        )
        return write_text_files(folder, texts)


def _run_time(source: ExportSource) -> datetime | None:
    """When the run was written (its ``result.json``'s modification time), for /ATTR's
    CREATE and MODIFIED; None for a run in memory. The run's time, not the export's,
    keeps the files of one run the same from export to export."""
    if source.folder is None:
        return None
    return datetime.fromtimestamp((source.folder / RESULT_FILE).stat().st_mtime)


def _check_drivable(program: Program, robot: Robot | None) -> None:
    """Refuse a robot TP does not drive (one line, key ``--format``)."""
    check_drivable(program, TP)
    tracks = sum(axis.kind == "track" for axis in program.external_axes)
    if tracks > 1:
        raise CaseError(
            f"TP writes one track (extended axis E1 of group 1), and the case has {tracks}: "
            "--format csv, json or ros export every axis",
            key="--format",
        )
    cartesian = any(not isinstance(move, JointMove) for move in program.moves())
    if cartesian and program.n_dof != MAX_AXES:
        raise CaseError(
            f"Cartesian FANUC positions carry the configuration of a 6-axis arm; robot "
            f"{program.robot!r} has {program.n_dof} joints: use --motion joint",
            key="--format",
        )
    if cartesian and robot is None:
        raise ValueError("render_fanuc needs the robot for Cartesian moves")


def _targets(move: Move) -> tuple[Target, ...]:
    """The Cartesian targets of a move, in order."""
    if isinstance(move, LinearMove):
        return (move.target,)
    if isinstance(move, CircularMove):
        return (move.via, move.target)
    if isinstance(move, SplineMove):
        return move.targets
    return ()


def _configurations(program: Program, robot: Robot | None) -> dict[int, str]:
    """The CONFIG string of every Cartesian target, by ``id(target)``, in one batch."""
    targets = [target for move in program.moves() for target in _targets(move)]
    if not targets or robot is None:
        return {}
    strings = config_strings(
        robot,
        np.stack([target.model_joints for target in targets]),
        np.stack([target.joints for target in targets]),
    )
    return {id(target): text for target, text in zip(targets, strings, strict=True)}


def _ascii(text: str) -> str:
    """``text`` as TP comment characters: ASCII, no ``;`` (it ends an instruction)."""
    return ascii_comment(text).replace(";", ",").replace("\t", " ")


def _header_lines(program: Program, options: FanucOptions) -> list[str]:
    """The header: the program's lines and the frames and registers this program uses."""
    return [
        *program.header,
        f"frames: UFRAME[{options.uframe}] = base, UTOOL[{options.utool}] = tool, "
        f"assembled in PR[{options.register}] (all three overwritten)",
        f"stops FINE, blends CNT{options.cnt}: a speed share, not mm (deviation not bounded)",
        *_external_header(program),
    ]


def _external_header(program: Program) -> list[str]:
    """The header lines on the external axes (none for an arm alone)."""
    axes = program.external_axes
    if not axes:
        return []
    track = [axis.name for axis in axes if axis.kind == "track"]
    turning = [axis.name for axis in axes if axis.kind != "track"]
    lines = []
    if track:
        lines.append(f"external: {track[0]} = E1 of group 1 (mm, an integrated extended axis)")
    if turning:
        listed = ", ".join(f"J{i + 1} = {name}" for i, name in enumerate(turning))
        lines.append(f"external: motion group 2 = the positioner, {listed} (deg)")
    return lines


def _part_names(name: str, n_parts: int) -> list[str]:
    """``NAME001`` … within :data:`NAME_LENGTH`, distinct from the main name."""
    width = max(3, len(str(n_parts)))
    stem = name[: NAME_LENGTH - width]
    names = [f"{stem}{k:0{width}d}" for k in range(1, n_parts + 1)]
    if name in names:
        raise CaseError(
            f"the program name {name!r} is also the name of one of its parts: give another --name",
            key="--name",
        )
    return names


def _frame_setup(listing: _Listing, program: Program, options: FanucOptions) -> None:
    """Assign UFRAME and UTOOL from the program's base and tool, and select them."""
    register = options.register
    for label, pose, assign in (
        ("base", program.base, f"UFRAME[{options.uframe}]"),
        ("tool", program.tool, f"UTOOL[{options.utool}]"),
    ):
        values = xyzwpr(pose)
        listing.comments([f"{label} frame"])
        listing.instruction(f"PR[{register}]=LPOS")
        for j, (value, decimals) in enumerate(zip(values, (4, 4, 4, 5, 5, 5), strict=True)):
            listing.instruction(f"PR[{register},{j + 1}]={number(float(value), decimals)}")
        listing.instruction(f"{assign}=PR[{register}]")
    listing.instruction(f"UFRAME_NUM={options.uframe}")
    listing.instruction(f"UTOOL_NUM={options.utool}")


def _linear_speed(speed: float) -> str:
    """A TCP speed in m/s as TP ``mm/sec`` (an integer, at least 1)."""
    return f"{max(1, round(speed * 1000.0))}mm/sec"


def _part_moves(
    listing: _Listing,
    part: Part,
    program: Program,
    configs: dict[int, str],
    options: FanucOptions,
) -> None:
    """The moves of a part, a comment at each section."""
    blended = f"CNT{options.cnt}"
    last_move = _last_move(program)
    for section in part.sections:
        listing.comments([f"{section.kind}: {section.label}"])
        for move in section.moves:
            if isinstance(move, JointMove):
                index = listing.joint_position(move.joints, options, move.external)
                if move.duration is not None:
                    term = "FINE" if move is last_move else "CNT100"
                    listing.motion("J", f"P[{index}] {number(move.duration, 3)}sec {term}")
                else:
                    percent = int(np.clip(round(move.speed * 100.0), 1, 100))
                    term = "FINE" if move.zone <= 0.0 else blended
                    listing.motion("J", f"P[{index}] {percent}% {term}")
                continue
            speed = _linear_speed(move.speed)
            term = "FINE" if move.zone <= 0.0 else blended
            if isinstance(move, LinearMove):
                index = listing.cartesian_position(move.target, configs, options)
                listing.motion("L", f"P[{index}] {speed} {term}")
            elif isinstance(move, CircularMove):
                via = listing.cartesian_position(move.via, configs, options)
                end = listing.cartesian_position(move.target, configs, options)
                listing.circular(via, end, f"{speed} {term}")
            else:
                for target in move.targets:
                    index = listing.cartesian_position(target, configs, options)
                    listing.motion("L", f"P[{index}] {speed} {term}")


def _last_move(program: Program) -> Move | None:
    """The program's last move (a timed replay stops there with FINE)."""
    last: Move | None = None
    for move in program.moves():
        last = move
    return last


@dataclass
class _Listing:
    """The ``/MN`` instructions and ``/POS`` records of one ``.ls`` file."""

    external: tuple[ExternalAxis, ...] = ()
    lines: list[str] = field(default_factory=list)
    positions: list[str] = field(default_factory=list)
    n_instructions: int = 0

    def axis_fields(self, external: np.ndarray, options: FanucOptions) -> dict[str, str]:
        """The record's ``extended`` (a track as E1 of group 1, mm) and ``group2`` (the
        positioner's axes in motion group 2, deg) of external axes (m, rad)."""
        if not self.external:
            return {}
        values = language_values(self.external, external)
        track = np.array([a.kind == "track" for a in self.external], dtype=bool)
        return {
            "extended": extended_fields(values[track]),
            "group2": group_block(values[~track], options.uframe, options.utool),
        }

    def _number(self) -> str:
        self.n_instructions += 1
        return f"{self.n_instructions:4d}:"

    def instruction(self, text: str) -> None:
        """A non-motion instruction (``UFRAME_NUM=9``), without the closing ``;``."""
        self.lines.append(f"{self._number()}  {text} ;")

    def comments(self, lines: list[str]) -> None:
        """``! …`` comment lines, each wrapped to :data:`COMMENT_WIDTH` characters;
        a wrapped line's continuations start with ``..``."""
        for line in lines:
            chunks = textwrap.wrap(_ascii(line), COMMENT_WIDTH, subsequent_indent="..")
            for chunk in chunks or [""]:
                self.instruction(f"! {chunk}")

    def motion(self, letter: str, text: str) -> None:
        """A motion instruction ``J``/``L`` with its position, speed and termination."""
        self.lines.append(f"{self._number()}{letter} {text} ;")

    def circular(self, via: int, end: int, rest: str) -> None:
        """A circular instruction on two lines: the via point, then the end point."""
        self.lines.append(f"{self._number()}C P[{via}] ")
        self.lines.append(f"    :  P[{end}] {rest} ;")

    def joint_position(
        self, joints: np.ndarray, options: FanucOptions, external: np.ndarray
    ) -> int:
        """Add a joint-represented position (and the external axes); its number."""
        index = len(self.positions) + 1
        degrees = np.degrees(np.asarray(joints, dtype=float))
        self.positions.append(
            joint_record(
                index,
                degrees,
                options.uframe,
                options.utool,
                **self.axis_fields(external, options),
            )
        )
        return index

    def cartesian_position(
        self, target: Target, configs: dict[int, str], options: FanucOptions
    ) -> int:
        """Add a Cartesian position (the TCP in the user frame) and its CONFIG; its number."""
        index = len(self.positions) + 1
        self.positions.append(
            cartesian_record(
                index,
                xyzwpr(target.pose),
                configs[id(target)],
                options.uframe,
                options.utool,
                **self.axis_fields(target.external, options),
            )
        )
        return index

    def text(self, name: str, program: Program, options: FanucOptions) -> str:
        """The whole file."""
        created = options.created or datetime(2000, 1, 1)
        stamp = created.strftime("DATE %y-%m-%d  TIME %H:%M:%S")
        form = "path" if program.motion == "cartesian" else program.motion
        comment = f"trackplan {form}"[:ATTR_COMMENT_LENGTH]
        attributes = [
            f"/PROG  {name}",
            "/ATTR",
            "OWNER\t\t= MNEDITOR;",
            f'COMMENT\t\t= "{comment}";',
            "PROG_SIZE\t= 0;",
            f"CREATE\t\t= {stamp};",
            f"MODIFIED\t= {stamp};",
            "FILE_NAME\t= ;",
            "VERSION\t\t= 0;",
            f"LINE_COUNT\t= {self.n_instructions};",
            "MEMORY_SIZE\t= 0;",
            "PROTECT\t\t= READ_WRITE;",
            "TCD:  STACK_SIZE\t= 0,",
            "      TASK_PRIORITY\t= 50,",
            "      TIME_SLICE\t= 0,",
            "      BUSY_LAMP_OFF\t= 0,",
            "      ABORT_REQUEST\t= 0,",
            "      PAUSE_REQUEST\t= 0;",
            f"DEFAULT_GROUP\t= 1,{'1' if program.coordinated else '*'},*,*,*;",
            "CONTROL_CODE\t= 00000000 00000000;",
            "/MN",
        ]
        return "\n".join([*attributes, *self.lines, "/POS", *self.positions, "/END", ""])


__all__ = [
    "DEFAULT_MAX_POINTS",
    "FanucOptions",
    "FanucWriter",
    "render_fanuc",
]
