"""A test parser of FANUC TP ``.ls`` files, independent of trackplan's writer.

:func:`parse_fanuc` reads the ASCII form of TP programs (``/PROG``, ``/ATTR``, ``/MN``,
``/POS``, ``/END``) with a lark grammar, follows ``CALL`` from the main program into the
other files, and returns a :class:`~tests.programs.parsed.ParsedProgram` in SI units: the
positions in their user frame (m), joints in rad, ``CONFIG`` fields as written. It follows
the frames a program assigns (``PR[i]=LPOS``, ``PR[i,j]=v``, ``UFRAME[n]=PR[i]``,
``UTOOL[m]=PR[i]``, ``UFRAME_NUM``, ``UTOOL_NUM``); any other instruction is read as text
and skipped.

The syntax follows public ``.ls`` files (see ``test_fanuc.py`` for the excerpts it reads)
and RoboDK's FANUC post; the orientation is ``Rz(R)·Ry(P)·Rx(W)``.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field

import numpy as np
from lark import Lark, Token, Transformer

from tests.programs.parsed import ParsedProgram, ParsedTarget

GRAMMAR = r"""
start: prog attr appl? mn pos "/END"

prog: "/PROG" NAME NAME?
attr: "/ATTR" ATTR_ITEM*
appl: "/APPL" ATTR_ITEM*
mn: "/MN" line*
pos: "/POS" position*

line: LINENO ":" statement? ";"
?statement: joint | linear | circular | comment | frame_element | frame_assign
          | frame_select | call | other
joint: MOTION_J target SPEED TERM option?
linear: MOTION_L target SPEED TERM option?
circular: MOTION_C target ":" target SPEED TERM option?
target: POSREF
comment: COMMENT
frame_element: PR_ELEMENT
frame_assign: FRAME_ASSIGN
frame_select: FRAME_SELECT
call: CALL
other: OTHER
option: OPTION

position: "P" "[" INT (":" LABEL?)? "]" "{" group+ "}" ";"
group: GROUP ":" "UF" ":" INT "," "UT" ":" INT "," config? field ("," field)* ","?
config: "CONFIG" ":" CONFIG_STRING ","
field: AXIS "=" NUMBER UNIT

NAME: /[A-Za-z][A-Za-z0-9_]*/
ATTR_ITEM: /[A-Za-z_][^;]*;/
LINENO: /\d+/
MOTION_J.3: /J(?=\s)/
MOTION_L.3: /L(?=\s)/
MOTION_C.3: /C(?=\s)/
POSREF: /(P|PR)\[\d+(:[^\]]*)?\]/
SPEED: /(\d+\.?\d*|\.\d+)\s*(%|mm\/sec|msec|sec|cm\/min|deg\/sec|inch\/min)/
TERM: /FINE|CNT\s*\d+|CR\s*\d+/
OPTION: /[^;\s][^;]*/
COMMENT.3: /![^;]*/
PR_ELEMENT.3: /PR\[\d+,\d+\]\s*=\s*[-+]?(\d+\.?\d*|\.\d+)/
FRAME_ASSIGN.3: /(UFRAME|UTOOL)\[\d+\]\s*=\s*PR\[\d+\]/
FRAME_SELECT.3: /(UFRAME_NUM|UTOOL_NUM)\s*=\s*\d+/
CALL.3: /CALL\s+[A-Za-z][A-Za-z0-9_]*/
OTHER.1: /[A-Za-z$][^;]*/
LABEL: /[^\]]+/
GROUP: /GP\d+/
CONFIG_STRING: /'[^']*'/
AXIS: /[XYZWPR]|J\d+|E\d+/
NUMBER: /[-+]?(\d+\.?\d*|\.\d+)([eE][-+]?\d+)?/
UNIT: "mm" | "deg"

%import common.INT
%import common.WS
%ignore WS
"""

_PARSER = Lark(GRAMMAR, parser="lalr", lexer="contextual")


@dataclass
class Motion:
    """A motion instruction as written: its kind, positions, speed and termination."""

    letter: str
    positions: list[str]
    speed: str
    term: str


@dataclass
class Record:
    """A ``/POS`` record of group 1: frame numbers, CONFIG, fields (name → value, unit)."""

    uframe: int
    utool: int
    config: str | None
    fields: dict[str, float]
    group2: dict[str, float] = field(default_factory=dict)


@dataclass
class Listing:
    """One ``.ls`` file read: its name, instructions in order and positions by number."""

    name: str
    statements: list[tuple[str, object]] = field(default_factory=list)
    positions: dict[int, Record] = field(default_factory=dict)


class _ToListing(Transformer[Token, Listing]):
    """The parse tree as a :class:`Listing`."""

    def start(self, items: list[object]) -> Listing:
        name = str(items[0])
        mn = next(item for item in items if isinstance(item, _Mn))
        pos = next(item for item in items if isinstance(item, _Pos))
        return Listing(name=name, statements=mn.statements, positions=pos.records)

    def prog(self, items: list[Token]) -> str:
        return str(items[0])

    def attr(self, items: list[Token]) -> None:
        return None

    def appl(self, items: list[Token]) -> None:
        return None

    def mn(self, items: list[object]) -> _Mn:
        return _Mn([item for item in items if item is not None])  # type: ignore[misc]

    def line(self, items: list[object]) -> tuple[str, object] | None:
        statements = [item for item in items if isinstance(item, tuple)]
        return statements[0] if statements else ("empty", None)

    def _motion(self, letter: str, items: list[object]) -> tuple[str, object]:
        targets = [item for item in items if isinstance(item, str) and item.startswith("P")]
        tokens = {item.type: str(item) for item in items if isinstance(item, Token)}
        speed, term = tokens["SPEED"], tokens["TERM"]
        return ("motion", Motion(letter, targets, speed, term))

    def joint(self, items: list[object]) -> tuple[str, object]:
        return self._motion("J", items)

    def linear(self, items: list[object]) -> tuple[str, object]:
        return self._motion("L", items)

    def circular(self, items: list[object]) -> tuple[str, object]:
        return self._motion("C", items)

    def target(self, items: list[Token]) -> str:
        return str(items[0])

    def option(self, items: list[Token]) -> str:
        return "option:" + str(items[0])

    def comment(self, items: list[Token]) -> tuple[str, object]:
        return ("comment", str(items[0])[1:].strip())

    def frame_element(self, items: list[Token]) -> tuple[str, object]:
        match = re.fullmatch(r"PR\[(\d+),(\d+)\]\s*=\s*(\S+)", str(items[0]))
        assert match is not None
        return ("element", (int(match[1]), int(match[2]), float(match[3])))

    def frame_assign(self, items: list[Token]) -> tuple[str, object]:
        match = re.fullmatch(r"(UFRAME|UTOOL)\[(\d+)\]\s*=\s*PR\[(\d+)\]", str(items[0]))
        assert match is not None
        return ("assign", (match[1], int(match[2]), int(match[3])))

    def frame_select(self, items: list[Token]) -> tuple[str, object]:
        match = re.fullmatch(r"(UFRAME_NUM|UTOOL_NUM)\s*=\s*(\d+)", str(items[0]))
        assert match is not None
        return ("select", (match[1], int(match[2])))

    def call(self, items: list[Token]) -> tuple[str, object]:
        return ("call", str(items[0]).split()[1])

    def other(self, items: list[Token]) -> tuple[str, object]:
        return ("other", str(items[0]).strip())

    def pos(self, items: list[tuple[int, Record]]) -> _Pos:
        return _Pos(dict(items))

    def position(self, items: list[object]) -> tuple[int, Record]:
        index = int(str(items[0]))
        groups = dict(item for item in items if isinstance(item, tuple))
        record = groups["GP1"]
        if "GP2" in groups:
            record.group2 = groups["GP2"].fields
        return index, record

    def group(self, items: list[object]) -> tuple[str, Record]:
        group, uframe, utool = str(items[0]), int(str(items[1])), int(str(items[2]))
        config = next((item for item in items if isinstance(item, _Config)), None)
        fields = dict(item for item in items if isinstance(item, tuple))
        return group, Record(uframe, utool, None if config is None else config.text, fields)

    def config(self, items: list[Token]) -> _Config:
        return _Config(str(items[0])[1:-1])

    def field(self, items: list[Token]) -> tuple[str, float]:
        return str(items[0]), float(str(items[1]))


@dataclass
class _Mn:
    statements: list[tuple[str, object]]


@dataclass
class _Pos:
    records: dict[int, Record]


@dataclass
class _Config:
    text: str


def read_listing(text: str) -> Listing:
    """Parse one ``.ls`` file."""
    return _ToListing().transform(_PARSER.parse(text))


def wpr_pose(values: list[float]) -> np.ndarray:
    """The pose of X, Y, Z (mm) and W, P, R (deg): ``Rz(R)·Ry(P)·Rx(W)``, m."""
    x, y, z, w, p, r = values
    w, p, r = np.radians([w, p, r])
    rx = np.array([[1, 0, 0], [0, np.cos(w), -np.sin(w)], [0, np.sin(w), np.cos(w)]])
    ry = np.array([[np.cos(p), 0, np.sin(p)], [0, 1, 0], [-np.sin(p), 0, np.cos(p)]])
    rz = np.array([[np.cos(r), -np.sin(r), 0], [np.sin(r), np.cos(r), 0], [0, 0, 1]])
    pose = np.eye(4)
    pose[:3, :3] = rz @ ry @ rx
    pose[:3, 3] = np.array([x, y, z]) / 1000.0
    return pose


def parse_config(text: str) -> dict[str, object]:
    """``'N U T, 0, 0, 0'`` as ``{"flip", "elbow", "front", "turns"}``."""
    letters, *turns = [part.strip() for part in text.split(",")]
    flip, elbow, front = letters.split()
    return {"flip": flip, "elbow": elbow, "front": front, "turns": tuple(int(t) for t in turns)}


@dataclass
class _State:
    registers: dict[int, list[float]] = field(default_factory=dict)
    frames: dict[tuple[str, int], np.ndarray] = field(default_factory=dict)
    uframe: int = 0
    utool: int = 0
    base: np.ndarray | None = None
    tool: np.ndarray | None = None
    coupled: str = ""


def parse_fanuc(files: dict[str, str], *, strict: bool = True) -> ParsedProgram:
    """Read a TP program and the programs it calls.

    Parameters
    ----------
    files
        File name → text; the main program is the one no other file calls (else the
        first).
    strict
        Raise ``KeyError`` on a ``CALL`` of a program not in ``files``; else skip it.

    Returns
    -------
    ParsedProgram
        Targets in execution order (SI units), the frames the program assigned (identity
        where it assigns none), the main program's leading comments as its header.
    """
    listings = {listing.name: listing for listing in map(read_listing, files.values())}
    called = {
        value
        for listing in listings.values()
        for kind, value in listing.statements
        if kind == "call"
    }
    roots = [name for name in listings if name not in called]
    main = listings[roots[0] if roots else next(iter(listings))]
    state = _State()
    targets: list[ParsedTarget] = []
    _run(main, listings, state, targets, strict)
    return ParsedProgram(
        name=main.name,
        base=np.eye(4) if state.base is None else state.base,
        tool=np.eye(4) if state.tool is None else state.tool,
        targets=targets,
        header=_header(main),
        files=list(files),
        coupled=state.coupled,
    )


def _header(listing: Listing) -> list[str]:
    """Leading comments, continuations (``..``) joined to their line."""
    header: list[str] = []
    for kind, value in listing.statements:
        if kind != "comment":
            break
        text = str(value)
        if text.startswith("..") and header:
            header[-1] = f"{header[-1]} {text[2:]}"
        else:
            header.append(text)
    return header


def _run(
    listing: Listing,
    listings: dict[str, Listing],
    state: _State,
    targets: list[ParsedTarget],
    strict: bool,
) -> None:
    for kind, value in listing.statements:
        if kind == "element":
            register, element, number = value  # type: ignore[misc]
            state.registers.setdefault(register, [0.0] * 6)[element - 1] = number
        elif kind == "other" and re.fullmatch(r"PR\[(\d+)\]\s*=\s*LPOS", str(value)):
            register = int(re.findall(r"\d+", str(value))[0])
            state.registers[register] = [0.0] * 6
        elif kind == "assign":
            which, number, register = value  # type: ignore[misc]
            state.frames[(which, number)] = wpr_pose(state.registers[register])
        elif kind == "select":
            which, number = value  # type: ignore[misc]
            if which == "UFRAME_NUM":
                state.uframe = number
            else:
                state.utool = number
        elif kind == "call" and (strict or str(value) in listings):
            _run(listings[str(value)], listings, state, targets, strict)
        elif kind == "motion":
            _motion(listing, value, state, targets)  # type: ignore[arg-type]


def _motion(listing: Listing, motion: Motion, state: _State, targets: list[ParsedTarget]) -> None:
    if state.base is None:
        state.base = state.frames.get(("UFRAME", state.uframe))
        state.tool = state.frames.get(("UTOOL", state.utool))
    speed, duration = _speed(motion.speed)
    term = motion.term.replace(" ", "")
    zone = 0.0 if term == "FINE" else float(term[2:]) / 1000.0 if term.startswith("CR") else None
    kinds = {"J": ["joint"], "L": ["linear"], "C": ["circular_via", "circular_end"]}[motion.letter]
    for k, (kind, reference) in enumerate(zip(kinds, motion.positions, strict=True)):
        last = k == len(kinds) - 1
        target = ParsedTarget(kind=kind, part=listing.name)
        if last:
            target.speed, target.duration, target.zone = speed, duration, zone
        match = re.fullmatch(r"P\[(\d+)(:[^\]]*)?\]", reference)
        if match is not None:
            record = listing.positions[int(match[1])]
            if "X" in record.fields:
                target.pose = wpr_pose([record.fields[axis] for axis in "XYZWPR"])
            joints = [record.fields[f"J{i}"] for i in range(1, 10) if f"J{i}" in record.fields]
            if joints:
                target.joints = np.radians(joints)
            if record.config is not None:
                target.config = parse_config(record.config)
            # group 1's extended axes E1 … (mm or deg), then group 2's axes J1 …
            extended = [record.fields[f"E{i}"] for i in range(1, 4) if f"E{i}" in record.fields]
            group2 = [record.group2[f"J{i}"] for i in range(1, 10) if f"J{i}" in record.group2]
            target.external = np.array(extended + group2, dtype=float)
            if group2:
                state.coupled = "GP2"
        targets.append(target)


def _speed(text: str) -> tuple[float | None, float | None]:
    """(speed, duration) of a TP speed: % → share, mm/sec → m/s, sec/msec → s."""
    match = re.fullmatch(r"(\d+\.?\d*|\.\d+)\s*(\S+)", text)
    assert match is not None
    value, unit = float(match[1]), match[2]
    if unit == "%":
        return value / 100.0, None
    if unit == "mm/sec":
        return value / 1000.0, None
    if unit == "cm/min":
        return value / 6000.0, None
    if unit == "sec":
        return None, value
    if unit == "msec":
        return None, value / 1000.0
    return None, None


__all__ = ["Listing", "parse_config", "parse_fanuc", "read_listing", "wpr_pose"]
