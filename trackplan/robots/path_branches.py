"""The candidate branches' joint paths along pose paths, solved and analysed.

The shared core of :func:`trackplan.robots.path_ik.solve_path_ik` and
:func:`~trackplan.robots.path_ik.solve_path_ik_branches` (see :mod:`trackplan.robots.path_ik`
for the branches and what counts as a switch): the closed-form families solve all eight
branches in pieces shared among threads (:class:`~trackplan.robots.thread_sharing.ThreadSharing`)
or one branch alone; other robots march each numerical seed along the path
(:func:`numeric_seeds`). The compiled analysis is in :mod:`trackplan.robots._path_kernels`.
"""

from __future__ import annotations

import time
from collections import deque
from concurrent.futures import ThreadPoolExecutor

import numpy as np

from trackplan.errors import CaseError
from trackplan.robots._path_kernels import (
    F_MARGIN,
    I_N_SWITCH,
    I_N_UNREACH,
    N_FLOAT,
    N_INT,
    SINGULAR,
    analyse_closed_form,
    analyse_paths,
    numeric_paths,
    room_bounds,
)
from trackplan.robots.families import AUX_SIZE, IKFamily, ik_family
from trackplan.robots.families.numeric import numeric_seeds as numeric_seeds
from trackplan.robots.ik_numeric import NEWTON_TOL, chain_arrays
from trackplan.robots.model import Robot
from trackplan.robots.thread_sharing import ThreadSharing, path_threads

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
"""Every how many poses the screen of :func:`~trackplan.robots.path_ik.solve_path_ik`
solves all eight branches to bound their margins (a bound from fewer poses is looser but
still a bound)."""

PIECE_POSES = 512
"""Poses per piece of work of the closed-form path IK on all branches: the candidates are
solved and analysed a few at a time (whole candidates, about this many poses), so that a
piece's eight-branch solutions (some 200 kB) are analysed while still in the core's cache;
threads take the pieces in turn."""

_NEWTON_TOL = NEWTON_TOL
_MARCH_MAX_ITER = 100  # first pose from a seed, and the coarse march
_FINE_MAX_ITER = 30  # every pose, seeded within a coarse step of its solution


def branch_paths(
    robot: Robot,
    T_base_tool: np.ndarray,
    branch: int | np.ndarray | None,
    max_step: float | np.ndarray | None,
    method: str,
    threads: int | None,
    *,
    screen: bool = False,
    sharing: ThreadSharing | None = None,
    free: np.ndarray | None = None,
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

    Parameters are those of :func:`~trackplan.robots.path_ik.solve_path_ik`. With ``screen``
    (closed form, no branch given), all eight branches are solved at every
    :data:`SCREEN_STRIDE`-th pose, and the branch whose poses there leave the most room in
    the limits one at a time (:func:`~trackplan.robots._path_kernels.room_bounds`) is solved
    alone at every pose and analysed first; when its path is usable with a margin above
    every other branch's bound (by :data:`_ROOM_SLACK`), no other branch can be chosen and
    it is returned alone (K = 1): the same branch and analysis as from all eight. Otherwise
    all eight are solved and analysed. A given branch is solved alone.

    ``free`` is a redundant family's parameter at every pose: shape (B, M), the same for
    every branch, or (B, K, M), one profile per branch (each branch then solved alone).
    A tracked family (or ``method="numeric"``) starts branch k at the k-th distinct
    solution of each candidate's first pose (:meth:`IKFamily.seed_solutions`); a branch
    with no such solution reaches no pose.

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
    family = ik_family(robot)
    n_k = family.n_branches
    candidates = _candidate_branches(branch, T.shape[0], n_k)
    step = _max_step(max_step, robot.n_dof)
    if threads is not None and not threads >= 1:
        raise CaseError(f"threads must be None or ≥ 1, got {threads!r}")
    n_cand = T.shape[0]
    n = robot.n_dof
    free = _free_values(family, free, T.shape[:2], n_k)
    if method == "auto":
        method = "closed_form" if family.closed_form else "numeric"
    if method == "closed_form":
        if not family.closed_form:
            raise CaseError(f"the {family.name} IK family has no closed form: use method numeric")
        if free is not None and free.ndim == 3:  # a profile per branch: each solved alone
            paths = per_branch_paths(family, robot, T, candidates, step, free)
            q, reach, switch, report, values, windings, winding = paths
            ok = _usable(report, values)
            return q, reach, switch, report, values, ok, candidates, step, method, windings, winding
        if screen and branch is None:
            # the subset's poses bound each branch's margin from above as all poses do
            sub = np.ascontiguousarray(T[:, ::SCREEN_STRIDE]).reshape(-1, 4, 4)
            free_sub = None if free is None else np.ascontiguousarray(free[:, ::SCREEN_STRIDE])
            q_sub, valid_sub, _ = family.solve_flat(
                sub, free=None if free_sub is None else free_sub.ravel(), with_aux=False
            )
            shape = (n_cand, -1, n_k)
            bound = room_bounds(
                q_sub.reshape(*shape, n), valid_sub.reshape(shape), robot.q_min, robot.q_max
            )
            best = np.argmax(bound, axis=1)
            rival = np.where(np.arange(n_k) == best[:, None], -np.inf, bound).max(axis=1)
            first = np.ascontiguousarray(best[:, None])
            q, reach, switch, report, values, windings, winding = one_branch_paths(
                family, robot, T, best, step, free
            )
            ok = _usable(report, values)
            if np.all(ok[:, 0] & (values[:, 0, F_MARGIN] > rival + _ROOM_SLACK)):
                return q, reach, switch, report, values, ok, first, step, method, windings, winding
        if branch is None:
            paths = all_branch_paths(family, robot, T, candidates, step, threads, sharing, free)
        else:
            paths = one_branch_paths(family, robot, T, candidates[:, 0], step, free)
        q, reach, switch, report, values, windings, winding = paths
        ok = _usable(report, values)
        return q, reach, switch, report, values, ok, candidates, step, method, windings, winding
    if method != "numeric":
        raise CaseError(f"method must be auto, closed_form or numeric, got {method!r}")
    q, reach, magnitude, crossing = tracked_paths(family, robot, T, candidates, free)
    channel_kind = np.array([SINGULAR])
    switch, report, values, windings, winding = analyse_paths(
        q, reach, magnitude, channel_kind, crossing, robot.q_min.copy(), robot.q_max.copy(), step
    )
    ok = _usable(report, values)
    return q, reach, switch, report, values, ok, candidates, step, method, windings, winding


def tracked_paths(
    family: IKFamily,
    robot: Robot,
    T: np.ndarray,
    candidates: np.ndarray,
    free: np.ndarray | None,
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Joint paths that follow, by warm-started Newton, the distinct solutions of each
    candidate's first pose (:meth:`IKFamily.seed_solutions`; columns ``candidates``).

    Parameters
    ----------
    family, robot
        The IK family and its robot.
    T
        Tool poses, shape (B, M, 4, 4), m, C-contiguous.
    candidates
        The solution (branch) of each column, shape (B, K), int.
    free
        The redundancy parameter, shape (B, M) or (B, K, M), rad, or None.

    Returns
    -------
    q, reach, magnitude, crossing
        As :func:`~trackplan.robots._path_kernels.numeric_paths`, shapes (B, K, M, n),
        (B, K, M), (B, K, M, 1), (B, K, M); a column without a first solution reaches no
        pose.
    """
    n_cand, n_poses = T.shape[:2]
    n_k = candidates.shape[1]
    locked = -1 if family.redundancy is None else family.redundancy.joint
    if family.redundancy is not None and locked is None:
        raise CaseError(f"the {family.name} IK family is not tracked by a held joint")
    locked = -1 if locked is None else int(locked)
    if free is None:
        per_column = np.empty((n_cand, n_k, 0))
    elif free.ndim == 2:
        per_column = np.broadcast_to(free[:, None], (n_cand, n_k, n_poses))
    else:
        per_column = free
    rows = np.arange(n_cand)[:, None]
    q = np.empty((n_cand, n_k, n_poses, robot.n_dof))
    reach = np.empty((n_cand, n_k, n_poses), dtype=np.bool_)
    magnitude = np.empty((n_cand, n_k, n_poses, 1))
    crossing = np.empty((n_cand, n_k, n_poses), dtype=np.int8)
    coarse = _coarse_poses(T)
    chain = chain_arrays(robot)
    middle = 0.5 * (robot.q_min + robot.q_max)
    # a profile per column: the first pose's solutions under each column's first value
    groups = (
        [[k] for k in range(n_k)] if free is not None and free.ndim == 3 else [list(range(n_k))]
    )
    for columns in groups:
        held = np.empty((0, 0))
        first_free = None
        if free is not None:
            held = np.ascontiguousarray(per_column[:, columns[0]])
            first_free = np.ascontiguousarray(held[:, 0])
        seeds, found = family.seed_solutions(
            np.ascontiguousarray(T[:, 0]), robot.q_min, robot.q_max, free=first_free
        )
        chosen = seeds[rows, candidates[:, columns]]
        has = found[rows, candidates[:, columns]]
        chosen = np.where(has[..., None], chosen, middle)  # not followed: reaches no pose
        out = numeric_paths(
            *chain,
            T,
            np.ascontiguousarray(chosen),
            coarse,
            _NEWTON_TOL,
            _MARCH_MAX_ITER,
            _FINE_MAX_ITER,
            locked,
            held,
            np.ascontiguousarray(has),
        )
        q[:, columns], reach[:, columns], magnitude[:, columns], crossing[:, columns] = out
    return q, reach, magnitude, crossing


def _free_values(
    family: IKFamily, free: np.ndarray | None, lead: tuple[int, ...], n_k: int
) -> np.ndarray | None:
    """The redundancy parameter as float (B, M) or (B, K, M), checked against the family.

    Raises
    ------
    CaseError
        When a redundant family gets none, another family gets one, or the shape is wrong.
    """
    if family.redundancy is None:
        if free is not None:
            raise CaseError(f"the {family.name} IK family has no redundancy parameter")
        return None
    if free is None:
        raise CaseError(
            f"the {family.name} IK family needs its {family.redundancy.name} at every pose"
        )
    values = np.ascontiguousarray(free, dtype=float)
    if values.shape not in (lead, (lead[0], n_k, lead[1])):
        raise CaseError(
            f"free must have shape {lead} or {(lead[0], n_k, lead[1])}, got {values.shape}"
        )
    return values


def one_branch_paths(
    family: IKFamily,
    robot: Robot,
    T: np.ndarray,
    branches: np.ndarray,
    step: np.ndarray,
    free: np.ndarray | None = None,
) -> tuple[np.ndarray, ...]:
    """:func:`all_branch_paths` of one closed-form branch per candidate, solved alone
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
    free
        The redundancy parameter, shape (B, M), rad, or None.

    Returns
    -------
    q, reach, switch, report, values, windings, winding
        As :func:`all_branch_paths` with K = 1.
    """
    n_cand, n_poses = T.shape[:2]
    q_all = np.empty((n_cand, n_poses, 1, robot.n_dof))
    valid = np.empty((n_cand, n_poses, 1), dtype=np.bool_)
    aux = np.empty((n_cand, n_poses, 1, AUX_SIZE))
    for k in np.unique(branches):  # the candidates on one branch in one call
        rows = np.flatnonzero(branches == k)
        poses = T[rows].reshape(-1, 4, 4)
        values = None if free is None else free[rows].reshape(-1)
        q, ok, quantities = family.solve_branch(poses, int(k), free=values, with_aux=True)
        q_all[rows, :, 0] = q.reshape(len(rows), n_poses, -1)
        valid[rows, :, 0] = ok.reshape(len(rows), n_poses)
        aux[rows, :, 0] = quantities.reshape(len(rows), n_poses, AUX_SIZE)
    only = np.zeros((len(branches), 1), dtype=np.int64)
    paths = _analysis_arrays(len(branches), 1, T.shape[1], robot.n_dof)
    limits = robot.q_min.copy(), robot.q_max.copy()  # writable: one compiled kernel
    analyse_closed_form(q_all, valid, aux, only, *limits, step, *paths)
    return paths


def per_branch_paths(
    family: IKFamily,
    robot: Robot,
    T: np.ndarray,
    candidates: np.ndarray,
    step: np.ndarray,
    free: np.ndarray,
) -> tuple[np.ndarray, ...]:
    """:func:`all_branch_paths` of a redundant closed-form family with one profile of its
    parameter per candidate and branch, ``free`` (B, K, M): each column solved alone."""
    columns = [
        one_branch_paths(family, robot, T, candidates[:, k], step, free[:, k])
        for k in range(candidates.shape[1])
    ]
    return tuple(np.concatenate(parts, axis=1) for parts in zip(*columns, strict=True))


def all_branch_paths(
    family: IKFamily,
    robot: Robot,
    T: np.ndarray,
    candidates: np.ndarray,
    step: np.ndarray,
    threads: int | None,
    sharing: ThreadSharing | None = None,
    free: np.ndarray | None = None,
) -> tuple[np.ndarray, ...]:
    """The candidate branches' closed-form joint paths, analysed
    (:func:`~trackplan.robots._path_kernels.analyse_closed_form` of all eight branches'
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
        Threads to share the pieces among; None: as ``sharing`` says.
    sharing
        The caller's record of whether sharing pays, consulted and updated when
        ``threads`` is None; None: :func:`path_threads` threads, nothing recorded.
    free
        The redundancy parameter, shape (B, M), rad, or None.

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
    flat_free = None if free is None else free.reshape(-1)
    n_k = family.n_branches
    pieces = deque(range(0, n_cand, size))
    q_min, q_max = robot.q_min.copy(), robot.q_max.copy()  # writable: one compiled kernel

    def work(timed: bool = True) -> float:  # the thread's CPU time, s (0 untimed)
        started = time.thread_time() if timed else 0.0
        rows = size * n_poses
        q_rows = np.empty((rows, n_k, robot.n_dof))
        valid_rows = np.empty((rows, n_k), dtype=np.bool_)
        aux_rows = np.empty((rows, n_k, AUX_SIZE))
        while True:
            try:
                start = pieces.popleft()
            except IndexError:  # no piece left
                return time.thread_time() - started if timed else 0.0
            stop = min(start + size, n_cand)
            rows = (stop - start) * n_poses
            out = (q_rows[:rows], valid_rows[:rows], aux_rows[:rows])
            part = slice(start * n_poses, stop * n_poses)
            q_all, valid, aux = family.solve_flat(
                flat[part], free=None if flat_free is None else flat_free[part], out=out
            )
            shape = (stop - start, n_poses, n_k)
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

    if threads is None:
        threads = path_threads() if sharing is None else sharing.threads()
        record = sharing
    else:
        record = None  # a given number of threads: nothing to learn
    n_threads = min(threads, len(pieces))
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
    if record is not None:
        record.note(cpu / (n_threads * (time.perf_counter() - start)))
    return paths


def _analysis_arrays(n_cand: int, n_k: int, n_poses: int, n: int) -> tuple[np.ndarray, ...]:
    """Uninitialised outputs of :func:`~trackplan.robots._path_kernels.analyse_closed_form`."""
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
    usable: np.ndarray = ok & (values[..., F_MARGIN] >= 0.0)
    return usable


def _candidate_branches(branch: int | np.ndarray | None, n_cand: int, n_k: int) -> np.ndarray:
    """Branches to try per candidate (of the family's ``n_k``), shape (B, K), int64."""
    if branch is None:
        return np.ascontiguousarray(np.broadcast_to(np.arange(n_k), (n_cand, n_k)))
    chosen = np.asarray(branch)
    if chosen.ndim == 0:
        chosen = np.full(n_cand, chosen)
    if chosen.shape != (n_cand,) or not np.issubdtype(chosen.dtype, np.integer):
        raise CaseError(f"branch must be None, an int or an int array ({n_cand},), got {branch!r}")
    if np.any((chosen < 0) | (chosen >= n_k)):
        raise CaseError(f"branch must be in 0…{n_k - 1}, got {chosen.tolist()}")
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
