"""Dynamics read from URDFs (``<inertial>``, ``<limit effort>``) and robot files pointing at
them, against pinocchio's ``rnea`` on the same files and roboticstoolbox on UR's DH table."""

from __future__ import annotations

import dataclasses
import re
from pathlib import Path

import numpy as np
import pytest

from tests.oracles import oracle
from trackplan.cli import ExitCode, main
from trackplan.errors import CaseError
from trackplan.io.robot_file import LIBRARY_DIR, builtin_robot, load_robot
from trackplan.robots.dynamics.rne import inverse_dynamics

N_STATES = 1000
GRAVITY = (1.5, -2.0, -9.3)
"""Not along −z: a tilted mount."""
CASES = Path(__file__).resolve().parents[2] / "cases"


def states(rng: np.random.Generator, n: int = N_STATES) -> tuple[np.ndarray, ...]:
    """Random (q, q̇, q̈) for six joints."""
    return (
        rng.uniform(-np.pi, np.pi, (n, 6)),
        rng.uniform(-3.0, 3.0, (n, 6)),
        rng.uniform(-10.0, 10.0, (n, 6)),
    )


def _rotation(rng: np.random.Generator) -> np.ndarray:
    R = np.linalg.qr(rng.normal(size=(3, 3)))[0]
    return R * np.sign(np.linalg.det(R))


def _origin(rng: np.random.Generator) -> str:
    xyz = " ".join(f"{v:.17g}" for v in rng.uniform(-0.2, 0.2, 3))
    rpy = " ".join(f"{v:.17g}" for v in rng.uniform(-np.pi, np.pi, 3))
    return f'<origin xyz="{xyz}" rpy="{rpy}"/>'


def _inertial(rng: np.random.Generator) -> str:
    """A full inertial: rotated origin, off-diagonal inertia, physical principal moments."""
    R = _rotation(rng)
    inertia = R @ np.diag(rng.uniform(1.0, 2.0, 3) * 0.02) @ R.T
    entries = {
        "ixx": inertia[0, 0],
        "ixy": inertia[0, 1],
        "ixz": inertia[0, 2],
        "iyy": inertia[1, 1],
        "iyz": inertia[1, 2],
        "izz": inertia[2, 2],
    }
    values = " ".join(f'{k}="{v:.17g}"' for k, v in entries.items())
    return (
        f'<inertial>{_origin(rng)}<mass value="{rng.uniform(0.5, 5.0):.17g}"/>'
        f"<inertia {values}/></inertial>"
    )


def write_test_robot(tmp_path: Path, rng: np.random.Generator) -> Path:
    """A six-joint URDF with unaligned axes, rotated joint and inertial origins, masses fixed
    to the base (no effect), to the chain between joints, on a side branch and at the tool;
    and a robot file that names its tip and tilts gravity."""
    lines = ['<robot name="testarm">', f'<link name="base_link">{_inertial(rng)}</link>']

    def link(name: str) -> None:
        lines.append(f'<link name="{name}">{_inertial(rng)}</link>')

    def fixed(name: str, parent: str, child: str) -> None:
        lines.append(
            f'<joint name="{name}" type="fixed">{_origin(rng)}<parent link="{parent}"/>'
            f'<child link="{child}"/></joint>'
        )

    def revolute(name: str, parent: str, child: str) -> None:
        axis = rng.normal(size=3)
        axis /= np.linalg.norm(axis)
        lines.append(
            f'<joint name="{name}" type="revolute">{_origin(rng)}<parent link="{parent}"/>'
            f'<child link="{child}"/><axis xyz="{" ".join(f"{v:.17g}" for v in axis)}"/>'
            '<limit lower="-3.5" upper="3.5" effort="100" velocity="3"/></joint>'
        )

    for name in (
        "mount",
        "l1",
        "l2",
        "l3",
        "sensor",
        "l4",
        "camera",
        "l5",
        "l6",
        "flange",
        "tool0",
    ):
        link(name)
    fixed("mount_joint", "base_link", "mount")
    revolute("j1", "mount", "l1")
    revolute("j2", "l1", "l2")
    revolute("j3", "l2", "l3")
    fixed("sensor_joint", "l3", "sensor")
    revolute("j4", "sensor", "l4")
    fixed("camera_joint", "l4", "camera")
    revolute("j5", "l4", "l5")
    revolute("j6", "l5", "l6")
    fixed("flange_joint", "l6", "flange")
    fixed("tool_joint", "flange", "tool0")
    lines.append("</robot>")
    (tmp_path / "testarm.urdf").write_text("\n".join(lines), encoding="utf-8")
    robot_file = tmp_path / "testarm.yaml"
    robot_file.write_text(
        "name: testarm\nurdf: testarm.urdf\ntip_link: tool0\n"
        "limits: {acceleration: [5, 5, 5, 5, 5, 5], jerk: [50, 50, 50, 50, 50, 50]}\n"
        f"gravity: [{', '.join(str(g) for g in GRAVITY)}]\n",
        encoding="utf-8",
    )
    return robot_file


def pinocchio_torques(urdf: Path, gravity, q, qd, qdd) -> np.ndarray:  # type: ignore[no-untyped-def]
    """τ = rnea(q, q̇, q̈) of pinocchio's model built from the URDF file itself."""
    pin = oracle("pinocchio")
    model = pin.buildModelFromUrdf(str(urdf))
    model.gravity.linear = np.asarray(gravity, dtype=float)
    data = model.createData()
    assert model.nq == q.shape[1]
    return np.array([pin.rnea(model, data, *state) for state in zip(q, qd, qdd, strict=True)])


def test_urdf_inertials_match_pinocchio(tmp_path: Path, rng: np.random.Generator) -> None:
    """1000 random states on a URDF with full inertials and tilted gravity."""
    robot = load_robot(write_test_robot(tmp_path, rng))
    assert robot.dynamics is not None
    np.testing.assert_array_equal(robot.dynamics.gravity, GRAVITY)
    np.testing.assert_array_equal(robot.dynamics.torque_max, np.full(6, 100.0))
    q, qd, qdd = states(rng)
    expected = pinocchio_torques(tmp_path / "testarm.urdf", GRAVITY, q, qd, qdd)
    np.testing.assert_allclose(inverse_dynamics(robot, q, qd, qdd), expected, rtol=1e-9, atol=1e-10)
    # the masses fixed to the chain count: without sensor, camera and tool the torques differ
    text = (tmp_path / "testarm.urdf").read_text(encoding="utf-8")
    for name in ("sensor", "camera", "flange", "tool0"):
        start = text.index(f'<link name="{name}">')
        text = text[:start] + f'<link name="{name}"/>' + text[text.index("</link>", start) + 7 :]
    (tmp_path / "testarm.urdf").write_text(text, encoding="utf-8")
    lighter = load_robot(tmp_path / "testarm.yaml")
    assert np.abs(inverse_dynamics(lighter, q, qd, qdd) - expected).max() > 1e-2


def test_ur5e_matches_pinocchio_on_its_urdf(rng: np.random.Generator) -> None:
    """The shipped UR5e, floor and ceiling mounted."""
    robot = builtin_robot("ur5e")
    assert robot.dynamics is not None
    q, qd, qdd = states(rng)
    for gravity in ((0.0, 0.0, -9.81), (0.0, 0.0, 9.81)):
        mounted = dataclasses.replace(
            robot, dynamics=dataclasses.replace(robot.dynamics, gravity=np.array(gravity))
        )
        expected = pinocchio_torques(LIBRARY_DIR / "ur5e.urdf", gravity, q, qd, qdd)
        np.testing.assert_allclose(
            inverse_dynamics(mounted, q, qd, qdd), expected, rtol=1e-9, atol=1e-10
        )


UR5E_DH = {  # Universal Robots, "DH parameters for calculations of kinematics and dynamics"
    "d": [0.1625, 0, 0, 0.1333, 0.0997, 0.0996],
    "a": [0, -0.425, -0.3922, 0, 0, 0],
    "alpha": [np.pi / 2, 0, 0, np.pi / 2, -np.pi / 2, 0],
    "mass": [3.761, 8.058, 2.846, 1.37, 1.3, 0.365],
    "com": [  # in the DH link frames
        [0, -0.02561, 0.00193],
        [0.2125, 0, 0.11336],
        [0.15, 0, 0.0265],
        [0, -0.0018, 0.01634],
        [0, 0.0018, 0.01634],
        [0, 0, -0.001159],
    ],
}
UR5E_CYLINDERS = [
    (1, 0.15, 0.06),
    (0, 0.425, 0.05),
    (0, 0.3922, 0.04),
    (2, 0.12, 0.045),
    (2, 0.12, 0.045),
    (2, 0.04, 0.045),
]
"""The stated inertia approximation: (DH axis, length m, radius m) of a uniform cylinder."""


def test_ur5e_urdf_inertials_are_urs_dh_table(rng: np.random.Generator) -> None:
    """The URDF's link-frame inertials are UR's DH-frame table: roboticstoolbox on the DH
    table with the same masses, centres of mass and cylinder inertias gives the same torques."""
    rtb = oracle("roboticstoolbox")
    links = []
    for i, (axis, length, radius) in enumerate(UR5E_CYLINDERS):
        m = UR5E_DH["mass"][i]
        moments = np.full(3, m * (3 * radius**2 + length**2) / 12)
        moments[axis] = m * radius**2 / 2
        links.append(
            rtb.RevoluteDH(
                d=UR5E_DH["d"][i],
                a=UR5E_DH["a"][i],
                alpha=UR5E_DH["alpha"][i],
                m=m,
                r=UR5E_DH["com"][i],
                I=np.diag(moments),
                Jm=0.0,
                G=1.0,
                B=0.0,
                Tc=[0.0, 0.0],
            )
        )
    reference = rtb.DHRobot(links)
    robot = builtin_robot("ur5e")
    q, qd, qdd = states(rng, 200)
    np.testing.assert_allclose(
        inverse_dynamics(robot, q, qd, qdd), reference.rne(q, qd, qdd), rtol=1e-9, atol=1e-9
    )
    np.testing.assert_array_equal(robot.dynamics.torque_max, [150, 150, 150, 28, 28, 28])


def test_robot_file_adds_motors_and_replaces_limits(
    tmp_path: Path, rng: np.random.Generator
) -> None:
    robot_file = write_test_robot(tmp_path, rng)
    base = load_robot(robot_file)
    text = robot_file.read_text(encoding="utf-8")
    robot_file.write_text(
        text
        + "dynamics:\n"
        + "  torque: [90, 90, 90, 20, 20, 20]\n"
        + "  motor_inertia: [2.0e-4, 2.0e-4, 2.0e-4, 3.0e-5, 3.0e-5, 3.0e-5]\n"
        + "  gear_ratio: [100, -100, 100, 80, 80, 80]\n"
        + "  viscous: [1.0e-3, 1.0e-3, 1.0e-3, 1.0e-4, 1.0e-4, 1.0e-4]\n"
        + "  coulomb: [[0.1, -0.1], [0.1, -0.1], [0.1, -0.1], [0.01, -0.02], [0.01, -0.02], "
        + "[0.01, -0.02]]\n",
        encoding="utf-8",
    )
    robot = load_robot(robot_file)
    assert robot.dynamics is not None
    np.testing.assert_array_equal(robot.dynamics.torque_max, [90, 90, 90, 20, 20, 20])
    q, qd, qdd = states(rng, 50)
    G = np.array([100, -100, 100, 80, 80, 80.0])
    Jm = np.array([2e-4] * 3 + [3e-5] * 3)
    B = np.array([1e-3] * 3 + [1e-4] * 3)
    Tc = np.array([[0.1, -0.1]] * 3 + [[0.01, -0.02]] * 3)
    coulomb = np.where(qd > 0, Tc[:, 0], np.where(qd < 0, Tc[:, 1], 0.0)) * np.abs(G)
    expected = inverse_dynamics(base, q, qd, qdd) + G**2 * (Jm * qdd + B * qd) + coulomb
    np.testing.assert_allclose(inverse_dynamics(robot, q, qd, qdd), expected, rtol=1e-12)


def test_robot_file_inertials_replace_the_urdfs(tmp_path: Path, rng: np.random.Generator) -> None:
    robot_file = write_test_robot(tmp_path, rng)
    robot_file.write_text(
        robot_file.read_text(encoding="utf-8")
        + "dynamics:\n  mass: [1, 1, 1, 1, 1, 2]\n"
        + "  com: [[0, 0, 0], [0, 0, 0], [0, 0, 0], [0, 0, 0], [0, 0, 0], [0, 0, 0.1]]\n"
        + "  inertia: [[0, 0, 0, 0, 0, 0], [0, 0, 0, 0, 0, 0], [0, 0, 0, 0, 0, 0], "
        + "[0, 0, 0, 0, 0, 0], [0, 0, 0, 0, 0, 0], [0.01, 0.01, 0.01, 0, 0, 0]]\n",
        encoding="utf-8",
    )
    dynamics = load_robot(robot_file).dynamics
    assert dynamics is not None
    np.testing.assert_array_equal(dynamics.mass, [1, 1, 1, 1, 1, 2])
    np.testing.assert_array_equal(dynamics.com[5], [0, 0, 0.1])
    np.testing.assert_array_equal(dynamics.torque_max, np.full(6, 100.0))  # the URDF's effort


def test_urdf_without_effort_or_inertials_has_no_dynamics(tmp_path: Path) -> None:
    """A bare URDF short of either has no torque check; a robot file asking for one is told
    what is missing."""
    text = (LIBRARY_DIR / "ur5e.urdf").read_text(encoding="utf-8")
    no_effort = text.replace('effort="28"', 'effort="0"')
    (tmp_path / "no_effort.urdf").write_text(no_effort, encoding="utf-8")
    assert load_robot(tmp_path / "no_effort.urdf", assume_limits=True).dynamics is None
    (tmp_path / "robot.yaml").write_text(
        "name: r\nurdf: no_effort.urdf\nlimits: {acceleration: [5, 5, 5, 5, 5, 5], "
        "jerk: [50, 50, 50, 50, 50, 50]}\npayload: {mass: 1.0}\n",
        encoding="utf-8",
    )
    with pytest.raises(CaseError) as error:
        load_robot(tmp_path / "robot.yaml")
    assert error.value.one_line() == (
        f"{tmp_path / 'robot.yaml'}: dynamics: no torque limit for joints joint_4, joint_5, "
        "joint_6: give effort > 0 in their <limit> in the URDF or dynamics.torque"
    )
    no_inertials = re.sub(r"<inertial>.*?</inertial>", "", text, flags=re.DOTALL)
    (tmp_path / "no_inertials.urdf").write_text(no_inertials, encoding="utf-8")
    assert load_robot(tmp_path / "no_inertials.urdf", assume_limits=True).dynamics is None
    (tmp_path / "robot.yaml").write_text(
        "name: r\nurdf: no_inertials.urdf\nlimits: {acceleration: [5, 5, 5, 5, 5, 5], "
        "jerk: [50, 50, 50, 50, 50, 50]}\ndynamics: {gear_ratio: [1, 1, 1, 1, 1, 1]}\n",
        encoding="utf-8",
    )
    with pytest.raises(CaseError, match="the URDF has no <inertial> on the chain's links"):
        load_robot(tmp_path / "robot.yaml")


def _ur5e_with(tmp_path: Path, old: str, new: str, extra: str = "") -> Path:
    """A copy of the UR5e robot file and URDF with one change."""
    text = (LIBRARY_DIR / "ur5e.urdf").read_text(encoding="utf-8")
    assert old in text
    (tmp_path / "ur5e.urdf").write_text(text.replace(old, new, 1), encoding="utf-8")
    robot = (LIBRARY_DIR / "ur5e.yaml").read_text(encoding="utf-8") + extra
    (tmp_path / "ur5e.yaml").write_text(robot, encoding="utf-8")
    return tmp_path / "ur5e.yaml"


CYLINDER_1 = 'ixx="0.010436775" ixy="0" ixz="0" iyy="0.010436775" iyz="0" izz="0.0067698"'


@pytest.mark.parametrize(
    ("old", "new", "extra", "message"),
    [
        (
            '<mass value="2.846"/>',
            '<mass value="-2.846"/>',
            "",
            "ur5e.urdf: line 40: link 'link_3' <inertial> <mass value>: expected a number in "
            "[0, 100000] kg, got '-2.846'",
        ),
        (
            CYLINDER_1,
            CYLINDER_1.replace('ixy="0"', 'ixy="0.02"'),
            "",
            "ur5e.urdf: link 'link_1': inertia is not positive semi-definite",
        ),
        (
            CYLINDER_1,
            CYLINDER_1.replace('izz="0.0067698"', 'izz="0.03"'),
            "",
            "ur5e.urdf: link 'link_1': inertia breaks the triangle inequality: principal "
            "moment 0.03 exceeds 0.01044 + 0.01044 kg·m²",
        ),
        (
            'effort="150"',
            'effort="-150"',
            "",
            "ur5e.urdf: line 77: joint 'joint_1' <limit effort>: expected a number in "
            "[0, 1e+07] N·m, got '-150'",
        ),
        (
            "",
            "",
            "dynamics: {torque: [150, 150, 0, 28, 28, 28]}\n",
            "ur5e.yaml: dynamics.torque[2]: torque limit must be > 0 N·m, got 0",
        ),
        (
            "",
            "",
            "dynamics: {gear_ratio: [100, 100]}\n",
            "ur5e.yaml: dynamics.gear_ratio: expected 6 entries, one per joint of the chain",
        ),
        (
            "",
            "",
            "dynamics: {mass: [1, 1, 1, 1, 1, 1]}\n",
            "ur5e.yaml: dynamics: give mass, com and inertia together",
        ),
    ],
)
def test_bad_dynamics_in_urdf_robots_are_one_line(
    tmp_path: Path, old: str, new: str, extra: str, message: str
) -> None:
    with pytest.raises(CaseError) as error:
        load_robot(_ur5e_with(tmp_path, old, new, extra))
    line = error.value.one_line()
    assert "\n" not in line
    assert line.startswith(
        str(tmp_path / message.split(":", 1)[0]) + ":" + message.split(":", 1)[1]
    )


def test_bad_urdf_inertial_exits_2_from_the_cli(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    _ur5e_with(tmp_path, '<mass value="2.846"/>', '<mass value="-2.846"/>')
    case = (CASES / "ur5e-glue.yaml").read_text(encoding="utf-8")
    assert "robot: ur5e\n" in case
    (tmp_path / "case.yaml").write_text(case.replace("robot: ur5e\n", "robot: ur5e.yaml\n"))
    code = main(["validate", str(tmp_path / "case.yaml")])
    assert code == ExitCode.BAD_INPUT
    assert capsys.readouterr().err.strip().splitlines() == [
        f"{tmp_path / 'ur5e.urdf'}: line 40: link 'link_3' <inertial> <mass value>: expected a"
        " number in [0, 100000] kg, got '-2.846'"
    ]
