"""The seam derivation on analytic parts: exact pieces, weld normals, chains and refusals."""

from __future__ import annotations

import numpy as np
import pytest

from tests.cad.parts import (
    CURVATURE,
    LENGTH,
    RADIUS,
    THICKNESS,
    AnalyticEdge,
    curved_wall,
    line_edges,
    pipe_on_plate,
    t_joint,
)
from trackplan.cad.part import Circle
from trackplan.cad.seams import (
    NEAR_DISTANCE,
    CadSeam,
    FaceRef,
    SeamError,
    derive_seam,
    seam_summary,
)
from trackplan.paths import NominalPath
from trackplan.paths.specs import ArcSpec, LineSpec, PointsSpec
from trackplan.tool.weld_normal import ArcNormal, PointsNormal

TOL = 1e-4
ANGLE = np.radians(0.1)  # normals within 0.1° of the analytic ones
POSITION = 1e-8  # m: exact pieces


def _angles(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    a = a / np.linalg.norm(a, axis=1, keepdims=True)
    b = b / np.linalg.norm(b, axis=1, keepdims=True)
    return np.arccos(np.clip(np.sum(a * b, axis=1), -1.0, 1.0))


def _faces(a: int, b: int) -> CadSeam:
    return CadSeam(between=(FaceRef(face=a), FaceRef(face=b)))


def _foot_bisector(points: np.ndarray) -> np.ndarray:
    radial = points * np.array([1.0, 1.0, 0.0])
    radial /= np.linalg.norm(radial, axis=1, keepdims=True)
    return radial + np.array([0.0, 0.0, 1.0])


def test_pipe_foot_is_one_exact_closed_arc_whose_normal_turns_with_the_pipe() -> None:
    start, segments = derive_seam(pipe_on_plate(), _faces(1, 2), TOL)
    assert np.allclose(start, [RADIUS, 0, 0], atol=POSITION)
    (arc,) = segments
    assert isinstance(arc, ArcSpec) and arc.weld_normal is not None
    assert np.allclose(arc.center, 0, atol=POSITION) and np.allclose(arc.normal, [0, 0, 1])
    assert arc.angle == pytest.approx(2 * np.pi, abs=1e-12)
    field = ArcNormal.from_arc(start, arc, arc.weld_normal)
    theta = np.linspace(0, 2 * np.pi, 37)
    points = np.stack([RADIUS * np.cos(theta), RADIUS * np.sin(theta), 0 * theta], axis=1)
    assert _angles(field(points, theta * RADIUS), _foot_bisector(points)).max() < ANGLE
    summary = seam_summary(start, segments)
    assert summary["closed"] is True
    assert summary["length"] == pytest.approx(2 * np.pi * RADIUS, rel=1e-9)
    assert summary["kinds"] == {"line": 0, "arc": 1, "points": 0}


def test_near_points_pick_the_nearest_faces() -> None:
    seam = CadSeam(
        between=(
            FaceRef(near=np.array([0.08, 0.0, 0.0005])),
            FaceRef(near=np.array([0.0605, 0, 0.02])),
        )
    )
    _, (arc,) = derive_seam(pipe_on_plate(), seam, TOL)
    assert isinstance(arc, ArcSpec) and arc.weld_normal is not None
    assert np.allclose(arc.weld_normal, np.array([1, 0, 1]) / np.sqrt(2), atol=1e-12)


def test_reverse_runs_the_arc_the_other_way_from_the_same_point() -> None:
    seam = CadSeam(between=(FaceRef(face=1), FaceRef(face=2)), reverse=True)
    start, (arc,) = derive_seam(pipe_on_plate(), seam, TOL)
    assert isinstance(arc, ArcSpec) and arc.weld_normal is not None
    assert np.allclose(start, [RADIUS, 0, 0], atol=POSITION)
    assert arc.angle == pytest.approx(-2 * np.pi, abs=1e-12)
    field = ArcNormal.from_arc(start, arc, arc.weld_normal)
    point = np.array([[0.0, -RADIUS, 0.0]])  # a quarter turn clockwise
    assert _angles(field(point, np.zeros(1)), _foot_bisector(point)).max() < ANGLE


def test_joint_face_gives_the_first_faces_normal() -> None:
    seam = CadSeam(between=(FaceRef(face=2), FaceRef(face=1)), joint="face")
    _, (arc,) = derive_seam(pipe_on_plate(), seam, TOL)
    assert isinstance(arc, ArcSpec) and arc.weld_normal is not None
    assert np.allclose(arc.weld_normal, [1, 0, 0], atol=1e-12)  # the wall's radial normal


def test_t_joint_fillet_is_a_straight_piece_with_the_constant_bisector() -> None:
    start, (piece,) = derive_seam(t_joint(), _faces(1, 3), TOL)
    h = THICKNESS / 2
    assert np.allclose(start, [h, 0, 0], atol=POSITION)
    assert isinstance(piece, PointsSpec) and piece.normals is not None
    assert np.allclose(piece.points, [[h, LENGTH / 2, 0], [h, LENGTH, 0]], atol=POSITION)
    assert _angles(piece.normals, np.array([[1.0, 0, 1]] * 2)).max() < ANGLE
    nominal = NominalPath.from_specs(start, (piece,))
    assert nominal.length == pytest.approx(LENGTH, rel=1e-9)  # a straight line
    summary = seam_summary(start, (piece,))
    assert summary["kinds"] == {"line": 1, "arc": 0, "points": 0} and not summary["closed"]
    field = PointsNormal.from_points(start, piece)
    inside = field(np.zeros((3, 3)), np.array([0.0, 0.05, 0.2]))
    assert _angles(inside, np.array([[1.0, 0, 1]] * 3)).max() < 1e-9


def test_edges_without_a_normal_are_plain_lines_and_reverse_flips_them() -> None:
    start, (line,) = derive_seam(t_joint(), CadSeam(edges=(1,)), TOL)
    assert isinstance(line, LineSpec)
    assert np.allclose(start, [THICKNESS / 2, 0, 0]) and np.allclose(line.to[1], LENGTH)
    start, (line,) = derive_seam(t_joint(), CadSeam(edges=(1,), reverse=True), TOL)
    assert isinstance(line, LineSpec)
    assert np.allclose(start[1], LENGTH) and np.allclose(line.to, [THICKNESS / 2, 0, 0])


def test_edges_with_a_normal_between_two_faces_carry_the_bisector() -> None:
    seam = CadSeam(edges=(2,), normal=(FaceRef(face=1), FaceRef(face=2)))
    _, (piece,) = derive_seam(t_joint(), seam, TOL)
    assert isinstance(piece, PointsSpec) and piece.normals is not None
    assert _angles(piece.normals, np.array([[-1.0, 0, 1]] * 2)).max() < ANGLE
    seam = CadSeam(edges=(2,), normal=(FaceRef(face=2),))
    _, (piece,) = derive_seam(t_joint(), seam, TOL)
    assert isinstance(piece, PointsSpec) and np.allclose(piece.normals, [[-1, 0, 0]] * 2)


def test_a_curved_edge_is_sampled_within_a_tenth_of_the_tolerance_with_bisectors() -> None:
    part = curved_wall()
    start, (piece,) = derive_seam(part, _faces(1, 2), TOL)
    assert isinstance(piece, PointsSpec) and piece.normals is not None
    assert part.queried == [pytest.approx(TOL / 10)]
    points = np.vstack([start, piece.points])
    # on the analytic curve y = a x², z = 0, from x = -50 mm to 50 mm
    assert np.abs(points[:, 1] - CURVATURE * points[:, 0] ** 2).max() < 1e-12
    assert np.allclose(points[[0, -1], 0], [-0.05, 0.05], atol=POSITION)
    wall = np.stack(
        [2 * CURVATURE * piece.points[:, 0], -np.ones(len(piece.points)), 0 * piece.points[:, 0]], 1
    )
    wall /= np.linalg.norm(wall, axis=1, keepdims=True)
    assert _angles(piece.normals, wall + np.array([0.0, 0.0, 1.0])).max() < ANGLE
    # the chord between samples stays within a tenth of the tolerance of the curve
    middle = 0.5 * (points[1:] + points[:-1])
    assert np.abs(middle[:, 1] - CURVATURE * middle[:, 0] ** 2).max() <= TOL / 10


def test_a_circle_whose_normals_do_not_turn_with_it_is_sampled() -> None:
    part = pipe_on_plate()
    part.face_list[1].normal = lambda p: np.repeat([[1.0, 0, 0]], len(p), axis=0)
    start, (piece,) = derive_seam(part, _faces(1, 2), TOL)
    assert isinstance(piece, PointsSpec) and piece.normals is not None
    assert _angles(piece.normals, np.array([[1.0, 0, 1]] * len(piece.normals))).max() < 1e-9
    assert np.allclose(piece.points[-1], start, atol=POSITION)  # still closed


def test_edges_chain_end_to_end_whatever_their_order_and_direction() -> None:
    part = line_edges(
        ((0.1, 0, 0), (0.2, 0, 0)),  # 1
        ((0.3, 0, 0), (0.2, 0, 0)),  # 2: runs backwards
        ((0.0, 0, 0), (0.1, 0, 0)),  # 3: before edge 1
    )
    start, segments = derive_seam(part, CadSeam(edges=(1, 2, 3)), TOL)
    assert np.allclose(start, [0, 0, 0])
    ends = [segment.to[0] for segment in segments if isinstance(segment, LineSpec)]
    assert ends == pytest.approx([0.1, 0.2, 0.3])
    start, segments = derive_seam(part, CadSeam(edges=(1, 2, 3), reverse=True), TOL)
    assert np.allclose(start, [0.3, 0, 0])
    assert [s.to[0] for s in segments if isinstance(s, LineSpec)] == pytest.approx([0.2, 0.1, 0])


def test_a_closed_chain_is_a_closed_seam_from_the_first_edges_start() -> None:
    square = [(0, 0, 0), (0.1, 0, 0), (0.1, 0.1, 0), (0, 0.1, 0)]
    part = line_edges(*[(square[i], square[(i + 1) % 4]) for i in (2, 0, 3, 1)])
    start, segments = derive_seam(part, CadSeam(edges=(2, 1, 3, 4)), TOL)
    assert np.allclose(start, square[0])  # edge 2 runs from the first corner
    assert np.allclose(segments[-1].to, start)  # type: ignore[union-attr]
    summary = seam_summary(start, segments)
    assert summary["closed"] is True and summary["length"] == pytest.approx(0.4)


@pytest.mark.parametrize(
    ("segments", "words"),
    [
        ([((0, 0, 0), (0.1, 0, 0)), ((0.101, 0, 0), (0.2, 0, 0))], ["gap", "1 mm"]),
        (
            [((0, 0, 0), (0.1, 0, 0)), ((0.1, 0, 0), (0.2, 0, 0)), ((0.1, 0, 0), (0.1, 0.1, 0))],
            ["branch", "edges 1, 2, 3"],
        ),
    ],
)
def test_gaps_and_branches_are_refused(segments: list, words: list[str]) -> None:
    part = line_edges(*segments)
    with pytest.raises(SeamError) as error:
        derive_seam(part, CadSeam(edges=tuple(range(1, len(segments) + 1))), TOL)
    assert error.value.where == ("edges",)
    assert all(word in error.value.message for word in words), error.value.message


def test_a_gap_just_over_a_micrometre_is_refused_and_just_under_chains() -> None:
    for offset, chains in ((0.9e-6, True), (1.1e-6, False)):
        part = line_edges(((0, 0, 0), (0.1, 0, 0)), ((0.1 + offset, 0, 0), (0.2, 0, 0)))
        if chains:
            derive_seam(part, CadSeam(edges=(1, 2)), TOL)
        else:
            with pytest.raises(SeamError, match="gap"):
                derive_seam(part, CadSeam(edges=(1, 2)), TOL)


def test_a_near_point_too_far_from_every_face_is_refused() -> None:
    far = np.array([0.0, 0.0, NEAR_DISTANCE + 0.001 + 0.1])  # 6 mm above the pipe top
    seam = CadSeam(between=(FaceRef(face=1), FaceRef(near=far)))
    with pytest.raises(SeamError) as error:
        derive_seam(pipe_on_plate(), seam, TOL)
    assert error.value.where == ("between", 1, "near")
    assert "6 mm away, more than 5 mm" in error.value.message


@pytest.mark.parametrize(
    ("seam", "where", "text"),
    [
        (_faces(1, 99), ("between", 1, "face"), "face 99 does not exist (the part has 3 faces"),
        (_faces(1, 3), ("between",), "faces 1 and 3 share no edge"),
        (_faces(2, 2), ("between",), "both name face 2"),
        (CadSeam(edges=(1, 7)), ("edges", 1), "edge 7 does not exist (the part has 2 edges"),
        (CadSeam(edges=(1, 1)), ("edges",), "named twice"),
        (CadSeam(edges=(1,), normal=(FaceRef(face=0),)), ("normal", "face"), "face 0 does not"),
    ],
)
def test_bad_ids_are_refused_at_their_key(seam: CadSeam, where: tuple, text: str) -> None:
    with pytest.raises(SeamError) as error:
        derive_seam(pipe_on_plate(), seam, TOL)
    assert error.value.where == where
    assert text in error.value.message


def test_faces_with_opposite_normals_have_no_fillet_bisector() -> None:
    part = t_joint()
    part.edge_list.append(AnalyticEdge("line", part.edge_list[0].curve, (2, 3)))
    with pytest.raises(SeamError, match="no fillet bisector"):
        derive_seam(part, _faces(2, 3), TOL)


def test_a_closed_edge_among_others_is_a_branch() -> None:
    part = pipe_on_plate()
    part.edge_list.append(
        AnalyticEdge(
            "line", lambda t: np.outer(1 - t, [RADIUS, 0, 0]) + np.outer(t, [0.1, 0, 0]), (1, 2)
        )
    )
    assert isinstance(part.edge_list[0].circle, Circle)
    with pytest.raises(SeamError, match="closed"):
        derive_seam(part, CadSeam(edges=(1, 3)), TOL)


def test_an_arc_turns_the_way_its_edge_runs_whatever_the_sense_of_the_given_axis() -> None:
    part = pipe_on_plate()
    given = part.edge_list[0].circle
    assert given is not None
    part.edge_list[0].circle = Circle(
        given.center, -given.axis, given.radius, given.angle, given.start
    )
    _, (arc,) = derive_seam(part, _faces(1, 2), TOL)
    assert isinstance(arc, ArcSpec) and np.allclose(arc.normal, [0, 0, 1])
    assert arc.angle == pytest.approx(2 * np.pi)


def test_a_circle_its_edge_points_leave_is_sampled() -> None:
    part = pipe_on_plate()
    given = part.edge_list[0].circle
    assert given is not None
    part.edge_list[0].circle = Circle(given.center, given.axis, 0.05, given.angle, given.start)
    _, (piece,) = derive_seam(part, _faces(1, 2), TOL)
    assert isinstance(piece, PointsSpec)


def test_many_edges_shuffled_and_turned_chain_into_one_polyline() -> None:
    rng = np.random.default_rng(1)
    corners = np.cumsum(rng.uniform(0.001, 0.002, size=(501, 3)), axis=0)
    order = rng.permutation(500)
    turned = rng.random(500) < 0.5
    segments = [
        (tuple(corners[k + 1]), tuple(corners[k])) if turned[k] else
        (tuple(corners[k]), tuple(corners[k + 1]))
        for k in order
    ]  # fmt: skip
    part = line_edges(*segments)
    first = int(order[0])
    start, chain = derive_seam(part, CadSeam(edges=tuple(range(1, 501))), TOL)
    # the first edge given runs its own way, so the chain runs as that edge does
    forward = not turned[first]
    expected = corners if forward else corners[::-1]
    assert np.allclose(start, expected[0])
    assert np.allclose([piece.to for piece in chain], expected[1:])  # type: ignore[union-attr]
