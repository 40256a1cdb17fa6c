"""A case's ``tcp`` key: parsed into ``case.robot``, refused as one located line (exit 2),
honoured by the closed-form IK families, the planned joints (against roboticstoolbox),
result.json and a KRL export's tool frame."""

from __future__ import annotations

import json
from dataclasses import replace
from pathlib import Path
from typing import Any

import numpy as np
import pytest
import yaml

import trackplan
from tests.conftest import CASES
from tests.io.test_case_file import validate_fails, write_case
from tests.oracles import oracle
from tests.programs.krl_parser import parse_krl
from tests.robots.test_families import assert_round_trip
from trackplan.case import Case
from trackplan.cli import main
from trackplan.frames import pose_matrix, rpy_matrix
from trackplan.io.case_file import load_case
from trackplan.io.robot_file import builtin_robot, robot_to_yaml
from trackplan.jointpath import JointPath
from trackplan.outputs import write_run
from trackplan.planning.result import PlanResult
from trackplan.report.html_case import case_section
from trackplan.robots.dynamics.rne import inverse_dynamics
from trackplan.robots.families import ik_family
from trackplan.robots.kinematics import joint_frames
from trackplan.writers import ExportSource

TCP = {"xyz": [0.02, -0.01, 0.12], "rpy": [0.1, 0.3839724354387525, -0.2]}
"""A torch-like TCP: 0.12 m out, bent 22° (rad) about y, a little roll and yaw."""
TOOL_OF_ROBOT_FILE = {"xyz": [0.0, 0.0, 0.25], "rpy": [0.0, 0.3, 0.0]}


def tcp_matrix(tcp: dict[str, Any]) -> np.ndarray:
    return pose_matrix(np.array(tcp["xyz"]), rpy_matrix(np.array(tcp["rpy"])))


def robot_file_with_tool(folder: Path) -> Path:
    """The PUMA560's robot file with a tool of its own."""
    parsed = yaml.safe_load(robot_to_yaml(builtin_robot("puma560")))
    parsed["tool"] = TOOL_OF_ROBOT_FILE
    file = folder / "arm.yaml"
    file.write_text(yaml.safe_dump(parsed, sort_keys=False), encoding="utf-8")
    return file


# --------------------------------------------------------------------------- parsing


@pytest.mark.parametrize("robot", ["puma560", "kuka_kr6_r700_sixx", "ur5e"])
def test_the_tcp_is_the_robots_tool_on_a_builtin_arm(tmp_path: Path, robot: str) -> None:
    case = load_case(write_case(tmp_path, {"robot": robot, "tcp": TCP}))
    np.testing.assert_allclose(case.robot.T_flange_tool, tcp_matrix(TCP), atol=1e-15)
    np.testing.assert_array_equal(case.robot_tool, np.eye(4))
    assert case.tcp_source == "case"
    # the rest of the robot is the built-in one
    builtin = builtin_robot(robot)
    np.testing.assert_array_equal(case.robot.origins, builtin.origins)
    np.testing.assert_array_equal(case.robot.v_max, builtin.v_max)


def test_without_tcp_the_robots_own_tool_is_used(tmp_path: Path) -> None:
    plain = load_case(write_case(tmp_path))
    assert plain.robot_tool is None and plain.tcp_source == "none"
    arm = robot_file_with_tool(tmp_path)
    own = load_case(write_case(tmp_path, {"robot": arm.name}, name="own.yaml"))
    assert own.robot_tool is None and own.tcp_source == "robot"
    np.testing.assert_allclose(own.robot.T_flange_tool, tcp_matrix(TOOL_OF_ROBOT_FILE))


def test_the_cases_tcp_wins_over_the_robot_files_tool(tmp_path: Path) -> None:
    arm = robot_file_with_tool(tmp_path)
    case = load_case(write_case(tmp_path, {"robot": arm.name, "tcp": TCP}))
    np.testing.assert_allclose(case.robot.T_flange_tool, tcp_matrix(TCP), atol=1e-15)
    assert case.robot_tool is not None
    np.testing.assert_allclose(case.robot_tool, tcp_matrix(TOOL_OF_ROBOT_FILE), atol=1e-15)
    assert case.tcp_source == "case"


def test_tcp_defaults_to_the_flange_and_still_replaces_the_robots_tool(tmp_path: Path) -> None:
    arm = robot_file_with_tool(tmp_path)
    case = load_case(write_case(tmp_path, {"robot": arm.name, "tcp": {}}))
    np.testing.assert_array_equal(case.robot.T_flange_tool, np.eye(4))
    assert case.tcp_source == "case"


@pytest.mark.parametrize(
    ("tcp", "where", "what"),
    [
        ({"xyz": [0, 0]}, "tcp.xyz", "expected 3 numbers"),
        ({"xyz": [0, 0, 0.1, 0]}, "tcp.xyz", "expected 3 numbers"),
        ({"rpy": [0, 0]}, "tcp.rpy", "expected 3 numbers"),
        ({"xyz": [0, 0, ".nan"]}, "tcp.xyz[2]", "expected a finite number"),
        ({"xyz": [0, 0, ".inf"]}, "tcp.xyz[2]", "expected a finite number"),
        ({"rpy": [0, "-.inf", 0]}, "tcp.rpy[1]", "expected a finite number"),
        ({"xyz": [0, 0, "a"]}, "tcp.xyz[2]", "expected a number"),
        ({"xyz": [0, 0, 1.0e4]}, "tcp.xyz[2]", "expected a number ≤ 1000"),
        ({"rpy": [-2.0e3, 0, 0]}, "tcp.rpy[0]", "expected a number ≥ -1000"),
        ({"xyz": [900, 900, 0]}, "tcp.xyz", "at most 1000 m from the flange"),
        ({"xyz": [0, 0, 0.1], "mass": 2}, "tcp.mass", "unknown key"),
        ([0, 0, 0.1], "tcp", "expected a mapping"),
    ],
)
def test_a_bad_tcp_is_one_located_line(
    capsys: pytest.CaptureFixture[str], tmp_path: Path, tcp: Any, where: str, what: str
) -> None:
    file = write_case(tmp_path, {"tcp": tcp})
    text = file.read_text().replace("'.nan'", ".nan").replace("'.inf'", ".inf")
    file.write_text(text.replace("'-.inf'", "-.inf"), encoding="utf-8")
    line = validate_fails(capsys, str(file))
    assert f"{where}:" in line or f"{where} " in line, line
    assert what in line, line
    assert str(file) in line


def test_validate_prints_the_cases_tcp(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["validate", str(CASES / "kuka-torch.yaml")]) == 0
    out = capsys.readouterr().out
    assert "tcp       xyz [0.045, 0, 0.35] m, rpy [0, 0.383972, 0] rad" in out
    assert main(["validate", str(CASES / "kuka-weld.yaml")]) == 0
    assert "  tcp  " not in capsys.readouterr().out


def test_a_top_level_tool_points_to_tcp(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    file = write_case(tmp_path, {"tool": TCP})
    line = validate_fails(capsys, str(file))
    assert "tcp: {xyz, rpy}" in line and "task.tool" in line, line


# --------------------------------------------------------------------------- kinematics


@pytest.mark.parametrize("robot", ["kuka_kr6_r700_sixx", "abb_irb1600", "ur5e", "ur10e"])
def test_closed_form_ik_stays_exact_with_the_cases_tcp(
    tmp_path: Path, robot: str, rng: np.random.Generator
) -> None:
    case = load_case(write_case(tmp_path, {"robot": robot, "tcp": TCP}))
    assert ik_family(case.robot).name == ("ur" if robot.startswith("ur") else "opw")
    assert_round_trip(case.robot, rng.uniform(-np.pi, np.pi, (2000, 6)), found=0.999)


def test_planned_joints_put_the_tcp_on_the_planned_poses(tmp_path: Path) -> None:
    """roboticstoolbox's FK of the planned joints with the case's TCP as its tool is the
    planned tool pose at every grid point; without the TCP it is not."""
    rtb = oracle("roboticstoolbox")
    from spatialmath import SE3

    case = load_case(write_case(tmp_path, {"tcp": TCP}))
    X = np.array([0.0, 0.3, -0.2, 0.0, 0.0, 0.0])  # reachable with this TCP
    result = trackplan.plan(case, X)
    path: JointPath = result.joint_path
    assert path.success, path.message
    planned = path.poses(path.s)
    links = [rtb.RevoluteDH(d=d, a=a, alpha=al, offset=o) for d, a, al, o in case.robot.dh]
    with_tcp = rtb.DHRobot(links, tool=SE3(tcp_matrix(TCP), check=False))
    without = rtb.DHRobot(links)
    fk = np.array([with_tcp.fkine(q).A for q in path.q])
    assert np.abs(fk - planned).max() < 1e-8
    # the frame the cell's tool capsules ride (docs/cell.md) is the TCP too
    np.testing.assert_allclose(joint_frames(case.robot, path.q)[:, -1], fk, rtol=0, atol=1e-9)
    bare = np.array([without.fkine(q).A for q in path.q])
    assert np.abs(bare[:, :3, 3] - planned[:, :3, 3]).max() > 0.1
    # the trajectory's tool point is the TCP too
    fk_samples = np.array([with_tcp.fkine(q).A[:3, 3] for q in result.trajectory.q[::50]])
    np.testing.assert_allclose(fk_samples, result.trajectory.tool_position[::50], atol=1e-9)


def entries(inertia: np.ndarray) -> list[float]:
    """An inertia matrix as a payload's ``[Ixx, Iyy, Izz, Ixy, Iyz, Ixz]``."""
    pairs = ((0, 0), (1, 1), (2, 2), (0, 1), (1, 2), (0, 2))
    return [float(inertia[i, j]) for i, j in pairs]


def test_the_payload_sits_at_the_cases_tcp(tmp_path: Path, rng: np.random.Generator) -> None:
    """A payload given in the case's TCP frame has the torques of the same body given in the
    flange frame (centre of mass moved by the TCP, inertia turned by its rotation)."""
    tcp = {"xyz": [0.02, -0.01, 0.3], "rpy": [0.2, 0.4, -0.1]}
    T = tcp_matrix(tcp)
    com = np.array([0.01, 0.0, 0.05])
    inertia = np.array([[0.03, 0.001, 0.002], [0.001, 0.035, 0.003], [0.002, 0.003, 0.02]])
    at_tcp = load_case(
        write_case(
            tmp_path,
            {
                "tcp": tcp,
                "payload": {"mass": 4.0, "com": com.tolist(), "inertia": entries(inertia)},
            },
            "tcp.yaml",
        )
    )
    R = T[:3, :3]
    in_flange = load_case(
        write_case(
            tmp_path,
            {
                "payload": {
                    "mass": 4.0,
                    "com": (T[:3, :3] @ com + T[:3, 3]).tolist(),
                    "inertia": entries(R @ inertia @ R.T),
                }
            },
            "flange.yaml",
        )
    )
    q, qd, qdd = (rng.uniform(-2, 2, (200, 6)) for _ in range(3))
    tau_tcp = inverse_dynamics(at_tcp.robot, q, qd, qdd)
    tau_flange = inverse_dynamics(in_flange.robot, q, qd, qdd)
    np.testing.assert_allclose(tau_tcp, tau_flange, rtol=0, atol=1e-9)
    moved = replace(at_tcp.robot, T_flange_tool=np.eye(4))  # the same payload at the flange
    assert np.abs(inverse_dynamics(moved, q, qd, qdd) - tau_tcp).max() > 0.1


# --------------------------------------------------------------------------- outputs


@pytest.fixture(scope="module")
def torch_plan() -> tuple[Case, PlanResult]:
    """cases/kuka-torch.yaml planned at its example placement."""
    case = load_case(CASES / "kuka-torch.yaml")
    assert case.bounds.example is not None
    result = trackplan.plan(case, np.asarray(case.bounds.example))
    assert result.feasible, result.message
    return case, result


@pytest.fixture(scope="module")
def torch_run(
    tmp_path_factory: pytest.TempPathFactory, torch_plan: tuple[Case, PlanResult]
) -> Path:
    """The kuka-torch plan as a run folder."""
    case, result = torch_plan
    folder = tmp_path_factory.mktemp("torch") / "run"
    write_run(folder, result, case, report=False)
    return folder


def test_the_report_states_the_tcp_and_its_source(torch_plan: tuple[Case, PlanResult]) -> None:
    case, result = torch_plan
    html = case_section(result, case)
    assert "xyz (0.045, 0, 0.35) m, rpy (0, 0.384, 0) rad (the case&#x27;s tcp)" in html
    plain = load_case(CASES / "kuka-weld.yaml")
    assert "none (tool = flange)" in case_section(result, plain)


def test_kuka_torch_is_feasible_and_records_its_tcp(torch_run: Path) -> None:
    summary = json.loads((torch_run / "result.json").read_text())
    assert summary["status"] == "feasible"
    tcp = summary["tcp"]
    assert tcp["source"] == "case" and tcp["replaced"] is None
    np.testing.assert_allclose(tcp["xyz"], [0.045, 0.0, 0.35], atol=1e-12)
    np.testing.assert_allclose(tcp["rpy"], [0.0, np.radians(22.0), 0.0], atol=1e-12)


def test_result_json_says_the_cases_tcp_replaced_the_robots_tool(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    arm = robot_file_with_tool(tmp_path)
    example = [0.0, 0.3, -0.2, 0.0, 0.0, 0.0]
    for name, changes in (
        ("case", {"robot": arm.name, "tcp": TCP}),
        ("robot", {"robot": arm.name}),
        ("none", {}),
    ):
        file = write_case(tmp_path, {**changes, "placement.example": example}, f"{name}.yaml")
        out = tmp_path / f"run-{name}"
        main(["plan", str(file), "--out", str(out), "--no-report"])
        capsys.readouterr()
        tcp = json.loads((out / "result.json").read_text())["tcp"]
        assert tcp["source"] == name
        want = {"case": TCP, "robot": TOOL_OF_ROBOT_FILE, "none": {"xyz": [0] * 3, "rpy": [0] * 3}}
        np.testing.assert_allclose(tcp["xyz"], want[name]["xyz"], atol=1e-12)
        np.testing.assert_allclose(tcp["rpy"], want[name]["rpy"], atol=1e-12)
        if name == "case":
            np.testing.assert_allclose(tcp["replaced"]["xyz"], TOOL_OF_ROBOT_FILE["xyz"])
            np.testing.assert_allclose(tcp["replaced"]["rpy"], TOOL_OF_ROBOT_FILE["rpy"])
        else:
            assert tcp["replaced"] is None


def test_a_krl_export_sets_the_cases_tcp_as_its_tool(torch_run: Path, tmp_path: Path) -> None:
    out = tmp_path / "krl"
    trackplan.export(ExportSource.of(torch_run), out, format="krl")
    files = {file.name: file.read_bytes().decode("ascii") for file in sorted(out.iterdir())}
    parsed = parse_krl(files)
    want = tcp_matrix({"xyz": [0.045, 0.0, 0.35], "rpy": [0.0, np.radians(22.0), 0.0]})
    assert np.abs(parsed.tool[:3, 3] - want[:3, 3]).max() < 1e-6  # m: KRL writes mm
    assert np.abs(parsed.tool[:3, :3] - want[:3, :3]).max() < 1e-6
