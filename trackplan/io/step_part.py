"""Read a STEP part with OpenCascade (the ``cadquery-ocp`` binding): :func:`read_step_part`.

The part becomes a :class:`~trackplan.cad.part.PartModel`: its faces and edges numbered from
1 in the order OpenCascade's ``TopExp.MapShapes`` visits them (stable for a given file), with
their kinds, sizes and neighbours, and the exact geometric queries the seams need. Lengths are
metres: the file's own unit is converted (OpenCascade reads into millimetres unless told
otherwise; the reader is told metres).

OCP is imported inside the functions only, so that the command line and a plan start without
it; a missing OCP is one line (exit 2) saying how to install it.
"""

from __future__ import annotations

from functools import cache
from pathlib import Path
from typing import Any

import numpy as np

from trackplan.cad.part import Circle, Edge, Face, Tessellation
from trackplan.errors import CaseError

INSTALL_HINT = "pip install cadquery-ocp (make test and make run install it)"
"""How to install the OpenCascade binding."""

_SURFACE_KINDS = {
    "GeomAbs_Plane": "plane",
    "GeomAbs_Cylinder": "cylinder",
    "GeomAbs_Cone": "cone",
    "GeomAbs_Sphere": "sphere",
    "GeomAbs_Torus": "torus",
    "GeomAbs_BezierSurface": "bspline",
    "GeomAbs_BSplineSurface": "bspline",
}
_CURVE_KINDS = {
    "GeomAbs_Line": "line",
    "GeomAbs_Circle": "circle",
    "GeomAbs_Ellipse": "ellipse",
    "GeomAbs_BezierCurve": "bspline",
    "GeomAbs_BSplineCurve": "bspline",
}


@cache
def _occ() -> Any:
    """The OCP modules this reader uses, as one namespace; CaseError when OCP is missing."""
    try:
        from OCP import (
            BRep,
            BRepAdaptor,
            BRepBuilderAPI,
            BRepExtrema,
            BRepGProp,
            BRepLProp,
            BRepMesh,
            BRepTools,
            GCPnts,
            GProp,
            IFSelect,
            Message,
            ShapeAnalysis,
            STEPControl,
            TopAbs,
            TopExp,
            TopLoc,
            TopoDS,
            collections,
            gp,
        )
    except ImportError as exc:
        raise CaseError(f"reading a STEP part needs OpenCascade ({exc}): {INSTALL_HINT}") from exc
    for printer in Message.Message.DefaultMessenger_s().Printers():  # no chatter on stdout
        printer.SetTraceLevel(Message.Message_Gravity.Message_Fail)

    class _Namespace:
        pass

    ns = _Namespace()
    for module in (
        BRep,
        BRepAdaptor,
        BRepBuilderAPI,
        BRepExtrema,
        BRepGProp,
        BRepLProp,
        BRepMesh,
        BRepTools,
        GCPnts,
        GProp,
        IFSelect,
        ShapeAnalysis,
        STEPControl,
        TopAbs,
        TopExp,
        TopLoc,
        TopoDS,
        collections,
        gp,
    ):
        for name in dir(module):
            if not name.startswith("_"):
                setattr(ns, name, getattr(module, name))
    return ns


def _xyz(p: Any) -> np.ndarray:
    """A gp_Pnt / gp_Dir / gp_Vec as an array (3,)."""
    return np.array([p.X(), p.Y(), p.Z()], dtype=float)


def read_step_part(path: str | Path) -> StepPart:
    """Read a STEP file into a :class:`StepPart` (metres).

    Raises
    ------
    CaseError
        The file is missing, unreadable as STEP or empty, holds no solid or shell, or OCP is
        not installed.
    """
    file = str(path)
    if not Path(path).is_file():
        raise CaseError("no such STEP file: give the path of a .step/.stp file", file=file)
    occ = _occ()
    reader = occ.STEPControl_Reader()
    status = reader.ReadFile(file)
    if status != occ.IFSelect_ReturnStatus.IFSelect_RetDone:
        raise CaseError(
            f"cannot read it as STEP ({status.name}): export the part as STEP AP203/AP214/AP242",
            file=file,
        )
    reader.SetSystemLengthUnit(1000.0)  # millimetres per unit of the shapes: metres
    reader.TransferRoots()
    shape = reader.OneShape()
    if shape.IsNull():
        raise CaseError("the STEP file holds no shape: export the part's solid", file=file)
    if not any(
        occ.TopExp_Explorer(shape, kind).More()
        for kind in (occ.TopAbs_ShapeEnum.TopAbs_SOLID, occ.TopAbs_ShapeEnum.TopAbs_SHELL)
    ):
        raise CaseError(
            "the STEP file holds no solid or shell (only curves or points?): export the part's "
            "solid body",
            file=file,
        )
    return StepPart(file, shape, occ)


class StepPart:
    """A part read from a STEP file: an exact B-rep (:class:`~trackplan.cad.part.PartModel`).

    Made by :func:`read_step_part`; its faces and edges are numbered from 1 in
    ``TopExp.MapShapes`` order.
    """

    def __init__(self, source: str, shape: Any, occ: Any) -> None:
        self._source = source
        self._shape = shape
        self._occ = occ
        shapes = occ.TopAbs_ShapeEnum
        self._face_map = occ.IndexedMap_TopoDS_Shape_TopTools_ShapeMapHasher()
        occ.TopExp.MapShapes_s(shape, shapes.TopAbs_FACE, self._face_map)
        self._edge_map = occ.IndexedMap_TopoDS_Shape_TopTools_ShapeMapHasher()
        occ.TopExp.MapShapes_s(shape, shapes.TopAbs_EDGE, self._edge_map)
        ancestors = occ.IndexedDataMap_TopoDS_Shape_List_TopoDS_Shape_TopTools_ShapeMapHasher()
        occ.TopExp.MapShapesAndAncestors_s(shape, shapes.TopAbs_EDGE, shapes.TopAbs_FACE, ancestors)
        self._faces = tuple(self._read_face(i) for i in range(1, self._face_map.Extent() + 1))
        edges = []
        for i in range(1, self._edge_map.Extent() + 1):
            edge = self._edge_map.FindKey(i)
            owners = sorted({self._face_map.FindIndex(f) for f in ancestors.FindFromKey(edge)})
            edges.append(self._read_edge(i, tuple(owners)))
        self._edges = tuple(edges)
        self._meshed: float | None = None

    # -- the protocol's properties -------------------------------------------------------

    @property
    def source(self) -> str:
        """The file it was read from."""
        return self._source

    @property
    def exact(self) -> bool:
        """True: a STEP part is an exact B-rep."""
        return True

    @property
    def faces(self) -> tuple[Face, ...]:
        """Every face, by id order."""
        return self._faces

    @property
    def edges(self) -> tuple[Edge, ...]:
        """Every edge, by id order."""
        return self._edges

    # -- reading -------------------------------------------------------------------------

    def _face(self, face: int) -> Any:
        """The TopoDS_Face of an id; CaseError for an id that does not exist."""
        return self._occ.TopoDS.Face(self._shape_of(self._face_map, face, "face"))

    def _edge(self, edge: int) -> Any:
        """The TopoDS_Edge of an id; CaseError for an id that does not exist."""
        return self._occ.TopoDS.Edge(self._shape_of(self._edge_map, edge, "edge"))

    def _shape_of(self, shapes: Any, number: int, what: str) -> Any:
        """The shape numbered ``number`` (from 1) of an indexed map of faces or edges."""
        count = shapes.Extent()
        if not isinstance(number, int | np.integer) or not 1 <= number <= count:
            raise CaseError(
                f"{what} {number} does not exist: the part has {what}s 1 to {count} "
                "(`trackplan part FILE` lists them)",
                file=self._source,
            )
        return shapes.FindKey(int(number))

    def _reversed(self, shape: Any) -> bool:
        return bool(shape.Orientation() == self._occ.TopAbs_Orientation.TopAbs_REVERSED)

    def _read_face(self, i: int) -> Face:
        occ = self._occ
        face = self._face(i)
        surface = occ.BRepAdaptor_Surface(face)
        kind = _SURFACE_KINDS.get(surface.GetType().name, "other")
        props = occ.GProp_GProps()
        occ.BRepGProp.SurfaceProperties_s(face, props)
        normal = axis = None
        if kind == "plane":
            normal = _xyz(surface.Plane().Axis().Direction())
            if self._reversed(face):
                normal = -normal
        elif kind in ("cylinder", "cone", "torus"):
            getter = {"cylinder": surface.Cylinder, "cone": surface.Cone, "torus": surface.Torus}
            axis = _xyz(getter[kind]().Axis().Direction())
        return Face(
            id=i,
            kind=kind,
            area=float(props.Mass()),
            centroid=_xyz(props.CentreOfMass()),
            normal=normal,
            axis=axis,
        )

    def _curve(self, edge: int) -> tuple[Any, float, float, bool]:
        """The edge's curve adaptor, its parameter range and whether it runs backwards."""
        shape = self._edge(edge)
        curve = self._occ.BRepAdaptor_Curve(shape)
        return curve, curve.FirstParameter(), curve.LastParameter(), self._reversed(shape)

    def _read_edge(self, i: int, faces: tuple[int, ...]) -> Edge:
        occ = self._occ
        curve, u0, u1, backwards = self._curve(i)
        degenerated = occ.BRep_Tool.Degenerated_s(self._edge(i))
        kind = "other" if degenerated else _CURVE_KINDS.get(curve.GetType().name, "other")
        start, end = _xyz(curve.Value(u0)), _xyz(curve.Value(u1))
        if backwards:
            start, end = end, start
        length = 0.0 if degenerated else float(occ.GCPnts_AbscissaPoint.Length_s(curve))
        return Edge(id=i, kind=kind, length=length, start=start, end=end, faces=faces)

    # -- queries -------------------------------------------------------------------------

    def edge_points(self, edge: int, max_chord_error: float) -> np.ndarray:
        """Points along an edge from its start to its end (m): its ends for a line, else
        close enough that the polyline stays within ``max_chord_error`` (m) of the curve."""
        info = self._edge_info(edge)
        if info.kind == "line" or info.length == 0:  # a line, or a degenerated edge (a pole)
            return np.stack([info.start, info.end])
        if not max_chord_error > 0:
            raise CaseError(f"the chord error must be > 0 m, got {max_chord_error}")
        curve, u0, u1, backwards = self._curve(edge)
        sampler = self._occ.GCPnts_QuasiUniformDeflection(curve, float(max_chord_error), u0, u1)
        if not sampler.IsDone() or sampler.NbPoints() < 2:
            raise CaseError(f"cannot sample edge {edge} of the part", file=self._source)
        u = np.array([sampler.Parameter(k) for k in range(1, sampler.NbPoints() + 1)])
        points = np.array([_xyz(curve.Value(float(v))) for v in u])
        points[0], points[-1] = _xyz(curve.Value(u0)), _xyz(curve.Value(u1))
        return points[::-1].copy() if backwards else points

    def edge_circle(self, edge: int) -> Circle | None:
        """The exact circle of a circular edge in its own direction, else None."""
        info = self._edge_info(edge)
        if info.kind != "circle":
            return None
        curve, u0, u1, backwards = self._curve(edge)
        circle = curve.Circle()
        axis = _xyz(circle.Axis().Direction())  # the parameter turns positively about it
        return Circle(
            center=_xyz(circle.Location()),
            axis=-axis if backwards else axis,
            radius=float(circle.Radius()),
            angle=float(u1 - u0),
            start=info.start.copy(),
        )

    def face_normals(self, face: int, points: np.ndarray) -> np.ndarray:
        """The face's outward unit normal at the points of its surface nearest ``points``
        (M, 3), shape (M, 3)."""
        occ = self._occ
        shape = self._face(face)
        points = np.asarray(points, dtype=float).reshape(-1, 3)
        surface = occ.BRepAdaptor_Surface(shape)
        analysis = occ.ShapeAnalysis_Surface(occ.BRep_Tool.Surface_s(shape))
        sign = -1.0 if self._reversed(shape) else 1.0
        normals = np.empty_like(points)
        for k, p in enumerate(points):
            uv = analysis.ValueOfUV(occ.gp_Pnt(*p), 1e-9)
            props = occ.BRepLProp_SLProps(surface, uv.X(), uv.Y(), 1, 1e-9)
            if not props.IsNormalDefined():
                raise CaseError(
                    f"face {face} has no normal at {p.tolist()} (a singular point)",
                    file=self._source,
                )
            normals[k] = sign * _xyz(props.Normal())
        return normals / np.linalg.norm(normals, axis=1, keepdims=True)

    def nearest_face(self, point: np.ndarray) -> tuple[int, float]:
        """The face nearest a point (3,), and its distance, m. On an edge between faces, the
        face whose outward normal points most towards the point (the lowest id on a tie)."""
        occ = self._occ
        p = np.asarray(point, dtype=float).reshape(3)
        vertex = occ.BRepBuilderAPI_MakeVertex(occ.gp_Pnt(*p)).Vertex()
        best: tuple[float, float, int] | None = None
        for i in range(1, len(self._faces) + 1):
            dist = occ.BRepExtrema_DistShapeShape(vertex, self._face(i))
            if not dist.IsDone() or dist.NbSolution() == 0:
                continue
            d = float(dist.Value())
            if best is not None and d > best[0] + 1e-9:
                continue
            q = _xyz(dist.PointOnShape2(1))
            away = p - q
            facing, gap = 0.0, float(np.linalg.norm(away))
            if gap > 1e-12:  # prefer the face that faces the point
                facing = -float(self.face_normals(i, q[None])[0] @ away) / gap
            key = (d, facing, i)
            if best is None or d < best[0] - 1e-9 or (key[1:] < best[1:]):
                best = key
        if best is None:
            raise CaseError("no face of the part is near the point", file=self._source)
        return best[2], best[0]

    def shared_edges(self, a: int, b: int) -> tuple[int, ...]:
        """The edges that faces a and b (a ≠ b) share, by id (none when they do not meet)."""
        self._face(a), self._face(b)
        if a == b:
            return ()
        return tuple(e.id for e in self._edges if a in e.faces and b in e.faces)

    def tessellation(self, chord_error: float) -> Tessellation:
        """The part's triangles within ``chord_error`` (m) of the surface, outward."""
        occ = self._occ
        if not chord_error > 0:
            raise CaseError(f"the chord error must be > 0 m, got {chord_error}")
        if self._meshed != chord_error:
            occ.BRepTools.Clean_s(self._shape)
            occ.BRepMesh_IncrementalMesh(self._shape, float(chord_error), False, 0.5, True)
            self._meshed = chord_error
        vertices, triangles, owner = [], [], []
        count = 0
        for i in range(1, len(self._faces) + 1):
            face = self._face(i)
            location = occ.TopLoc_Location()
            mesh = occ.BRep_Tool.Triangulation_s(face, location)
            if mesh is None:
                continue
            node, triangle = mesh.Node, mesh.Triangle
            nodes = np.array(
                [node(k).Coord() for k in range(1, mesh.NbNodes() + 1)], dtype=float
            ).reshape(-1, 3)
            if not location.IsIdentity():
                T = location.Transformation()
                rows = [[T.Value(r, c) for c in range(1, 5)] for r in range(1, 4)]
                matrix = np.array(rows)
                nodes = nodes @ matrix[:, :3].T + matrix[:, 3]
            tris = np.array(
                [triangle(k).Get() for k in range(1, mesh.NbTriangles() + 1)], dtype=int
            ).reshape(-1, 3)
            tris = tris - 1 + count
            if self._reversed(face):
                tris = tris[:, [0, 2, 1]]
            vertices.append(nodes)
            triangles.append(tris)
            owner.append(np.full(len(tris), i, dtype=int))
            count += len(nodes)
        return Tessellation(
            vertices=np.concatenate(vertices) if vertices else np.zeros((0, 3)),
            triangles=np.concatenate(triangles) if triangles else np.zeros((0, 3), dtype=int),
            chord_error=float(chord_error),
            face=np.concatenate(owner) if owner else np.zeros(0, dtype=int),
        )

    def _edge_info(self, edge: int) -> Edge:
        """The listed edge of an id, after checking it."""
        self._edge(edge)
        return self._edges[int(edge) - 1]
