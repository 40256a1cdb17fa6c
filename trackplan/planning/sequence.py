"""The order and direction in which to run a part's seams (``docs/seams.md``).

A sequence visits every seam once, each forward (as written) or reversed (only where the
seam allows it). Its cost is the cost of starting at the first seam's start, running each
seam in its direction, moving from each seam's end to the next seam's start, and returning
from the last seam's end:

``start[s_1] + Σ_k seam[s_k] + Σ_k air[s_k, s_k+1] + end[s_m]``

with ``s_k = (seam, direction)``. The costs are whatever the caller minimises (cycle time
from :func:`~trackplan.timing.airmove.air_time_estimate`, or a weighted objective).

:func:`best_sequence` is exact for up to ``exact_up_to`` seams: Held-Karp dynamic
programming over (set of seams done, last seam, its direction), ``O(2^m m² 4)`` operations,
one numpy step per set size and next seam. Above that it uses a deterministic heuristic
(:func:`best_sequence`'s notes).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

EXACT_UP_TO = 8
"""Largest number of seams :func:`best_sequence` solves exactly by default."""
LOCAL_SEARCH_STARTS = 4
"""Nearest-neighbour tours (the cheapest ones) the heuristic improves, besides the given order."""
OR_OPT_BLOCK = 3
"""Longest block of consecutive visits the heuristic moves in one step."""


@dataclass(frozen=True)
class Visit:
    """One seam in a sequence.

    Attributes
    ----------
    seam
        Index of the seam, 0-based, in the order written.
    reversed
        True when the seam runs from its end to its start.
    """

    seam: int
    reversed: bool


@dataclass(frozen=True)
class Sequence:
    """An order and direction for every seam.

    Attributes
    ----------
    visits
        The seams in the order they run, each once.
    cost
        The sequence's cost (see the module) under the costs it was chosen with; NaN for
        :func:`given_sequence`, which is chosen without costs (:func:`sequence_cost`
        evaluates any sequence).
    exact
        True when the sequence is proven optimal for those costs (dynamic programming).
    """

    visits: tuple[Visit, ...]
    cost: float
    exact: bool


def given_sequence(m: int) -> Sequence:
    """The seams in the order written, each forward.

    Parameters
    ----------
    m
        Number of seams.

    Returns
    -------
    Sequence
        ``cost`` NaN (not evaluated), ``exact`` False.
    """
    return Sequence(tuple(Visit(i, False) for i in range(m)), math.nan, False)


def sequence_cost(
    visits: tuple[Visit, ...],
    seam_cost: np.ndarray,
    air_cost: np.ndarray,
    start_cost: np.ndarray,
    end_cost: np.ndarray,
) -> float:
    """The cost of a sequence (see the module); arguments as :func:`best_sequence`."""
    states = np.array([[2 * v.seam + int(v.reversed) for v in visits]])
    costs = _Costs.from_arrays(seam_cost, air_cost, start_cost, end_cost, None)
    return float(costs.tour_cost(states)[0])


def best_sequence(
    seam_cost: np.ndarray,
    air_cost: np.ndarray,
    start_cost: np.ndarray,
    end_cost: np.ndarray,
    reversible: np.ndarray,
    *,
    exact_up_to: int = EXACT_UP_TO,
) -> Sequence:
    """The cheapest order and direction of ``m`` seams.

    Parameters
    ----------
    seam_cost
        Shape (m, 2): cost of seam ``i`` run forward (``[i, 0]``) and reversed (``[i, 1]``).
    air_cost
        Shape (m, 2, m, 2): cost from the end of seam ``i`` run in direction ``d`` to the
        start of seam ``j`` run in direction ``e`` (``[i, d, j, e]``).
    start_cost
        Shape (m, 2): cost from the start (home) to the start of each seam and direction;
        zeros when there is no home.
    end_cost
        Shape (m, 2): cost from the end of each seam and direction back home; zeros when
        there is no home.
    reversible
        Shape (m,), bool: seams that may run reversed; the others only run forward.
    exact_up_to
        Largest ``m`` solved exactly.

    Returns
    -------
    Sequence
        The order with the least cost; ``exact`` tells whether it is proven optimal.

    Raises
    ------
    ValueError
        When the shapes disagree or a cost is not finite.

    Notes
    -----
    Up to ``exact_up_to`` seams: Held-Karp dynamic programming, exact. Above: a nearest
    neighbour tour from every allowed first (seam, direction); the
    :data:`LOCAL_SEARCH_STARTS` cheapest of them and the given order are then improved by
    steepest descent over one neighbourhood until no move lowers the cost: flipping one
    seam, reversing a stretch of the order (2-opt; with and without flipping the seams in
    it), and moving a block of up to :data:`OR_OPT_BLOCK` visits elsewhere (or-opt; as is
    or reversed). The result is never worse than the given order. Deterministic: ties go to
    the lowest index.
    """
    costs = _Costs.from_arrays(seam_cost, air_cost, start_cost, end_cost, reversible)
    if costs.m <= exact_up_to:
        states, cost = _held_karp(costs)
        exact = True
    else:
        states, cost = _heuristic(costs)
        exact = False
    visits = tuple(Visit(int(s) // 2, bool(s % 2)) for s in states)
    return Sequence(visits, float(cost), exact)


@dataclass(frozen=True, eq=False)
class _Costs:
    """The costs over states ``s = 2 · seam + direction`` (S = 2m of them).

    ``first[s]``: start plus seam; ``step[a, b]``: air from ``a`` plus seam ``b``;
    ``last[s]``: back home. Disallowed states cost infinity.
    """

    m: int
    first: np.ndarray  # (S,)
    step: np.ndarray  # (S, S)
    last: np.ndarray  # (S,)
    reversible: np.ndarray  # (m,) bool

    @classmethod
    def from_arrays(
        cls,
        seam_cost: np.ndarray,
        air_cost: np.ndarray,
        start_cost: np.ndarray,
        end_cost: np.ndarray,
        reversible: np.ndarray | None,
    ) -> _Costs:
        seam = np.asarray(seam_cost, dtype=float)
        m = len(seam)
        air = np.asarray(air_cost, dtype=float)
        start = np.asarray(start_cost, dtype=float)
        end = np.asarray(end_cost, dtype=float)
        rev = np.ones(m, bool) if reversible is None else np.asarray(reversible, dtype=bool)
        shapes = {
            "seam_cost": (seam.shape, (m, 2)),
            "air_cost": (air.shape, (m, 2, m, 2)),
            "start_cost": (start.shape, (m, 2)),
            "end_cost": (end.shape, (m, 2)),
            "reversible": (rev.shape, (m,)),
        }
        for name, (shape, expected) in shapes.items():
            if shape != expected:
                raise ValueError(f"sequencing: {name} has shape {shape}, expected {expected}")
        if m == 0:
            raise ValueError("sequencing: no seams")
        if not all(np.isfinite(x).all() for x in (seam, air, start, end)):
            raise ValueError("sequencing: every cost must be finite")
        n_states = 2 * m
        allowed = np.ones((m, 2), bool)
        allowed[:, 1] = rev
        blocked = np.where(allowed.reshape(n_states), 0.0, np.inf)
        seam_s = seam.reshape(n_states) + blocked
        return cls(
            m=m,
            first=start.reshape(n_states) + seam_s,
            step=air.reshape(n_states, n_states) + seam_s[None, :],
            last=end.reshape(n_states) + blocked,
            reversible=rev,
        )

    def tour_cost(self, states: np.ndarray) -> np.ndarray:
        """Cost of tours given as states, shape (C, m) -> (C,)."""
        inner = self.step[states[:, :-1], states[:, 1:]].sum(axis=1)
        cost: np.ndarray = self.first[states[:, 0]] + inner + self.last[states[:, -1]]
        return cost


def _held_karp(costs: _Costs) -> tuple[np.ndarray, float]:
    """Exact: ``best[mask, s]`` is the least cost of running the seams in ``mask`` and
    ending in state ``s`` (whose seam is in ``mask``); shape (2^m, 2m)."""
    m = costs.m
    n_states = 2 * m
    n_masks = 1 << m
    seam_of = np.arange(n_states) // 2
    best = np.full((n_masks, n_states), np.inf)
    parent = np.full((n_masks, n_states), -1, dtype=np.int64)
    single = 1 << seam_of
    best[single, np.arange(n_states)] = costs.first
    masks = np.arange(n_masks)
    size = np.zeros(n_masks, dtype=np.int64)
    for i in range(m):
        size += (masks >> i) & 1
    for k in range(1, m):
        layer = masks[size == k]
        # cheapest way into every state from every set of size k: (K, S)
        through = best[layer][:, :, None] + costs.step[None, :, :]
        previous = through.argmin(axis=1)
        value = np.take_along_axis(through, previous[:, None, :], axis=1)[:, 0, :]
        for j in range(m):
            free = ((layer >> j) & 1) == 0
            target = layer[free] | (1 << j)
            # each target set is reached with seam j last from exactly one set of size k
            best[target, 2 * j : 2 * j + 2] = value[free, 2 * j : 2 * j + 2]
            parent[target, 2 * j : 2 * j + 2] = previous[free, 2 * j : 2 * j + 2]
    full = n_masks - 1
    total = best[full] + costs.last
    state = int(total.argmin())
    cost = float(total[state])
    order = []
    mask = full
    while state >= 0:
        order.append(state)
        state, mask = int(parent[mask, state]), mask ^ (1 << (state // 2))
    return np.array(order[::-1]), cost


def _heuristic(costs: _Costs) -> tuple[np.ndarray, float]:
    """Nearest neighbour from every start, then local search (see :func:`best_sequence`)."""
    tours = _nearest_neighbour(costs)
    tour_costs = costs.tour_cost(tours)
    picked = np.argsort(tour_costs, kind="stable")[:LOCAL_SEARCH_STARTS]
    given = 2 * np.arange(costs.m)
    moves = _moves(costs.m)
    best_tour, best_cost = given, math.inf
    for tour in [given, *tours[picked]]:
        tour, cost = _local_search(costs, tour, moves)
        if cost < best_cost:
            best_tour, best_cost = tour, cost
    return best_tour, best_cost


def _nearest_neighbour(costs: _Costs) -> np.ndarray:
    """A greedy tour from every allowed first state, shape (C, m) of states."""
    n_states = 2 * costs.m
    starts = np.flatnonzero(np.isfinite(costs.first))
    seam_of = np.arange(n_states) // 2
    tours = np.empty((len(starts), costs.m), dtype=np.int64)
    tours[:, 0] = starts
    done = np.zeros((len(starts), costs.m), bool)
    rows = np.arange(len(starts))
    done[rows, seam_of[starts]] = True
    for k in range(1, costs.m):
        # a blocked direction (finite cap) still ranks before a seam already done
        step = np.where(done[:, seam_of], np.inf, np.minimum(costs.step[tours[:, k - 1]], 1e300))
        nxt = step.argmin(axis=1)
        tours[:, k] = nxt
        done[rows, seam_of[nxt]] = True
    return tours


def _moves(m: int) -> tuple[np.ndarray, np.ndarray]:
    """The local-search neighbourhood of a tour of ``m`` visits.

    Returns ``(order, flip)``, each shape (C, m): a neighbour visits the tour's positions
    ``order[c]``, flipping the direction where ``flip[c]`` (if the seam is reversible).
    """
    positions = np.arange(m)
    orders: list[np.ndarray] = []
    flips: list[np.ndarray] = []
    for p in range(m):
        orders.append(positions)
        flips.append(positions == p)
    for i in range(m):
        for k in range(i + 1, m):
            order = np.concatenate([positions[:i], positions[i : k + 1][::-1], positions[k + 1 :]])
            inside = (positions >= i) & (positions <= k)
            orders += [order, order]
            flips += [inside, np.zeros(m, bool)]
    for length in range(1, min(OR_OPT_BLOCK, m - 1) + 1):
        for i in range(m - length + 1):
            block = positions[i : i + length]
            rest = np.concatenate([positions[:i], positions[i + length :]])
            for t in range(len(rest) + 1):
                if t == i:
                    continue
                for backwards in (False, True):
                    moved = block[::-1] if backwards else block
                    orders.append(np.concatenate([rest[:t], moved, rest[t:]]))
                    flip = np.zeros(m, bool)
                    flip[t : t + length] = backwards
                    flips.append(flip)
    return np.array(orders), np.array(flips)


def _local_search(
    costs: _Costs, tour: np.ndarray, moves: tuple[np.ndarray, np.ndarray]
) -> tuple[np.ndarray, float]:
    """Steepest descent over the neighbourhood until no move lowers the cost."""
    order, flip = moves
    cost = float(costs.tour_cost(tour[None, :])[0])
    while True:
        states = tour[order]
        seams = states // 2
        states = states ^ (flip & costs.reversible[seams])
        candidate = costs.tour_cost(states)
        best = int(candidate.argmin())
        if not candidate[best] < cost - 1e-12 * max(abs(cost), 1.0):
            return tour, cost
        tour, cost = states[best], float(candidate[best])
