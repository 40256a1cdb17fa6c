"""Capsules that enclose boxes, cylinders, spheres and point clouds (meshes)."""

from __future__ import annotations

import numpy as np
import trimesh
from hypothesis import given, settings
from hypothesis import strategies as st

from trackplan.robots.collision import (
    box_capsule,
    cylinder_capsule,
    points_capsule,
    sphere_capsule,
)

TOL = 1e-9
sizes = st.floats(0.001, 2.0)
seeds = st.integers(0, 2**32 - 1)


def distance_to_segment(points: np.ndarray, segment: np.ndarray) -> np.ndarray:
    """Distance of each point (N, 3) from the segment (2, 3): the oracle, written out."""
    a, b = segment
    ab = b - a
    length2 = float(ab @ ab)
    t = np.zeros(len(points)) if length2 == 0.0 else np.clip((points - a) @ ab / length2, 0, 1)
    return np.linalg.norm(points - (a + t[:, None] * ab), axis=1)


def inside_box(rng: np.random.Generator, half: np.ndarray, n: int) -> np.ndarray:
    """The corners, then random points of the box (and of its faces)."""
    corners = np.array(np.meshgrid(*[[-h, h] for h in half])).reshape(3, -1).T
    points = rng.uniform(-half, half, (n, 3))
    faces = rng.uniform(-half, half, (n, 3))
    axis = rng.integers(0, 3, n)
    faces[np.arange(n), axis] = half[axis] * rng.choice([-1.0, 1.0], n)
    return np.concatenate([corners, points, faces])


def inside_cylinder(rng: np.random.Generator, radius: float, length: float, n: int) -> np.ndarray:
    """Points on both rims, then random points of the cylinder (axis z, centred)."""
    angle = rng.uniform(0, 2 * np.pi, n)
    rims = np.stack(
        [radius * np.cos(angle), radius * np.sin(angle), 0.5 * length * rng.choice([-1, 1], n)], 1
    )
    r = radius * np.sqrt(rng.uniform(0, 1, n))
    angle = rng.uniform(0, 2 * np.pi, n)
    z = rng.uniform(-0.5 * length, 0.5 * length, n)
    return np.concatenate([rims, np.stack([r * np.cos(angle), r * np.sin(angle), z], 1)])


@settings(max_examples=200, deadline=None)
@given(sizes, sizes, sizes, seeds)
def test_box_capsule_encloses_the_box(hx: float, hy: float, hz: float, seed: int) -> None:
    half = np.array([hx, hy, hz])
    segment, radius = box_capsule(half)
    points = inside_box(np.random.default_rng(seed), half, 200)
    distance = distance_to_segment(points, segment)
    assert distance.max() <= radius + TOL
    # tight: the corners lie on the capsule's surface
    assert distance.max() >= radius - TOL
    assert np.linalg.norm(segment[1] - segment[0]) == 2 * half.max()


@settings(max_examples=200, deadline=None)
@given(sizes, sizes, seeds)
def test_cylinder_capsule_encloses_the_cylinder(radius: float, length: float, seed: int) -> None:
    segment, r = cylinder_capsule(radius, length)
    points = inside_cylinder(np.random.default_rng(seed), radius, length, 200)
    distance = distance_to_segment(points, segment)
    assert distance.max() <= r + TOL
    assert distance.max() >= r - TOL  # the rims touch it


def test_sphere_capsule_is_the_sphere() -> None:
    segment, radius = sphere_capsule(0.3)
    assert radius == 0.3 and not np.any(segment)


@settings(max_examples=200, deadline=None)
@given(st.integers(1, 60), seeds, st.floats(0.01, 3.0))
def test_points_capsule_encloses_every_point_and_is_tight(n: int, seed: int, scale: float) -> None:
    rng = np.random.default_rng(seed)
    stretch = rng.normal(size=(3, 3)) * scale  # an elongated, rotated, sheared cloud
    points = rng.normal(size=(n, 3)) @ stretch + rng.normal(size=3)
    segment, radius = points_capsule(points)
    distance = distance_to_segment(points, segment)
    assert distance.max() <= radius + TOL * max(1.0, radius)
    # the smallest radius about this axis: some point lies on the cylinder part
    axis = segment[1] - segment[0]
    if np.linalg.norm(axis) > 0:
        u = axis / np.linalg.norm(axis)
        off_axis = np.linalg.norm(np.cross(points - segment[0], u), axis=1)
        assert abs(off_axis.max() - radius) <= TOL * max(1.0, radius)


@settings(max_examples=50, deadline=None)
@given(sizes, sizes, sizes, seeds)
def test_mesh_capsule_encloses_the_solid(hx: float, hy: float, hz: float, seed: int) -> None:
    """A box mesh's capsule holds the whole box (a capsule is convex), and a cylinder's."""
    rng = np.random.default_rng(seed)
    half = np.array([hx, hy, hz])
    transform = trimesh.transformations.random_rotation_matrix(rng.random(3))
    mesh = trimesh.creation.box(extents=2 * half, transform=transform)
    segment, radius = points_capsule(mesh.vertices)
    points = inside_box(rng, half, 200) @ transform[:3, :3].T
    assert distance_to_segment(points, segment).max() <= radius + TOL
    tube = trimesh.creation.cylinder(radius=hx, height=2 * hy, sections=64)
    segment, radius = points_capsule(tube.vertices)
    # the 64-gon is inscribed in the circle: the points of its own surface are enclosed
    assert distance_to_segment(tube.vertices, segment).max() <= radius + TOL
