"""The continuous speed curve the smooth law takes near a wrist singularity."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from tests.conftest import CASES
from trackplan.io.case_file import load_case
from trackplan.planning.plan import check, plan
from trackplan.timing import continuous, curve_nodes, curve_program, smooth
from trackplan.timing.profile import SpeedProfile, speed_change_phases, speed_change_time
from trackplan.timing.sample_checks import robot_checks
from trackplan.timing.smooth import LIMIT_SHARE

WRIST_X = np.array([-0.1891, 0.1807, 0.1739, -0.5075, -1.3612, 1.5486])
"""A paper-line placement whose wrist passes near a singularity: joints 4 and 6 cap the speed
at 0.03 m/s over a few centimetres."""
WRIST_TOPP3 = 4.667
"""copp-py's TOPP3 on that joint path, s (``python -m benchmarks plan``'s reference)."""
WINDOWS_ONLY = 7.092
"""The window plan alone on that joint path, s (before the continuous curve)."""


CORNER_X = np.array([0.3838, 0.5001, 0.0963, 1.1437, -1.3496, -0.6161])
"""A random paper-corner placement (``python -m benchmarks plan``, seed 0) whose blend turns
joints 3, 4 and 6 hard within its 5 mm: the window plan took 8.56 s there, 1.135 × TOPP3."""
CORNER_TOPP3 = 7.541
"""copp-py's TOPP3 on that joint path, s."""
BRACKET_X = np.array([0.3969, -0.0753, 0.1047, 0.2625, -0.2849, 2.4899])
"""A random bracket-two-faces placement (seed 1) where the curve used to collapse at a blend
and the window plan stood at 30.3 s, 1.65 × TOPP3."""
BRACKET_TOPP3 = 18.380
"""copp-py's TOPP3 on that joint path, s."""
SEAM_X = np.array([0.218, 0.4117, 0.5431, 0.2251, 0.0495, 0.5351])
"""A random bracket-two-faces placement (seed 1) where the seam frame starts turning on the
straight 5 mm before the blend, between two planning-grid points 2 mm apart: the curve on
interpolated derivatives took 1.0486 × TOPP3 there."""
SEAM_TOPP3 = 18.329
"""copp-py's TOPP3 on that joint path, s."""
FRESH_X = np.array([0.1389, 0.1585, -0.334, 1.5527, -1.4335, -0.1822])
"""A paper-corner placement of a draw the curve was not tuned on (seed 2)."""
FRESH_TOPP3 = 7.553
"""copp-py's TOPP3 on that joint path, s."""


def _divided_differences(s: np.ndarray, x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """x' and x'' at the inner nodes from the quadratic through each three neighbours
    (Newton's divided differences), shape (G - 2,) each."""
    first = np.diff(x) / np.diff(s)  # x[k, k+1]
    second = np.diff(first) / (s[2:] - s[:-2])  # x[k-1, k, k+1]
    return first[:-1] + second * (s[1:-1] - s[:-2]), 2.0 * second


@pytest.fixture(scope="module")
def wrist():
    case = load_case(CASES / "paper-line.yaml")
    return case, plan(case, WRIST_X)


def test_near_a_wrist_singularity_the_law_is_within_4_percent_of_topp3(wrist):
    case, result = wrist
    assert result.feasible, result.message
    assert result.duration <= 1.04 * WRIST_TOPP3
    assert result.duration < 0.7 * WINDOWS_ONLY
    report = check(case, WRIST_X, result.trajectory.q, case.task.sample_time)
    assert report.success, report.violations[:3]
    assert any("joint 4" in d.limit or "joint 6" in d.limit for d in result.slowdowns)


def test_the_linear_program_meets_its_node_bounds(wrist):
    """x = ṡ² from the LP meets the discretised velocity, acceleration and jerk bounds at
    every node, on both sides of every node, with the jerk bound at the planned speed."""
    case, result = wrist
    robot = case.robot
    stretch = curve_nodes.split_stretches(result.joint_path, case.task)[0]
    limits = LIMIT_SHARE * np.stack([robot.v_max, robot.a_max, robot.j_max])[:, None, :]
    limits = np.broadcast_to(limits, (3, len(stretch.s), robot.n_dof))
    x = curve_program.solve_curve(stretch, limits, stretch.cap)
    assert x is not None
    v = np.sqrt(x)
    assert v.max() <= case.task.rated_speed
    assert np.all(np.abs(stretch.d1 * v[None, :, None]) <= limits[0] * (1 + 1e-6))
    slope, bend = _divided_differences(stretch.s, x)
    d1, d2, d3 = (d[:, 1:-1] for d in (stretch.d1, stretch.d2, stretch.d3))
    accel = d1 * slope[None, :, None] / 2 + d2 * x[None, 1:-1, None]
    jerk = v[None, 1:-1, None] * (
        d1 * bend[None, :, None] / 2 + 1.5 * d2 * slope[None, :, None] + d3 * x[None, 1:-1, None]
    )
    assert np.all(np.abs(accel) <= limits[1, 1:-1] * (1 + 1e-6) + 1e-9)
    assert np.all(np.abs(jerk) <= limits[2, 1:-1] * (1 + 1e-6) + 1e-9)
    # the curve rises above the constant-speed cap somewhere (signed demand cancels)
    cap, _ = continuous._joint_caps(stretch, robot, LIMIT_SHARE)
    assert np.any(v > 1.2 * cap)


def test_rest_envelope_is_a_start_at_constant_path_jerk():
    s = np.linspace(0.0, 0.01, 101)
    d1 = np.full((2, len(s), 1), 2.0)  # q' = 2 rad/m: path jerk J = j_max / 2
    jerk = np.full((len(s), 1), 8.0)
    x = curve_program._rest_envelope(s, d1, jerk)
    J = curve_program.REST_JERK_SHARE * 4.0
    t = np.cbrt(6 * s / J)  # s = J t³/6
    near_start = s <= 0.005
    assert np.allclose(x[near_start], (J * t[near_start] ** 2 / 2) ** 2, rtol=1e-12)
    assert x[0] == 0.0 and x[-1] == 0.0
    assert np.allclose(x, x[::-1], rtol=1e-12)  # the stop mirrors the start


def test_a_curve_that_cannot_beat_the_windows_is_given_up(wrist):
    """Given the window plan's duration to beat, the curve is planned when it is faster and
    given up (None) when even the nodes' own timing cannot beat a shorter one."""
    case, result = wrist
    checks = robot_checks(case.robot)
    curve = continuous.plan_speed_curve(
        result.joint_path, case.task, checks, LIMIT_SHARE, to_beat=WINDOWS_ONLY
    )
    assert curve is not None and curve.duration < WINDOWS_ONLY
    unbeatable = 0.5 * curve.duration
    assert (
        continuous.plan_speed_curve(
            result.joint_path, case.task, checks, LIMIT_SHARE, to_beat=unbeatable
        )
        is None
    )


@pytest.mark.parametrize(
    ("name", "X", "topp3"),
    [
        ("paper-corner", CORNER_X, CORNER_TOPP3),
        ("bracket-two-faces", BRACKET_X, BRACKET_TOPP3),
        ("bracket-two-faces", SEAM_X, SEAM_TOPP3),
    ],
)
def test_a_short_blend_that_turns_the_wrist_is_within_4_percent_of_topp3(name, X, topp3):
    """The nodes follow the planning grid into the blend, and off the grid where the seam
    frame turns, so the curve resolves them and is taken (the window plan was 1.135, 1.65
    and 1.05 × TOPP3 there), every sample re-checked."""
    _assert_planned_within(name, X, 1.04 * topp3)


def test_a_first_round_that_leaves_blend_nodes_at_rest_is_solved_again_lower():
    """At this corner placement (a fresh draw, seed 2 of the benchmark) the first round's
    room of 1.5 × the constant-speed cap left four nodes of the blend at rest, the curve was
    given up, and the window plan took 8.222 s, 1.089 × TOPP3; the room of 1.0 plans the
    curve (7.866 s at these rounded coordinates, 1.041 ×; 7.786 s, 1.031 ×, with the
    samples' time stretched evenly and the rests at 95 % of the path jerk), every sample
    re-checked."""
    _assert_planned_within("paper-corner", FRESH_X, 1.04 * FRESH_TOPP3)


REST_X = np.array([-0.2996, 0.4437, 0.2325, 0.5551, 1.51, 1.5166])
"""A paper-corner placement (seed 3 of the benchmark) where a rebuild's first round left one
node of the blend at rest."""
REST_TOPP3 = 7.6909
"""copp-py's TOPP3 on that joint path, s (``topp3_reference`` on the plan's joint path, as
``python -m benchmarks plan`` runs it, measured once)."""
PAYLOAD_X = np.array([-0.4502, 0.139, 0.0567, 0.6352, -0.2492, -1.1289])
"""A puma-payload placement (seed 3) where the torque check failed just after the blend:
the window plan, rebuilt for the torques, took 7.820 s, 1.049 × TOPP3."""
PAYLOAD_TOPP3 = 7.4525
"""copp-py's TOPP3 on that joint path, s (measured once, as :data:`REST_TOPP3`)."""
WRIST_FLIP_X = np.array([0.4356, -0.2384, 0.0836, -0.1436, -0.2325, 2.5266])
"""A bracket-two-faces placement (seed 3) where joints 4 and 6 turn against each other
before the blend (their q' about ±100 rad/m, q''' ±2e8 rad/m³): the path jerk steps from 0
to 37 m/s³ within one node, the samples failed the jerk check by up to 2 ×, and the
rebuilds took the curve from 18.20 s to 19.28 s, 1.041 × TOPP3."""
WRIST_FLIP_TOPP3 = 18.5199
"""copp-py's TOPP3 on that joint path, s (measured once, as :data:`REST_TOPP3`)."""


@pytest.mark.parametrize(
    ("name", "X", "topp3"),
    [
        ("paper-corner", REST_X, REST_TOPP3),
        ("puma-payload", PAYLOAD_X, PAYLOAD_TOPP3),
        ("bracket-two-faces", WRIST_FLIP_X, WRIST_FLIP_TOPP3),
    ],
)
def test_the_held_out_placements_of_seed_3_are_within_4_percent_of_topp3(name, X, topp3):
    """The three placements of the benchmark's seed 3 above 1.04 × TOPP3 (1.0446, 1.0492
    and 1.0410): a node at rest gives way to a faster try, the torque check lowers the speed
    where it fails, and a rebuild's lowered jerk limit lowers the path jerk too (the
    path-jerk rows); every sample re-checked."""
    _assert_planned_within(name, X, 1.04 * topp3)


START_X = np.array([-0.1205, 0.5056, 0.0068, 1.1294, 0.1302, 0.8987])
"""A paper-line placement (seed 6 of the benchmark) whose start runs through a stretch where
joint 6 turns hard (q' 12.7 rad/m, q''' -4000 rad/m³): the window plan's start, at one
acceleration and one jerk bound over its 76 mm, took 1.01 s against 0.59 s at the bounds the
joints allow at rest, and the plan 4.526 s, 1.0433 × TOPP3."""
START_TOPP3 = 4.3383
"""copp-py's TOPP3 on that joint path, s (``topp3_reference`` on the plan's joint path at
these rounded coordinates, as ``python -m benchmarks plan`` runs it, measured once)."""


def test_a_slow_start_through_high_joint_demand_tries_the_curve():
    """The start and the stop lose more than :data:`smooth.REST_CHANGE_SHARE` of the window
    plan's time there, so the curve is tried and taken (4.375 s, 1.0085 ×), every sample
    re-checked."""
    _assert_planned_within("paper-line", START_X, 1.04 * START_TOPP3)


def test_the_rest_change_loss_is_the_time_beyond_changes_at_the_rest_bounds(wrist):
    """A start at the bounds the joints allow at rest loses nothing; a stop at half their
    jerk loses the difference of the two changes' durations (to two samples at each end:
    a change is counted to the first sample whose backward difference is at the top speed)."""
    _, result = wrist
    joint_path, robot = result.joint_path, result.joint_path.robot
    Ts, top = 1e-3, 0.1
    first, last = np.abs(joint_path.dq[0]), np.abs(joint_path.dq[-1])
    accel = LIMIT_SHARE / np.max(first / robot.a_max)
    jerk = LIMIT_SHARE / np.max(first / robot.j_max)
    stop_accel = LIMIT_SHARE / np.max(last / robot.a_max)
    stop_jerk = LIMIT_SHARE / np.max(last / robot.j_max)
    phases = [*speed_change_phases(0.0, top, accel, jerk), (0.5, 0.0)]
    phases += speed_change_phases(top, 0.0, stop_accel, 0.5 * stop_jerk)
    duration = sum(d for d, _ in phases)
    profile = SpeedProfile.from_phases(phases, 1.0)
    s = profile.position(np.arange(int(np.ceil(duration / Ts)) + 1) * Ts)
    lost = speed_change_time(top, stop_accel, 0.5 * stop_jerk) - speed_change_time(
        top, stop_accel, stop_jerk
    )
    assert lost > 0.05
    assert abs(smooth._rest_change_loss(s, Ts, joint_path) - lost) <= 4 * Ts


def test_a_torque_failure_lowers_the_speed_around_it():
    """A check other than the rates (order 4 + o) puts a ceiling of
    ``(REBUILD_FACTOR / ratio)^(1/o)`` times the planned speed on the nodes around the
    failing sample, tapering off beyond the reach, and lowers the acceleration limit with
    its square; the rate limits and the cap stay."""
    s = np.linspace(0.0, 0.1, 101)
    speed = np.full(101, 0.2)
    scale = np.vstack([np.ones((4, 101)), np.full(101, np.inf)])
    hits = np.zeros(101, dtype=int)
    continuous._lower(s, speed, scale, hits, np.array([0.05]), np.array([6]), np.array([1.5]))
    target = (continuous.REBUILD_FACTOR / 1.5) ** 0.5
    assert np.allclose(scale[4, 47:54], target * 0.2)
    assert np.all(scale[4, :44] == np.inf) and np.all(scale[4, 57:] == np.inf)
    assert np.all(np.diff(scale[4, 44:51]) <= 0.0)  # tapering in
    assert np.allclose(scale[1, 47:54], target**2)
    assert np.all(scale[[0, 2, 3]] == 1.0)
    assert hits.sum() == 11


def _assert_planned_within(name: str, X: np.ndarray, duration: float) -> None:
    """The case ``name`` plans feasible at X within ``duration`` (s), and its trajectory
    passes the checker sample by sample."""
    case = load_case(CASES / f"{name}.yaml")
    result = plan(case, X)
    assert result.feasible, result.message
    assert result.duration <= duration
    report = check(case, X, result.trajectory.q, case.task.sample_time)
    assert report.success, report.violations[:3]


def test_no_node_inside_a_stretch_comes_to_rest_in_a_short_blend():
    """On the corner placement's joint path the linear program keeps every node of the
    blend above 80 % of the lowest speed the joints allow there at a constant speed (the
    window plan's plateau); with nodes 1 mm apart across the 5 mm blend and Σ x as
    objective, nodes came to rest there."""
    case = load_case(CASES / "paper-corner.yaml")
    joint_path = plan(case, CORNER_X).joint_path
    robot = case.robot
    (stretch,) = curve_nodes.split_stretches(joint_path, case.task)
    limits = LIMIT_SHARE * np.stack([robot.v_max, robot.a_max, robot.j_max])[:, None, :]
    limits = np.broadcast_to(limits, (3, len(stretch.s), robot.n_dof))
    x = curve_program.solve_curve(stretch, limits, stretch.cap)
    assert x is not None
    cap, _ = continuous._joint_caps(stretch, robot, LIMIT_SHARE)
    blend = (stretch.s > 0.4964) & (stretch.s < 0.5014)
    assert blend.sum() >= 50  # the grid's own points, 0.06 mm apart
    assert np.sqrt(x[blend]).min() >= 0.8 * cap[blend].min()


def test_nodes_keep_the_grid_points_and_grow_gradually():
    grid = np.concatenate(
        [np.linspace(0.0, 0.5, 251), np.linspace(0.5, 0.505, 83), np.linspace(0.505, 1.0, 250)]
    )
    nodes = curve_nodes._nodes(grid, 0.0, 1.0)
    steps = np.diff(nodes)
    assert nodes[0] == 0.0 and nodes[-1] == 1.0
    assert np.all(np.isin(np.unique(grid), nodes))
    assert steps.max() <= curve_nodes.NODE_SPACING * (1 + 1e-9)
    # neighbouring steps stay alike: at most NODE_GROWTH of the step apart (and a rounding)
    growth = np.maximum(steps[1:] / steps[:-1], steps[:-1] / steps[1:])
    assert growth.max() <= 1.0 + 1.2 * curve_nodes.NODE_GROWTH
    assert len(nodes) < 1.2 * (1.0 / curve_nodes.NODE_SPACING + 83)


@given(
    steps=st.lists(st.floats(1e-5, 1e-3), min_size=3, max_size=12),
    a=st.floats(-5.0, 5.0),
    b=st.floats(-5.0, 5.0),
    c=st.floats(-5.0, 5.0),
)
@settings(max_examples=40, deadline=None)
def test_three_point_differences_are_exact_for_quadratics(steps, a, b, c):
    s = np.concatenate([[0.0], np.cumsum(steps)])
    x = a + b * s + c * s**2
    slope, bend = curve_program._differences(s)
    rows = np.stack([x[:-2], x[1:-1], x[2:]], axis=1)
    scale = 1.0 + abs(b) + abs(c)
    assert np.allclose((slope * rows).sum(axis=1), b + 2 * c * s[1:-1], atol=1e-6 * scale)
    assert np.allclose((bend * rows).sum(axis=1), 2 * c, atol=1e-6 * scale / min(steps))


def test_the_nodes_see_the_seam_frame_start_turning_between_grid_points():
    """On the straight before the bracket's bend the planning grid is 2 mm apart, and the
    seam frame starts turning between two of its points: q''' rises from about 200 to 2e8
    rad/m³ at once. Every point of the last 22 mm before the blend (20 µm apart, derivatives
    by IK) asks the joints, at a constant speed, for at most 2.5 times what the larger of
    its two neighbouring nodes asks (it was 5.7 times with the grid's derivatives
    interpolated: a speed cap 1.8 times too high)."""
    case = load_case(CASES / "bracket-two-faces.yaml")
    joint_path = plan(case, SEAM_X).joint_path
    (stretch,) = curve_nodes.split_stretches(joint_path, case.task)
    blend = joint_path.geometry.zones()[0][1]
    points = np.arange(blend - 0.022, blend, 2e-5)
    demand = curve_nodes._steady_demand(
        joint_path.derivatives(points, 0.0, blend, 2e-5), case.robot
    )
    at_nodes = curve_nodes._steady_demand(
        tuple(np.abs(d).max(axis=0) for d in (stretch.d1, stretch.d2, stretch.d3)), case.robot
    )
    after = np.searchsorted(stretch.s, points)
    seen = np.maximum(at_nodes[after - 1], at_nodes[after])
    assert demand.max() ** (-1 / 3) < 0.02  # the turn caps the speed below the rated 0.02 m/s
    assert np.all(demand <= 2.5 * seen)
    # the grid gap where the turn starts holds one node between 1 mm fill steps; the
    # bisection puts more there, graded down towards the start
    start = points[np.argmax(demand > 1e3 * demand[0])]
    grid = np.unique(joint_path.s)
    k = np.searchsorted(grid, start)
    inner = (stretch.s > grid[k - 1]) & (stretch.s < grid[k])
    assert inner.sum() >= 6


def test_once_the_rebuilds_are_spent_the_curve_runs_slower_instead_of_being_given_up(
    monkeypatch,
):
    """With a single plan allowed, the corner placement's first curve (7.99 s of node timing,
    whose start fails the jerk check by 1.36 ×) is stretched in time by the worst failure's
    ratio (1.36^(1/3) = 1.11) until its samples pass, instead of being given up; every
    sample re-checked."""
    case = load_case(CASES / "paper-corner.yaml")
    joint_path = plan(case, REST_X).joint_path
    checks = robot_checks(case.robot)
    monkeypatch.setattr(continuous, "MAX_REBUILDS", 1)
    curve = continuous.plan_speed_curve(joint_path, case.task, checks, LIMIT_SHARE)
    assert curve is not None and 1 < curve.rebuilds <= 1 + continuous.SLOW_DOWNS
    assert curve.duration <= 1.112 * 7.992
    report = check(case, REST_X, curve.motion.q, case.task.sample_time)
    assert report.success, report.violations[:3]


def test_the_slow_down_meets_the_worst_failure_of_each_order():
    """A jerk 1.331 × its limit needs the time 1.1 × longer, a speed 1.01 × its cap 1.01 ×,
    a torque whose speed factor is squared (order 4 + 2) at 1.21 × 1.1 ×."""
    order = np.array([3, 4, 6, 2])
    ratio = np.array([1.331, 1.01, 1.21, 1.1])
    slower = continuous._slow_down(order, ratio)
    assert slower == pytest.approx(1.1 * continuous.SLOW_DOWN_MARGIN)


@pytest.mark.parametrize("rows", [True, False])
def test_a_lowered_jerk_limit_lowers_the_path_jerk_at_a_wrist_flip(rows, monkeypatch):
    """Where joints 4 and 6 turn against each other, with the jerk limits at a quarter (as
    rebuilds lower them around failing samples), the linear program without the path-jerk
    rows meets them by cancelling ``ṡ q' x''/2`` against the other terms, 3.1 times the
    lowered limit; with the rows that term itself stays within CANCEL_ROOM times it."""
    room = curve_program.CANCEL_ROOM
    case = load_case(CASES / "bracket-two-faces.yaml")
    joint_path = plan(case, WRIST_FLIP_X).joint_path
    robot = case.robot
    (stretch,) = curve_nodes.split_stretches(joint_path, case.task)
    limits = LIMIT_SHARE * np.stack([robot.v_max, robot.a_max, 0.25 * robot.j_max])[:, None, :]
    limits = np.broadcast_to(limits, (3, len(stretch.s), robot.n_dof))
    if not rows:
        monkeypatch.setattr(curve_program, "CANCEL_ROOM", np.inf)
    x = curve_program.solve_curve(stretch, limits, stretch.cap)
    assert x is not None
    _, bend = _divided_differences(stretch.s, x)
    path_jerk = np.sqrt(x[1:-1])[None, :, None] * stretch.d1[:, 1:-1] * bend[None, :, None] / 2
    worst = np.max(np.abs(path_jerk) / limits[2, 1:-1])
    if rows:
        assert worst <= room * (1 + 1e-6)
    else:
        assert worst > 1.4 * room
