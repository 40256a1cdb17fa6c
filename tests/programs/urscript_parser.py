"""A test parser for URScript programs: reads ``.script`` files back into a
:class:`~tests.programs.parsed.ParsedProgram`, independently of the writer.

The grammar (lark, LALR) covers the statements of motion programs as Universal Robots'
PolyScope and trackplan write them: ``def``/``thread`` … ``end``, ``while``/``if`` blocks,
assignments (``global``/``local``), calls with positional and keyword arguments, ``$``
markers, comments, and expressions of numbers, strings, lists, poses ``p[…]``, names,
calls, attributes, indexing and arithmetic.

The reader runs the first ``def`` (the program) as the controller would for motion: it
assigns variables, follows calls into the program's own functions, runs a ``while`` body
once and an ``if`` branch whose condition it can evaluate, and records every ``movej``,
``movel``, ``movec`` and ``servoj`` with its arguments by URScript's signatures. Poses are
turned into transforms by :mod:`tests.programs.urscript_reference`; a Cartesian target is
returned in the frame of the program's ``part`` variable (the identity when there is none).
A ``movej`` speed written as a share of ``v_joint`` is returned as that share.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np
from lark import Lark, Token, Tree

from tests.programs.parsed import ParsedProgram, ParsedTarget
from tests.programs.urscript_reference import pose_matrix, pose_trans

GRAMMAR = r"""
start: _NL* (_stmt _NL*)*

_stmt: funcdef | threaddef | while_stmt | if_stmt | simple

funcdef: "def" NAME "(" [params] ")" ":" _NL body "end"
threaddef: "thread" NAME "(" ")" ":" _NL body "end"
while_stmt: "while" expr ":" _NL body "end"
if_stmt: "if" expr ":" _NL body elif_clause* else_clause? "end"
elif_clause: "elif" expr ":" _NL body
else_clause: "else" ":" _NL body
body: _NL* (_stmt _NL*)*
params: param ("," param)*
param: NAME ("=" expr)?

simple: assign | call_stmt | marker | return_stmt | keyword_stmt
assign: ("global" | "local")? target "=" expr
target: NAME ("[" expr "]" | "." NAME)*
call_stmt: postfix
marker: "$" NUMBER STRING+
return_stmt: "return" expr?
keyword_stmt: "halt" -> halt | "pass" -> pass_ | "break" -> break_ | "continue" -> continue_

?expr: or_expr
?or_expr: and_expr ("or" and_expr)*
?and_expr: not_expr ("and" not_expr)*
?not_expr: "not" not_expr -> not_op | comparison
?comparison: sum (COMP_OP sum)?
?sum: product (ADD_OP product)*
?product: unary (MUL_OP unary)*
?unary: "-" unary -> neg | "+" unary | postfix
?postfix: atom | call | postfix "[" expr "]" -> index | postfix "." NAME -> attribute
call: NAME "(" [args] ")" | postfix "." NAME "(" [args] ")" -> method
args: arg ("," arg)*
arg: (NAME "=")? expr
?atom: NUMBER -> number
     | STRING -> string
     | "True" -> true
     | "False" -> false
     | NAME -> name
     | "[" [expr ("," expr)*] "]" -> list
     | POSE "[" expr ("," expr)* "]" -> pose
     | "(" expr ")"

POSE.3: /p(?=\[)/
COMP_OP: "==" | "!=" | "<=" | ">=" | "<" | ">"
ADD_OP: "+" | "-"
MUL_OP: "*" | "/" | "%"
NAME: /[A-Za-z_][A-Za-z0-9_]*/
NUMBER: /(\d+\.?\d*|\.\d+)([eE][-+]?\d+)?/
STRING: /"[^"\n]*"/
COMMENT: /#[^\n]*/
_NL: /(\r?\n[\t ]*)+/
%ignore /[\t ]+/
%ignore COMMENT
"""

_PARSER = Lark(GRAMMAR, parser="lalr", maybe_placeholders=False)

SIGNATURES = {
    "movej": ("q", "a", "v", "t", "r"),
    "movel": ("pose", "a", "v", "t", "r"),
    "movec": ("pose_via", "pose_to", "a", "v", "r", "mode"),
    "servoj": ("q", "a", "v", "t", "lookahead_time", "gain"),
    "set_tcp": ("pose",),
    "get_inverse_kin": ("x", "qnear"),
    "pose_trans": ("p_from", "p_from_to"),
}
"""Positional parameters of the URScript functions the reader interprets."""


@dataclass
class _Pose:
    """A pose value: a transform, (4, 4)."""

    matrix: np.ndarray


@dataclass
class _Ik:
    """``get_inverse_kin(x, qnear=…)``: a pose and the joints to solve near."""

    pose: np.ndarray
    qnear: np.ndarray | None


@dataclass
class _Reader:
    """Runs a program's statements and records its moves."""

    functions: dict[str, Tree] = field(default_factory=dict)
    variables: dict[str, Any] = field(default_factory=dict)
    tool: np.ndarray = field(default_factory=lambda: np.eye(4))
    moves: list[tuple[str, dict[str, Any], str]] = field(default_factory=list)
    depth: int = 0

    def run(self, body: Tree, routine: str) -> None:
        for statement in body.children:
            self.statement(statement, routine)

    def statement(self, node: Tree, routine: str) -> None:
        kind = node.data
        if kind == "simple":
            self.statement(node.children[0], routine)
        elif kind == "funcdef":
            self.functions[str(node.children[0])] = node
        elif kind == "assign":
            target = next(c for c in node.children if isinstance(c, Tree))
            if len(target.children) == 1:
                self.variables[str(target.children[0])] = self.value(node.children[-1], routine)
        elif kind == "call_stmt":
            self.value(node.children[0], routine)
        elif kind == "while_stmt":
            self.run(node.children[1], routine)
        elif kind == "if_stmt":
            self.branch(node, routine)
        # threads, markers, returns and keywords move nothing

    def branch(self, node: Tree, routine: str) -> None:
        clauses = [(node.children[0], node.children[1])]
        clauses += [
            (c.children[0], c.children[1]) for c in node.children[2:] if c.data == "elif_clause"
        ]
        for condition, body in clauses:
            if self.value(condition, routine) is True:
                self.run(body, routine)
                return
        for clause in node.children[2:]:
            if clause.data == "else_clause":
                self.run(clause.children[0], routine)

    def value(self, node: Tree | Token, routine: str) -> Any:
        if isinstance(node, Token):
            return None
        kind = node.data
        if kind == "number":
            return float(node.children[0])
        if kind == "string":
            return str(node.children[0])[1:-1]
        if kind in ("true", "false"):
            return kind == "true"
        if kind == "name":
            return self.variables.get(str(node.children[0]))
        if kind == "list":
            return [self.value(c, routine) for c in node.children if c is not None]
        if kind == "pose":
            values = [self.value(c, routine) for c in node.children[1:]]
            return _Pose(pose_matrix(np.array(values, dtype=float)))
        if kind == "neg":
            operand = self.value(node.children[0], routine)
            return -operand if isinstance(operand, float) else None
        if kind in ("product", "sum"):
            return self.arithmetic(node, routine)
        if kind == "call":
            return self.call(node, routine)
        return None

    def arithmetic(self, node: Tree, routine: str) -> float | None:
        result = self.value(node.children[0], routine)
        for operator, operand in zip(node.children[1::2], node.children[2::2], strict=True):
            right = self.value(operand, routine)
            if not isinstance(result, float) or not isinstance(right, float):
                return None
            result = {
                "*": lambda a, b: a * b,
                "/": lambda a, b: a / b,
                "+": lambda a, b: a + b,
                "-": lambda a, b: a - b,
                "%": lambda a, b: a % b,
            }[str(operator)](result, right)
        return result

    def call(self, node: Tree, routine: str) -> Any:
        name = str(node.children[0])
        arguments = _arguments(node.children[1] if len(node.children) > 1 else None)
        if name in self.functions:
            self.depth += 1
            if self.depth > 50:
                raise ValueError(f"calls nested deeper than 50 at {name}")
            self.run(self.functions[name].children[-1], name)
            self.depth -= 1
            return None
        if name not in SIGNATURES:
            return None
        values = {key: self.value(expr, routine) for key, expr in _bind(name, arguments).items()}
        if name == "pose_trans":
            left, right = values.get("p_from"), values.get("p_from_to")
            if isinstance(left, _Pose) and isinstance(right, _Pose):
                return _Pose(pose_trans(left.matrix, right.matrix))
            return None
        if name == "get_inverse_kin":
            x, qnear = values.get("x"), values.get("qnear")
            if isinstance(x, _Pose):
                return _Ik(x.matrix, None if qnear is None else np.array(qnear, dtype=float))
            return None
        if name == "set_tcp":
            if isinstance(values.get("pose"), _Pose):
                self.tool = values["pose"].matrix
            return None
        self.moves.append((name, values, routine))
        return None


def _arguments(node: Tree | None) -> list[tuple[str | None, Tree]]:
    """(keyword or None, expression) of each argument."""
    if node is None:
        return []
    result = []
    for arg in node.children:
        if len(arg.children) == 2:
            result.append((str(arg.children[0]), arg.children[1]))
        else:
            result.append((None, arg.children[0]))
    return result


def _bind(name: str, arguments: list[tuple[str | None, Tree]]) -> dict[str, Tree]:
    """Arguments by parameter name, by URScript's signature of ``name``."""
    bound: dict[str, Tree] = {}
    positional = iter(SIGNATURES[name])
    for keyword, expr in arguments:
        bound[keyword if keyword is not None else next(positional)] = expr
    return bound


def parse_urscript_text(text: str) -> Tree:
    """The syntax tree of a URScript text (raises lark's errors on bad syntax)."""
    return _PARSER.parse(text if text.endswith("\n") else text + "\n")


def parse_urscript(files: dict[str, str]) -> ParsedProgram:
    """Read a URScript program back.

    Parameters
    ----------
    files
        File name → text; the program is the first ``def`` of the first ``.script`` file.

    Returns
    -------
    ParsedProgram
        Targets in execution order (SI units, Cartesian poses in the ``part`` frame,
        controller joints in rad), the tool set by ``set_tcp``, the comment lines that
        open the program's body (its header).
    """
    file_name = next(name for name in files if name.endswith(".script"))
    text = files[file_name]
    tree = parse_urscript_text(text)
    reader = _Reader()
    program = next((s for s in tree.children if isinstance(s, Tree) and s.data == "funcdef"), None)
    if program is None:
        raise ValueError(f"{file_name}: no def ... end program")
    name = str(program.children[0])
    reader.run(program.children[-1], name)
    part = reader.variables.get("part")
    base = part.matrix if isinstance(part, _Pose) else np.eye(4)
    v_joint = reader.variables.get("v_joint")
    targets: list[ParsedTarget] = []
    for function, values, routine in reader.moves:
        targets.extend(_targets(function, values, routine, base, v_joint))
    header = []  # the comment lines that open the program's body
    for line in text.splitlines()[1:]:
        if not line.strip().startswith("#"):
            break
        header.append(line.strip()[1:].removeprefix(" "))
    return ParsedProgram(
        name=name, base=base, tool=reader.tool, targets=targets, header=header, files=[file_name]
    )


def _targets(
    function: str, values: dict[str, Any], routine: str, base: np.ndarray, v_joint: Any
) -> list[ParsedTarget]:
    """The targets of one recorded move."""
    inverse = np.linalg.inv(base)

    def in_part(value: Any) -> np.ndarray | None:
        if isinstance(value, _Pose):
            return inverse @ value.matrix
        if isinstance(value, _Ik):
            return inverse @ value.pose
        return None

    zone, speed = values.get("r", 0.0), values.get("v")
    if function in ("movej", "servoj"):
        q = values.get("q")
        joints = q.qnear if isinstance(q, _Ik) else np.array(q, dtype=float)
        if function == "movej" and isinstance(speed, float) and isinstance(v_joint, float):
            speed = speed / v_joint
        return [
            ParsedTarget(
                kind="joint",
                pose=in_part(q),
                joints=joints,
                speed=speed if function == "movej" else None,
                zone=zone if function == "movej" else None,
                duration=values.get("t") if function == "servoj" else None,
                part=routine,
            )
        ]
    if function == "movel":
        return [
            ParsedTarget(
                kind="linear", pose=in_part(values["pose"]), speed=speed, zone=zone, part=routine
            )
        ]
    return [
        ParsedTarget(
            kind="circular_via", pose=in_part(values["pose_via"]), speed=speed, part=routine
        ),
        ParsedTarget(
            kind="circular_end",
            pose=in_part(values["pose_to"]),
            speed=speed,
            zone=zone,
            part=routine,
        ),
    ]
