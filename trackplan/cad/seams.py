"""Seams derived from a part's CAD model: segments and weld normals along chained edges.

:func:`derive_seam` turns a ``cad:`` seam (:class:`CadSeam`: the edges two faces share, or
edges by id) into the path's start point and segments, exact where the CAD is exact:

- a line edge is a :class:`~trackplan.paths.specs.LineSpec` (without weld normals) or, with
  its constant weld normal, a :class:`~trackplan.paths.specs.PointsSpec` through its midpoint
  and end point with that normal at both (the existing per-point normals of a points
  segment: a straight line, the normal constant on it);
- a circular edge is an :class:`~trackplan.paths.specs.ArcSpec` (centre, axis and angle from
  the CAD) whose ``weld_normal`` is the normal at its start, carried round the axis; the
  derived normals along the edge are checked against that rotation (within
  :data:`ARC_NORMAL_ANGLE`), else the edge is sampled like any curve;
- any other edge is a :class:`~trackplan.paths.specs.PointsSpec` sampled with a chord error
  of at most a tenth of the tolerance, with the weld normal at every point.

Weld normals: ``fillet`` the bisector of the two faces' outward normals at each point of the
edge, ``face`` the named face's outward normal. Problems raise :class:`SeamError` with the key
(under the ``cad:`` block) it belongs to.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from trackplan.cad.part import Circle, Edge, PartModel
from trackplan.paths.specs import ArcSpec, LineSpec, PointsSpec, SegmentSpec

NEAR_DISTANCE = 0.005
"""Largest distance of a ``near`` point from the face it names, m (5 mm)."""
CHAIN_GAP = 1e-6
"""Largest distance between the ends of two edges that chain, m (a micrometre)."""
ARC_NORMAL_ANGLE = np.radians(0.01)
"""Largest angle between a circular edge's derived normals and its start normal carried
round the axis for the edge to stay an exact arc with ``weld_normal``, rad (0.01°)."""
ARC_CHECK_POINTS = 16
"""Points along a circular edge at which that check is made."""
CHORD_FRACTION = 0.1
"""Chord error of a sampled edge as a fraction of the tolerance."""
JOINTS = ("fillet", "face")


class SeamError(ValueError):
    """A ``cad:`` seam that cannot be derived: ``where`` is its key under the ``cad:`` block
    (``("between", 0, "near")``), ``message`` what is wrong and how to fix it."""

    def __init__(self, where: tuple[str | int, ...], message: str) -> None:
        super().__init__(message)
        self.where = where
        self.message = message


@dataclass(frozen=True, eq=False)
class FaceRef:
    """A face by id (``face``) or by a point near it (``near``, shape (3,), m)."""

    face: int | None = None
    near: np.ndarray | None = None


@dataclass(frozen=True, eq=False)
class CadSeam:
    """A ``cad:`` seam.

    Attributes
    ----------
    between
        Two faces whose shared edges are the seam, or None.
    edges
        Edge ids chained end to end, or None (exactly one of ``between``, ``edges``).
    joint
        ``fillet`` (bisector of the two faces' normals) or ``face`` (the first face's
        normal); only with ``between`` (None: fillet, unless ``normal`` is given).
    normal
        The faces whose normals are the weld normal: one face (its normal) or two (their
        bisector); None: from ``joint`` (``between``) or no weld normals (``edges``).
    reverse
        Travel the chain the other way.
    """

    between: tuple[FaceRef, FaceRef] | None = None
    edges: tuple[int, ...] | None = None
    joint: str | None = None
    normal: tuple[FaceRef, ...] | None = None
    reverse: bool = False


def derive_seam(
    part: PartModel, spec: CadSeam, tolerance: float
) -> tuple[np.ndarray, tuple[SegmentSpec, ...]]:
    """The start point (3,) and segments of a ``cad:`` seam on ``part``.

    Parameters
    ----------
    part
        The part's model.
    spec
        The seam.
    tolerance
        The task's path tolerance, m: sampled edges keep within a tenth of it.

    Returns
    -------
    start, segments
        A closed chain ends where it starts.

    Raises
    ------
    SeamError
        A face or edge that does not exist, a ``near`` point farther than
        :data:`NEAR_DISTANCE` from every face, two faces that share no edge, a chain with a
        gap or a branch, faces whose normals cancel.
    """
    faces: tuple[int, ...] = ()
    all_edges = part.edges
    if spec.between is not None:
        faces = tuple(_face(part, ref, ("between", i)) for i, ref in enumerate(spec.between))
        if faces[0] == faces[1]:
            raise SeamError(("between",), f"both name face {faces[0]}: name two faces")
        ids = part.shared_edges(*faces)
        if not ids:
            raise SeamError(
                ("between",),
                f"faces {faces[0]} and {faces[1]} share no edge; `trackplan part "
                f"{part.source}` lists the faces each edge joins",
            )
        at: tuple[str | int, ...] = ("between",)
    else:
        assert spec.edges is not None
        ids = tuple(spec.edges)
        for k, edge in enumerate(ids):
            if not 1 <= edge <= len(all_edges):
                raise SeamError(
                    ("edges", k),
                    f"edge {edge} does not exist (the part has {len(all_edges)} edges: "
                    f"trackplan part {part.source} lists them)",
                )
        if len(set(ids)) < len(ids):
            raise SeamError(("edges",), "an edge is named twice; name each edge once")
        at = ("edges",)
    normal_faces = _normal_faces(part, spec, faces)
    chain = chain_edges([all_edges[i - 1] for i in ids], at)
    if spec.reverse:
        chain = [(edge, not forward) for edge, forward in reversed(chain)]
    first, forward = chain[0]
    start = np.array(first.start if forward else first.end, dtype=float)
    segments = tuple(
        _segment(part, edge, forward, normal_faces, tolerance) for edge, forward in chain
    )
    return start, segments


def _face(part: PartModel, ref: FaceRef, where: tuple[str | int, ...]) -> int:
    """The id of a face reference, checked."""
    count = len(part.faces)
    if ref.face is not None:
        if not 1 <= ref.face <= count:
            raise SeamError(
                (*where, "face"),
                f"face {ref.face} does not exist (the part has {count} faces: "
                f"trackplan part {part.source} lists them)",
            )
        return ref.face
    assert ref.near is not None
    face, distance = part.nearest_face(np.asarray(ref.near, dtype=float))
    if not distance <= NEAR_DISTANCE:
        raise SeamError(
            (*where, "near"),
            f"the nearest face ({face}) is {distance * 1000:.3g} mm away, more than "
            f"{NEAR_DISTANCE * 1000:g} mm: give a point on the face (m, in the part's frame)",
        )
    return face


def _normal_faces(part: PartModel, spec: CadSeam, faces: tuple[int, ...]) -> tuple[int, ...]:
    """The faces whose normals make the weld normal: one (its normal), two (their
    bisector) or none (no weld normals)."""
    if spec.normal is not None:
        return tuple(
            _face(part, ref, ("normal",) if len(spec.normal) == 1 else ("normal", "between", i))
            for i, ref in enumerate(spec.normal)
        )
    if spec.between is None:
        return ()
    return faces[:1] if spec.joint == "face" else faces


def chain_edges(
    edges: list[Edge], at: tuple[str | int, ...] = ("edges",)
) -> list[tuple[Edge, bool]]:
    """Edges ordered end to end, each with whether it runs in its own direction.

    An open chain runs so that the first edge given runs in its own direction; a closed
    chain starts at the first edge's start. Ends within :data:`CHAIN_GAP` meet.

    Raises
    ------
    SeamError
        A branch (three or more ends at one point, or a closed edge among others) or a gap
        (edges that do not all connect), at ``at``.
    """
    if len(edges) == 1:
        return [(edges[0], True)]
    ends = np.array([[edge.start, edge.end] for edge in edges], dtype=float).reshape(-1, 3)
    node = _cluster(ends)
    for edge, (a, b) in zip(edges, node.reshape(-1, 2), strict=True):
        if a == b:
            raise SeamError(at, f"edge {edge.id} is closed: it makes a seam on its own")
    degree = np.bincount(node)
    if degree.max() > 2:
        branch = int(np.argmax(degree))
        where = ends[int(np.flatnonzero(node == branch)[0])]
        pairs = node.reshape(-1, 2)
        meeting = [edge.id for edge, pair in zip(edges, pairs, strict=True) if branch in pair]
        raise SeamError(
            at,
            f"edges {', '.join(map(str, meeting))} meet at one point "
            f"{np.round(where, 6).tolist()} m: a branch; name the edges of one seam "
            "(edges: [...])",
        )
    pairs = node.reshape(-1, 2)
    open_ends = np.flatnonzero(degree == 1)
    touching: dict[int, list[int]] = {}
    for k, (a, b) in enumerate(pairs.tolist()):
        touching.setdefault(a, []).append(k)
        touching.setdefault(b, []).append(k)
    # walk from the first edge forwards, then prepend backwards from its start
    chain: list[tuple[Edge, bool]] = [(edges[0], True)]
    used = {0}
    for direction in (1, 0):
        current = int(pairs[0, direction])
        while True:
            nxt = [k for k in touching[current] if k not in used]
            if not nxt:
                break
            k = nxt[0]
            used.add(k)
            leaves_at_start = int(pairs[k, 0]) == current
            if direction == 1:
                chain.append((edges[k], leaves_at_start))
                current = int(pairs[k, 1 if leaves_at_start else 0])
            else:  # before the chain: runs into the current node
                chain.insert(0, (edges[k], not leaves_at_start))
                current = int(pairs[k, 0 if not leaves_at_start else 1])
    if len(used) < len(edges):
        apart = [k for k in range(len(edges)) if k not in used]
        gap = _nearest_gap(ends, [k for k in used], apart)
        raise SeamError(
            at,
            f"the edges do not chain: edge {edges[apart[0]].id} is {gap * 1000:.3g} mm from "
            f"the chain of edge {edges[0].id} (ends meet within {CHAIN_GAP:g} m): a gap; "
            "name edges that meet end to end",
        )
    if len(open_ends) == 0:  # closed: start at the first edge's start
        k = next(i for i, (edge, _) in enumerate(chain) if edge is edges[0])
        chain = chain[k:] + chain[:k]
    return chain


def _cluster(points: np.ndarray) -> np.ndarray:
    """A node number per point: points within :data:`CHAIN_GAP` share one."""
    # imported here: a case without cad: seams never needs scipy's spatial module
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components
    from scipy.spatial import cKDTree

    pairs = cKDTree(points).query_pairs(CHAIN_GAP, output_type="ndarray")
    graph = coo_matrix(
        (np.ones(len(pairs)), (pairs[:, 0], pairs[:, 1])), shape=(len(points), len(points))
    )
    return np.asarray(connected_components(graph, directed=False)[1], dtype=int)


def _nearest_gap(ends: np.ndarray, chained: list[int], apart: list[int]) -> float:
    """The least distance between an end of the chained edges and one of the others, m."""
    a = ends.reshape(-1, 2, 3)[chained].reshape(-1, 3)
    b = ends.reshape(-1, 2, 3)[apart].reshape(-1, 3)
    return float(np.linalg.norm(a[:, None] - b[None], axis=2).min())


def weld_normals(part: PartModel, faces: tuple[int, ...], points: np.ndarray) -> np.ndarray:
    """Unit weld normals at points (M, 3) of an edge: one face's outward normal, or the
    bisector of two faces' outward normals, shape (M, 3).

    Raises
    ------
    SeamError
        Two faces whose normals cancel (no bisector).
    """
    total = sum(part.face_normals(face, points) for face in faces)
    norm = np.linalg.norm(total, axis=1, keepdims=True)
    if not np.all(norm > 1e-6):
        raise SeamError(
            ("joint",),
            f"faces {faces[0]} and {faces[1]} have opposite normals on the seam: no fillet "
            "bisector; use joint: face or normal: {face: ID}",
        )
    return np.asarray(total / norm, dtype=float)


def _segment(
    part: PartModel, edge: Edge, forward: bool, faces: tuple[int, ...], tolerance: float
) -> SegmentSpec:
    """One edge's segment, in its direction along the chain."""
    begin, end = (edge.start, edge.end) if forward else (edge.end, edge.start)
    begin, end = np.asarray(begin, dtype=float), np.asarray(end, dtype=float)
    if edge.kind == "line":
        if not faces:
            return LineSpec(to=end.copy())
        middle = 0.5 * (begin + end)
        normals = weld_normals(part, faces, np.vstack([middle, end]))
        constant = np.repeat(weld_normals(part, faces, middle[None]), 2, axis=0)
        if np.allclose(normals, constant, atol=1e-9):
            return PointsSpec(points=np.vstack([middle, end]), normals=constant)
        return _sampled(part, edge, forward, faces, tolerance)
    circle = part.edge_circle(edge.id) if edge.kind == "circle" else None
    axis = None if circle is None else _edge_axis(part, edge, circle, tolerance)
    if circle is not None and axis is not None:
        angle = circle.angle if forward else -circle.angle
        arc = ArcSpec(np.asarray(circle.center, dtype=float), axis, angle)
        if not faces:
            return arc
        weld = weld_normals(part, faces, begin[None])[0]
        if _turns_with_arc(part, edge, forward, faces, arc, weld, begin):
            return ArcSpec(arc.center, arc.normal, arc.angle, weld)
    return _sampled(part, edge, forward, faces, tolerance)


def _edge_axis(part: PartModel, edge: Edge, circle: Circle, tolerance: float) -> np.ndarray | None:
    """The circle's unit axis in the sense its edge turns (the edge's own points decide), or
    None when those points leave the circle by more than a tenth of the tolerance."""
    points = np.asarray(part.edge_points(edge.id, CHORD_FRACTION * tolerance), dtype=float)
    axis = np.asarray(circle.axis, dtype=float)
    axis = axis / np.linalg.norm(axis)
    offset = points - np.asarray(circle.center, dtype=float)
    height = offset @ axis
    radial = offset - np.outer(height, axis)
    off = np.abs(np.linalg.norm(radial, axis=1) - circle.radius).max() + np.abs(height).max()
    if len(points) < 2 or not off <= CHORD_FRACTION * tolerance + 1e-9:
        return None
    e_r = radial[0] / np.linalg.norm(radial[0])
    turn = float(np.arctan2(radial[1] @ np.cross(axis, e_r), radial[1] @ e_r))
    return axis if turn >= 0.0 else -axis


def _sampled(
    part: PartModel, edge: Edge, forward: bool, faces: tuple[int, ...], tolerance: float
) -> PointsSpec:
    """An edge as points within a tenth of the tolerance, with weld normals if any."""
    points = np.asarray(part.edge_points(edge.id, CHORD_FRACTION * tolerance), dtype=float)
    if not forward:
        points = points[::-1]
    if len(points) == 2:  # a straight piece: its midpoint, so that two points follow
        points = np.vstack([points[0], 0.5 * (points[0] + points[1]), points[1]])
    if not faces:
        return PointsSpec(points=points[1:].copy())
    normals = weld_normals(part, faces, points)
    return PointsSpec(points=points[1:].copy(), normals=normals[1:].copy())


def _turns_with_arc(
    part: PartModel,
    edge: Edge,
    forward: bool,
    faces: tuple[int, ...],
    arc: ArcSpec,
    weld: np.ndarray,
    begin: np.ndarray,
) -> bool:
    """Whether the weld normals along a circular edge are its start normal carried round
    the axis (within :data:`ARC_NORMAL_ANGLE`)."""
    axis = arc.normal / np.linalg.norm(arc.normal)
    angles = np.linspace(0.0, arc.angle, ARC_CHECK_POINTS)
    points = arc.center + _rotate(begin - arc.center, axis, angles)
    carried = _rotate(weld, axis, angles)
    derived = weld_normals(part, faces, points)
    cosine = np.clip(np.sum(carried * derived, axis=1), -1.0, 1.0)
    return bool(np.all(np.arccos(cosine) <= ARC_NORMAL_ANGLE))


def _rotate(vector: np.ndarray, axis: np.ndarray, angles: np.ndarray) -> np.ndarray:
    """``vector`` (3,) turned about the unit ``axis`` by each angle (M,), shape (M, 3)
    (Rodrigues)."""
    c, s = np.cos(angles)[:, None], np.sin(angles)[:, None]
    return np.asarray(
        vector * c + np.cross(axis, vector) * s + np.outer(1.0 - c[:, 0], axis) * (axis @ vector),
        dtype=float,
    )


def seam_summary(start: np.ndarray, segments: tuple[SegmentSpec, ...]) -> dict[str, object]:
    """Length (m), pieces by kind and closedness of a derived seam."""
    length, current = 0.0, np.asarray(start, dtype=float)
    kinds = {"line": 0, "arc": 0, "points": 0}
    for segment in segments:
        if isinstance(segment, LineSpec):
            kinds["line"] += 1
            length += float(np.linalg.norm(segment.to - current))
            current = np.asarray(segment.to, dtype=float)
        elif isinstance(segment, ArcSpec):
            kinds["arc"] += 1
            axis = segment.normal / np.linalg.norm(segment.normal)
            radial = current - segment.center
            radial = radial - (radial @ axis) * axis
            length += float(np.linalg.norm(radial) * abs(segment.angle))
            turned = _rotate(current - segment.center, axis, np.array([segment.angle]))
            current = segment.center + turned[0]
        else:
            path = np.vstack([current, segment.points])
            normals = segment.normals
            constant = normals is not None and len(segment.points) == 2
            constant = constant and normals is not None and np.allclose(normals[0], normals[1])
            straight = constant and _collinear(path)
            kinds["line" if straight else "points"] += 1
            length += float(np.linalg.norm(np.diff(path, axis=0), axis=1).sum())
            current = np.asarray(segment.points[-1], dtype=float)
    closed = bool(np.linalg.norm(current - np.asarray(start)) <= CHAIN_GAP)
    return {"length": length, "kinds": kinds, "closed": closed}


def _collinear(path: np.ndarray) -> bool:
    """Whether three points lie on one line (within a micrometre)."""
    a, b, c = path[:3]
    span = np.linalg.norm(c - a)
    return bool(span > 0 and np.linalg.norm(np.cross(b - a, c - a)) / span <= CHAIN_GAP)
