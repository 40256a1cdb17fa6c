"""A mesh part (STL, OBJ, PLY, … read by trimesh) as a :class:`~trackplan.cad.part.PartModel`.

A mesh has no faces to name, so its faces are its *smooth regions*: the triangles connected
across edges whose dihedral angle (the angle between the two triangles' normals) is below the
feature angle (``part.feature_angle``, default 20°). Its edges are the *boundaries* between two
regions, and the open borders of an open mesh: each a chain of mesh edges ordered end to end
into a polyline (one edge per connected chain per pair of regions). Positions and normals are
as good as the tessellation: a boundary is the mesh's own polyline, and a region's normal at a
point is its vertex normals interpolated across the nearest triangle (``docs/cad.md``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from trackplan.cad.part import Circle, Edge, Face, Tessellation
from trackplan.errors import CaseError
from trackplan.io.urdf import file_kind

MESH_SUFFIXES = (".stl", ".obj", ".ply")
"""Mesh formats that carry no unit: ``part.scale`` is required for them."""
ROUND = 9
"""Decimals (of m, and of the area fraction) that ids are sorted on, so that ids do not
depend on the last bits of a sum."""


@dataclass(frozen=True, eq=False)
class MeshPart:
    """A part read from a mesh: regions as faces, their boundaries as edges.

    Build it with :func:`read_mesh_part`. ``region`` is the face id of every triangle.
    """

    source: str
    faces: tuple[Face, ...]
    edges: tuple[Edge, ...]
    vertices: np.ndarray
    triangles: np.ndarray
    region: np.ndarray
    corner_normals: np.ndarray
    polylines: tuple[np.ndarray, ...]
    feature_angle: float
    _cache: dict[int, Any] = field(default_factory=dict, repr=False)

    @property
    def exact(self) -> bool:
        """False: positions and normals are as good as the tessellation."""
        return False

    def _face(self, face: int) -> int:
        if not 1 <= int(face) <= len(self.faces) or int(face) != face:
            raise CaseError(
                f"face {face} does not exist: the part {self.source!r} has faces 1 to "
                f"{len(self.faces)} (`trackplan part FILE` lists them)"
            )
        return int(face)

    def _edge(self, edge: int) -> int:
        if not 1 <= int(edge) <= len(self.edges) or int(edge) != edge:
            raise CaseError(
                f"edge {edge} does not exist: the part {self.source!r} has edges 1 to "
                f"{len(self.edges)} (`trackplan part FILE` lists them)"
            )
        return int(edge)

    def edge_points(self, edge: int, max_chord_error: float) -> np.ndarray:
        """The boundary's polyline from its start to its end, shape (K, 3), m (the start
        repeated at the end when it is closed). ``max_chord_error`` is not used: the polyline
        is the mesh's own, its error from the true seam is the tessellation's."""
        return self.polylines[self._edge(edge) - 1].copy()

    def edge_circle(self, edge: int) -> Circle | None:
        """None: a mesh boundary is a polyline, never an exact circle."""
        self._edge(edge)
        return None

    def _region_mesh(self, face: int) -> Any:
        """The region's triangles as a trimesh (cached), and their indices in the part."""
        hit = self._cache.get(face)
        if hit is None:
            import trimesh

            index = np.flatnonzero(self.region == face)
            sub = trimesh.Trimesh(self.vertices, self.triangles[index], process=False)
            hit = (sub, index)
            self._cache[face] = hit
        return hit

    def face_normals(self, face: int, points: np.ndarray) -> np.ndarray:
        """The region's outward unit normal at the points of it nearest ``points`` (M, 3):
        the region's own vertex normals (angle-weighted over the region's triangles only, so
        a boundary vertex has each region's normal on its side) interpolated barycentrically
        across the region's triangle nearest each point. Shape (M, 3)."""
        import trimesh

        sub, index = self._region_mesh(self._face(face))
        pts = np.atleast_2d(np.asarray(points, dtype=float)).reshape(-1, 3)
        if len(pts) == 0:
            return np.zeros((0, 3))
        closest, _, tri = trimesh.proximity.closest_point(sub, pts)
        tri = np.asarray(tri, dtype=np.int64)
        bary = trimesh.triangles.points_to_barycentric(sub.triangles[tri], closest)
        bary = np.clip(bary, 0.0, None)
        bary /= bary.sum(axis=1, keepdims=True)
        normals = np.einsum("mk,mkj->mj", bary, self.corner_normals[index[tri]])
        length = np.linalg.norm(normals, axis=1, keepdims=True)
        fallback = sub.face_normals[tri]
        ok = length[:, 0] > 1e-12
        normals[ok] /= length[ok]
        normals[~ok] = fallback[~ok]
        return np.asarray(normals)

    def nearest_face(self, point: np.ndarray) -> tuple[int, float]:
        """The region nearest a point (3,), and its distance, m."""
        import trimesh

        whole = self._cache.get(0)
        if whole is None:
            whole = trimesh.Trimesh(self.vertices, self.triangles, process=False)
            self._cache[0] = whole
        _, distance, tri = trimesh.proximity.closest_point(
            whole, np.asarray(point, dtype=float).reshape(1, 3)
        )
        return int(self.region[int(tri[0])]), float(distance[0])

    def shared_edges(self, a: int, b: int) -> tuple[int, ...]:
        """The boundaries between regions a and b, by id (none when they do not meet)."""
        pair = {self._face(a), self._face(b)}
        if len(pair) == 1:
            return ()
        return tuple(e.id for e in self.edges if set(e.faces) == pair)

    def tessellation(self, chord_error: float) -> Tessellation:
        """The mesh itself (chord error 0: it is its own surface), ``face`` the region ids."""
        return Tessellation(self.vertices.copy(), self.triangles.copy(), 0.0, self.region.copy())


def read_mesh_part(
    path: str | Path,
    *,
    scale: float | None = None,
    feature_angle: float = math.radians(20.0),
    case_file: str | None = None,
) -> MeshPart:
    """Read a mesh file into a :class:`MeshPart`.

    Parameters
    ----------
    path
        The mesh file (STL, OBJ, PLY, or any mesh trimesh reads).
    scale
        File units to metres. Required for STL, OBJ and PLY, which carry no unit; for a
        format trimesh reads a unit from, None converts that unit.
    feature_angle
        rad, in (0, π): triangles whose normals differ by less across an edge are one region.
    case_file
        The case file, for the error's location.

    Raises
    ------
    CaseError
        A missing or unreadable file, no triangles, a missing or bad scale or feature angle,
        an edge shared by more than two triangles, or a surface that cannot be oriented.
    """
    file = Path(path)

    def refuse(message: str, key: str = "part.file") -> CaseError:
        return CaseError(message, file=case_file, key=key)

    if not (math.isfinite(feature_angle) and 0.0 < feature_angle < math.pi):
        raise refuse(
            f"feature angle must lie in (0, π) rad, got {feature_angle:g} rad "
            f"(the default is {math.radians(20.0):.4f} rad, 20°)",
            "part.feature_angle",
        )
    if scale is not None and not (math.isfinite(scale) and scale > 0.0):
        raise refuse(f"scale must be > 0 (file units to metres), got {scale:g}", "part.scale")
    no_unit = refuse(
        f"mesh file {str(file)!r} carries no unit: set part.scale, its units in metres "
        "(0.001 for millimetres, 1 for metres)",
        "part.scale",
    )
    if scale is None and file.suffix.lower() in MESH_SUFFIXES:
        raise no_unit
    mesh = _load(file, refuse)
    if scale is None:
        import trimesh

        try:
            scale = float(trimesh.units.unit_conversion(mesh.units, "meters"))
        except Exception:
            raise no_unit from None
    vertices = np.asarray(mesh.vertices, dtype=float) * scale
    triangles = np.asarray(mesh.faces, dtype=np.int64)
    return _build(str(file), mesh, vertices, triangles, feature_angle)


def _load(file: Path, refuse: Any) -> Any:
    """The cleaned trimesh of a file: duplicate vertices merged, degenerate and repeated
    triangles dropped, winding made consistent and outward."""
    import trimesh

    kind = file_kind(file)
    if kind is not None:
        raise refuse(f"mesh file {str(file)!r} {kind}")
    try:
        loaded = trimesh.load(str(file), force="mesh", process=False)
    except Exception as exc:
        reason = str(exc).splitlines()[0] if str(exc) else type(exc).__name__
        raise refuse(f"mesh file {str(file)!r} cannot be read as a mesh: {reason}") from None
    faces = np.asarray(getattr(loaded, "faces", np.zeros((0, 3))), dtype=np.int64)
    if faces.ndim != 2 or faces.shape[1] != 3 or len(faces) == 0:
        raise refuse(
            f"mesh file {str(file)!r} holds no triangles (expected a mesh: STL, OBJ, PLY, …)"
        )
    vertices = np.asarray(getattr(loaded, "vertices"), dtype=float)  # noqa: B009
    mesh = trimesh.Trimesh(vertices, faces, process=True)
    mesh.units = getattr(loaded, "units", None)  # type: ignore[assignment]
    mesh.update_faces(mesh.nondegenerate_faces())
    mesh.update_faces(mesh.unique_faces())
    mesh.remove_unreferenced_vertices()
    if len(mesh.faces) == 0:
        raise refuse(f"mesh file {str(file)!r} holds only degenerate triangles")
    counts = np.bincount(mesh.edges_unique_inverse)
    bad = np.flatnonzero(counts > 2)
    if len(bad):
        where = mesh.vertices[mesh.edges_unique[bad[0]]].mean(axis=0)
        raise refuse(
            f"mesh file {str(file)!r} is not a manifold: edges shared by more than two "
            f"triangles: {len(bad)} (the first near {np.array2string(where, precision=4)} in "
            "file units); export the part as one closed or open surface"
        )
    trimesh.repair.fix_normals(mesh, multibody=True)
    if not mesh.is_winding_consistent:
        raise refuse(
            f"mesh file {str(file)!r} cannot be oriented (its triangles cannot all face one "
            "side); export the part as an orientable surface"
        )
    return mesh


def _build(
    source: str, mesh: Any, vertices: np.ndarray, triangles: np.ndarray, feature_angle: float
) -> MeshPart:
    """Regions, boundaries and the region-wise vertex normals of a cleaned mesh."""
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    T = len(triangles)
    adjacency = np.asarray(mesh.face_adjacency, dtype=np.int64).reshape(-1, 2)
    smooth = adjacency[np.asarray(mesh.face_adjacency_angles) < feature_angle]
    graph = coo_matrix((np.ones(len(smooth)), (smooth[:, 0], smooth[:, 1])), shape=(T, T))
    n, labels = connected_components(graph, directed=False)

    corners = vertices[triangles]  # (T, 3, 3)
    cross = np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0])
    double_area = np.linalg.norm(cross, axis=1)
    unit = cross / np.maximum(double_area, 1e-300)[:, None]
    area = 0.5 * double_area
    region_area = np.bincount(labels, weights=area, minlength=n)
    centroid = (
        np.stack(
            [
                np.bincount(labels, weights=area * corners[:, :, k].mean(axis=1), minlength=n)
                for k in range(3)
            ],
            axis=1,
        )
        / np.maximum(region_area, 1e-300)[:, None]
    )
    normal_sum = np.stack(
        [np.bincount(labels, weights=area * unit[:, k], minlength=n) for k in range(3)], axis=1
    )
    order = np.lexsort(
        (
            np.round(centroid[:, 2], ROUND),
            np.round(centroid[:, 1], ROUND),
            np.round(centroid[:, 0], ROUND),
            -np.round(region_area / region_area.sum(), ROUND),
        )
    )
    ident = np.empty(n, dtype=np.int64)
    ident[order] = np.arange(1, n + 1)
    region = ident[labels]
    faces = []
    for k, old in enumerate(order):
        mean = normal_sum[old]
        size = float(np.linalg.norm(mean))
        faces.append(
            Face(
                id=k + 1,
                kind="region",
                area=float(region_area[old]),
                centroid=centroid[old].copy(),
                normal=mean / size if size > 1e-6 * region_area[old] else None,
            )
        )

    corner_normals = _corner_normals(triangles, region, np.asarray(mesh.face_angles), unit)
    edges, polylines = _boundaries(vertices, triangles, region, mesh)
    return MeshPart(
        source=source,
        faces=tuple(faces),
        edges=edges,
        vertices=vertices,
        triangles=triangles,
        region=region,
        corner_normals=corner_normals,
        polylines=polylines,
        feature_angle=feature_angle,
    )


def _corner_normals(
    triangles: np.ndarray, region: np.ndarray, angles: np.ndarray, unit: np.ndarray
) -> np.ndarray:
    """The unit normal at every triangle corner, shape (T, 3, 3): the angle-weighted mean of
    the normals of the triangles of the same region round that vertex."""
    key = (region[:, None] * (triangles.max() + 1) + triangles).ravel()
    uniq, inverse = np.unique(key, return_inverse=True)
    weighted = (angles[:, :, None] * unit[:, None, :]).reshape(-1, 3)
    total = np.zeros((len(uniq), 3))
    np.add.at(total, inverse, weighted)
    total /= np.maximum(np.linalg.norm(total, axis=1, keepdims=True), 1e-300)
    return total[inverse].reshape(-1, 3, 3)


def _boundaries(
    vertices: np.ndarray, triangles: np.ndarray, region: np.ndarray, mesh: Any
) -> tuple[tuple[Edge, ...], tuple[np.ndarray, ...]]:
    """The boundaries: mesh edges between two regions (or on an open border), grouped by
    their pair of regions and chained end to end, each chain running the way the triangles
    of its lower-id region wind (so that region lies on its left, seen from outside)."""
    directed = np.asarray(mesh.edges, dtype=np.int64)  # (3T, 2) in triangle order
    owner = region[np.asarray(mesh.edges_face, dtype=np.int64)]
    unique = np.asarray(mesh.edges_unique_inverse, dtype=np.int64)
    order = np.lexsort((owner, unique))  # per unique edge: the lower region first
    unique_sorted = unique[order]
    first = np.ones(len(order), dtype=bool)
    first[1:] = unique_sorted[1:] != unique_sorted[:-1]
    starts = np.flatnonzero(first)
    count = np.diff(np.append(starts, len(order)))
    low = owner[order[starts]]
    high = np.where(count == 2, owner[order[np.minimum(starts + 1, len(order) - 1)]], 0)
    keep = (count == 1) | (high != low)
    chosen = order[starts[keep]]
    pairs = np.stack([low[keep], high[keep]], axis=1)
    segs = directed[chosen]

    chains: list[tuple[tuple[int, ...], np.ndarray]] = []
    group = np.lexsort((pairs[:, 1], pairs[:, 0]))
    pairs, segs = pairs[group], segs[group]
    cut = np.flatnonzero(np.any(np.diff(pairs, axis=0) != 0, axis=1)) + 1
    for block, seg in zip(np.split(pairs, cut), np.split(segs, cut), strict=True):
        if len(seg) == 0:
            continue
        a, b = int(block[0, 0]), int(block[0, 1])
        pair: tuple[int, ...] = (a, b) if b else (a,)
        for path in _chain(seg, vertices):
            chains.append((pair, path))

    def sort_key(item: tuple[tuple[int, ...], np.ndarray]) -> tuple[Any, ...]:
        faces, path = item
        start = np.round(vertices[path[0]], ROUND)
        return (faces[0], faces[1] if len(faces) > 1 else 0, *start.tolist())

    chains.sort(key=sort_key)
    edges = []
    polylines = []
    for k, (faces, path) in enumerate(chains):
        points = vertices[path]
        polylines.append(points)
        edges.append(
            Edge(
                id=k + 1,
                kind="boundary",
                length=float(np.linalg.norm(np.diff(points, axis=0), axis=1).sum()),
                start=points[0].copy(),
                end=points[-1].copy(),
                faces=faces,
            )
        )
    return tuple(edges), tuple(polylines)


def _chain(seg: np.ndarray, vertices: np.ndarray) -> list[np.ndarray]:
    """Directed segments (S, 2) split into paths of vertex indices, each end to end: open
    paths from a vertex where the chain ends or branches, then closed loops (the first vertex
    repeated at the end), each loop started at its lexicographically smallest vertex."""
    outgoing: dict[int, list[int]] = {}
    indegree: dict[int, int] = {}
    for i, (u, v) in enumerate(seg.tolist()):
        outgoing.setdefault(u, []).append(i)
        indegree[v] = indegree.get(v, 0) + 1
    used = np.zeros(len(seg), dtype=bool)

    def through(v: int) -> bool:
        return indegree.get(v, 0) == 1 and len(outgoing.get(v, ())) == 1

    def walk(i: int) -> list[int]:
        path = [int(seg[i, 0])]
        while True:
            used[i] = True
            v = int(seg[i, 1])
            path.append(v)
            if not through(v):
                return path
            i = outgoing[v][0]
            if used[i]:
                return path

    paths = []
    ends = sorted((u for u in outgoing if not through(u)), key=lambda u: tuple(vertices[u]))
    for u in ends:
        for i in outgoing[u]:
            if not used[i]:
                paths.append(np.asarray(walk(i)))
    while not used.all():
        loop = np.asarray(walk(int(np.flatnonzero(~used)[0])))[:-1]
        first = int(np.lexsort(vertices[loop][:, ::-1].T)[0])
        loop = np.roll(loop, -first)
        paths.append(np.append(loop, loop[0]))
    return paths
