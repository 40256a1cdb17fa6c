"""Universal Robots URScript: ``NAME.script``, one ``def NAME():`` … ``end`` program.

:func:`render_urscript` prints a :class:`~trackplan.programs.model.Program` (file name →
text); :class:`UrscriptWriter` writes it into a folder. The program sets the tool with
``set_tcp(p[…])``, holds the part frame in one pose variable (``global part = p[…]``) and
composes every Cartesian target ``pose_trans(part, p[…])``, so that a moved part needs one
line changed. Units are URScript's: m, rad, s; a pose's orientation is a rotation vector.

- ``cartesian``: ``movej`` to the planned start joints (URScript poses carry no
  configuration: the controller keeps the branch from there), then ``movel`` for lines and
  for the points of sampled curves (URScript has no spline move), ``movec`` for arcs, each
  with its speed ``v`` (m/s) and blend radius ``r`` (m); air moves as ``movej``.
- ``joint``: ``servoj(q, a=0, v=0, t=period, lookahead_time=…, gain=…)`` on every written
  sample, the period a multiple of the controller's cycle (0.002 s on e-Series, 0.008 s on
  CB3).

Long programs are split into functions ``NAME_part1`` … called in order from ``NAME``.
See ``docs/export-urscript.md`` for the conventions and their sources.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from trackplan.errors import CaseError
from trackplan.programs.model import (
    CircularMove,
    JointMove,
    LinearMove,
    Part,
    Program,
    SplineMove,
    Target,
    split_program,
)
from trackplan.programs.names import ascii_comment, program_identifier
from trackplan.robots.kinematics import forward_kinematics
from trackplan.robots.model import Robot
from trackplan.writers.drivable import Drives, check_drivable
from trackplan.writers.protocol import write_text_files
from trackplan.writers.source import ExportSource
from trackplan.writers.urscript_geometry import (
    arc_mode,
    blend_radii,
    check_period,
    joints_literal,
    number,
    pose_literal,
    pose_literals,
)

DEFAULT_MAX_POINTS = 5000
"""Targets per function when no ``max_points`` is given. Universal Robots publishes no
program size limit; the whole ``.script`` is one file the controller compiles before it
runs, so the split only keeps each function a size that PolyScope's script view and an
integrator can read (the order of RoboDK's 5000-line RAPID modules)."""

DEFAULT_CYCLE = 0.002
"""Controller step, s, when the robot's convention gives none: UR e-Series (500 Hz)."""

LINEAR_ACCELERATION = 1.2
"""Tool acceleration ``a`` of ``movel`` and ``movec``, m/s² (the URScript manual's default)."""

JOINT_ACCELERATION = 1.4
"""``a_joint``, rad/s², when no robot is given (the URScript manual's ``movej`` default)."""

SERVO_LOOKAHEAD_TIME = 0.1
"""``servoj`` ``lookahead_time``, s (range [0.03, 0.2]; the URScript manual's default)."""

SERVO_GAIN = 300.0
"""``servoj`` ``gain`` (range [100, 2000]; the URScript manual's default)."""

URSCRIPT = Drives(
    format="urscript",
    language="URScript",
    vendors=("ur",),
    no_external="Universal Robots controllers drive no external axes",
)
"""URScript drives Universal Robots arms: ``movej`` and ``servoj`` take 6 values."""

RESERVED = frozenset(
    "def end if elif else while for return global local thread run kill halt pass break "
    "continue and or xor not True False part v_joint a_joint movej movel movec servoj "
    "set_tcp pose_trans sleep sync stopj stopl".split()
)
"""Names a program may not take (URScript keywords, the functions and variables it uses)."""


@dataclass(frozen=True, eq=False)
class _Step:
    """One URScript move: ``kind`` movej | servoj | movel | movec."""

    kind: str
    speed: float
    zone: float
    target: Target | None = None
    via: Target | None = None
    joints: np.ndarray | None = None
    duration: float | None = None
    pose: np.ndarray | None = None  # TCP in the part frame at its end, (4, 4), if known


def urscript_name(name: str) -> str:
    """``name`` as a URScript function name: letters, digits, ``_``, starting with a
    letter, case kept, no length limit; a keyword or a name the program uses gets
    ``_program`` appended.

    Raises
    ------
    CaseError
        When nothing of ``name`` starts with a letter (key ``--name``).
    """
    identifier = program_identifier(name, key="--name")
    return f"{identifier}_program" if identifier in RESERVED else identifier


def render_urscript(
    program: Program,
    *,
    max_points: int | None = None,
    robot: Robot | None = None,
    lookahead_time: float = SERVO_LOOKAHEAD_TIME,
    gain: float = SERVO_GAIN,
) -> dict[str, str]:
    """Print a program as URScript.

    Parameters
    ----------
    program
        The program (SI units, controller joints, targets in the part frame).
    max_points
        Targets per function, or None for :data:`DEFAULT_MAX_POINTS`.
    robot
        The robot the program drives: its convention's ``cycle`` (s) checks the ``servoj``
        period, its kinematics place the ``movej`` waypoints for the blend radii and its
        acceleration limits give ``a_joint``. None: a 0.002 s cycle (said in the header),
        no blend at joint moves, ``a_joint`` 1.4 rad/s².
    lookahead_time, gain
        ``servoj``'s smoothing time (s) and proportional gain.

    Returns
    -------
    dict[str, str]
        ``{"NAME.script": text}``.

    Raises
    ------
    CaseError
        A robot that is not a UR or has not 6 joints (key ``--format``), a name that
        cannot be made valid (``--name``), a ``servoj`` period that is not a multiple of
        the controller's cycle (``--period``), fewer than 2 points per part
        (``--max-points``).
    """
    check_drivable(program, URSCRIPT)
    name = urscript_name(program.name)
    cycle = robot.convention.cycle if robot is not None else None
    cycle_note = "" if cycle is not None else " (assumed: the robot states no cycle)"
    cycle = cycle if cycle is not None else DEFAULT_CYCLE
    if max_points is not None and max_points < 2:
        raise CaseError(
            f"--max-points must be at least 2 (a circular move writes two targets), got "
            f"{max_points}",
            key="--max-points",
        )
    parts = split_program(program, DEFAULT_MAX_POINTS if max_points is None else max_points)
    items = [_part_items(part, program, robot) for part in parts]
    steps = [item for part_items in items for item in part_items if isinstance(item, _Step)]
    for step in steps:
        if step.kind == "servoj" and step.duration is not None:
            check_period(step.duration, program.sample_time, cycle)
    points = [
        None if step.kind == "servoj" or step.pose is None else step.pose[:3, 3] for step in steps
    ]
    radii = blend_radii(points, [step.zone for step in steps])
    modes = [
        arc_mode(steps[k - 1].pose if k > 0 else None, step.via.pose, step.target.pose)
        if step.kind == "movec" and step.via is not None and step.target is not None
        else 0
        for k, step in enumerate(steps)
    ]
    cartesian = [t for step in steps for t in (step.via, step.target) if t is not None]
    literals = pose_literals(np.array([t.pose for t in cartesian])) if cartesian else []
    literal_of = {id(t): text for t, text in zip(cartesian, literals, strict=True)}
    statements = iter(
        _statement(step, float(r), mode, lookahead_time, gain, literal_of)
        for step, r, mode in zip(steps, radii, modes, strict=True)
    )
    header = [
        *_header(program, name, cycle, cycle_note),
        f"largest blend radius written: {number(float(np.max(radii, initial=0.0)), 6)} m",
    ]
    lines = [f"def {name}():"]
    lines += [f"  # {ascii_comment(line)}" if line else "  #" for line in header]
    lines += [
        f"  set_tcp({pose_literal(program.tool)})",
        f"  global part = {pose_literal(program.base)}",
        f"  global v_joint = {number(_slowest(program.v_max, robot, 'v'), 6)}",
        f"  global a_joint = {number(_slowest(None, robot, 'a'), 6)}",
    ]
    single = len(items) == 1
    for part, part_items in zip(parts, items, strict=True):
        indent = "  " if single else "    "
        if not single:
            lines.append(f"  def {name}_part{part.index}():")
        for item in part_items:
            lines.append(indent + (item if isinstance(item, str) else next(statements)))
        if not single:
            lines.append("  end")
    if not single:
        lines += [f"  {name}_part{part.index}()" for part in parts]
    lines.append("end")
    return {f"{name}.script": "\n".join(lines) + "\n"}


def _header(program: Program, name: str, cycle: float, cycle_note: str) -> list[str]:
    """The header comment lines (without ``#``)."""
    lines = [f"{name}: URScript program for a Universal Robots controller, by trackplan", ""]
    lines += list(program.header)
    lines += [
        "",
        "units: m, rad, s; poses p[x, y, z, rx, ry, rz] with (rx, ry, rz) a rotation vector",
        "frames: set_tcp = the TCP in the tool flange; part = the part frame in the robot's",
        "  Base; every Cartesian target is pose_trans(part, p[...]): a moved part needs only",
        "  'part' changed",
        "movej: v and a are shares of v_joint (the slowest joint's rated speed, rad/s) and",
        "  a_joint (rad/s^2); movel/movec: a in m/s^2, v in m/s, blend radius r in m, at most",
        "  40 % of the distance to the neighbouring waypoints (UR: blends cannot overlap)",
    ]
    if program.motion == "joint":
        period = program.period if program.period is not None else program.sample_time
        lines += [
            f"joint form: servoj every {number(period, 6)} s, a multiple of the controller's "
            f"{number(cycle, 6)} s cycle{cycle_note}",
        ]
    return lines


def _slowest(v_max: np.ndarray | None, robot: Robot | None, kind: str) -> float:
    """The slowest joint's rated speed (``v``, rad/s) or acceleration (``a``, rad/s²)."""
    if kind == "v" and v_max is not None and v_max.size:
        return float(np.min(v_max))
    if robot is not None:
        return float(np.min(robot.v_max if kind == "v" else robot.a_max))
    return 1.05 if kind == "v" else JOINT_ACCELERATION


def _part_items(part: Part, program: Program, robot: Robot | None) -> list[str | _Step]:
    """A part's comment lines and moves, in order."""
    items: list[str | _Step] = []
    for section in part.sections:
        items.append(ascii_comment(f"# {section.kind}: {section.label}"))
        if section.kind == "start":
            items.append(
                "# the joint move to the planned start: URScript poses carry no "
                "configuration, the controller keeps the arm's branch from here"
            )
        for move in section.moves:
            if isinstance(move, JointMove):
                timed = move.duration is not None
                pose = None if timed else _tcp_pose(move.model_joints, program, robot)
                kind = "servoj" if timed else "movej"
                items.append(
                    _Step(
                        kind,
                        move.speed,
                        move.zone,
                        joints=move.joints,
                        duration=move.duration,
                        pose=pose,
                    )
                )
            elif isinstance(move, LinearMove):
                items.append(
                    _Step("movel", move.speed, move.zone, target=move.target, pose=move.target.pose)
                )
            elif isinstance(move, CircularMove):
                items.append(
                    _Step(
                        "movec",
                        move.speed,
                        move.zone,
                        target=move.target,
                        via=move.via,
                        pose=move.target.pose,
                    )
                )
            elif isinstance(move, SplineMove):
                items.extend(
                    _Step("movel", move.speed, move.zone, target=target, pose=target.pose)
                    for target in move.targets
                )
    return items


def _tcp_pose(model_joints: np.ndarray, program: Program, robot: Robot | None) -> np.ndarray | None:
    """The TCP in the part frame at model joints, (4, 4), or None without a robot."""
    if robot is None:
        return None
    flange = forward_kinematics(robot, model_joints) @ np.linalg.inv(robot.T_flange_tool)
    world_tcp = robot.convention.world_from_base(flange @ program.tool)
    pose: np.ndarray = np.linalg.inv(program.base) @ world_tcp
    return pose


def _statement(
    step: _Step,
    r: float,
    mode: int,
    lookahead_time: float,
    gain: float,
    literal_of: dict[int, str],
) -> str:
    """One move as URScript; ``literal_of`` holds each target's ``p[…]`` by ``id``."""
    if step.kind == "servoj":
        assert step.joints is not None and step.duration is not None
        return (
            f"servoj({joints_literal(step.joints)}, a=0, v=0, t={number(step.duration, 6)}, "
            f"lookahead_time={number(lookahead_time, 6)}, gain={number(gain, 3)})"
        )
    if step.kind == "movej":
        assert step.joints is not None
        share = number(step.speed, 6)
        return (
            f"movej({joints_literal(step.joints)}, a={share}*a_joint, v={share}*v_joint, "
            f"r={number(r, 6)})"
        )
    assert step.target is not None
    to = f"pose_trans(part, {literal_of[id(step.target)]})"
    speeds = f"a={number(LINEAR_ACCELERATION, 6)}, v={number(step.speed, 6)}, r={number(r, 6)}"
    if step.kind == "movec":
        assert step.via is not None
        via = f"pose_trans(part, {literal_of[id(step.via)]})"
        return f"movec({via}, {to}, {speeds}, mode={mode})"
    return f"movel({to}, {speeds})"


@dataclass(frozen=True)
class UrscriptWriter:
    """``--format urscript``: ``NAME.script`` (ASCII, ``\\n`` line ends) in the folder
    ``urscript``."""

    name: str = "urscript"
    suffix: str = ".script"
    default_file: str = "urscript"
    folder: bool = True

    def write(self, source: ExportSource, folder: Path, **options: Any) -> tuple[str, ...]:
        """Build the run's program and write its ``.script`` file into ``folder``.

        Parameters
        ----------
        source
            The export source: ``source.program(motion=…, name=…, period=…, force=…)``
            builds the program; ``source.run.case.robot`` is the robot.
        folder
            A fresh staging folder.
        **options
            ``motion`` (``cartesian``), ``name``, ``period`` (s), ``force``,
            ``max_points``.

        Returns
        -------
        tuple[str, ...]
            The names of the files written.
        """
        texts = render_urscript(
            source.program_of(options), robot=source.robot, max_points=options.get("max_points")
        )
        return write_text_files(folder, texts)


__all__ = [
    "DEFAULT_CYCLE",
    "DEFAULT_MAX_POINTS",
    "UrscriptWriter",
    "render_urscript",
    "urscript_name",
]
