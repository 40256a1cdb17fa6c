"""A mesh part: smooth regions as faces, their boundaries as edges (trackplan/io/mesh_part.py).

Every mesh is made here with trimesh; expected regions, boundaries and normals come from the
shapes' own geometry, not from the reader.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
import trimesh

from trackplan.errors import CaseError
from trackplan.io.mesh_part import read_mesh_part

TOL = 1e-6  # m: STL stores float32 coordinates


def write(mesh: trimesh.Trimesh, path: Path) -> Path:
    mesh.export(str(path))
    return path


@pytest.fixture
def box(tmp_path: Path) -> Path:
    return write(trimesh.creation.box(extents=(0.2, 0.1, 0.05)), tmp_path / "box.stl")


def pipe_on_plate() -> trimesh.Trimesh:
    """A plate 0.2 x 0.2 x 0.01 m (top at z = 0) and a pipe of radius 0.03 m, 0.1 m high,
    standing on it, fused by trimesh's boolean engine: 64 facets round, 5.625° apart."""
    pytest.importorskip("manifold3d", reason="no boolean engine for trimesh")
    plate = trimesh.creation.box(extents=(0.2, 0.2, 0.01))
    plate.apply_translation((0.0, 0.0, -0.005))
    pipe = trimesh.creation.cylinder(radius=0.03, height=0.1, sections=64)
    pipe.apply_translation((0.0, 0.0, 0.05))
    return trimesh.boolean.union([plate, pipe], engine="manifold")


def pipe_on_disc(n: int = 64) -> trimesh.Trimesh:
    """The same union built by hand: a disc plate of radius 0.1 m (top at z = 0, 0.01 m
    thick) and a pipe of radius 0.03 m, 0.1 m high, both with n facets round."""
    t = np.linspace(0.0, 2 * np.pi, n, endpoint=False)

    def ring(r: float, z: float) -> np.ndarray:
        return np.column_stack([r * np.cos(t), r * np.sin(t), np.full(n, z)])

    centres = [[0.0, 0.0, -0.01], [0.0, 0.0, 0.1]]
    vertices = np.vstack(
        [ring(0.1, -0.01), ring(0.1, 0.0), ring(0.03, 0.0), ring(0.03, 0.1), centres]
    )
    k = np.arange(n)
    k1 = (k + 1) % n
    A, B, C, D = (k + i * n for i in range(4))  # rings: plate bottom, plate top, foot, top
    A1, B1, C1, D1 = (k1 + i * n for i in range(4))
    bottom, top = np.full(n, 4 * n), np.full(n, 4 * n + 1)
    faces = np.vstack(
        [
            np.column_stack([bottom, A1, A]),  # plate bottom, -z
            np.column_stack([A, A1, B1]),  # plate rim, radial
            np.column_stack([A, B1, B]),
            np.column_stack([C, B, B1]),  # plate top round the pipe's foot, +z
            np.column_stack([C, B1, C1]),
            np.column_stack([C, C1, D1]),  # pipe wall, radial
            np.column_stack([C, D1, D]),
            np.column_stack([top, D, D1]),  # pipe cap, +z
        ]
    )
    mesh = trimesh.Trimesh(vertices, faces, process=False)
    assert mesh.is_watertight and mesh.volume > 0
    return mesh


def test_box_has_six_plane_regions_and_twelve_boundaries(box: Path) -> None:
    part = read_mesh_part(box, scale=1.0)
    assert part.exact is False
    assert len(part.faces) == 6 and len(part.edges) == 12
    assert [f.id for f in part.faces] == [1, 2, 3, 4, 5, 6]
    assert all(f.kind == "region" for f in part.faces)
    # by area, descending: the two 0.2 x 0.1 faces first, the two 0.1 x 0.05 last
    areas = [f.area for f in part.faces]
    assert areas == pytest.approx([0.02, 0.02, 0.01, 0.01, 0.005, 0.005], rel=1e-6)
    for face in part.faces:
        assert face.normal is not None
        # outward: the normal points from the box centre to the face's centroid
        assert np.allclose(face.normal * np.abs(face.centroid).max(), face.centroid, atol=TOL)
    lengths = sorted(e.length for e in part.edges)
    assert lengths == pytest.approx([0.05] * 4 + [0.1] * 4 + [0.2] * 4, rel=1e-6)
    for edge in part.edges:
        assert edge.kind == "boundary" and len(edge.faces) == 2 and not edge.closed
        a, b = (part.faces[i - 1] for i in edge.faces)
        # a boundary between two planes lies on both: its ends are on both faces' planes
        for face in (a, b):
            for point in (edge.start, edge.end):
                assert abs(np.dot(point - face.centroid, face.normal)) < TOL
        pts = part.edge_points(edge.id, 1e-4)
        assert np.allclose(pts[[0, -1]], [edge.start, edge.end])
        assert part.edge_circle(edge.id) is None
        # the lower-id region lies on the boundary's left, seen from outside
        n = part.faces[edge.faces[0] - 1].normal
        left = np.cross(n, edge.end - edge.start)
        assert np.dot(left, part.faces[edge.faces[0] - 1].centroid - edge.start) > 0
    # opposite faces share no edge; adjacent ones exactly one
    top = next(f.id for f in part.faces if f.normal[2] > 0.5)
    bottom = next(f.id for f in part.faces if f.normal[2] < -0.5)
    side = next(f.id for f in part.faces if f.normal[0] > 0.5)
    assert part.shared_edges(top, bottom) == ()
    (edge,) = part.shared_edges(top, side)
    assert part.shared_edges(side, top) == (edge,)
    assert np.allclose(part.edges[edge - 1].start[[0, 2]], [0.1, 0.025], atol=TOL)


def test_boundaries_of_many_mesh_edges_are_chained_end_to_end(tmp_path: Path) -> None:
    fine = trimesh.creation.box(extents=(0.2, 0.1, 0.05)).subdivide().subdivide()
    part = read_mesh_part(write(fine, tmp_path / "fine.stl"), scale=1.0)
    assert len(part.faces) == 6 and len(part.edges) == 12
    lengths = sorted(e.length for e in part.edges)
    assert lengths == pytest.approx([0.05] * 4 + [0.1] * 4 + [0.2] * 4, rel=1e-6)
    for edge in part.edges:
        pts = part.edge_points(edge.id, 1e-4)
        assert len(pts) == 5  # 4 mesh edges, in order: evenly spaced from start to end
        expected = np.linspace(edge.start, edge.end, 5)
        assert np.allclose(pts, expected, atol=TOL)


def test_ids_do_not_depend_on_the_triangle_order(box: Path, tmp_path: Path) -> None:
    mesh = trimesh.creation.box(extents=(0.2, 0.1, 0.05))
    shuffled = trimesh.Trimesh(
        mesh.vertices, mesh.faces[np.random.default_rng(3).permutation(len(mesh.faces))]
    )
    a = read_mesh_part(box, scale=1.0)
    b = read_mesh_part(write(shuffled, tmp_path / "shuffled.stl"), scale=1.0)
    for fa, fb in zip(a.faces, b.faces, strict=True):
        assert np.allclose(fa.centroid, fb.centroid, atol=TOL)
    for ea, eb in zip(a.edges, b.edges, strict=True):
        assert ea.faces == eb.faces
        assert np.allclose([ea.start, ea.end], [eb.start, eb.end], atol=TOL)


def test_scale_converts_file_units_to_metres(tmp_path: Path) -> None:
    mm = write(trimesh.creation.box(extents=(200.0, 100.0, 50.0)), tmp_path / "mm.stl")
    part = read_mesh_part(mm, scale=0.001)
    assert part.faces[0].area == pytest.approx(0.02, rel=1e-6)
    assert sorted(e.length for e in part.edges)[-1] == pytest.approx(0.2, rel=1e-6)
    tess = part.tessellation(1e-4)
    assert tess.chord_error == 0.0
    assert np.abs(tess.vertices).max() == pytest.approx(0.1, rel=1e-6)
    assert sorted(set(tess.face.tolist())) == [1, 2, 3, 4, 5, 6]


def test_a_unit_the_file_carries_is_honoured(tmp_path: Path) -> None:
    mesh = trimesh.creation.box(extents=(200.0, 100.0, 50.0))
    mesh.units = "mm"
    part = read_mesh_part(write(mesh, tmp_path / "mm.glb"))  # glTF keeps trimesh's unit
    assert part.faces[0].area == pytest.approx(0.02, rel=1e-9)
    with pytest.raises(CaseError, match=r"part\.scale: .* carries no unit"):
        read_mesh_part(write(trimesh.creation.box(), tmp_path / "box.off"))


def test_cylinder_wall_is_one_region_above_its_facet_angle(tmp_path: Path) -> None:
    cylinder = trimesh.creation.cylinder(radius=0.03, height=0.1, sections=64)
    path = write(cylinder, tmp_path / "cyl.stl")
    part = read_mesh_part(path, scale=1.0)  # 20° > 5.625° between facets
    assert len(part.faces) == 3
    wall = part.faces[0]
    assert wall.area == pytest.approx(64 * 0.03 * math.sin(math.pi / 64) * 2 * 0.1, rel=1e-6)
    assert wall.normal is None  # its normals cancel: no mean normal
    assert len(part.edges) == 2
    for edge in part.edges:
        assert edge.closed and set(edge.faces) - {1} and 1 in edge.faces
        pts = part.edge_points(edge.id, 1e-4)
        assert len(pts) == 65 and np.allclose(pts[0], pts[-1])
        assert np.allclose(np.hypot(pts[:, 0], pts[:, 1]), 0.03, atol=TOL)
        assert edge.length == pytest.approx(64 * 2 * 0.03 * math.sin(math.pi / 64), rel=1e-6)
    # a threshold below the facet angle splits the wall into its 64 facets (+ 2 caps)
    split = read_mesh_part(path, scale=1.0, feature_angle=math.radians(5.0))
    assert len(split.faces) == 66


def test_normals_are_outward_and_interpolated_across_the_region(tmp_path: Path) -> None:
    cylinder = trimesh.creation.cylinder(radius=0.03, height=0.1, sections=64)
    part = read_mesh_part(write(cylinder, tmp_path / "cyl.stl"), scale=1.0)
    angle = np.linspace(0.0, 2 * math.pi, 50)
    points = np.column_stack([0.05 * np.cos(angle), 0.05 * np.sin(angle), np.zeros(50)])
    normals = part.face_normals(1, points)
    assert np.allclose(np.linalg.norm(normals, axis=1), 1.0, atol=1e-9)
    # interpolated vertex normals: radial at the nearest point of the wall, where a facet's
    # own normal is off by up to half the facet angle (2.8°)
    foot, _, _ = trimesh.proximity.closest_point(cylinder, points)
    radial = np.column_stack([foot[:, :2], np.zeros(50)])
    radial /= np.linalg.norm(radial, axis=1, keepdims=True)
    error = np.degrees(np.arccos(np.clip(np.sum(normals * radial, axis=1), -1, 1)))
    assert error.max() < 1e-3
    # a facet's own normal would be off by up to 2.8° between its vertices
    assert part.face_normals(1, np.zeros((0, 3))).shape == (0, 3)
    top = next(f for f in part.faces if f.normal is not None and f.normal[2] > 0.5)
    assert np.allclose(part.face_normals(top.id, [[0.01, 0.0, 0.3]]), [[0, 0, 1]], atol=1e-9)


def test_an_inside_out_mesh_is_turned_outward(tmp_path: Path) -> None:
    box = trimesh.creation.box(extents=(0.2, 0.1, 0.05))
    inverted = trimesh.Trimesh(box.vertices, box.faces[:, ::-1], process=False)
    assert inverted.volume < 0
    part = read_mesh_part(write(inverted, tmp_path / "inverted.stl"), scale=1.0)
    for face in part.faces:
        assert np.dot(face.normal, face.centroid) > 0
        assert np.dot(part.face_normals(face.id, face.centroid[None])[0], face.centroid) > 0
    tess = part.tessellation(1e-4)
    assert trimesh.Trimesh(tess.vertices, tess.triangles).volume == pytest.approx(1e-3)


def test_nearest_face_and_its_distance(box: Path) -> None:
    part = read_mesh_part(box, scale=1.0)
    face, distance = part.nearest_face(np.array([0.0, 0.0, 0.125]))
    assert part.faces[face - 1].normal == pytest.approx([0, 0, 1])
    assert distance == pytest.approx(0.1, abs=TOL)
    face, distance = part.nearest_face(np.array([0.09, 0.0, 0.0]))  # inside, nearest +x
    assert part.faces[face - 1].normal == pytest.approx([1, 0, 0])
    assert distance == pytest.approx(0.01, abs=TOL)


@pytest.mark.parametrize("make", [pipe_on_disc, pipe_on_plate])
def test_pipe_on_plate_fillet_is_one_closed_boundary(make, tmp_path: Path) -> None:
    part = read_mesh_part(write(make(), tmp_path / "pipe.stl"), scale=1.0)
    # plate top (with the pipe's foot), bottom, sides (4 of a box, 1 of a disc); pipe wall, cap
    assert len(part.faces) == (5 if make is pipe_on_disc else 8)
    plate, _ = part.nearest_face(np.array([0.06, 0.0, 0.0005]))
    pipe, _ = part.nearest_face(np.array([0.0305, 0.0, 0.02]))
    assert part.faces[plate - 1].normal == pytest.approx([0, 0, 1])
    assert part.faces[pipe - 1].normal is None
    (seam,) = part.shared_edges(plate, pipe)
    edge = part.edges[seam - 1]
    assert edge.closed and edge.faces == tuple(sorted((plate, pipe)))
    pts = part.edge_points(seam, 1e-5)
    assert len(pts) == 65
    assert np.allclose(pts[:, 2], 0.0, atol=TOL)
    assert np.allclose(np.hypot(pts[:, 0], pts[:, 1]), 0.03, atol=TOL)
    assert edge.length == pytest.approx(64 * 2 * 0.03 * math.sin(math.pi / 64), rel=1e-6)
    # the weld normals the seam would use: the plate's +z, the pipe's radial
    assert np.allclose(part.face_normals(plate, pts), [0, 0, 1], atol=1e-9)
    radial = np.column_stack([pts[:, :2] / 0.03, np.zeros(len(pts))])
    assert np.allclose(part.face_normals(pipe, pts), radial, atol=1e-6)
    # every boundary is closed: round the pipe's cap, its foot, and the plate's
    if make is pipe_on_disc:
        assert len(part.edges) == 4 and all(e.closed for e in part.edges)


def test_an_open_mesh_has_its_border_as_an_edge(tmp_path: Path) -> None:
    cylinder = trimesh.creation.cylinder(radius=0.03, height=0.1, sections=32)
    keep = np.abs(cylinder.triangles_center[:, 2] - 0.05) > 1e-9  # drop the top cap
    cup = trimesh.Trimesh(cylinder.vertices, cylinder.faces[keep])
    part = read_mesh_part(write(cup, tmp_path / "cup.stl"), scale=1.0)
    assert len(part.faces) == 2
    border = [e for e in part.edges if len(e.faces) == 1]
    assert len(border) == 1 and border[0].closed
    assert np.allclose(part.edge_points(border[0].id, 1e-4)[:, 2], 0.05, atol=TOL)


def one_line(exc: pytest.ExceptionInfo[CaseError]) -> str:
    text = exc.value.one_line()
    assert "\n" not in text
    return text


def test_refusals_are_one_line(box: Path, tmp_path: Path) -> None:
    with pytest.raises(CaseError, match=r"part\.scale") as exc:
        read_mesh_part(box)
    assert "carries no unit" in one_line(exc)
    with pytest.raises(CaseError, match="scale must be > 0") as exc:
        read_mesh_part(box, scale=0.0)
    for angle in (0.0, math.pi, math.nan):
        with pytest.raises(CaseError, match=r"part\.feature_angle: .* in \(0, π\) rad"):
            read_mesh_part(box, scale=1.0, feature_angle=angle)
    with pytest.raises(CaseError, match="not found") as exc:
        read_mesh_part(tmp_path / "missing.stl", scale=1.0, case_file="case.yaml")
    assert one_line(exc).startswith("case.yaml: part.file: ")
    with pytest.raises(CaseError, match="is a directory"):
        read_mesh_part(tmp_path, scale=1.0)
    garbage = tmp_path / "garbage.stl"
    garbage.write_bytes(b"\x00\x01 not a mesh")
    with pytest.raises(CaseError, match=r"garbage\.stl") as exc:
        read_mesh_part(garbage, scale=1.0)
    one_line(exc)
    empty = tmp_path / "empty.stl"
    empty.write_text("solid empty\nendsolid empty\n")
    with pytest.raises(CaseError, match="no triangles") as exc:
        read_mesh_part(empty, scale=1.0)
    one_line(exc)


def test_a_non_manifold_mesh_is_refused(tmp_path: Path) -> None:
    # three triangles on one edge: a fin
    vertices = [[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, -1, 0], [0, 0, 1]]
    fin = trimesh.Trimesh(vertices, [[0, 1, 2], [1, 0, 3], [0, 1, 4]], process=False)
    with pytest.raises(CaseError, match=r"not a manifold: .* triangles: 1 ") as exc:
        read_mesh_part(write(fin, tmp_path / "fin.ply"), scale=1.0)
    one_line(exc)


def test_a_non_orientable_mesh_is_refused(tmp_path: Path) -> None:
    # a Möbius strip: 12 quads round, the last joined with a half twist
    n = 12
    t = np.linspace(0.0, 2 * math.pi, n, endpoint=False)
    ring = []
    for s in (-0.1, 0.1):
        r = 1 + s * np.cos(t / 2)
        ring.append(np.column_stack([r * np.cos(t), r * np.sin(t), s * np.sin(t / 2)]))
    vertices = np.vstack(ring)
    faces = []
    for i in range(n):
        a, b = i, n + i
        c, d = (i + 1, n + i + 1) if i + 1 < n else (n, 0)
        faces += [[a, c, b], [b, c, d]]
    strip = trimesh.Trimesh(vertices, faces, process=False)
    with pytest.raises(CaseError, match="cannot be oriented") as exc:
        read_mesh_part(write(strip, tmp_path / "strip.ply"), scale=1.0)
    one_line(exc)


def test_unknown_ids_are_refused(box: Path) -> None:
    part = read_mesh_part(box, scale=1.0)
    with pytest.raises(CaseError, match=r"face 7 does not exist: .* faces 1 to 6"):
        part.face_normals(7, np.zeros((1, 3)))
    with pytest.raises(CaseError, match="edge 13 does not exist"):
        part.edge_points(13, 1e-4)
    with pytest.raises(CaseError, match="face 0 does not exist"):
        part.shared_edges(0, 1)
