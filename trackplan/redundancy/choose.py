"""The free parameter of a redundant arm chosen along a seam, per candidate and branch.

For every candidate placement (its tool poses on a coarse grid of the seam) and every IK
branch, :func:`choose_redundancy` chooses the profile of the arm's free parameter (the arm
angle of an S-R-S arm, a chosen joint otherwise) within the case's steering
(:class:`~trackplan.redundancy.spec.RedundancySpec`):

1. **Constants.** The path IK of every candidate at :data:`CONSTANTS` constant values of
   the parameter spread over its bounds, in one batched call; per branch the constant with
   the least joint travel J (Eq. 8, the case's travel weights) among those whose path is
   usable (reached everywhere, no singularity crossed, inside the joint limits), else the
   one whose first problem comes latest.
2. **A profile** (``free-varying``). Dynamic programming over :data:`STAGES` stages of the
   seam and the constants' values as states: a state is usable where the constant's path is
   usable over the stage's stretch of the seam, a step from one state to the next moves the
   parameter no faster than the steering's rate, and costs the weighted joint travel
   between the two states' joints. The cheapest sequence, fitted by least squares with a
   clamped cubic B-spline of :data:`~trackplan.redundancy.spec.NODES` coefficients and held
   to the bounds and the rate (:meth:`~trackplan.profiles.FreeProfile.coefficients`), is
   solved exactly, and kept where its path is usable with less travel than the best
   constant's (or where no constant is usable).

The smoothness of the profile (C², its rate bounded by the convex hull of its
coefficients) is what keeps the joints' jerk in bounds; every planned sample is checked
anyway. The choice is deterministic: the search's screening and the plan of the chosen
placement make the same one.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from trackplan.profiles import Profile, profile_values
from trackplan.redundancy._kernels import cheapest_sequences
from trackplan.redundancy.spec import NODES, RedundancyMode, RedundancySpec
from trackplan.robots.families import ik_family
from trackplan.robots.model import Robot
from trackplan.robots.path_ik import PathIKBranches, solve_path_ik_branches
from trackplan.robots.thread_sharing import ThreadSharing

CONSTANTS = 12
"""Constant values of the parameter tried per candidate (closed-form families)."""
TRACKED_CONSTANTS = 5
"""Constant values tried per candidate for a tracked (Newton) family, whose path IK costs
more per pose."""
STAGES = 12
"""Stages of the seam the profile's dynamic programming steps through."""
_RATE_SLACK = 1e-9


@dataclass(frozen=True, eq=False)
class RedundancyChoice:
    """The chosen profiles of B candidates on K branches, and their path IK.

    Attributes
    ----------
    values
        The parameter at the grid's arc lengths, shape (B, K, M), rad.
    coefficients
        Each profile's B-spline coefficients over [0, length], shape (B, K, c), rad (c = 1
        for a constant).
    length
        Length of the seam the profiles span, m.
    paths
        The path IK of every candidate and branch with its profile (as
        :func:`~trackplan.robots.path_ik.solve_path_ik_branches` gives it).
    """

    values: np.ndarray
    coefficients: np.ndarray
    length: float
    paths: PathIKBranches

    def profile(self, candidate: int, branch: int) -> Profile:
        """The profile of one candidate on one branch (column), over [0, length]."""
        coefficients = np.array(self.coefficients[candidate, branch], dtype=float)
        if np.ptp(coefficients) == 0.0:  # a constant
            coefficients = coefficients[:1]
        return Profile(coefficients, self.length)


def choose_redundancy(
    robot: Robot,
    poses: np.ndarray,
    s: np.ndarray,
    length: float,
    spec: RedundancySpec,
    weights: np.ndarray,
    *,
    sharing: ThreadSharing | None = None,
) -> RedundancyChoice:
    """Choose a redundant arm's free parameter along a seam for each candidate and branch.

    Parameters
    ----------
    robot
        An arm whose IK family is redundant (:attr:`IKFamily.redundancy`).
    poses
        Tool poses in the arm's base frame on a grid of the seam, shape (B, M, 4, 4), m.
    s
        The grid's arc lengths, shape (M,), m, increasing.
    length
        Length of the seam, m (the profiles span [0, length]).
    spec
        The case's steering (mode, bounds, rate).
    weights
        Travel weight per joint of the arm, shape (n,).
    sharing
        The path IK's thread record (:class:`~trackplan.robots.thread_sharing.ThreadSharing`).

    Returns
    -------
    RedundancyChoice

    Raises
    ------
    ValueError
        When the arm is not redundant.
    """
    family = ik_family(robot)
    parameter = family.redundancy
    if parameter is None:
        raise ValueError(f"{robot.name} has no redundancy to choose")
    poses = np.ascontiguousarray(poses, dtype=float)
    s = np.asarray(s, dtype=float)
    n_cand, n_poses = poses.shape[:2]
    weights = np.asarray(weights, dtype=float)
    if spec.mode is RedundancyMode.FIXED:
        value = spec.fixed_value(parameter)
        free = np.full((n_cand, n_poses), value)
        paths = solve_path_ik_branches(robot, poses, free=free, sharing=sharing)
        n_k = paths.q.shape[1]
        return RedundancyChoice(
            np.full((n_cand, n_k, n_poses), value),
            np.full((n_cand, n_k, 1), value),
            float(length),
            paths,
        )
    lower, upper = spec.bounds(parameter)
    count = CONSTANTS if family.closed_form else TRACKED_CONSTANTS
    constants = np.linspace(lower, upper, count, endpoint=not spec.full_turn(parameter))
    repeated = np.repeat(poses, count, axis=0)  # row b·R + r
    free = np.broadcast_to(np.tile(constants, n_cand)[:, None], (n_cand * count, n_poses))
    tried = solve_path_ik_branches(robot, repeated, free=np.array(free), sharing=sharing)
    n_k = tried.q.shape[1]
    travel = _travel(tried, weights).reshape(n_cand, count, n_k)
    best = _best_constant(tried, travel, count)  # (B, K) index into R
    rows = np.arange(n_cand)[:, None] * count + best  # rows of `tried`
    chosen = _take(tried, rows)
    values = np.broadcast_to(constants[best][..., None], (n_cand, n_k, n_poses)).copy()
    coefficients = constants[best][..., None]
    if spec.mode is RedundancyMode.FREE:
        return RedundancyChoice(values, coefficients, float(length), chosen)
    best_travel = np.take_along_axis(travel, best[:, None], axis=1)[:, 0]  # (B, K)
    profile = spec.free_profile(parameter)
    limits = (robot.q_min, robot.q_max)
    sequence, found = _cheapest_sequence(tried, limits, constants, s, spec.rate, weights, count)
    stage_s = s[_stage_indices(n_poses)]
    design = profile_values(np.eye(NODES), stage_s, length)  # (NODES, S + 1)
    fitted = np.linalg.lstsq(design.T, sequence.reshape(-1, sequence.shape[-1]).T, rcond=None)[0]
    nodes = profile.coefficients(profile.variables(fitted.T, length), length)
    nodes = nodes.reshape(n_cand, n_k, NODES)
    varying = profile_values(nodes.reshape(-1, NODES), s, length).reshape(n_cand, n_k, n_poses)
    solved = solve_path_ik_branches(robot, poses, free=varying, sharing=sharing)
    varying_travel = _travel(solved, weights)
    better = found & solved.success & (varying_travel < best_travel)
    better |= found & solved.success & ~chosen.success
    columns = np.broadcast_to(np.arange(n_k), (n_cand, n_k))
    merged = _merge(chosen, solved, better, columns)
    values = np.where(better[..., None], varying, values)
    coefficients = np.where(better[..., None], nodes, np.repeat(coefficients, NODES, axis=-1))
    return RedundancyChoice(values, coefficients, float(length), merged)


def _travel(paths: PathIKBranches, weights: np.ndarray) -> np.ndarray:
    """Weighted joint travel of each usable path, shape (B, K); inf where not usable."""
    steps = np.abs(np.diff(paths.q, axis=2)) @ weights  # (B, K, M - 1)
    travel = np.sum(steps, axis=2)
    return np.where(paths.success & np.isfinite(travel), travel, np.inf)


def _best_constant(tried: PathIKBranches, travel: np.ndarray, count: int) -> np.ndarray:
    """Per candidate and branch the constant with the least travel among usable paths,
    else the one whose first problem comes latest (then the largest margin), (B, K)."""
    n_cand = travel.shape[0]
    first = tried.first_problem.reshape(n_cand, count, -1).astype(float)
    margin = tried.margin.reshape(n_cand, count, -1)
    fallback = first + 0.5 + 0.5 * np.tanh(np.where(np.isfinite(margin), margin, -1e9))
    usable = np.isfinite(travel).any(axis=1)
    best: np.ndarray = np.where(usable, np.argmin(travel, axis=1), np.argmax(fallback, axis=1))
    return best


def _stage_indices(n_poses: int) -> np.ndarray:
    """Grid poses at the stage boundaries, shape (S + 1,), increasing, first and last."""
    indices: np.ndarray = np.unique(np.round(np.linspace(0, n_poses - 1, STAGES + 1)).astype(int))
    return indices


def _cheapest_sequence(
    tried: PathIKBranches,
    limits: tuple[np.ndarray, np.ndarray],
    constants: np.ndarray,
    s: np.ndarray,
    rate: float,
    weights: np.ndarray,
    count: int,
) -> tuple[np.ndarray, np.ndarray]:
    """The cheapest sequence of the constants' values over the stage boundaries, per
    candidate and branch (dynamic programming, compiled:
    :func:`~trackplan.redundancy._kernels.cheapest_sequences`; see the module docstring).

    A state (a constant at a boundary) is usable where its path is reached, does not switch
    and stays inside the limits from the midpoint before the boundary to the one after it;
    a step moves the parameter at most ``rate`` times the arc length between boundaries and
    costs the weighted joint travel between the two states' joints (each joint's difference
    taken modulo 2π).

    Returns
    -------
    sequence
        Shape (B, K, S + 1), rad.
    found
        Shape (B, K), bool: a sequence of usable states exists.
    """
    n_rows, n_k, n_poses, _ = tried.q.shape
    n_cand = n_rows // count
    stages = _stage_indices(n_poses)
    reach = rate * np.diff(s[stages]) + _RATE_SLACK
    path = np.empty((n_cand, n_k, len(stages)), dtype=np.int64)
    found = np.empty((n_cand, n_k), dtype=np.bool_)
    cheapest_sequences(
        np.ascontiguousarray(np.nan_to_num(tried.q, nan=np.inf)),
        np.ascontiguousarray(tried.reachable & ~tried.switch),
        np.ascontiguousarray(limits[0], dtype=float),
        np.ascontiguousarray(limits[1], dtype=float),
        stages,
        np.ascontiguousarray(constants, dtype=float),
        reach,
        np.ascontiguousarray(weights, dtype=float),
        path,
        found,
    )
    return constants[path], found


def _take(paths: PathIKBranches, rows: np.ndarray) -> PathIKBranches:
    """The paths of row ``rows[b, k]`` of ``paths`` in column k, for B × K picks."""
    columns = np.broadcast_to(np.arange(rows.shape[1]), rows.shape)
    return _merge(paths, paths, np.zeros(rows.shape, dtype=bool), columns, rows)


def _merge(
    first: PathIKBranches,
    second: PathIKBranches,
    use_second: np.ndarray,
    columns: np.ndarray,
    rows: np.ndarray | None = None,
) -> PathIKBranches:
    """Per candidate and column, the path of ``second`` where ``use_second`` (B, K), else
    of ``first`` (at row ``rows[b, k]`` of ``first`` when given, else row b)."""
    n_cand = use_second.shape[0]
    own = np.broadcast_to(np.arange(n_cand)[:, None], use_second.shape)
    first_rows = own if rows is None else rows

    def pick(a: np.ndarray, b: np.ndarray) -> np.ndarray:
        mask = use_second.reshape(use_second.shape + (1,) * (a.ndim - 2))
        picked: np.ndarray = np.where(mask, b[own, columns], a[first_rows, columns])
        return picked

    return PathIKBranches(
        q=pick(first.q, second.q),
        branches=first.branches,
        reachable=pick(first.reachable, second.reachable),
        switch=pick(first.switch, second.switch),
        success=pick(first.success, second.success),
        margin=pick(first.margin, second.margin),
        first_problem=pick(first.first_problem, second.first_problem),
        reachable_fraction=pick(first.reachable_fraction, second.reachable_fraction),
        n_switches=pick(first.n_switches, second.n_switches),
        method=first.method,
        windings=pick(first.windings, second.windings),
        winding=pick(first.winding, second.winding),
    )
