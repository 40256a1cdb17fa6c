"""Joint paths along pose paths: one IK branch throughout, continuous, inside the limits.

For each candidate (a placement of the path) and each branch, the IK solutions of the M
poses form a joint path. The path is unwrapped continuously along M and then shifted by
a multiple of 2π per joint so that it sits inside ``[q_min, q_max]`` with the largest
margin. A branch is usable (``success``) when every pose is reachable, the branch never
switches (a switch is a singularity crossing: the joint path would need infinite speed
or a jump) and the shifted path stays inside the position limits.

Branches
--------
Robots of a closed-form family (OPW or UR, :mod:`trackplan.robots.families`) have the
eight closed-form branches ``b = 4·shoulder + 2·elbow + wrist``. A closed-form label swaps
at a singularity, so a switch is detected from the branch-defining quantities of each
pose and branch: the shoulder measure, the elbow measure and the wrist vector (whose
norm is |sin θ5|). Where one of them has a local minimum at pose k that is no larger
than its change to a neighbour (it reaches about zero between consecutive poses), or
where the wrist vector reverses between poses k − 1 and k, the path crosses that
singularity.

Tracked families (the CRX family, numeric IK: :mod:`trackplan.robots.ik_numeric`) have no
labelled branches: branch k of a candidate is the k-th distinct solution of its first pose
inside the limits (:meth:`~trackplan.robots.families.base.IKFamily.seed_solutions`: every
solution of a semi-closed form, or those damped Newton reaches from a fixed set of starts).
A coarse subset of the poses (one every :data:`~trackplan.robots.path_branches.COARSE_STEP`
of combined travel) is marched sequentially with warm starts, and all M poses are then
solved at once by Newton seeded with the linear interpolation of the coarse solution. A
singularity crossing shows as a sign change of det J (6 joints, or 7 with one held) or a
touch of zero of the manipulability sqrt(det(J Jᵀ)).

A redundant family takes its free parameter at every pose (``free``): the arm angle or a
held joint, chosen along the path by :mod:`trackplan.redundancy`.

Both methods also count as a switch any joint step larger than ``max_step`` between
consecutive poses (default :data:`DEFAULT_MAX_STEP`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from trackplan.robots._path_kernels import (
    ELBOW,
    F_MARGIN,
    F_STEP,
    F_VALUE,
    I_FIRST,
    I_JOINT,
    I_KIND,
    I_LIMIT,
    I_LIMIT_JOINT,
    I_N_SWITCH,
    I_N_UNREACH,
    I_SWITCH,
    I_UNREACH,
    JUMP,
    SHOULDER,
    SINGULAR,
    WRIST,
)
from trackplan.robots.families import ik_family
from trackplan.robots.ik_numeric import track_poses
from trackplan.robots.model import Robot
from trackplan.robots.path_branches import _NEWTON_TOL as _NEWTON_TOL  # planning/checker.py
from trackplan.robots.path_branches import DEFAULT_MAX_STEP as DEFAULT_MAX_STEP
from trackplan.robots.path_branches import branch_paths
from trackplan.robots.path_branches import numeric_seeds as numeric_seeds
from trackplan.robots.thread_sharing import ThreadSharing

# moved to thread_sharing; importers outside this package keep working
from trackplan.robots.thread_sharing import path_threads as path_threads
from trackplan.status import Status


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
        Branch used per candidate, shape (B,), int (closed-form label, or the solution of
        the first pose a tracked family follows).
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
    windings
        Shape (B, n), int: how many windings (shifts by 2π) of each joint's path fit inside
        its limits; more than one for joints whose range exceeds the travel by over 2π
        (a KUKA A6 of ±350°, a UR joint of ±360°).
    winding
        Shape (B, n), int: the winding used, counted from the lowest: the one with the
        largest margin to the limits. Windings change no derivative of the joint path, so
        the objective and the time law are the same on each; only the margin differs.
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
    windings: np.ndarray
    winding: np.ndarray


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
        the first pose's solution a tracked family follows).
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
    windings, winding
        Shape (B, K, n), int: as :attr:`PathIK.windings` and :attr:`PathIK.winding`, per
        branch: the search chooses a branch and, with it, the winding of largest margin.
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
    windings: np.ndarray
    winding: np.ndarray


def solve_path_ik(
    robot: Robot,
    T_base_tool: np.ndarray,
    branch: int | np.ndarray | None = None,
    max_step: float | np.ndarray | None = None,
    *,
    method: str = "auto",
    threads: int | None = None,
    sharing: ThreadSharing | None = None,
    free: np.ndarray | None = None,
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
        ``"auto"`` (closed form for the OPW and UR families, else numeric),
        ``"closed_form"`` or ``"numeric"``.
    threads
        Threads that solve and analyse all eight closed-form branches, sharing the
        candidates; None: as ``sharing`` says. The results do not depend on it.
    sharing
        The caller's record of whether sharing the work among threads pays
        (:class:`~trackplan.robots.thread_sharing.ThreadSharing`), consulted and updated
        when ``threads`` is None: a caller that solves many batches (the search) keeps one.
        None: one thread per core this process may run on (:func:`path_threads`), nothing
        recorded.
    free
        A redundant arm's IK parameter (:attr:`IKFamily.redundancy`) at every pose, shape
        (B, M), rad, or one profile per branch, (B, K, M); None for other arms.

    Returns
    -------
    PathIK

    Raises
    ------
    CaseError
        When the shapes, the branch, max_step or the method are invalid.
    """
    paths = branch_paths(
        robot,
        T_base_tool,
        branch,
        max_step,
        method,
        threads,
        screen=True,
        sharing=sharing,
        free=free,
    )
    q, reach, switch, report, values, ok = paths[:6]
    candidates, step, method, windings, winding = paths[6:]
    n_cand, n_poses = reach.shape[0], reach.shape[2]
    chosen = _choose(ok, report[..., I_FIRST], values[..., F_MARGIN])
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
        margin=values[:, F_MARGIN],
        first_problem=report[:, I_FIRST],
        status=statuses,
        message=messages,
        method=method,
        windings=windings[rows, chosen],
        winding=winding[rows, chosen],
    )


def solve_path_ik_branches(
    robot: Robot,
    T_base_tool: np.ndarray,
    max_step: float | np.ndarray | None = None,
    *,
    method: str = "auto",
    threads: int | None = None,
    sharing: ThreadSharing | None = None,
    free: np.ndarray | None = None,
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
    method, threads, sharing, free
        As for :func:`solve_path_ik`.

    Returns
    -------
    PathIKBranches

    Raises
    ------
    CaseError
        When the shapes, max_step or the method are invalid.
    """
    q, reach, switch, report, values, ok, _, _, method, windings, winding = branch_paths(
        robot, T_base_tool, None, max_step, method, threads, sharing=sharing, free=free
    )
    return PathIKBranches(
        q=q,
        branches=np.arange(q.shape[1]),
        reachable=reach,
        switch=switch,
        success=ok,
        margin=values[..., F_MARGIN],
        first_problem=report[..., I_FIRST],
        reachable_fraction=1.0 - report[..., I_N_UNREACH] / reach.shape[2],
        n_switches=report[..., I_N_SWITCH],
        method=method,
        windings=windings,
        winding=winding,
    )


def branch_joints(
    robot: Robot,
    T_base_tool: np.ndarray,
    branch: int,
    reference: np.ndarray,
    free: np.ndarray | None = None,
) -> np.ndarray:
    """Joint positions of poses on one known branch, each on the winding nearest a reference.

    The joints of ``solve_path_ik(robot, T_base_tool[None], branch=branch).q[0]``, each
    moved by the multiple of 2π that brings it nearest ``reference``: a pose the branch
    does not reach repeats the reachable pose before it (the first reachable one before
    them all). A closed-form family solves only that branch
    (:meth:`~trackplan.robots.families.base.IKFamily.solve_branch`, the same operations
    as for all eight), with no path analysis: the poses of a planned trajectory, whose
    branch the planning grid has chosen and checked.

    Parameters
    ----------
    robot
        The robot.
    T_base_tool
        Tool poses in the base frame, shape (M, 4, 4), m.
    branch
        The IK branch (closed-form label, or a tracked family's first-pose solution).
    reference
        Joint positions each result is wound nearest to, shape (M, n), rad.
    free
        A redundant arm's IK parameter at every pose, shape (M,), rad, or None.

    Returns
    -------
    numpy.ndarray
        Shape (M, n), rad.
    """
    T = np.asarray(T_base_tool, dtype=float)
    at = np.arange(len(reference), dtype=float)  # interpolating at the nodes: the reference
    return branch_joints_along(
        robot, T[:, :3, :3], T[:, :3, 3], branch, at, at, reference, free=free
    )


def branch_joints_along(
    robot: Robot,
    R_base_tool: np.ndarray,
    p_base_tool: np.ndarray,
    branch: int,
    s: np.ndarray,
    s_grid: np.ndarray,
    q_grid: np.ndarray,
    *,
    free: np.ndarray | None = None,
) -> np.ndarray:
    """:func:`branch_joints` of poses given by their parts, the reference interpolated from
    a grid, in one pass.

    The joints are those of :func:`branch_joints` of the poses ``[R_base_tool p_base_tool;
    0 1]`` with the reference ``numpy.interp(s, s_grid, q_grid[:, j])`` per joint j. A
    closed-form family reads the rotations and positions as they are
    (:meth:`~trackplan.robots.families.base.IKFamily.solve_branch_parts`: no (M, 4, 4)
    array) and holds and winds the joints in the same compiled pass (``hold_and_wind`` of
    ``families/_kernels.py``). A tracked family solves each pose by Newton from the
    reference (:func:`~trackplan.robots.ik_numeric.track_poses`): the grid's joint path,
    within a grid step of the solution, keeps the branch the grid followed.

    Parameters
    ----------
    robot
        The robot.
    R_base_tool
        Tool rotations in the base frame, shape (M, 3, 3), or one for all poses, (3, 3).
    p_base_tool
        Tool positions in the base frame, shape (M, 3), m.
    branch
        The IK branch (closed-form label, or a tracked family's first-pose solution).
    s
        Where each pose lies on the grid's axis, shape (M,) (arc length, m).
    s_grid, q_grid
        The reference: strictly increasing grid (G,) and joint positions there (G, n), rad.
    free
        A redundant arm's IK parameter at every pose, shape (M,), rad, or None.

    Returns
    -------
    numpy.ndarray
        Shape (M, n), rad.
    """
    family = ik_family(robot)
    if family.closed_form:
        grid = (s, s_grid, q_grid)
        return family.solve_branch_parts(
            R_base_tool, p_base_tool, branch, free=free, with_aux=False, wind_to=grid
        )[0]
    q_grid = np.asarray(q_grid, dtype=float)
    reference = np.column_stack([np.interp(s, s_grid, column) for column in q_grid.T])
    joint = None if family.redundancy is None else family.redundancy.joint
    held = None if joint is None else free
    q, ok = track_poses(
        robot, R_base_tool, p_base_tool, reference, held, free_joint=-1 if joint is None else joint
    )
    # a pose not solved repeats the solved pose before it (the reference before any)
    last = np.maximum.accumulate(np.where(ok, np.arange(len(ok)), -1))
    held_rows: np.ndarray = np.where((last >= 0)[:, None], q[np.maximum(last, 0)], reference)
    return held_rows


def _choose(ok: np.ndarray, first_problem: np.ndarray, margin: np.ndarray) -> np.ndarray:
    """Index of the best branch per candidate, shape (B,): ok with the largest margin,
    else the latest first problem, then the largest margin; ties to the lower branch."""
    primary = np.where(ok, 0, 1)
    secondary = np.where(ok, 0, -first_problem)
    order = np.lexsort((-margin, secondary, primary), axis=-1)
    return order[:, 0]


def _status(report: np.ndarray, values: np.ndarray) -> Status:
    """The status of one branch's report."""
    if report[I_N_UNREACH] > 0:
        return Status.UNREACHABLE
    if report[I_N_SWITCH] > 0:
        return Status.BRANCH_SWITCH
    if values[F_MARGIN] < 0.0:
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
    family = ik_family(robot)
    name = (
        family.describe_branch(branch)
        if (method == "closed_form") == family.closed_form
        else f"solution {branch} of the first pose"
    )
    if status is Status.FEASIBLE:
        margin = values[F_MARGIN]
        return f"branch {branch} ({name}) follows all {n_poses} poses, margin {margin:.3f} rad"
    parts = []
    if method == "numeric" and report[I_N_UNREACH] == n_poses:
        # a tracked branch starts at a solution of the first pose: none reached, none exists
        return (
            f"branch {branch} ({name}): the path's first pose has no such solution inside "
            "the joint limits (it has fewer distinct solutions, or none)"
        )
    if report[I_N_UNREACH] > 0:
        count = report[I_N_UNREACH]
        more = f" ({count} poses in all)" if count > 1 else ""
        parts.append(f"pose {report[I_UNREACH]} of {n_poses} is out of reach{more}")
    if report[I_N_SWITCH] > 0:
        k, kind, joint = report[I_SWITCH], report[I_KIND], report[I_JOINT]
        parts.append(
            {
                SHOULDER: f"the wrist centre crosses the shoulder singularity near pose {k}",
                ELBOW: f"joint 3 crosses the elbow singularity (arm stretched) near pose {k}",
                WRIST: f"joint 5 crosses the wrist singularity near pose {k}",
                SINGULAR: f"the path crosses a singularity (det J changes sign) near pose {k}",
                JUMP: (
                    f"joint {joint + 1} jumps {values[F_STEP]:.3g} rad between poses {k - 1} "
                    f"and {k} (max {max_step[joint]:.3g})"
                ),
            }[int(kind)]
        )
    if values[F_MARGIN] < 0.0 and report[I_LIMIT] >= 0:
        joint = report[I_LIMIT_JOINT]
        parts.append(
            f"joint {joint + 1} at {values[F_VALUE]:.3f} rad leaves "
            f"[{robot.q_min[joint]:.3f}, {robot.q_max[joint]:.3f}] at pose {report[I_LIMIT]}"
        )
    return f"branch {branch} ({name}): " + "; ".join(parts)
