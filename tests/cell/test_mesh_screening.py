"""A mesh body is screened as boxes around its triangles: never farther than the exact
distance (coal), and a tool in the corner of a large part is not inside the part's box."""

from __future__ import annotations

import numpy as np
import pytest
import trimesh

from trackplan.cell import _kernels
from trackplan.cell.exact import ExactDistance
from trackplan.cell.model import Body, Shape


def t_joint() -> Body:
    """A T-joint as one mesh: a base plate 0.3 × 0.2 × 0.01 m (top at z = 0) and a web
    0.3 × 0.01 × 0.1 m standing on it along x."""
    base = trimesh.creation.box([0.3, 0.2, 0.01])
    base.apply_translation([0.0, 0.0, -0.005])
    web = trimesh.creation.box([0.3, 0.01, 0.1])
    web.apply_translation([0.0, 0.0, 0.05])
    mesh = trimesh.util.concatenate([base, web])
    return Body("part", Shape.MESH, np.eye(4), vertices=mesh.vertices, faces=mesh.faces)


def box_distance(T: np.ndarray, half: np.ndarray, a: np.ndarray, b: np.ndarray, r: float) -> float:
    """The kernel's capsule–box distance (box at T with half extents ``half``)."""
    T_box_world = np.ascontiguousarray(np.linalg.inv(T)[:3])
    return float(_kernels.capsule_body(a, b, r, int(Shape.BOX), half, T_box_world))


def screened(body: Body, a: np.ndarray, b: np.ndarray, radius: float) -> float:
    """The least screened distance over the body's boxes."""
    return min(box_distance(T, half, a, b, radius) for T, half in body.screening_boxes())


def test_a_torch_in_the_corner_is_outside_the_boxes_and_never_farther_than_coal() -> None:
    body = t_joint()
    # a torch 20 mm out of the corner along the 45° bisector, pointing into it
    direction = np.array([0.0, -1.0, 1.0]) / np.sqrt(2.0)
    a = np.array([0.0, -0.005, 0.0]) + 0.02 * direction
    b = a + 0.2 * direction
    radius = 0.005
    exact = ExactDistance().capsule_body(a, b, radius, body, np.eye(4))
    one_box = box_distance(*body.screening_box(), a, b, radius)
    many = screened(body, a, b, radius)
    assert one_box < 0.0  # the part's bounding box swallows the torch
    assert 0.0 < many <= exact + 1e-9  # its boxes do not, and never exceed the exact distance
    assert len(body.screening_boxes()) > 1


@pytest.mark.parametrize("seed", range(5))
def test_screened_mesh_distances_never_exceed_the_exact_ones(seed: int) -> None:
    rng = np.random.default_rng(seed)
    body = t_joint()
    oracle = ExactDistance()
    for _ in range(40):
        a = rng.uniform([-0.2, -0.15, -0.05], [0.2, 0.15, 0.15])
        b = a + rng.uniform(-0.1, 0.1, 3)
        radius = float(rng.uniform(0.0, 0.02))
        exact = oracle.capsule_body(a, b, radius, body, np.eye(4))
        if exact > 0.0:  # apart: the boxes enclose every triangle
            assert screened(body, a, b, radius) <= exact + 1e-9
