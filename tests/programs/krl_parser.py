"""Read KUKA KRL programs back (tests only): a lark grammar of the KRL that motion programs
use, and a walk of the main routine that follows its calls into other modules.

The grammar covers module files (``&`` attributes, ``DEF``/``DEFFCT`` … ``END``, ``DEFDAT``
… ``ENDDAT`` with ``DECL`` and ``EXT``), declarations, assignments, calls, ``IF``, ``LOOP``,
``WAIT``, ``HALT``, interrupts, the motions ``PTP``, ``LIN``, ``CIRC`` with ``C_DIS`` /
``C_PTP``, and the spline blocks ``SPLINE`` (``SPL``, ``SLIN``, ``SCIRC``) and
``PTP_SPLINE`` (``SPTP``) with ``WITH`` and ``C_SPL``; keywords in any case, as KRL reads
them. The walk reads every statement once in program order (it evaluates no condition
and runs a loop body once) and returns a :class:`~tests.programs.parsed.ParsedProgram` in
SI units: targets in the part frame (``$BASE``), axis values in rad, ``S``/``T`` as written.
It imports nothing of trackplan's writers.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import PurePath
from typing import Any

import numpy as np
from lark import Lark, Token, Transformer, Tree, v_args

from tests.programs.parsed import ParsedProgram, ParsedTarget

GRAMMAR = r"""
start: _NL* directive* unit+
directive: DIRECTIVE _NL+
?unit: routine | function | dataset

routine: "GLOBAL"i? "DEF"i NAME "(" [params] ")" _NL+ body "END"i _NL*
function: "GLOBAL"i? "DEFFCT"i NAME NAME "(" [params] ")" _NL+ body "ENDFCT"i _NL*
dataset: "DEFDAT"i NAME "PUBLIC"i? _NL+ (_dat_line _NL+)* "ENDDAT"i _NL*
params: param ("," param)*
param: NAME (":" NAME)?
_dat_line: decl | ext
ext: ("EXT"i | "EXTFCT"i) NAME NAME? "(" [ext_params] ")"
ext_params: ext_param ("," ext_param)*
ext_param: NAME ("[" "]")? ":" NAME

body: (_stmt _NL+)*
_stmt: ptp | lin | circ | spline_block | ptp_spline_block | assign | call | decl
     | if_stmt | loop_stmt | wait_stmt | halt | return_stmt | interrupt_decl
     | interrupt_stmt

ptp: "PTP"i target [approx]
lin: "LIN"i target [approx]
circ: "CIRC"i target "," target ("," "CA"i expr)? [approx]
approx: C_DIS | C_PTP | C_VEL | C_ORI
spline_block: "SPLINE"i [with_clause] _NL+ (_segment _NL+)* "ENDSPLINE"i [C_SPL]
_segment: spl | slin | scirc
spl: "SPL"i target [with_clause]
slin: "SLIN"i target [with_clause]
scirc: "SCIRC"i target "," target [with_clause]
ptp_spline_block: "PTP_SPLINE"i [with_clause] _NL+ (sptp _NL+)* "ENDSPLINE"i [C_SPL]
sptp: "SPTP"i target [with_clause]
with_clause: "WITH"i assign ("," assign)*

assign: lvalue "=" expr
call: NAME "(" [args] ")"
decl: "DECL"i "GLOBAL"i? NAME decl_item ("," decl_item)*
decl_item: NAME dims? ("=" expr)?
dims: "[" [expr ("," expr)*] "]"
if_stmt: "IF"i expr "THEN"i _NL+ body ("ELSE"i _NL+ body)? "ENDIF"i
loop_stmt: "LOOP"i _NL+ body "ENDLOOP"i
wait_stmt: "WAIT"i ("SEC"i | "FOR"i) expr
halt: "HALT"i
return_stmt: "RETURN"i expr?
interrupt_decl: "GLOBAL"i? "INTERRUPT"i "DECL"i expr "WHEN"i expr "DO"i call
interrupt_stmt: "INTERRUPT"i NAME expr?

?target: aggregate | lvalue
lvalue: NAME _accessor*
_accessor: "." NAME | "[" [expr ("," expr)*] "]"
aggregate: "{" (NAME ":")? item ("," item)* "}"
item: NAME ("[" "]")? expr
args: expr ("," expr)*

?expr: or_expr
?or_expr: and_expr (("OR"i | "EXOR"i) and_expr)*
?and_expr: not_expr ("AND"i not_expr)*
?not_expr: "NOT"i not_expr -> not_op
         | comparison
?comparison: sum (CMP_OP sum)?
?sum: product (ADD_OP product)*
?product: unary (MUL_OP unary)*
?unary: "-" unary -> neg
      | "+" unary
      | atom
?atom: NUMBER -> number
     | STRING -> string
     | BITS -> bits
     | ENUM -> enum
     | call
     | lvalue
     | aggregate
     | "(" expr ")"

C_DIS: "C_DIS"i
C_PTP: "C_PTP"i
C_VEL: "C_VEL"i
C_ORI: "C_ORI"i
C_SPL: "C_SPL"i
CMP_OP: "==" | "<>" | "<=" | ">=" | "<" | ">"
ADD_OP: "+" | "-"
MUL_OP: "*" | "/"
DIRECTIVE: /&[^\n]*/
NAME: /[$A-Za-z_][$A-Za-z0-9_]*/i
NUMBER: /(\d+\.\d*|\.\d+|\d+)([eE][+-]?\d+)?/
STRING: /"[^"\n]*"/
BITS: /'[^'\n]*'/
ENUM: /#[A-Za-z_][A-Za-z0-9_]*/
COMMENT: /;[^\n]*/
_NL: /\r?\n/
%ignore /[ \t\f]+/
%ignore COMMENT
"""


@v_args(inline=True)
class _Values(Transformer[Token, Any]):
    """Literals to Python values; lvalues to upper-case dotted names."""

    def number(self, token: Token) -> float:
        return float(token)

    def neg(self, value: Any) -> Any:
        return -value

    def string(self, token: Token) -> str:
        return str(token)[1:-1]

    def bits(self, token: Token) -> int | str:
        text = str(token)[1:-1]
        if text[:1].upper() == "B":
            return int(text[1:], 2)
        if text[:1].upper() == "H":
            return int(text[1:], 16)
        return text

    def enum(self, token: Token) -> str:
        return str(token).upper()

    def lvalue(self, *parts: Any) -> str:
        text = str(parts[0]).upper()
        for part in parts[1:]:
            if isinstance(part, Token):
                text += f".{str(part).upper()}"
            else:
                text += f"[{part:g}]" if isinstance(part, float) else f"[{part}]"
        return text

    def item(self, key: Token, value: Any) -> tuple[str, Any]:
        return str(key).upper(), value

    def aggregate(self, *items: Any) -> dict[str, Any]:
        return dict(item for item in items if isinstance(item, tuple))


_PARSER = Lark(GRAMMAR, parser="lalr", maybe_placeholders=True, transformer=_Values())
"""LALR with the literals turned into values while parsing (one pass over the file)."""


def parse_tree(text: str) -> Tree[Any]:
    """The parse tree of one KRL file, literals already turned into values."""
    tree: Tree[Any] = _PARSER.parse(text if text.endswith("\n") else text + "\n")
    return tree


def abc_rotation(a: float, b: float, c: float) -> np.ndarray:
    """``Rz(A) · Ry(B) · Rx(C)`` of angles in degrees."""
    a, b, c = np.deg2rad([a, b, c])
    rz = np.array([[np.cos(a), -np.sin(a), 0], [np.sin(a), np.cos(a), 0], [0, 0, 1]])
    ry = np.array([[np.cos(b), 0, np.sin(b)], [0, 1, 0], [-np.sin(b), 0, np.cos(b)]])
    rx = np.array([[1, 0, 0], [0, np.cos(c), -np.sin(c)], [0, np.sin(c), np.cos(c)]])
    rotation: np.ndarray = rz @ ry @ rx
    return rotation


def frame_pose(value: dict[str, Any]) -> np.ndarray:
    """The pose (m) of a FRAME / POS / E6POS aggregate (mm, deg)."""
    pose = np.eye(4)
    pose[:3, :3] = abc_rotation(value.get("A", 0.0), value.get("B", 0.0), value.get("C", 0.0))
    pose[:3, 3] = [value.get(key, 0.0) / 1000.0 for key in "XYZ"]
    return pose


@dataclass
class _State:
    """What the walk has set so far."""

    base: np.ndarray = field(default_factory=lambda: np.eye(4))
    tool: np.ndarray = field(default_factory=lambda: np.eye(4))
    vel_cp: float | None = None
    vel_axis: dict[int, float] = field(default_factory=dict)
    cdis: float = 0.0
    targets: list[ParsedTarget] = field(default_factory=list)
    coupled: str = ""


@dataclass
class _Module:
    """One module: its routines by upper-case name and its data list."""

    name: str
    routines: dict[str, Tree[Any]] = field(default_factory=dict)
    data: dict[str, Any] = field(default_factory=dict)
    header: list[str] = field(default_factory=list)


def parse_krl(files: dict[str, str]) -> ParsedProgram:
    """Read a KRL program: ``.src`` and ``.dat`` files by name.

    Parameters
    ----------
    files
        File name → text; the main module is the ``.src`` that no other calls.

    Returns
    -------
    ParsedProgram
        SI units; poses in ``$BASE``; the header is the comment block after the main
        ``DEF`` line.
    """
    modules: dict[str, _Module] = {}
    for file_name, text in files.items():
        stem, suffix = PurePath(file_name).stem.upper(), PurePath(file_name).suffix.lower()
        module = modules.setdefault(stem, _Module(PurePath(file_name).stem))
        tree = parse_tree(text)
        for unit in tree.children:
            if not isinstance(unit, Tree):
                continue
            if unit.data == "dataset":
                for decl in unit.find_data("decl"):
                    module.data.update(_declared(decl))
            elif unit.data in ("routine", "function"):
                module.routines[str(unit.children[0]).upper()] = unit
        if suffix == ".src":
            module.header = _header_comments(text)
    routines = {
        name: (module, tree)
        for module in modules.values()
        for name, tree in module.routines.items()
    }
    called = {
        str(call.children[0]).upper()
        for _, tree in routines.values()
        for call in tree.find_data("call")
    }
    mains = [m for m in modules.values() if m.name.upper() not in called and m.routines]
    if len(mains) != 1:
        raise ValueError(f"expected one main module, found {[m.name for m in mains]}")
    main = mains[0]
    first = next(iter(main.routines))  # a module's first routine is the one it runs
    state = _State()
    _run(routines, first, state)
    return ParsedProgram(
        name=str(main.routines[first].children[0]),
        base=state.base,
        tool=state.tool,
        targets=state.targets,
        header=main.header,
        files=sorted(files),
        coupled=state.coupled,
    )


def _declared(decl: Tree[Any]) -> dict[str, Any]:
    """``{NAME: value}`` of a DECL's initialised items."""
    found = {}
    for item in decl.find_data("decl_item"):
        name, *rest = item.children
        value = (
            rest[-1]
            if rest and not (isinstance(rest[-1], Tree) and rest[-1].data == "dims")
            else None
        )
        if value is not None:
            found[str(name).upper()] = value
    return found


def _header_comments(text: str) -> list[str]:
    """The comment lines right after the first ``DEF`` line, without ``;`` and FOLDs."""
    lines = text.splitlines()
    start = next(
        i
        for i, line in enumerate(lines)
        if line.strip().upper().startswith(("DEF ", "GLOBAL DEF "))
    )
    header = []
    for line in lines[start + 1 :]:
        stripped = line.strip()
        if not stripped.startswith(";"):
            break
        if stripped[1:].upper().startswith(("FOLD", "ENDFOLD")):
            continue
        header.append(stripped[1:].strip())
    return header


def _run(routines: dict[str, tuple[_Module, Tree[Any]]], name: str, state: _State) -> None:
    """Walk one routine's statements (following calls to known routines)."""
    module, tree = routines[name]
    local = dict(module.data)
    for decl in tree.find_data("decl"):
        local.update(_declared(decl))
    body = next(
        child for child in tree.children if isinstance(child, Tree) and child.data == "body"
    )
    _walk(body, routines, module, local, state, str(tree.children[0]))


def _walk(
    body: Tree[Any],
    routines: dict[str, tuple[_Module, Tree[Any]]],
    module: _Module,
    local: dict[str, Any],
    state: _State,
    part: str,
) -> None:
    for statement in body.children:
        if not isinstance(statement, Tree):
            continue
        kind = statement.data
        if kind in ("if_stmt", "loop_stmt"):
            for inner in statement.children:
                if isinstance(inner, Tree) and inner.data == "body":
                    _walk(inner, routines, module, local, state, part)
        elif kind == "call":
            callee = str(statement.children[0]).upper()
            if callee in routines:
                _run(routines, callee, state)
        elif kind == "assign":
            _assign(statement, local, state)
        elif kind in ("ptp", "lin", "circ"):
            _motion(statement, local, state, part)
        elif kind in ("spline_block", "ptp_spline_block"):
            _block(statement, local, state, part)


def _value(target: Any, local: dict[str, Any]) -> Any:
    """A target's aggregate: a literal, a declared name, or None (set at run time)."""
    if isinstance(target, dict):
        return target
    return local.get(str(target).upper())


def _assign(statement: Tree[Any], local: dict[str, Any], state: _State) -> None:
    name, value = statement.children
    value = _value(value, local) if isinstance(value, str) else value
    if name == "$BASE" and isinstance(value, Tree) and value.data == "call":
        # $BASE = EK(MACHINE_DEF[i].ROOT, MACHINE_DEF[i].MECH_TYPE, frame): the frame on
        # the external kinematics' flange, moved with it
        function, args = value.children
        if str(function).upper() == "EK" and isinstance(args, Tree):
            root, _, frame = args.children
            state.coupled = str(root).rsplit(".", 1)[0]
            coupled = _value(frame, local)
            if isinstance(coupled, dict):
                state.base = frame_pose(coupled)
    elif name == "$BASE" and isinstance(value, dict):
        state.base = frame_pose(value)
    elif name == "$TOOL" and isinstance(value, dict):
        state.tool = frame_pose(value)
    elif not isinstance(value, float):
        return
    elif name == "$VEL.CP":
        state.vel_cp = value
    elif name == "$APO.CDIS":
        state.cdis = value / 1000.0
    elif name.startswith("$VEL_AXIS["):
        state.vel_axis[int(name[10:-1])] = float(value)


def _target(kind: str, value: Any, part: str, config_ok: bool = True) -> ParsedTarget:
    """A ParsedTarget of an aggregate: axis values (A1 …) or a Cartesian point."""
    target = ParsedTarget(kind=kind, part=part)
    if value is None:
        return target
    external = [value[f"E{i}"] for i in range(1, 7) if f"E{i}" in value]
    target.external = np.array(external, dtype=float)
    if "A1" in value:
        axes = [value[f"A{i}"] for i in range(1, 7) if f"A{i}" in value]
        target.joints = np.deg2rad(np.array(axes, dtype=float))
    elif "X" in value:
        target.pose = frame_pose(value)
        if config_ok:
            target.config = {key: value[key] for key in ("S", "T") if key in value}
    return target


def _axis_share(state: _State, overrides: dict[int, float] | None = None) -> float | None:
    values = {**state.vel_axis, **(overrides or {})}
    return min(values.values()) / 100.0 if values else None


def _motion(statement: Tree[Any], local: dict[str, Any], state: _State, part: str) -> None:
    *targets, approx = statement.children
    zone = state.cdis if approx is not None else 0.0
    if statement.data == "ptp":
        target = _target("joint", _value(targets[0], local), part)
        target.speed, target.zone = _axis_share(state), zone
        state.targets.append(target)
    elif statement.data == "lin":
        target = _target("linear", _value(targets[0], local), part)
        target.speed, target.zone = state.vel_cp, zone
        state.targets.append(target)
    else:
        via = _target("circular_via", _value(targets[0], local), part)
        end = _target("circular_end", _value(targets[1], local), part)
        via.speed, end.speed, end.zone = state.vel_cp, state.vel_cp, zone
        state.targets.extend([via, end])


def _with_values(clause: Any) -> dict[int, float]:
    """``$VEL_AXIS[i]`` values of a WITH clause."""
    found: dict[int, float] = {}
    if isinstance(clause, Tree):
        for assign in clause.children:
            name, value = assign.children
            if name.startswith("$VEL_AXIS["):
                found[int(name[10:-1])] = float(value)
    return found


def _block(statement: Tree[Any], local: dict[str, Any], state: _State, part: str) -> None:
    segments = [c for c in statement.children if isinstance(c, Tree) and c.data != "with_clause"]
    approximated = statement.children[-1] is not None
    added: list[ParsedTarget] = []
    for segment in segments:
        if segment.data == "sptp":
            target = _target("joint", _value(segment.children[0], local), part)
            target.speed = _axis_share(state, _with_values(segment.children[1]))
        elif segment.data == "scirc":
            via = _target("circular_via", _value(segment.children[0], local), part)
            via.speed = state.vel_cp
            added.append(via)
            target = _target("circular_end", _value(segment.children[1], local), part)
            target.speed = state.vel_cp
        else:
            kind = "spline" if segment.data == "spl" else "linear"
            target = _target(kind, _value(segment.children[0], local), part)
            target.speed = state.vel_cp
        target.zone = 0.0
        added.append(target)
    if added and approximated:
        added[-1].zone = state.cdis
    state.targets.extend(added)


__all__ = ["GRAMMAR", "abc_rotation", "frame_pose", "parse_krl", "parse_tree"]
