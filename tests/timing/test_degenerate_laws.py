"""Degenerate inputs to the time laws end in a verdict that names what and where, never in
a ZeroDivisionError or NaN samples (docs/timing.md, "When no speed helps")."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from tests.conftest import CASES
from trackplan.cli import ExitCode, main
from trackplan.errors import CaseError
from trackplan.io.case_file import load_case
from trackplan.jointpath import JointPath
from trackplan.paths.path_geometry import PathGeometry
from trackplan.planning.plan import plan
from trackplan.status import Status
from trackplan.timing import smooth, zones
from trackplan.timing.airmove import plan_air_move
from trackplan.timing.continuous import _sample
from trackplan.tool import ToolOrientation

ON_THE_AXIS = np.array([0.0, 0.0, -0.2, 0.0, 0.0, 0.0])
"""Puts the seam's start on joint 1's axis of the KR10 R1420 (the torch held vertical): the
shoulder singularity, where joint 1 jumps between the first pose and the next."""


@pytest.fixture(scope="module")
def axis_case_file(tmp_path_factory):
    """One straight seam from the KR10 R1420's joint 1 axis, the torch vertical."""
    text = (CASES / "kuka-weld.yaml").read_text()
    text = text.replace("robot: kuka_kr6_r700_sixx", "robot: kuka_kr10_r1420")
    text = text.replace(
        "tool_rpy: [3.141592653589793, 0.5, 0]", "tool_rpy: [3.141592653589793, 0, 0]"
    )
    start = text.index("  segments:")
    end = text.index("task:")
    text = text[:start] + "  segments:\n    - line: {to: [0.15, 0, 0]}\n" + text[end:]
    file = tmp_path_factory.mktemp("axis") / "axis.yaml"
    file.write_text(text)
    return file


def test_a_joint_path_that_jumps_at_the_start_is_a_verdict_not_a_zero_division(axis_case_file):
    case = load_case(axis_case_file)
    result = plan(case, ON_THE_AXIS)
    assert result.status is Status.LIMITS_VIOLATED
    message = result.message
    assert "joint 1" in message
    assert "no speed meets it" in message
    assert "s = 0.0" in message  # where: the path's start
    assert result.trajectory.n_samples == 0


def test_the_cli_exits_3_with_the_verdict(axis_case_file, tmp_path, capsys):
    args = ["plan", str(axis_case_file), "--placement", *map(str, ON_THE_AXIS)]
    code = main([*args, "--out", str(tmp_path / "run"), "--no-report"])
    out, err = capsys.readouterr()
    assert code == ExitCode.INFEASIBLE, out + err
    assert "no speed meets it" in out + err
    assert "Traceback" not in out + err and "ZeroDivision" not in out + err


def test_a_plan_collapsed_to_zero_speed_is_a_verdict(axis_case_file, monkeypatch):
    """Every window's plateau 0 (a zero-duration profile) from the first plan on."""
    case = load_case(axis_case_file)
    geometry = PathGeometry.from_case(case)
    tool = ToolOrientation.choose(case.task.tool, geometry)
    joint_path = JointPath.solve(case.robot, geometry, np.array([0.45, 0, 0.05, 0, 0, 0]), tool)
    assert joint_path.success
    planned = zones.ZonePlanner.plan

    def at_rest(self):  # type: ignore[no-untyped-def]
        return [
            zones.ZonePlan(p.s_start, p.s_end, p.kind, p.cap, 0.0, "joint 2 velocity")
            for p in planned(self)
        ]

    monkeypatch.setattr(zones.ZonePlanner, "plan", at_rest)
    law = smooth.plan_smooth_time_law(joint_path, case.task)
    assert not law.success
    assert law.status is Status.LIMITS_VIOLATED
    assert "joint 2 velocity" in law.message and "s = 0.0000..0.1500 m" in law.message
    assert law.s.size == 0


def test_a_speed_curve_of_no_length_is_not_sampled():
    """The continuous curve's stretches of zero length: no curve (the window law stands)."""

    class Still:
        s = np.zeros(3)

    assert _sample([Still()], [np.zeros(3)], 0.004) is None  # type: ignore[list-item]


@pytest.mark.parametrize("apart", [0.0, 1e-15, 1e-12])
def test_an_air_move_of_no_length_is_finite(apart):
    q0 = np.zeros(6)
    move = plan_air_move(q0, q0 + apart, np.ones(6), np.ones(6), np.ones(6), 0.004)
    assert np.all(np.isfinite(move.q))
    assert move.q[0] == pytest.approx(q0, abs=0) and move.q[-1] == pytest.approx(q0 + apart, abs=0)


KR6_FEASIBLE = np.array([0.3147, -0.0547, 0.0967, 0.046, -0.1904, -0.014])
"""A placement of the KUKA weld case the search found feasible."""


@pytest.mark.parametrize(
    ("name", "value"),
    [
        ("rated_speed", 0.0),
        ("corner_speed", 0.0),
        ("corner_speed", float("nan")),
        ("sample_time", 0.0),
        ("tolerance", -1e-3),
    ],
)
def test_a_task_built_in_code_with_no_speed_is_bad_input(name, value):
    """The case loader refuses these in files; a Task built in code is refused the same way
    (before: a zero corner speed planned a standstill, a NaN one passed every check)."""
    case = load_case(CASES / "kuka-weld.yaml")
    bad = replace(case, task=replace(case.task, **{name: value}))
    with pytest.raises(CaseError, match=rf"task\.{name}: must be a finite number > 0"):
        plan(bad, KR6_FEASIBLE)


def test_a_tiny_task_speed_is_not_blamed_on_a_singularity():
    case = load_case(CASES / "kuka-weld.yaml")
    slow = replace(case, task=replace(case.task, rated_speed=1e-9))
    result = plan(slow, KR6_FEASIBLE)
    assert result.status is Status.LIMITS_VIOLATED
    assert "rated speed holds the speed to 1e-09 m/s" in result.message
    assert "singularity" not in result.message
