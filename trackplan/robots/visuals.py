"""How a robot looks: triangle meshes on the chain's frames, and their decimation.

A robot read from a URDF with ``<visual>`` elements carries them as
:attr:`trackplan.robots.model.Robot.visuals`: one :class:`LinkVisual` per element, its
vertices in the chain frame it moves with (numbered as the link capsules are, see
:func:`trackplan.robots.kinematics.joint_frames`), its triangles and its colour. They are
drawn in the report's 3D view and never checked for collisions (the capsules are).

Meshes are decimated to a triangle budget by :func:`decimate`: trimesh's quadric
decimation when the optional ``fast_simplification`` package is installed, else vertex
clustering (the vertices in each cell of a grid merged into their mean, the
triangles that collapse and repeated ones dropped with trimesh; the finest grid that meets
the budget), which needs nothing beyond trimesh and numpy.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

MAX_TRIANGLES = 20_000
"""Most triangles a robot's visuals keep in all (they are decimated on reading)."""
DEFAULT_COLOR = "#a8b4c4"
"""Colour of a visual whose URDF gives no material colour."""


@dataclass(frozen=True, eq=False)
class LinkVisual:
    """One visual mesh of a robot link.

    Attributes
    ----------
    frame
        Index of the chain frame the mesh moves with: 0 the base, i the link of joint i.
    vertices
        Shape (V, 3), m, in that frame.
    faces
        Triangles, shape (T, 3), int indices into ``vertices``.
    color
        ``#rrggbb``.
    name
        The link's name.
    """

    frame: int
    vertices: np.ndarray
    faces: np.ndarray
    color: str = DEFAULT_COLOR
    name: str = ""

    def __post_init__(self) -> None:
        vertices = np.array(self.vertices, dtype=float).reshape(-1, 3)
        faces = np.array(self.faces, dtype=np.int64).reshape(-1, 3)
        if len(faces) and (faces.min() < 0 or faces.max() >= len(vertices)):
            raise ValueError(f"visual of {self.name!r}: a triangle indexes a missing vertex")
        vertices.flags.writeable = False
        faces.flags.writeable = False
        object.__setattr__(self, "vertices", vertices)
        object.__setattr__(self, "faces", faces)
        object.__setattr__(self, "frame", int(self.frame))

    @property
    def n_triangles(self) -> int:
        """Number of triangles."""
        return len(self.faces)


def n_triangles(visuals: tuple[LinkVisual, ...]) -> int:
    """Triangles of all visuals."""
    return sum(visual.n_triangles for visual in visuals)


def decimate(
    vertices: np.ndarray, faces: np.ndarray, target: int, *, quadric: bool | None = None
) -> tuple[np.ndarray, np.ndarray]:
    """A mesh with at most ``target`` triangles (unchanged when it has no more).

    Parameters
    ----------
    vertices, faces
        The mesh: (V, 3) m, (T, 3) int.
    target
        Most triangles kept (≥ 4).
    quadric
        Use trimesh's quadric decimation (needs ``fast_simplification``); None: when it is
        installed, else vertex clustering.

    Returns
    -------
    vertices, faces
        The decimated mesh, unused vertices removed.
    """
    import trimesh

    target = max(4, int(target))
    faces = np.asarray(faces, dtype=np.int64).reshape(-1, 3)
    if len(faces) <= target:
        return np.asarray(vertices, dtype=float), faces
    mesh = trimesh.Trimesh(vertices, faces, process=False)
    if quadric is None:
        quadric = _has_fast_simplification()
    if quadric:
        simplified = mesh.simplify_quadric_decimation(face_count=target)
        if 0 < len(simplified.faces) <= target:
            return np.asarray(simplified.vertices, float), np.asarray(simplified.faces, np.int64)
    return _cluster(mesh, target)


def _has_fast_simplification() -> bool:
    try:
        import fast_simplification  # noqa: F401
    except ImportError:
        return False
    return True


def _cluster(mesh: object, target: int) -> tuple[np.ndarray, np.ndarray]:
    """Vertex clustering: the finest grid (found by bisection on the cell size) whose merged
    mesh has at most ``target`` triangles."""
    import trimesh

    assert isinstance(mesh, trimesh.Trimesh)
    vertices = np.asarray(mesh.vertices)
    extent = float(np.max(np.ptp(vertices, axis=0))) or 1.0
    low, high = 0.0, extent  # cell sizes: too fine, coarse enough
    best = _clustered(mesh, high)
    for _ in range(24):
        cell = 0.5 * (low + high)
        candidate = _clustered(mesh, cell)
        if len(candidate[1]) <= target:
            high, best = cell, candidate
        else:
            low = cell
        if high - low < 1e-4 * extent:
            break
    return best


def _clustered(mesh: object, cell: float) -> tuple[np.ndarray, np.ndarray]:
    """The mesh with the vertices in each grid cell of side ``cell`` merged into their mean."""
    import trimesh

    assert isinstance(mesh, trimesh.Trimesh)
    vertices = np.asarray(mesh.vertices)
    keys = np.floor(vertices / cell).astype(np.int64)
    _, inverse = np.unique(keys, axis=0, return_inverse=True)
    inverse = inverse.reshape(-1)
    count = np.bincount(inverse)
    merged = (
        np.stack([np.bincount(inverse, weights=vertices[:, axis]) for axis in range(3)], axis=1)
        / count[:, None]
    )
    clustered = trimesh.Trimesh(merged, inverse[np.asarray(mesh.faces)], process=False)
    clustered.update_faces(clustered.nondegenerate_faces())
    clustered.update_faces(clustered.unique_faces())
    clustered.remove_unreferenced_vertices()
    return np.asarray(clustered.vertices, float), np.asarray(clustered.faces, np.int64)


def decimate_visuals(
    visuals: tuple[LinkVisual, ...], budget: int, *, quadric: bool | None = None
) -> tuple[LinkVisual, ...]:
    """The visuals with at most ``budget`` triangles in all, each decimated to its share
    (its triangles' fraction of the total).

    Parameters
    ----------
    visuals
        The robot's visuals.
    budget
        Most triangles in all.
    quadric
        As :func:`decimate`.
    """
    total = n_triangles(visuals)
    if total <= budget:
        return visuals
    out = []
    for visual in visuals:
        share = max(4, int(budget * visual.n_triangles / total))
        vertices, faces = decimate(visual.vertices, visual.faces, share, quadric=quadric)
        out.append(replace(visual, vertices=vertices, faces=faces))
    kept = tuple(out)
    if n_triangles(kept) > budget:  # the floor of 4 per visual: drop the smallest
        kept = tuple(sorted(kept, key=lambda v: -v.n_triangles))
        while kept and n_triangles(kept) > budget:
            kept = kept[:-1]
    return kept
