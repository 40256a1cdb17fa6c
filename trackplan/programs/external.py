"""The external axes of a program: which a case's machine has, and their values at the
written samples and targets (``docs/export.md``, *External axes*).

The trajectory's joint vector is ``[arm, track, positioner]``
(:class:`~trackplan.robots.machine.Machine`): the columns after the arm's are the external
axes, in SI units (track m, positioner axes rad), in that order in every program.
"""

from __future__ import annotations

import numpy as np

from trackplan.case import Case
from trackplan.programs.model import ExternalAxis
from trackplan.robots.machine import Machine


def external_axes(case: Case) -> tuple[ExternalAxis, ...]:
    """The external axes of a case's machine, in the joint vector's order (empty for an
    arm alone)."""
    machine = case.machine
    if not isinstance(machine, Machine) or machine.n_external == 0:
        return ()
    n = machine.n_arm
    return tuple(
        ExternalAxis(name=name, kind=kind, unit=unit, v_max=float(v_max))
        for name, kind, unit, v_max in zip(
            machine.joint_names[n:],
            machine.kinds[n:],
            machine.units[n:],
            machine.v_max[n:],
            strict=True,
        )
    )


def rated_velocities(case: Case) -> np.ndarray:
    """Every joint's rated velocity, the arm's then the external axes', shape (n + e,)."""
    machine = case.machine
    return np.array(machine.v_max, dtype=float)


def interpolate_columns(x: np.ndarray, columns: np.ndarray, at: np.ndarray) -> np.ndarray:
    """Each column of ``columns`` (K, e), sampled at non-decreasing ``x`` (K,), linearly
    interpolated at ``at`` (M,); shape (M, e)."""
    columns = np.asarray(columns, dtype=float)
    at = np.asarray(at, dtype=float)
    if columns.shape[1] == 0:
        return np.zeros((len(at), 0))
    return np.stack([np.interp(at, x, columns[:, j]) for j in range(columns.shape[1])], axis=1)


__all__ = ["external_axes", "interpolate_columns", "rated_velocities"]
