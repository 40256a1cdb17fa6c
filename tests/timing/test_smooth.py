"""The smooth time law: steady speed where allowed, slow-down windows where not."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from tests.conftest import CASES
from trackplan.io.case_file import load_case
from trackplan.planning.plan import plan_placement
from trackplan.timing.smooth import WINDOW_MIN_LENGTH, _level_runs


def test_level_runs_merge_short_runs_into_slower_ones():
    s = np.linspace(0.0, 0.1, 101)  # 1 mm grid
    level = np.zeros(101, dtype=int)
    level[40:42] = 3  # a 1 mm dip: too short for a window of its own
    level[60:90] = 1
    runs = _level_runs(s, level, WINDOW_MIN_LENGTH)
    for first, last in runs:
        assert s[last] - s[first] >= WINDOW_MIN_LENGTH or len(runs) == 1
    # the dip survives (merged into a slower neighbourhood, never sped up)
    covering = next(r for r in runs if r[0] <= 40 <= r[1])
    assert covering[1] - covering[0] >= 4


def test_a_joint_limit_forces_a_reported_slow_down(tmp_path):
    case = load_case(CASES / "paper-corner.yaml")
    slow_robot = replace(case.robot, v_max=case.robot.v_max * np.array([1, 1, 1, 0.1, 1, 1]))
    slow_case = replace(case, robot=slow_robot)
    result = plan_placement(slow_case, case.bounds.example)
    assert result.feasible, result.message
    assert result.slowdowns, "joint 4 at 0.5 rad/s cannot keep 0.15 m/s on the whole path"
    assert any("joint 4 velocity" in d.limit for d in result.slowdowns)
    for slow in result.slowdowns:
        assert slow.speed < slow.rated_speed and slow.s_end > slow.s_start
    assert result.rated_speed_fraction < 0.85
    qd = result.trajectory.qd[:, 3]
    assert np.abs(qd).max() <= slow_robot.v_max[3]
    assert np.abs(qd).max() > 0.9 * slow_robot.v_max[3]  # the binding limit is used


def test_rated_speed_held_exactly_elsewhere(tmp_path):
    case = load_case(CASES / "paper-line.yaml")
    result = plan_placement(case, case.bounds.example)
    traj = result.trajectory
    path_speed = np.diff(traj.s) / traj.sample_time
    assert path_speed.max() == pytest.approx(case.task.rated_speed, rel=1e-12)


def test_rebuilds_until_the_sampled_trajectory_meets_every_limit(monkeypatch):
    """Aiming above the limits, the law must still end within them by tightening zones."""
    import dataclasses

    import trackplan.timing as timing
    import trackplan.timing.smooth as smooth

    monkeypatch.setattr(smooth, "LIMIT_SHARE", 1.1)
    laws = []
    original = smooth.plan_smooth_time_law

    def spy(*args, **kwargs):
        laws.append(original(*args, **kwargs))
        return laws[-1]

    spec = dataclasses.replace(smooth.SPEC, plan=spy)
    monkeypatch.setitem(timing.TIME_LAWS, smooth.SPEC.timing, spec)
    case = load_case(CASES / "paper-corner.yaml")
    result = plan_placement(case, case.bounds.example)
    assert laws[-1].iterations > 1 and laws[-1].success
    assert result.feasible, result.message
