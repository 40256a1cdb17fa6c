"""Link capsules from robot files: the ``collision:`` key and a URDF's ``<collision>`` elements."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import trimesh
import yourdfpy

from trackplan import cli
from trackplan.io.robot_file import builtin_robot, library_robots, load_robot, robot_to_yaml
from trackplan.robots.builtin import puma560
from trackplan.robots.kinematics import joint_frames
from trackplan.robots.model import Robot

DATA = Path(__file__).resolve().parent / "data"
LIMITS = "limits:\n  acceleration: [5, 5, 5, 5, 5, 5, 5]\n  jerk: [50, 50, 50, 50, 50, 50, 50]\n"

# <collision> elements added to the tilted7 test chain: every shape, origins with rotations,
# links fixed to the chain (world → base, l2 → l2b, l7 → tool), two elements on one link.
COLLISIONS = {
    "base": '<collision><origin xyz="0.01 0.02 0.05" rpy="0.1 0.2 0.3"/>'
    '<geometry><box size="0.3 0.2 0.1"/></geometry></collision>',
    "l2": '<collision><origin xyz="0 0 0.1" rpy="0 0.3 0"/>'
    '<geometry><cylinder radius="0.05" length="0.3"/></geometry></collision>',
    "l2b": '<collision><origin xyz="0.1 0 0"/><geometry><sphere radius="0.06"/></geometry>'
    "</collision>",
    "l3": '<collision><geometry><box size="0.05 0.05 0.25"/></geometry></collision>'
    '<collision><origin xyz="0 0.1 0" rpy="1 0 0"/>'
    '<geometry><cylinder radius="0.08" length="0.02"/></geometry></collision>',
    "l4": '<collision><origin xyz="0.02 0 0.03" rpy="0.4 -0.2 0.9"/>'
    '<geometry><mesh filename="part.stl" scale="0.001 0.001 0.002"/></geometry></collision>',
    "tool": '<collision><origin xyz="0 0 -0.05"/>'
    '<geometry><cylinder radius="0.02" length="0.1"/></geometry></collision>',
}


def collision_urdf(folder: Path, collisions: dict[str, str] = COLLISIONS) -> Path:
    """tilted7.urdf with ``collisions`` on its links, and the mesh it names, in ``folder``."""
    text = (DATA / "tilted7.urdf").read_text(encoding="utf-8")
    for name, elements in collisions.items():
        text = text.replace(f'<link name="{name}"/>', f'<link name="{name}">{elements}</link>')
    mesh = trimesh.creation.icosphere(subdivisions=2, radius=40.0)  # mm
    mesh.apply_scale([1.0, 2.5, 0.7])
    mesh.export(folder / "part.stl")
    file = folder / "arm.urdf"
    file.write_text(text, encoding="utf-8")
    return file


def shape_points(geometry: yourdfpy.Geometry, folder: Path, rng: np.random.Generator) -> np.ndarray:
    """Points of a collision shape in its own frame: corners, rims, surface and inside."""
    if geometry.box is not None:
        half = 0.5 * np.asarray(geometry.box.size)
        corners = np.array(np.meshgrid(*[[-h, h] for h in half])).reshape(3, -1).T
        return np.concatenate([corners, rng.uniform(-half, half, (200, 3))])
    if geometry.cylinder is not None:
        r, h = geometry.cylinder.radius, 0.5 * geometry.cylinder.length
        angle = rng.uniform(0, 2 * np.pi, 400)
        z = np.where(np.arange(400) < 200, h * rng.choice([-1, 1], 400), rng.uniform(-h, h, 400))
        return np.stack([r * np.cos(angle), r * np.sin(angle), z], 1)
    if geometry.sphere is not None:
        direction = rng.normal(size=(400, 3))
        return geometry.sphere.radius * direction / np.linalg.norm(direction, axis=1)[:, None]
    mesh = trimesh.load(folder / geometry.mesh.filename, force="mesh")
    return np.asarray(mesh.vertices) * np.asarray(geometry.mesh.scale)


def test_urdf_collision_shapes_are_enclosed_on_the_moving_chain(
    tmp_path: Path, rng: np.random.Generator
) -> None:
    """Every shape's points, placed by yourdfpy's own FK, lie inside its capsule as placed by
    trackplan's chain frames, over random configurations."""
    file = collision_urdf(tmp_path)
    robot = load_robot(file, assume_limits=True)
    capsules = robot.collision
    assert capsules is not None
    assert capsules.name == ("base", "l2", "l2b", "l3", "l3", "l4", "tool")
    np.testing.assert_array_equal(capsules.frame, [0, 2, 2, 3, 3, 4, 7])
    urdf = yourdfpy.URDF.load(str(file), load_meshes=False, load_collision_meshes=False)
    links = {link.name: link for link in urdf.robot.links}
    for q in rng.uniform(robot.q_min, robot.q_max, (20, robot.n_dof)):
        urdf.update_cfg(q)
        frames = joint_frames(robot, q)
        k = 0
        for name in ("base", "l2", "l2b", "l3", "l4", "tool"):
            for collision in links[name].collisions:
                origin = np.eye(4) if collision.origin is None else collision.origin
                T_world_shape = urdf.get_transform(name, "world") @ origin
                points = shape_points(collision.geometry, tmp_path, rng)
                world = points @ T_world_shape[:3, :3].T + T_world_shape[:3, 3]
                T = frames[capsules.frame[k]]
                a, b = capsules.segment[k] @ T[:3, :3].T + T[:3, 3]
                t = np.clip((world - a) @ (b - a) / max((b - a) @ (b - a), 1e-300), 0, 1)
                distance = np.linalg.norm(world - (a + t[:, None] * (b - a)), axis=1)
                assert distance.max() <= capsules.radius[k] + 1e-9, (name, k)
                k += 1


def test_robot_file_collision_replaces_the_urdfs(tmp_path: Path) -> None:
    collision_urdf(tmp_path)
    (tmp_path / "arm.yaml").write_text(
        "name: arm\nurdf: arm.urdf\n" + LIMITS + "collision:\n"
        "  - {link: l2b, from: [0, 0, 0], to: [0.1, 0, 0], radius: 0.03}\n"
        "  - {link: 5, from: [0, 0, 0], to: [0, 0, 0.1], radius: 0.02}\n",
        encoding="utf-8",
    )
    robot = load_robot(tmp_path / "arm.yaml")
    assert robot.collision is not None
    assert robot.collision.name == ("l2b", "link 5")
    np.testing.assert_array_equal(robot.collision.frame, [2, 5])
    # l2b is fixed to l2 at xyz (0, 0, 0.2), rpy (0.05, 0, -0.1): the capsule moves into l2
    c, s = np.cos(-0.1), np.sin(-0.1)
    np.testing.assert_allclose(robot.collision.segment[0, 0], [0, 0, 0.2], atol=1e-15)
    np.testing.assert_allclose(robot.collision.segment[0, 1] - [0, 0, 0.2], [0.1 * c, 0.1 * s, 0])
    np.testing.assert_array_equal(robot.collision.radius, [0.03, 0.02])


def test_a_urdf_without_collision_elements_has_no_capsules() -> None:
    assert load_robot(DATA / "tilted7.urdf", assume_limits=True).collision is None


def test_dh_robot_file_collision_round_trips(tmp_path: Path) -> None:
    robot = puma560()
    loaded = load_robot_round_trip(tmp_path, robot)
    assert loaded.collision is not None and robot.collision is not None
    np.testing.assert_array_equal(loaded.collision.frame, robot.collision.frame)
    np.testing.assert_array_equal(loaded.collision.segment, robot.collision.segment)
    np.testing.assert_array_equal(loaded.collision.radius, robot.collision.radius)
    assert loaded.collision.name == robot.collision.name


def load_robot_round_trip(folder: Path, robot: Robot) -> Robot:
    file = folder / "arm.yaml"
    file.write_text(robot_to_yaml(robot), encoding="utf-8")
    return load_robot(file)


@pytest.mark.parametrize("name", sorted(library_robots()))
def test_every_library_robot_ships_link_capsules(name: str) -> None:
    robot = builtin_robot(name)
    assert robot.collision is not None
    bodies = set(robot.collision.frame.tolist())
    assert bodies == set(range(robot.n_dof))  # the last joint turns the flange about its axis
    assert np.all(robot.collision.radius > 0.03)


def test_robots_command_counts_the_capsules(capsys: pytest.CaptureFixture[str]) -> None:
    assert cli.main(["robots", "kuka_kr6_r700_sixx"]) == 0
    out = capsys.readouterr().out
    assert "link capsules: 9 on 6 bodies; 23 capsule pairs of non-adjacent bodies" in out


DH_COLLISION = "collision:\n  - {link: 2, from: [0, 0, 0], to: [0.4, 0, 0], radius: 0.07}\n"


@pytest.mark.parametrize(
    ("kind", "old", "new", "message"),
    [
        ("dh", "link: 2", "link: 7", "collision[0].link: expected a link number 0..6 (0 = base)"),
        ("dh", "link: 2", "link: -1", "collision[0].link: expected a link number 0..6"),
        ("dh", "link: 2", "link: elbow", "collision[0].link: unknown link 'elbow'"),
        ("dh", "radius: 0.07", "radius: 0", "collision[0].radius: "),
        ("dh", "radius: 0.07", "radius: -0.1", "collision[0].radius: "),
        ("dh", "to: [0.4, 0, 0]", "to: [.nan, 0, 0]", "collision[0].to"),
        ("dh", "to: [0.4, 0, 0]", "to: [.inf, 0, 0]", "collision[0].to"),
        ("dh", "to: [0.4, 0, 0]", "b: [0.4, 0, 0]", "collision[0]"),
        ("urdf", "link: l2b", "link: l9", "collision[0].link: no link 'l9' on the URDF's chain"),
        ("urdf", "link: l2b", "link: 8", "collision[0].link: expected a link number 0..7"),
        ("urdf", "radius: 0.03", "radius: 0", "collision[0].radius: "),
    ],
)
def test_bad_collision_key_is_one_line_exit_2(
    capsys: pytest.CaptureFixture[str],
    tmp_path: Path,
    kind: str,
    old: str,
    new: str,
    message: str,
) -> None:
    if kind == "dh":
        text = robot_to_yaml(puma560()).split("\ncollision:")[0] + "\n" + DH_COLLISION
    else:
        collision_urdf(tmp_path)
        text = (
            "name: arm\nurdf: arm.urdf\n" + LIMITS + "collision:\n"
            "  - {link: l2b, from: [0, 0, 0], to: [0.1, 0, 0], radius: 0.03}\n"
        )
    assert old in text
    file = tmp_path / "robot.yaml"
    file.write_text(text.replace(old, new), encoding="utf-8")
    assert cli.main(["robots", str(file)]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1
    assert err.startswith(f"{file}: {message}"), err


@pytest.mark.parametrize(
    ("link", "collision", "message"),
    [
        (
            "l4",
            '<collision><geometry><mesh filename="missing.stl"/></geometry></collision>',
            "link 'l4' <collision> mesh 'missing.stl' not found",
        ),
        (
            "l4",
            '<collision><geometry><mesh filename="broken.stl"/></geometry></collision>',
            "link 'l4' <collision> mesh 'broken.stl' cannot be read as a mesh",
        ),
        (
            "l3",
            '<collision><geometry><box size="0.1 0 0.1"/></geometry></collision>',
            "link 'l3' <collision> box size must be > 0 m, got [0.1, 0.0, 0.1]",
        ),
        (
            "l3",
            '<collision><geometry><cylinder radius="-0.1" length="0.2"/></geometry></collision>',
            "line 7: link 'l3' <collision> <cylinder radius>: expected a number in [0, 1000] m, "
            "got '-0.1'",
        ),
        (
            "l2",
            '<collision><geometry><sphere radius="0"/></geometry></collision>',
            "link 'l2' <collision> sphere radius must be > 0 m",
        ),
    ],
)
def test_bad_urdf_collision_is_one_line_exit_2(
    capsys: pytest.CaptureFixture[str], tmp_path: Path, link: str, collision: str, message: str
) -> None:
    (tmp_path / "broken.stl").write_bytes(b"solid x\nthis is not an stl file\n")
    file = collision_urdf(tmp_path, {link: collision})
    assert cli.main(["robots", str(file), "--assume-limits"]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1
    assert err.startswith(f"{file}: {message}"), err
