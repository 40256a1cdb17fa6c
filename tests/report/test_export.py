"""Trajectory export: CSV, JSON and ROS 2 JointTrajectory YAML from a run directory."""

from __future__ import annotations

import json

import numpy as np
import pytest
import yaml

from trackplan.errors import CaseError
from trackplan.io.export import read_trajectory_table
from trackplan.io.results import trajectory_header, write_result_json, write_trajectory_csv
from trackplan.io.run_folder import HASH_KEY, file_sha256
from trackplan.writers import export_trajectory

# yaml.safe_load's constructors, in libyaml's C loader: ten times faster on 1834 points
SAFE_LOADER = getattr(yaml, "CSafeLoader", yaml.SafeLoader)
NAMES = ["waist", "shoulder", "elbow", "wrist_roll", "wrist_pitch", "flange"]


@pytest.fixture
def run_dir(tmp_path, corner_result):
    """A run directory as ``trackplan plan`` leaves it: trajectory.csv and result.json."""
    write_trajectory_csv(corner_result.trajectory, tmp_path / "trajectory.csv")
    digest = file_sha256(tmp_path / "trajectory.csv")
    write_result_json(
        {"case": "paper-corner", "joint_names": NAMES, HASH_KEY: digest}, tmp_path / "result.json"
    )
    return tmp_path


def test_ros_yaml_has_the_joint_trajectory_layout(run_dir, corner_result):
    written = export_trajectory(run_dir, "ros")
    assert written == run_dir / "trajectory.ros.yaml"
    message = yaml.load(written.read_text(), Loader=SAFE_LOADER)
    assert list(message) == ["header", "joint_names", "points"]
    assert message["header"] == {"stamp": {"sec": 0, "nanosec": 0}, "frame_id": ""}
    assert message["joint_names"] == NAMES
    trajectory = corner_result.trajectory
    points = message["points"]
    assert len(points) == trajectory.n_samples
    for k in (0, 1, 199, 200, trajectory.n_samples - 1):
        point = points[k]
        assert list(point) == [
            "positions",
            "velocities",
            "accelerations",
            "effort",
            "time_from_start",
        ]
        assert point["positions"] == trajectory.q[k].tolist()
        assert point["velocities"] == trajectory.qd[k].tolist()
        assert point["accelerations"] == trajectory.qdd[k].tolist()
        assert point["effort"] == []
        stamp = point["time_from_start"]
        assert isinstance(stamp["sec"], int) and 0 <= stamp["nanosec"] < 1_000_000_000
        assert stamp["sec"] + 1e-9 * stamp["nanosec"] == pytest.approx(trajectory.t[k], abs=1e-9)
    assert points[200]["time_from_start"] == {"sec": 1, "nanosec": 0}  # t = 200 · 5 ms


def test_csv_round_trip(run_dir, corner_result):
    written = export_trajectory(run_dir / "trajectory.csv", "csv")
    assert written == run_dir / "trajectory.export.csv"
    lines = written.read_text().splitlines()
    assert lines[0] == ",".join(["t", *NAMES])
    table = np.loadtxt(written, delimiter=",", skiprows=1)
    np.testing.assert_array_equal(table[:, 0], corner_result.trajectory.t)
    np.testing.assert_array_equal(table[:, 1:], corner_result.trajectory.q)


def test_json_round_trip(run_dir, corner_result):
    content = json.loads(export_trajectory(run_dir, "json").read_text())
    trajectory = corner_result.trajectory
    assert content["joint_names"] == NAMES
    assert content["units"]["positions"] == "rad" and content["units"]["t"] == "s"
    for key, expected in (
        ("t", trajectory.t),
        ("positions", trajectory.q),
        ("velocities", trajectory.qd),
        ("accelerations", trajectory.qdd),
        ("jerks", trajectory.qddd),
        ("tool_position", trajectory.tool_position),
        ("speed", trajectory.speed),
    ):
        np.testing.assert_array_equal(np.array(content[key]), expected, err_msg=key)


def test_in_memory_trajectory_matches_the_file(run_dir, tmp_path, corner_result):
    from_file = export_trajectory(run_dir, "json", tmp_path / "a" / "from-file.json")
    from_memory = export_trajectory(
        corner_result.trajectory, "json", tmp_path / "b.json", joint_names=NAMES
    )
    assert from_file.read_text() == from_memory.read_text()
    with pytest.raises(CaseError, match="output file is needed"):
        export_trajectory(corner_result.trajectory, "ros")


def test_output_overrides_the_file_and_a_directory_takes_the_default_name(run_dir, tmp_path):
    target = tmp_path / "out" / "robot.yaml"
    assert export_trajectory(run_dir, "ROS", target) == target
    assert target.exists()
    (tmp_path / "dir").mkdir()
    assert (
        export_trajectory(run_dir, "csv", tmp_path / "dir")
        == tmp_path / "dir" / "trajectory.export.csv"
    )


def test_joint_names_default_to_q1_qn_without_result_json(tmp_path, corner_result):
    write_trajectory_csv(corner_result.trajectory, tmp_path / "trajectory.csv")
    assert read_trajectory_table(tmp_path).joint_names == tuple(f"q{i}" for i in range(1, 7))
    with pytest.raises(CaseError, match=r"no result\.json beside trajectory\.csv"):
        export_trajectory(tmp_path, "ros")  # a run folder must vouch for its trajectory
    csv = tmp_path / "trajectory.csv"
    message = yaml.load(export_trajectory(csv, "ros", frame_id="base").read_text(), SAFE_LOADER)
    assert message["joint_names"] == [f"q{i}" for i in range(1, 7)]
    assert message["header"]["frame_id"] == "base"


def _write(directory, header, rows):
    text = ",".join(header) + "\n" + "".join(",".join(map(str, r)) + "\n" for r in rows)
    (directory / "trajectory.csv").write_text(text)


@pytest.mark.parametrize(
    ("header", "rows", "message"),
    [
        (trajectory_header(2)[:-1], [[0.0] * 13], "header must be"),
        (["t", "q2", "q1", *trajectory_header(2)[3:]], [[0.0] * 14], "header must be"),
        (trajectory_header(2), [], "no sample"),
        (trajectory_header(2), [[0.0] * 14, [0.1] * 13], "malformed row"),
        (trajectory_header(2), [[0.0] * 14, ["abc"] * 14], "malformed row"),
        (trajectory_header(2), [[0.0] * 14, [0.1, "nan", *[0.0] * 12]], "non-finite q1 on line 3"),
        (trajectory_header(2), [[0.1] * 14, [0.1] * 14], "increase"),
    ],
)
def test_malformed_trajectory_files_raise_case_error(tmp_path, header, rows, message):
    _write(tmp_path, header, rows)
    with pytest.raises(CaseError, match=message) as raised:
        export_trajectory(tmp_path / "trajectory.csv", "csv")
    assert raised.value.file == str(tmp_path / "trajectory.csv")


def test_missing_trajectory_and_bad_arguments(tmp_path, run_dir):
    with pytest.raises(CaseError, match="no trajectory file") as raised:
        export_trajectory(tmp_path / "nothing", "csv")
    assert raised.value.file == str(tmp_path / "nothing" / "trajectory.csv")
    with pytest.raises(CaseError, match="unknown export format 'xml'"):
        export_trajectory(run_dir, "xml")
    with pytest.raises(CaseError, match="6 distinct joint names"):
        export_trajectory(run_dir, "csv", joint_names=["a", "b"])
    digest = file_sha256(run_dir / "trajectory.csv")
    names = ["a", "a", "b", "c", "d", "e"]
    write_result_json({"joint_names": names, HASH_KEY: digest}, run_dir / "result.json")
    with pytest.raises(CaseError, match="distinct joint names") as raised:
        export_trajectory(run_dir, "csv")
    assert raised.value.file == str(run_dir / "result.json")
    (run_dir / "result.json").write_text("{not json")
    with pytest.raises(CaseError, match=r"unreadable result\.json"):
        export_trajectory(run_dir, "csv")
