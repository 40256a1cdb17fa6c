"""The cell check of a machine: a track that carries the arm, a positioner that turns the part.

Every distance is compared with an independent computation: the test's own forward
kinematics of the track and the positioner (rotation matrices written out here) and coal's
distance between the capsules and bodies built from them.
"""

from __future__ import annotations

from collections import Counter

import coal
import numpy as np
import pytest

from trackplan.cell.check import check_cell, nearest_points, pair_distances
from trackplan.cell.model import Body, Capsules, Cell, Shape
from trackplan.cell.screening import CellGeometry, cell_frames, part_placements
from trackplan.errors import CaseError
from trackplan.frames import pose_matrix
from trackplan.robots.builtin import puma560
from trackplan.robots.kinematics import joint_frames
from trackplan.robots.machine import Machine, Positioner, Track
from trackplan.robots.model import Robot

TS = 0.01
N = 61
ARM_Q = np.array([0.0, 0.0, -np.pi / 2, 0.0, 0.0, 0.0])
"""PUMA560 stretched forwards (the forearm along the upper arm)."""
HEIGHT = 0.6
"""Height of the positioner's flange above its base, m (tilt axis at 0.5, table 0.1 above)."""
TABLE = 0.3
"""Length of the table's arm from the rotate axis, m."""
ROBOT_MIN_CLEARANCE = -0.04603621584803378
"""The robot check's least distance in the test below, computed at commit 2a8efef, m."""


def two_axis_chain(capsules: bool = True) -> Robot:
    """A tilt–rotate positioner: tilt about x at 0.5 m, rotate about z 0.1 m above it."""
    origins = np.stack([pose_matrix([0, 0, 0.5], np.eye(3)), pose_matrix([0, 0, 0.1], np.eye(3))])
    collision = Capsules(
        np.array([0, 1, 2]),
        np.array(
            [
                [[0.0, 0.0, 0.0], [0.0, 0.0, 0.4]],  # pedestal
                [[-0.2, 0.0, 0.0], [0.2, 0.0, 0.0]],  # tilt body
                [[0.0, 0.0, 0.0], [TABLE, 0.0, 0.0]],  # the table's arm
            ]
        ),
        np.array([0.1, 0.08, 0.03]),
        ("base", "link 1", "link 2"),
    )
    return Robot(
        name="tilt-rotate",
        origins=origins,
        axes=np.array([[1.0, 0.0, 0.0], [0.0, 0.0, 1.0]]),
        q_min=[-2.0, -7.0],
        q_max=[2.0, 7.0],
        v_max=[1.0, 2.0],
        a_max=[2.0, 4.0],
        j_max=[20.0, 40.0],
        joint_names=("tilt", "rotate"),
        collision=collision if capsules else None,
    )


def rot(axis: str, angle: float) -> np.ndarray:
    c, s = np.cos(angle), np.sin(angle)
    if axis == "x":
        return np.array([[1, 0, 0], [0, c, -s], [0, s, c]])
    return np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]])


def own_positioner_frames(base: np.ndarray, tilt: float, rotate: float) -> list[np.ndarray]:
    """The test's forward kinematics of :func:`two_axis_chain` standing at ``base`` (3,)."""
    T0 = pose_matrix(base, np.eye(3))
    T1 = T0 @ pose_matrix([0, 0, 0.5], rot("x", tilt))
    T2 = T1 @ pose_matrix([0, 0, 0.1], rot("z", rotate))
    return [T0, T1, T2]


def coal_capsule(a: np.ndarray, b: np.ndarray, radius: float) -> tuple[coal.Capsule, np.ndarray]:
    """A coal capsule along a–b and its pose (z along the axis)."""
    axis = b - a
    length = float(np.linalg.norm(axis))
    z = axis / length
    x = np.cross([0.0, 1.0, 0.0] if abs(z[0]) > 0.9 else [1.0, 0.0, 0.0], z)
    x /= np.linalg.norm(x)
    R = np.column_stack([x, np.cross(z, x), z])
    return coal.Capsule(radius, length), pose_matrix(0.5 * (a + b), R)


def coal_distance(g0: coal.CollisionGeometry, T0: np.ndarray, g1, T1: np.ndarray) -> float:
    request = coal.DistanceRequest()
    request.gjk_tolerance = 1e-10
    request.enable_signed_distance = True
    return float(
        coal.distance(
            g0,
            coal.Transform3s(T0[:3, :3], T0[:3, 3]),
            g1,
            coal.Transform3s(T1[:3, :3], T1[:3, 3]),
            request,
            coal.DistanceResult(),
        )
    )


def arm_capsule(frames: np.ndarray, capsules: Capsules, k: int, shift: np.ndarray):
    """Capsule k of the arm in the cell, its chain frames moved by ``shift`` (3,)."""
    T = frames[capsules.frame[k]]
    a, b = capsules.segment[k] @ T[:3, :3].T + T[:3, 3] + shift
    return coal_capsule(a, b, capsules.radius[k])


def column(geometry: CellGeometry, who: str, other: str) -> int:
    return geometry.pair_names().index((who, other))


def _frames_and_part_at(
    machine: Machine, q: np.ndarray, T_carrier_part: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The frames and the part's placements of a machine's samples (pair_distances' inputs)."""
    T, group = part_placements(machine, q, T_carrier_part)
    return cell_frames(machine, q), T, group


def test_track_carries_the_arm_into_an_obstacle() -> None:
    arm = puma560()
    machine = Machine(arm, track=Track([0.0, 1.0, 0.0], 0.0, 1.0, 1.0, 2.0, 20.0))
    frames = joint_frames(arm, ARM_Q)
    wrist = frames[5, :3, 3]
    ball = Body(
        "ball",
        Shape.SPHERE,
        pose_matrix(wrist + np.array([0.0, 0.6, 0.0]), np.eye(3)),
        [0.05, 0, 0],
    )
    cell = Cell(obstacles=(ball,), clearance=0.01)
    geometry = CellGeometry.from_cell(cell, machine)
    q = np.tile(np.r_[ARM_Q, 0.0], (N, 1))
    q[:, 6] = np.linspace(0.0, 1.0, N)  # the track carries the forearm through the ball
    report = check_cell(geometry, machine, q, TS, np.eye(4))
    # independently: every moving capsule of the arm, shifted by the track, against the ball
    capsules = arm.collision
    assert capsules is not None
    sphere = coal.Sphere(0.05)
    own = np.array(
        [
            min(
                coal_distance(
                    *arm_capsule(frames, capsules, k, [0, y, 0]), sphere, ball.T_frame_body
                )
                for k in np.flatnonzero(capsules.frame > 0)
            )
            for y in q[:, 6]
        ]
    )
    t = np.arange(N) * TS
    bad = np.flatnonzero(own < cell.clearance)
    assert len(bad) and 0 not in bad and N - 1 not in bad
    hits = [v for v in report.violations if v.limit == "collision" and "ball" in v.message]
    assert hits, report.violations
    assert min(v.t_first for v in hits) == pytest.approx(t[bad[0]], abs=1e-9)
    assert max(v.t_last for v in hits) == pytest.approx(t[bad[-1]], abs=1e-9)
    # apart, the screening equals the independent distance; at the worst it is coal's depth
    columns = [i for i, (_, other) in enumerate(geometry.pair_names()) if other == "ball"]
    d = pair_distances(geometry, *_frames_and_part_at(machine, q, np.eye(4)))[:, columns]
    apart = own > 0
    np.testing.assert_allclose(d.min(axis=1)[apart], own[apart], atol=1e-6)
    assert report.min_clearance == pytest.approx(own.min(), abs=1e-6)
    assert report.t_closest == pytest.approx(t[np.argmin(own)], abs=1e-9)
    # without the track the same arm pose stays clear of the ball
    still = check_cell(CellGeometry.from_cell(cell, arm), arm, q[:, :6], TS, np.eye(4))
    assert still.success


def turning_machine() -> tuple[Machine, np.ndarray, np.ndarray]:
    """The arm stretched forwards and a positioner whose table's arm reaches the arm's
    wrist centre at rotate = π/2: (machine, positioner base position, wrist centre)."""
    arm = puma560()
    wrist = joint_frames(arm, ARM_Q)[5, :3, 3]
    base = wrist - np.array([0.0, TABLE, HEIGHT])
    positioner = Positioner(two_axis_chain(), np.r_[base, 0.0, 0.0, 0.0], model="test")
    return Machine(arm, positioner=positioner), base, wrist


def test_positioner_turns_its_table_into_the_arm() -> None:
    machine, base, _ = turning_machine()
    arm = machine.arm
    geometry = CellGeometry.from_cell(Cell(clearance=0.01), machine)
    q = np.tile(np.r_[ARM_Q, 0.0, 0.0], (N, 1))
    q[:, 7] = np.linspace(-np.pi / 2, np.pi / 2, N)
    report = check_cell(geometry, machine, q, TS, np.eye(4))
    assert not report.success
    hits = [v for v in report.violations if v.limit == "collision"]
    assert hits and all("positioner link 2" in v.message for v in hits)
    assert all(v.message.startswith("collision: ") and " hits " in v.message for v in hits)
    assert report.closest[0].startswith("link") and report.closest[1] == "positioner link 2"
    # independently: the table's arm (own FK) against the arm's capsule the report names
    capsules = arm.collision
    assert capsules is not None
    k = capsules.name.index(report.closest[0])
    frames = joint_frames(arm, ARM_Q)
    own = []
    for angle in q[:, 7]:
        T2 = own_positioner_frames(base, 0.0, angle)[2]
        a, b = T2[:3, 3], T2[:3, :3] @ [TABLE, 0, 0] + T2[:3, 3]
        own.append(coal_distance(*arm_capsule(frames, capsules, k, 0.0), *coal_capsule(a, b, 0.03)))
    own_d = np.array(own)
    p = column(geometry, report.closest[0], "positioner link 2")
    d = pair_distances(geometry, *_frames_and_part_at(machine, q, np.eye(4)))
    apart = own_d > 0
    np.testing.assert_allclose(d[apart, p], own_d[apart], atol=1e-6)
    # at the deepest sample the exact check gives coal's penetration depth
    worst = int(np.argmin(own_d))
    assert own_d[worst] < 0 and d[worst, p] == pytest.approx(own_d[worst], abs=1e-6)
    t = np.arange(N) * TS
    bad = np.flatnonzero(own_d < 0.01)
    table_hits = [v for v in report.violations if report.closest[0] + " hits" in v.message]
    assert table_hits[0].t_first == pytest.approx(t[bad[0]], abs=1e-9)
    assert 0 not in bad  # turned away at the start: clear


def test_the_part_on_the_flange_follows_the_positioner() -> None:
    machine, base, _ = turning_machine()
    # the positioner stands 0.25 m lower and 0.15 m aside: its own links stay clear of the arm
    base = base + np.array([0.0, -0.15, -0.25])
    machine = machine.with_positioner_pose(np.r_[base, 0.0, 0.0, 0.0])
    # a post clamped on the table at 0.45 m from the rotate axis, 0.25 m high
    T_carrier_part = pose_matrix([0.45, 0.0, 0.0], np.eye(3))
    post = Body("post", Shape.BOX, pose_matrix([0, 0, 0.125], np.eye(3)), [0.02, 0.02, 0.125])
    cell = Cell(workpiece=(post,), clearance=0.02)
    geometry = CellGeometry.from_cell(cell, machine)
    names = geometry.pair_names()
    assert not any(who.startswith("positioner") and other == "post" for who, other in names)
    q = np.tile(np.r_[ARM_Q, 0.0, 0.0], (N, 1))
    q[:, 7] = np.linspace(-np.pi, np.pi, N)
    report = check_cell(geometry, machine, q, TS, T_carrier_part)
    capsules = machine.arm.collision
    assert capsules is not None
    frames = joint_frames(machine.arm, ARM_Q)
    box = coal.Box(0.04, 0.04, 0.25)
    own = np.empty(N)
    for s, angle in enumerate(q[:, 7]):
        T_part = own_positioner_frames(base, 0.0, angle)[2] @ T_carrier_part @ post.T_frame_body
        own[s] = min(
            coal_distance(*arm_capsule(frames, capsules, k, 0.0), box, T_part)
            for k in range(len(capsules))
        )
    t = np.arange(N) * TS
    bad = np.flatnonzero(own < cell.clearance)
    # the post comes round into the arm and leaves again
    assert len(bad) and bad[0] > 0 and bad[-1] < N - 1
    post_hits = [v for v in report.violations if "post" in v.message]
    assert post_hits
    assert min(v.t_first for v in post_hits) == pytest.approx(t[bad[0]], abs=1e-9)
    assert max(v.t_last for v in post_hits) == pytest.approx(t[bad[-1]], abs=1e-9)
    apart = own > 0
    part_columns = [i for i, (_, other) in enumerate(names) if other == "post"]
    d = pair_distances(geometry, *_frames_and_part_at(machine, q, T_carrier_part))
    np.testing.assert_allclose(d[:, part_columns].min(axis=1)[apart], own[apart], atol=1e-6)
    # the same arm pose with the positioner turned away is clear of the post
    away = check_cell(geometry, machine, q[:1], TS, T_carrier_part)
    assert away.success
    # the nearest points just before the post comes within the clearance lie on the post
    # where the test's own kinematics put it
    s = int(bad[0]) - 1
    assert own[s] > cell.clearance
    pair = part_columns[int(np.argmin(d[s, part_columns]))]
    points, distance = nearest_points(geometry, machine, q[s], T_carrier_part, pair)
    assert distance == pytest.approx(own[s], abs=1e-6)
    assert np.linalg.norm(points[1] - points[0]) == pytest.approx(own[s], abs=1e-6)
    T_part = own_positioner_frames(base, 0.0, q[s, 7])[2] @ T_carrier_part @ post.T_frame_body
    local = np.linalg.solve(T_part, np.r_[points[1], 1.0])[:3]
    assert np.max(np.abs(local) - post.size) == pytest.approx(0.0, abs=1e-6)


def test_screen_joints_of_a_machine_takes_placements_per_group() -> None:
    machine, _, _ = turning_machine()
    post = Body("post", Shape.BOX, pose_matrix([0, 0, 0.125], np.eye(3)), [0.02, 0.02, 0.125])
    geometry = CellGeometry.from_cell(Cell(workpiece=(post,)), machine)
    q = np.tile(np.r_[ARM_Q, 0.0, 0.0], (8, 1))
    q[:, 7] = np.linspace(-1.0, 1.0, 8)
    T = np.stack([pose_matrix([0.2, 0.0, 0.0], np.eye(3)), pose_matrix([0.0, 0.1, 0.0], np.eye(3))])
    group = np.arange(8) % 2
    body, own = geometry.screen_joints(machine, q, T, group)
    for g in (0, 1):
        rows = group == g
        one_body, one_own = geometry.screen_joints(machine, q[rows], T[g])
        np.testing.assert_allclose(body[rows], one_body, atol=1e-12)
        np.testing.assert_allclose(own[rows], one_own, atol=1e-12)
    with pytest.raises(ValueError, match="frames"):
        geometry.screen_joints(machine.arm, q[:, :6], T[0])


def test_a_robot_and_a_machine_of_it_give_the_same_numbers() -> None:
    """A machine without external axes, or with them at rest at 0 and out of the way, is
    the robot: same pairs, same distances (to round-off), same report."""
    arm = puma560()
    q = np.zeros((40, 6))
    q[:, 0] = np.linspace(0.0, np.pi / 2, 40)
    q[:, 2] = -np.pi / 2
    ball = Body("ball", Shape.SPHERE, pose_matrix([0.1, 0.5, 0.0], np.eye(3)), [0.05, 0, 0])
    plate = Body("plate", Shape.BOX, pose_matrix([0, 0, 0], np.eye(3)), [0.1, 0.1, 0.01])
    tool = Capsules([0], [[[0, 0, 0.1], [0, 0, 0.25]]], [0.01], ("torch",))
    cell = Cell(obstacles=(ball,), workpiece=(plate,), tool=tool, clearance=0.01)
    T_part = pose_matrix([0.3, 0.5, -0.3], np.eye(3))
    robot_report = check_cell(CellGeometry.from_cell(cell, arm), arm, q, TS, T_part)
    for machine, extra in (
        (Machine(arm), np.zeros((40, 0))),
        (Machine(arm, track=Track([0.0, 1.0, 0.0], -1.0, 1.0, 1.0, 1.0, 1.0)), np.zeros((40, 1))),
    ):
        geometry = CellGeometry.from_cell(cell, machine)
        report = check_cell(geometry, machine, np.hstack([q, extra]), TS, T_part)
        assert report.closest == robot_report.closest
        assert report.min_clearance == pytest.approx(robot_report.min_clearance, abs=1e-12)
        np.testing.assert_allclose(report.distance, robot_report.distance, atol=1e-12)
        assert [v.message for v in report.violations] == [
            v.message for v in robot_report.violations
        ]
    # the numbers of the robot check before machines existed (commit 2a8efef)
    assert robot_report.min_clearance == pytest.approx(ROBOT_MIN_CLEARANCE, abs=1e-9)


def test_a_positioner_without_capsules_is_one_line() -> None:
    positioner = Positioner(two_axis_chain(capsules=False), np.zeros(6), model="bare")
    with pytest.raises(CaseError, match="positioner 'bare' has no link capsules"):
        CellGeometry.from_cell(Cell(), Machine(puma560(), positioner=positioner))


def test_the_positioner_tilts_its_table_into_an_obstacle() -> None:
    """Its moving links meet obstacles; its base, standing in a bench, does not count."""
    base = np.array([0.0, -1.2, -0.5])
    positioner = Positioner(two_axis_chain(), np.r_[base, 0.0, 0.0, 0.0], model="test")
    machine = Machine(puma560(), positioner=positioner)
    bench = Body(
        "bench",
        Shape.BOX,
        pose_matrix(base + np.array([0.0, 0.0, 0.15]), np.eye(3)),
        [0.5, 0.5, 0.2],
    )
    cell = Cell(obstacles=(bench,), clearance=0.01)
    geometry = CellGeometry.from_cell(cell, machine)
    assert ("positioner base", "bench") not in geometry.pair_names()
    q = np.tile(np.r_[ARM_Q, 0.0, np.pi / 2], (N, 1))
    q[:, 6] = np.linspace(0.0, -np.pi / 2, N)  # the table's arm (along y) tilts down
    report = check_cell(geometry, machine, q, TS, np.eye(4))
    assert [v.message.split(" hits ")[0] for v in report.violations] == [
        "collision: positioner link 2"
    ]
    assert "bench" in report.violations[0].message
    box = coal.Box(1.0, 1.0, 0.4)
    own = np.empty(N)
    for s, tilt in enumerate(q[:, 6]):
        T2 = own_positioner_frames(base, tilt, np.pi / 2)[2]
        a, b = T2[:3, 3], T2[:3, :3] @ [TABLE, 0, 0] + T2[:3, 3]
        own[s] = coal_distance(*coal_capsule(a, b, 0.03), box, bench.T_frame_body)
    t = np.arange(N) * TS
    bad = np.flatnonzero(own < cell.clearance)
    assert len(bad) and bad[0] > 0
    assert report.violations[0].t_first == pytest.approx(t[bad[0]], abs=1e-9)
    p = column(geometry, "positioner link 2", "bench")
    d = pair_distances(geometry, *_frames_and_part_at(machine, q, np.eye(4)))[:, p]
    apart = own > 0
    np.testing.assert_allclose(d[apart], own[apart], atol=1e-6)
    assert report.violations[0].worst == pytest.approx(own.min(), abs=1e-6)


def test_a_machine_checks_the_robots_pairs_and_the_positioners() -> None:
    """The machine's pairs are the arm's (same names) and the positioner's against the arm's
    links and tool, and its moving links against the obstacles."""
    machine, _, _ = turning_machine()
    ball = Body("ball", Shape.SPHERE, np.eye(4), [0.05, 0, 0])
    plate = Body("plate", Shape.BOX, np.eye(4), [0.1, 0.1, 0.01])
    tool = Capsules([0], [[[0, 0, -0.2], [0, 0, 0]]], [0.01], ("torch",))
    cell = Cell(obstacles=(ball,), workpiece=(plate,), tool=tool, tool_contact=0.05)
    arm_names = CellGeometry.from_cell(cell, machine.arm).pair_names()
    names = CellGeometry.from_cell(cell, machine).pair_names()
    own = machine.arm.collision
    assert own is not None
    positioner = [f"positioner {name}" for name in ("base", "link 1", "link 2")]
    expected = [(a, p) for a in (*own.name, "torch") for p in positioner]
    expected += [(p, "ball") for p in positioner[1:]]
    assert Counter(names) == Counter(arm_names) + Counter(expected)
