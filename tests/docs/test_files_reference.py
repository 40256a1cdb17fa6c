"""docs/files.md against the case and robot file schemas: it cannot drift from them."""

from __future__ import annotations

import re
import typing
from pathlib import Path

import pytest
import yaml
from pydantic import BaseModel

from trackplan.io.case_schema import ArcModel, CaseModel, LineModel, PointsFileModel
from trackplan.io.robot_file import RobotFileModel

PAGE = Path(__file__).resolve().parents[2] / "docs" / "files.md"
PARENT = object()
"""Marks a key that holds further keys (a mapping, or a list of mappings)."""


def _section(title: str, next_title: str) -> str:
    text = PAGE.read_text(encoding="utf-8")
    return text[text.index(f"\n## {title}\n") : text.index(f"\n## {next_title}\n")]


def _nested_model(annotation: object) -> type[BaseModel] | None:
    """The model inside ``Model``, ``Model | None`` or ``list[Model]``, else None."""
    if isinstance(annotation, type) and issubclass(annotation, BaseModel):
        return annotation
    for arg in typing.get_args(annotation):
        found = _nested_model(arg)
        if found is not None:
            return found
    return None


def _schema(model: type[BaseModel], prefix: str = "") -> dict[str, object]:
    """Every key path the schema accepts -> its default (``...`` when required, PARENT for
    a key that holds further keys)."""
    keys: dict[str, object] = {}
    for name, field in model.model_fields.items():
        key = f"{prefix}{field.alias or name}"
        origin = typing.get_origin(field.annotation)
        inner = _nested_model(field.annotation)
        if inner is not None and key not in ("path.segments", "paths[i].segments"):
            keys[key] = PARENT
            # a list of the model (not a union of some list and the model, as a pose is)
            listed = rf"list\[[\w.]*\b{inner.__name__}\]"
            is_list = origin is list or re.search(listed, str(field.annotation)) is not None
            keys.update(_schema(inner, f"{key}[i]." if is_list else f"{key}."))
        else:
            keys[key] = ... if field.is_required() else field.get_default(call_default_factory=True)
    return keys


def _documented(section: str) -> dict[str, str]:
    """Key path -> the default cell of the table rows that name it."""
    rows: dict[str, str] = {}
    for line in section.splitlines():
        cells = [c.strip() for c in re.split(r"(?<!\\)\|", line.strip().strip("|"))]
        if not line.startswith("| `") or len(cells) != 5:
            continue
        parent = ""
        for token in re.findall(r"`([^`]+)`", cells[0]):
            key = parent + token[1:] if token.startswith(".") else token
            parent = key[: key.rindex(".") + 1] if "." in key else ""
            rows[key] = cells[3]
    return rows


@pytest.mark.parametrize(
    ("model", "title", "next_title"),
    [(CaseModel, "Case file", "Robot file"), (RobotFileModel, "Robot file", "Validation")],
)
def test_every_key_is_documented_with_its_default(model, title, next_title):
    schema = _schema(model)
    documented = _documented(_section(title, next_title))
    assert sorted(set(documented) - set(schema)) == [], "documented keys the schema refuses"
    missing = sorted(k for k, v in schema.items() if v is not PARENT and k not in documented)
    assert missing == [], "schema keys missing from docs/files.md"
    for key, default in schema.items():
        if key not in documented:
            continue
        cell = documented[key]
        if default is ...:
            assert "**required**" in cell, f"{key} is required: {cell!r}"
        elif default is not None and default is not PARENT:
            shown = re.findall(r"`([^`]+)`", cell)
            assert shown, f"{key}: default {default!r} not shown in {cell!r}"
            value = yaml.safe_load(shown[0].replace("1.0e6", "1.0e+6"))
            if isinstance(default, str) and value != default and default == "":
                continue
            assert value == pytest.approx(default), f"{key}: documented {shown[0]}, is {default!r}"


def test_segment_kinds_and_their_keys_are_documented():
    table = _section("Case file", "Robot file")
    rows = {
        line.split("|")[1].strip(): line
        for line in table.splitlines()
        if line.startswith(("| `line`", "| `arc`", "| `points`"))
    }
    assert {"`line`", "`arc`", "`points`"} <= set(rows)
    for kind, model in (("line", LineModel), ("arc", ArcModel)):
        for name in model.model_fields:
            assert f"`{name}" in rows[f"`{kind}`"], f"{kind}.{name} undocumented"
    files = [line for line in table.splitlines() if line.startswith("| `points` | `{file")]
    assert files and all(f"{name}:" in files[0] for name in PointsFileModel.model_fields)
