"""Objectives of the placement search, registered by name (``objective.kind``).

Each objective has two forms:

- ``screen``: an estimate on the search's geometric screening grid, batched over candidate
  placements and IK branches, from the joint paths ``q (..., M, n)`` and the time each grid
  interval takes at least (``dt (..., M - 1)``, s: the task speed cap or the slowest joint at
  its velocity limit, whichever is slower). At process speeds the tool runs at the task
  speed almost everywhere, so this is close to the planned time.
- ``exact``: the value on a planned, checked trajectory (:class:`PlanResult`).

``travel`` is the paper's Eq. 8 (:func:`joint_travel`) and the default. The case's
``objective.kind`` is one of these or ``weighted``: ``Σ mix[name] · objective[name]`` over
the names in ``objective.mix``.
``energy`` and ``copper`` need a robot with dynamics; their screening form is quasi-static
(inverse dynamics at the grid's joint velocities, no acceleration): the holding torque
against gravity and friction dominate at process speeds (``docs/dynamics.md``).
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from trackplan.case import Case, Objective
from trackplan.choices import OBJECTIVE_KINDS
from trackplan.errors import CaseError
from trackplan.planning.result import PlanResult
from trackplan.robots.dynamics.rne import inverse_dynamics
from trackplan.robots.machine import Machine
from trackplan.robots.model import Robot


def joint_travel(q: np.ndarray, weights: np.ndarray) -> np.ndarray:
    """``J = Σ_k Σ_i C_i |q_i(k) − q_i(k−1)|`` (Eq. 8).

    Parameters
    ----------
    q
        Joint paths, shape (..., N, n), rad.
    weights
        C_i, shape (n,).

    Returns
    -------
    numpy.ndarray
        J, shape (...), rad (weighted).
    """
    steps = np.abs(np.diff(np.asarray(q, dtype=float), axis=-2))
    travel: np.ndarray = np.einsum("...kn,n->...", steps, np.asarray(weights, dtype=float))
    return travel


@dataclass(frozen=True, eq=False)
class ScreenInput:
    """What a screening estimate sees.

    Attributes
    ----------
    robot
        The robot.
    q
        Joint paths on the screening grid, shape (..., M, n), rad (NaN where unsolved).
    dt
        Least time of each grid interval, shape (..., M - 1), s.
    weights
        C_i of Eq. 8, shape (n,).
    """

    robot: Robot | Machine
    q: np.ndarray
    dt: np.ndarray
    weights: np.ndarray


@dataclass(frozen=True, eq=False)
class ObjectiveSpec:
    """One objective of the registry.

    Attributes
    ----------
    name
        The ``objective.kind`` value.
    unit
        Unit of its values.
    needs_dynamics
        True when the robot must have dynamic parameters.
    screen
        Estimate on the screening grid: ``screen(ScreenInput) -> (...)``.
    exact
        Value of a planned trajectory: ``exact(PlanResult) -> float`` (NaN when not planned).
    """

    name: str
    unit: str
    needs_dynamics: bool
    screen: Callable[[ScreenInput], np.ndarray]
    exact: Callable[[PlanResult], float]


def _quasi_static_torque(data: ScreenInput) -> tuple[np.ndarray, np.ndarray]:
    """Torque and velocity on each grid interval (midpoint, no acceleration), (..., M-1, n)."""
    q = np.nan_to_num(data.q)
    qd = np.diff(q, axis=-2) / np.maximum(data.dt, 1e-12)[..., None]
    mid = 0.5 * (q[..., 1:, :] + q[..., :-1, :])
    assert not isinstance(data.robot, Machine)  # refused when the objective is chosen
    return inverse_dynamics(data.robot, mid, qd, np.zeros_like(qd)), qd


def _screen_travel(data: ScreenInput) -> np.ndarray:
    with np.errstate(invalid="ignore"):
        return joint_travel(data.q, data.weights)


def _screen_time(data: ScreenInput) -> np.ndarray:
    time: np.ndarray = data.dt.sum(axis=-1)
    return time


def _screen_energy(data: ScreenInput) -> np.ndarray:
    tau, qd = _quasi_static_torque(data)
    energy: np.ndarray = np.sum(np.maximum(tau * qd, 0.0).sum(axis=-1) * data.dt, axis=-1)
    return energy


def _screen_copper(data: ScreenInput) -> np.ndarray:
    dynamics = data.robot.dynamics
    assert dynamics is not None  # checked when the case is loaded
    tau, _ = _quasi_static_torque(data)
    k_m = 1.0 if dynamics.motor_constant is None else dynamics.motor_constant
    motor = tau / (np.asarray(dynamics.gear_ratio) * k_m)
    copper: np.ndarray = np.sum(np.square(motor).sum(axis=-1) * data.dt, axis=-1)
    return copper


def _energy_value(plan: PlanResult, key: str) -> float:
    return float("nan") if plan.energy is None else float(getattr(plan.energy, key))


OBJECTIVES: dict[str, ObjectiveSpec] = {
    spec.name: spec
    for spec in (
        ObjectiveSpec(
            "travel", "rad", OBJECTIVE_KINDS["travel"], _screen_travel, lambda plan: plan.objective
        ),
        ObjectiveSpec(
            "time", "s", OBJECTIVE_KINDS["time"], _screen_time, lambda plan: plan.duration
        ),
        ObjectiveSpec(
            "energy",
            "J",
            OBJECTIVE_KINDS["energy"],
            _screen_energy,
            lambda plan: _energy_value(plan, "mechanical_energy"),
        ),
        ObjectiveSpec(
            "copper",
            "W·s ((N·m)²·s without motor constants)",
            OBJECTIVE_KINDS["copper"],
            _screen_copper,
            lambda plan: _energy_value(plan, "copper_loss"),
        ),
    )
}
"""Single objectives by name."""


def objective_spec(name: str) -> ObjectiveSpec:
    """The registered objective called ``name``.

    Raises
    ------
    KeyError
        For an unknown name (the message lists the known ones).
    """
    try:
        return OBJECTIVES[name]
    except KeyError:
        raise KeyError(f"unknown objective {name!r}: use one of {', '.join(OBJECTIVES)}") from None


KINDS = (*OBJECTIVES, "weighted")
"""Values of ``objective.kind``."""


def _terms(objective: Objective) -> dict[str, float]:
    """The registered objectives a case's objective adds up, with their coefficients."""
    if objective.kind == "weighted":
        return dict(objective.mix)
    return {objective.kind: 1.0}


def screen_objective(objective: Objective, data: ScreenInput) -> np.ndarray:
    """A case's objective on the screening grid (see :class:`ScreenInput`), shape (...)."""
    return sum(
        (c * OBJECTIVES[name].screen(data) for name, c in _terms(objective).items()),
        start=np.zeros(data.q.shape[:-2]),
    )


def plan_objective(objective: Objective, plan: PlanResult) -> float:
    """A case's objective on a planned trajectory."""
    return float(sum(c * OBJECTIVES[name].exact(plan) for name, c in _terms(objective).items()))


def needs_dynamics(objective: Objective) -> bool:
    """True when the objective uses joint torques."""
    return any(OBJECTIVES[name].needs_dynamics for name in _terms(objective))


def with_objective(case: Case, kind: str, key: str = "--objective") -> Case:
    """The case with ``objective.kind`` replaced by a single registered objective.

    Raises
    ------
    CaseError
        For an unknown name, or one that needs dynamics the robot does not have.
    """
    if kind not in OBJECTIVES:
        raise CaseError(f"unknown objective {kind!r}: use {', '.join(OBJECTIVES)}", key=key)
    if OBJECTIVES[kind].needs_dynamics and case.machine is not case.robot:
        raise CaseError(
            f"{kind} needs joint torques, which trackplan does not compute for an arm on a "
            "track or with a positioner: use travel or time",
            key=key,
        )
    if OBJECTIVES[kind].needs_dynamics and case.robot.dynamics is None:
        raise CaseError(
            f"{kind} needs joint torques, but robot {case.robot.name} has no dynamic parameters",
            key=key,
        )
    objective = dataclasses.replace(case.objective, kind=kind, mix={})
    return dataclasses.replace(case, objective=objective)
