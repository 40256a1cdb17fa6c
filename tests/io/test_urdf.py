"""URDF robots: FK against yourdfpy's own FK, robot files pointing at URDFs, and the errors."""

from __future__ import annotations

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
        assert robot.source and "assumed" in robot.assumptions[0]
        assert "ASSUMED" in (LIBRARY_DIR / f"{name}.yaml").read_text()
        assert "<!--" in (LIBRARY_DIR / f"{name}.urdf").read_text()


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
    assert "malformed.urdf: not a valid URDF" in err


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
