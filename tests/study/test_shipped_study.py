"""The shipped robot-selection study: its parts fit every arm it compares."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from trackplan.io.study_file import load_study

STUDY = Path(__file__).resolve().parents[2] / "studies" / "robot-selection.yaml"


def test_robot_selection_runs_every_part_on_three_industrial_arms() -> None:
    study = load_study(STUDY)
    assert set(study.robots) == {"kuka_kr6_r700_sixx", "abb_irb1600", "ur10e"}
    parts = {job.case_label for job in study.jobs}
    assert len(parts) >= 4
    assert len(study.jobs) == len(parts) * len(study.robots)
    for job in study.jobs:
        # no placement box in a part file: each arm searches ± its own reach
        reach = np.floor(job.case.robot.reach * 100.0) / 100.0
        np.testing.assert_array_equal(job.case.bounds.upper[:3], [reach] * 3)
        assert job.case.robot.name == job.robot
