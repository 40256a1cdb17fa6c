"""Read ABB RAPID modules back into a :class:`ParsedProgram` (tests only).

A lark grammar of the RAPID subset that robot programs of data declarations and motion
instructions use (RAPID is case-insensitive; optional arguments ``\\Name:=value`` follow
an argument with or without a comma). It does not import trackplan's writer: it reads the
syntax of the RAPID reference manual — robtarget ``[[x,y,z],[q1..q4],[cf1,cf4,cf6,cfx],
[eax]]`` in mm, jointtarget ``[[j1..j6],[eax]]`` in degrees, speeddata ``[v_tcp, v_ori,
v_leax, v_reax]``, zonedata ``[finep, pzone_tcp, …]``, tooldata ``[robhold, tframe,
tload]``, wobjdata ``[robhold, ufprog, ufmec, uframe, oframe]`` — and the predefined
speeds (``v5`` … ``v7000``), zones (``fine``, ``z0`` … ``z200``), ``tool0`` and ``wobj0``.
Execution starts at ``main`` and follows procedure calls.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from lark import Lark, Token, Transformer

from tests.programs.parsed import ParsedProgram, ParsedTarget

GRAMMAR = r"""
start: module+
module: _MODULE NAME attributes? item* _ENDMODULE
attributes: "(" NAME ("," NAME)* ")"
?item: data | proc
data: scope? storage NAME NAME (":=" value)? ";"
scope: LOCAL | TASK
storage: CONST | PERS | VAR
proc: scope? _PROC NAME "(" ")" call* _ENDPROC
call: NAME (first rest*)? ";"
first: value | option
rest: "," value | ","? option
option: "\\" NAME (":=" value)?
?value: list | SIGNED_NUMBER -> number | ESCAPED_STRING -> string | NAME -> name
list: "[" value ("," value)* "]"

_MODULE: "MODULE"i
_ENDMODULE: "ENDMODULE"i
_PROC: "PROC"i
_ENDPROC: "ENDPROC"i
LOCAL: "LOCAL"i
TASK: "TASK"i
CONST: "CONST"i
PERS: "PERS"i
VAR: "VAR"i
NAME: /[A-Za-z][A-Za-z0-9_]*/
COMMENT: /![^\n]*/
%import common.SIGNED_NUMBER
%import common.ESCAPED_STRING
%import common.WS
%ignore WS
%ignore COMMENT
"""

PREDEFINED_ZONES_MM = {
    "fine": 0.0,
    "z0": 0.3,
    "z1": 1.0,
    "z5": 5.0,
    "z10": 10.0,
    "z15": 15.0,
    "z20": 20.0,
    "z30": 30.0,
    "z40": 40.0,
    "z50": 50.0,
    "z60": 60.0,
    "z80": 80.0,
    "z100": 100.0,
    "z150": 150.0,
    "z200": 200.0,
}
"""pzone_tcp (mm) of RAPID's predefined zonedata (RAPID reference, zonedata)."""

IDENTITY_POSE: list[Any] = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0, 0.0]]


@dataclass
class Call:
    """One instruction: its name, positional arguments and optional arguments."""

    name: str
    args: list[Any] = field(default_factory=list)
    options: dict[str, Any] = field(default_factory=dict)


@dataclass
class Name:
    """A reference to data by name."""

    text: str


class _Tree(Transformer[Token, Any]):
    def number(self, items: list[Token]) -> float:
        return float(items[0])

    def string(self, items: list[Token]) -> str:
        return str(items[0])[1:-1]

    def name(self, items: list[Token]) -> Any:
        word = str(items[0])
        if word.upper() in ("TRUE", "FALSE"):
            return word.upper() == "TRUE"
        return Name(word)

    def list(self, items: list[Any]) -> list[Any]:
        return items

    def option(self, items: list[Any]) -> tuple[str, Any]:
        return (str(items[0]).lower(), items[1] if len(items) > 1 else True)

    def first(self, items: list[Any]) -> Any:
        return items[0]

    def rest(self, items: list[Any]) -> Any:
        return items[0]

    def call(self, items: list[Any]) -> Call:
        call = Call(str(items[0]))
        for item in items[1:]:
            if isinstance(item, tuple):
                call.options[item[0]] = item[1]
            else:
                call.args.append(item)
        return call

    def storage(self, items: list[Token]) -> str:
        return str(items[0]).upper()

    def scope(self, items: list[Token]) -> str:
        return str(items[0]).upper()

    def data(self, items: list[Any]) -> tuple[str, str, str, Any]:
        items = [item for item in items if item not in ("LOCAL", "TASK")]
        type_name, name = str(items[1]), str(items[2])
        return ("data", type_name.lower(), name.lower(), items[3] if len(items) > 3 else None)

    def proc(self, items: list[Any]) -> tuple[str, str, list[Call]]:
        items = [item for item in items if item not in ("LOCAL",)]
        return ("proc", str(items[0]).lower(), [item for item in items[1:]])

    def attributes(self, items: list[Token]) -> None:
        return None

    def module(self, items: list[Any]) -> tuple[str, list[Any]]:
        return (str(items[0]), [item for item in items[1:] if item is not None])


_PARSER = Lark(GRAMMAR, parser="lalr", transformer=_Tree())


def quaternion_matrix(q: list[float]) -> np.ndarray:
    """Rotation matrix of a unit quaternion [q1, q2, q3, q4], q1 the scalar."""
    w, x, y, z = np.asarray(q, dtype=float) / np.linalg.norm(q)
    return np.array(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
            [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
            [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)],
        ]
    )


def pose_matrix(pose: list[Any]) -> np.ndarray:
    """4×4 transform (m) of a RAPID pose ``[[x,y,z],[q1..q4]]`` (mm)."""
    T = np.eye(4)
    T[:3, :3] = quaternion_matrix(pose[1])
    T[:3, 3] = np.asarray(pose[0], dtype=float) / 1000.0
    return T


@dataclass
class Module:
    """One module as declared: its data (name → value or None) and procedures."""

    name: str
    data: dict[str, Any]
    procs: dict[str, list[Call]]


def parse_modules(text: str) -> list[Module]:
    """The modules of one file, names of data and procedures in lower case."""
    modules = []
    for module_name, items in _PARSER.parse(text).children:
        module = Module(name=module_name, data={}, procs={})
        for item in items:
            if item[0] == "data":
                module.data[item[2]] = item[3]
            else:
                module.procs[item[1]] = item[2]
        modules.append(module)
    return modules


def parse_rapid(files: dict[str, str]) -> ParsedProgram:
    """Read RAPID modules (file name → text) from ``main`` on.

    Returns
    -------
    ParsedProgram
        ``name`` is the module that holds ``main`` (RAPID's entry routine is always
        ``main``; the module carries the program's name). Targets in SI units: poses in
        the work object (m), controller joints (rad), speeds (m/s), zones (m), durations
        (s); config ``{"cf1", "cf4", "cf6", "cfx"}``.
    """
    data: dict[str, Any] = {}
    procs: dict[str, list[Call]] = {}
    header: list[str] = []
    main_module = ""
    for text in files.values():
        for module in parse_modules(text):
            data.update(module.data)
            procs.update(module.procs)
            if "main" in module.procs:
                main_module = module.name
                header = _header(text)
    if "main" not in procs:
        raise ValueError("no PROC main() in the modules")
    state = _Run(data=data, procs=procs)
    state.run("main")
    return ParsedProgram(
        name=main_module,
        base=state.base if state.base is not None else np.eye(4),
        tool=state.tool if state.tool is not None else np.eye(4),
        targets=state.targets,
        header=header,
        files=list(files),
        coupled=state.coupled,
    )


def _header(text: str) -> list[str]:
    """Comment lines before the module's first declaration or procedure."""
    lines: list[str] = []
    rows = text.splitlines()
    start = next(i for i, row in enumerate(rows) if row.strip().upper().startswith("MODULE"))
    for line in rows[start + 1 :]:
        stripped = line.strip()
        if stripped.startswith("!"):
            lines.append(re.sub(r"^!\s?", "", stripped))
        elif stripped:
            break
    return lines


@dataclass
class _Run:
    data: dict[str, Any]
    procs: dict[str, list[Call]]
    targets: list[ParsedTarget] = field(default_factory=list)
    base: np.ndarray | None = None
    tool: np.ndarray | None = None
    cartesian: bool = False
    coupled: str = ""

    def value(self, item: Any) -> Any:
        if isinstance(item, Name):
            key = item.text.lower()
            if key in self.data:
                return self.value(self.data[key])
            return item
        if isinstance(item, list):
            return [self.value(v) for v in item]
        return item

    def run(self, proc: str, depth: int = 0) -> None:
        if depth > 50:
            raise ValueError("procedure calls nest too deep")
        for call in self.procs[proc]:
            word = call.name.lower()
            if word in self.procs:
                self.run(word, depth + 1)
            elif word in ("moveabsj", "movel", "movec", "movej"):
                self.move(word, call, proc)

    def frames(self, call: Call, tool: Any, cartesian: bool) -> None:
        """Take the program's frames from its first Cartesian move (else its first move)."""
        tool_value = self.value(tool)
        tool_pose = pose_matrix(tool_value[1]) if isinstance(tool_value, list) else np.eye(4)
        wobj = self.value(call.options.get("wobj", Name("wobj0")))
        coupled = ""
        if isinstance(wobj, list):
            base = pose_matrix(wobj[3]) @ pose_matrix(wobj[4])
            # ufprog FALSE: the user frame moves with the mechanical unit ufmec
            coupled = str(wobj[2]) if not _true(wobj[1]) else ""
        else:
            base = np.eye(4)
        if self.tool is None or (cartesian and not self.cartesian):
            self.tool, self.base, self.coupled = tool_pose, base, coupled
        self.cartesian |= cartesian

    def speed_zone(self, call: Call, speed: Any, zone: Any) -> tuple[float | None, float]:
        speed_value = self.value(speed)
        v_tcp: float | None = None
        if isinstance(speed_value, list):
            v_tcp = float(speed_value[0]) / 1000.0
        elif isinstance(speed_value, Name) and re.fullmatch(r"v\d+", speed_value.text.lower()):
            v_tcp = float(speed_value.text[1:]) / 1000.0
        if "v" in call.options:
            v_tcp = float(self.value(call.options["v"])) / 1000.0
        zone_value = self.value(zone)
        if isinstance(zone_value, list):
            radius = 0.0 if zone_value[0] else float(zone_value[1]) / 1000.0
        else:
            radius = PREDEFINED_ZONES_MM[zone_value.text.lower()] / 1000.0
        if "z" in call.options:
            radius = float(self.value(call.options["z"])) / 1000.0
        return v_tcp, radius

    def move(self, word: str, call: Call, proc: str) -> None:
        args = call.args
        n_points = 2 if word == "movec" else 1
        speed, zone, tool = args[n_points], args[n_points + 1], args[n_points + 2]
        self.frames(call, tool, word != "moveabsj")
        v_tcp, radius = self.speed_zone(call, speed, zone)
        duration = float(self.value(call.options["t"])) if "t" in call.options else None
        if word == "moveabsj":
            value = self.value(args[0])
            joints = np.radians(np.asarray(value[0], dtype=float))
            self.targets.append(
                ParsedTarget(
                    kind="joint",
                    joints=joints,
                    zone=radius,
                    duration=duration,
                    part=proc,
                    external=_extjoint(value[1]),
                )
            )
            return
        kinds = ["circular_via", "circular_end"] if word == "movec" else ["linear"]
        if word == "movej":
            kinds = ["joint_cartesian"]
        for kind, arg in zip(kinds, args[:n_points], strict=True):
            target = self.value(arg)
            pose = np.eye(4)
            pose[:3, :3] = quaternion_matrix(target[1])
            pose[:3, 3] = np.asarray(target[0], dtype=float) / 1000.0
            cf1, cf4, cf6, cfx = (int(c) for c in target[2])
            last = kind != "circular_via"
            self.targets.append(
                ParsedTarget(
                    kind=kind,
                    pose=pose,
                    config={"cf1": cf1, "cf4": cf4, "cf6": cf6, "cfx": cfx},
                    speed=v_tcp if last else None,
                    zone=radius if last else None,
                    duration=duration if last else None,
                    part=proc,
                    external=_extjoint(target[3]),
                )
            )


def _extjoint(values: list[Any]) -> np.ndarray:
    """The used external axes of an ``extjoint`` (mm, degrees): those below 9E9, which
    marks an axis not used."""
    return np.array([float(v) for v in values if abs(float(v)) < 8.9e9], dtype=float)


def _true(value: Any) -> bool:
    """A RAPID bool as read (``TRUE``/``FALSE`` names or Python bools)."""
    if isinstance(value, Name):
        return value.text.upper() == "TRUE"
    return bool(value)


__all__ = [
    "GRAMMAR",
    "Call",
    "Module",
    "Name",
    "parse_modules",
    "parse_rapid",
    "pose_matrix",
    "quaternion_matrix",
]
