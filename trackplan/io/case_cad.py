"""Seams from the part's CAD model in a case file: ``part:`` and ``paths[i].cad``.

:func:`expand_cad` reads the part (``part.file``, relative to the case file, with
:func:`trackplan.io.part_file.load_part`), derives every ``cad:`` seam's start point and
segments (:func:`trackplan.cad.seams.derive_seam`) and writes them into the case data as
plain ``start``/``segments`` (lines, arcs with ``weld_normal``, points with normals), so that
the rest of the case is read as any other. :func:`with_part_body` adds the part's
tessellation to the cell's workpiece; :func:`plain_case_yaml` writes the expanded case for
``trackplan seams``.
"""

from __future__ import annotations

import copy
import dataclasses
import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from pydantic import BaseModel, ConfigDict

from trackplan.cad.part import PartModel
from trackplan.cad.seams import CadSeam, FaceRef, SeamError, derive_seam, seam_summary
from trackplan.case import Case
from trackplan.cell.model import Body, Cell, Shape
from trackplan.errors import CaseError
from trackplan.io.case_schema import MIN_TOLERANCE, CadSeamModel, FaceRefModel, PartFileModel
from trackplan.io.yaml_input import (
    Loc,
    key_path,
    parse_yaml,
    raise_first,
    read_text,
    validate_model,
)
from trackplan.paths import check_segments
from trackplan.paths.specs import ArcSpec, LineSpec, SegmentSpec

PART_CHORD_ERROR = 0.0005
"""Chord error of the part's tessellation as a workpiece body of the cell, m (0.5 mm)."""
BODY_NAME = "part"
"""The name of the part's workpiece body in the cell and its reports."""


class _View(BaseModel):
    model_config = ConfigDict(extra="ignore")


class _TaskView(_View):
    tolerance: Any = None  # the case schema checks it; a bad one derives with the default


class _SeamView(_View):
    name: Any = None
    start: Any = None
    segments: Any = None
    task: _TaskView | None = None
    cad: CadSeamModel | None = None


class _CaseView(_View):
    """The keys the expansion reads; the case schema checks the rest afterwards."""

    part: PartFileModel | None = None
    paths: list[_SeamView] | None = None
    task: Any = None


@dataclass(frozen=True, eq=False)
class CadPath:
    """One derived seam: its index in ``paths``, name, start point and segments."""

    index: int
    name: str
    start: np.ndarray
    segments: tuple[SegmentSpec, ...]

    def summary(self) -> dict[str, object]:
        """Length (m), pieces by kind, closedness (:func:`~trackplan.cad.seams.seam_summary`)."""
        return seam_summary(self.start, self.segments)


@dataclass(frozen=True, eq=False)
class CadCase:
    """The part of a case and its derived seams."""

    part: PartModel
    body: bool
    paths: tuple[CadPath, ...]
    cell: bool = False
    """Whether the case has a ``cell`` (else the part is the body of a cell of its own)."""


def expand_cad(data: Any, file: str | None, base: Path) -> tuple[Any, CadCase | None]:
    """The case data with every ``cad:`` seam as plain ``start``/``segments``, and the part.

    Data without ``part`` or ``cad`` keys is returned as it is (and None).

    Raises
    ------
    CaseError
        A bad ``part`` or ``cad`` block, a part file that cannot be read, a seam that cannot
        be derived (:class:`~trackplan.cad.seams.SeamError`), at its key.
    """
    if not isinstance(data, dict):
        return data, None
    paths = data.get("paths")
    entries = paths if isinstance(paths, list) else []
    has_cad = any(isinstance(entry, dict) and "cad" in entry for entry in entries)
    if "part" not in data and not has_cad:
        return data, None
    view = validate_model(_CaseView, data, file)
    problems: list[tuple[Loc, str]] = []
    for k, seam in enumerate(view.paths or []):
        if seam.cad is None:
            continue
        if seam.start is not None or seam.segments is not None:
            problems.append(
                (
                    ("paths", k, "cad"),
                    "give cad (a seam from the part) or start and segments, not both",
                )
            )
        elif view.part is None:
            problems.append(
                (("paths", k, "cad"), "cad needs the part's CAD model: add part: {file: NAME.step}")
            )
    raise_first(problems, data, file)
    if view.part is None:
        return data, None
    part = _read_part(view.part, base, file)
    derived: list[CadPath] = []
    out = dict(data)
    out["paths"] = list(entries)
    for k, seam in enumerate(view.paths or []):
        if seam.cad is None:
            continue
        tolerance = _tolerance(view, seam)
        try:
            start, segments = derive_seam(part, as_cad_seam(seam.cad), tolerance)
        except SeamError as exc:
            raise CaseError(
                exc.message, file=file, key=key_path(("paths", k, "cad", *exc.where))
            ) from None
        for key, message in check_segments(start, segments):  # e.g. a mesh's repeated point
            where = key_path(("paths", k, "cad"))
            raise CaseError(
                f"the derived seam is degenerate at {key.removeprefix('path.')}: {message}",
                file=file,
                key=where,
            )
        derived.append(CadPath(k, str(seam.name), start, segments))
        out["paths"][k] = _plain_entry(entries[k], start, segments)
    return out, CadCase(part, view.part.body, tuple(derived), cell="cell" in data)


def load_cad(file: str | Path) -> tuple[Any, CadCase | None]:
    """A case file's data with its ``cad:`` seams expanded, and its part (None without one).

    Raises
    ------
    CaseError
        As :func:`expand_cad`, and an unreadable file or bad YAML.
    """
    text = read_text(file, what="case file")
    return expand_cad(parse_yaml(text, str(file)), str(file), Path(file).parent)


def describe_cad(cad: CadCase) -> list[str]:
    """One line per derived seam (length, pieces by kind, closed or open) and the part's
    accuracy, for ``trackplan validate``."""
    part = cad.part
    lines = [
        f"part {part.source}: {len(part.faces)} faces, {len(part.edges)} edges, "
        + (
            "exact (STEP B-rep)"
            if part.exact
            else "a mesh: seam positions and normals as good as its tessellation"
        )
        + (
            f"; a workpiece body of the cell within {PART_CHORD_ERROR * 1000:g} mm"
            + ("" if cad.cell else " (a cell of the part alone: the case has no cell)")
            if cad.body
            else "; not a body of the cell (part.body: false)"
        )
    ]
    for path in cad.paths:
        summary = path.summary()
        kinds = summary["kinds"]
        assert isinstance(kinds, dict)
        names = {"line": "line", "arc": "arc", "points": "sampled curve"}
        pieces = ", ".join(
            f"{n} {names[kind]}{'s' if n > 1 else ''}" for kind, n in kinds.items() if n
        )
        closed = "closed" if summary["closed"] else "open"
        lines.append(
            f"CAD seam {path.name} (paths[{path.index}]): {summary['length']:.4f} m, "
            f"{pieces}, {closed}"
        )
    return lines


def _tolerance(view: _CaseView, seam: _SeamView) -> float:
    """The seam's path tolerance: its own, the case's, else the default 1 mm (also for a
    bad value, which the case schema then refuses)."""
    case_task = view.task.get("tolerance") if isinstance(view.task, dict) else None
    for value in (None if seam.task is None else seam.task.tolerance, case_task):
        if isinstance(value, int | float) and not isinstance(value, bool):
            if math.isfinite(value) and value >= MIN_TOLERANCE:
                return float(value)
    return 0.001


def _read_part(model: PartFileModel, base: Path, file: str | None) -> PartModel:
    """The part read from its file, problems located at ``part.file``."""
    from trackplan.io.part_file import load_part  # OCP and trimesh only for a case with a part

    path = base / model.file
    try:
        stat = path.stat()
        stamp = (str(path.resolve()), stat.st_mtime_ns, stat.st_size)
    except OSError:
        stamp = (str(path), -1, -1)  # the reader says what is wrong with it
    try:
        if stamp[1] < 0:
            part: PartModel = load_part(path, scale=model.scale, feature_angle=model.feature_angle)
        else:
            part = _cached_part(load_part, path, stamp, model.scale, model.feature_angle)
    except CaseError as exc:  # the part file's own problem, located at part.file
        if exc.key is not None:
            raise
        raise CaseError(exc.one_line(), file=file, key="part.file") from None
    return part


_PARTS: dict[tuple[object, ...], PartModel] = {}
"""Parts read in this process, by file, modification time, size, scale and feature angle:
``validate`` and ``seams`` read a case twice, a study many times."""
MAX_CACHED_PARTS = 4


def _cached_part(
    load_part: Any,
    path: Path,
    stamp: tuple[str, int, int],
    scale: float | None,
    feature_angle: float,
) -> PartModel:
    key = (*stamp, scale, feature_angle, load_part)
    if key not in _PARTS:
        while len(_PARTS) >= MAX_CACHED_PARTS:
            _PARTS.pop(next(iter(_PARTS)))
        _PARTS[key] = load_part(path, scale=scale, feature_angle=feature_angle)
    return _PARTS[key]


def as_cad_seam(model: CadSeamModel) -> CadSeam:
    """The derivation's view of a validated ``cad:`` block."""
    normal: tuple[FaceRef, ...] | None = None
    if model.normal is not None:
        if model.normal.between is not None:
            normal = tuple(_ref(ref) for ref in model.normal.between)
        else:
            normal = (_ref(FaceRefModel(face=model.normal.face, near=model.normal.near)),)
    return CadSeam(
        between=None if model.between is None else (_ref(model.between[0]), _ref(model.between[1])),
        edges=None if model.edges is None else tuple(model.edges),
        joint=model.joint,
        normal=normal,
        reverse=model.reverse,
    )


def _ref(model: FaceRefModel) -> FaceRef:
    return FaceRef(
        face=model.face, near=None if model.near is None else np.array(model.near, dtype=float)
    )


def _plain_entry(
    entry: dict[str, Any], start: np.ndarray, segments: tuple[SegmentSpec, ...]
) -> dict[str, Any]:
    """A ``paths`` entry with ``start`` and ``segments`` beside its ``cad``."""
    plain: dict[str, Any] = {}
    for key, value in entry.items():
        plain[key] = value
        if key == "cad":
            plain["start"] = _floats(start)
            plain["segments"] = [plain_segment(segment) for segment in segments]
    return plain


def plain_segment(segment: SegmentSpec) -> dict[str, Any]:
    """A segment as a case file writes it: ``line``, ``arc`` or ``points`` (with normals)."""
    if isinstance(segment, LineSpec):
        return {"line": {"to": _floats(segment.to)}}
    if isinstance(segment, ArcSpec):
        arc: dict[str, Any] = {
            "center": _floats(segment.center),
            "normal": _floats(segment.normal),
            "angle": float(segment.angle),
        }
        if segment.weld_normal is not None:
            arc["weld_normal"] = _floats(segment.weld_normal)
        return {"arc": arc}
    rows = np.asarray(segment.points, dtype=float)
    if segment.normals is not None:
        rows = np.hstack([rows, np.asarray(segment.normals, dtype=float)])
    return {"points": [_floats(row) for row in rows]}


def _floats(values: Any) -> list[float]:
    return [float(v) + 0.0 for v in np.asarray(values, dtype=float)]


def with_part_body(case: Case, cad: CadCase | None) -> Case:
    """The case with the part's tessellation (within :data:`PART_CHORD_ERROR`) as a
    workpiece mesh body of its cell when the part is a body: of the case's cell, or of a cell
    of the part alone (the robot's own link capsules, the default clearance) when the case
    has none."""
    if cad is None or not cad.body:
        return case
    mesh = cad.part.tessellation(PART_CHORD_ERROR)
    body = Body(BODY_NAME, Shape.MESH, np.eye(4), vertices=mesh.vertices, faces=mesh.triangles)
    own = case.cell if case.cell is not None else Cell()
    cell = dataclasses.replace(own, workpiece=(*own.workpiece, body))
    return dataclasses.replace(case, cell=cell)


def plain_case_yaml(data: Any) -> str:
    """The expanded case data as YAML, without the ``cad`` blocks: every seam as plain
    segments with their weld normals (the part stays, for its body)."""
    import yaml

    out = copy.deepcopy(data)
    for entry in out.get("paths") or []:
        if isinstance(entry, dict):
            entry.pop("cad", None)
    text: str = yaml.safe_dump(out, sort_keys=False, default_flow_style=None, width=100)
    return text
