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

import os
import time
from collections import deque
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass

import numpy as np

from trackplan.errors import CaseError
from trackplan.robots._kernels import (
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
    N_FLOAT,
    N_INT,
    SHOULDER,
    SINGULAR,
    WRIST,
    analyse_closed_form,
    analyse_paths,
    numeric_paths,
    room_bounds,
)
from trackplan.robots.families import AUX_SIZE, N_BRANCHES, IKFamily, ik_family
from trackplan.robots.ik_numeric import chain_arrays
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

_ROOM_SLACK = 1e-9
"""Margin by which the screened branch must beat every other branch's bound, rad: far
above the round-off of unwrapping a path (about 1e-12 rad over thousands of poses)."""

SCREEN_STRIDE = 8
"""Every how many poses the screen of :func:`solve_path_ik` solves all eight branches to
bound their margins (a bound from fewer poses is looser but still a bound)."""

PIECE_POSES = 512
"""Poses per piece of work of the closed-form path IK on all branches: the candidates are
solved and analysed a few at a time (whole candidates, about this many poses), so that a
piece's eight-branch solutions (some 200 kB) are analysed while still in the core's cache;
threads take the pieces in turn."""

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
    threads: int | None = None,
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
        candidates; None: one per core this process may run on (:func:`path_threads`)
        while that pays (:class:`ThreadSharing`), else one. The results do not depend on it.

    Returns
    -------
    PathIK

    Raises
    ------
    CaseError
        When the shapes, the branch, max_step or the method are invalid.
    """
    paths = _branch_paths(robot, T_base_tool, branch, max_step, method, threads, screen=True)
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
    method, threads
        As for :func:`solve_path_ik`.

    Returns
    -------
    PathIKBranches

    Raises
    ------
    CaseError
        When the shapes, max_step or the method are invalid.
    """
    q, reach, switch, report, values, ok, _, _, method, windings, winding = _branch_paths(
        robot, T_base_tool, None, max_step, method, threads
    )
    return PathIKBranches(
        q=q,
        branches=np.arange(N_BRANCHES),
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
    robot: Robot, T_base_tool: np.ndarray, branch: int, reference: np.ndarray
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
        The IK branch (closed-form branch or numeric seed), 0 … 7.
    reference
        Joint positions each result is wound nearest to, shape (M, n), rad.

    Returns
    -------
    numpy.ndarray
        Shape (M, n), rad.
    """
    T = np.asarray(T_base_tool, dtype=float)
    at = np.arange(len(reference), dtype=float)  # interpolating at the nodes: the reference
    return branch_joints_along(robot, T[:, :3, :3], T[:, :3, 3], branch, at, at, reference)


def branch_joints_along(
    robot: Robot,
    R_base_tool: np.ndarray,
    p_base_tool: np.ndarray,
    branch: int,
    s: np.ndarray,
    s_grid: np.ndarray,
    q_grid: np.ndarray,
) -> np.ndarray:
    """:func:`branch_joints` of poses given by their parts, the reference interpolated from
    a grid, in one pass.

    The joints are those of :func:`branch_joints` of the poses ``[R_base_tool p_base_tool;
    0 1]`` with the reference ``numpy.interp(s, s_grid, q_grid[:, j])`` per joint j. A
    closed-form family reads the rotations and positions as they are
    (:meth:`~trackplan.robots.families.base.IKFamily.solve_branch_parts`: no (M, 4, 4)
    array) and holds and winds the joints in the same compiled pass (``hold_and_wind`` of
    ``families/_kernels.py``); numeric IK winds them after its path IK.

    Parameters
    ----------
    robot
        The robot.
    R_base_tool
        Tool rotations in the base frame, shape (M, 3, 3), or one for all poses, (3, 3).
    p_base_tool
        Tool positions in the base frame, shape (M, 3), m.
    branch
        The IK branch (closed-form branch or numeric seed), 0 … 7.
    s
        Where each pose lies on the grid's axis, shape (M,) (arc length, m).
    s_grid, q_grid
        The reference: strictly increasing grid (G,) and joint positions there (G, n), rad.

    Returns
    -------
    numpy.ndarray
        Shape (M, n), rad.
    """
    family = ik_family(robot)
    if family.closed_form:
        grid = (s, s_grid, q_grid)
        return family.solve_branch_parts(
            R_base_tool, p_base_tool, branch, with_aux=False, wind_to=grid
        )[0]
    T = np.zeros((len(p_base_tool), 4, 4))
    T[:, :3, :3] = R_base_tool
    T[:, :3, 3] = p_base_tool
    T[:, 3, 3] = 1.0
    q = solve_path_ik(robot, T[None], branch=branch).q[0]  # missed poses held
    q_grid = np.asarray(q_grid, dtype=float)
    reference = np.column_stack([np.interp(s, s_grid, column) for column in q_grid.T])
    return q - 2 * np.pi * np.round((q - reference) / (2 * np.pi))


def _branch_paths(
    robot: Robot,
    T_base_tool: np.ndarray,
    branch: int | np.ndarray | None,
    max_step: float | np.ndarray | None,
    method: str,
    threads: int | None,
    *,
    screen: bool = False,
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
    np.ndarray,
    np.ndarray,
]:
    """The candidate branches' joint paths, analysed: the shared core of both solvers.

    Parameters are those of :func:`solve_path_ik`. With ``screen`` (closed form, no branch
    given), all eight branches are solved at every :data:`SCREEN_STRIDE`-th pose, and the
    branch whose poses there leave the most room in the limits one at a time
    (:func:`~trackplan.robots._kernels.room_bounds`) is solved alone at every pose and
    analysed first; when its path is usable with a margin above every other branch's
    bound (by :data:`_ROOM_SLACK`), no other branch can be chosen and it is returned alone
    (K = 1): the same branch and analysis as from all eight. Otherwise all eight are
    solved and analysed. A given branch is solved alone.

    Returns
    -------
    q, reach, switch, report, values, ok, candidates, step, method, windings, winding
        Shapes (B, K, M, n), (B, K, M), (B, K, M), (B, K, N_INT), (B, K, N_FLOAT),
        (B, K) bool; the branches tried (B, K), the step limit (n,), the method used, and
        per joint the number of 2π windings that fit and the one kept, (B, K, n) each.
    """
    T = np.ascontiguousarray(T_base_tool, dtype=float)
    if T.ndim != 4 or T.shape[-2:] != (4, 4) or T.shape[1] < 1:
        raise CaseError(f"T_base_tool must have shape (B, M, 4, 4), got {T.shape}")
    candidates = _candidate_branches(branch, T.shape[0])
    step = _max_step(max_step, robot.n_dof)
    if threads is not None and not threads >= 1:
        raise CaseError(f"threads must be None or ≥ 1, got {threads!r}")
    n_cand = T.shape[0]
    n = robot.n_dof
    family = ik_family(robot)
    if method == "auto":
        method = "closed_form" if family.closed_form else "numeric"
    if method == "closed_form":
        if screen and branch is None:
            # the subset's poses bound each branch's margin from above as all poses do
            sub = np.ascontiguousarray(T[:, ::SCREEN_STRIDE]).reshape(-1, 4, 4)
            q_sub, valid_sub, _ = family.solve_flat(sub, with_aux=False)
            shape = (n_cand, -1, N_BRANCHES)
            bound = room_bounds(
                q_sub.reshape(*shape, n), valid_sub.reshape(shape), robot.q_min, robot.q_max
            )
            best = np.argmax(bound, axis=1)
            rival = np.where(np.arange(N_BRANCHES) == best[:, None], -np.inf, bound).max(axis=1)
            first = np.ascontiguousarray(best[:, None])
            q, reach, switch, report, values, windings, winding = _one_branch_paths(
                family, robot, T, best, step
            )
            ok = _usable(report, values)
            if np.all(ok[:, 0] & (values[:, 0, F_MARGIN] > rival + _ROOM_SLACK)):
                return q, reach, switch, report, values, ok, first, step, method, windings, winding
        if branch is None:
            paths = _all_branch_paths(family, robot, T, candidates, step, threads)
        else:
            paths = _one_branch_paths(family, robot, T, candidates[:, 0], step)
        q, reach, switch, report, values, windings, winding = paths
        ok = _usable(report, values)
        return q, reach, switch, report, values, ok, candidates, step, method, windings, winding
    if method == "numeric":
        seeds = np.ascontiguousarray(numeric_seeds(robot)[candidates])
        q, reach, magnitude, crossing = numeric_paths(
            *chain_arrays(robot),
            T,
            seeds,
            _coarse_poses(T),
            _NEWTON_TOL,
            _MARCH_MAX_ITER,
            _FINE_MAX_ITER,
        )
        channel_kind = np.array([SINGULAR])
    else:
        raise CaseError(f"method must be auto, closed_form or numeric, got {method!r}")
    switch, report, values, windings, winding = analyse_paths(
        q, reach, magnitude, channel_kind, crossing, robot.q_min.copy(), robot.q_max.copy(), step
    )
    ok = _usable(report, values)
    return q, reach, switch, report, values, ok, candidates, step, method, windings, winding


def _one_branch_paths(
    family: IKFamily, robot: Robot, T: np.ndarray, branches: np.ndarray, step: np.ndarray
) -> tuple[np.ndarray, ...]:
    """:func:`_all_branch_paths` of one closed-form branch per candidate, solved alone
    (:meth:`~trackplan.robots.families.base.IKFamily.solve_branch`, the bits of that branch
    of all eight).

    Parameters
    ----------
    family
        A closed-form family.
    robot
        The robot.
    T
        Tool poses, shape (B, M, 4, 4), m.
    branches
        The branch of each candidate, shape (B,), int.
    step
        The step limit per joint, shape (n,), rad.

    Returns
    -------
    q, reach, switch, report, values, windings, winding
        As :func:`_all_branch_paths` with K = 1.
    """
    solved = [family.solve_branch(T[b], int(k), with_aux=True) for b, k in enumerate(branches)]
    q_all, valid, aux = (np.stack([found[i] for found in solved])[:, :, None] for i in range(3))
    only = np.zeros((len(branches), 1), dtype=np.int64)
    paths = _analysis_arrays(len(branches), 1, T.shape[1], robot.n_dof)
    limits = robot.q_min.copy(), robot.q_max.copy()  # writable: one compiled kernel
    analyse_closed_form(q_all, valid, aux, only, *limits, step, *paths)
    return paths


def _all_branch_paths(
    family: IKFamily,
    robot: Robot,
    T: np.ndarray,
    candidates: np.ndarray,
    step: np.ndarray,
    threads: int | None,
) -> tuple[np.ndarray, ...]:
    """The candidate branches' closed-form joint paths, analysed
    (:func:`~trackplan.robots._kernels.analyse_closed_form` of all eight branches'
    solutions), in pieces of about :data:`PIECE_POSES` poses shared among threads.

    Each piece's candidates are solved on all eight branches into the thread's scratch and
    analysed from there; the pieces write disjoint parts of the outputs, so the results do
    not depend on the number of threads.

    Parameters
    ----------
    family
        A closed-form family.
    robot
        The robot.
    T
        Tool poses, shape (B, M, 4, 4), m, C-contiguous.
    candidates
        Branches per candidate, shape (B, K), int64.
    step
        The step limit per joint, shape (n,), rad.
    threads
        Threads to share the pieces among; None: as :class:`ThreadSharing` says.

    Returns
    -------
    q, reach, switch, report, values, windings, winding
        Shapes (B, K, M, n), (B, K, M), (B, K, M), (B, K, N_INT), (B, K, N_FLOAT),
        (B, K, n), (B, K, n).
    """
    n_cand, n_poses = T.shape[:2]
    paths = _analysis_arrays(n_cand, candidates.shape[1], n_poses, robot.n_dof)
    size = max(1, PIECE_POSES // n_poses)  # candidates per piece
    flat = T.reshape(-1, 4, 4)
    pieces = deque(range(0, n_cand, size))
    q_min, q_max = robot.q_min.copy(), robot.q_max.copy()  # writable: one compiled kernel

    def work(timed: bool = True) -> float:  # the thread's CPU time, s (0 untimed)
        started = time.thread_time() if timed else 0.0
        rows = size * n_poses
        q_rows = np.empty((rows, N_BRANCHES, robot.n_dof))
        valid_rows = np.empty((rows, N_BRANCHES), dtype=np.bool_)
        aux_rows = np.empty((rows, N_BRANCHES, AUX_SIZE))
        while True:
            try:
                start = pieces.popleft()
            except IndexError:  # no piece left
                return time.thread_time() - started if timed else 0.0
            stop = min(start + size, n_cand)
            rows = (stop - start) * n_poses
            out = (q_rows[:rows], valid_rows[:rows], aux_rows[:rows])
            q_all, valid, aux = family.solve_flat(flat[start * n_poses : stop * n_poses], out=out)
            shape = (stop - start, n_poses, N_BRANCHES)
            analyse_closed_form(
                q_all.reshape(*shape, -1),
                valid.reshape(shape),
                aux.reshape(*shape, AUX_SIZE),
                candidates[start:stop],
                q_min,
                q_max,
                step,
                *(array[start:stop] for array in paths),
            )

    n_threads = min(_SHARING.threads() if threads is None else threads, len(pieces))
    if n_threads < 2:
        work(timed=False)
        return paths
    start = time.perf_counter()
    with ThreadPoolExecutor(n_threads - 1) as pool:  # its threads end with the block
        running = [pool.submit(work) for _ in range(n_threads - 1)]
        try:
            cpu = work()
        finally:
            pieces.clear()  # on an exception here the helpers stop after their piece
        cpu += sum(future.result() for future in running)
    if threads is None:
        _SHARING.note(cpu / (n_threads * (time.perf_counter() - start)))
    return paths


def path_threads() -> int:
    """The cores this process may run on (``os.sched_getaffinity``): the threads the
    closed-form path IK on all branches shares its work among while that pays."""
    if hasattr(os, "sched_getaffinity"):
        return len(os.sched_getaffinity(0))
    return os.cpu_count() or 1


EFFICIENT = 0.7
"""Parallel efficiency (the threads' CPU time over threads × wall time) of a shared call of
the path IK below which sharing does not pay: a thread waited for a core. Measured on two
cores: about 0.95 with the second core free, about 0.3–0.4 at a load of 4."""

FIRST_PAUSE = 4
"""Calls of the path IK run on one thread after a shared call that did not pay; the pause
doubles while sharing keeps not paying, up to :data:`LAST_PAUSE`."""
LAST_PAUSE = 64


class ThreadSharing:
    """Whether the path IK shares its work among threads: while sharing pays.

    Threads help only where a core is free. On a busy machine a thread waits for a core
    and the caller waits for the thread: the call then takes longer than on one thread
    (the corner case's search took 1.5× its one-thread wall time at a load of 4 on two
    cores). So each shared call measures its parallel efficiency; below
    :data:`EFFICIENT`, the next calls run on one thread (:data:`FIRST_PAUSE` calls, twice
    as many after each further shared call that does not pay, at most
    :data:`LAST_PAUSE`). The results are the same on any number of threads.
    """

    def __init__(self) -> None:
        self.pause = 0  # the last pause, calls
        self.left = 0  # calls still to run on one thread

    def threads(self) -> int:
        """Threads for the next call: one during a pause, else :func:`path_threads`."""
        if self.left > 0:
            self.left -= 1
            return 1
        return path_threads()

    def note(self, efficiency: float) -> None:
        """Record a shared call's parallel efficiency (in (0, 1])."""
        if efficiency >= EFFICIENT:
            self.pause = 0
        else:
            self.pause = min(LAST_PAUSE, 2 * self.pause if self.pause else FIRST_PAUSE)
            self.left = self.pause


_SHARING = ThreadSharing()
"""The process's record of whether sharing the path IK among threads pays."""


def _analysis_arrays(n_cand: int, n_k: int, n_poses: int, n: int) -> tuple[np.ndarray, ...]:
    """Uninitialised outputs of :func:`~trackplan.robots._kernels.analyse_closed_form`."""
    return (
        np.empty((n_cand, n_k, n_poses, n)),
        np.empty((n_cand, n_k, n_poses), dtype=np.bool_),
        np.empty((n_cand, n_k, n_poses), dtype=np.bool_),
        np.empty((n_cand, n_k, N_INT), dtype=np.int64),
        np.empty((n_cand, n_k, N_FLOAT)),
        np.empty((n_cand, n_k, n), dtype=np.int64),
        np.empty((n_cand, n_k, n), dtype=np.int64),
    )


def _usable(report: np.ndarray, values: np.ndarray) -> np.ndarray:
    """Which analysed branches are usable: reachable everywhere, no switch, inside the
    limits; shape (B, K), bool."""
    ok = (report[..., I_N_UNREACH] == 0) & (report[..., I_N_SWITCH] == 0)
    return ok & (values[..., F_MARGIN] >= 0.0)


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
    name = ik_family(robot).describe_branch(branch) if method == "closed_form" else f"seed {branch}"
    if status is Status.FEASIBLE:
        margin = values[F_MARGIN]
        return f"branch {branch} ({name}) follows all {n_poses} poses, margin {margin:.3f} rad"
    parts = []
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
