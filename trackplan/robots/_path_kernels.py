"""Compiled kernels of the path IK: branch analysis, switches, limits and windings.

The Python API is :mod:`trackplan.robots.path_ik` (through
:mod:`trackplan.robots.path_branches`): :func:`analyse_closed_form` and
:func:`analyse_paths` analyse the joint paths of the closed-form and the numerical
branches, :func:`numeric_paths` marches the numerical seeds along the poses, and
:func:`room_bounds` bounds each branch's margin from a subset of the poses.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from trackplan.robots._ik_kernels import (
    fk_jacobian_into,
    gauss_newton_into,
    newton_into,
    work_size_kernel,
)

N_INT = 9
# Per-branch float report: margin (rad), the jump (rad), the joint value outside (rad).
F_MARGIN, F_STEP, F_VALUE = range(3)
N_FLOAT = 3


# Kinds of switch, in the order of the per-branch report.
NONE, SHOULDER, ELBOW, WRIST, SINGULAR, JUMP = range(6)
# Per-branch integer report: first problem, first unreachable pose, number unreachable,
# first switch, its kind, its joint (jumps), number of switches, first pose outside the
# limits, its joint.
I_FIRST, I_UNREACH, I_N_UNREACH, I_SWITCH, I_KIND, I_JOINT, I_N_SWITCH = range(7)
I_LIMIT, I_LIMIT_JOINT = 7, 8


@njit(cache=True, error_model="numpy")
def room_bounds(
    q_all: np.ndarray, valid: np.ndarray, q_min: np.ndarray, q_max: np.ndarray
) -> np.ndarray:  # pragma: no cover - compiled
    """Kernel: an upper bound of each branch's path margin from its poses one at a time.

    A joint value θ fits its limits by at most ``max_k min(θ + 2πk − q_min, q_max − θ −
    2πk)``, reached at the k nearest the centre of the range. The continuous path through
    a branch's poses, shifted by one multiple of 2π per joint, has no more margin than its
    worst pose (:func:`analyse_paths`): the smallest of these over the poses and joints
    bounds the branch's margin from above (up to the round-off of the unwrapping).
    A branch that misses a pose is not usable: −inf.

    Parameters
    ----------
    q_all, valid
        Closed-form solutions (B, M, 8, n), rad, and their validity (B, M, 8).
    q_min, q_max
        Joint limits, shape (n,), rad.

    Returns
    -------
    numpy.ndarray
        Shape (B, 8), rad.
    """
    n_cand, n_poses, n_branch, n = q_all.shape
    two_pi = 2.0 * math.pi
    bound = np.full((n_cand, n_branch), np.inf)
    for b in range(n_cand):
        for m in range(n_poses):
            for k in range(n_branch):
                if not valid[b, m, k]:
                    bound[b, k] = -np.inf
                    continue
                for j in range(n):
                    theta = q_all[b, m, k, j]
                    middle = 0.5 * (q_min[j] + q_max[j])
                    shift = two_pi * math.floor((middle - theta) / two_pi + 0.5)
                    room = min(theta + shift - q_min[j], q_max[j] - theta - shift)
                    if room < bound[b, k]:
                        bound[b, k] = room
    return bound


@njit(cache=True, error_model="numpy")
def numeric_paths(
    chain: np.ndarray,
    tool: np.ndarray,
    T: np.ndarray,
    seeds: np.ndarray,
    coarse: np.ndarray,
    tol: float,
    march_iter: int,
    fine_iter: int,
    locked: int,
    free: np.ndarray,
    active: np.ndarray,
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:  # pragma: no cover - compiled
    """Kernel: numerical joint paths from seeds, marched coarsely then solved everywhere.

    Parameters
    ----------
    chain, tool
        From :func:`trackplan.robots.ik_numeric.chain_arrays`.
    T
        Tool poses, shape (B, M, 4, 4).
    seeds
        Seed per candidate and branch, shape (B, K, n), rad.
    coarse
        Poses to march through, shape (B, M), bool (first and last included).
    tol, march_iter, fine_iter
        Newton tolerance (m and rad) and iteration limits of the march and the fine solve.
    locked, free
        A 7-joint arm's redundancy: joint ``locked`` (≥ 0) is held at ``free[b, m]`` at
        pose m of candidate b, shape (B, M), rad, and the others solve the pose; −1 (and
        an empty ``free``): no joint is held.
    active
        Shape (B, K), bool: the paths to follow; an inactive one (its seed is no solution of
        the first pose) stays at its seed, reaches no pose and is not solved at all.

    The fine solve tries undamped Gauss–Newton from the interpolation first
    (:func:`~trackplan.robots._ik_kernels.gauss_newton_into`, square Jacobians), damped
    Newton from the interpolation again where that does not converge.

    Returns
    -------
    q, reach, magnitude, crossing
        Shapes (B, K, M, n), (B, K, M) (Newton converged), (B, K, M, 1): |det J| (or the
        manipulability when n ≠ 6), and (B, K, M) int8: SINGULAR where det J changes sign.
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
    e = np.empty(6)
    A = np.empty((6, 7))
    dq = np.empty(n)
    square_jacobian = n == 6 or (n == 7 and locked >= 0)
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
            if not active[b, k]:
                for m in range(n_poses):
                    reach[b, k, m] = False
                    magnitude[b, k, m, 0] = 0.0
                    for j in range(n):
                        path[m, j] = current[j]
                continue
            for m in range(n_poses):  # march the coarse poses with warm starts
                if coarse[b, m]:
                    for j in range(n):
                        path[m, j] = current[j]
                    if locked >= 0:
                        path[m, locked] = free[b, m]
                    ok = newton_into(chain, tool, T[b, m], path[m], tol, march_iter, work, locked)[
                        0
                    ]
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
                    if locked >= 0:
                        path[m, locked] = free[b, m]
                    if square_jacobian and gauss_newton_into(
                        chain, tool, T[b, m], path[m], tol, locked, T_k, J, axes, e, A, dq
                    ):
                        reach[b, k, m] = True
                        continue
                    for j in range(n):  # from the interpolation again, damped where needed
                        path[m, j] = (1.0 - w) * path[m0, j] + w * path[m1, j]
                    if locked >= 0:
                        path[m, locked] = free[b, m]
                    solved = newton_into(
                        chain, tool, T[b, m], path[m], tol, fine_iter, work, locked
                    )
                    reach[b, k, m] = solved[0]
            previous = 0.0
            for m in range(n_poses):
                fk_jacobian_into(chain, tool, path[m], T_k, J, axes)
                det = singularity_measure(J, square, locked)
                magnitude[b, k, m, 0] = abs(det)
                if m > 0 and square_jacobian and reach[b, k, m] and reach[b, k, m - 1]:
                    if det * previous <= 0.0:
                        crossing[b, k, m] = SINGULAR
                previous = det
    return q, reach, magnitude, crossing


@njit(cache=True, error_model="numpy")
def singularity_measure(
    J: np.ndarray, square: np.ndarray, locked: int = -1
) -> float:  # pragma: no cover - compiled
    """Kernel: det J for a 6 × 6 Jacobian (or a 6 × 7 one without the ``locked`` column),
    else sqrt(det(J Jᵀ)); ``square`` is (6, 6) scratch."""
    n = J.shape[1]
    square_jacobian = n == 6 or (n == 7 and locked >= 0)
    for i in range(6):
        for j in range(6):
            if n == 6:
                square[i, j] = J[i, j]
            elif square_jacobian:
                square[i, j] = J[i, j if j < locked else j + 1]
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
    return det if square_jacobian else math.sqrt(abs(det))


@njit(cache=True, error_model="numpy")
def analyse_paths(
    q: np.ndarray,
    reach: np.ndarray,
    magnitude: np.ndarray,
    channel_kind: np.ndarray,
    crossing: np.ndarray,
    q_min: np.ndarray,
    q_max: np.ndarray,
    max_step: np.ndarray,
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:  # pragma: no cover
    """Kernel: make each path continuous, find its switches, fit it into the limits.

    q (B, K, M, n) is modified in place: unreachable poses repeat the previous reachable
    configuration, angles are unwrapped along M and each joint is shifted by the
    multiple of 2π that centres its range in the limits as well as integers allow. A
    joint whose range exceeds its travel by more than 2π has several such windings; they
    are enumerated (``windings``) and the one with the largest margin is kept.

    Returns
    -------
    switch
        Shape (B, K, M), bool.
    report
        Shape (B, K, N_INT), int64 (see the ``_I_*`` indices).
    values
        Shape (B, K, N_FLOAT): margin, jump size, joint value outside the limits (rad).
    windings
        Shape (B, K, n), int64: how many 2π windings of each joint's path fit inside its
        limits (0 when none does).
    winding
        Shape (B, K, n), int64: which of them is kept, counted from the lowest (0 when
        none fits).
    """
    n_cand, n_k, n_poses, n = q.shape
    two_pi = 2.0 * math.pi
    switch = np.zeros((n_cand, n_k, n_poses), dtype=np.bool_)
    report = np.full((n_cand, n_k, N_INT), -1, dtype=np.int64)
    values = np.zeros((n_cand, n_k, N_FLOAT))
    windings = np.zeros((n_cand, n_k, n), dtype=np.int64)
    winding = np.zeros((n_cand, n_k, n), dtype=np.int64)
    low = np.empty(n)
    high = np.empty(n)
    offset = np.empty(n)
    for b in range(n_cand):
        for k in range(n_k):
            path = q[b, k]
            ok = reach[b, k]
            rep = report[b, k]
            val = values[b, k]
            rep[I_N_UNREACH] = 0
            rep[I_N_SWITCH] = 0
            first = -1
            for m in range(n_poses):
                if ok[m]:
                    first = m
                    break
                if rep[I_UNREACH] < 0:
                    rep[I_UNREACH] = m
                rep[I_N_UNREACH] += 1
            if first < 0:
                val[F_MARGIN] = -np.inf
                rep[I_FIRST] = 0
                continue
            for m in range(first):
                for j in range(n):
                    path[m, j] = path[first, j]
            for m in range(first + 1, n_poses):
                if not ok[m]:
                    if rep[I_UNREACH] < 0:
                        rep[I_UNREACH] = m
                    rep[I_N_UNREACH] += 1
                    for j in range(n):
                        path[m, j] = path[m - 1, j]
                    continue
                for j in range(n):
                    step = path[m, j] - path[m - 1, j]
                    step -= two_pi * math.floor(step / two_pi + 0.5)
                    path[m, j] = path[m - 1, j] + step
                    if ok[m - 1] and abs(step) > max_step[j] and not switch[b, k, m]:
                        note_switch(rep, val, switch[b, k], m, int(JUMP), j, abs(step))
                if crossing[b, k, m] != NONE and ok[m - 1]:
                    note_switch(
                        rep, val, switch[b, k], m, int(crossing[b, k, m]), int(NO_JOINT), 0.0
                    )
            for c in range(magnitude.shape[3]):
                note_minima(magnitude[b, k, :, c], ok, int(channel_kind[c]), rep, val, switch[b, k])
            for j in range(n):
                low[j] = np.inf
                high[j] = -np.inf
            for m in range(n_poses):
                if ok[m]:
                    for j in range(n):
                        low[j] = min(low[j], path[m, j])
                        high[j] = max(high[j], path[m, j])
            fit_limits(
                path, ok, q_min, q_max, rep, val, windings[b, k], winding[b, k], low, high, offset
            )
    return switch, report, values, windings, winding


@njit(cache=True, error_model="numpy", nogil=True)
def analyse_closed_form(
    q_all: np.ndarray,
    valid: np.ndarray,
    aux: np.ndarray,
    candidates: np.ndarray,
    q_min: np.ndarray,
    q_max: np.ndarray,
    max_step: np.ndarray,
    q: np.ndarray,
    reach: np.ndarray,
    switch: np.ndarray,
    report: np.ndarray,
    values: np.ndarray,
    windings: np.ndarray,
    winding: np.ndarray,
) -> None:  # pragma: no cover - compiled
    """Kernel: :func:`analyse_paths` of the closed-form solutions' candidate branches, in
    one pass per path written once.

    The outputs are those of gathering each candidate branch's joints, reach and branch
    quantities from all eight branches' solutions and analysing the gathered paths with
    :func:`analyse_paths` (channels shoulder, elbow, wrist; a wrist crossing where the
    wrist vector reverses between two reached poses), bit for bit, without the gathered
    (B, K, M, ·) arrays: each path is unwrapped as it is read, its branch measures go to a
    small scratch. Releases the GIL: threads may analyse separate candidates at once.

    Parameters
    ----------
    q_all, valid, aux
        Closed-form solutions (B, M, 8, n), rad, validity (B, M, 8) and branch quantities
        (B, M, 8, 5): shoulder and elbow measures, wrist vector.
    candidates
        Branches per candidate, shape (B, K).
    q_min, q_max, max_step
        Joint limits and the largest step that is not a jump, shape (n,), rad.
    q, reach, switch, report, values, windings, winding
        Outputs: the analysed paths (B, K, M, n), rad; reach (B, K, M) and switch
        (B, K, M) bool; the reports (B, K, N_INT) and (B, K, N_FLOAT); windings and winding
        (B, K, n) (see :func:`analyse_paths`). Every entry is written.
    """
    n_cand, n_poses, _, n = q_all.shape
    n_k = candidates.shape[1]
    two_pi = 2.0 * math.pi
    mag = np.empty((3, n_poses))
    low = np.empty(n)
    high = np.empty(n)
    offset = np.empty(n)
    steps = np.empty(n)
    for b in range(n_cand):
        for k in range(n_k):
            branch = candidates[b, k]
            path = q[b, k]
            ok = reach[b, k]
            sw = switch[b, k]
            rep = report[b, k]
            val = values[b, k]
            for i in range(N_INT):
                rep[i] = -1
            for i in range(N_FLOAT):
                val[i] = 0.0
            for j in range(n):
                windings[b, k, j] = 0
                winding[b, k, j] = 0
            rep[I_N_UNREACH] = 0
            rep[I_N_SWITCH] = 0
            first = -1
            for m in range(n_poses):
                reached = valid[b, m, branch]
                ok[m] = reached
                sw[m] = False
                x = aux[b, m, branch, 2]
                y = aux[b, m, branch, 3]
                z = aux[b, m, branch, 4]
                mag[0, m] = aux[b, m, branch, 0]
                mag[1, m] = aux[b, m, branch, 1]
                mag[2, m] = math.sqrt(x * x + y * y + z * z)
                if reached:
                    if first < 0:
                        first = m
                else:
                    if rep[I_UNREACH] < 0:
                        rep[I_UNREACH] = m
                    rep[I_N_UNREACH] += 1
            if first < 0:
                for m in range(n_poses):
                    for j in range(n):
                        path[m, j] = q_all[b, m, branch, j]
                val[F_MARGIN] = -np.inf
                rep[I_FIRST] = 0
                continue
            for m in range(first + 1):
                for j in range(n):
                    path[m, j] = q_all[b, first, branch, j]
            for j in range(n):
                low[j] = path[first, j]
                high[j] = path[first, j]
            for m in range(first + 1, n_poses):
                if not ok[m]:
                    for j in range(n):
                        path[m, j] = path[m - 1, j]
                    continue
                jump = False
                for j in range(n):
                    before = path[m - 1, j]
                    step = q_all[b, m, branch, j] - before
                    step -= two_pi * np.floor(step / two_pi + 0.5)
                    steps[j] = step
                    value = before + step
                    path[m, j] = value
                    low[j] = min(low[j], value)
                    high[j] = max(high[j], value)
                    jump |= abs(step) > max_step[j]
                if jump and ok[m - 1]:
                    for j in range(n):
                        step = steps[j]
                        if abs(step) > max_step[j] and not sw[m]:
                            note_switch(rep, val, sw, m, int(JUMP), j, abs(step))
                if ok[m - 1]:
                    x = aux[b, m, branch, 2]
                    y = aux[b, m, branch, 3]
                    z = aux[b, m, branch, 4]
                    dot = (
                        x * aux[b, m - 1, branch, 2]
                        + y * aux[b, m - 1, branch, 3]
                        + z * aux[b, m - 1, branch, 4]
                    )
                    if dot <= 0.0:
                        note_switch(rep, val, sw, m, int(WRIST), int(NO_JOINT), 0.0)
            note_minima(mag[0], ok, int(SHOULDER), rep, val, sw)
            note_minima(mag[1], ok, int(ELBOW), rep, val, sw)
            note_minima(mag[2], ok, int(WRIST), rep, val, sw)
            fit_limits(
                path, ok, q_min, q_max, rep, val, windings[b, k], winding[b, k], low, high, offset
            )


@njit(cache=True, error_model="numpy")
def note_minima(
    mag: np.ndarray, ok: np.ndarray, kind: int, rep: np.ndarray, val: np.ndarray, switch: np.ndarray
) -> None:  # pragma: no cover - compiled
    """Kernel: note a switch of ``kind`` where a branch measure mag (M,) has a local minimum
    no larger than its change to a neighbour (it reaches about zero between the poses)."""
    for m in range(1, mag.shape[0] - 1):
        if not (ok[m - 1] and ok[m] and ok[m + 1]):
            continue
        left = mag[m - 1] - mag[m]
        right = mag[m + 1] - mag[m]
        if left >= 0.0 and right >= 0.0 and (left > 0.0 or right > 0.0):
            if mag[m] <= max(left, right):  # reaches ~0 between poses
                at = m + 1 if left > right else m
                note_switch(rep, val, switch, at, int(kind), int(NO_JOINT), 0.0)


@njit(cache=True, error_model="numpy")
def fit_limits(
    path: np.ndarray,
    ok: np.ndarray,
    q_min: np.ndarray,
    q_max: np.ndarray,
    rep: np.ndarray,
    val: np.ndarray,
    windings: np.ndarray,
    winding: np.ndarray,
    low: np.ndarray,
    high: np.ndarray,
    offset: np.ndarray,
) -> None:  # pragma: no cover - compiled
    """Kernel: shift each joint of a continuous path (M, n) in place by the multiple of 2π
    that centres it in the limits, count its windings (n,) and keep the one of largest
    margin, and complete the branch's report (margin, first pose outside, first problem).

    low and high (n,) are the smallest and largest joint values of the reached poses;
    offset (n,) is scratch.
    """
    n_poses, n = path.shape
    two_pi = 2.0 * math.pi
    margin = np.inf
    for j in range(n):
        centre = ((q_min[j] + q_max[j]) - (low[j] + high[j])) / (2.0 * two_pi)
        best = 0.0
        best_margin = -np.inf
        for up in range(2):
            shift = math.floor(centre) + up
            room = min(low[j] + two_pi * shift - q_min[j], q_max[j] - high[j] - two_pi * shift)
            if room > best_margin:
                best_margin = room
                best = shift
        offset[j] = two_pi * best
        margin = min(margin, best_margin)
        lowest = math.ceil((q_min[j] - low[j]) / two_pi)
        highest = math.floor((q_max[j] - high[j]) / two_pi)
        if highest >= lowest:
            windings[j] = highest - lowest + 1
            winding[j] = int(best) - lowest
    for m in range(n_poses):
        for j in range(n):
            path[m, j] += offset[j]
    val[F_MARGIN] = margin
    if margin < 0.0:
        for m in range(n_poses):
            if not ok[m]:
                continue
            for j in range(n):
                if path[m, j] < q_min[j] or path[m, j] > q_max[j]:
                    rep[I_LIMIT] = m
                    rep[I_LIMIT_JOINT] = j
                    val[F_VALUE] = path[m, j]
                    break
            if rep[I_LIMIT] >= 0:
                break
    first_problem = n_poses
    for index in (I_UNREACH, I_SWITCH, I_LIMIT):
        if rep[index] >= 0:
            first_problem = min(first_problem, rep[index])
    rep[I_FIRST] = first_problem if first_problem < n_poses else -1


NO_JOINT = -1
"""``joint`` of a switch that is not a joint's jump."""


@njit(cache=True, error_model="numpy")
def note_switch(
    rep: np.ndarray, val: np.ndarray, switch: np.ndarray, m: int, kind: int, joint: int, step: float
) -> None:  # pragma: no cover - compiled
    """Kernel: record a switch at pose m in one branch's report.

    Its callers pass ``kind`` and ``joint`` through ``int()`` (as :func:`note_minima`'s pass
    ``kind``): a constant argument would compile a version of it per value.
    """
    if not switch[m]:
        switch[m] = True
        rep[I_N_SWITCH] += 1
    first = rep[I_SWITCH]
    if first < 0 or m < first or (m == first and rep[I_KIND] == JUMP and kind != JUMP):
        rep[I_SWITCH] = m  # the earliest switch; at one pose a singularity explains a jump
        rep[I_KIND] = kind
        rep[I_JOINT] = joint
        val[F_STEP] = step
