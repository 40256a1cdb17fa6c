"""One plan reads its samples' derivatives, tool poses and torques from one pass each, and
builds the case's paths once for every plan."""

from __future__ import annotations

import numpy as np

import trackplan
import trackplan.motion as motion
import trackplan.planning.checker as checker
import trackplan.planning.seam_plan as seam_plan
import trackplan.timing.sample_checks as sample_checks
from tests.conftest import CASES
from trackplan.planning.plan import plan


def test_a_plan_makes_one_derivative_fk_and_rne_pass_over_its_samples(monkeypatch):
    case = trackplan.load_case(CASES / "paper-corner.yaml")
    assert case.robot.dynamics is not None
    calls: list[tuple[str, int]] = []

    def counted(name, function):
        def wrapper(*args, **kwargs):
            q = next(a for a in args if isinstance(a, np.ndarray))
            calls.append((name, len(q)))
            return function(*args, **kwargs)

        return wrapper

    for module in (motion, checker, sample_checks):
        for name in ("backward_derivatives", "forward_kinematics", "inverse_dynamics"):
            if hasattr(module, name):
                monkeypatch.setattr(module, name, counted(name, getattr(module, name)))
    result = plan(case, case.bounds.example)
    assert result.success, result.message
    assert result.energy is not None
    n = result.trajectory.n_samples
    on_samples = [(name, rows) for name, rows in calls if rows in (n, n + 3)]
    assert sorted(on_samples) == [
        ("backward_derivatives", n),
        ("forward_kinematics", n),
        ("inverse_dynamics", n + 3),
    ]
    # and no other: the FK of the points between the samples (tracking between them) is
    # the checker's task frames' own pass (trackplan.planning._kernels.task_frames)
    assert [name for name, rows in calls if rows not in (n, n + 3)] == []


def test_every_plan_of_a_case_shares_its_paths():
    case = trackplan.load_case(CASES / "paper-corner.yaml")
    first = plan(case, case.bounds.example)
    second = plan(case, case.bounds.example + 0.01)
    assert first.joint_path.geometry is second.joint_path.geometry
    assert seam_plan.case_geometry(case) is first.joint_path.geometry
    other = trackplan.load_case(CASES / "paper-corner.yaml")
    assert seam_plan.case_geometry(other) is not first.joint_path.geometry
