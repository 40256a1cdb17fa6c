"""The ``cell:`` block of a case file: obstacles, workpiece bodies, tool and link capsules.

Format (``docs/cell.md``)::

    cell:
      clearance: 0.01                # m (default 0.005)
      obstacles:                     # robot base frame; pose = [x, y, z, roll, pitch, yaw]
        - {name: floor, plane: {normal: [0, 0, 1], offset: -0.65}}
        - {name: table, box: {size: [1.2, 0.8, 0.04], pose: [0.7, 0, -0.42, 0, 0, 0]}}
        - {name: column, cylinder: {radius: 0.06, length: 1.5, pose: [-0.4, 0.5, 0.1, 0, 0, 0]}}
        - {name: ball, sphere: {radius: 0.1, pose: [0.5, 0.5, 0.5, 0, 0, 0]}}
        - {name: post, capsule: {radius: 0.05, length: 0.4, pose: [0, 0.6, 0, 0, 0, 0]}}
        - {name: fence, mesh: {file: fence.stl, pose: [0, 0, 0, 0, 0, 0], scale: 0.001}}
      workpiece:                     # the path's definition frame (moves with the placement)
        - {name: plate, box: {size: [0.6, 0.3, 0.01], pose: [0.25, 0.1, -0.005, 0, 0, 0]}}
      tool:                          # capsules in the TCP frame (tool axis z)
        - {name: torch, from: [0, 0, -0.2], to: [0, 0, 0], radius: 0.015}
      tool_contact: 0.02             # m behind the TCP that may touch the workpiece
      links:                         # optional: replaces the robot's built-in capsule model
        - {link: 2, from: [-0.4318, 0, 0], to: [0, 0, 0], radius: 0.07}

Cylinders and capsules lie along z of their pose, centred on it; a plane's solid side is
opposite its normal (``normal · p < offset``).
"""

from __future__ import annotations

from pathlib import Path
from typing import Annotated, Any

import numpy as np
from pydantic import Field, model_validator
from pydantic_core import PydanticCustomError

from trackplan.cell.model import DEFAULT_CLEARANCE, Body, Capsules, Cell, Shape
from trackplan.cell.robot_bodies import builtin_link_capsules
from trackplan.errors import CaseError
from trackplan.frames import placement_transform
from trackplan.io.robot_bounds import MAX_LENGTH
from trackplan.io.urdf import file_kind
from trackplan.io.yaml_input import (
    NonEmptyStr,
    NonNegative,
    Positive,
    Problem,
    StrictModel,
    Vec3,
    Vec6,
    key_path,
    list_default,
    show,
)
from trackplan.robots.model import Robot

SHAPES = ("plane", "box", "cylinder", "sphere", "capsule", "mesh")

PositiveVec3 = Annotated[list[Positive], Field(min_length=3, max_length=3)]


class PlaneModel(StrictModel):
    """``plane: {normal, offset}``: the half-space ``normal · p < offset`` is solid, m."""

    normal: Vec3
    offset: float = 0.0


class BoxModel(StrictModel):
    """``box: {size, pose}``: full edge lengths (m) and pose of the centre."""

    size: PositiveVec3
    pose: Vec6 = list_default(0.0, 0.0, 0.0, 0.0, 0.0, 0.0)


class CylinderModel(StrictModel):
    """``cylinder: {radius, length, pose}``: along z of the pose, centred on it, m."""

    radius: Positive
    length: Positive
    pose: Vec6 = list_default(0.0, 0.0, 0.0, 0.0, 0.0, 0.0)


class SphereModel(StrictModel):
    """``sphere: {radius, pose}``, m."""

    radius: Positive
    pose: Vec6 = list_default(0.0, 0.0, 0.0, 0.0, 0.0, 0.0)


class MeshModel(StrictModel):
    """``mesh: {file, pose, scale}``: a mesh file (STL, OBJ, PLY, …) read by trimesh."""

    file: NonEmptyStr
    pose: Vec6 = list_default(0.0, 0.0, 0.0, 0.0, 0.0, 0.0)
    scale: Positive = 1.0


class BodyModel(StrictModel):
    """One body: a name and exactly one shape."""

    name: NonEmptyStr
    plane: PlaneModel | None = None
    box: BoxModel | None = None
    cylinder: CylinderModel | None = None
    sphere: SphereModel | None = None
    capsule: CylinderModel | None = None
    mesh: MeshModel | None = None

    @model_validator(mode="after")
    def _one_shape(self) -> BodyModel:
        given = [shape for shape in SHAPES if getattr(self, shape) is not None]
        if len(given) != 1:
            raise PydanticCustomError(
                "body_shape",
                "expected exactly one shape of " + ", ".join(SHAPES) + ", got {given}",
                {"given": ", ".join(given) or "none"},
            )
        return self


class CapsuleModel(StrictModel):
    """A tool capsule in the TCP frame: axis ``from`` → ``to`` (m) and radius (m)."""

    name: NonEmptyStr = "tool"
    from_: Vec3 = Field(alias="from")
    to: Vec3
    radius: Positive


class LinkCapsuleModel(StrictModel):
    """A link capsule: link number (0 = base), axis end points in the link frame, radius, m."""

    link: Annotated[int, Field(ge=0)]
    from_: Vec3 = Field(alias="from")
    to: Vec3
    radius: Positive


class CellModel(StrictModel):
    """Schema of the ``cell:`` block."""

    clearance: NonNegative = DEFAULT_CLEARANCE
    obstacles: list[BodyModel] = Field(default_factory=list)
    workpiece: list[BodyModel] = Field(default_factory=list)
    tool: list[CapsuleModel] = Field(default_factory=list)
    tool_contact: NonNegative = 0.0
    links: list[LinkCapsuleModel] | None = None


def cell_problems(model: CellModel, n_dof: int) -> list[Problem]:
    """Values the schema cannot check: zero plane normals, link numbers past the chain."""
    problems: list[Problem] = []
    for group in ("obstacles", "workpiece"):
        for i, body in enumerate(getattr(model, group)):
            if body.plane is not None and np.linalg.norm(body.plane.normal) < 1e-12:
                problems.append(
                    (
                        ("cell", group, i, "plane", "normal"),
                        f"expected a non-zero normal vector, got {show(body.plane.normal)}",
                    )
                )
    for i, capsule in enumerate(model.links or []):
        if capsule.link > n_dof:
            problems.append(
                (
                    ("cell", "links", i, "link"),
                    f"expected a link number 0..{n_dof} (0 = base), got {capsule.link}",
                )
            )
    return problems


def build_cell(model: CellModel, base_dir: Path, case_file: str | None, robot: Robot) -> Cell:
    """The :class:`Cell` of a validated ``cell:`` block (meshes read relative to ``base_dir``).

    Raises
    ------
    CaseError
        When a mesh file is missing or cannot be read as a mesh (at its ``file`` key), or
        the block gives no ``links`` for a robot without a built-in capsule model.
    """
    if model.links is None:
        try:
            builtin_link_capsules(robot)
        except CaseError as exc:
            raise CaseError(exc.message, file=case_file, key="cell") from None
    obstacles = tuple(
        _body(body, base_dir, case_file, ("cell", "obstacles", i))
        for i, body in enumerate(model.obstacles)
    )
    workpiece = tuple(
        _body(body, base_dir, case_file, ("cell", "workpiece", i))
        for i, body in enumerate(model.workpiece)
    )
    tool = Capsules(
        frame=np.zeros(len(model.tool), dtype=np.int64),
        segment=np.array([[c.from_, c.to] for c in model.tool], dtype=float).reshape(-1, 2, 3),
        radius=np.array([c.radius for c in model.tool], dtype=float),
        name=tuple(c.name for c in model.tool),
    )
    links = None
    if model.links is not None:
        links = Capsules(
            frame=np.array([c.link for c in model.links], dtype=np.int64),
            segment=np.array([[c.from_, c.to] for c in model.links], dtype=float).reshape(-1, 2, 3),
            radius=np.array([c.radius for c in model.links], dtype=float),
            name=tuple("base" if c.link == 0 else f"link {c.link}" for c in model.links),
        )
    return Cell(
        obstacles=obstacles,
        workpiece=workpiece,
        tool=tool,
        links=links,
        clearance=model.clearance,
        tool_contact=model.tool_contact,
    )


def _pose(values: list[float]) -> np.ndarray:
    return placement_transform(np.asarray(values, dtype=float))


def _body(body: BodyModel, base_dir: Path, case_file: str | None, loc: tuple[Any, ...]) -> Body:
    if body.plane is not None:
        normal = np.asarray(body.plane.normal, dtype=float)
        norm = float(np.linalg.norm(normal))
        return Body(body.name, Shape.PLANE, _plane_frame(normal / norm, body.plane.offset / norm))
    if body.box is not None:
        half = 0.5 * np.asarray(body.box.size, dtype=float)
        return Body(body.name, Shape.BOX, _pose(body.box.pose), half)
    if body.cylinder is not None:
        c = body.cylinder
        return Body(
            body.name, Shape.CYLINDER, _pose(c.pose), np.array([c.radius, 0.5 * c.length, 0.0])
        )
    if body.sphere is not None:
        return Body(
            body.name, Shape.SPHERE, _pose(body.sphere.pose), np.array([body.sphere.radius, 0, 0])
        )
    if body.capsule is not None:
        c = body.capsule
        return Body(
            body.name, Shape.CAPSULE, _pose(c.pose), np.array([c.radius, 0.5 * c.length, 0.0])
        )
    assert body.mesh is not None  # the schema requires exactly one shape
    file = base_dir / body.mesh.file
    vertices, faces = load_mesh(file, case_file, key_path((*loc, "mesh", "file")))
    with np.errstate(over="ignore", invalid="ignore"):
        scaled = vertices * body.mesh.scale
        extent = float(np.max(np.abs(scaled)))
    if not extent <= MAX_LENGTH:  # NaN too
        raise CaseError(
            f"mesh file {str(file)!r} has a vertex {extent:g} m from its origin once scaled: "
            f"vertices must lie within ±{MAX_LENGTH:g} m (check the mesh's units and scale)",
            file=case_file,
            key=key_path((*loc, "mesh", "scale")),
        )
    return Body(body.name, Shape.MESH, _pose(body.mesh.pose), vertices=scaled, faces=faces)


def _plane_frame(normal: np.ndarray, offset: float) -> np.ndarray:
    """A frame whose z axis is the unit normal and whose origin lies on the plane."""
    helper = np.array([1.0, 0.0, 0.0]) if abs(normal[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
    x = np.cross(helper, normal)
    x /= np.linalg.norm(x)
    T = np.eye(4)
    T[:3, :3] = np.column_stack([x, np.cross(normal, x), normal])
    T[:3, 3] = offset * normal
    return T


def load_mesh(file: Path, case_file: str | None, key: str) -> tuple[np.ndarray, np.ndarray]:
    """Vertices (V, 3) and triangles (F, 3) of a mesh file, read by trimesh.

    Raises
    ------
    CaseError
        When the file is missing, unreadable, or holds no triangles (at ``key``).
    """
    import trimesh

    kind = file_kind(file)
    if kind is not None:
        raise CaseError(f"mesh file {str(file)!r} {kind}", file=case_file, key=key)
    try:
        mesh = trimesh.load(str(file), force="mesh")
    except Exception as exc:
        reason = str(exc).splitlines()[0] if str(exc) else type(exc).__name__
        raise CaseError(
            f"mesh file {str(file)!r} cannot be read as a mesh: {reason}", file=case_file, key=key
        ) from None
    faces = np.asarray(getattr(mesh, "faces", np.zeros((0, 3))), dtype=np.int64)
    if faces.ndim != 2 or len(faces) == 0:
        raise CaseError(
            f"mesh file {str(file)!r} cannot be read as a mesh: no triangles found "
            "(expected STL, OBJ, PLY, …)",
            file=case_file,
            key=key,
        )
    return np.asarray(getattr(mesh, "vertices"), dtype=float), faces  # noqa: B009
