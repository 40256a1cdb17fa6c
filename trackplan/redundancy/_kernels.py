"""Compiled kernel of the free parameter's dynamic programming."""

from __future__ import annotations

import math

import numpy as np
from numba import njit


@njit(cache=True, error_model="numpy")
def cheapest_sequences(
    q: np.ndarray,
    usable: np.ndarray,
    q_min: np.ndarray,
    q_max: np.ndarray,
    stages: np.ndarray,
    constants: np.ndarray,
    reach: np.ndarray,
    weights: np.ndarray,
    path: np.ndarray,
    found: np.ndarray,
) -> None:  # pragma: no cover - compiled
    """Kernel: per candidate and branch, the cheapest sequence of the constants over the
    stage boundaries (:func:`trackplan.redundancy.choose._cheapest_sequence`).

    Parameters
    ----------
    q
        Joint paths at each constant, shape (B·R, K, M, n), rad (row b·R + r).
    usable
        Reached and not switching, shape (B·R, K, M), bool.
    q_min, q_max
        Joint limits, shape (n,), rad.
    stages
        Grid poses at the stage boundaries, shape (S + 1,), increasing.
    constants
        The R values of the parameter, shape (R,), rad.
    reach
        Largest parameter step between consecutive boundaries, shape (S,), rad.
    weights
        Travel weight per joint, shape (n,).
    path
        Output: the chosen constant's index at each boundary, shape (B, K, S + 1).
    found
        Output: a sequence of usable states exists, shape (B, K).
    """
    n_rows, n_k, n_poses, n = q.shape
    n_const = constants.shape[0]
    n_cand = n_rows // n_const
    n_stage = stages.shape[0]
    two_pi = 2.0 * math.pi
    edges = np.empty(n_stage + 1, dtype=np.int64)
    edges[0] = 0
    for i in range(1, n_stage):
        edges[i] = (stages[i] + stages[i - 1] + 1) // 2
    edges[n_stage] = n_poses
    state_ok = np.empty((n_stage, n_const), dtype=np.bool_)
    cost = np.empty(n_const)
    total = np.empty(n_const)
    came = np.empty((n_stage, n_const), dtype=np.int64)
    for b in range(n_cand):
        for k in range(n_k):
            for r in range(n_const):
                row = b * n_const + r
                for i in range(n_stage):
                    ok = True
                    for m in range(edges[i], edges[i + 1]):
                        if not usable[row, k, m]:
                            ok = False
                            break
                        for j in range(n):
                            value = q[row, k, m, j]
                            if not (q_min[j] <= value <= q_max[j]):
                                ok = False
                                break
                        if not ok:
                            break
                    state_ok[i, r] = ok
            for r in range(n_const):
                cost[r] = 0.0 if state_ok[0, r] else np.inf
            for i in range(1, n_stage):
                for r in range(n_const):
                    best = np.inf
                    arg = 0
                    row = b * n_const + r
                    for p in range(n_const):
                        if cost[p] == np.inf or abs(constants[r] - constants[p]) > reach[i - 1]:
                            continue
                        prev = b * n_const + p
                        moved = 0.0
                        for j in range(n):
                            d = q[row, k, stages[i], j] - q[prev, k, stages[i - 1], j]
                            d = abs((d + math.pi) % two_pi - math.pi)
                            moved += weights[j] * d
                        if cost[p] + moved < best:
                            best = cost[p] + moved
                            arg = p
                    came[i, r] = arg
                    total[r] = best if state_ok[i, r] else np.inf
                for r in range(n_const):
                    cost[r] = total[r]
            state = 0
            for r in range(1, n_const):
                if cost[r] < cost[state]:
                    state = r
            found[b, k] = cost[state] < np.inf
            path[b, k, n_stage - 1] = state
            for i in range(n_stage - 1, 0, -1):
                state = came[i, state]
                path[b, k, i - 1] = state
