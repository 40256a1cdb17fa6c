"""The planning calls of the search, in one place.

The search plans a candidate of a case (the final plans and the "before" plan), plans one
seam with the time law while screening (paper timing, or a time weight), builds the seams'
paths once, and reads the case's sequencing settings. Each is one function here, so that
the search reaches the planner through this module only.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, TypeAlias

import numpy as np

from trackplan.case import Case
from trackplan.paths.path_geometry import PathGeometry
from trackplan.planning.plan import plan_placement
from trackplan.planning.result import PlanResult
from trackplan.timing import time_law

if TYPE_CHECKING:  # the cycle planner (and ruckig) are imported for cases with moves only
    from trackplan.planning.cycle import CycleResult

CasePlan: TypeAlias = "PlanResult | CycleResult"
"""The plan of a case at one placement: every seam, sequenced, checked."""
SeamGeometries = dict[tuple[int, bool], PathGeometry]
"""Paths of each seam direction ``(seam index, reversed)`` for one time law's path mode."""


def seam_geometries(case: Case, timing: str) -> SeamGeometries:
    """The paths of every seam of the case in each direction it may be welded, built once
    in the path mode of the time law ``timing``."""
    if case.cycle is None:  # one seam, welded as written
        return {(0, False): PathGeometry.from_case(case, time_law(timing).path_mode)}
    from trackplan.planning.cycle import seam_geometries as cycle_geometries

    return cycle_geometries(case, timing)


def sequencing_home(case: Case) -> np.ndarray | None:
    """The joint configuration the case's cycle starts from and returns to (n,), rad, or
    None."""
    return None if case.cycle is None else case.cycle.home


def plan_case(
    case: Case,
    X: np.ndarray,
    *,
    timing: str,
    geometries: SeamGeometries,
    branches: tuple[int, ...] | None = None,
    spins: tuple[np.ndarray | None, ...] | None = None,
) -> CasePlan:
    """Plan every seam of the case at placement X (6,), sequence and check them.

    Parameters
    ----------
    case
        The case.
    X
        Placement, shape (6,), metres and radians.
    timing
        The time law.
    geometries
        The seams' paths in that law's path mode (:func:`seam_geometries`).
    branches
        The IK branch of each seam (as written); None: the largest joint-limit margin.
    spins
        Each seam's spin variables (None for a fixed spin); None: the middle of the range.
    """
    if case.cycle is None:
        return plan_placement(
            case,
            X,
            timing=timing,
            branch=None if branches is None else branches[0],
            geometry=geometries[0, False],
            spin=None if spins is None else spins[0],
        )
    from trackplan.planning.cycle import plan_cycle

    return plan_cycle(case, X, timing=timing, geometries=geometries, branches=branches, spins=spins)


def plan_seam(
    case: Case, X: np.ndarray, *, timing: str, branch: int, geometry: PathGeometry
) -> PlanResult:
    """Plan the single-seam case ``case`` at X (placement, then the tool's spin variables)
    on ``branch``, with the time law ``timing`` on ``geometry``."""
    return plan_placement(case, X[:6], timing=timing, branch=branch, geometry=geometry, spin=X[6:])
