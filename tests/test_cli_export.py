"""`trackplan export` on a planned run."""

from __future__ import annotations

import yaml

from tests.conftest import CASES
from trackplan.cli import main


def test_export_ros_csv_json_and_bad_format(tmp_path, capsys):
    run = tmp_path / "run"
    assert main(["plan", str(CASES / "paper-line.yaml"), "--out", str(run), "--no-report"]) == 0
    assert main(["export", str(run), "--format", "ros", "--joint-names", "a,b,c,d,e,f"]) == 0
    message = yaml.safe_load((run / "trajectory.ros.yaml").read_text())
    assert message["joint_names"] == ["a", "b", "c", "d", "e", "f"]
    point = message["points"][-1]
    assert set(point) == {"positions", "velocities", "accelerations", "effort", "time_from_start"}
    assert len(point["positions"]) == 6
    assert main(["export", str(run), "--format", "json"]) == 0
    assert (run / "trajectory.json").is_file()
    other = tmp_path / "elsewhere.csv"
    assert main(["export", str(run), "--format", "csv", "--output", str(other)]) == 0
    assert other.read_text().startswith("t,")
    assert main(["export", str(run), "--format", "xml"]) == 2
    assert "unknown export format" in capsys.readouterr().err
