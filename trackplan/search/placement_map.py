"""The placement map: feasibility and J over an x–y grid of placements at one orientation.

A cell designer's view of where the part may go: every grid point is screened by the
search's batched fitness (:class:`trackplan.search.fitness.PlacementFitness`, geometric
path, IK on every branch, the cell's clearance) and classified by the first reason it
fails: ``reach`` (outside the reach interval, or some pose has no IK solution),
``joint limit`` (every reaching branch leaves the joint range or crosses a singularity),
``collision`` (every otherwise feasible branch breaks the clearance) or ``feasible`` with
its joint travel J (Eq. 8).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from trackplan.case import Case
from trackplan.errors import CaseError
from trackplan.paths.path_geometry import PathGeometry
from trackplan.search.fitness import PlacementFitness
from trackplan.search.screening import OUTCOMES
from trackplan.search.space import SearchSpace
from trackplan.status import Status

REASONS = ("feasible", "reach", "joint limit", "collision")
"""Map classes, by code 0..3."""
_CODE = {
    Status.FEASIBLE: 0,
    Status.REACH: 1,
    Status.UNREACHABLE: 1,
    Status.BRANCH_SWITCH: 2,
    Status.POSITION_LIMITS: 2,
    Status.LIMITS_VIOLATED: 2,
    Status.HOLDING_TORQUE: 2,
    Status.COLLISION: 3,
}
_CLASS = np.array([_CODE.get(status, 2) for status in OUTCOMES])
"""Map class of every outcome code of the screening."""
CHUNK = 256
"""Placements screened per batch (bounds the IK arrays' memory)."""

MAX_MAP_POINTS = 501
"""Most grid points along x and along y (251,001 placements).

The screening is chunked (:data:`CHUNK`), so memory is not what limits a map: the time is,
about 0.2 ms a placement for the paper's corner and more for longer paths (a minute at the
limit; 100,000 points a side would take weeks and 75 GiB for the grid alone). A finer grid
shows nothing more on the figure."""


def check_map_points(n_points: int, key: str = "n_points") -> int:
    """Check the grid size of a placement map: 2 to :data:`MAX_MAP_POINTS` points a side.

    Raises
    ------
    CaseError
        Naming ``key`` (``--points`` on the command line) and the bound.
    """
    if not 2 <= n_points <= MAX_MAP_POINTS:
        raise CaseError(
            f"expected at most {MAX_MAP_POINTS} grid points along x and y (and at least 2: "
            f"the map screens points² placements), got {n_points}",
            key=key,
        )
    return n_points


@dataclass(frozen=True, eq=False)
class PlacementMap:
    """Feasibility over an x–y grid of placements.

    Attributes
    ----------
    case_name
        The case.
    x, y
        Grid coordinates of the definition frame's origin in the base frame, shapes (nx,)
        and (ny,), m.
    z
        Height of every placement, m.
    rpy
        Orientation of every placement (roll, pitch, yaw), shape (3,), rad.
    reason
        Class of each grid point, shape (ny, nx), int: index into :data:`REASONS`.
    objective
        J of Eq. 8 on the screening grid where feasible, NaN elsewhere, shape (ny, nx).
    reference
        The placement the height and orientation came from (the search's best), shape
        (6,); x and y are NaN when only a height and orientation were given.
    """

    case_name: str
    x: np.ndarray
    y: np.ndarray
    z: float
    rpy: np.ndarray
    reason: np.ndarray
    objective: np.ndarray
    reference: np.ndarray

    @property
    def feasible_share(self) -> float:
        """Share of the grid that is feasible."""
        return float(np.mean(self.reason == 0))

    def placements(self) -> np.ndarray:
        """Every grid placement, shape (ny, nx, 6), row-major like :attr:`reason`."""
        xx, yy = np.meshgrid(self.x, self.y)
        X = np.empty((*xx.shape, 6))
        X[..., 0], X[..., 1], X[..., 2] = xx, yy, self.z
        X[..., 3:] = self.rpy
        return X


def placement_map(
    case: Case,
    reference: np.ndarray,
    *,
    n_points: int = 41,
    geometry: PathGeometry | None = None,
) -> PlacementMap:
    """Screen an x–y grid of placements at the height and orientation of ``reference``.

    Parameters
    ----------
    case
        The case (its cell, if any, is checked).
    reference
        Placement (x, y, z, roll, pitch, yaw) whose z and orientation the map keeps,
        shape (6,), metres and radians (for example the search's best).
    n_points
        Grid points along x and along y, over the case's placement ranges (2 to
        :data:`MAX_MAP_POINTS`).
    geometry
        The case's paths (smooth timing) when already built.

    Returns
    -------
    PlacementMap

    Raises
    ------
    CaseError
        When ``n_points`` is outside 2 to :data:`MAX_MAP_POINTS`.
    """
    check_map_points(n_points)
    reference = np.asarray(reference, dtype=float)
    geometry = geometry or PathGeometry.from_case(case, "g2")
    fitness = PlacementFitness(case, SearchSpace.from_bounds(case.bounds), geometry, "smooth")
    x = np.linspace(case.bounds.lower[0], case.bounds.upper[0], n_points)
    y = np.linspace(case.bounds.lower[1], case.bounds.upper[1], n_points)
    partial = PlacementMap(
        case.name,
        x,
        y,
        float(reference[2]),
        reference[3:].copy(),
        np.zeros((n_points, n_points), dtype=int),
        np.full((n_points, n_points), np.nan),
        reference,
    )
    X = partial.placements().reshape(-1, 6)
    reason = np.empty(len(X), dtype=int)
    objective = np.full(len(X), np.nan)
    for start in range(0, len(X), CHUNK):
        # an incumbent of -inf: no candidate is timed, the map is about geometry
        screening = fitness.evaluate(X[start : start + CHUNK], incumbent=-np.inf)
        reason[start : start + CHUNK] = _CLASS[screening.finding]
        objective[start : start + CHUNK] = screening.objective
    return PlacementMap(
        case.name,
        x,
        y,
        partial.z,
        partial.rpy,
        reason.reshape(n_points, n_points),
        np.where(reason == 0, objective, np.nan).reshape(n_points, n_points),
        reference,
    )
