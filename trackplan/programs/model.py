"""A robot program in no controller's language: the moves a writer turns into KRL, RAPID,
FANUC TP or URScript.

:func:`trackplan.programs.build_program` makes a :class:`Program` from a verified run; each
program writer (:mod:`trackplan.writers`) prints it in its language. Everything here is in
SI units (m, rad, s) and in the controller's convention (joint values through the robot's
:class:`~trackplan.robots.controller.ControllerConvention`); writers convert to the units of
their language (mm and degrees for KRL, RAPID and TP).

Frames: a Cartesian :class:`Target`'s pose is the TCP in the **part frame** (the frame the
seams are written in). The program sets its base / work object to :attr:`Program.base`
(the part frame in the controller's world frame) and its tool to :attr:`Program.tool` (the
TCP in the flange), so that ``world_T_tcp = base · target.pose`` and a moved part needs
one frame changed.
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass, field
from typing import Literal

import numpy as np

MotionForm = Literal["cartesian", "joint"]
"""``cartesian``: the seams in the language's own path moves; ``joint``: the verified joint
trajectory replayed sample by sample."""

MOTION_FORMS: tuple[MotionForm, ...] = ("cartesian", "joint")


@dataclass(frozen=True, kw_only=True)
class ExternalAxis:
    """An external axis of a program: a track or a positioner axis.

    Attributes
    ----------
    name
        Its name in the trajectory (``track``, the positioner's joint names).
    kind
        ``track`` or ``positioner``.
    unit
        ``m`` (track) or ``rad`` (positioner); targets carry SI values, each writer
        converts to its language's unit (mm, degrees).
    v_max
        Rated velocity, m/s or rad/s.
    """

    name: str
    kind: str
    unit: str
    v_max: float


@dataclass(frozen=True, eq=False, kw_only=True)
class Target:
    """A Cartesian target and the planned joints there.

    Attributes
    ----------
    pose
        The TCP in the part frame, shape (4, 4), m.
    joints
        The planned joints at this point in the controller's convention, shape (n,), rad:
        writers derive configuration fields (KRL S/T, RAPID confdata, FANUC CONFIG) from
        them.
    model_joints
        The same planned joints in the robot model's convention, shape (n,), rad (for
        geometric configuration tests: wrist centre behind axis 1, elbow, flip).
    external
        The external axes there (:attr:`Program.external_axes`: track in m, positioner
        axes in rad), shape (e,); empty without external axes.
    """

    pose: np.ndarray
    joints: np.ndarray
    model_joints: np.ndarray
    external: np.ndarray = field(default_factory=lambda: np.zeros(0))


@dataclass(frozen=True, eq=False, kw_only=True)
class JointMove:
    """A move to a joint configuration, in the controller's own joint interpolation
    (KRL ``PTP``, RAPID ``MoveAbsJ``, FANUC ``J``, URScript ``movej``).

    Attributes
    ----------
    joints
        Controller joints at the end, shape (n,), rad.
    model_joints
        The same in the model's convention, shape (n,), rad.
    speed
        Share of each joint's rated velocity, in (0, 1] (KRL ``$VEL_AXIS``/PTP %, FANUC
        ``%``, RAPID ``v`` speed chosen from it, URScript ``v`` as that share of the
        slowest joint's rate).
    duration
        The move's time, s, when the program times it (``--motion joint``), else None.
    zone
        Blend radius at the end, m; 0 stops there.
    external
        The external axes at the end (:attr:`Program.external_axes`), shape (e,).
    """

    joints: np.ndarray
    model_joints: np.ndarray
    speed: float
    duration: float | None = None
    zone: float = 0.0
    external: np.ndarray = field(default_factory=lambda: np.zeros(0))


@dataclass(frozen=True, eq=False, kw_only=True)
class LinearMove:
    """A straight TCP move (``LIN``, ``MoveL``, ``L``, ``movel``).

    Attributes
    ----------
    target
        Where it ends.
    speed
        TCP speed, m/s.
    zone
        Blend radius at the end, m; 0 stops there (``FINE``).
    """

    target: Target
    speed: float
    zone: float = 0.0


@dataclass(frozen=True, eq=False, kw_only=True)
class CircularMove:
    """A circular TCP move through a via point (``CIRC``, ``MoveC``, ``C``, ``movec``).

    Attributes
    ----------
    via
        A point on the arc between its start and its end (the mid-arc point).
    target
        Where it ends.
    speed
        TCP speed, m/s.
    zone
        Blend radius at the end, m; 0 stops there.
    """

    via: Target
    target: Target
    speed: float
    zone: float = 0.0


@dataclass(frozen=True, eq=False, kw_only=True)
class SplineMove:
    """A TCP spline through points of a fitted curve (KRL ``SPLINE`` … ``ENDSPLINE`` with
    ``SPL``); a language without one writes linear moves through the same points, blended
    with ``zone``.

    Attributes
    ----------
    targets
        The points after the start, in order; the last is where it ends.
    speed
        TCP speed, m/s.
    zone
        Blend radius between the linear moves that replace it, and at its end, m.
    """

    targets: tuple[Target, ...]
    speed: float
    zone: float = 0.0


Move = JointMove | LinearMove | CircularMove | SplineMove
"""One instruction of a program."""


@dataclass(frozen=True, eq=False, kw_only=True)
class Section:
    """Consecutive moves of one kind of span: a seam, or a move between configurations.

    Attributes
    ----------
    kind
        ``seam``, ``approach``, ``retract``, ``air`` or ``start`` (the joint move to the
        planned start).
    label
        The seam's name or the kind (a comment in the program).
    moves
        The moves, in order.
    """

    kind: str
    label: str
    moves: tuple[Move, ...]


@dataclass(frozen=True, eq=False, kw_only=True)
class Budget:
    """How the Cartesian program keeps within the task tolerance (stated in the header).

    The executed path stays within ``tolerance`` of the seam when
    ``chord_error + zone ≤ tolerance − tracking_error``.

    Attributes
    ----------
    tolerance
        The task tolerance, m (the smallest over the seams).
    tracking_error
        The plan's own largest distance from the seam, m.
    chord_error
        Largest distance of the written moves (lines between points of a curve) from the
        planned path, m.
    zone
        Largest blend radius written, m.
    """

    tolerance: float
    tracking_error: float
    chord_error: float
    zone: float

    @property
    def slack(self) -> float:
        """``tolerance − tracking_error − chord_error − zone``, m (≥ 0 when kept)."""
        return self.tolerance - self.tracking_error - self.chord_error - self.zone


@dataclass(frozen=True, eq=False, kw_only=True)
class Program:
    """A robot program in no language.

    Attributes
    ----------
    name
        The program's name as asked (``--name`` or the case name); each writer makes it a
        valid identifier of its language (:mod:`trackplan.programs.names`).
    motion
        ``cartesian`` or ``joint``.
    robot
        The robot's name.
    vendor
        The controller family of the robot (``kuka``, ``abb``, ``fanuc``, ``ur``,
        ``generic``).
    n_dof
        Number of robot joints.
    base
        The part frame in the controller's world frame, shape (4, 4), m; with a
        positioner (:attr:`coordinated`) the part frame in the positioner's flange frame.
    tool
        The TCP in the flange, shape (4, 4), m.
    sections
        The program's sections in time order; the first is the joint move to the start.
    header
        Lines of the header comment (version, case, robot, placement, frames, verdict,
        duration, form, tolerance budget), without comment marks.
    sample_time
        The trajectory's sample time, s.
    period
        Time of each timed joint move, s (``joint`` form), else None.
    budget
        The tolerance budget (``cartesian`` form), else None.
    feasible
        The run's verdict.
    v_max
        Each joint's rated velocity, shape (n,), rad/s (for joint speeds as a share).
    external_axes
        The external axes every target carries, in order (track, then the positioner's);
        empty for an arm alone.
    """

    name: str
    motion: MotionForm
    robot: str
    vendor: str
    n_dof: int
    base: np.ndarray
    tool: np.ndarray
    sections: tuple[Section, ...]
    header: tuple[str, ...]
    sample_time: float
    period: float | None = None
    budget: Budget | None = None
    feasible: bool = True
    v_max: np.ndarray = field(default_factory=lambda: np.zeros(0))
    external_axes: tuple[ExternalAxis, ...] = ()

    @property
    def coordinated(self) -> bool:
        """True when a positioner carries the part: :attr:`base` is then the part frame in
        the positioner's flange frame (the carrier), and the controller must move the base
        with the positioner (coordinated motion: KRL ``EK``, RAPID ``ufmec``)."""
        return any(axis.kind == "positioner" for axis in self.external_axes)

    def moves(self) -> Iterator[Move]:
        """Every move in order."""
        for section in self.sections:
            yield from section.moves

    @property
    def n_points(self) -> int:
        """Number of targets written: one per joint, linear or spline point, two per
        circular move."""
        return sum(point_count(move) for move in self.moves())


@dataclass(frozen=True, eq=False, kw_only=True)
class Part:
    """A part of a long program, called in order from the main program.

    Attributes
    ----------
    index
        1-based number of the part.
    sections
        Its sections (a section split across parts keeps its kind and label in each).
    """

    index: int
    sections: tuple[Section, ...]

    @property
    def n_points(self) -> int:
        """Targets the part writes."""
        return sum(point_count(move) for section in self.sections for move in section.moves)


def split_program(program: Program, max_points: int | None) -> tuple[Part, ...]:
    """Split a program into parts of at most ``max_points`` targets each.

    Moves are never cut, except a spline longer than ``max_points``, which becomes
    consecutive splines (each starts where the one before ended). No target is lost and
    none is repeated: a part starts where the previous one stopped.

    Parameters
    ----------
    program
        The program.
    max_points
        Targets per part (≥ 2), or None for one part.

    Returns
    -------
    tuple[Part, ...]
        One part when the program fits (or ``max_points`` is None), else several.
    """
    if max_points is None or program.n_points <= max_points:
        return (Part(index=1, sections=program.sections),)
    if max_points < 2:
        raise ValueError("max_points must be at least 2")
    parts: list[Part] = []
    current: list[Section] = []
    moves: list[Move] = []
    count = 0

    def close_section(section: Section) -> None:
        nonlocal moves
        if moves:
            current.append(Section(kind=section.kind, label=section.label, moves=tuple(moves)))
            moves = []

    def close_part(section: Section) -> None:
        nonlocal current, count
        close_section(section)
        if current:
            parts.append(Part(index=len(parts) + 1, sections=tuple(current)))
        current, count = [], 0

    for section in program.sections:
        for move in section.moves:
            pieces: list[Move] = [move]
            if isinstance(move, SplineMove) and len(move.targets) > max_points:
                pieces = [
                    SplineMove(
                        targets=move.targets[k : k + max_points], speed=move.speed, zone=move.zone
                    )
                    for k in range(0, len(move.targets), max_points)
                ]
            for piece in pieces:
                if count + point_count(piece) > max_points:
                    close_part(section)
                moves.append(piece)
                count += point_count(piece)
        close_section(section)
    if current:
        parts.append(Part(index=len(parts) + 1, sections=tuple(current)))
    return tuple(parts)


def point_count(move: Move) -> int:
    """Targets a move writes: 2 for a circular move, the points of a spline, else 1."""
    if isinstance(move, CircularMove):
        return 2
    if isinstance(move, SplineMove):
        return len(move.targets)
    return 1


__all__ = [
    "MOTION_FORMS",
    "Budget",
    "CircularMove",
    "ExternalAxis",
    "JointMove",
    "LinearMove",
    "MotionForm",
    "Move",
    "Part",
    "Program",
    "Section",
    "SplineMove",
    "Target",
    "point_count",
    "split_program",
]
