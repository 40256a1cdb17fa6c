"""Weaving planned and checked like the seam (issue 29's acceptance, docs/positioner.md).

The case ``cases/kuka-weld-weave.yaml`` weaves 2 mm at 2 Hz; its ``task.weave`` is built
here in code, so the test holds whether or not the case file parser reads the key.
"""

from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np
import pytest
import yaml

import trackplan
from tests.programs.roundtrip import PlannedRun
from trackplan.case import Case
from trackplan.errors import CaseError
from trackplan.frames import placement_transform
from trackplan.io.results import result_summary, seams_summary
from trackplan.motion import JointSamples
from trackplan.planning.checker import check_motion
from trackplan.planning.seam_plan import case_geometry, tracking_reference
from trackplan.programs import build_program
from trackplan.robots.kinematics import forward_kinematics
from trackplan.tool.weave import Weave

CASE = Path(__file__).parents[2] / "cases" / "kuka-weld-weave.yaml"


def _case(tmp_path: Path, **weave: float) -> Case:
    """The example case, its weave given in code (``amplitude`` etc. override it)."""
    data = yaml.safe_load(CASE.read_text())
    given = data["task"].pop("weave")
    file = tmp_path / "case.yaml"
    file.write_text(yaml.safe_dump(data))
    case = trackplan.load_case(file)
    task = dataclasses.replace(case.task, weave=Weave(**{**given, **weave}))
    return dataclasses.replace(case, task=task)


def _lateral(case: Case, q: np.ndarray, placement: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Our own measure of the weave on the first seam line (y = 0, along +x, normal +z):
    the tool point's offset along the seam frame's y axis (−y there) from the robot's FK,
    and whether the point lies on the line's middle (x in [0.02, 0.13] m)."""
    T_part_tool = np.linalg.inv(placement_transform(placement)) @ forward_kinematics(case.robot, q)
    p = T_part_tool[:, :3, 3]
    on_line = (p[:, 0] > 0.02) & (p[:, 0] < 0.13) & (np.abs(p[:, 1]) < 0.01)
    return -p[:, 1], on_line


@pytest.mark.slow
def test_weave_2mm_2hz_reached_within_every_limit(tmp_path: Path) -> None:
    case = _case(tmp_path)
    placement = case.bounds.example
    result = trackplan.plan(case, placement)
    assert result.success, result.message
    assert all(v.min() >= 0.0 for v in result.check.joint_margins.values())
    assert result.check.task_margins["weave"] >= 0.0

    # the project's checker again, from the joints alone
    geometry = case_geometry(case)
    again = check_motion(
        JointSamples(case.robot, result.trajectory.q, case.task.sample_time),
        tracking_reference(case, geometry, placement),
    )
    assert again.success, again.violations

    # our own FK: the lateral excursion and its zero crossings on the first line
    q, t = result.trajectory.q, result.trajectory.t
    lateral, on_line = _lateral(case, q, placement)
    amplitude = (lateral[on_line].max() - lateral[on_line].min()) / 2.0
    assert amplitude == pytest.approx(0.002, rel=0.05)
    k = np.flatnonzero(on_line[:-1] & on_line[1:] & (lateral[:-1] < 0) & (lateral[1:] >= 0))
    crossings = t[k] - lateral[k] / (lateral[k + 1] - lateral[k]) * (t[k + 1] - t[k])
    assert len(crossings) >= 5
    frequency = (len(crossings) - 1) / (crossings[-1] - crossings[0])
    assert frequency == pytest.approx(2.0, rel=0.01)

    # the figures the result states
    assert result.weave is not None
    assert result.weave.amplitude == pytest.approx(0.002, rel=0.05)
    assert result.weave.frequency == pytest.approx(2.0, rel=0.01)
    stated = result_summary(result, case.robot.joint_names)["weave"]
    assert stated == {
        "amplitude": result.weave.amplitude,
        "frequency": result.weave.frequency,
        "pattern": "triangle",
        "plane": "seam",
    }


@pytest.mark.slow
@pytest.mark.parametrize("wrong", [{"amplitude": 0.001}, None])
def test_a_wrong_weave_fails_the_check(tmp_path: Path, wrong: dict[str, float] | None) -> None:
    case = _case(tmp_path)
    if wrong is None:  # planned without a weave
        other = dataclasses.replace(case, task=dataclasses.replace(case.task, weave=None))
    else:  # planned with the amplitude 50 % off
        other = _case(tmp_path, **wrong)
    placement = case.bounds.example
    planned = trackplan.plan(other, placement)
    assert planned.success, planned.message
    checked = check_motion(
        JointSamples(case.robot, planned.trajectory.q, case.task.sample_time),
        tracking_reference(case, case_geometry(case), placement),
    )
    assert not checked.success
    assert any(v.limit == "weave" for v in checked.violations)
    assert checked.task_margins["weave"] < 0.0


@pytest.mark.slow
def test_a_weaving_run_exports_joints_not_path_moves(tmp_path: Path) -> None:
    """Path moves along the centre line would drop the weave: the Cartesian form is
    refused in one line, the joint form carries the planned joints, weave included."""
    case = _case(tmp_path)
    result = trackplan.plan(case, case.bounds.example)
    run = PlannedRun(case=case, plan=result)
    with pytest.raises(CaseError, match=r"--motion: .*weave.*--motion joint"):
        build_program(run)
    program = build_program(run, motion="joint", period=0.02)
    assert program.motion == "joint"


@pytest.mark.slow
def test_one_weaving_seam_of_several() -> None:
    """bracket-4-fillets with its first rib weaving 2 mm at 2 Hz: the cycle stays
    feasible, the rib's plan and result.json's seam state the weave, the others none. The
    puma560's joint 3 jerk slows the rib at the turn-arounds, so its frequency is lower."""
    case = trackplan.load_case(CASE.parent / "bracket-4-fillets.yaml")
    seams = list(case.paths)
    weave = Weave(amplitude=0.002, frequency=2.0)
    seams[0] = dataclasses.replace(seams[0], task=dataclasses.replace(seams[0].task, weave=weave))
    case = dataclasses.replace(case, paths=tuple(seams))
    result = trackplan.plan(case, case.bounds.example)
    assert result.success, result.message
    stated = {seam["name"]: seam["weave"] for seam in seams_summary(result, case)["seams"]}
    rib = stated.pop("rib-left")
    assert rib["amplitude"] == pytest.approx(0.002, rel=0.01)
    assert 1.0 < rib["frequency"] < 2.0
    assert set(stated.values()) == {None}
    assert all(check.success for check in result.seam_checks)
