"""The search space of placements: the box of Eq. 28/31 and the reach shell of Eq. 29/32.

A placement X = (x, y, z, roll, pitch, yaw) is admissible when it lies inside the case's
bounds ``[lower, upper]`` and its translation's distance from the base origin lies in the
reach interval ``[r_min, r_max]``. The box is convex, the shell is not: sampling rejects,
repair projects radially and falls back to a bisection towards a known admissible point.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from trackplan.case import PLACEMENT_KEYS, Case, PlacementBounds
from trackplan.errors import CaseError
from trackplan.search.positioner_pose import pose_bounds

N_VAR = 6
"""Number of placement variables (the spin variables of the tool follow them)."""

_REJECTION_ROUNDS = 200
"""Batches of rejection sampling before the remaining samples are repaired instead."""
_BISECTION_STEPS = 40
"""Halvings of the segment towards the anchor when radial projection is not enough."""
_INSIDE = 1e-12
"""Relative amount by which projections land inside the reach radii (round-off)."""
_GRID_NODES = 41
"""Grid nodes per axis of the fallback search for the admissible point nearest the centre."""
BOUND_SHARE = 1e-3
"""A placement variable lies on a bound of the box when it is within this share of the box's
width (``upper - lower``) of it: 3 mrad of the default ±1.57 rad roll and pitch, 0.35 mm of
a 0.35 m range of x. The searches clip candidates to the box, so an optimum pressed against
a bound sits on it to round-off; one this close is held there by the bound, not by the
task."""
_UNITS = ("m", "m", "m", "rad", "rad", "rad")


@dataclass(frozen=True)
class BoundHit:
    """A placement variable on a bound of the search box.

    Attributes
    ----------
    variable
        ``x``, ``y``, ``z``, ``roll``, ``pitch`` or ``yaw``.
    side
        ``lower`` or ``upper``.
    value, bound
        The variable and the bound it lies on, m or rad.
    """

    variable: str
    side: str
    value: float
    bound: float

    def describe(self) -> str:
        """``roll = 1.5700 rad is on its upper bound 1.57 rad``."""
        unit = _UNITS[PLACEMENT_KEYS.index(self.variable)]
        return (
            f"{self.variable} = {self.value:.4f} {unit} is on its {self.side} bound "
            f"{self.bound:g} {unit}"
        )

    def as_dict(self) -> dict[str, str | float]:
        """``{"variable", "side", "value", "bound"}`` in plain JSON types."""
        return {
            "variable": self.variable,
            "side": self.side,
            "value": float(self.value),
            "bound": float(self.bound),
        }


def bounds_note(hits: tuple[BoundHit, ...] | list[BoundHit]) -> str:
    """One line on the placement variables on a bound of the box ('' when none): which,
    which bound, and what to do about it."""
    if not hits:
        return ""
    keys = ", ".join(f"placement.{hit.variable}" for hit in hits)
    return (
        f"the placement lies on a bound of the search box: "
        f"{'; '.join(h.describe() for h in hits)} "
        f"(within {BOUND_SHARE:.1%} of the range); the optimum may lie beyond it: widen "
        f"{keys} if the range is not a hard limit"
    )


def box_distance_range(lower: np.ndarray, upper: np.ndarray) -> tuple[float, float]:
    """Nearest and farthest distance of an axis-aligned box from the origin.

    Parameters
    ----------
    lower, upper
        Corners of the box, shape (3,), m.

    Returns
    -------
    tuple of float
        (nearest, farthest) distance, m.
    """
    lower = np.asarray(lower, dtype=float)
    upper = np.asarray(upper, dtype=float)
    nearest = np.clip(0.0, lower, upper)
    farthest = np.where(np.abs(lower) > np.abs(upper), lower, upper)
    return float(np.linalg.norm(nearest)), float(np.linalg.norm(farthest))


@dataclass(frozen=True, eq=False)
class SearchSpace:
    """Admissible placements: a box and a reach shell.

    Attributes
    ----------
    lower, upper
        Bounds of X, shape (6,), metres and radians.
    reach
        (r_min, r_max): admissible distance of (x, y, z) from the base origin, m.
    anchor
        An admissible placement (the one nearest the box centre), shape (6,): the start of
        the "before" plan and the fallback target of :meth:`repair`.

    With a ``free`` or ``free-varying`` tool spin (:class:`trackplan.tool.ToolSpec`) the
    vectors hold 6 + k variables: the placement, then the k spin variables
    (:meth:`ToolSpec.spin_bounds`), which only the box bounds.
    """

    lower: np.ndarray
    upper: np.ndarray
    reach: tuple[float, float]
    anchor: np.ndarray

    @classmethod
    def from_bounds(cls, bounds: PlacementBounds, file: str | None = None) -> SearchSpace:
        """The search space of a case's bounds.

        Raises
        ------
        CaseError
            When no point of the box satisfies the reach constraint (checked analytically:
            the box's nearest and farthest points from the origin against the interval).
        """
        lower = np.asarray(bounds.lower, dtype=float)  # placement only: 6 ranges
        upper = np.asarray(bounds.upper, dtype=float)
        r_min, r_max = (float(r) for r in bounds.reach)
        if lower.shape != (N_VAR,) or upper.shape != (N_VAR,) or np.any(lower > upper):
            raise CaseError(
                f"placement bounds must be 6 ranges [min, max], got {lower} .. {upper}",
                file=file,
                key="placement",
            )
        nearest, farthest = box_distance_range(lower[:3], upper[:3])
        if nearest > r_max or farthest < r_min or r_min > r_max:
            raise CaseError(
                f"no placement satisfies the reach constraint: the x, y, z box lies "
                f"{nearest:.4g} to {farthest:.4g} m from the base origin, outside "
                f"placement.reach [{r_min:.4g}, {r_max:.4g}] m",
                file=file,
                key="placement.reach",
            )
        centre = 0.5 * (lower + upper)
        anchor = centre.copy()
        anchor[:3] = _nearest_in_shell(centre[:3], lower[:3], upper[:3], r_min, r_max)
        return cls(lower, upper, (r_min, r_max), anchor)

    @classmethod
    def from_case(cls, case: Case) -> SearchSpace:
        """The search space of a case: the placement (see :meth:`from_bounds`), then each
        seam's spin variables in the order written (:meth:`ToolSpec.spin_bounds` of the
        seam's tool: one for ``spin: free``, the profile's for ``free-varying``, none for
        ``fixed``), then the positioner pose's searched keys
        (:mod:`~trackplan.search.positioner_pose`)."""
        space = cls.from_bounds(case.bounds, case.source)
        tools = [seam.task.tool for seam in case.seams if seam.task.tool.n_spin]
        pose_lower, pose_upper, pose_start = pose_bounds(case)
        if not tools and not len(pose_lower):
            return space
        bounds = [tool.spin_bounds() for tool in tools]
        return cls(
            np.concatenate([space.lower, *(lower for lower, _ in bounds), pose_lower]),
            np.concatenate([space.upper, *(upper for _, upper in bounds), pose_upper]),
            space.reach,
            np.concatenate(
                [space.anchor, *(tool.default_variables() for tool in tools), pose_start]
            ),
        )

    @property
    def n_var(self) -> int:
        """Number of variables: 6, plus the tool's spin variables."""
        return len(self.lower)

    @property
    def span(self) -> np.ndarray:
        """``upper - lower``, shape (6,)."""
        return self.upper - self.lower

    def to_unit(self, X: np.ndarray) -> np.ndarray:
        """Placements scaled to [0, 1] per variable, shape (..., n_var).

        A fixed coordinate (``min = max``) maps to 0.5, so scaled searches never divide by
        its zero span.
        """
        span = self.span
        fixed = span == 0.0
        Z = (np.asarray(X, dtype=float) - self.lower) / np.where(fixed, 1.0, span)
        return np.where(fixed, 0.5, Z)

    def from_unit(self, Z: np.ndarray) -> np.ndarray:
        """The placements of scaled points ``Z`` (shape (..., n_var), clipped to [0, 1])."""
        return self.lower + np.clip(Z, 0.0, 1.0) * self.span

    def reach_excess(self, X: np.ndarray) -> np.ndarray:
        """Distance of each translation outside the reach interval (0 inside).

        Parameters
        ----------
        X
            Placements, shape (B, 6).

        Returns
        -------
        numpy.ndarray
            Shape (B,), m.
        """
        r = np.linalg.norm(np.asarray(X, dtype=float)[:, :3], axis=1)
        return np.maximum(0.0, np.maximum(self.reach[0] - r, r - self.reach[1]))

    def contains(self, X: np.ndarray) -> np.ndarray:
        """Inside the box and the reach shell, shape (B,) bool."""
        X = np.asarray(X, dtype=float)
        inside = np.all((X >= self.lower) & (X <= self.upper), axis=1)
        return inside & (self.reach_excess(X) == 0.0)

    def sample(self, rng: np.random.Generator, n: int) -> np.ndarray:
        """Uniform admissible placements by rejection sampling.

        Placements are drawn uniformly in the box and kept when they satisfy the reach
        constraint. Should the admissible share be so small that 200 batches do not
        fill the sample, the rest is drawn in the box and repaired (no longer uniform).

        Parameters
        ----------
        rng
            The random generator.
        n
            Number of placements.

        Returns
        -------
        numpy.ndarray
            Shape (n, 6).
        """
        kept: list[np.ndarray] = []
        count = 0
        batch = max(4 * n, 64)
        for _ in range(_REJECTION_ROUNDS):
            if count >= n:
                break
            X = rng.uniform(self.lower, self.upper, size=(batch, self.n_var))
            X = X[self.reach_excess(X) == 0.0]
            kept.append(X)
            count += len(X)
        if count < n:
            kept.append(
                self.repair(rng.uniform(self.lower, self.upper, size=(n - count, self.n_var)))
            )
        return np.concatenate(kept)[:n]

    def repair(self, X: np.ndarray) -> np.ndarray:
        """Move placements into the box and the reach shell.

        Angles are clipped to their bounds. The translation is clipped to the box and
        scaled radially onto the nearest reach radius (three rounds); what is still
        outside moves along the segment towards :attr:`anchor` to the admissible point
        nearest to it (bisection). Admissible placements are returned unchanged.

        Parameters
        ----------
        X
            Placements, shape (B, 6).

        Returns
        -------
        numpy.ndarray
            Admissible placements, shape (B, 6).
        """
        X = np.clip(np.array(X, dtype=float), self.lower, self.upper)
        bad = ~self.contains(X)
        if not bad.any():
            return X
        r_min, r_max = self.reach
        p = X[bad, :3]
        for _ in range(3):
            r = np.linalg.norm(p, axis=1, keepdims=True)
            safe = np.where(r > 0.0, r, 1.0)
            target = np.clip(r, r_min * (1 + _INSIDE), r_max * (1 - _INSIDE))
            p = np.where(r > 0.0, p * target / safe, p)
            p = np.clip(p, self.lower[:3], self.upper[:3])
        X[bad, :3] = p
        still = ~self.contains(X)
        if still.any():
            X[still] = self._bisect_to_anchor(X[still])
        return X

    def _bisect_to_anchor(self, X: np.ndarray) -> np.ndarray:
        """For each row, the admissible point of the segment anchor → X nearest to X."""
        inside = np.zeros(len(X))  # fraction of the way from the anchor known admissible
        outside = np.ones(len(X))
        for _ in range(_BISECTION_STEPS):
            middle = 0.5 * (inside + outside)
            ok = self.contains(self.anchor + middle[:, None] * (X - self.anchor))
            inside = np.where(ok, middle, inside)
            outside = np.where(ok, outside, middle)
        return self.anchor + inside[:, None] * (X - self.anchor)

    def describe(self, X: np.ndarray) -> str:
        """``x = 0.1 m, ..., yaw = -0.2 rad`` for one placement, shape (6,)."""
        return ", ".join(
            f"{key} = {value:.4f} {unit}"
            for key, value, unit in zip(PLACEMENT_KEYS, X, _UNITS, strict=True)
        )

    def bound_hits(self, X: np.ndarray) -> tuple[BoundHit, ...]:
        """The placement variables of X that lie on a bound of the box.

        On a bound means within :data:`BOUND_SHARE` of the box's width of it; a variable
        the box fixes (``lower == upper``) is never reported.

        Parameters
        ----------
        X
            A placement, shape (6,) or (6 + k,) (the spin variables are not reported),
            metres and radians.

        Returns
        -------
        tuple of BoundHit
            In the order x, y, z, roll, pitch, yaw.
        """
        X = np.asarray(X, dtype=float)[:N_VAR]
        lower, upper = self.lower[:N_VAR], self.upper[:N_VAR]
        near = BOUND_SHARE * (upper - lower)
        hits = []
        for i, key in enumerate(PLACEMENT_KEYS):
            if not upper[i] > lower[i]:
                continue
            if X[i] - lower[i] <= near[i]:
                hits.append(BoundHit(key, "lower", float(X[i]), float(lower[i])))
            elif upper[i] - X[i] <= near[i]:
                hits.append(BoundHit(key, "upper", float(X[i]), float(upper[i])))
        return tuple(hits)


def _nearest_in_shell(
    point: np.ndarray, lower: np.ndarray, upper: np.ndarray, r_min: float, r_max: float
) -> np.ndarray:
    """The point of ``box ∩ {r_min ≤ |p| ≤ r_max}`` nearest to ``point`` (a point of the box).

    An admissible point is returned as it is. Otherwise the radial projection onto the
    violated radius is the nearest point of the shell, hence of the admissible set when it
    lies in the box; a point at the origin projects along +x, −x, +y, −y, +z, −z, the first
    that lies in the box. When the projection leaves the box, the answer is the nearest
    admissible node of a 41 × 41 × 41 grid over the box (within a grid step of the
    optimum). The caller has checked that the box meets the shell.
    """
    r = float(np.linalg.norm(point))
    if r_min <= r <= r_max:
        return point.copy()
    radius = r_min * (1 + _INSIDE) if r < r_min else r_max * (1 - _INSIDE)
    if r > 0.0:
        directions = [point / r]
    else:
        directions = [np.eye(3)[axis] * sign for axis in range(3) for sign in (1.0, -1.0)]
    for direction in directions:
        candidate = direction * radius
        if np.all(candidate >= lower) and np.all(candidate <= upper):
            return candidate
    axes = np.linspace(lower, upper, _GRID_NODES).T
    grid = np.stack(np.meshgrid(*axes, indexing="ij"), axis=-1).reshape(-1, 3)
    norm = np.linalg.norm(grid, axis=1)
    grid = grid[(norm >= r_min) & (norm <= r_max)]
    if len(grid) == 0:  # a shell thinner than the grid step
        grid = _point_at_radius(lower, upper, r_min, r_max)[None]
    return grid[np.argmin(np.linalg.norm(grid - point, axis=1))]


def _point_at_radius(
    lower: np.ndarray, upper: np.ndarray, r_min: float, r_max: float
) -> np.ndarray:
    """A point of the box whose distance from the origin lies in ``[r_min, r_max]``.

    Along the segment from the box point nearest the origin to the farthest corner the
    distance grows monotonically (it is convex and smallest at the start), so bisection
    finds the middle of the admissible distances the box offers.
    """
    start = np.clip(0.0, lower, upper)
    end = np.where(np.abs(lower) > np.abs(upper), lower, upper)
    nearest, farthest = float(np.linalg.norm(start)), float(np.linalg.norm(end))
    target = 0.5 * (max(r_min, nearest) + min(r_max, farthest))
    low, high = 0.0, 1.0
    for _ in range(_BISECTION_STEPS + 20):
        middle = 0.5 * (low + high)
        if np.linalg.norm(start + middle * (end - start)) < target:
            low = middle
        else:
            high = middle
    return start + 0.5 * (low + high) * (end - start)
