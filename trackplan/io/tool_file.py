"""The ``task.tool`` key of case files: schema, value checks and the :class:`ToolSpec` it gives.

``task.tool_rpy: [r, p, y]`` stays an alias of ``task.tool: {frame: part, rpy: [r, p, y]}``;
giving both is an error. The keys and conventions are in ``docs/tool.md``.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from pathlib import Path
from typing import Annotated, Literal

import numpy as np
from pydantic import Field

from trackplan.errors import CaseError
from trackplan.io.input_text import read_text
from trackplan.io.yaml_input import (
    Coordinate,
    Loc,
    Problem,
    Range,
    StrictModel,
    Vec3,
    key_path,
    list_default,
    parse_yaml,
    show,
)
from trackplan.paths.nominal import NominalPath
from trackplan.paths.specs import ArcSpec, PointsSpec, SegmentSpec
from trackplan.tool import (
    DEFAULT_SPIN_RATE,
    MIN_NORMAL_LENGTH,
    SpinMode,
    SpinProfile,
    ToolFrame,
    ToolSpec,
    seam_problems,
)
from trackplan.tool.weld_normal import declares_normals

MAX_SPIN_RATE = 1.0e6
"""Largest ``spin_rate``, rad/m (one ≤ 0 is reported with its unit by :func:`tool_problems`)."""


class ToolModel(StrictModel):
    """``task.tool``: frame, normal, work and travel angles (rad), spin (rad, rad/m)."""

    frame: Literal["part", "seam"] = "part"
    rpy: Vec3 | None = None
    normal: Vec3 | None = None
    normals: list[Vec3] | None = None
    work_angle: Coordinate = 0.0
    travel_angle: Coordinate = 0.0
    spin: Literal["fixed", "free", "free-varying"] = "fixed"
    spin_value: Coordinate = 0.0
    spin_range: Range = list_default(-math.pi, math.pi)
    spin_rate: Annotated[float, Field(le=MAX_SPIN_RATE)] = DEFAULT_SPIN_RATE


def tool_problems(
    tool: ToolModel | None, tool_rpy: list[float] | None, nominal: NominalPath | None
) -> list[Problem]:
    """Bad values of ``task.tool`` (and its alias), located in the file.

    Parameters
    ----------
    tool, tool_rpy
        The validated ``task.tool`` and ``task.tool_rpy`` keys, either may be absent.
    nominal
        The case's nominal path (for the seam frame along it), None when the path is bad.
    """
    at: Loc = ("task", "tool")
    if tool is not None and tool_rpy is not None:
        return [
            (
                ("task", "tool_rpy"),
                "give the tool orientation once: task.tool_rpy is the old spelling of "
                "task.tool {frame: part, rpy: ...}; remove one of the two",
            )
        ]
    if tool is None:
        return []
    problems: list[Problem] = []
    if tool.frame == "seam":
        problems += _normal_problems(tool, nominal)
        if tool.rpy is not None:
            problems.append(((*at, "rpy"), "rpy applies to frame: part; remove it or the frame"))
    else:
        for key in ("normal", "normals"):
            if getattr(tool, key) is not None:
                problems.append(((*at, key), f"{key} applies to frame: seam; remove it or set it"))
    low, high = tool.spin_range
    if low > high:
        problems.append(
            (
                (*at, "spin_range"),
                f"expected [min, max] with min ≤ max, rad, got {show([low, high])}",
            )
        )
    if not tool.spin_rate > 0.0:
        problems.append(
            ((*at, "spin_rate"), f"expected a rate > 0, rad/m of path, got {show(tool.spin_rate)}")
        )
    return problems


def _normal_problems(tool: ToolModel, nominal: NominalPath | None) -> list[Problem]:
    """Bad ``normal`` / ``normals`` of ``frame: seam``: absent, both, count, zero, parallel."""
    at: Loc = ("task", "tool")
    if tool.normal is not None and tool.normals is not None:
        return [
            (
                (*at, "normals"),
                "give the surface normal once: normal (the whole path) or normals (one per "
                "path segment); remove one of the two",
            )
        ]
    uncovered = _segments_without_normal(nominal)
    if tool.normal is None and tool.normals is None and uncovered:
        return [
            (
                (*at, "frame"),
                "frame: seam needs task.tool.normal [x, y, z] or task.tool.normals "
                "[[x, y, z], ...] (one per path segment)"
                + (
                    f", or a weld normal on every segment (path.segments[{uncovered[0]}] has none)"
                    if nominal is not None and len(uncovered) < len(nominal.segments)
                    else ""
                ),
            )
        ]
    short = f"expected a surface normal of length ≥ {MIN_NORMAL_LENGTH:g}, got"
    if tool.normal is not None and not math.hypot(*tool.normal) >= MIN_NORMAL_LENGTH:
        return [((*at, "normal"), f"{short} {show(tool.normal)}")]
    if tool.normals is not None:
        if nominal is not None and len(tool.normals) != len(nominal.segments):
            n = len(nominal.segments)
            return [
                (
                    (*at, "normals"),
                    f"expected {n} normals, one per path segment ({n} segments), "
                    f"got {len(tool.normals)}",
                )
            ]
        for i, normal in enumerate(tool.normals):
            if not math.hypot(*normal) >= MIN_NORMAL_LENGTH:
                return [((*at, "normals", i), f"{short} {show(normal)}")]
    if nominal is None:
        return []
    return [
        (_seam_problem_key(tool, nominal, index), text)
        for index, text in seam_problems(as_spec(tool), nominal)
    ]


def _seam_problem_key(tool: ToolModel, nominal: NominalPath, index: int | None) -> Loc:
    """Where a problem of :func:`seam_problems` about normal ``index`` is in the file."""
    at: Loc = ("task", "tool")
    if index is None:
        return (*at, "normal")
    if declares_normals([nominal.segments[index]]):
        kind = "arc" if isinstance(nominal.segments[index], ArcSpec) else "points"
        return ("path", "segments", index, kind)
    if tool.normals is not None:
        return (*at, "normals", index)
    return (*at, "normal")


def path_tool_problems(
    tool: ToolModel | None,
    tool_rpy: list[float] | None,
    nominal: NominalPath | None,
    segments: Sequence[SegmentSpec],
    loc: Loc,
    prefix: Loc,
) -> list[Problem]:
    """The problems of one path's tool (:func:`tool_problems`) and of the weld normals on
    its segments (:func:`segment_normal_problems`), located in the file: ``loc`` is the
    path's location, ``prefix`` that of the ``task`` holding the tool (() for the case's)."""
    problems: list[Problem] = [
        ((*loc, *where[1:]) if where[:1] == ("path",) else (*prefix, *where), message)
        for where, message in tool_problems(tool, tool_rpy, nominal)
    ]
    frame = None if tool is None else tool.frame
    tool_key = key_path((*prefix, "task", "tool"))
    return problems + [
        ((*loc, *where), message)
        for where, message in segment_normal_problems(segments, frame, tool_key)
    ]


def _segments_without_normal(nominal: NominalPath | None) -> list[int | str]:
    """The segments that declare no weld normal of their own (["?"] without a path)."""
    if nominal is None:
        return ["?"]
    return [i for i, segment in enumerate(nominal.segments) if not declares_normals([segment])]


def segment_normal_problems(
    segments: Sequence[SegmentSpec], frame: str | None, tool_key: str = "task.tool"
) -> list[Problem]:
    """Bad weld normals declared on path segments (locations relative to the path).

    A declared normal needs ``frame: seam`` and a length of at least
    :data:`~trackplan.tool.MIN_NORMAL_LENGTH` (each row of a points segment).
    """
    problems: list[Problem] = []
    for i, segment in enumerate(segments):
        if not declares_normals([segment]):
            continue
        key: Loc = ("segments", i, "arc", "weld_normal")
        if isinstance(segment, PointsSpec):
            key = ("segments", i, "points")
        if frame != "seam":
            problems.append(
                (
                    key,
                    f"a weld normal applies to {tool_key}.frame: seam (the tool held relative "
                    "to the seam); set that frame or remove the normal",
                )
            )
            continue
        given = (
            segment.weld_normal
            if isinstance(segment, ArcSpec)
            else segment.normals
            if isinstance(segment, PointsSpec)
            else None
        )
        length = np.linalg.norm(np.atleast_2d(np.asarray(given, dtype=float)), axis=1)
        short = np.flatnonzero(~(length >= MIN_NORMAL_LENGTH))
        if len(short):
            where = "" if isinstance(segment, ArcSpec) else f" at point {int(short[0])}"
            shown = show(np.atleast_2d(np.asarray(given))[short[0]].tolist())
            problems.append(
                (
                    key,
                    f"expected a surface normal of length ≥ {MIN_NORMAL_LENGTH:g}{where}, got "
                    f"{shown}",
                )
            )
    return problems


def as_spec(tool: ToolModel | None, tool_rpy: list[float] | None = None) -> ToolSpec:
    """The :class:`ToolSpec` of checked keys (the paper's tool when neither is given)."""
    if tool is None:
        return ToolSpec.part(np.array(tool_rpy if tool_rpy is not None else [0.0, 0.0, 0.0]))
    return ToolSpec(
        frame=ToolFrame(tool.frame),
        rpy=np.array(tool.rpy if tool.rpy is not None else [0.0, 0.0, 0.0], dtype=float),
        normal=None if tool.normal is None else np.array(tool.normal, dtype=float),
        normals=None if tool.normals is None else np.array(tool.normals, dtype=float),
        work_angle=tool.work_angle,
        travel_angle=tool.travel_angle,
        spin=SpinMode(tool.spin),
        spin_value=tool.spin_value,
        spin_range=(tool.spin_range[0], tool.spin_range[1]),
        spin_rate=tool.spin_rate,
    )


def load_spin_profile(file: str | Path) -> SpinProfile:
    """Read a spin profile: ``{value: v}`` or ``{coefficients: [...]}`` in YAML or JSON, rad.

    A ``result.json`` of a run is accepted too (its ``spin`` entry). The coefficients are
    those of a clamped cubic B-spline on uniform knots over the planned path
    (``docs/tool.md``); the path length is the case's.

    Raises
    ------
    CaseError
        When the file is unreadable or holds neither a value nor coefficients.
    """
    text = read_text(file, what="spin profile")
    data = parse_yaml(text, str(file))
    if isinstance(data, dict) and isinstance(data.get("spin"), dict):
        data = data["spin"]
    if isinstance(data, dict) and "value" in data:
        values = [data["value"]]
    elif isinstance(data, dict) and "coefficients" in data:
        values = data["coefficients"]
    else:
        raise CaseError(
            "expected {value: rad} or {coefficients: [rad, ...]} (or a result.json)",
            file=str(file),
        )
    try:
        coefficients = np.array(values, dtype=float).reshape(-1)
    except (TypeError, ValueError):
        raise CaseError(f"expected numbers, got {show(values)}", file=str(file)) from None
    if not coefficients.size or not np.all(np.isfinite(coefficients)):
        raise CaseError(f"expected finite numbers, got {show(values)}", file=str(file))
    return SpinProfile(coefficients, 0.0)
