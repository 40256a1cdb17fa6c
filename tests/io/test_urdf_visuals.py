"""A URDF's <visual> meshes read onto the robot (trackplan.io.urdf_geometry), decimated."""

from __future__ import annotations

import dataclasses
import shutil
from pathlib import Path

import numpy as np
import pytest
import trimesh

from trackplan.errors import CaseError
from trackplan.io.robot_file import load_robot
from trackplan.io.urdf_robot import robot_from_urdf_file
from trackplan.robots.builtin import puma560
from trackplan.robots.visuals import LinkVisual, decimate, decimate_visuals, n_triangles

FIXTURE = Path(__file__).resolve().parents[1] / "fixtures" / "meshed_robot"
URDF = FIXTURE / "meshed_robot.urdf"


def _stl_triangles(name: str) -> int:
    return len(trimesh.load(FIXTURE / "meshes" / f"{name}.stl", force="mesh").faces)


def test_a_urdf_robot_reads_its_visual_meshes_with_their_colours():
    robot = robot_from_urdf_file(URDF, assume_limits=True)
    assert robot.visuals is not None
    by_link = {visual.name: visual for visual in robot.visuals}
    assert {name: v.frame for name, v in by_link.items()} == {"l0": 0, "l2": 2, "l3": 3, "l5": 5}
    for name, visual in by_link.items():
        assert visual.n_triangles == _stl_triangles(name)  # under the budget: kept whole
    # the named top-level material (0.35 0.37 0.4) and an inline colour (0.9 0.45 0.05)
    assert by_link["l0"].color == "#595e66"
    assert by_link["l2"].color == "#e6730d"
    # the upper arm's capsule (radius 0.06 m) runs along x of its link frame from the
    # shoulder to the elbow, 0.4318 m away: the visual's origin and rpy are applied
    low, high = by_link["l2"].vertices.min(axis=0), by_link["l2"].vertices.max(axis=0)
    np.testing.assert_allclose(low, [-0.06, -0.06, -0.06], atol=4e-3)  # facets
    np.testing.assert_allclose(high, [0.4318 + 0.06, 0.06, 0.06], atol=4e-3)


def test_a_robot_file_pointing_at_the_urdf_gets_the_visuals(tmp_path):
    file = tmp_path / "meshed.yaml"
    file.write_text(
        f"name: meshed\nurdf: {URDF}\n"
        "limits: {acceleration: [10, 10, 10, 10, 10, 10], jerk: [100, 100, 100, 100, 100, 100]}\n"
    )
    robot = load_robot(file)
    assert robot.visuals is not None and n_triangles(robot.visuals) == 1088


def test_a_missing_visual_mesh_leaves_the_robot_without_visuals(tmp_path):
    copy = tmp_path / "robot"
    shutil.copytree(FIXTURE, copy)
    (copy / "meshes" / "l3.stl").unlink()
    robot = robot_from_urdf_file(copy / "meshed_robot.urdf", assume_limits=True)
    assert robot.visuals is None  # drawn from capsules or lines; planning unaffected
    (copy / "meshes" / "l2.stl").write_text("not a mesh")
    assert robot_from_urdf_file(copy / "meshed_robot.urdf", assume_limits=True).visuals is None


def test_visuals_on_a_frame_beyond_the_chain_are_refused():
    visual = LinkVisual(frame=7, vertices=np.eye(3), faces=[[0, 1, 2]], name="l7")
    with pytest.raises(CaseError, match=r"link visuals must be on frames 0\.\.6"):
        dataclasses.replace(puma560(), visuals=(visual,))


def test_vertex_clustering_decimates_to_the_target():
    sphere = trimesh.creation.icosphere(subdivisions=4, radius=0.1)  # 5120 triangles
    for target in (2000, 500, 100):
        vertices, faces = decimate(sphere.vertices, sphere.faces, target, quadric=False)
        assert 0.3 * target < len(faces) <= target
        assert faces.max() < len(vertices)
        # still the sphere: every vertex within a grid cell of its surface
        radii = np.linalg.norm(vertices, axis=1)
        assert np.all(np.abs(radii - 0.1) < 0.03)
    unchanged = decimate(sphere.vertices, sphere.faces, 6000, quadric=False)
    assert len(unchanged[1]) == len(sphere.faces)


def test_the_robot_visuals_are_decimated_to_a_total_budget():
    visuals = robot_from_urdf_file(URDF, assume_limits=True).visuals
    assert visuals is not None
    kept = decimate_visuals(visuals, 400, quadric=False)
    assert n_triangles(kept) <= 400
    assert [v.name for v in kept] == [v.name for v in visuals]  # every link keeps a mesh


@pytest.mark.parametrize("kind", ["obj", "dae"])
def test_obj_and_dae_visual_meshes_are_read(tmp_path, kind):
    if kind == "dae":
        pytest.importorskip("collada", reason="trimesh reads DAE with pycollada")
    copy = tmp_path / "robot"
    shutil.copytree(FIXTURE, copy)
    mesh = trimesh.load(copy / "meshes" / "l2.stl", force="mesh")
    mesh.export(copy / "meshes" / f"l2.{kind}")
    urdf = copy / "meshed_robot.urdf"
    urdf.write_text(urdf.read_text().replace("meshes/l2.stl", f"meshes/l2.{kind}"))
    robot = robot_from_urdf_file(urdf, assume_limits=True)
    assert robot.visuals is not None
    upper_arm = next(v for v in robot.visuals if v.name == "l2")
    assert upper_arm.n_triangles == len(mesh.faces)
    reference = robot_from_urdf_file(URDF, assume_limits=True).visuals
    assert reference is not None
    expected = next(v for v in reference if v.name == "l2")
    # the same surface, placed the same way (the formats may order the vertices differently)
    np.testing.assert_allclose(
        upper_arm.vertices.min(axis=0), expected.vertices.min(axis=0), atol=1e-6
    )
    np.testing.assert_allclose(
        upper_arm.vertices.max(axis=0), expected.vertices.max(axis=0), atol=1e-6
    )


def test_box_cylinder_and_sphere_visuals_are_tessellated(tmp_path):
    copy = tmp_path / "robot"
    shutil.copytree(FIXTURE, copy)
    urdf = copy / "meshed_robot.urdf"
    text = urdf.read_text()
    for name, shape in (
        ("l0", '<box size="0.2 0.3 0.4"/>'),
        ("l3", '<cylinder radius="0.05" length="0.4"/>'),
        ("l5", '<sphere radius="0.05"/>'),
    ):
        text = text.replace(f'<mesh filename="meshes/{name}.stl"/>', shape)
    urdf.write_text(text)
    robot = robot_from_urdf_file(urdf, assume_limits=True)
    assert robot.visuals is not None
    by_link = {visual.name: visual for visual in robot.visuals}
    box = by_link["l0"].vertices  # centred 0.25 m below the base frame
    np.testing.assert_allclose(box.min(axis=0), [-0.1, -0.15, -0.45], atol=1e-9)
    np.testing.assert_allclose(box.max(axis=0), [0.1, 0.15, -0.05], atol=1e-9)
    np.testing.assert_allclose(np.linalg.norm(by_link["l5"].vertices, axis=1), 0.05, atol=1e-9)
    assert by_link["l3"].n_triangles > 20
