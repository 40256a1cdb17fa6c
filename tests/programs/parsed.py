"""A controller program read back by a test parser, in one neutral form.

Each language's parser in this folder (``krl_parser``, ``rapid_parser``, ``fanuc_parser``,
``urscript_parser``) reads the files a writer wrote, independently of the writer's code, and
returns a :class:`ParsedProgram` in SI units (m, rad, s), so that the round-trip tests compare
every target with the plan the same way for every language.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np


@dataclass
class ParsedTarget:
    """One target as the program states it.

    Attributes
    ----------
    kind
        ``joint`` (PTP/MoveAbsJ/J/movej/servoj), ``linear``, ``circular_via``,
        ``circular_end`` or ``spline``.
    pose
        TCP in the part frame (the program's base/work object), shape (4, 4), m; None for a
        joint target.
    joints
        Controller joints, shape (n,), rad, for a joint target (or a Cartesian target that
        also states them); else None.
    config
        The language's configuration fields as written, e.g. ``{"S": 2, "T": 35}``,
        ``{"cf1": 0, "cf4": -1, "cf6": 0, "cfx": 1}``, ``{"flip": "N", "elbow": "U",
        "front": "T", "turns": (0, 0, 0)}``; empty when none.
    speed
        TCP speed (m/s) for a Cartesian move, share of the joint rate for a joint move,
        or None when the move states none.
    zone
        Blend radius at its end, m (0 for a stop point), or None.
    duration
        Time of a timed move, s, else None.
    part
        The name of the routine (procedure, subprogram, function) it is in.
    external
        The external axes as written, in the language's units (mm for a track, degrees
        for a rotary axis; the parser does not know which axis is which), in the
        language's order (KRL E1 …, RAPID eax_a …, FANUC E1 of group 1 then group 2's
        J1 …), the unused ones (RAPID 9E9) left out; empty when none.
    """

    kind: str
    pose: np.ndarray | None = None
    joints: np.ndarray | None = None
    config: dict[str, object] = field(default_factory=dict)
    speed: float | None = None
    zone: float | None = None
    duration: float | None = None
    part: str = ""
    external: np.ndarray = field(default_factory=lambda: np.zeros(0))


@dataclass
class ParsedProgram:
    """A program read back.

    Attributes
    ----------
    name
        The main routine's name.
    base
        The base / work object frame set by the program (part frame in the controller's
        world), shape (4, 4), m.
    tool
        The tool frame set by the program (TCP in the flange), shape (4, 4), m.
    targets
        Every target in execution order, following the main routine's calls into parts.
    header
        The header comment lines, without comment marks.
    files
        The file names read.
    coupled
        The mechanism the base moves with (coordinated motion: KRL ``EK``'s machine,
        RAPID's ``ufmec``, FANUC's motion group 2), empty when the base is fixed.
    """

    name: str
    base: np.ndarray
    tool: np.ndarray
    targets: list[ParsedTarget]
    header: list[str] = field(default_factory=list)
    files: list[str] = field(default_factory=list)
    coupled: str = ""
