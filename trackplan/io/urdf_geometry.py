"""A URDF's links on its chain: their collision geometry fitted with capsules, and their
visual meshes.

:func:`read_urdf_link_geometry` maps every link onto the chain's frames
(:func:`~trackplan.io.urdf.read_urdf_chain` reads the chain) and fits each
``<collision>`` element with an enclosing capsule; only it loads collision meshes
(``docs/cell.md``).

:func:`read_urdf_visuals` reads each ``<visual>`` of the links on the chain (meshes in STL,
OBJ, DAE or any format trimesh reads, ``package://`` and relative names resolved as for
collision meshes; boxes, cylinders and spheres tessellated by trimesh), places it in the
chain frame its link moves with, takes its colour from the URDF's material (the visual's
own ``<color>`` or a named top-level ``<material>``) and decimates the whole robot to
:data:`~trackplan.robots.visuals.MAX_TRIANGLES`. Visuals only change the report's picture:
when one of them is missing or cannot be read, the robot gets none (the report draws its
capsules) and the planning is unaffected.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from trackplan.errors import CaseError
from trackplan.io.robot_bounds import (
    MAX_LENGTH,
)
from trackplan.io.urdf import (
    _quiet,
    file_kind,
    load_urdf_model,
)
from trackplan.robots.collision import (
    Capsules,
    box_capsule,
    cylinder_capsule,
    points_capsule,
    sphere_capsule,
    transform_capsule,
)
from trackplan.robots.visuals import (
    DEFAULT_COLOR,
    MAX_TRIANGLES,
    LinkVisual,
    decimate_visuals,
)


@dataclass(frozen=True, eq=False)
class URDFLinkGeometry:
    """Where a URDF's links sit on the chain, and their collision geometry as capsules.

    Attributes
    ----------
    link_frames
        Link name → (frame, ``T_frame_link``): the chain frame the link moves with (0 the
        base link, i the child link of the i-th moving joint; see
        :func:`trackplan.robots.kinematics.joint_frames`) and the link's fixed pose in it,
        shape (4, 4). Only links on the chain or fixed to it appear.
    capsules
        One capsule per ``<collision>`` element of those links, enclosing its box,
        cylinder, sphere or mesh, in the chain frame; named after the link.
    """

    link_frames: dict[str, tuple[int, np.ndarray]]
    capsules: Capsules


def read_urdf_link_geometry(
    file: str | Path,
    joint_names: tuple[str, ...],
    base_link: str | None = None,
    *,
    collisions: bool = True,
) -> URDFLinkGeometry:
    """The chain frames of a URDF's links and capsules enclosing their ``<collision>`` shapes.

    A link belongs to frame i when fixed joints alone connect it to the child link of the
    chain's i-th moving joint (or to the base link, frame 0). Boxes, cylinders and spheres
    are fitted in closed form, meshes (read by trimesh, only here) from their vertices
    (:mod:`trackplan.robots.collision`).

    Parameters
    ----------
    file
        Path of the URDF.
    joint_names
        The chain's moving joints, base to tip (:attr:`URDFChain.joint_names`).
    base_link
        The chain's base link; default the root.
    collisions
        Read the ``<collision>`` elements (False: only the link frames).

    Returns
    -------
    URDFLinkGeometry

    Raises
    ------
    CaseError
        When a collision mesh is missing or cannot be read, or a shape has a size ≤ 0.
    """

    path = str(file)
    robot = load_urdf_model(path)
    by_child = {joint.child: joint for joint in robot.joints}
    base = base_link or next(link.name for link in robot.links if link.name not in by_child)
    anchors = {base: 0}
    for i, name in enumerate(joint_names):
        anchors[next(j.child for j in robot.joints if j.name == name)] = i + 1
    link_frames: dict[str, tuple[int, np.ndarray]] = {}
    for link in robot.links:
        T_anchor_link = np.eye(4)
        name = link.name
        while name not in anchors:
            joint = by_child.get(name)
            if joint is None or joint.type != "fixed":
                break
            origin = np.eye(4) if joint.origin is None else np.asarray(joint.origin, float)
            T_anchor_link = origin @ T_anchor_link
            name = joint.parent
        else:
            link_frames[link.name] = (anchors[name], T_anchor_link)
    frames, segments, radii, names = [], [], [], []
    for link in robot.links if collisions else ():
        if link.name not in link_frames:
            continue
        frame, T_frame_link = link_frames[link.name]
        for collision in link.collisions:
            segment, radius = _collision_capsule(collision, link.name, path)
            T_link_shape = (
                np.eye(4) if collision.origin is None else np.asarray(collision.origin, float)
            )
            frames.append(frame)
            segments.append(transform_capsule(segment, T_frame_link @ T_link_shape))
            radii.append(radius)
            names.append(link.name)
    capsules = Capsules(
        np.array(frames, dtype=np.int64), np.array(segments), np.array(radii), tuple(names)
    )
    return URDFLinkGeometry(link_frames, capsules)


def _collision_capsule(collision: Any, link: str, path: str) -> tuple[np.ndarray, float]:
    """The enclosing capsule of one ``<collision>`` element, in its own frame."""
    geometry = collision.geometry
    where = f"link {link!r} <collision>"
    if geometry is None:
        raise CaseError(f"{where} has no geometry", file=path)
    if geometry.box is not None:
        size = np.asarray(geometry.box.size, dtype=float)
        _positive(size, f"{where} box size", path)
        return box_capsule(0.5 * size)
    if geometry.cylinder is not None:
        cylinder = geometry.cylinder
        _positive(
            np.array([cylinder.radius, cylinder.length]), f"{where} cylinder radius, length", path
        )
        return cylinder_capsule(float(cylinder.radius), float(cylinder.length))
    if geometry.sphere is not None:
        _positive(np.array([geometry.sphere.radius]), f"{where} sphere radius", path)
        return sphere_capsule(float(geometry.sphere.radius))
    if geometry.mesh is not None:
        return points_capsule(_mesh_vertices(geometry.mesh, where, path))
    raise CaseError(f"{where} has no box, cylinder, sphere or mesh", file=path)


def _positive(values: np.ndarray, what: str, path: str) -> None:
    if not np.all(np.isfinite(values)) or np.any(values <= 0):
        raise CaseError(f"{what} must be > 0 m, got {values.tolist()}", file=path)


def _mesh_vertices(mesh: Any, where: str, path: str) -> np.ndarray:
    """The scaled vertices of a collision mesh (package:// and relative names resolved)."""
    import trimesh
    import yourdfpy

    with _quiet("yourdfpy"):
        name = yourdfpy.filename_handler_magic(mesh.filename, dir=str(Path(path).parent))
    kind = file_kind(Path(name))
    if kind is not None:
        raise CaseError(
            f"{where} mesh {mesh.filename!r} {kind}: fix the file name, or give the links' "
            "capsules under collision: in a robot file pointing at the URDF, which reads no "
            "meshes (docs/robots.md)",
            file=path,
        )
    try:
        with warnings.catch_warnings(), np.errstate(all="ignore"), _quiet("trimesh"):
            warnings.simplefilter("ignore")
            loaded = trimesh.load(name, force="mesh")
        vertices = np.asarray(getattr(loaded, "vertices"), dtype=float).reshape(-1, 3)  # noqa: B009
    except Exception as exc:  # trimesh raises whatever its format readers meet
        reason = str(exc).splitlines()[0] if str(exc) else type(exc).__name__
        raise CaseError(
            f"{where} mesh {mesh.filename!r} cannot be read as a mesh: {reason}", file=path
        ) from None
    if len(vertices) == 0:
        raise CaseError(
            f"{where} mesh {mesh.filename!r} cannot be read as a mesh: no vertices found "
            "(expected STL, OBJ, PLY, …)",
            file=path,
        )
    scale = np.ones(3) if mesh.scale is None else np.asarray(mesh.scale, dtype=float)
    with np.errstate(over="ignore", invalid="ignore"):
        scaled = np.asarray(vertices * scale)
        extent = float(np.max(np.abs(scaled)))
    if not extent <= MAX_LENGTH:  # NaN too
        raise CaseError(
            f"{where} mesh {mesh.filename!r} has a vertex {extent:g} m from its origin once "
            f"scaled: vertices must lie within ±{MAX_LENGTH:g} m (check the mesh's units and "
            "scale)",
            file=path,
        )
    return scaled


class _Unreadable(Exception):
    """A visual that cannot be turned into a mesh."""


def read_urdf_visuals(
    file: str | Path,
    link_frames: dict[str, tuple[int, np.ndarray]],
    budget: int = MAX_TRIANGLES,
) -> tuple[LinkVisual, ...] | None:
    """The visual meshes of a URDF's links on the chain, decimated to ``budget`` triangles.

    Parameters
    ----------
    file
        Path of the URDF.
    link_frames
        Link name → (chain frame, ``T_frame_link``)
        (:attr:`~trackplan.io.urdf_geometry.URDFLinkGeometry.link_frames`).
    budget
        Most triangles in all.

    Returns
    -------
    tuple of LinkVisual or None
        None when the links on the chain have no ``<visual>``, or when one of them cannot
        be read (a missing or unreadable mesh file).
    """
    path = str(file)
    robot = load_urdf_model(path)
    colors = {
        material.name: _hex(material.color.rgba)
        for material in getattr(robot, "materials", None) or ()
        if material.name and material.color is not None
    }
    visuals: list[LinkVisual] = []
    for link in robot.links:
        if link.name not in link_frames:
            continue
        frame, T_frame_link = link_frames[link.name]
        for visual in link.visuals:
            try:
                vertices, faces = _visual_mesh(visual.geometry, path)
            except _Unreadable:
                return None
            T_link_visual = np.eye(4) if visual.origin is None else np.asarray(visual.origin)
            T = T_frame_link @ T_link_visual
            visuals.append(
                LinkVisual(
                    frame=frame,
                    vertices=vertices @ T[:3, :3].T + T[:3, 3],
                    faces=faces,
                    color=_color(visual.material, colors),
                    name=link.name,
                )
            )
    if not visuals:
        return None
    return decimate_visuals(tuple(visuals), budget)


def _hex(rgba: Any) -> str:
    """``#rrggbb`` of an RGBA in 0..1."""
    rgb = np.clip(np.asarray(rgba, dtype=float).ravel()[:3], 0.0, 1.0)
    if rgb.size != 3 or not np.all(np.isfinite(rgb)):
        return DEFAULT_COLOR
    return "#" + "".join(f"{round(255 * c):02x}" for c in rgb)


def _color(material: Any, named: dict[str, str]) -> str:
    if material is None:
        return DEFAULT_COLOR
    if material.color is not None:
        return _hex(material.color.rgba)
    return named.get(material.name or "", DEFAULT_COLOR)


def _visual_mesh(geometry: Any, path: str) -> tuple[np.ndarray, np.ndarray]:
    """Vertices (V, 3) in the visual's frame and triangles (T, 3) of one ``<visual>``."""
    import trimesh

    if geometry is None:
        raise _Unreadable
    if geometry.box is not None:
        shape = trimesh.creation.box(extents=np.asarray(geometry.box.size, dtype=float))
    elif geometry.cylinder is not None:
        c = geometry.cylinder
        shape = trimesh.creation.cylinder(radius=float(c.radius), height=float(c.length))
    elif geometry.sphere is not None:
        shape = trimesh.creation.icosphere(subdivisions=2, radius=float(geometry.sphere.radius))
    elif geometry.mesh is not None:
        return _mesh_file(geometry.mesh, path)
    else:
        raise _Unreadable
    return np.asarray(shape.vertices, float), np.asarray(shape.faces, np.int64)


def _mesh_file(mesh: Any, path: str) -> tuple[np.ndarray, np.ndarray]:
    """A visual mesh file's scaled vertices and triangles (read with trimesh)."""
    import trimesh
    import yourdfpy

    with _quiet("yourdfpy"):
        name = yourdfpy.filename_handler_magic(mesh.filename, dir=str(Path(path).parent))
    if file_kind(Path(name)) is not None:
        raise _Unreadable
    try:
        with warnings.catch_warnings(), np.errstate(all="ignore"), _quiet("trimesh"):
            warnings.simplefilter("ignore")
            loaded = trimesh.load(name, force="mesh")
        vertices = np.asarray(getattr(loaded, "vertices"), dtype=np.float64).reshape(-1, 3)  # noqa: B009
        faces = np.asarray(getattr(loaded, "faces"), dtype=np.int64).reshape(-1, 3)  # noqa: B009
    except Exception:  # trimesh raises whatever its format readers meet
        raise _Unreadable from None
    if len(faces) == 0:
        raise _Unreadable
    scale = np.ones(3) if mesh.scale is None else np.asarray(mesh.scale, dtype=np.float64)
    vertices = np.multiply(vertices, scale)
    if not np.all(np.isfinite(vertices)):
        raise _Unreadable
    return vertices, faces
