"""Golden values: plans of every shipped case at fixed placements, recorded before the
planning speed-up (one pose, IK, FK, derivative and RNE pass per plan), must not change
beyond round-off: to :data:`TOLERANCE` (relative), except the tool axis error (an arccos
near 1) and the jerk and acceleration figures (differences over Ts³ and Ts²), each to the
resolution that round-off leaves them. Outcomes, sample counts and messages are compared
exactly.

The placements are each case's ``placement.example``, or for a case without one a
placement drawn once with a seeded generator inside its bounds (the corner cell at the
corner case's example, where the cell check reports a collision). The recorded figures
are in ``plan_golden.json`` next to this file; ``python -m tests.planning.test_plan_golden``
rewrites it (only after a change that is meant to change results).
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import numpy as np
import pytest

import trackplan
from tests.conftest import CASES
from trackplan.planning.checker import ORIENTATION_TOLERANCE

GOLDEN = Path(__file__).with_name("plan_golden.json")
PLACEMENTS: dict[str, list[float] | None] = {
    "paper-line": None,
    "paper-corner": None,
    "paper-circle": None,
    "paper-circle-seam-fixed": None,
    "paper-circle-seam-free": None,
    "puma-payload": None,
    "bracket-weld": None,
    "paper-corner-cell": [0.0902, 0.209, 0.202, 0.3263, 0.3016, -0.2522],
    "kuka-weld": [0.321, -0.143, 0.175, -0.132, -0.009, 3.019],
    "seam-weld-fixed": [0.342, -0.238, 0.4, -0.132, -0.009, 3.019],
    "seam-weld-free": [0.342, -0.238, 0.4, -0.132, -0.009, 3.019],
    "ur5-bead": [0.014, 0.541, -0.199, 0.449, -0.188, -0.482],
    "ur5e-glue": [0.012, 0.45, -0.128, 0.269, -0.113, -0.482],
}
"""Case name → placement (None: the case's example)."""
ORIENTATION_RESOLUTION = 1e-7
"""The tool axis error is an arccos of a cosine near 1, resolved to about sqrt(2 eps) ≈ 2e-8
rad: below this a change of its last bits is round-off, rad."""
RATE_RESOLUTION = 1e-4
"""Acceleration and jerk margins are second and third differences of q over Ts² and Ts³:
the rounding that the law's root finding leaves in the timing of a sample is amplified by
1/Ts² and 1/Ts³ (seen between installs: 2e-6 of a margin, 3.5e-5 of the sum of jerks). A
hundredth of a percent of the limit is far above that and far below anything a margin
guards."""
SLOW = {"bracket-weld", "kuka-weld", "seam-weld-fixed", "seam-weld-free", "ur5-bead"}
"""Cases whose plan takes about a second or more."""
TOLERANCE = 1e-6
"""Relative tolerance of every other figure. The time law finds its speed caps by root
finding on rounded kernels, so a figure carries the rounding of the numpy, numba and BLAS
it ran on: between the install that recorded them and numpy 2.4 with numba 0.68 they moved
by up to 5e-8 (a velocity margin by 3e-9, an objective by 7e-9). One part in a million is
far below what any figure guards (a tenth of a percent of a limit, a micrometre, a sample
time) and far above that rounding."""


def figures(name: str) -> dict[str, Any]:
    """What a plan of the case at its golden placement gives: outcome and every figure."""
    case = trackplan.load_case(CASES / f"{name}.yaml")
    X = PLACEMENTS[name]
    result = trackplan.plan(case, case.bounds.example if X is None else X)
    trajectory = result.trajectory
    energy = result.energy
    return {
        "status": result.status.name,
        "message": result.message,
        "n_samples": int(trajectory.n_samples),
        "duration": result.duration,
        "objective": result.objective,
        "joint_margins": {k: v.tolist() for k, v in result.check.joint_margins.items()},
        "task_margins": dict(result.check.task_margins),
        "max_tracking_error": result.check.max_tracking_error,
        "max_orientation_error": result.check.max_orientation_error,
        "rated_speed_fraction": result.rated_speed_fraction,
        "min_corner_speed": result.min_corner_speed,
        "q_abs_sum": float(np.abs(trajectory.q).sum()),
        "qddd_abs_sum": float(np.abs(trajectory.qddd).sum()),
        "speed_sum": float(trajectory.speed.sum()),
        "tool_position_sum": float(np.abs(trajectory.tool_position).sum()),
        "energy": None
        if energy is None
        else [energy.mechanical_energy, energy.copper_loss, energy.peak_torque_ratio],
    }


def _close(actual: Any, expected: Any, where: str) -> None:
    """Equal strings, or numbers equal to :data:`TOLERANCE` (relative or absolute); the
    tool axis error and its margin to :data:`ORIENTATION_RESOLUTION`, jerk and acceleration
    margins (and the sum of jerks, relative) to :data:`RATE_RESOLUTION`."""
    if where.endswith("orientation_error"):
        assert actual == pytest.approx(expected, abs=ORIENTATION_RESOLUTION, nan_ok=True), where
    elif ".joint_margins.jerk[" in where or ".joint_margins.acceleration[" in where:
        assert actual == pytest.approx(expected, abs=RATE_RESOLUTION), where
    elif where.endswith(".qddd_abs_sum"):
        assert actual == pytest.approx(expected, rel=RATE_RESOLUTION), where
    elif where.endswith("task_margins.orientation"):
        resolution = ORIENTATION_RESOLUTION / ORIENTATION_TOLERANCE
        assert actual == pytest.approx(expected, abs=resolution), where
    elif isinstance(expected, dict):
        assert sorted(actual) == sorted(expected), where
        for key in expected:
            _close(actual[key], expected[key], f"{where}.{key}")
    elif isinstance(expected, list):
        assert len(actual) == len(expected), where
        for i, (a, e) in enumerate(zip(actual, expected, strict=True)):
            _close(a, e, f"{where}[{i}]")
    elif isinstance(expected, float) or isinstance(actual, float):
        if np.isnan(expected):
            assert np.isnan(actual), where
        else:
            assert actual == pytest.approx(expected, rel=TOLERANCE, abs=TOLERANCE), where
    else:
        assert actual == expected, where


@pytest.mark.parametrize(
    "name",
    [pytest.param(n, marks=pytest.mark.slow) if n in SLOW else n for n in PLACEMENTS],
)
def test_plan_matches_recorded_figures(name: str) -> None:
    expected = json.loads(GOLDEN.read_text())[name]
    _close(figures(name), expected, name)


if __name__ == "__main__":
    GOLDEN.write_text(json.dumps({n: figures(n) for n in PLACEMENTS}, indent=1) + "\n")
