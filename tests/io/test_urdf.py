"""URDF robots: FK against yourdfpy's own FK, robot files pointing at URDFs, and the errors."""

from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np
import pytest
import yourdfpy

from trackplan import cli
from trackplan.errors import CaseError
from trackplan.io.robot_file import (
    ASSUMED_ACCELERATION_TIME,
    ASSUMED_JERK_TIME,
    LIBRARY_DIR,
    builtin_robot,
    library_robots,
    load_robot,
)
from trackplan.robots.families import ik_family
from trackplan.robots.kinematics import forward_kinematics

DATA = Path(__file__).resolve().parent / "data"
N_CONFIGS = 1000
LIBRARY = sorted(library_robots())
PUBLISHED_LIMITS = {"franka_panda"}  # libfranka rate_limiting.h


def yourdfpy_fk(file: Path, q: np.ndarray, base: str, tip: str) -> np.ndarray:
    """yourdfpy's transform of ``tip`` in ``base`` at each configuration, (N, 4, 4)."""
    urdf = yourdfpy.URDF.load(str(file), load_meshes=False, load_collision_meshes=False)
    out = np.empty((len(q), 4, 4))
    for k, qk in enumerate(q):
        urdf.update_cfg(qk)
        out[k] = urdf.get_transform(tip, base)
    return out


@pytest.mark.parametrize("name", LIBRARY)
def test_library_fk_matches_yourdfpy(name: str, rng: np.random.Generator) -> None:
    robot = builtin_robot(name)
    q = rng.uniform(robot.q_min, robot.q_max, (N_CONFIGS, robot.n_dof))
    expected = yourdfpy_fk(LIBRARY_DIR / f"{name}.urdf", q, "base_link", "tool0")
    assert np.abs(forward_kinematics(robot, q) - expected).max() < 1e-9


def test_test_urdf_fk_matches_yourdfpy(rng: np.random.Generator) -> None:
    robot = load_robot(DATA / "tilted7.urdf", assume_limits=True)
    assert robot.n_dof == 7 and robot.joint_names == ("j1", "j2", "j3", "j4", "j5", "j6", "j7")
    assert (robot.q_min[2], robot.q_max[2]) == (-2 * np.pi, 2 * np.pi)  # continuous joint
    q = rng.uniform(robot.q_min, robot.q_max, (N_CONFIGS, 7))
    expected = yourdfpy_fk(DATA / "tilted7.urdf", q, "world", "tool")
    assert np.abs(forward_kinematics(robot, q) - expected).max() < 1e-9
    assert ik_family(robot).name == "numeric"


def test_robot_file_with_links_tool_and_limits(tmp_path: Path, rng: np.random.Generator) -> None:
    (tmp_path / "arm.urdf").write_text((DATA / "tilted7.urdf").read_text())
    (tmp_path / "arm.yaml").write_text(
        "name: my-arm\nurdf: arm.urdf\nbase_link: base\ntip_link: l5\n"
        "tool: {xyz: [0, 0, 0.25], rpy: [0, 0.3, 0]}\ncontinuous_range: 3.5\n"
        "limits:\n  acceleration: [5, 5, 5, 10, 10]\n  jerk: [25, 25, 25, 50, 50]\n"
        "  velocity: [2.6, 2.6, 2.6, 6.2, 6.2]\n"
    )
    robot = load_robot(tmp_path / "arm.yaml")
    assert robot.name == "my-arm" and robot.n_dof == 5 and robot.assumptions == ()
    np.testing.assert_array_equal(robot.a_max, [5, 5, 5, 10, 10])
    np.testing.assert_array_equal(robot.v_max, [2.6, 2.6, 2.6, 6.2, 6.2])
    assert robot.q_max[2] == 3.5
    q = rng.uniform(robot.q_min, robot.q_max, (100, 5))
    padded = np.concatenate([q, np.zeros((len(q), 2))], axis=1)  # j6, j7 are not in the chain
    flange = yourdfpy_fk(DATA / "tilted7.urdf", padded, "base", "l5")
    c, s = np.cos(0.3), np.sin(0.3)
    tool = np.array([[c, 0, s, 0], [0, 1, 0, 0], [-s, 0, c, 0.25], [0, 0, 0, 1]])
    assert np.abs(forward_kinematics(robot, q) - flange @ tool).max() < 1e-9


def test_assumed_limits_follow_the_rule_and_are_recorded() -> None:
    with pytest.raises(CaseError, match=r"no acceleration or jerk limits.*--assume-limits"):
        load_robot(DATA / "tilted7.urdf")
    robot = load_robot(DATA / "tilted7.urdf", assume_limits=True)
    np.testing.assert_allclose(robot.a_max, robot.v_max / ASSUMED_ACCELERATION_TIME)
    np.testing.assert_allclose(robot.j_max, robot.a_max / ASSUMED_JERK_TIME)
    assert len(robot.assumptions) == 2 and "velocity / 0.25 s" in robot.assumptions[0]


def test_library_files_cite_sources_and_mark_assumptions() -> None:
    for name in LIBRARY:
        robot = builtin_robot(name)
        assert robot.source and "<!--" in (LIBRARY_DIR / f"{name}.urdf").read_text()
        if name in PUBLISHED_LIMITS:  # acceleration and jerk published: nothing assumed
            assert robot.assumptions == () and "ASSUMED" not in robot.source
            continue
        assert "assumed" in robot.assumptions[0]
        assert "ASSUMED" in (LIBRARY_DIR / f"{name}.yaml").read_text()


def one_line_error(capsys: pytest.CaptureFixture[str], target: str) -> str:
    """Run ``trackplan robots TARGET``: exit 2 with one line on stderr, which is returned."""
    code = cli.main(["robots", target])
    err = capsys.readouterr().err
    assert code == 2
    assert err.count("\n") == 1 and "Traceback" not in err
    return err


def robot_file(tmp_path: Path, urdf: str, extra: str = "") -> str:
    (tmp_path / "arm.urdf").write_text((DATA / urdf).read_text())
    (tmp_path / "arm.yaml").write_text(
        f"name: arm\nurdf: arm.urdf\n{extra}limits:\n  acceleration: [5, 5, 5, 5, 5, 5]\n"
        "  jerk: [50, 50, 50, 50, 50, 50]\n"
    )
    return str(tmp_path / "arm.yaml")


def test_malformed_urdf(capsys: pytest.CaptureFixture[str]) -> None:
    err = one_line_error(capsys, str(DATA / "malformed.urdf"))
    assert "malformed.urdf: not well-formed XML at line 32, column 28: " in err


def test_missing_named_link(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    file = robot_file(tmp_path, "mimic.urdf", "tip_link: flange\n")
    err = one_line_error(capsys, file)
    assert "arm.yaml: tip_link: the URDF has no link 'flange': use one of base_link" in err


def test_branching_chain(capsys: pytest.CaptureFixture[str]) -> None:
    err = one_line_error(capsys, str(DATA / "branching.urdf"))
    assert "branching tree (leaves camera, tool0): name the chain's end with tip_link" in err


def test_mimic_joint(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    err = one_line_error(capsys, robot_file(tmp_path, "mimic.urdf"))
    assert "joint 'joint_3' is a mimic joint" in err


def test_prismatic_joint(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    err = one_line_error(capsys, robot_file(tmp_path, "prismatic.urdf"))
    assert "joint 'joint_2' is prismatic: trackplan supports revolute and continuous" in err


def test_wrong_number_of_limit_entries(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    file = robot_file(tmp_path, "branching.urdf", "tip_link: tool0\n")
    text = Path(file).read_text().replace("jerk: [50, 50, 50, 50, 50, 50]", "jerk: [50, 50, 50]")
    Path(file).write_text(text)
    err = one_line_error(capsys, file)
    assert "arm.yaml: limits.jerk: expected 6 entries, one per joint of the chain" in err
    assert "got 3" in err


# --------------------------------------------------------------------------- hostile URDFs

TILTED7 = (DATA / "tilted7.urdf").read_text(encoding="utf-8")
J2_AXIS = '<axis xyz="0 1 0.2"/>'
J2_LIMIT = '<limit lower="-2" upper="2" velocity="2" effort="1"/>'
J2_ORIGIN = '<origin xyz="0.05 0.02 0.1" rpy="-0.3 0.1 0"/>'


def mutated_urdf(folder: Path, old: str, new: str) -> Path:
    """tilted7.urdf with ``old`` replaced by ``new`` (``old`` must occur)."""
    assert old in TILTED7
    file = folder / "arm.urdf"
    file.write_text(TILTED7.replace(old, new, 1), encoding="utf-8")
    return file


@pytest.mark.parametrize(
    ("old", "new", "message"),
    [
        # malformed XML, which yourdfpy's recovering parser would read as something else
        (J2_AXIS, "<axis xyz=0 0 1/>", "not well-formed XML at line 20, column 61: AttValue: "),
        ("</robot>", "", "not well-formed XML at line 57, column 1: Premature end of data in "),
        ('name="j5"', 'name="j4"', "line 37: joint name 'j4' is given twice (first at line 32)"),
        ('<link name="l5"/>', '<link name="l5"/>\n<link name="l5"/>', "line 9: link name 'l5' is"),
        ("-->", "", "not well-formed XML at line 57, column 1: Comment not terminated\n"),
        ('<robot name="tilted7">', '<robo name="x">', "not well-formed XML at line 56, column 9: "),
        # values out of their range, named with the joint, the attribute and the range
        (
            J2_AXIS,
            '<axis xyz="0 1 0.2 1"/>',
            "line 20: joint 'j2' <axis xyz>: expected 3 numbers, ",
        ),
        (J2_AXIS, '<axis xyz="a b c"/>', "line 20: joint 'j2' <axis xyz>: expected 3 numbers, "),
        (
            J2_AXIS,
            '<axis xyz="0 0 1e-300"/>',
            "line 20: joint 'j2' <axis xyz>: expected a joint axis of length ≥ 1e-06, got",
        ),
        (
            J2_LIMIT,
            J2_LIMIT.replace('lower="-2" upper="2"', 'lower="-1e308" upper="1e308"'),
            "line 21: joint 'j2' <limit lower>: expected a number within ±1000 rad, got '-1e308'",
        ),
        (
            J2_ORIGIN,
            J2_ORIGIN.replace("0.05 0.02", "nan 0.02"),
            "line 20: joint 'j2' <origin xyz>: expected 3 numbers within ±1000 m, got 'nan 0.02",
        ),
        (
            J2_ORIGIN,
            J2_ORIGIN.replace("0.1 0", "inf 0"),
            "line 20: joint 'j2' <origin rpy>: expected 3 numbers within ±1000 rad, got",
        ),
        (
            J2_LIMIT,
            J2_LIMIT.replace('velocity="2"', 'velocity="0"'),
            "line 21: joint 'j2' <limit velocity>: expected a number in [0.001, 1e+06] rad/s, "
            "got '0'",
        ),
        (
            J2_LIMIT,
            J2_LIMIT.replace('velocity="2"', 'velocity="-1"'),
            "line 21: joint 'j2' <limit velocity>: expected a number in [0.001, 1e+06] rad/s, got",
        ),
        (
            J2_LIMIT,
            J2_LIMIT.replace('effort="1"', 'effort="1e300"'),
            "line 21: joint 'j2' <limit effort>: expected a number in [0, 1e+07] N·m, got '1e300'",
        ),
    ],
)
def test_hostile_urdf_is_one_line_naming_the_line(
    capsys: pytest.CaptureFixture[str], tmp_path: Path, old: str, new: str, message: str
) -> None:
    file = mutated_urdf(tmp_path, old, new)
    code = cli.main(["robots", str(file), "--assume-limits"])
    err = capsys.readouterr().err
    assert code == 2 and err.count("\n") == 1, err
    assert err.startswith(f"{file}: {message}"), err


def test_a_fixed_joints_zero_axis_is_ignored(tmp_path: Path) -> None:
    old = '<origin xyz="0 0 0.2" rpy="0.05 0 -0.1"/>'
    file = mutated_urdf(tmp_path, old, old + '<axis xyz="0 0 0"/>')
    assert load_robot(file, assume_limits=True).n_dof == 7


@pytest.mark.parametrize(
    ("filename", "what"),
    [
        ("package://arm_description/meshes/missing.stl", "not found"),
        ("/dev/zero", "is a character device, not a regular file"),
        (".", "is a directory, not a regular file"),
    ],
)
def test_a_missing_mesh_is_one_line_suggesting_capsules(
    capsys: pytest.CaptureFixture[str], tmp_path: Path, filename: str, what: str
) -> None:
    mesh = f'<collision><geometry><mesh filename="{filename}"/></geometry></collision>'
    file = mutated_urdf(tmp_path, '<link name="l4"/>', f'<link name="l4">{mesh}</link>')
    assert cli.main(["robots", str(file), "--assume-limits"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1, err  # yourdfpy's own warning line is silenced
    assert err.startswith(f"{file}: link 'l4' <collision> mesh {filename!r} {what}: "), err
    assert "capsules under collision: in a robot file" in err
    # ... and that robot file reads no mesh
    (tmp_path / "arm.yaml").write_text(
        "name: arm\nurdf: arm.urdf\nlimits:\n  acceleration: [5, 5, 5, 5, 5, 5, 5]\n"
        "  jerk: [50, 50, 50, 50, 50, 50, 50]\ncollision:\n"
        "  - {link: l4, from: [0, 0, 0], to: [0.1, 0, 0], radius: 0.05}\n",
        encoding="utf-8",
    )
    assert len(load_robot(tmp_path / "arm.yaml").collision or ()) == 1


def test_mesh_vertices_far_out_are_refused_without_warnings(
    capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    (tmp_path / "far.obj").write_text("v 0 0 0\nv 1e300 0 0\nv 0 1 0\nf 1 2 3\n")
    mesh = '<collision><geometry><mesh filename="far.obj" scale="1000 1 1"/></geometry></collision>'
    file = mutated_urdf(tmp_path, '<link name="l4"/>', f'<link name="l4">{mesh}</link>')
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert cli.main(["robots", str(file), "--assume-limits"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1, err
    assert (
        "mesh 'far.obj' has a vertex 1e+303 m from its origin once scaled: vertices must lie "
        in err
    )
    big = mesh.replace('scale="1000 1 1"', 'scale="1e300 1 1"')
    file = mutated_urdf(tmp_path, '<link name="l4"/>', f'<link name="l4">{big}</link>')
    assert cli.main(["robots", str(file), "--assume-limits"]) == 2
    err = capsys.readouterr().err
    assert "<mesh scale>: expected 3 numbers within ±1000, got '1e300 1 1'" in err


def test_a_urdf_needs_a_robot_root(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    file = tmp_path / "arm.urdf"
    file.write_text(TILTED7.replace("<robot ", "<model ").replace("</robot>", "</model>"))
    assert cli.main(["robots", str(file), "--assume-limits"]) == 2
    assert (
        capsys.readouterr().err == f"{file}: line 4: expected a <robot> root element, got <model>\n"
    )


def test_messages_quote_at_most_60_characters_of_an_attribute(
    capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    file = mutated_urdf(tmp_path, J2_AXIS, '<axis xyz="' + "0 " * 3000 + '"/>')
    assert cli.main(["robots", str(file), "--assume-limits"]) == 2
    err = capsys.readouterr().err
    message = err.removeprefix(f"{file}: ")  # the temporary folder's name varies in length
    assert "<axis xyz>: expected 3 numbers, got '0 0 0" in message and len(message) < 120
