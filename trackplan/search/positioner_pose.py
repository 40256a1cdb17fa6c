"""The positioner's pose as variables of the search (``positioner.pose`` with bounds).

A case whose positioner pose gives ``[min, max]`` ranges searches those keys together with
the placement: their variables follow the seams' spin variables in the decision vector
(:meth:`~trackplan.search.space.SearchSpace.from_case`), and a candidate is planned with the
positioner standing at its pose (:func:`positioned`).
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from trackplan.case import Case


def pose_indices(case: Case) -> np.ndarray:
    """Indices (of x, y, z, roll, pitch, yaw) of the positioner pose's searched keys, shape
    (k,) (none without a positioner or bounds)."""
    if case.positioner is None:
        return np.zeros(0, dtype=int)
    return case.positioner.searched


def pose_bounds(case: Case) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Lower and upper bounds of the pose variables and their start (the pose given), shape
    (k,) each, m and rad."""
    index = pose_indices(case)
    positioner = case.positioner
    if positioner is None or positioner.lower is None or positioner.upper is None:
        empty = np.zeros(0)
        return empty, empty, empty
    return positioner.lower[index], positioner.upper[index], positioner.pose[index]


def pose_of(case: Case, variables: np.ndarray) -> np.ndarray:
    """The positioner's full pose, shape (6,), from its searched variables (k,)."""
    assert case.positioner is not None
    pose = np.array(case.positioner.pose, dtype=float)
    pose[pose_indices(case)] = variables
    return pose


def positioned(case: Case, variables: np.ndarray) -> Case:
    """The case with its positioner standing at the pose of ``variables`` (k,): the case
    itself when the pose is not searched."""
    if case.positioner is None or not len(pose_indices(case)):
        return case
    return replace(case, positioner=case.positioner.at(pose_of(case, np.asarray(variables))))
