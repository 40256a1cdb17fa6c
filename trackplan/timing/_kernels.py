"""Compiled kernels of the smooth law's speed-change sizing (:mod:`trackplan.timing.demand`).

The plateau search and the speed-change search evaluate the same few formulas hundreds of
times per plan on small arrays (tens of speeds or candidate bounds, six joints), where numpy's
per-call cost dominates. These kernels compute them in one pass, in the same order of
operations as the numpy reference functions of :mod:`trackplan.timing.demand`
(:func:`~trackplan.timing.demand.uniform_change_bounds_many`,
:func:`~trackplan.timing.demand.change_distances`,
:meth:`~trackplan.timing.demand.ZoneDemand.stretch_peaks`), so results agree to round-off.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

MAX_PATH_ACCELERATION = 50.0
"""Upper bound on |s̈|, m/s², where no joint bounds it (a joint path that does not move)."""
MAX_PATH_JERK = 5000.0
"""Upper bound on |s⃛|, m/s³, likewise."""


@njit(cache=True)
def change_bounds(
    q1: np.ndarray,
    q2: np.ndarray,
    q3: np.ndarray,
    top: float,
    a_limit: np.ndarray,
    j_limit: np.ndarray,
) -> tuple[float, float]:
    """Path acceleration and jerk bounds at one top speed, m/s² and m/s³.

    :func:`~trackplan.timing.demand.uniform_change_bounds` for peaks ``q1, q2, q3`` (n,)
    and the shares of the joint limits ``a_limit, j_limit`` (n,).
    """
    accel_ratio = np.inf
    coupling_ratio = np.inf
    for i in range(q1.size):
        accel_room = a_limit[i] - q2[i] * (top * top)
        jerk_room = j_limit[i] - q3[i] * top**3.0
        coupling = 3.0 * q2[i] * top
        if q1[i] > 0.0:
            accel_ratio = min(accel_ratio, accel_room / q1[i])
        if coupling > 0.0:
            coupling_ratio = min(coupling_ratio, 0.5 * jerk_room / coupling)
    accel = min(min(accel_ratio, coupling_ratio), MAX_PATH_ACCELERATION)
    jerk = np.inf
    for i in range(q1.size):
        if q1[i] > 0.0:
            jerk_room = j_limit[i] - q3[i] * top**3.0
            jerk = min(jerk, (jerk_room - 3.0 * q2[i] * top * accel) / q1[i])
    return accel, min(jerk, MAX_PATH_JERK)


@njit(cache=True)
def _distance(v_from: float, v_to: float, accel: float, jerk: float) -> float:
    """Length of one jerk-limited speed change (``change_distances``), m."""
    delta = abs(v_to - v_from)
    if delta == 0.0:
        return 0.0
    if not (accel > 0.0 and jerk > 0.0):
        return np.inf
    if delta * jerk >= accel * accel:
        time = delta / accel + accel / jerk
    else:
        time = 2.0 * math.sqrt(delta / jerk)
    return 0.5 * (v_from + v_to) * time


@njit(cache=True)
def quick_distances(
    s: np.ndarray,
    peaks: np.ndarray,
    running: np.ndarray,
    v_from: np.ndarray,
    v_to: np.ndarray,
    rise: bool,
    length: float,
    a_limit: np.ndarray,
    j_limit: np.ndarray,
) -> np.ndarray:
    """Distances of speed changes under bounds valid over their stretch of a zone, m.

    Parameters
    ----------
    s
        The zone's grid, shape (G,), m, increasing (G ≥ 1).
    peaks
        Largest |q'|, |q''|, |q'''| over the zone, shape (3, n).
    running
        Running maxima from the zone start (``rise``) or from its end, shape (G, 3, n).
    v_from, v_to
        Speeds before and after, shape (V,), m/s.
    rise
        True when the changes start at the zone start, False when they end at its end.
    length
        The zone's length, m.
    a_limit, j_limit
        Share of the joint acceleration and jerk limits, shape (n,).

    Returns
    -------
    numpy.ndarray
        Shape (V,), m (inf where the joints leave no room).
    """
    n_grid = s.size
    out = np.empty(v_from.size)
    for k in range(v_from.size):
        top = max(v_from[k], v_to[k])
        accel, jerk = change_bounds(peaks[0], peaks[1], peaks[2], top, a_limit, j_limit)
        distance = _distance(v_from[k], v_to[k], accel, jerk)
        if not (np.isfinite(distance) and distance < length):
            out[k] = distance
            continue
        stretch = min(distance, length)
        if rise:
            row = np.searchsorted(s, s[0] + stretch, side="left") + 2
            row = min(max(row, 1), n_grid) - 1
        else:
            row = np.searchsorted(s, s[-1] - stretch, side="right") - 2
            row = min(max(row, 0), n_grid - 1)
        local = running[row]
        local_accel, local_jerk = change_bounds(local[0], local[1], local[2], top, a_limit, j_limit)
        out[k] = _distance(v_from[k], v_to[k], max(accel, local_accel), max(jerk, local_jerk))
    return out


@njit(cache=True)
def changes_within_limits(
    s: np.ndarray,
    d1: np.ndarray,
    d2: np.ndarray,
    d3: np.ndarray,
    s_start: float,
    s_end: float,
    v_from: float,
    v_to: float,
    at_start: bool,
    a_limit: np.ndarray,
    j_limit: np.ndarray,
    accel: np.ndarray,
    jerk: np.ndarray,
    u: np.ndarray,
) -> tuple[np.ndarray, np.ndarray]:
    """Which candidate speed changes meet the joint limits along their own stretch.

    Parameters
    ----------
    s
        The zone's grid, shape (G,), m, increasing (G ≥ 2).
    d1, d2, d3
        Signed q', q'', q''' on the grid, shape (G, n).
    s_start, s_end
        The zone, m.
    v_from, v_to
        Speeds before and after, m/s (different).
    at_start
        True when the changes start at ``s_start``, False when they end at ``s_end``.
    a_limit, j_limit
        Share of the joint acceleration and jerk limits, shape (n,).
    accel, jerk
        Candidate bounds, shape (K,), m/s² and m/s³.
    u
        Check points in each constant-jerk phase, as shares of it, shape (P,).

    Returns
    -------
    ok : numpy.ndarray
        Shape (K,), bool.
    distance : numpy.ndarray
        Path length of each change, shape (K,), m.
    """
    n_grid, n_dof = d1.shape
    delta = abs(v_to - v_from)
    sign = 1.0 if v_to > v_from else -1.0
    ok = np.empty(accel.size, dtype=np.bool_)
    distance = np.empty(accel.size)
    for k in range(accel.size):
        a_k, j_k = accel[k], jerk[k]
        full = delta * j_k >= a_k * a_k
        peak = a_k if full else math.sqrt(delta * j_k)
        t_jerk = peak / j_k
        t_hold = delta / a_k - t_jerk if full else 0.0
        distance[k] = 0.5 * (v_from + v_to) * (2 * t_jerk + t_hold)
        v1 = v_from + sign * 0.5 * j_k * t_jerk**2
        v2 = v1 + sign * peak * t_hold
        s1 = v_from * t_jerk + sign * j_k * t_jerk**3.0 / 6.0
        s2 = s1 + v1 * t_hold + sign * peak * t_hold**2 / 2.0
        origin = s_start if at_start else s_end - distance[k]
        ok[k] = True
        for phase in range(3):
            if phase == 0:
                duration, j, a0, v0, p0 = t_jerk, sign * j_k * 1.0, 0.0, v_from, 0.0
            elif phase == 1:
                duration, j, a0, v0, p0 = t_hold, sign * j_k * 0.0, sign * peak, v1, s1
            else:
                duration, j, a0, v0, p0 = t_jerk, sign * j_k * -1.0, sign * peak, v2, s2
            for p in range(u.size):
                tau = duration * u[p]
                a = a0 + j * tau
                v = v0 + a0 * tau + j * tau**2 / 2.0
                where = p0 + v0 * tau + a0 * tau**2 / 2 + j * tau**3.0 / 6
                where = min(max(origin + where, s_start), s_end)
                row = np.searchsorted(s, where, side="right") - 1
                row = min(max(row, 0), n_grid - 2)
                span = s[row + 1] - s[row]
                w = (where - s[row]) / (span if span > 0 else 1.0)
                w = min(max(w, 0.0), 1.0)
                for i in range(n_dof):
                    q1 = d1[row, i] + w * (d1[row + 1, i] - d1[row, i])
                    q2 = d2[row, i] + w * (d2[row + 1, i] - d2[row, i])
                    q3 = d3[row, i] + w * (d3[row + 1, i] - d3[row, i])
                    joint_accel = abs(q1 * a + q2 * v * v) / a_limit[i]
                    joint_jerk = abs(q1 * j + 3.0 * q2 * v * a + q3 * v**3.0) / j_limit[i]
                    if not (joint_accel <= 1.0 and joint_jerk <= 1.0):
                        ok[k] = False
                        break
                if not ok[k]:
                    break
            if not ok[k]:
                break
    return ok, distance


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
def rate_ratios(q: np.ndarray, steps: np.ndarray, limits: np.ndarray) -> np.ndarray:
    """Largest joint velocity, acceleration and jerk over their limits, per sample.

    Backward differences at rest before the first sample and for the three samples after
    the last, as :func:`trackplan.derivatives.backward_derivatives` with ``pad_end``
    computes them (same differences, same order of operations).

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
        Shape (N + 3, 3): max over the joints of ``|derivative| / limit``, per order.
    """
    n_samples, n_dof = q.shape
    out = np.zeros((n_samples + 3, 3))
    for r in range(n_samples + 3):
        for i in range(n_dof):
            p0 = q[min(max(r - 3, 0), n_samples - 1), i]
            p1 = q[min(max(r - 2, 0), n_samples - 1), i]
            p2 = q[min(max(r - 1, 0), n_samples - 1), i]
            p3 = q[min(r, n_samples - 1), i]
            first_a = p1 - p0
            first_b = p2 - p1
            first_c = p3 - p2
            second_b = first_c - first_b
            second_a = first_b - first_a
            third = second_b - second_a
            out[r, 0] = max(out[r, 0], abs(first_c / steps[0]) / limits[0, i])
            out[r, 1] = max(out[r, 1], abs(second_b / steps[1]) / limits[1, i])
            out[r, 2] = max(out[r, 2], abs(third / steps[2]) / limits[2, i])
    return out
