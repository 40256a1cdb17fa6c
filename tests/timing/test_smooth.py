"""The smooth time law: steady speed where allowed, slow-down windows where not."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from tests.conftest import CASES
from trackplan.io.case_file import load_case
from trackplan.paths.path_geometry import PathGeometry
from trackplan.planning.plan import check, plan
from trackplan.robots.dynamics.rne import holding_torque_ratio
from trackplan.timing.sample_checks import LIMIT_MARGIN, RateLimits, run_checks
from trackplan.timing.smooth import plan_smooth_time_law
from trackplan.timing.zones import WINDOW_MIN_LENGTH, level_runs

WRIST_TURN_CASES = {"paper-circle-seam-fixed", "paper-circle-seam-free"}
"""Their seam frame turns the tool once about its axis: at a constant spin no placement has a
joint path on the PUMA560; tests/search/test_spin.py plans and checks them with the spin
chosen."""
SLOW_CELLS = ("cad-", "positioner-", "track-")
"""Shipped welding cells and CAD parts: their draws are slow tests (their own acceptance tests
run in the fast tier's place: tests/axes, tests/cad)."""
SHIPPED_PATHS = [
    pytest.param(
        file.stem,
        seam,
        marks=[pytest.mark.slow] if file.stem.startswith(SLOW_CELLS) else [],
    )
    for file in sorted(CASES.glob("*.yaml"))
    if file.stem not in WRIST_TURN_CASES
    for seam in range(len(load_case(file).seams))
]
"""(case, seam index) of every shipped path: each seam of a case with several seams."""
PLACEMENTS_PER_CASE = 3


def test_level_runs_merge_short_runs_into_slower_ones():
    s = np.linspace(0.0, 0.1, 101)  # 1 mm grid
    level = np.zeros(101, dtype=int)
    level[40:42] = 3  # a 1 mm dip: too short for a window of its own
    level[60:90] = 1
    runs = level_runs(s, level, WINDOW_MIN_LENGTH)
    for first, last in runs:
        assert s[last] - s[first] >= WINDOW_MIN_LENGTH or len(runs) == 1
    # the dip survives (merged into a slower neighbourhood, never sped up)
    covering = next(r for r in runs if r[0] <= 40 <= r[1])
    assert covering[1] - covering[0] >= 4


def _level_runs_reference(s, level, shortest):  # type: ignore[no-untyped-def]
    """The merge rule in plain numpy, one merge per pass (reference of the compiled one)."""
    level = level.copy()
    while True:
        edges = np.flatnonzero(np.diff(level)) + 1
        starts = np.concatenate([[0], edges])
        ends = np.concatenate([edges - 1, [len(level) - 1]])
        lengths = s[ends] - s[starts]
        short = np.flatnonzero(lengths < shortest)
        if short.size == 0 or len(starts) == 1:
            return list(zip(starts.tolist(), ends.tolist(), strict=True))
        k = int(short[np.argmin(lengths[short])])
        own = int(level[starts[k]])
        neighbours = [j for j in (k - 1, k + 1) if 0 <= j < len(starts)]
        slower = max(neighbours, key=lambda j: int(level[starts[j]]))
        if int(level[starts[slower]]) >= own:
            level[starts[k] : ends[k] + 1] = level[starts[slower]]
        else:
            level[starts[slower] : ends[slower] + 1] = own


def test_level_runs_match_the_plain_merge_rule():
    rng = np.random.default_rng(7)
    for _ in range(200):
        n = int(rng.integers(1, 120))
        s = np.cumsum(rng.uniform(0.0, 2e-3, n))
        level = np.repeat(rng.integers(0, 4, n), rng.integers(1, 6, n))[:n]
        shortest = float(rng.uniform(0.0, 0.02))
        assert level_runs(s, level, shortest) == _level_runs_reference(s, level, shortest)


def test_a_joint_limit_forces_a_reported_slow_down(tmp_path):
    case = load_case(CASES / "paper-corner.yaml")
    slow_robot = replace(case.robot, v_max=case.robot.v_max * np.array([1, 1, 1, 0.1, 1, 1]))
    slow_case = replace(case, robot=slow_robot)
    result = plan(slow_case, case.bounds.example)
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
    result = plan(case, case.bounds.example)
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

    spec = dataclasses.replace(smooth.LAW, plan=spy)
    monkeypatch.setitem(timing.TIME_LAWS, smooth.LAW.timing, spec)
    case = load_case(CASES / "paper-corner.yaml")
    result = plan(case, case.bounds.example)
    assert laws[-1].iterations > 1 and laws[-1].success
    assert result.feasible, result.message


CELL_LIMITS = ("collision", "clearance")
"""Violations of the work cell, which the geometry decides and no time law changes."""


@pytest.mark.parametrize(("name", "seam"), SHIPPED_PATHS)
def test_random_placements_of_every_case_pass_the_checker(name, seam):
    """Wherever the path has a joint path the robot can hold against gravity, the smooth
    law's samples pass every check."""
    case = load_case(CASES / f"{name}.yaml").seam_case(seam)
    geometry = PathGeometry.from_case(case)
    rng = np.random.default_rng(sum(map(ord, name)) + seam)
    lower, upper = case.bounds.lower, case.bounds.upper
    reach_min, reach_max = case.bounds.reach
    planned = 0
    for _ in range(2000):
        X = rng.uniform(lower, upper)
        if not reach_min <= np.linalg.norm(X[:3]) <= reach_max:
            continue
        result = plan(case, X, geometries={(0, False): geometry})
        if not result.joint_path.success:
            continue
        if case.robot.dynamics and holding_torque_ratio(case.robot, result.joint_path.q) > 1:
            continue  # the robot cannot hold the path still: no time law helps
        report = check(case, X, result.trajectory.q, case.task.sample_time)
        timing_violations = [v for v in report.violations if v.limit not in CELL_LIMITS]
        if len(timing_violations) < len(report.violations):
            continue  # the placement collides with the cell: no time law helps
        planned += 1
        assert result.success, (X, result.message)
        assert report.success, (X, report.violations)
        if planned == PLACEMENTS_PER_CASE:
            break
    assert planned == PLACEMENTS_PER_CASE


def test_planned_speed_stays_under_the_corner_cap_by_the_margin():
    """ur5-bead at Ts = 1 ms once exceeded its corner speed by 9e-8 m/s: the law plans
    arcs and blends at (1 - LIMIT_MARGIN) of the corner speed, straights at the rated one."""
    case = load_case(CASES / "ur5-bead.yaml")
    fine = replace(case, task=replace(case.task, sample_time=1e-3))
    geometry = PathGeometry.from_case(fine)
    rng = np.random.default_rng(8)
    for _ in range(2000):
        X = rng.uniform(case.bounds.lower, case.bounds.upper)
        result = plan(fine, X, geometries={(0, False): geometry})
        if result.joint_path.success:
            break
    traj = result.trajectory
    speed = np.diff(traj.s) / traj.sample_time
    curved = geometry.on_curved_zone(traj.s[1:]) & geometry.on_curved_zone(traj.s[:-1])
    corner = case.task.corner_speed
    assert speed[curved].max() <= corner * (1 - LIMIT_MARGIN) * (1 + 1e-9)
    assert speed[curved].max() > 0.99 * corner  # the arcs do run at the corner speed
    assert speed.max() == pytest.approx(case.task.rated_speed, rel=1e-12)


def test_a_sample_check_handed_to_the_law_is_met():
    """Another limit joins the rebuild loop as one more check, without touching the law."""
    case = load_case(CASES / "paper-corner.yaml")
    free = plan(case, case.bounds.example)
    cap = 0.5 * np.abs(free.trajectory.qd[:, 0]).max()

    def joint_1_speed(q, sample_time):
        qd = np.abs(np.diff(q[:, 0], prepend=q[0, 0])) / sample_time
        bad = np.flatnonzero(qd > cap)
        return bad, np.ones(bad.size, dtype=int), qd[bad] / cap

    law = plan_smooth_time_law(
        free.joint_path, case.task, sample_checks=(RateLimits(case.robot), joint_1_speed)
    )
    assert law.success and law.iterations > 1
    assert joint_1_speed(law.q, case.task.sample_time)[0].size == 0
    assert law.duration > free.duration
    assert not run_checks((RateLimits(case.robot),), law.q, case.task.sample_time)[0].size


def test_rate_limits_keep_a_relative_margin(puma):
    """A sample 5e-7 under a limit counts as a violation: the law keeps 1e-6 clear of it."""
    Ts = 1e-3
    q = np.zeros((10, 6))
    q[5:, 0] = (1 - 5e-7) * puma.v_max[0] * Ts * np.arange(1, 6)
    sample, order, ratio = RateLimits(puma)(q, Ts)
    assert 1 in order[sample >= 5]
    assert np.all(ratio > 1.0)
    assert not RateLimits(puma, margin=0.0)(q[:, :1].repeat(6, axis=1) * 0, Ts)[0].size
