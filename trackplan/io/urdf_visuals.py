"""A URDF's ``<visual>`` elements as triangle meshes on the chain's frames.

:func:`read_urdf_visuals` reads each visual of the links on the chain (meshes in STL, OBJ,
DAE or any format trimesh reads, ``package://`` and relative names resolved as for
collision meshes; boxes, cylinders and spheres tessellated by trimesh), places it in the
chain frame its link moves with, takes its colour from the URDF's material (by the
visual's own ``<color>`` or a named top-level ``<material>``) and decimates the whole robot
to :data:`~trackplan.robots.visuals.MAX_TRIANGLES`. Visuals only change the report's
picture: when one of them is missing or cannot be read, the robot gets none (the report
draws its capsules) and the planning is unaffected.
"""

from __future__ import annotations

import warnings
from pathlib import Path
from typing import Any

import numpy as np

from trackplan.io.urdf import _quiet, file_kind, load_urdf_model
from trackplan.robots.visuals import (
    DEFAULT_COLOR,
    MAX_TRIANGLES,
    LinkVisual,
    decimate_visuals,
)


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
