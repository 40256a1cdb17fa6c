"""The schema of case files (pydantic models): every key, its type and its default.

:mod:`trackplan.io.case_file` validates a file against these models, then checks the
values and builds the case; ``docs/files.md`` describes every key.
"""

from __future__ import annotations

from typing import Annotated, Any, Literal

from pydantic import AfterValidator, Discriminator, Field, Tag, model_validator
from pydantic_core import PydanticCustomError

from trackplan.io.case_axes import DownhandModel, PositionerModel, TrackModel, WeaveModel
from trackplan.io.case_redundancy import RedundancyModel
from trackplan.io.case_tcp import TcpModel
from trackplan.io.cell_file import CellModel
from trackplan.io.points_file import MIN_POINTS
from trackplan.io.robot_file import PayloadModel
from trackplan.io.sizes import MAX_SAMPLE_TIME
from trackplan.io.tool_file import ToolModel
from trackplan.io.yaml_input import (
    Coordinate,
    NonEmptyStr,
    NonNegative,
    Positive,
    Range,
    StrictModel,
    Vec3,
    Vec6,
    list_default,
)

ANGLE_RANGE = (-1.57, 1.57)
"""Default search range of roll, pitch, yaw, rad (the paper's Eq. 31)."""


class LineModel(StrictModel):
    """``line: {to: [x, y, z]}``, m."""

    to: Vec3


class ArcModel(StrictModel):
    """``arc: {center, normal, angle}``: rotation of the current point by ``angle`` (rad).

    ``weld_normal``: the weld's surface normal at the arc's start, turned with the arc."""

    center: Vec3
    normal: Vec3
    angle: float
    weld_normal: Vec3 | None = None


def _point_row(value: list[float]) -> list[float]:
    if len(value) not in (3, 6):
        raise PydanticCustomError(
            "vector_length",
            "expected 3 numbers [x, y, z] or 6 [x, y, z, nx, ny, nz], got {actual}",
            {"actual": len(value)},
        )
    return value


PointRow = Annotated[list[Coordinate], AfterValidator(_point_row)]
"""An inline point: ``[x, y, z]`` or ``[x, y, z, nx, ny, nz]`` (with the weld's normal)."""


def _one_width(rows: list[list[float]]) -> list[list[float]]:
    if len({len(row) for row in rows}) > 1:
        raise PydanticCustomError(
            "points_width",
            "expected every point as [x, y, z] or every point as [x, y, z, nx, ny, nz] "
            "(with the weld's normal), not a mix",
        )
    return rows


class PointsFileModel(StrictModel):
    """``points: {file: seam.csv}``: x, y, z rows (or x, y, z, nx, ny, nz), relative to the
    case file."""

    file: NonEmptyStr


def _points_kind(value: Any) -> str | None:
    if isinstance(value, list):
        return "<list>"
    if isinstance(value, dict):
        return "<file>"
    return None


PointsModel = Annotated[
    Annotated[
        list[PointRow], Field(min_length=MIN_POINTS), AfterValidator(_one_width), Tag("<list>")
    ]
    | Annotated[PointsFileModel, Tag("<file>")],
    Discriminator(
        _points_kind,
        custom_error_type="points_type",
        custom_error_message=(
            "expected a list of [x, y, z] (or [x, y, z, nx, ny, nz]) points or {file: name.csv}"
        ),
    ),
]


class SegmentModel(StrictModel):
    """One path segment: exactly one of ``line``, ``arc``, ``points``."""

    line: LineModel | None = None
    arc: ArcModel | None = None
    points: PointsModel | None = None

    @model_validator(mode="after")
    def _one_kind(self) -> SegmentModel:
        given = [kind for kind in ("line", "arc", "points") if getattr(self, kind) is not None]
        if len(given) != 1:
            raise PydanticCustomError(
                "segment_kind",
                "expected exactly one of line, arc, points, got {given}",
                {"given": ", ".join(given) or "none"},
            )
        return self


class PathModel(StrictModel):
    """``path``: start point and segments in the definition frame, m."""

    start: Vec3
    segments: Annotated[list[SegmentModel], Field(min_length=1)]


MIN_TOLERANCE = 1e-6
"""Smallest path tolerance, m: a micrometre, below the repeatability of any industrial arm
(0.02 mm and more). Corner blends and the checker's grid refine with the tolerance, so a
tolerance far below it (1e-300) would ask for more memory than any machine has."""
Tolerance = Annotated[float, Field(ge=MIN_TOLERANCE)]


class TaskModel(StrictModel):
    """``task``: speeds (m/s), tolerance (m), sample time (s), tool orientation (rad), weave."""

    rated_speed: Positive
    corner_speed: Positive | None = None
    tolerance: Tolerance = 0.001
    sample_time: Annotated[float, Field(gt=0, le=MAX_SAMPLE_TIME)] = 0.001
    tool_rpy: Vec3 | None = None
    tool: ToolModel | None = None
    timing: Literal["smooth", "paper"] = "smooth"
    weave: WeaveModel | None = None
    redundancy: RedundancyModel | None = None


class SeamTaskModel(StrictModel):
    """A seam's ``task``: overrides of the case's speeds (m/s), tolerance (m), tool and weave."""

    rated_speed: Positive | None = None
    corner_speed: Positive | None = None
    tolerance: Tolerance | None = None
    tool_rpy: Vec3 | None = None
    tool: ToolModel | None = None
    weave: WeaveModel | None = None  # null turns the case's weave off for this seam
    redundancy: RedundancyModel | None = None


def _csv_safe_name(name: str) -> str:
    """A seam name that ``trajectory.csv``'s ``segment`` column can hold as it is."""
    if any(mark in name for mark in ',"') or not name.isprintable() or name[0] in "=+-@":
        raise PydanticCustomError(
            "seam_name",
            "a seam name labels the rows of trajectory.csv: no commas, quotes, tabs or line "
            "breaks, and no =, +, - or @ first (a spreadsheet would run it as a formula)",
        )
    return name


class FaceRefModel(StrictModel):
    """A face of the part: ``{face: ID}`` or ``{near: [x, y, z]}`` (m, the nearest face)."""

    face: int | None = None
    near: Vec3 | None = None

    @model_validator(mode="after")
    def _one_way(self) -> FaceRefModel:
        if (self.face is None) == (self.near is None):
            raise PydanticCustomError(
                "face_ref", "expected exactly one of face (an id) or near ([x, y, z], m)"
            )
        return self


class CadNormalModel(StrictModel):
    """``cad.normal``: one face's normal (``face`` or ``near``) or the bisector of two
    faces' normals (``between``)."""

    face: int | None = None
    near: Vec3 | None = None
    between: Annotated[list[FaceRefModel], Field(min_length=2, max_length=2)] | None = None

    @model_validator(mode="after")
    def _one_way(self) -> CadNormalModel:
        if sum(value is not None for value in (self.face, self.near, self.between)) != 1:
            raise PydanticCustomError(
                "cad_normal", "expected exactly one of face, near or between (two faces)"
            )
        return self


class CadSeamModel(StrictModel):
    """``paths[i].cad``: a seam from the part's CAD model (instead of start and segments)."""

    between: Annotated[list[FaceRefModel], Field(min_length=2, max_length=2)] | None = None
    edges: Annotated[list[Annotated[int, Field(ge=1)]], Field(min_length=1)] | None = None
    joint: Literal["fillet", "face"] | None = None
    normal: CadNormalModel | None = None
    reverse: bool = False

    @model_validator(mode="after")
    def _one_kind(self) -> CadSeamModel:
        if (self.between is None) == (self.edges is None):
            raise PydanticCustomError(
                "cad_kind",
                "expected exactly one of between (two faces) or edges (edge ids)",
            )
        if self.joint is not None and self.between is None:
            raise PydanticCustomError(
                "cad_joint", "joint applies to between; with edges give normal: {face: ID}"
            )
        if self.joint is not None and self.normal is not None:
            raise PydanticCustomError(
                "cad_joint", "give joint or normal, not both (normal names the faces itself)"
            )
        return self


class PartFileModel(StrictModel):
    """``part``: the part's CAD model (STEP or mesh), relative to the case file."""

    file: NonEmptyStr
    scale: Positive | None = None
    body: bool = True
    feature_angle: Annotated[float, Field(gt=0, lt=3.1416)] = 0.349


class SeamModel(PathModel):
    """One entry of ``paths``: a named path, its task overrides, whether it may be reversed.

    ``cad``: the seam from the part's CAD model; :mod:`trackplan.io.case_cad` derives its
    ``start`` and ``segments`` before the case is validated."""

    name: Annotated[NonEmptyStr, AfterValidator(_csv_safe_name)]
    task: SeamTaskModel | None = None
    reversible: bool = True
    cad: CadSeamModel | None = None


class PlacementModel(StrictModel):
    """``placement``: search ranges [min, max] of X and the reach range, m and rad."""

    x: Range | None = None  # default: position_range(robot)
    y: Range | None = None
    z: Range | None = None
    roll: Range = list_default(*ANGLE_RANGE)
    pitch: Range = list_default(*ANGLE_RANGE)
    yaw: Range = list_default(*ANGLE_RANGE)
    reach: Range | None = None  # default: the robot's default_placement_reach
    example: Vec6 | None = None


class ObjectiveModel(StrictModel):
    """``objective``: kind, joint weights of Eq. 8, time weight (1/s), mix and penalty."""

    kind: Literal["travel", "energy", "copper", "time", "weighted"] = "travel"
    mix: dict[str, NonNegative] | None = None
    weights: list[NonNegative] | None = None
    external_weights: list[NonNegative] | None = None
    time_weight: NonNegative = 0.0
    penalty: Literal["graded", "flat"] = "graded"
    flat_penalty: Positive = 1.0e6


class OptimizerModel(StrictModel):
    """``optimizer``: method, population, seed, evaluation budget and independent runs."""

    method: Literal["multistart", "ga", "cmaes", "de", "random"] = "multistart"
    population: Annotated[int, Field(ge=2)] = 30
    seed: Annotated[int, Field(ge=0)] = 0
    budget: Annotated[int, Field(ge=1)] | None = None
    restarts: Annotated[int, Field(ge=1)] | None = None


class CaseModel(StrictModel):
    """Schema of a case file."""

    name: NonEmptyStr
    robot: NonEmptyStr = "puma560"
    payload: PayloadModel | None = None
    tcp: TcpModel | None = None
    path: PathModel | None = None
    paths: Annotated[list[SeamModel], Field(min_length=1)] | None = None
    part: PartFileModel | None = None
    sequence: Literal["optimize", "given"] | None = None
    approach: NonNegative | None = None
    home: Annotated[list[Coordinate], Field(min_length=1)] | None = None
    task: TaskModel
    placement: PlacementModel = Field(default_factory=PlacementModel)
    objective: ObjectiveModel = Field(default_factory=ObjectiveModel)
    optimizer: OptimizerModel = Field(default_factory=OptimizerModel)
    cell: CellModel | None = None
    positioner: PositionerModel | None = None
    track: TrackModel | None = None
    downhand: DownhandModel | None = None


class SinglePathCaseModel(CaseModel):
    """A case file without ``paths``: its ``path`` is required (reported like any missing key)."""

    path: PathModel
