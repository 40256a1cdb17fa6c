"""Dynamic parameters in robot and case files: torques as roboticstoolbox computes them,
and one-line errors for unphysical values."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from tests.oracles import oracle
from trackplan.cli import ExitCode, main
from trackplan.errors import CaseError
from trackplan.io.case_file import load_case
from trackplan.io.robot_file import load_robot_text
from trackplan.robots.dynamics.rne import inverse_dynamics

rtb = oracle("roboticstoolbox")

CASES = Path(__file__).resolve().parents[2] / "cases"

JOINTS = [
    # d, a, alpha, mass, com, inertia (physical: triangle inequality holds), torque
    (0.1, 0.0, 1.5707963267948966, 2.0, [0, -0.02, 0.01], [0.02, 0.02, 0.01, 0, 0, 0], 90),
    (0.0, 0.43, 0.0, 9.0, [-0.2, 0.0, 0.1], [0.05, 0.3, 0.3, 0.01, 0, 0.02], 180),
    (0.15, 0.02, -1.5707963267948966, 4.0, [0, -0.01, 0.05], [0.06, 0.06, 0.01, 0, 0.001, 0], 90),
    (0.43, 0.0, 1.5707963267948966, 0.8, [0, 0.02, 0], [2e-3, 1.5e-3, 2e-3, 0, 0, 0], 24),
    (0.0, 0.0, -1.5707963267948966, 0.3, [0, 0, 0], [3e-4, 4e-4, 3e-4, 0, 0, 0], 20),
    (0.05, 0.0, 0.0, 0.1, [0, 0, 0.03], [1.5e-4, 1.5e-4, 0.5e-4, 0, 0, 0], 21),
]
MOTORS = [(2e-4, -62.6, 1.5e-3, [0.4, -0.43])] * 3 + [(3.3e-5, 76.0, 7e-5, [0.011, -0.017])] * 3


def robot_text(payload: str = "", **override: str) -> str:
    lines = ["name: test6", "joints:"]
    for i, ((d, a, alpha, m, com, inertia, torque), (jm, g, b, tc)) in enumerate(
        zip(JOINTS, MOTORS, strict=True)
    ):
        entry = {
            "d": d,
            "a": a,
            "alpha": alpha,
            "position": "[-3, 3]",
            "velocity": 5,
            "acceleration": 10,
            "jerk": 50,
            "mass": m,
            "com": com,
            "inertia": inertia,
            "torque": torque,
            "motor_inertia": jm,
            "gear_ratio": g,
            "viscous": b,
            "coulomb": tc,
        }
        for key, value in override.items():
            joint, name = key.split("_", 1)
            if int(joint[1:]) == i:
                entry[name] = value
        lines.append("  - {" + ", ".join(f"{k}: {v}" for k, v in entry.items()) + "}")
    return "\n".join(lines) + "\n" + payload


def test_robot_file_dynamics_match_roboticstoolbox(rng: np.random.Generator) -> None:
    robot = load_robot_text(robot_text())
    ref = rtb.DHRobot(
        [
            rtb.RevoluteDH(
                d=d,
                a=a,
                alpha=alpha,
                m=m,
                r=com,
                I=inertia,
                Jm=jm,
                G=g,
                B=b,
                Tc=tc,
            )
            for (d, a, alpha, m, com, inertia, _), (jm, g, b, tc) in zip(
                JOINTS, MOTORS, strict=True
            )
        ]
    )
    q = rng.uniform(-3, 3, (200, 6))
    qd = rng.uniform(-2, 2, (200, 6))
    qdd = rng.uniform(-8, 8, (200, 6))
    np.testing.assert_allclose(
        inverse_dynamics(robot, q, qd, qdd), ref.rne(q, qd, qdd), rtol=1e-9, atol=1e-12
    )
    np.testing.assert_array_equal(robot.dynamics.torque_max, [90, 180, 90, 24, 20, 21])
    np.testing.assert_array_equal(robot.dynamics.gravity, [0, 0, -9.81])


def test_payload_and_gravity_in_the_robot_file(rng: np.random.Generator) -> None:
    ceiling = load_robot_text(robot_text("gravity: [0, 0, 9.81]\n"))
    plain = load_robot_text(robot_text())
    q = rng.uniform(-3, 3, (20, 6))
    zero = np.zeros_like(q)
    holding = inverse_dynamics(plain, q, zero, zero)
    np.testing.assert_allclose(inverse_dynamics(ceiling, q, zero, zero), -holding, atol=1e-9)
    loaded = load_robot_text(robot_text("payload: {mass: 5, com: [0, 0, 0.1]}\n"))
    assert loaded.dynamics.payload.mass == 5.0
    assert np.abs(inverse_dynamics(loaded, q, zero, zero) - holding)[:, 1].max() > 5.0


@pytest.mark.parametrize(
    ("text", "message"),
    [
        (robot_text(j1_mass="-1"), "joints[1].mass: mass must be >= 0 kg, got -1"),
        (
            robot_text(j2_inertia="[0.1, 0.1, 0.1, 0.2, 0, 0]"),
            "joints[2].inertia: inertia is not positive semi-definite",
        ),
        (
            robot_text(j2_inertia="[0.066, 0.086, 0.0125, 0, 0, 0]"),
            "joints[2].inertia: inertia breaks the triangle inequality",
        ),
        (robot_text(j4_torque="0"), "joints[4].torque: torque limit must be > 0 N·m, got 0"),
        (robot_text(j3_torque="null", j3_mass="null"), "joints[3]: missing mass"),
        (
            robot_text("payload: {mass: -2}\n"),
            "payload.mass: mass must be >= 0 kg, got -2",
        ),
        (robot_text("payload: {mass: 1e300}\n"), "payload.mass: expected a number ≤ 100000"),
        (robot_text(j1_mass="1e300"), "joints[1].mass: expected a number ≤ 100000, got 1e+300"),
        (robot_text(j1_torque="1e300"), "joints[1].torque: expected a number ≤ 1e+07, got"),
        (
            robot_text(j2_inertia="[1e300, 1, 1, 0, 0, 0]"),
            "joints[2].inertia[0]: expected a number ≤ 100000, got 1e+300",
        ),
        (robot_text(j0_gear_ratio="1e300"), "joints[0].gear_ratio: expected a number ≤ 10000"),
        (robot_text(j0_viscous="1e300"), "joints[0].viscous: expected a number ≤ 1e+06"),
        (robot_text(j0_coulomb="[1e300, 0]"), "joints[0].coulomb[0]: expected a number ≤ 1e+07"),
        (robot_text(j0_motor_inertia="1e300"), "joints[0].motor_inertia: expected a number ≤"),
    ],
)
def test_bad_dynamics_are_one_line_errors(text: str, message: str) -> None:
    with pytest.raises(CaseError) as error:
        load_robot_text(text, file="robot.yaml")
    assert error.value.one_line().startswith(f"robot.yaml: {message}")


def test_bad_dynamics_exit_2_from_the_cli(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    (tmp_path / "robot.yaml").write_text(robot_text(j1_mass="-3"), encoding="utf-8")
    case = (CASES / "paper-line.yaml").read_text(encoding="utf-8")
    case = case.replace("robot: puma560", "robot: robot.yaml")
    assert "robot: robot.yaml" in case
    (tmp_path / "case.yaml").write_text(case, encoding="utf-8")
    code = main(["validate", str(tmp_path / "case.yaml")])
    err = capsys.readouterr().err
    assert code == ExitCode.BAD_INPUT
    assert err.strip().splitlines() == [
        f"{tmp_path / 'robot.yaml'}: joints[1].mass: mass must be >= 0 kg, got -3"
    ]


def test_case_payload_on_the_puma560(tmp_path: Path) -> None:
    case = (CASES / "paper-line.yaml").read_text(encoding="utf-8")
    file = tmp_path / "case.yaml"
    file.write_text(case + "payload: {mass: 5.0, com: [0, 0, 0.05]}\n", encoding="utf-8")
    payload = load_case(file).robot.dynamics.payload
    assert payload.mass == 5.0
    np.testing.assert_array_equal(payload.com, [0, 0, 0.05])
    file.write_text(
        case.replace("robot: puma560", "robot: ur5") + "payload: {mass: 5.0}\n", encoding="utf-8"
    )
    with pytest.raises(CaseError, match="robot ur5 has no dynamic parameters"):
        load_case(file)
