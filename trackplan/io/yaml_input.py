"""Reading YAML input files, and turning every problem in them into one :class:`CaseError`.

Shared by the case and robot file loaders. The rules, in the order they are applied:

1. The file must exist, be a regular file (not a FIFO or a device) of at most
   :data:`MAX_YAML_BYTES` and be UTF-8 text (a byte order mark is skipped).
2. It must be valid YAML with YAML 1.2 core-schema scalars (no ``yes``/``no`` booleans, no
   sexagesimal ``1:30``), at most :data:`MAX_YAML_BYTES` long; a key given twice, a
   complex key, a recursive alias, an alias bomb, nesting deeper than :data:`MAX_DEPTH`
   and more than :data:`MAX_YAML_VALUES` values are errors. Errors name the line and
   column.
3. It must match the pydantic schema of the file. Of all schema problems, the one that
   comes first in the file is reported.
4. Checks that need more than one value (bounds, geometry, robot joint count) are
   collected by the loaders as :data:`Problem` entries and the first in file order is
   reported, through :func:`raise_first`.

One problem is reported at a time, as one line ``file: key.path[i]: message``, where the
message says what is expected and what was found.
"""

from __future__ import annotations

import difflib
import math
import re
import types
import typing
from collections.abc import Sequence
from typing import Annotated, Any, TypeVar

import yaml
from pydantic import AfterValidator, BaseModel, ConfigDict, Field, ValidationError
from pydantic_core import ErrorDetails, PydanticCustomError

from trackplan.errors import CaseError
from trackplan.io.input_text import MAX_TEXT_BYTES

# moved to input_text; importers outside this package keep working
from trackplan.io.input_text import read_text as read_text

Loc = tuple[str | int, ...]
"""A location inside a loaded YAML document: mapping keys and list indices."""

Problem = tuple[Loc, str]
"""A problem found after schema validation: where it is, and the message."""

ModelT = TypeVar("ModelT", bound=BaseModel)


class StrictModel(BaseModel):
    """Base of every input schema: unknown keys, type coercion and nan/inf are errors."""

    model_config = ConfigDict(
        extra="forbid", strict=True, allow_inf_nan=False, frozen=True, defer_build=True
    )


def _fixed_length(n: int, names: str) -> Any:
    """An after-validator that requires a list of exactly ``n`` entries named ``names``."""

    def check(value: list[float]) -> list[float]:
        if len(value) != n:
            raise PydanticCustomError(
                "vector_length",
                "expected {n} numbers [{names}], got {actual}",
                {"n": n, "names": names, "actual": len(value)},
            )
        return value

    return AfterValidator(check)


def list_default(*values: float) -> Any:
    """A field default that is a fresh list of ``values`` for each model."""
    return Field(default_factory=lambda: list(values))


MAX_COORDINATE = 1.0e3
"""Largest |entry| of a vector (m or rad): far beyond any robot cell, far from overflow."""

# Numbers are floats; an integer is accepted, and StrictModel forbids nan and inf.
Positive = Annotated[float, Field(gt=0)]
NonNegative = Annotated[float, Field(ge=0)]
NonEmptyStr = Annotated[str, Field(min_length=1)]
Coordinate = Annotated[float, Field(ge=-MAX_COORDINATE, le=MAX_COORDINATE)]
Vec3 = Annotated[list[Coordinate], _fixed_length(3, "x, y, z")]
Vec6 = Annotated[list[Coordinate], _fixed_length(6, "x, y, z, roll, pitch, yaw")]
Range = Annotated[list[Coordinate], _fixed_length(2, "min, max")]


# --------------------------------------------------------------------------- files and YAML


MAX_DEPTH = 100
"""Deepest nesting of lists and mappings accepted in a YAML file (a case file needs 6)."""

MAX_YAML_VALUES = 50_000
"""Most values (scalars, lists and mappings) a YAML file may hold: about 12,000 inline
points of 4 values each, parsed in about 2 s. A file over it is refused as soon as the
parser reaches the limit, before the rest is read (long sampled curves belong in a points
file)."""

MAX_ALIAS_EXPANSION = 100_000
"""Most values that aliases (``*name``) may add to a YAML document when expanded."""

MAX_YAML_BYTES = MAX_TEXT_BYTES
"""Largest YAML file read, bytes (long sampled curves belong in a points file)."""

MAX_INTEGER = 2**63 - 1
"""Largest |integer| in a YAML file."""


class _Loader(yaml.SafeLoader):
    """PyYAML's safe loader with YAML 1.2 core-schema scalars and hostile input refused.

    - Scalars resolve as in YAML 1.2's core schema: ``true``/``false`` (not ``yes``/``no``/
      ``on``/``off``), decimal integers (``010`` is ten), ``0o`` and ``0x`` integers,
      floats such as ``1e-3`` and ``.inf``, ``null``/``~``; anything else, such as the
      YAML 1.1 sexagesimal ``1:30`` or a date, is a string.
    - A key given twice, a list or mapping used as a key, a key that is not a non-empty
      string (``1``, ``null``, ``true``), nesting deeper than
      :data:`MAX_DEPTH`, more than :data:`MAX_YAML_VALUES` values, an alias inside the
      node it names (recursion), and aliases that expand to more than
      :data:`MAX_ALIAS_EXPANSION` values ("billion laughs") are errors at their line.
    """

    def __init__(self, stream: str) -> None:
        super().__init__(stream)
        self._depth = 0
        self._values = 0
        self._open_anchors: set[str] = set()
        self._sizes: dict[int, int] = {}
        self._expanded = 0

    def compose_node(self, parent: yaml.Node | None, index: Any) -> yaml.Node:
        """Compose one node, refusing recursive aliases, alias bombs and deep nesting."""
        event = self.peek_event()
        if isinstance(event, yaml.AliasEvent):
            anchor = event.anchor
            if anchor in self._open_anchors:
                raise yaml.composer.ComposerError(
                    None,
                    None,
                    f"alias *{anchor} refers to a node that contains it (recursive alias)",
                    event.start_mark,
                )
            node = super().compose_node(parent, index)
            self._expanded += self._size(node)
            if self._expanded > MAX_ALIAS_EXPANSION:
                raise _LimitError(
                    None,
                    None,
                    f"alias *{anchor} expands the document beyond {MAX_ALIAS_EXPANSION} "
                    "values; write the values out instead",
                    event.start_mark,
                )
            return node
        self._values += 1
        if self._values > MAX_YAML_VALUES:
            raise _LimitError(
                None,
                None,
                f"the file holds more than {MAX_YAML_VALUES} values; put long sampled curves "
                "in a points file (points: {file: seam.csv})",
                event.start_mark,
            )
        self._depth += 1
        if self._depth > MAX_DEPTH:
            raise _LimitError(
                None, None, f"nesting deeper than {MAX_DEPTH} levels", event.start_mark
            )
        anchor = getattr(event, "anchor", None)
        if anchor is not None:
            self._open_anchors.add(anchor)
        try:
            return super().compose_node(parent, index)
        finally:
            self._depth -= 1
            if anchor is not None:
                self._open_anchors.discard(anchor)

    def _size(self, node: yaml.Node) -> int:
        """Number of nodes of ``node`` with every alias expanded (memoised per node)."""
        known = self._sizes.get(id(node))
        if known is not None:
            return known
        if isinstance(node, yaml.SequenceNode):
            size = 1 + sum(self._size(item) for item in node.value)
        elif isinstance(node, yaml.MappingNode):
            size = 1 + sum(self._size(key) + self._size(item) for key, item in node.value)
        else:
            size = 1
        self._sizes[id(node)] = size
        return size

    def construct_mapping(self, node: yaml.MappingNode, deep: bool = False) -> dict[Any, Any]:
        """Build a mapping, refusing a key that occurs twice, that is a list or mapping, or
        that is not a non-empty string (``1:``, ``null:``, ``true:``, ``'':``)."""
        seen: set[Any] = set()
        for key_node, _ in node.value:
            if not isinstance(key_node, yaml.ScalarNode):
                raise yaml.constructor.ConstructorError(
                    None, None, "a list or mapping as a key is not supported", key_node.start_mark
                )
            key = self.construct_object(key_node, deep=deep)
            if not isinstance(key, str) or not key:
                raise yaml.constructor.ConstructorError(
                    None,
                    None,
                    f"a key must be a non-empty name, got {show(key)}",
                    key_node.start_mark,
                )
            if key in seen:
                raise yaml.constructor.ConstructorError(
                    None, None, f"duplicate key {show(key)}", key_node.start_mark
                )
            seen.add(key)
        return super().construct_mapping(node, deep=deep)

    def construct_yaml_int(self, node: yaml.ScalarNode) -> int:
        """A YAML 1.2 integer: decimal (leading zeros allowed), ``0o`` octal, ``0x`` hex."""
        text = str(self.construct_scalar(node))
        sign = -1 if text.startswith("-") else 1
        digits = text.lstrip("+-")
        if len(digits) > 20:
            value = MAX_INTEGER + 1
        elif digits[:2] in ("0o", "0x"):
            value = int(digits[2:], 8 if digits[1] == "o" else 16)
        else:
            value = int(digits, 10)
        if value > MAX_INTEGER:
            raise yaml.constructor.ConstructorError(
                None, None, f"integer {show(text, 24)} is too large", node.start_mark
            )
        return sign * value

    def construct_yaml_bool(self, node: yaml.ScalarNode) -> bool:
        """``true`` or ``false`` (any case the core schema allows)."""
        return str(self.construct_scalar(node)).lower() == "true"


# The YAML 1.2 core schema (https://yaml.org/spec/1.2.2/#1023-core-schema); a fresh table,
# so that SafeLoader's YAML 1.1 resolvers (yes/no, 1:30, dates, merge keys) are not used.
_Loader.yaml_implicit_resolvers = {}
for _tag, _pattern, _first in (
    ("tag:yaml.org,2002:null", r"^(?:~|null|Null|NULL|)$", ["~", "n", "N", ""]),
    ("tag:yaml.org,2002:bool", r"^(?:true|True|TRUE|false|False|FALSE)$", list("tTfF")),
    ("tag:yaml.org,2002:int", r"^(?:[-+]?[0-9]+|0o[0-7]+|0x[0-9a-fA-F]+)$", list("-+0123456789")),
    (
        "tag:yaml.org,2002:float",
        r"^(?:[-+]?(?:\.[0-9]+|[0-9]+(?:\.[0-9]*)?)(?:[eE][-+]?[0-9]+)?"
        r"|[-+]?\.(?:inf|Inf|INF)|\.(?:nan|NaN|NAN))$",
        list("-+.0123456789"),
    ),
):
    _Loader.add_implicit_resolver(_tag, re.compile(_pattern), _first)
_Loader.add_constructor("tag:yaml.org,2002:int", _Loader.construct_yaml_int)
_Loader.add_constructor("tag:yaml.org,2002:bool", _Loader.construct_yaml_bool)


class _LimitError(yaml.composer.ComposerError):
    """A document over one of :class:`_Loader`'s size limits (values, depth, alias
    expansion): well-formed YAML, refused for its size."""


def parse_yaml(text: str, file: str | None) -> Any:
    """The data of a YAML document.

    Raises
    ------
    CaseError
        On a syntax error (the message names line and column, counted from 1), a
        duplicate key, or an empty document.
    """
    if len(text) > MAX_YAML_BYTES:
        raise CaseError(
            f"the file has {len(text)} characters, more than {MAX_YAML_BYTES} "
            "(put long sampled curves in a points file)",
            file=file,
        )
    try:
        # _Loader derives from SafeLoader: no arbitrary Python objects.
        data = yaml.load(text, Loader=_Loader)
    except yaml.MarkedYAMLError as exc:
        kind = "YAML limit reached" if isinstance(exc, _LimitError) else "YAML syntax error"
        message = kind + _at(exc.problem_mark or exc.context_mark)
        message += f": {exc.problem or exc.context or 'invalid YAML'}"
        if exc.problem and exc.context and exc.context_mark:
            message += f" ({exc.context}{_at(exc.context_mark)})"
        raise CaseError(message, file=file) from None
    except yaml.YAMLError as exc:
        raise CaseError(f"YAML syntax error: {exc}", file=file) from None
    if data is None:
        raise CaseError("the file is empty, expected a mapping of keys", file=file)
    return data


def _at(mark: yaml.Mark | None) -> str:
    """`` at line L, column C`` (counted from 1) of a YAML mark, or nothing."""
    return f" at line {mark.line + 1}, column {mark.column + 1}" if mark else ""


# --------------------------------------------------------------------------- key paths


def key_path(loc: Sequence[str | int]) -> str:
    """The key path of a location: ``("path", "segments", 2, "arc")`` → ``path.segments[2].arc``.

    Union tags added by pydantic (written ``<name>`` in our schemas) are left out.
    """
    text = ""
    for part in loc:
        if isinstance(part, int):
            text += f"[{part}]"
        elif not part.startswith("<"):
            text += f".{part}" if text else part
    return text


def parse_key_path(key: str) -> Loc:
    """The location of a key path (inverse of :func:`key_path`)."""
    loc: list[str | int] = []
    for name, index in re.findall(r"([^.\[\]]+)|\[(\d+)\]", key):
        loc.append(int(index) if index else name)
    return tuple(loc)


def file_position(data: Any, loc: Loc) -> tuple[int, ...]:
    """Where a location comes in the file, for ordering problems as they appear.

    Mapping keys keep the file's order (PyYAML builds insertion-ordered dicts); a key
    that is missing sorts after the keys present in its mapping.
    """
    position: list[int] = []
    node = data
    for part in loc:
        if isinstance(node, dict):
            keys = list(node)
            position.append(keys.index(part) if part in node else len(keys))
            node = node.get(part)
        elif isinstance(node, list) and isinstance(part, int):
            position.append(part)
            node = node[part] if 0 <= part < len(node) else None
        else:
            position.append(0)
            node = None
    return tuple(position)


def raise_first(problems: Sequence[Problem], data: Any, file: str | None) -> None:
    """Raise the problem that comes first in the file, if there is any.

    Raises
    ------
    CaseError
        With the key path and message of the first problem.
    """
    if problems:
        loc, message = min(problems, key=lambda problem: file_position(data, problem[0]))
        raise CaseError(message, file=file, key=key_path(loc) or None)


# --------------------------------------------------------------------------- schema


def validate_model(model: type[ModelT], data: Any, file: str | None) -> ModelT:
    """Validate ``data`` against a schema.

    Raises
    ------
    CaseError
        The schema problem that comes first in the file, with its key path.
    """
    try:
        return model.model_validate(data)
    except ValidationError as exc:
        errors = exc.errors(include_url=False)
        problems = [(_clean_loc(error["loc"]), _message(model, error)) for error in errors]
        raise_first(problems, data, file)
        raise CaseError(str(exc), file=file) from None  # a ValidationError has errors


def _clean_loc(loc: Sequence[str | int]) -> Loc:
    return tuple(part for part in loc if isinstance(part, int) or not part.startswith("<"))


def _message(model: type[BaseModel], error: ErrorDetails) -> str:
    """Our wording of one pydantic error: what is expected, and the value found."""
    kind = error["type"]
    ctx = error.get("ctx", {})
    got = f", got {show(error['input'])}"
    loc = _clean_loc(error["loc"])
    if kind == "missing":
        return "required key is missing"
    if kind == "extra_forbidden":
        return _unknown_key_message(model, loc)
    if not loc and kind in ("model_type", "model_attributes_type", "dict_type"):
        return f"expected a mapping of keys at the top level{got}"
    simple = {
        "float_type": "expected a number",
        "float_parsing": "expected a number",
        "int_type": "expected an integer",
        "int_parsing": "expected an integer",
        "int_from_float": "expected an integer",
        "finite_number": "expected a finite number",
        "string_type": "expected a string",
        "string_too_short": "expected a non-empty string",
        "list_type": "expected a list",
        "model_type": "expected a mapping of keys",
        "model_attributes_type": "expected a mapping of keys",
        "dict_type": "expected a mapping of keys",
    }
    if kind in simple:
        return simple[kind] + got
    bounds = {
        "greater_than": ("gt", ">"),
        "greater_than_equal": ("ge", "≥"),
        "less_than": ("lt", "<"),
        "less_than_equal": ("le", "≤"),
    }
    if kind in bounds:
        name, sign = bounds[kind]
        return f"expected a number {sign} {ctx[name]:g}{got}"
    if kind == "literal_error":
        return f"expected one of {ctx['expected']}{got}"
    if kind == "too_short":
        return f"expected at least {_entries(ctx['min_length'])}, got {ctx['actual_length']}"
    if kind == "too_long":
        return f"expected at most {_entries(ctx['max_length'])}, got {ctx['actual_length']}"
    if kind == "vector_length":
        return f"{error['msg']}: {show(error['input'])}"
    if kind in CUSTOM_ERRORS:
        return error["msg"]
    return error["msg"] + got


CUSTOM_ERRORS = frozenset({"segment_kind", "points_type", "body_shape"})
"""Error types raised by our schemas whose message already says everything."""


def _entries(n: int) -> str:
    return f"{n} entry" if n == 1 else f"{n} entries"


def _unknown_key_message(model: type[BaseModel], loc: Loc) -> str:
    names = [part for part in loc if isinstance(part, str)]
    parent = model_at(model, names[:-1])
    if parent is None:
        return "unknown key"
    allowed = list(parent.model_fields)
    close = difflib.get_close_matches(str(names[-1]), allowed, n=1)
    hint = f"did you mean {close[0]!r}? " if close else ""
    return f"unknown key; {hint}expected one of: {', '.join(allowed)}"


def model_at(model: type[BaseModel], names: Sequence[str]) -> type[BaseModel] | None:
    """The schema of the mapping at a path of field names (list indices left out)."""
    current: type[BaseModel] | None = model
    for name in names:
        if current is None or name not in current.model_fields:
            return None
        current = _find_model(current.model_fields[name].annotation)
    return current


def _find_model(annotation: Any) -> type[BaseModel] | None:
    """The first pydantic model inside an annotation (through list, Optional, Union, Annotated)."""
    if isinstance(annotation, type) and issubclass(annotation, BaseModel):
        return annotation
    if isinstance(annotation, types.UnionType) or typing.get_origin(annotation) is not None:
        for argument in typing.get_args(annotation):
            found = _find_model(argument)
            if found is not None:
                return found
    return None


class _Full(Exception):
    """The rendering of :func:`show` reached its limit."""


def show(value: Any, limit: int = 60) -> str:
    """A short YAML-like rendering of an input value for messages.

    The work is bounded by ``limit`` whatever the value's size (an alias bomb expands to
    billions of entries): rendering stops as soon as the text is long enough.
    """
    parts: list[str] = []
    room = [limit + 1]

    def emit(text: str) -> None:
        if room[0] <= 0:
            raise _Full
        text = text[: room[0]]
        parts.append(text)
        room[0] -= len(text)

    def walk(item: Any) -> None:
        if isinstance(item, bool):
            emit("true" if item else "false")
        elif item is None:
            emit("null")
        elif isinstance(item, float):
            emit(repr(item) if math.isfinite(item) else str(item))
        elif isinstance(item, str):
            emit(repr(item[: limit + 2]))
        elif isinstance(item, dict):
            emit("{")
            for i, (key, entry) in enumerate(item.items()):
                emit(", " if i else "")
                emit(f"{str(key)[: limit + 1]}: ")
                walk(entry)
            emit("}")
        elif isinstance(item, list | tuple):
            emit("[")
            for i, entry in enumerate(item):
                emit(", " if i else "")
                walk(entry)
            emit("]")
        else:
            emit(str(item)[: limit + 1])

    try:
        walk(value)
    except _Full:
        pass
    text = "".join(parts)
    return text if len(text) <= limit else text[: limit - 1] + "…"
