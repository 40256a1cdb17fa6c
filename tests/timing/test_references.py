"""toppra and copp-py TOPP3 references on the joint path trackplan times."""

from __future__ import annotations

import numpy as np
import pytest

from tests.conftest import CASES
from trackplan.io.case_file import load_case
from trackplan.planning.checker import check_trajectory
from trackplan.planning.plan import plan
from trackplan.timing.references import (
    reference_durations,
    reference_inputs,
    speed_caps,
    topp3_reference,
    toppra_reference,
)

pytest.importorskip("toppra")
pytest.importorskip("copp_py")

LINE = np.array([-0.2230, 0.1029, 0.1829, 0.0312, -0.4124, 0.5020])


@pytest.fixture(scope="module")
def line():
    case = load_case(CASES / "paper-line.yaml")
    result = plan(case, LINE, timing="smooth")
    assert result.joint_path.success
    s_grid, q_grid, caps = reference_inputs(result.joint_path, case.task)
    return case, result, s_grid, q_grid, caps


@pytest.fixture(scope="module")
def toppra_line(line):
    case, _, s_grid, q_grid, caps = line
    return toppra_reference(case.robot, s_grid, q_grid, caps, case.task.sample_time)


def test_toppra_is_a_lower_bound_of_the_smooth_law(line, toppra_line):
    case, result, *_ = line
    assert result.feasible
    assert toppra_line.success, toppra_line.message
    length = result.planned_path.length
    assert length / case.task.rated_speed <= toppra_line.duration <= result.duration
    assert toppra_line.compute_time_s > 0.0


def test_toppra_output_meets_its_limits_but_breaks_jerk(line, toppra_line):
    case, *_ = line
    q = toppra_line.q
    assert q.shape == (len(toppra_line.s), 6)
    assert toppra_line.s[-1] == pytest.approx(line[2][-1])
    report = check_trajectory(case.robot, q, case.task.sample_time)
    jerks = [v for v in report.violations if v.limit == "jerk"]
    assert jerks, "constant-acceleration pieces step the acceleration: jerk must be broken"
    assert max(abs(v.worst) / v.bound for v in jerks) > 10.0
    # velocity and acceleration are toppra's own constraints (a sampling margin aside)
    assert np.min(report.joint_margins["velocity"]) > -0.02
    assert np.min(report.joint_margins["acceleration"]) > -0.1


def test_topp3_is_slower_than_toppra_and_meets_jerk():
    # a short synthetic joint path keeps the SOCP fast
    case = load_case(CASES / "paper-line.yaml")
    s = np.linspace(0.0, 0.12, 121)
    q = np.stack([0.2 * np.sin(4.0 * s + i) + 2.0 * s for i in range(6)], axis=1)
    caps = speed_caps([(0.0, 0.06, "straight"), (0.06, 0.12, "curved")], s, 0.15, 0.1)
    second = toppra_reference(case.robot, s, q, caps, 1e-3)
    third = topp3_reference(case.robot, s, q, caps, 1e-3)
    assert second.success and third.success, (second.message, third.message)
    assert third.duration >= second.duration * (1 - 1e-6)
    report = check_trajectory(case.robot, third.q, 1e-3)
    # jerk is met up to the solver's station discretisation (not to the sample)
    assert np.min(report.joint_margins["jerk"]) > -0.25
    # the speed cap holds on the sampled output (path speed = ds/dt)
    speed = np.diff(third.s) / 1e-3
    cap = np.interp(third.s[1:], s, caps)
    assert np.all(speed <= cap * 1.02)


def test_speed_caps_follow_the_zones():
    s = np.array([0.0, 0.1, 0.2, 0.3])
    caps = speed_caps([(0.0, 0.15, "straight"), (0.15, 0.25, "curved")], s, 0.2, 0.1)
    np.testing.assert_allclose(caps, [0.2, 0.2, 0.1, 0.2])


def test_reference_durations_keys(line, monkeypatch):
    case, result, *_ = line
    import trackplan.timing.references as references

    def fake_topp3(robot, s_grid, q_grid, caps, sample_time):
        return references.ReferenceResult(
            "topp3", True, "", 9.0, 0.0, sample_time, np.zeros(0), np.zeros((0, 6))
        )

    monkeypatch.setattr(references, "topp3_reference", fake_topp3)
    durations = reference_durations(result.joint_path, case.task)
    assert set(durations) == {"toppra_duration", "topp3_duration"}
    assert durations["topp3_duration"] == 9.0
    assert durations["toppra_duration"] <= result.duration
