"""Compiled kernels the smooth law runs along its path and samples.

:func:`level_runs` merges the windows where one limit rules
(:class:`trackplan.timing.zones.ZonePlanner`), :func:`local_caps` gives the zones' local
speed caps (:mod:`trackplan.timing.demand`), :func:`rate_ratios` checks the samples' joint
rates (:mod:`trackplan.timing.sample_checks`) and :func:`profile_position` evaluates a
speed profile at the samples (:meth:`~trackplan.timing.profile.SpeedProfile.position`).
Each runs in the same order of operations as the numpy statement it replaces, so results
agree to round-off. The speed-change sizing kernels are in :mod:`trackplan.timing._kernels`.
"""

from __future__ import annotations

import numpy as np
from numba import njit


@njit(cache=True)
def _runs(level: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """First and last index of each run of equal values, each shape (R,)."""
    n_runs = 1
    for k in range(1, level.size):
        if level[k] != level[k - 1]:
            n_runs += 1
    starts = np.empty(n_runs, dtype=np.int64)
    ends = np.empty(n_runs, dtype=np.int64)
    starts[0] = 0
    r = 0
    for k in range(1, level.size):
        if level[k] != level[k - 1]:
            ends[r] = k - 1
            r += 1
            starts[r] = k
    ends[r] = level.size - 1
    return starts, ends


@njit(cache=True)
def level_runs(s: np.ndarray, level: np.ndarray, shortest: float) -> tuple[np.ndarray, np.ndarray]:
    """Runs of equal speed level along a zone's grid, runs under ``shortest`` merged.

    The shortest run under ``shortest`` (m) joins its slower neighbour (the higher level;
    the earlier one on a tie); when it is itself the slowest, that neighbour slows down
    to it. Repeated until no run is short or one run is left.

    Parameters
    ----------
    s
        Grid, shape (G,), m, increasing (G ≥ 1).
    level
        Speed level of each grid point, shape (G,), int (higher is slower).
    shortest
        Shortest run kept, m.

    Returns
    -------
    tuple of numpy.ndarray
        First and last grid index of each run, each shape (R,).
    """
    level = level.copy()
    while True:
        starts, ends = _runs(level)
        if starts.size == 1:
            return starts, ends
        k = -1
        for r in range(starts.size):
            length = s[ends[r]] - s[starts[r]]
            if length < shortest and (k < 0 or length < s[ends[k]] - s[starts[k]]):
                k = r
        if k < 0:
            return starts, ends
        own = level[starts[k]]
        slower = k - 1 if k > 0 else k + 1
        if k + 1 < starts.size and level[starts[k + 1]] > level[starts[slower]]:
            slower = k + 1
        if level[starts[slower]] >= own:
            level[starts[k] : ends[k] + 1] = level[starts[slower]]
        else:
            level[starts[slower] : ends[slower] + 1] = own


@njit(cache=True)
def local_caps(
    q1: np.ndarray, q2: np.ndarray, q3: np.ndarray, rooms: np.ndarray
) -> np.ndarray:  # pragma: no cover - compiled
    """Highest constant speed the joint limits allow at each grid point, m/s.

    :meth:`~trackplan.timing.demand.ZoneDemand.local_caps`: per point the least of
    ``room / |q'|``, ``√(room / |q''|)`` and ``∛(room / |q'''|)`` over the joints (+inf where
    a demand is not positive), NaN propagated as numpy's ``min`` and ``minimum``. The square
    root is taken of the least ratio (a correctly rounded root keeps the order: the same
    value); the cube root of the ratios within 1e-12 of the least (libm's cube root is
    within an ulp, not correctly rounded: the least of these is the least of all).

    Parameters
    ----------
    q1, q2, q3
        |q'|, |q''|, |q'''| at the grid, shape (G, n) each.
    rooms
        The share of the velocity, acceleration and jerk limits, shape (3, n).

    Returns
    -------
    numpy.ndarray
        Shape (G,), m/s.
    """
    n_rows, n = q1.shape
    out = np.empty(n_rows)
    least = np.empty(3)
    ratio = np.empty(n)
    for g in range(n_rows):
        for order in range(3):
            d = q1 if order == 0 else (q2 if order == 1 else q3)
            best = np.inf
            for j in range(n):
                demand = d[g, j]
                ratio[j] = rooms[order, j] / demand if demand > 0 else np.inf
                if ratio[j] < best or (ratio[j] != ratio[j] and best == best):
                    best = ratio[j]
            if order == 1:
                best = np.sqrt(best)
            elif order == 2 and best == best:
                near = best * (1.0 + 1e-12)
                best = np.inf
                for j in range(n):
                    if ratio[j] <= near:
                        best = min(best, np.cbrt(ratio[j]))
            least[order] = best
        cap = least[0]
        for order in (1, 2):
            root = least[order]
            cap = cap if (cap < root or cap != cap) else root
        out[g] = cap
    return out


@njit(cache=True)
def rate_ratios(q: np.ndarray, steps: np.ndarray, limits: np.ndarray) -> np.ndarray:
    """Largest joint velocity, acceleration and jerk over their limits, per sample.

    Backward differences at rest before the first sample and for the three samples after
    the last, as :func:`trackplan.derivatives.backward_derivatives` with ``pad_end``
    computes them (same differences, same order of operations). Joint by joint over a
    padded copy of its column, so that the loop over the samples runs in SIMD lanes.

    Parameters
    ----------
    q
        Joint positions, shape (N, n), rad (N ≥ 1).
    steps
        ``Ts, Ts², Ts³``, shape (3,).
    limits
        The velocity, acceleration and jerk each ratio is taken against, shape (3, n).

    Returns
    -------
    numpy.ndarray
        Shape (N + 3, 3): max over the joints of ``|derivative| / limit``, per order (a
        column-major view: each order's ratios are contiguous).
    """
    n_samples, n_dof = q.shape
    rows = n_samples + 3
    out = np.zeros((3, rows))
    column = np.empty(rows + 3)  # a joint's positions, three rest samples before and after
    ts1, ts2, ts3 = steps[0], steps[1], steps[2]
    velocity, acceleration, jerk = out[0], out[1], out[2]
    for i in range(n_dof):
        for r in range(3):
            column[r] = q[0, i]
            column[n_samples + 3 + r] = q[n_samples - 1, i]
        for r in range(n_samples):
            column[r + 3] = q[r, i]
        v_limit, a_limit, j_limit = limits[0, i], limits[1, i], limits[2, i]
        for r in range(rows):  # row r: the differences ending at padded row r + 3
            p0 = column[r]
            p1 = column[r + 1]
            p2 = column[r + 2]
            p3 = column[r + 3]
            first_a = p1 - p0
            first_b = p2 - p1
            first_c = p3 - p2
            second_b = first_c - first_b
            second_a = first_b - first_a
            third = second_b - second_a
            velocity[r] = max(velocity[r], abs(first_c / ts1) / v_limit)
            acceleration[r] = max(acceleration[r], abs(second_b / ts2) / a_limit)
            jerk[r] = max(jerk[r], abs(third / ts3) / j_limit)
    return out.T


@njit(cache=True)
def profile_position(
    t_start: np.ndarray,
    s0: np.ndarray,
    v0: np.ndarray,
    a0: np.ndarray,
    jerk: np.ndarray,
    length: float,
    t: np.ndarray,
) -> np.ndarray:
    """Path position of a constant-jerk profile at times ``t`` (N,), clipped to
    [0, length], shape (N,), m (:meth:`~trackplan.timing.profile.SpeedProfile.position`).

    Each time's phase is ``searchsorted(t_start, t, "right") - 1``, clipped: for times in
    order (a plan's samples) by walking on from the previous time's count, else (the first
    time, a time before the previous one, NaN) by binary search.
    """
    out = np.empty(t.size)
    last = t_start.size - 1
    count = 0  # phases starting at or before the time: searchsorted(t_start, t, "right")
    for r in range(t.size):
        if r > 0 and t[r] >= t[r - 1]:
            while count <= last and t_start[count] <= t[r]:
                count += 1
        else:
            count = np.searchsorted(t_start, t[r], side="right")
        k = min(max(count - 1, 0), last)
        tau = t[r] - t_start[k]
        value = s0[k] + v0[k] * tau + a0[k] * (tau * tau) / 2.0 + jerk[k] * tau**3.0 / 6.0
        out[r] = min(max(value, 0.0), length)
    return out
