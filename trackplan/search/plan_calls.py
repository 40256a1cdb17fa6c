"""The planning calls of the search, in one place.

The search plans a candidate of a case (the final plans and the "before" plan) with
:func:`trackplan.planning.plan.plan`, plans one seam with the time law while screening
(paper timing, or a time weight) with the seam stage of that pipeline, and builds the seams'
paths once. Each is one function here, so that the search reaches the planner through this
module only.
"""

from __future__ import annotations

import numpy as np

from trackplan.case import Case
from trackplan.paths.path_geometry import PathGeometry
from trackplan.planning.plan import plan
from trackplan.planning.result import PlanResult
from trackplan.planning.seam_plan import plan_seam as plan_one_seam
from trackplan.planning.seams import SeamGeometries
from trackplan.planning.seams import seam_geometries as planning_geometries


def seam_geometries(case: Case, timing: str) -> SeamGeometries:
    """The paths of every seam of the case in each direction it may be welded, built once
    in the path mode of the time law ``timing``."""
    return planning_geometries(case, timing)


def plan_case(
    case: Case,
    X: np.ndarray,
    *,
    timing: str,
    geometries: SeamGeometries,
    branches: tuple[int, ...] | None = None,
    spins: tuple[np.ndarray | None, ...] | None = None,
) -> PlanResult:
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
    return plan(case, X, timing=timing, geometries=geometries, branches=branches, spins=spins)


def plan_seam(
    case: Case, X: np.ndarray, *, timing: str, branch: int, geometry: PathGeometry
) -> PlanResult:
    """Plan the single-seam case ``case`` at X (placement, then the tool's spin variables)
    on ``branch``, with the time law ``timing`` on ``geometry``: the seam stage of the
    pipeline, without the sequence and the whole-trajectory check (the screening ranks
    seams one at a time)."""
    return plan_one_seam(case, X[:6], timing=timing, branch=branch, geometry=geometry, spin=X[6:])
