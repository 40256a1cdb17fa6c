"""Energy figures: against roboticstoolbox torques, and in result.json."""

from __future__ import annotations

import dataclasses
import json

import numpy as np
import pytest

from tests.oracles import rtb_robot_from
from trackplan.io.results import result_summary
from trackplan.planning.energy import energy_figures
from trackplan.robots.dynamics.rne import gravity_load

pytest.importorskip("roboticstoolbox")


def test_energy_figures_against_roboticstoolbox(corner_case, corner_plan):
    q = corner_plan.trajectory.q
    Ts = corner_case.task.sample_time
    padded = np.concatenate([np.repeat(q[:1], 3, 0), q, np.repeat(q[-1:], 3, 0)])
    qd = np.diff(padded, 1, axis=0)[2:] / Ts
    qdd = np.diff(padded, 2, axis=0)[1:] / Ts**2
    tau = rtb_robot_from(corner_case.robot).rne(padded[3:], qd, qdd)
    dyn = corner_case.robot.dynamics
    figures = energy_figures(corner_case.robot, q, Ts)
    assert figures.mechanical_energy == pytest.approx(np.maximum(tau * qd, 0).sum() * Ts, rel=1e-9)
    assert figures.copper_loss == pytest.approx(((tau / dyn.gear_ratio) ** 2).sum() * Ts, rel=1e-9)
    ratio = np.abs(tau) / dyn.torque_max
    assert figures.peak_torque_ratio == pytest.approx(ratio.max(), rel=1e-9)
    assert figures.peak_torque_joint == np.argmax(ratio.max(axis=0)) + 1
    assert figures.copper_loss_unit == "(N·m)²·s"
    assert corner_plan.energy == figures


def test_holding_still_costs_copper_but_no_work(puma, rng):
    q = np.tile(rng.uniform(-1, 1, 6), (500, 1))
    k_m = np.array([0.2, 0.2, 0.2, 0.05, 0.05, 0.05])
    robot = dataclasses.replace(
        puma, dynamics=dataclasses.replace(puma.dynamics, motor_constant=k_m)
    )
    figures = energy_figures(robot, q, 1e-3)
    holding = gravity_load(robot, q[0])
    assert figures.mechanical_energy == 0.0
    # 503 samples: the trajectory and the three rest samples after it
    expected = np.sum((holding / (robot.dynamics.gear_ratio * k_m)) ** 2) * 503 * 1e-3
    assert figures.copper_loss == pytest.approx(expected, rel=1e-12)
    assert figures.copper_loss_unit == "W·s"


def test_result_json_has_the_energy_figures(corner_case, corner_plan, ur):
    summary = json.loads(json.dumps(result_summary(corner_plan, corner_case.robot.joint_names)))
    assert summary["mechanical_energy"] == corner_plan.energy.mechanical_energy > 0
    assert summary["copper_loss"] == corner_plan.energy.copper_loss > 0
    assert 0 < summary["peak_torque_ratio"] < 1
    assert set(summary["margins"]["torque"]) == set(corner_case.robot.joint_names)
    no_dynamics = dataclasses.replace(corner_plan, energy=None)
    assert result_summary(no_dynamics, ur.joint_names)["copper_loss"] is None
