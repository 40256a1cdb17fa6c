"""Joint paths along pose paths: one IK branch throughout, continuous, inside the limits.

For each candidate (a placement of the path) and each branch, the IK solutions of the M
poses form a joint path. The path is unwrapped continuously along M and then shifted by
a multiple of 2π per joint so that it sits inside ``[q_min, q_max]`` with the largest
margin. A branch is usable (``success``) when every pose is reachable, the branch never
switches (a switch is a singularity crossing: the joint path would need infinite speed
or a jump) and the shifted path stays inside the position limits.

Branches
--------
Robots with a closed form (:mod:`trackplan.robots.ik_closed_form`) have the eight
closed-form branches ``b = 4·shoulder + 2·elbow + wrist``. A closed-form label swaps
at a singularity, so a switch is detected from the branch-defining quantities of each
pose: the shoulder distance |r|, the elbow sine |sin(θ3 + β)| and the wrist sine
|sin θ5|. Where one of them has a local minimum at pose k that is no larger than its
change to a neighbour (it reaches about zero between consecutive poses), or where the
wrist vector z3 × z5 reverses between poses k − 1 and k (q5 changes sign), the path
crosses that singularity.

Other robots use :mod:`trackplan.robots.ik_numeric`. Branch b is defined by the seed
``seed_b`` of :func:`numeric_seeds`: the first pose is solved from it, a coarse subset of
the poses (one every :data:`COARSE_STEP` of combined travel) is marched sequentially
with warm starts, and all M poses are then solved at once by Newton seeded with the
linear interpolation of the coarse solution. Two seeds may reach the same solution; the
branches are then equal. A singularity crossing shows as a sign change of det J (6
joints) or a touch of zero of the manipulability sqrt(det(J Jᵀ)).

Both methods also count as a switch any joint step larger than ``max_step`` between
consecutive poses (default :data:`DEFAULT_MAX_STEP`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numba import njit

from trackplan.errors import CaseError
from trackplan.robots import ik_closed_form
from trackplan.robots.ik_closed_form import N_BRANCHES, describe_branch, has_closed_form
from trackplan.robots.ik_numeric import (
    chain_arrays,
    fk_jacobian_into,
    newton_into,
    work_size_kernel,
)
from trackplan.robots.model import Robot
from trackplan.status import Status

DEFAULT_MAX_STEP = np.pi / 4
"""Joint step between consecutive poses that counts as a jump when ``max_step`` is None,
rad: no sampling a planner uses moves a joint this far between two poses."""

COARSE_STEP = 0.01
"""Travel between the coarse poses the numerical path IK marches through, m; rotation
counts :data:`ROTATION_LENGTH` metres per radian."""

ROTATION_LENGTH = 0.2
"""Metres of travel one radian of tool rotation counts for when choosing coarse poses."""

# Kinds of switch, in the order of the per-branch report.
_NONE, _SHOULDER, _ELBOW, _WRIST, _SINGULAR, _JUMP = range(6)
# Per-branch integer report: first problem, first unreachable pose, number unreachable,
# first switch, its kind, its joint (jumps), number of switches, first pose outside the
# limits, its joint.
_I_FIRST, _I_UNREACH, _I_N_UNREACH, _I_SWITCH, _I_KIND, _I_JOINT, _I_N_SWITCH = range(7)
_I_LIMIT, _I_LIMIT_JOINT = 7, 8
_N_INT = 9
# Per-branch float report: margin (rad), the jump (rad), the joint value outside (rad).
_F_MARGIN, _F_STEP, _F_VALUE = range(3)
_N_FLOAT = 3
_NEWTON_TOL = 1e-10
_MARCH_MAX_ITER = 100  # first pose from a seed, and the coarse march
_FINE_MAX_ITER = 30  # every pose, seeded within a coarse step of its solution


@dataclass(frozen=True, eq=False)
class PathIK:
    """Joint paths of B candidates along M poses each, one branch per candidate.

    Attributes
    ----------
    q
        Joint paths, shape (B, M, n), rad: continuous along M, shifted by multiples of 2π
        per joint to sit inside the limits with the largest margin. Unreachable poses
        repeat the last reachable configuration (the first reachable one before it).
    branch
        Branch used per candidate, shape (B,), int (closed-form branch or numeric seed).
    reachable
        Shape (B, M), bool: the branch has an IK solution at the pose.
    switch
        Shape (B, M), bool: going from pose k − 1 to pose k needs a branch change
        (singularity crossing) or a joint step larger than ``max_step``.
    success
        Shape (B,), bool: reachable everywhere, no switch, inside the position limits.
    margin
        Smallest distance of the path to a joint position limit, shape (B,), rad;
        negative when outside, −inf when no pose is reachable.
    first_problem
        First pose with a problem (unreachable, switch, outside the limits), shape (B,),
        int; −1 when ``success``.
    status
        One :class:`trackplan.status.Status` per candidate (``FEASIBLE`` when ``success``).
    message
        One line per candidate saying what is wrong, or which branch is used and its margin.
    method
        ``"closed_form"`` or ``"numeric"``.
    """

    q: np.ndarray
    branch: np.ndarray
    reachable: np.ndarray
    switch: np.ndarray
    success: np.ndarray
    margin: np.ndarray
    first_problem: np.ndarray
    status: tuple[Status, ...]
    message: tuple[str, ...]
    method: str


@dataclass(frozen=True, eq=False)
class PathIKBranches:
    """Joint paths of B candidates along M poses each, on every branch.

    The same paths, in the same form, as :class:`PathIK` gives for one branch (branch k of
    candidate b is what ``solve_path_ik(robot, T, branch=k)`` returns for b), for a caller
    that chooses the branch itself, e.g. by the objective.

    Attributes
    ----------
    q
        Joint paths, shape (B, K, M, n), rad (see :attr:`PathIK.q`; NaN where a branch
        reaches no pose at all).
    branches
        The branch of each of the K columns, shape (K,), int (closed-form branch or numeric
        seed index: 0 … 7).
    reachable
        Shape (B, K, M), bool: the branch has an IK solution at the pose.
    switch
        Shape (B, K, M), bool: a singularity crossing or jump between poses k − 1 and k.
    success
        Shape (B, K), bool: reachable everywhere, no switch, inside the position limits.
    margin
        Smallest distance of the path to a joint position limit, shape (B, K), rad; negative
        when outside, −inf when no pose is reachable.
    first_problem
        First pose with a problem, shape (B, K), int; −1 when ``success``.
    reachable_fraction
        Share of the M poses the branch reaches, shape (B, K), in [0, 1].
    n_switches
        Number of poses at which the branch switches or jumps, shape (B, K), int.
    method
        ``"closed_form"`` or ``"numeric"``.
    """

    q: np.ndarray
    branches: np.ndarray
    reachable: np.ndarray
    switch: np.ndarray
    success: np.ndarray
    margin: np.ndarray
    first_problem: np.ndarray
    reachable_fraction: np.ndarray
    n_switches: np.ndarray
    method: str


def numeric_seeds(robot: Robot) -> np.ndarray:
    """The eight seed configurations that define the numerical branches.

    Branch ``b = 4·s + 2·e + w`` starts from the middle of the joint range plus
    ``(π·s, −π/4, ±π/3, 0, ±π/2, 0)`` on joints 1 to 6 (+π/3 for e = 0, +π/2 for w = 0;
    joints past the sixth stay in the middle); a joint that lands outside its limits is
    moved by a multiple of 2π into them where possible. Away from the usual singular
    configurations of 6R arms (stretched elbow, q5 = 0), they sample the shoulder, elbow
    and wrist alternatives of most industrial arms.

    Returns
    -------
    numpy.ndarray
        Shape (8, n), rad.
    """
    n = robot.n_dof
    b = np.arange(N_BRANCHES)
    shoulder, elbow, wrist = (b >> 2) & 1, (b >> 1) & 1, b & 1
    pattern = np.zeros((N_BRANCHES, max(n, 6)))
    pattern[:, 0] = np.pi * shoulder
    pattern[:, 1] = -np.pi / 4
    pattern[:, 2] = (1 - 2 * elbow) * np.pi / 3
    pattern[:, 4] = (1 - 2 * wrist) * np.pi / 2
    middle = 0.5 * (robot.q_min + robot.q_max)
    seeds = middle + pattern[:, :n]
    shifted = seeds + 2 * np.pi * np.ceil((robot.q_min - seeds) / (2 * np.pi))  # lowest ≥ q_min
    outside = (seeds < robot.q_min) | (seeds > robot.q_max)
    return np.where(outside & (shifted <= robot.q_max), shifted, seeds)


def solve_path_ik(
    robot: Robot,
    T_base_tool: np.ndarray,
    branch: int | np.ndarray | None = None,
    max_step: float | np.ndarray | None = None,
    *,
    method: str = "auto",
) -> PathIK:
    """Joint paths of candidate pose paths on one IK branch each.

    Parameters
    ----------
    robot
        The robot.
    T_base_tool
        Tool poses in the base frame, shape (B, M, 4, 4), metres: M poses along the path
        for each of B candidates.
    branch
        None: per candidate, the branch that is ok with the largest margin, or if none is
        ok the one whose first problem comes latest (then the largest margin). An int
        0…7 forces that branch for every candidate, an int array (B,) one per candidate.
    max_step
        Largest joint step between consecutive poses that is motion and not a jump,
        scalar or shape (n,), rad; None: :data:`DEFAULT_MAX_STEP`.
    method
        ``"auto"`` (closed form where :func:`has_closed_form`, else numeric),
        ``"closed_form"`` or ``"numeric"``.

    Returns
    -------
    PathIK

    Raises
    ------
    CaseError
        When the shapes, the branch, max_step or the method are invalid.
    """
    paths = _branch_paths(robot, T_base_tool, branch, max_step, method)
    q, reach, switch, report, values, ok = paths[:6]
    candidates, step, method = paths[6:]
    n_cand, n_poses = reach.shape[0], reach.shape[2]
    chosen = _choose(ok, report[..., _I_FIRST], values[..., _F_MARGIN])
    rows = np.arange(n_cand)
    report, values = report[rows, chosen], values[rows, chosen]
    branches = candidates[rows, chosen]
    statuses = tuple(_status(r, v) for r, v in zip(report, values, strict=True))
    messages = tuple(
        _message(robot, method, int(b), s, r, v, n_poses, step)
        for b, s, r, v in zip(branches, statuses, report, values, strict=True)
    )
    return PathIK(
        q=q[rows, chosen],
        branch=branches,
        reachable=reach[rows, chosen],
        switch=switch[rows, chosen],
        success=ok[rows, chosen],
        margin=values[:, _F_MARGIN],
        first_problem=report[:, _I_FIRST],
        status=statuses,
        message=messages,
        method=method,
    )


def solve_path_ik_branches(
    robot: Robot,
    T_base_tool: np.ndarray,
    max_step: float | np.ndarray | None = None,
    *,
    method: str = "auto",
) -> PathIKBranches:
    """Joint paths of candidate pose paths on every IK branch, in one batched call.

    Parameters
    ----------
    robot
        The robot.
    T_base_tool
        Tool poses in the base frame, shape (B, M, 4, 4), metres.
    max_step
        As for :func:`solve_path_ik`.
    method
        As for :func:`solve_path_ik`.

    Returns
    -------
    PathIKBranches

    Raises
    ------
    CaseError
        When the shapes, max_step or the method are invalid.
    """
    q, reach, switch, report, values, ok, _, _, method = _branch_paths(
        robot, T_base_tool, None, max_step, method
    )
    return PathIKBranches(
        q=q,
        branches=np.arange(N_BRANCHES),
        reachable=reach,
        switch=switch,
        success=ok,
        margin=values[..., _F_MARGIN],
        first_problem=report[..., _I_FIRST],
        reachable_fraction=1.0 - report[..., _I_N_UNREACH] / reach.shape[2],
        n_switches=report[..., _I_N_SWITCH],
        method=method,
    )


def _branch_paths(
    robot: Robot,
    T_base_tool: np.ndarray,
    branch: int | np.ndarray | None,
    max_step: float | np.ndarray | None,
    method: str,
) -> tuple[
    np.ndarray,
    np.ndarray,
    np.ndarray,
    np.ndarray,
    np.ndarray,
    np.ndarray,
    np.ndarray,
    np.ndarray,
    str,
]:
    """The candidate branches' joint paths, analysed: the shared core of both solvers.

    Parameters are those of :func:`solve_path_ik`.

    Returns
    -------
    q, reach, switch, report, values, ok, candidates, step, method
        Shapes (B, K, M, n), (B, K, M), (B, K, M), (B, K, _N_INT), (B, K, _N_FLOAT),
        (B, K) bool; the branches tried (B, K), the step limit (n,) and the method used.
    """
    T = np.ascontiguousarray(T_base_tool, dtype=float)
    if T.ndim != 4 or T.shape[-2:] != (4, 4) or T.shape[1] < 1:
        raise CaseError(f"T_base_tool must have shape (B, M, 4, 4), got {T.shape}")
    candidates = _candidate_branches(branch, T.shape[0])
    step = _max_step(max_step, robot.n_dof)
    n_cand, n_poses = T.shape[:2]
    n = robot.n_dof
    if method == "auto":
        method = "closed_form" if has_closed_form(robot) else "numeric"
    if method == "closed_form":
        q_all, valid, aux = ik_closed_form.solve_flat(robot, T.reshape(-1, 4, 4))
        shape = (n_cand, n_poses)
        q, reach, magnitude, crossing = _gather_closed_form(
            q_all.reshape(*shape, N_BRANCHES, n),
            valid.reshape(*shape, N_BRANCHES),
            aux.reshape(*shape, ik_closed_form.N_AUX),
            candidates,
        )
        channel_kind = np.array([_SHOULDER, _ELBOW, _WRIST])
    elif method == "numeric":
        seeds = np.ascontiguousarray(numeric_seeds(robot)[candidates])
        q, reach, magnitude, crossing = _numeric_paths(
            *chain_arrays(robot),
            T,
            seeds,
            _coarse_poses(T),
            _NEWTON_TOL,
            _MARCH_MAX_ITER,
            _FINE_MAX_ITER,
        )
        channel_kind = np.array([_SINGULAR])
    else:
        raise CaseError(f"method must be auto, closed_form or numeric, got {method!r}")
    switch, report, values = _analyse_paths(
        q, reach, magnitude, channel_kind, crossing, robot.q_min.copy(), robot.q_max.copy(), step
    )
    ok = (report[..., _I_N_UNREACH] == 0) & (report[..., _I_N_SWITCH] == 0)
    ok &= values[..., _F_MARGIN] >= 0.0
    return q, reach, switch, report, values, ok, candidates, step, method


def _candidate_branches(branch: int | np.ndarray | None, n_cand: int) -> np.ndarray:
    """Branches to try per candidate, shape (B, K), int64."""
    if branch is None:
        return np.ascontiguousarray(np.broadcast_to(np.arange(N_BRANCHES), (n_cand, N_BRANCHES)))
    chosen = np.asarray(branch)
    if chosen.ndim == 0:
        chosen = np.full(n_cand, chosen)
    if chosen.shape != (n_cand,) or not np.issubdtype(chosen.dtype, np.integer):
        raise CaseError(f"branch must be None, an int or an int array ({n_cand},), got {branch!r}")
    if np.any((chosen < 0) | (chosen >= N_BRANCHES)):
        raise CaseError(f"branch must be in 0…{N_BRANCHES - 1}, got {chosen.tolist()}")
    return np.ascontiguousarray(chosen.astype(np.int64)[:, None])


def _max_step(max_step: float | np.ndarray | None, n: int) -> np.ndarray:
    """The step limit per joint, shape (n,), rad."""
    step = np.full(n, DEFAULT_MAX_STEP) if max_step is None else np.asarray(max_step, float)
    try:
        step = np.ascontiguousarray(np.broadcast_to(step, (n,)), dtype=float)
    except ValueError:
        raise CaseError(
            f"max_step must be a scalar or have {n} entries, got {max_step!r}"
        ) from None
    if np.any(~(step > 0.0)):
        raise CaseError(f"max_step must be > 0, got {step.tolist()}")
    return step


def _choose(ok: np.ndarray, first_problem: np.ndarray, margin: np.ndarray) -> np.ndarray:
    """Index of the best branch per candidate, shape (B,): ok with the largest margin,
    else the latest first problem, then the largest margin; ties to the lower branch."""
    primary = np.where(ok, 0, 1)
    secondary = np.where(ok, 0, -first_problem)
    order = np.lexsort((-margin, secondary, primary), axis=-1)
    return order[:, 0]


def _status(report: np.ndarray, values: np.ndarray) -> Status:
    """The status of one branch's report."""
    if report[_I_N_UNREACH] > 0:
        return Status.UNREACHABLE
    if report[_I_N_SWITCH] > 0:
        return Status.BRANCH_SWITCH
    if values[_F_MARGIN] < 0.0:
        return Status.POSITION_LIMITS
    return Status.FEASIBLE


def _message(
    robot: Robot,
    method: str,
    branch: int,
    status: Status,
    report: np.ndarray,
    values: np.ndarray,
    n_poses: int,
    max_step: np.ndarray,
) -> str:
    """One line about one candidate's branch."""
    name = describe_branch(branch) if method == "closed_form" else f"seed {branch}"
    if status is Status.FEASIBLE:
        margin = values[_F_MARGIN]
        return f"branch {branch} ({name}) follows all {n_poses} poses, margin {margin:.3f} rad"
    parts = []
    if report[_I_N_UNREACH] > 0:
        count = report[_I_N_UNREACH]
        more = f" ({count} poses in all)" if count > 1 else ""
        parts.append(f"pose {report[_I_UNREACH]} of {n_poses} is out of reach{more}")
    if report[_I_N_SWITCH] > 0:
        k, kind, joint = report[_I_SWITCH], report[_I_KIND], report[_I_JOINT]
        parts.append(
            {
                _SHOULDER: f"the wrist centre crosses the shoulder singularity near pose {k}",
                _ELBOW: f"joint 3 crosses the elbow singularity (arm stretched) near pose {k}",
                _WRIST: f"joint 5 crosses the wrist singularity near pose {k}",
                _SINGULAR: f"the path crosses a singularity (det J changes sign) near pose {k}",
                _JUMP: (
                    f"joint {joint + 1} jumps {values[_F_STEP]:.3g} rad between poses {k - 1} "
                    f"and {k} (max {max_step[joint]:.3g})"
                ),
            }[int(kind)]
        )
    if values[_F_MARGIN] < 0.0 and report[_I_LIMIT] >= 0:
        joint = report[_I_LIMIT_JOINT]
        parts.append(
            f"joint {joint + 1} at {values[_F_VALUE]:.3f} rad leaves "
            f"[{robot.q_min[joint]:.3f}, {robot.q_max[joint]:.3f}] at pose {report[_I_LIMIT]}"
        )
    return f"branch {branch} ({name}): " + "; ".join(parts)


def _coarse_poses(T: np.ndarray) -> np.ndarray:
    """Poses the numerical path IK marches through, shape (B, M), bool.

    The first and last pose and one pose each time the combined travel
    ``|Δp| + ROTATION_LENGTH · |Δangle|`` passes a multiple of :data:`COARSE_STEP`.
    """
    position = T[..., :3, 3]
    rotation = T[..., :3, :3]
    dp = np.linalg.norm(np.diff(position, axis=1), axis=-1)
    cos_angle = 0.5 * (np.einsum("bmij,bmij->bm", rotation[:, :-1], rotation[:, 1:]) - 1.0)
    travel = dp + ROTATION_LENGTH * np.arccos(np.clip(cos_angle, -1.0, 1.0))
    cell = np.floor(
        np.concatenate([np.zeros((T.shape[0], 1)), np.cumsum(travel, 1)], 1) / COARSE_STEP
    )
    coarse = np.zeros(T.shape[:2], dtype=np.bool_)
    coarse[:, 1:] = cell[:, 1:] != cell[:, :-1]
    coarse[:, 0] = True
    coarse[:, -1] = True
    return coarse


@njit(cache=True, error_model="numpy")
def _gather_closed_form(
    q_all: np.ndarray, valid: np.ndarray, aux: np.ndarray, candidates: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:  # pragma: no cover - compiled
    """Kernel: the candidate branches' paths and branch quantities.

    Parameters
    ----------
    q_all, valid, aux
        Closed-form solutions (B, M, 8, n), validity (B, M, 8) and quantities (B, M, 14).
    candidates
        Branches per candidate, shape (B, K).

    Returns
    -------
    q, reach, magnitude, crossing
        Shapes (B, K, M, n), (B, K, M), (B, K, M, 3): |r|, |sin(θ3 + β)|, |sin θ5|, and
        (B, K, M) int8: _WRIST where z3 × z5 reverses between poses k − 1 and k.
    """
    n_cand, n_poses, _, n = q_all.shape
    n_k = candidates.shape[1]
    q = np.empty((n_cand, n_k, n_poses, n))
    reach = np.empty((n_cand, n_k, n_poses), dtype=np.bool_)
    magnitude = np.empty((n_cand, n_k, n_poses, 3))
    crossing = np.zeros((n_cand, n_k, n_poses), dtype=np.int8)
    for b in range(n_cand):
        for k in range(n_k):
            branch = candidates[b, k]
            at = 2 + 3 * (branch >> 1)  # the arm's wrist vector z3 × z5
            for m in range(n_poses):
                for j in range(n):
                    q[b, k, m, j] = q_all[b, m, branch, j]
                reach[b, k, m] = valid[b, m, branch]
                cx = aux[b, m, at]
                cy = aux[b, m, at + 1]
                cz = aux[b, m, at + 2]
                magnitude[b, k, m, 0] = aux[b, m, 0]
                magnitude[b, k, m, 1] = aux[b, m, 1]
                magnitude[b, k, m, 2] = math.sqrt(cx * cx + cy * cy + cz * cz)
                if m > 0 and reach[b, k, m] and reach[b, k, m - 1]:
                    dot = cx * aux[b, m - 1, at] + cy * aux[b, m - 1, at + 1]
                    dot += cz * aux[b, m - 1, at + 2]
                    if dot <= 0.0:
                        crossing[b, k, m] = _WRIST
    return q, reach, magnitude, crossing


@njit(cache=True, error_model="numpy")
def _numeric_paths(
    dh: np.ndarray,
    tool: np.ndarray,
    T: np.ndarray,
    seeds: np.ndarray,
    coarse: np.ndarray,
    tol: float,
    march_iter: int,
    fine_iter: int,
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:  # pragma: no cover - compiled
    """Kernel: numerical joint paths from seeds, marched coarsely then solved everywhere.

    Parameters
    ----------
    dh, tool
        From :func:`chain_arrays`.
    T
        Tool poses, shape (B, M, 4, 4).
    seeds
        Seed per candidate and branch, shape (B, K, n), rad.
    coarse
        Poses to march through, shape (B, M), bool (first and last included).
    tol, march_iter, fine_iter
        Newton tolerance (m and rad) and iteration limits of the march and the fine solve.

    Returns
    -------
    q, reach, magnitude, crossing
        Shapes (B, K, M, n), (B, K, M) (Newton converged), (B, K, M, 1): |det J| (or the
        manipulability when n ≠ 6), and (B, K, M) int8: _SINGULAR where det J changes sign.
    """
    n_cand, n_poses = T.shape[0], T.shape[1]
    n_k, n = seeds.shape[1], seeds.shape[2]
    q = np.empty((n_cand, n_k, n_poses, n))
    reach = np.empty((n_cand, n_k, n_poses), dtype=np.bool_)
    magnitude = np.empty((n_cand, n_k, n_poses, 1))
    crossing = np.zeros((n_cand, n_k, n_poses), dtype=np.int8)
    work = np.empty(work_size_kernel(n))
    current = np.empty(n)
    T_k = np.empty((4, 4))
    J = np.empty((6, n))
    axes = np.empty((n, 6))
    square = np.empty((6, 6))
    previous_coarse = np.empty(n_poses, dtype=np.int64)
    next_coarse = np.empty(n_poses, dtype=np.int64)
    for b in range(n_cand):
        last = 0
        for m in range(n_poses):
            if coarse[b, m]:
                last = m
            previous_coarse[m] = last
        for m in range(n_poses - 1, -1, -1):
            if coarse[b, m]:
                last = m
            next_coarse[m] = last
        for k in range(n_k):
            path = q[b, k]
            for j in range(n):
                current[j] = seeds[b, k, j]
            for m in range(n_poses):  # march the coarse poses with warm starts
                if coarse[b, m]:
                    for j in range(n):
                        path[m, j] = current[j]
                    ok = newton_into(dh, tool, T[b, m], path[m], tol, march_iter, work)[0]
                    reach[b, k, m] = ok
                    if ok:
                        for j in range(n):
                            current[j] = path[m, j]
                    else:
                        for j in range(n):
                            path[m, j] = current[j]
            for m in range(n_poses):  # every pose, from the interpolated coarse path
                if not coarse[b, m]:
                    m0 = previous_coarse[m]
                    m1 = next_coarse[m]
                    w = (m - m0) / (m1 - m0)
                    for j in range(n):
                        path[m, j] = (1.0 - w) * path[m0, j] + w * path[m1, j]
                    solved = newton_into(dh, tool, T[b, m], path[m], tol, fine_iter, work)
                    reach[b, k, m] = solved[0]
            previous = 0.0
            for m in range(n_poses):
                fk_jacobian_into(dh, tool, path[m], T_k, J, axes)
                det = singularity_measure(J, square)
                magnitude[b, k, m, 0] = abs(det)
                if m > 0 and n == 6 and reach[b, k, m] and reach[b, k, m - 1]:
                    if det * previous <= 0.0:
                        crossing[b, k, m] = _SINGULAR
                previous = det
    return q, reach, magnitude, crossing


@njit(cache=True, error_model="numpy")
def singularity_measure(J: np.ndarray, square: np.ndarray) -> float:  # pragma: no cover - compiled
    """Kernel: det J for a 6 × 6 Jacobian, else sqrt(det(J Jᵀ)); ``square`` is (6, 6) scratch."""
    n = J.shape[1]
    for i in range(6):
        for j in range(6):
            if n == 6:
                square[i, j] = J[i, j]
            else:
                acc = 0.0
                for c in range(n):
                    acc += J[i, c] * J[j, c]
                square[i, j] = acc
    det = 1.0
    for col in range(6):  # Gaussian elimination with partial pivoting
        pivot = col
        for r in range(col + 1, 6):
            if abs(square[r, col]) > abs(square[pivot, col]):
                pivot = r
        if square[pivot, col] == 0.0:
            return 0.0
        if pivot != col:
            det = -det
            for c in range(6):
                square[col, c], square[pivot, c] = square[pivot, c], square[col, c]
        det *= square[col, col]
        for r in range(col + 1, 6):
            factor = square[r, col] / square[col, col]
            for c in range(col, 6):
                square[r, c] -= factor * square[col, c]
    return det if n == 6 else math.sqrt(abs(det))


@njit(cache=True, error_model="numpy")
def _analyse_paths(
    q: np.ndarray,
    reach: np.ndarray,
    magnitude: np.ndarray,
    channel_kind: np.ndarray,
    crossing: np.ndarray,
    q_min: np.ndarray,
    q_max: np.ndarray,
    max_step: np.ndarray,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:  # pragma: no cover - compiled
    """Kernel: make each path continuous, find its switches, fit it into the limits.

    q (B, K, M, n) is modified in place: unreachable poses repeat the previous reachable
    configuration, angles are unwrapped along M and each joint is shifted by the
    multiple of 2π that centres its range in the limits as well as integers allow.

    Returns
    -------
    switch
        Shape (B, K, M), bool.
    report
        Shape (B, K, _N_INT), int64 (see the ``_I_*`` indices).
    values
        Shape (B, K, _N_FLOAT): margin, jump size, joint value outside the limits (rad).
    """
    n_cand, n_k, n_poses, n = q.shape
    two_pi = 2.0 * math.pi
    switch = np.zeros((n_cand, n_k, n_poses), dtype=np.bool_)
    report = np.full((n_cand, n_k, _N_INT), -1, dtype=np.int64)
    values = np.zeros((n_cand, n_k, _N_FLOAT))
    low = np.empty(n)
    high = np.empty(n)
    for b in range(n_cand):
        for k in range(n_k):
            path = q[b, k]
            ok = reach[b, k]
            rep = report[b, k]
            val = values[b, k]
            rep[_I_N_UNREACH] = 0
            rep[_I_N_SWITCH] = 0
            first = -1
            for m in range(n_poses):
                if ok[m]:
                    first = m
                    break
                if rep[_I_UNREACH] < 0:
                    rep[_I_UNREACH] = m
                rep[_I_N_UNREACH] += 1
            if first < 0:
                val[_F_MARGIN] = -np.inf
                rep[_I_FIRST] = 0
                continue
            for m in range(first):
                for j in range(n):
                    path[m, j] = path[first, j]
            for m in range(first + 1, n_poses):
                if not ok[m]:
                    if rep[_I_UNREACH] < 0:
                        rep[_I_UNREACH] = m
                    rep[_I_N_UNREACH] += 1
                    for j in range(n):
                        path[m, j] = path[m - 1, j]
                    continue
                for j in range(n):
                    step = path[m, j] - path[m - 1, j]
                    step -= two_pi * math.floor(step / two_pi + 0.5)
                    path[m, j] = path[m - 1, j] + step
                    if ok[m - 1] and abs(step) > max_step[j] and not switch[b, k, m]:
                        _note_switch(rep, val, switch[b, k], m, _JUMP, j, abs(step))
                if crossing[b, k, m] != _NONE and ok[m - 1]:
                    _note_switch(rep, val, switch[b, k], m, crossing[b, k, m], -1, 0.0)
            for c in range(magnitude.shape[3]):
                mag = magnitude[b, k, :, c]
                for m in range(1, n_poses - 1):
                    if not (ok[m - 1] and ok[m] and ok[m + 1]):
                        continue
                    left = mag[m - 1] - mag[m]
                    right = mag[m + 1] - mag[m]
                    if left >= 0.0 and right >= 0.0 and (left > 0.0 or right > 0.0):
                        if mag[m] <= max(left, right):  # reaches ~0 between poses
                            at = m + 1 if left > right else m
                            _note_switch(rep, val, switch[b, k], at, channel_kind[c], -1, 0.0)
            for j in range(n):
                low[j] = np.inf
                high[j] = -np.inf
            for m in range(n_poses):
                if ok[m]:
                    for j in range(n):
                        low[j] = min(low[j], path[m, j])
                        high[j] = max(high[j], path[m, j])
            margin = np.inf
            for j in range(n):
                centre = ((q_min[j] + q_max[j]) - (low[j] + high[j])) / (2.0 * two_pi)
                best = 0.0
                best_margin = -np.inf
                for up in range(2):
                    shift = math.floor(centre) + up
                    offset = two_pi * shift
                    room = min(low[j] + offset - q_min[j], q_max[j] - high[j] - offset)
                    if room > best_margin:
                        best_margin = room
                        best = shift
                for m in range(n_poses):
                    path[m, j] += two_pi * best
                margin = min(margin, best_margin)
            val[_F_MARGIN] = margin
            if margin < 0.0:
                for m in range(n_poses):
                    if not ok[m]:
                        continue
                    for j in range(n):
                        if path[m, j] < q_min[j] or path[m, j] > q_max[j]:
                            rep[_I_LIMIT] = m
                            rep[_I_LIMIT_JOINT] = j
                            val[_F_VALUE] = path[m, j]
                            break
                    if rep[_I_LIMIT] >= 0:
                        break
            first_problem = n_poses
            for index in (_I_UNREACH, _I_SWITCH, _I_LIMIT):
                if rep[index] >= 0:
                    first_problem = min(first_problem, rep[index])
            rep[_I_FIRST] = first_problem if first_problem < n_poses else -1
    return switch, report, values


@njit(cache=True, error_model="numpy")
def _note_switch(
    rep: np.ndarray, val: np.ndarray, switch: np.ndarray, m: int, kind: int, joint: int, step: float
) -> None:  # pragma: no cover - compiled
    """Kernel: record a switch at pose m in one branch's report."""
    if not switch[m]:
        switch[m] = True
        rep[_I_N_SWITCH] += 1
    first = rep[_I_SWITCH]
    if first < 0 or m < first or (m == first and rep[_I_KIND] == _JUMP and kind != _JUMP):
        rep[_I_SWITCH] = m  # the earliest switch; at one pose a singularity explains a jump
        rep[_I_KIND] = kind
        rep[_I_JOINT] = joint
        val[_F_STEP] = step
