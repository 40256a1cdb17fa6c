"""The linear program of the continuous speed curve, in ``x(s) = ṡ²`` over the nodes.

:func:`solve_curve` maximises the time-weighted ``Σ w x`` of one
:class:`~trackplan.timing.curve_nodes.Stretch` under the joint velocity, acceleration and
jerk rows (the jerk linearised under a speed bound ``v̄`` that shrinks round after round:
:data:`FIRST_ROOMS`, :data:`SPEED_ROOMS`), the task's speed caps and the start from and
stop at rest (:func:`_rest_envelope`), with HiGHS's dual simplex through
:func:`scipy.optimize.linprog`. The method is described in
:mod:`trackplan.timing.continuous`.
"""

from __future__ import annotations

import numpy as np

from trackplan.timing.curve_nodes import Stretch, node_steps

SPEED_ROOMS = (1.3, 1.1)
"""How far above the previous round's solution each round after the first may plan the
speed (its jerk bound assumes the speed stays below it): the second round 1.3 ×, the third
1.1 × (the first bounds √x by :data:`FIRST_ROOMS` times the constant-speed cap of the
joints)."""
FIRST_ROOMS = (1.5, 1.0)
"""How far above the constant-speed cap the joints allow (at each node) the first round's
speed may go (its jerk bound assumes the speed stays below it): the first room, and the
next one tried when a solution leaves a node inside the stretch at rest (:data:`RESTING`)."""
SLOW_FLOOR = 0.05
"""Share of the fastest speed below which the objective weighs a node as if it ran at it."""
CRUISE_ROOM = 1.5
"""How far above the speed cap the joints must allow a constant speed for a node to cruise
at its cap without the linear program (see :func:`_cruising`)."""
CRUISE_CLEARANCE = 0.05
"""Distance from any slowed or changing node beyond which a node cruises at its cap, m."""
MAX_DURATION = 2000.0
"""Longest curve sampled, s (the window law's longest, 2 000 000 samples at 1 ms): a curve
that would take longer has (almost) stopped inside a stretch, and the window law stands."""
RESTING = 1e-9
"""Share of the top ``x`` below which a node inside a stretch is at rest: a solution with
such a node is kept only if no later try of :func:`solve_curve` is faster."""
REST_JERK_SHARE = 0.95
"""Share of the path jerk the joints allow that a start from rest or a stop plans with."""
CANCEL_ROOM = 2.0
"""How far the path-jerk term ``√x q' x''/2`` of the joint jerk may pass the jerk limit on
its own, the other terms cancelling the rest (a row of its own in the linear program)."""


def solve_curve(stretch: Stretch, limits: np.ndarray, cap: np.ndarray) -> np.ndarray | None:
    """Node values of ``x = ṡ²`` (G,) maximising the time-weighted ``Σ w x`` under the limits
    (see the module), or None when the linear program fails.

    Parameters
    ----------
    limits
        Joint velocity, acceleration and jerk limits at each node, shape (3, G, n).
    cap
        Speed cap planned at each node, shape (G,), m/s.
    """
    import scipy.sparse as sparse  # scipy's LP stack only where a curve is planned
    from scipy.optimize import linprog

    s, d1, d2, d3 = stretch.s, stretch.d1, stretch.d2, stretch.d3
    count = len(s)
    with np.errstate(divide="ignore"):
        velocity = np.min(limits[0] / np.abs(d1), axis=(0, 2))
    top = np.minimum(np.minimum(cap, velocity) ** 2, _rest_envelope(s, d1, limits[2]))
    k = np.arange(1, count - 1)
    slope, bend = _differences(s)  # x'[k] = slope @ x[k-1:k+2], x''[k] = bend @ ...
    # accel:  q' x'/2 + q'' x
    # jerk:   q' x''/2 + 1.5 q'' x' + q''' x
    q1, q2, q3 = (d[:, k, :, None] for d in (d1, d2, d3))  # (2, m, n, 1)
    centre = np.array([0.0, 1.0, 0.0])
    coefficients = np.stack(
        [
            q1 * slope[:, None] / 2 + q2 * centre,
            q1 * bend[:, None] / 2 + 1.5 * q2 * slope[:, None] + q3 * centre,
        ]
    )  # (2 kinds, 2 sides, m, n, 3 columns)
    columns = np.broadcast_to(
        np.stack([k - 1, k, k + 1], axis=-1)[None, None, :, None, :], coefficients.shape
    )
    # the side after a node repeats the side before it except at zone boundaries
    same = np.all([np.all(d[0, k] == d[1, k], axis=-1) for d in (d1, d2, d3)], axis=0)  # (m,)
    distinct = np.stack([np.ones_like(same), ~same])[None, None, :, :, None]  # (1,1,2,m,1)
    signed = np.stack([coefficients, -coefficients])  # rows ≤ rhs in both directions
    positive = np.maximum(signed, 0.0)
    signed_columns = np.stack([columns, columns])
    # the path-jerk term alone: |q' x''/2| ≤ CANCEL_ROOM q⃛max / v̄ for every joint and side
    # is one row each way per node, |x''/2| ≤ CANCEL_ROOM (lowest q⃛max / |q'|) / v̄
    with np.errstate(divide="ignore"):
        path_jerk = CANCEL_ROOM * np.min(limits[2][k][None] / np.abs(d1[:, k]), axis=(0, 2))
    bend_rows = np.stack([bend / 2, -bend / 2])  # (2 signs, m, 3 columns)
    bend_positive = np.maximum(bend_rows, 0.0)
    bend_columns = np.broadcast_to(np.stack([k - 1, k, k + 1], axis=-1), bend_rows.shape)
    with np.errstate(divide="ignore"):
        steady = np.min(
            np.minimum(np.sqrt(limits[1] / np.abs(d2)), np.cbrt(limits[2] / np.abs(d3))),
            axis=(0, 2),
        )
    cruise = _cruising(s, top, steady)
    solution = best = None
    best_duration = MAX_DURATION
    tries = [(held, room) for room in FIRST_ROOMS for held in _holds(cruise)]
    for held, room in tries:
        # held at the cap first; if that leaves no room for a speed change, everything free
        x = np.minimum(top, (room * steady) ** 2)
        reference = x
        for next_room in (*SPEED_ROOMS, 1.0):
            bound = np.sqrt(x)
            with np.errstate(divide="ignore"):
                jerk = limits[2][k] / np.maximum(bound[k], 1e-9)[:, None]
            rhs = np.stack([np.broadcast_to(limits[1][k], jerk.shape), jerk])[:, None]
            rhs = np.broadcast_to(rhs, signed.shape[:-1])  # (2 signs, 2 kinds, 2 sides, m, n)
            bend_rhs = np.broadcast_to(path_jerk / np.maximum(bound[k], 1e-9), bend_rows.shape[:-1])
            # a row binds only if its largest value for 0 ≤ x ≤ the round's bound passes
            # rhs, and only if it reaches a node that is not held
            keep = distinct & (np.einsum("...c,...c->...", positive, x[signed_columns]) > rhs)
            keep &= ~np.all(held[signed_columns], axis=-1)
            bend_keep = np.einsum("...c,...c->...", bend_positive, x[bend_columns]) > bend_rhs
            bend_keep &= ~np.all(held[bend_columns], axis=-1)
            solution = x
            if keep.any() or bend_keep.any():
                kept = np.concatenate([signed[keep], bend_rows[bend_keep]])
                kept_columns = np.concatenate([signed_columns[keep], bend_columns[bend_keep]])
                matrix = sparse.csr_matrix(
                    (kept.ravel(), (np.repeat(np.arange(len(kept)), 3), kept_columns.ravel())),
                    shape=(len(kept), count),
                )
                result = linprog(
                    -_time_weights(s, reference),
                    A_ub=matrix,
                    b_ub=np.concatenate([rhs[keep], bend_rhs[bend_keep]]),
                    bounds=np.stack([np.where(held, x, 0.0), x], axis=1),
                    method="highs-ds",
                    options={"presolve": False},
                )
                if result.status != 0:
                    solution = None
                    break
                solution = np.clip(result.x, 0.0, x)
            x = np.minimum(top, next_room**2 * solution)
            reference = solution
        if solution is None:
            continue
        duration = node_steps(stretch, np.sqrt(solution)).sum()
        if duration < best_duration:
            best, best_duration = solution, duration
        if duration < MAX_DURATION and solution[1:-1].min() > RESTING * solution.max():
            break
    return best


def _holds(cruise: np.ndarray) -> tuple[np.ndarray, ...]:
    """The nodes held at their cap in turn (G,), bool: the cruising ones, then none."""
    return (cruise, np.zeros_like(cruise)) if cruise.any() else (cruise,)


def _time_weights(s: np.ndarray, reference: np.ndarray) -> np.ndarray:
    """Weights (G,) of the linear program's objective ``Σ w x``: the travel time
    ``∫ ds / √x`` falls by ``Δx · ds / (2 x^1.5)`` when x rises by ``Δx``, so each node
    weighs its share of the path over ``x^1.5`` at the reference ``x`` (the round's bound,
    then the previous solution), floored at :data:`SLOW_FLOOR` of the fastest node's speed so
    that a node at rest still counts. Largest weight 1."""
    length = np.diff(s, prepend=s[0]) + np.diff(s, append=s[-1])
    floor = (SLOW_FLOOR**2) * max(float(reference.max()), 1e-300)
    weights = length / np.maximum(reference, floor) ** 1.5
    normalised: np.ndarray = weights / weights.max()
    return normalised


def _cruising(s: np.ndarray, top: np.ndarray, steady: np.ndarray) -> np.ndarray:
    """Nodes the linear program holds at their bound ``top`` (G,), bool: those farther than
    :data:`CRUISE_CLEARANCE` from any node where ``top`` changes or where the joints allow
    less than :data:`CRUISE_ROOM` times the speed ``√top`` at a constant speed. There the
    curve cruises at its cap (the window plan's plateaus), and the linear program only plans
    the slowed parts and the speed changes around them (if that leaves a speed change too
    little room, :func:`solve_curve` plans again with every node free)."""
    flat = np.ones(len(s), dtype=bool)
    flat[1:-1] = (top[1:-1] == top[:-2]) & (top[1:-1] == top[2:])
    flat[[0, -1]] = False
    busy = s[~(flat & (CRUISE_ROOM**2 * top <= steady**2))]
    if not busy.size:
        return np.ones(len(s), dtype=bool)
    index = np.searchsorted(busy, s)
    after = busy[np.minimum(index, len(busy) - 1)]
    before = busy[np.maximum(index - 1, 0)]
    nearest: np.ndarray = np.minimum(np.abs(after - s), np.abs(s - before))
    return nearest > CRUISE_CLEARANCE


def _differences(s: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Three-point difference weights at the inner nodes of ``s`` (G,): the first and the
    second derivative at node k are the weights (G - 2, 3) times the values at k - 1, k and
    k + 1 (exact for quadratics on any spacing; the central differences on a uniform one)."""
    h1 = np.diff(s)[:-1, None]
    h2 = np.diff(s)[1:, None]
    total = h1 + h2
    slope = np.hstack([-h2 / (h1 * total), (h2 - h1) / (h1 * h2), h1 / (h2 * total)])
    bend = np.hstack([2.0 / (h1 * total), -2.0 / (h1 * h2), 2.0 / (h2 * total)])
    return slope, bend


def _rest_envelope(s: np.ndarray, d1: np.ndarray, jerk: np.ndarray) -> np.ndarray:
    """Bound on ``x = ṡ²`` (G,) near the rests at both ends of a stretch.

    Leaving or reaching a rest at a constant path jerk ``J`` covers ``s = J t³/6`` at
    ``ṡ = J t²/2``, so ``x = (6^(4/3)/4) J^(2/3) s^(4/3)`` at a distance ``s`` from the rest.
    ``J`` is :data:`REST_JERK_SHARE` of the lowest path jerk ``q⃛max / |q'|`` between the rest
    and the node (the rest of the joint jerk is left to the terms in q'' and q'''). The
    linear program's difference quotients cannot see the first interval, where the
    acceleration must grow from zero; this bound shapes it.

    Parameters
    ----------
    s
        Nodes, shape (G,), m.
    d1
        q' before and after each node, shape (2, G, n), rad/m.
    jerk
        Joint jerk limits at each node, shape (G, n), rad/s³.
    """
    with np.errstate(divide="ignore"):
        path_jerk = REST_JERK_SHARE * np.min(jerk / np.abs(d1), axis=(0, 2))
    forward = np.minimum.accumulate(path_jerk)
    backward = np.minimum.accumulate(path_jerk[::-1])[::-1]
    start = 6.0 ** (4.0 / 3.0) / 4.0 * np.cbrt(forward * (s - s[0]) ** 2) ** 2
    end = 6.0 ** (4.0 / 3.0) / 4.0 * np.cbrt(backward * (s[-1] - s) ** 2) ** 2
    envelope: np.ndarray = np.minimum(start, end)
    return envelope
