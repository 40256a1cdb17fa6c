"""The Cartesian speed check: one verdict for the search and the final check, and a message
that names the cap that applies (docs/conventions.md, "How the limits are checked")."""

from __future__ import annotations

import numpy as np
import pytest

from tests.conftest import CASES
from trackplan.derived import derived
from trackplan.io.case_file import load_case
from trackplan.jointpath import JointPath
from trackplan.paths.path_geometry import PathGeometry
from trackplan.planning.checker import (
    IK_POSITION_TOLERANCE,
    RELATIVE_SLACK,
    check_trajectory,
    speed_slack,
)
from trackplan.planning.plan import plan, tracking_reference
from trackplan.robots.families import detect
from trackplan.search.fitness import PlacementFitness
from trackplan.search.screening import code
from trackplan.search.space import SearchSpace
from trackplan.status import Status
from trackplan.tool import ToolOrientation


def test_speed_slack_is_derived_from_the_ik_tolerance_and_the_sample_time():
    # two tool points, each within the IK tolerance of its path point, one period apart
    assert speed_slack(0.004) == pytest.approx(2.0 * IK_POSITION_TOLERANCE / 0.004, rel=1e-12)
    assert speed_slack(0.001) == pytest.approx(4.0 * speed_slack(0.004), rel=1e-12)


@pytest.fixture(scope="module")
def numeric_kr10(tmp_path_factory):
    """The KUKA weld seam on a KUKA KR10 R1420 solved by numeric IK (as a vendor URDF the
    closed forms do not recognise is), with the placement where its plan ran 1.2e-6 above
    the rated speed."""
    text = (CASES / "kuka-weld.yaml").read_text()
    file = tmp_path_factory.mktemp("kr10") / "kr10.yaml"
    file.write_text(text.replace("robot: kuka_kr6_r700_sixx", "robot: kuka_kr10_r1420"))
    case = load_case(file)
    # the robot's IK family, derived once and kept on it: numeric here
    derived(case.robot, "ik family", lambda: detect.NumericFamily(case.robot))
    assert isinstance(detect.ik_family(case.robot), detect.NumericFamily)
    return case


def test_a_placement_the_search_counts_feasible_passes_the_final_check(numeric_kr10):
    case = numeric_kr10
    X = np.array([0.45, 0.0, 0.05, 0.0, 0.0, 0.0])
    geometry = PathGeometry.from_case(case)
    fitness = PlacementFitness(case, SearchSpace.from_case(case), geometry, "smooth")
    screened = fitness.evaluate(X[None])
    assert screened.finding[0] == code(Status.FEASIBLE)  # the search's verdict
    planned = plan(case, X, geometries={(0, False): geometry}, branch=int(screened.branch[0]))
    rated = case.task.rated_speed
    peak = float(planned.trajectory.speed.max())
    # the numeric IK's error (≤ 1e-10 m a sample) does lift the sampled speed above the
    # rated speed the law plans exactly (by 2.5e-8 m/s here): the slack covers it
    assert rated < peak <= rated + speed_slack(case.task.sample_time)
    assert planned.feasible, planned.message
    assert planned.check.task_margins["speed"] == 0.0


KR6_FEASIBLE = np.array([0.3147, -0.0547, 0.0967, 0.046, -0.1904, -0.014])
"""A placement of the KUKA weld case the search found feasible."""


def _straight_at(case, geometry, X, speed):
    """Joints moving the tool along the first (straight) piece at a constant speed, m/s."""
    tool = ToolOrientation.choose(case.task.tool, geometry)
    joint_path = JointPath.solve(case.robot, geometry, X, tool)
    assert joint_path.success, joint_path.message
    Ts = case.task.sample_time
    n = 200
    s = np.arange(n) * speed * Ts
    return joint_path.joints(s)


@pytest.mark.parametrize("side", [-0.5, 0.5])
def test_an_over_speed_just_past_the_slack_is_rejected_by_margin_and_violation(side):
    case = load_case(CASES / "kuka-weld.yaml")
    geometry = PathGeometry.from_case(case)
    X = KR6_FEASIBLE
    Ts = case.task.sample_time
    rated = case.task.rated_speed
    allowed = speed_slack(Ts) + RELATIVE_SLACK * rated
    planted = rated + allowed * (1.0 + side)  # half the slack below or above its edge
    q = _straight_at(case, geometry, X, planted)
    report = check_trajectory(case.robot, q, Ts, tracking_reference(case, geometry, X))
    speeds = [v for v in report.violations if v.limit == "speed"]
    if side < 0:
        assert not speeds
        assert report.task_margins["speed"] == 0.0
    else:
        assert len(speeds) == 1
        # the margin the search grades by says the same as the violation
        assert report.task_margins["speed"] < 0.0
        assert speeds[0].bound == rated
        assert "rated speed" in speeds[0].message


def test_an_over_speed_names_the_cap_that_applies_and_why():
    """Over the rated speed on the first straight, then slowly into the arc: the cap that
    applies is the rated speed, not the lowest cap of the trajectory (the corner speed)."""
    case = load_case(CASES / "kuka-weld.yaml")
    geometry = PathGeometry.from_case(case)
    X = KR6_FEASIBLE
    Ts = case.task.sample_time
    rated, corner = case.task.rated_speed, case.task.corner_speed
    assert corner < rated
    (_, straight_end, kind), (_, _, next_kind) = geometry.zones()[:2]
    assert (kind, next_kind) == ("straight", "curved")
    fast = np.arange(0.0, straight_end, 1.1 * rated * Ts)
    slow = fast[-1] + np.arange(1, 300) * 0.5 * corner * Ts
    tool = ToolOrientation.choose(case.task.tool, geometry)
    joint_path = JointPath.solve(case.robot, geometry, X, tool)
    q = joint_path.joints(np.concatenate([fast, slow]))
    report = check_trajectory(case.robot, q, Ts, tracking_reference(case, geometry, X))
    (violation,) = [v for v in report.violations if v.limit == "speed"]
    assert violation.bound == rated
    assert (
        f"exceeds the rated speed {rated:g} m/s (the cap on straight pieces)" in violation.message
    )
    assert f"{corner:g}" not in violation.message
    assert violation.t_last < len(fast) * Ts  # the straight only
