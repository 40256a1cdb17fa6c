"""STEP parts read with OpenCascade: the shipped parts against their analytic geometry."""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest

from tests.conftest import CASES
from trackplan.errors import CaseError
from trackplan.io.part_file import load_part
from trackplan.io.step_part import StepPart, read_step_part

PARTS = CASES / "parts"
ANGLE = np.radians(0.1)  # normals: within 0.1° of the analytic ones
POINT = 1e-8  # m: exact geometry, up to OpenCascade's tolerance


@pytest.fixture(scope="module")
def pipe() -> StepPart:
    return read_step_part(PARTS / "pipe-plate.step")


@pytest.fixture(scope="module")
def tee() -> StepPart:
    return read_step_part(PARTS / "t-joint.step")


@pytest.fixture(scope="module")
def saddle() -> StepPart:
    return read_step_part(PARTS / "saddle.step")


def angles(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Angles between unit vectors, rad."""
    return np.arccos(np.clip(np.sum(a * b, axis=-1), -1.0, 1.0))


def face_where(part: StepPart, kind: str, **near: float) -> int:
    """The one face of a kind whose area (or centroid z) is as given."""
    found = [
        f.id
        for f in part.faces
        if f.kind == kind
        and all(
            abs((f.area if key == "area" else f.centroid[2]) - value) < 1e-9
            for key, value in near.items()
        )
    ]
    assert len(found) == 1, found
    return found[0]


# -- the pipe on the plate ----------------------------------------------------------------

R, WALL, H = 0.06, 0.005, 0.15
R_IN = R - WALL
AREAS = {
    "plate top": 0.09 - np.pi * R**2,
    "disc inside the pipe": np.pi * R_IN**2,
    "plate bottom": 0.09,
    "plate side": 0.003,
    "pipe outside": 2 * np.pi * R * H,
    "pipe inside": 2 * np.pi * R_IN * H,
    "pipe top": np.pi * (R**2 - R_IN**2),
}


def test_the_pipe_on_the_plate_has_its_faces_with_their_analytic_areas(pipe: StepPart) -> None:
    assert pipe.exact and pipe.source.endswith("pipe-plate.step")
    assert [f.id for f in pipe.faces] == list(range(1, 11))
    assert sorted(f.kind for f in pipe.faces) == ["cylinder"] * 2 + ["plane"] * 8
    expected = sorted([*AREAS.values(), *[AREAS["plate side"]] * 3])
    assert np.allclose(sorted(f.area for f in pipe.faces), expected, rtol=1e-9, atol=1e-12)
    for face in pipe.faces:
        if face.kind == "cylinder":
            assert np.allclose(np.abs(face.axis), [0, 0, 1]) and face.normal is None
            assert np.allclose(face.centroid, [0, 0, H / 2], atol=POINT)
        else:
            assert face.axis is None and np.isclose(np.linalg.norm(face.normal), 1.0)
    top = face_where(pipe, "plane", area=AREAS["plate top"])
    bottom = face_where(pipe, "plane", area=AREAS["plate bottom"])
    assert np.allclose(pipe.faces[top - 1].normal, [0, 0, 1])  # outward: up
    assert np.allclose(pipe.faces[bottom - 1].normal, [0, 0, -1])
    assert np.isclose(pipe.faces[bottom - 1].centroid[2], -0.01)


def test_the_pipe_foot_is_an_exact_circle_shared_by_the_plate_and_the_pipe(
    pipe: StepPart,
) -> None:
    assert len(pipe.edges) == 18
    assert sorted(e.kind for e in pipe.edges) == ["circle"] * 4 + ["line"] * 14
    top = face_where(pipe, "plane", area=AREAS["plate top"])
    outside = face_where(pipe, "cylinder", area=AREAS["pipe outside"])
    (foot,) = pipe.shared_edges(top, outside)
    assert pipe.shared_edges(outside, top) == (foot,)
    edge = pipe.edges[foot - 1]
    assert edge.kind == "circle" and edge.closed and set(edge.faces) == {top, outside}
    assert np.isclose(edge.length, 2 * np.pi * R, rtol=1e-9)
    circle = pipe.edge_circle(foot)
    assert circle is not None
    assert np.allclose(circle.center, 0.0, atol=POINT) and np.isclose(circle.radius, R)
    assert np.allclose(np.abs(circle.axis), [0, 0, 1]) and np.isclose(circle.angle, 2 * np.pi)
    assert np.allclose(circle.start, edge.start)
    # the axis turns the edge positively: its points go round it right-handedly
    points = pipe.edge_points(foot, 1e-5)
    turn = np.cross(points[:-1] - circle.center, points[1:] - circle.center) @ circle.axis
    assert np.all(turn > 0)
    assert pipe.edge_circle(next(e.id for e in pipe.edges if e.kind == "line")) is None


def test_edge_points_stay_within_the_chord_error(pipe: StepPart, saddle: StepPart) -> None:
    top = face_where(pipe, "plane", area=AREAS["plate top"])
    outside = face_where(pipe, "cylinder", area=AREAS["pipe outside"])
    (foot,) = pipe.shared_edges(top, outside)
    for chord in (1e-3, 1e-5):
        points = pipe.edge_points(foot, chord)
        assert np.allclose(np.linalg.norm(points[:, :2], axis=1), R, atol=POINT)
        assert np.allclose(points[:, 2], 0.0, atol=POINT)
        half = np.linalg.norm(np.diff(points, axis=0), axis=1) / 2  # sagitta of each chord
        assert np.max(R - np.sqrt(R**2 - half**2)) <= chord * (1 + 1e-6)
        assert np.allclose(points[0], points[-1], atol=POINT)
    line = next(e for e in pipe.edges if e.kind == "line")
    assert np.allclose(pipe.edge_points(line.id, 1e-5), [line.start, line.end])


def test_face_normals_point_out_of_the_solid(pipe: StepPart) -> None:
    theta = np.linspace(0.0, 2 * np.pi, 13)
    radial = np.stack([np.cos(theta), np.sin(theta), np.zeros_like(theta)], axis=1)
    outside = face_where(pipe, "cylinder", area=AREAS["pipe outside"])
    inside = face_where(pipe, "cylinder", area=AREAS["pipe inside"])
    at = np.array([0.0, 0.0, 0.07])
    assert np.max(angles(pipe.face_normals(outside, R * radial + at), radial)) < ANGLE
    # near points off the surface are projected onto it first
    off = pipe.face_normals(outside, (R + 0.01) * radial + at)
    assert np.max(angles(off, radial)) < ANGLE
    assert np.max(angles(pipe.face_normals(inside, R_IN * radial + at), -radial)) < ANGLE
    top = face_where(pipe, "plane", area=AREAS["plate top"])
    bottom = face_where(pipe, "plane", area=AREAS["plate bottom"])
    on_top = np.array([[0.1, 0.1, 0.0], [-0.1, 0.12, 0.0]])
    assert np.max(angles(pipe.face_normals(top, on_top), np.array([0, 0, 1.0]))) < ANGLE
    below = pipe.face_normals(bottom, on_top - [0, 0, 0.01])
    assert np.max(angles(below, np.array([0, 0, -1.0]))) < ANGLE


def test_nearest_face_and_its_distance(pipe: StepPart) -> None:
    top = face_where(pipe, "plane", area=AREAS["plate top"])
    disc = face_where(pipe, "plane", area=AREAS["disc inside the pipe"])
    outside = face_where(pipe, "cylinder", area=AREAS["pipe outside"])
    face, distance = pipe.nearest_face(np.array([0.1, 0.1, 0.001]))
    assert face == top and np.isclose(distance, 0.001, atol=POINT)
    face, distance = pipe.nearest_face(np.array([0.0, 0.01, 0.002]))
    assert face == disc and np.isclose(distance, 0.002, atol=POINT)
    face, distance = pipe.nearest_face(np.array([0.0, -0.07, 0.05]))
    assert face == outside and np.isclose(distance, 0.01, atol=POINT)
    # just outside the foot, nearer the plate than the pipe: the plate
    face, _ = pipe.nearest_face(np.array([0.0605, 0.0, 0.0002]))
    assert face == top


def test_tessellation_is_outward_and_within_its_chord_error(pipe: StepPart) -> None:
    chord = 2e-4
    mesh = pipe.tessellation(chord)
    assert mesh.chord_error == chord
    assert mesh.triangles.shape[1] == 3 and len(mesh.face) == len(mesh.triangles)
    assert set(mesh.face.tolist()) == {f.id for f in pipe.faces}
    v = mesh.vertices[mesh.triangles]  # (T, 3, 3)
    volume = np.sum(np.einsum("ij,ij->i", v[:, 0], np.cross(v[:, 1], v[:, 2]))) / 6
    exact = 0.3 * 0.3 * 0.01 + np.pi * (R**2 - R_IN**2) * H
    area = sum(f.area for f in pipe.faces)
    assert abs(volume - exact) <= chord * area  # positive: every triangle faces outward
    outside = face_where(pipe, "cylinder", area=AREAS["pipe outside"])
    mine = v[mesh.face == outside]
    assert np.allclose(np.linalg.norm(mine[..., :2], axis=-1), R, atol=POINT)
    centroid = mine.mean(axis=1)
    assert np.min(np.linalg.norm(centroid[:, :2], axis=1)) >= R - chord
    normal = np.cross(mine[:, 1] - mine[:, 0], mine[:, 2] - mine[:, 0])
    assert np.all(np.einsum("ij,ij->i", normal[:, :2], centroid[:, :2]) > 0)
    finer = pipe.tessellation(chord / 4)
    assert len(finer.triangles) > len(mesh.triangles)


@pytest.mark.parametrize("name", ["pipe", "tee", "saddle"])
def test_edge_points_run_from_the_edges_start_to_its_end(
    name: str, request: pytest.FixtureRequest
) -> None:
    part: StepPart = request.getfixturevalue(name)
    for edge in part.edges:
        if edge.length == 0:
            continue
        points = part.edge_points(edge.id, 1e-4)
        assert np.allclose(points[0], edge.start, atol=POINT), edge.id
        assert np.allclose(points[-1], edge.end, atol=POINT), edge.id
        polyline = np.sum(np.linalg.norm(np.diff(points, axis=0), axis=1))
        assert edge.length * (1 - 1e-3) <= polyline <= edge.length * (1 + 1e-9), edge.id


def test_ids_are_stable_for_a_file(pipe: StepPart) -> None:
    again = read_step_part(PARTS / "pipe-plate.step")
    assert [(f.kind, round(f.area, 12)) for f in again.faces] == [
        (f.kind, round(f.area, 12)) for f in pipe.faces
    ]
    assert [(e.kind, e.faces) for e in again.edges] == [(e.kind, e.faces) for e in pipe.edges]


# -- the T-joint and the saddle -----------------------------------------------------------


def test_the_t_joint_has_two_straight_fillets(tee: StepPart) -> None:
    assert len(tee.faces) == 10 and {f.kind for f in tee.faces} == {"plane"}
    assert len(tee.edges) == 24 and {e.kind for e in tee.edges} == {"line"}
    web = [f.id for f in tee.faces if np.isclose(f.area, 0.03)]  # the web's two sides
    base = [f.id for f in tee.faces if np.isclose(f.area, 0.3 * 0.095)]  # the base's top
    assert len(web) == 2 and len(base) == 2
    seams = [e for w in web for b in base for e in tee.shared_edges(w, b)]
    assert len(seams) == 2
    for seam in seams:
        edge = tee.edges[seam - 1]
        side = np.sign(edge.start[1])
        assert np.allclose(sorted([edge.start[0], edge.end[0]]), [-0.15, 0.15])
        assert np.allclose([edge.start[1:], edge.end[1:]], [[side * 0.005, 0.0]] * 2)
        a, b = edge.faces
        normals = {f: tee.face_normals(f, np.stack([edge.start, edge.end])) for f in (a, b)}
        expected = {
            f: np.array([0, side, 0.0]) if f in web else np.array([0, 0, 1.0]) for f in (a, b)
        }
        for f in (a, b):
            assert np.max(angles(normals[f], expected[f])) < ANGLE


def test_the_saddle_seam_is_a_bspline_on_both_pipes(saddle: StepPart) -> None:
    main = next(f.id for f in saddle.faces if f.kind == "cylinder" and f.axis[1] != 0)
    branch = next(f.id for f in saddle.faces if f.kind == "cylinder" and f.axis[2] != 0)
    seam = saddle.shared_edges(main, branch)
    assert seam and all(saddle.edges[e - 1].kind == "bspline" for e in seam)
    chord = 1e-5
    theta = np.linspace(0.0, 2 * np.pi, 4001)
    x, y = 0.05 * np.cos(theta), 0.05 * np.sin(theta)
    curve = np.stack([x, y, np.sqrt(0.1**2 - x**2)], axis=1)  # the analytic seam
    total = 0.0
    for e in seam:
        points = saddle.edge_points(e, chord)
        assert np.allclose(np.hypot(points[:, 0], points[:, 1]), 0.05, atol=POINT)
        assert np.allclose(np.hypot(points[:, 0], points[:, 2]), 0.1, atol=POINT)
        total += saddle.edges[e - 1].length
        # every analytic point of this edge lies within the chord error of the polyline
        turn = np.unwrap(np.arctan2(points[:, 1], points[:, 0]))
        low, high = min(turn[0], turn[-1]), max(turn[0], turn[-1])
        mine = curve[low + np.mod(theta - low, 2 * np.pi) <= high]
        assert len(mine) > 500
        assert np.max(_near_polyline(mine, points)) <= chord * (1 + 1e-3)
        out_main = saddle.face_normals(main, points)
        out_branch = saddle.face_normals(branch, points)
        radial_main = points * [1, 0, 1] / 0.1
        radial_branch = points * [1, 1, 0] / 0.05
        assert np.max(angles(out_main, radial_main)) < ANGLE
        assert np.max(angles(out_branch, radial_branch)) < ANGLE
    length = np.sum(np.linalg.norm(np.diff(curve, axis=0), axis=1))
    assert np.isclose(total, length, rtol=1e-5)


def _near_polyline(points: np.ndarray, polyline: np.ndarray) -> np.ndarray:
    """Each point's distance to a polyline, m."""
    a, b = polyline[:-1], polyline[1:]
    ab = b - a
    t = np.einsum("pkj,kj->pk", points[:, None] - a, ab) / np.sum(ab * ab, axis=1)
    foot = a + np.clip(t, 0, 1)[..., None] * ab
    return np.min(np.linalg.norm(points[:, None] - foot, axis=2), axis=1)


# -- units and refusals -------------------------------------------------------------------


def _write_box(path: Path, unit: str) -> None:
    """A 200 × 100 × 50 mm box written to STEP in ``unit``."""
    from OCP.BRepPrimAPI import BRepPrimAPI_MakeBox
    from OCP.Interface import Interface_Static
    from OCP.STEPControl import STEPControl_StepModelType, STEPControl_Writer

    before = Interface_Static.CVal_s("write.step.unit")
    Interface_Static.SetCVal_s("write.step.unit", unit)
    try:
        writer = STEPControl_Writer()
        box = BRepPrimAPI_MakeBox(200.0, 100.0, 50.0).Shape()
        writer.Transfer(box, STEPControl_StepModelType.STEPControl_AsIs)
        writer.Write(str(path))
    finally:
        Interface_Static.SetCVal_s("write.step.unit", before)


@pytest.mark.parametrize("unit", ["MM", "M", "INCH"])
def test_the_file_unit_is_honoured(tmp_path: Path, unit: str) -> None:
    path = tmp_path / "box.step"
    _write_box(path, unit)
    text = path.read_text()
    assert ("200." in text) == (unit == "MM")  # the numbers are in the file's unit
    part = read_step_part(path)
    assert np.allclose(sorted(f.area for f in part.faces), [0.005] * 2 + [0.01] * 2 + [0.02] * 2)
    assert np.isclose(max(e.length for e in part.edges), 0.2)


def test_a_curve_only_step_is_refused(tmp_path: Path) -> None:
    from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeEdge
    from OCP.gp import gp_Pnt
    from OCP.STEPControl import STEPControl_StepModelType, STEPControl_Writer

    path = tmp_path / "curve.step"
    writer = STEPControl_Writer()
    edge = BRepBuilderAPI_MakeEdge(gp_Pnt(0, 0, 0), gp_Pnt(10, 0, 0)).Edge()
    writer.Transfer(edge, STEPControl_StepModelType.STEPControl_AsIs)
    writer.Write(str(path))
    with pytest.raises(CaseError, match="no solid or shell") as info:
        read_step_part(path)
    assert info.value.file == str(path) and "\n" not in str(info.value)


@pytest.mark.parametrize(
    ("text", "match"),
    [
        ("", "cannot read it as STEP"),
        ("solid cube\nendsolid cube\n", "cannot read it as STEP"),
    ],
    ids=["empty", "not-step"],
)
def test_an_unreadable_or_empty_step_is_refused(tmp_path: Path, text: str, match: str) -> None:
    path = tmp_path / "part.step"
    path.write_text(text)
    with pytest.raises(CaseError, match=match) as info:
        load_part(path)
    assert "\n" not in str(info.value)


def test_a_missing_file_an_unknown_suffix_and_bad_ids_are_refused(
    tmp_path: Path, pipe: StepPart
) -> None:
    with pytest.raises(CaseError, match="no such STEP file"):
        load_part(tmp_path / "nothing.stp")
    with pytest.raises(CaseError, match=r"STEP or a mesh .*got '\.iges'"):
        load_part(tmp_path / "part.iges")
    with pytest.raises(CaseError, match="face 11 does not exist: the part has faces 1 to 10"):
        pipe.face_normals(11, np.zeros((1, 3)))
    with pytest.raises(CaseError, match="edge 0 does not exist"):
        pipe.edge_points(0, 1e-4)
    with pytest.raises(CaseError, match="face 0 does not exist"):
        pipe.shared_edges(0, 3)


def test_a_missing_opencascade_is_one_line_saying_how_to_install_it(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    from trackplan.io.step_part import _occ

    monkeypatch.setitem(sys.modules, "OCP", None)
    _occ.cache_clear()  # the OCP modules are looked up once per process
    with pytest.raises(CaseError, match="pip install cadquery-ocp"):
        read_step_part(PARTS / "pipe-plate.step")


def test_spheres_cones_and_tori_and_a_degenerated_edge(tmp_path: Path) -> None:
    from OCP.BRepAlgoAPI import BRepAlgoAPI_Fuse
    from OCP.BRepPrimAPI import BRepPrimAPI_MakeCone, BRepPrimAPI_MakeSphere, BRepPrimAPI_MakeTorus
    from OCP.gp import gp_Ax2, gp_Dir, gp_Pnt
    from OCP.STEPControl import STEPControl_StepModelType, STEPControl_Writer

    up = gp_Dir(0, 0, 1)
    ball = BRepPrimAPI_MakeSphere(50.0).Shape()  # mm
    cone = BRepPrimAPI_MakeCone(gp_Ax2(gp_Pnt(0, 0, 40), up), 30.0, 10.0, 50.0).Shape()
    ring = BRepPrimAPI_MakeTorus(gp_Ax2(gp_Pnt(200, 0, 0), up), 40.0, 10.0).Shape()
    shape = BRepAlgoAPI_Fuse(BRepAlgoAPI_Fuse(ball, cone).Shape(), ring).Shape()
    writer = STEPControl_Writer()
    writer.Transfer(shape, STEPControl_StepModelType.STEPControl_AsIs)
    writer.Write(str(tmp_path / "round.step"))
    part = read_step_part(tmp_path / "round.step")
    kinds = {f.kind: f for f in part.faces}
    assert set(kinds) == {"sphere", "cone", "torus", "plane"}
    assert np.isclose(kinds["torus"].area, 4 * np.pi**2 * 0.04 * 0.01)
    assert np.allclose(np.abs(kinds["torus"].axis), [0, 0, 1])
    assert np.allclose(np.abs(kinds["cone"].axis), [0, 0, 1]) and kinds["sphere"].axis is None
    pole = [e for e in part.edges if e.length == 0]  # the sphere's bottom pole
    assert len(pole) == 1 and pole[0].kind == "other"
    assert np.allclose(part.edge_points(pole[0].id, 1e-4), [[0, 0, -0.05]] * 2, atol=POINT)
    sphere = kinds["sphere"].id
    on_ball = np.array([[0.05, 0, 0], [0, -0.03, -0.04]])
    assert np.max(angles(part.face_normals(sphere, on_ball), on_ball / 0.05)) < ANGLE
    mesh = part.tessellation(1e-4)
    v = mesh.vertices[mesh.triangles]
    volume = np.sum(np.einsum("ij,ij->i", v[:, 0], np.cross(v[:, 1], v[:, 2]))) / 6
    ring_volume = 2 * np.pi**2 * 0.04 * 0.01**2
    assert ring_volume + 4 / 3 * np.pi * 0.05**3 < volume < ring_volume + 0.0007
