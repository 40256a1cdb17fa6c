"""Inverse-kinematics families: one protocol, closed forms for OPW and UR arms.

On first use a robot's chain is examined at q = 0 (:func:`ik_family`): an
ortho-parallel arm with a spherical wrist gets the OPW solver
(:mod:`~trackplan.robots.families.opw`), a UR-type arm with three parallel axes the UR
solver (:mod:`~trackplan.robots.families.ur`), anything else numeric IK
(:mod:`~trackplan.robots.families.numeric`). See ``docs/robots.md``.
"""

from __future__ import annotations

from trackplan.robots.families.base import (
    AUX_SIZE,
    N_BRANCHES,
    ClosedFormIK,
    IKFamily,
    branch_bits,
)
from trackplan.robots.families.detect import ik_family, solve_ik

__all__ = [
    "AUX_SIZE",
    "N_BRANCHES",
    "ClosedFormIK",
    "IKFamily",
    "branch_bits",
    "ik_family",
    "solve_ik",
]
