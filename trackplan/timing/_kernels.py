"""Compiled kernels of the smooth law's speed-change sizing (:mod:`trackplan.timing.demand`).

The plateau search and the speed-change search evaluate the same few formulas hundreds of
times per plan on small arrays (tens of speeds or candidate bounds, six joints), where numpy's
per-call cost dominates. These kernels compute them in one pass, in the same order of
operations as the numpy reference functions of :mod:`trackplan.timing.demand`
(:func:`~trackplan.timing.demand.uniform_change_bounds_many`,
:func:`~trackplan.timing.demand.change_distances`,
:meth:`~trackplan.timing.demand.ZoneDemand.stretch_peaks`), so results agree to round-off.

The smooth law calls two of them per plan, each running a whole loop with the operations
of its numpy statement: :func:`plateau_search` (the plateaus over all zones,
:class:`trackplan.timing.zones.ZonePlanner`) and :func:`change_search` (one speed change,
:func:`~trackplan.timing.demand.speed_change`); the others run inside them. The kernels
that run along the path and its samples are in :mod:`trackplan.timing._kernels_samples`.
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


_RISE, _FALL = True, False
"""``rise`` of :func:`quick_distances`."""


@njit(cache=True)
def _needed(
    z: int,
    v: np.ndarray,
    plateau: np.ndarray,
    lengths: np.ndarray,
    offsets: np.ndarray,
    s: np.ndarray,
    peaks: np.ndarray,
    running_from_start: np.ndarray,
    running_from_end: np.ndarray,
    a_limit: np.ndarray,
    j_limit: np.ndarray,
) -> np.ndarray:
    """Length zone z needs for its rise into and fall out of each plateau of ``v`` (V,), m."""
    n_zones = plateau.size
    before = plateau[z - 1] if z > 0 else 0.0
    after = plateau[z + 1] if z < n_zones - 1 else 0.0
    first, stop = offsets[z], offsets[z + 1]
    total = np.zeros(v.size)
    top = v.max()
    if before < top:  # a rise into some of the speeds (only theirs count)
        rise = quick_distances(
            s[first:stop],
            peaks[z],
            running_from_start[first:stop],
            np.full(v.size, before),
            np.maximum(v, before),
            bool(_RISE),  # not the constant: one compiled version for both calls
            lengths[z],
            a_limit[z],
            j_limit[z],
        )
        for k in range(v.size):
            total[k] += rise[k] if before < v[k] else 0.0
    if after < top:
        fall = quick_distances(
            s[first:stop],
            peaks[z],
            running_from_end[first:stop],
            np.maximum(v, after),
            np.full(v.size, after),
            bool(_FALL),
            lengths[z],
            a_limit[z],
            j_limit[z],
        )
        for k in range(v.size):
            total[k] += fall[k] if after < v[k] else 0.0
    return total


@njit(cache=True)
def plateau_search(
    lengths: np.ndarray,
    caps: np.ndarray,
    offsets: np.ndarray,
    s: np.ndarray,
    peaks: np.ndarray,
    running_from_start: np.ndarray,
    running_from_end: np.ndarray,
    a_limit: np.ndarray,
    j_limit: np.ndarray,
    grid: int,
    rounds: int,
) -> tuple[np.ndarray, np.ndarray]:
    """Plateaus lowered until every zone fits its speed changes (look-ahead over the zones).

    A zone whose rise and fall at its plateau (:func:`quick_distances`, from the plateaus of
    its neighbours) need more than its length is lowered to the highest speed that fits, found
    on a grid of ``grid`` speeds below it, ``rounds`` times finer each round (the grid as
    ``np.linspace(low, high, grid + 1)[1:]``); passes over the zones repeat until none
    changes (at most ``10 Z + 10``).

    Parameters
    ----------
    lengths, caps
        Length (m) and speed cap (m/s) of each zone, shape (Z,); a cap of 0 is a stop.
    offsets
        Zone z's grid rows are ``offsets[z]:offsets[z + 1]`` of the next arrays, shape (Z + 1,).
    s
        The zones' grids one after the other, shape (G,), m.
    peaks
        Largest |q'|, |q''|, |q'''| over each zone, shape (Z, 3, n).
    running_from_start, running_from_end
        Running maxima of |q'|, |q''|, |q'''| from each zone's start and from its end,
        shape (G, 3, n) (:meth:`~trackplan.timing.demand.ZoneDemand.running_maxima`).
    a_limit, j_limit
        Share of the joint acceleration and jerk limits in each zone, shape (Z, n).
    grid, rounds
        The speed grid of a lowered plateau.

    Returns
    -------
    plateau : numpy.ndarray
        Shape (Z,), m/s.
    lowered : numpy.ndarray
        Shape (Z,), bool: the zones lowered below their cap.
    """
    n_zones = caps.size
    plateau = caps.copy()
    lowered = np.zeros(n_zones, dtype=np.bool_)
    one = np.empty(1)
    for _ in range(10 * n_zones + 10):
        changed = False
        for z in range(n_zones):
            top = plateau[z]
            if top == 0.0:
                continue
            one[0] = top
            need = _needed(
                z,
                one,
                plateau,
                lengths,
                offsets,
                s,
                peaks,
                running_from_start,
                running_from_end,
                a_limit,
                j_limit,
            )
            if need[0] <= lengths[z]:
                continue
            low, high = 0.0, top
            for _ in range(rounds):  # a grid of speeds, then a finer one
                delta = high - low
                step = delta / grid
                trial = np.empty(grid)
                for i in range(1, grid):  # np.linspace(low, high, grid + 1)[1:]
                    trial[i - 1] = (i / grid * delta if step == 0.0 else i * step) + low
                trial[grid - 1] = high
                need = _needed(
                    z,
                    trial,
                    plateau,
                    lengths,
                    offsets,
                    s,
                    peaks,
                    running_from_start,
                    running_from_end,
                    a_limit,
                    j_limit,
                )
                fits = need <= lengths[z]
                k = grid
                for i in range(grid):
                    if not fits[i]:
                        k = i
                        break
                low = trial[k - 1] if k > 0 else low
                high = trial[k] if k < grid else high
            plateau[z] = low
            lowered[z] = True
            changed = True
        if not changed:
            break
    return plateau, lowered


@njit(cache=True)
def _stretch_peaks(
    s: np.ndarray,
    d1: np.ndarray,
    d2: np.ndarray,
    d3: np.ndarray,
    running_from_start: np.ndarray,
    running_from_end: np.ndarray,
    s_from: float,
    s_to: float,
) -> np.ndarray:
    """:meth:`~trackplan.timing.demand.ZoneDemand.peaks` over [s_from, s_to], shape (3, n)
    (G ≥ 2)."""
    n_grid = s.size
    first = max(int(np.searchsorted(s, s_from, side="right")) - 2, 0)
    stop = min(int(np.searchsorted(s, s_to, side="left")) + 2, n_grid)
    stop = max(stop, first + 1)
    if first == 0:  # numpy's stubs type an indexed array as Any (numba compiles this)
        return running_from_start[stop - 1]  # type: ignore[no-any-return]
    if stop == n_grid:  # a copy: one layout whichever branch (one compiled change_bounds)
        return running_from_end[first].copy()  # type: ignore[no-any-return]
    out = np.zeros((3, d1.shape[1]))
    for r in range(first, stop):
        for i in range(d1.shape[1]):
            out[0, i] = max(out[0, i], abs(d1[r, i]))
            out[1, i] = max(out[1, i], abs(d2[r, i]))
            out[2, i] = max(out[2, i], abs(d3[r, i]))
    return out


@njit(cache=True)
def quick_change(
    s: np.ndarray,
    d1: np.ndarray,
    d2: np.ndarray,
    d3: np.ndarray,
    peaks: np.ndarray,
    running_from_start: np.ndarray,
    running_from_end: np.ndarray,
    s_start: float,
    s_end: float,
    v_from: float,
    v_to: float,
    a_limit: np.ndarray,
    j_limit: np.ndarray,
) -> tuple[float, float, float]:
    """One speed change under bounds valid over the stretch it covers.

    The bounds over the whole zone at the top speed (:func:`change_bounds`); where that
    change fits the zone, raised to those over the shorter stretch it covers (a rise from
    ``s_start``, a fall to ``s_end``; :meth:`~trackplan.timing.demand.ZoneDemand.peaks`).

    Parameters
    ----------
    s, d1, d2, d3
        The zone's grid (G,), m (G ≥ 1), and signed q', q'', q''' on it, shape (G, n).
    peaks
        Largest |q'|, |q''|, |q'''| over the grid, shape (3, n).
    running_from_start, running_from_end
        Their running maxima from the grid's start and from its end, shape (G, 3, n).
    s_start, s_end
        The zone, m.
    v_from, v_to
        Speeds before and after, m/s.
    a_limit, j_limit
        Share of the joint acceleration and jerk limits, shape (n,).

    Returns
    -------
    tuple of float
        ``(distance, accel, jerk)``: m (inf when the joints leave no room), m/s², m/s³.
    """
    top = max(v_from, v_to)
    accel, jerk = change_bounds(peaks[0], peaks[1], peaks[2], top, a_limit, j_limit)
    if accel <= 0.0 or jerk <= 0.0:
        return np.inf, accel, jerk
    distance = _distance(v_from, v_to, accel, jerk)
    if distance < s_end - s_start:
        if v_to > v_from:
            s_from, s_to = s_start, s_start + distance
        else:
            s_from, s_to = s_end - distance, s_end
        if s.size < 2:
            local_accel, local_jerk = accel, jerk
        else:
            local = _stretch_peaks(
                s, d1, d2, d3, running_from_start, running_from_end, s_from, s_to
            )
            local_accel, local_jerk = change_bounds(
                local[0], local[1], local[2], top, a_limit, j_limit
            )
        accel, jerk = max(accel, local_accel), max(jerk, local_jerk)
        distance = _distance(v_from, v_to, accel, jerk)
    return distance, accel, jerk


@njit(cache=True)
def change_search(
    s: np.ndarray,
    d1: np.ndarray,
    d2: np.ndarray,
    d3: np.ndarray,
    peaks: np.ndarray,
    s_start: float,
    s_end: float,
    v_from: float,
    v_to: float,
    at_start: bool,
    a_limit: np.ndarray,
    j_limit: np.ndarray,
    start: tuple[float, float, float],
    running_from_start: np.ndarray,
    running_from_end: np.ndarray,
    quick_start: bool,
    factors: np.ndarray,
    fine_factors: np.ndarray,
    u: np.ndarray,
) -> tuple[float, float, float]:
    """The fastest speed change inside a zone whose bounds hold along its own stretch
    (:func:`trackplan.timing.demand.speed_change`).

    From the change over the zone at the top speed (or ``start``, or with ``quick_start`` the
    :func:`quick_change`, when shorter), candidate
    bounds on the grids ``best · factors`` then ``best · fine_factors`` (each axis), each
    checked along its stretch (:func:`changes_within_limits`); the shortest that passes wins.

    Parameters
    ----------
    s, d1, d2, d3
        The zone's grid (G,), m, and signed q', q'', q''' on it, shape (G, n).
    peaks
        Largest |q'|, |q''|, |q'''| over the grid, shape (3, n).
    s_start, s_end
        The zone, m.
    v_from, v_to
        Speeds before and after, m/s.
    at_start
        True when the change starts at ``s_start``, False when it ends at ``s_end``.
    a_limit, j_limit
        Share of the joint acceleration and jerk limits, shape (n,).
    start
        ``(distance, accel, jerk)`` of a change known to meet the limits (inf: none).
    running_from_start, running_from_end
        Running maxima of |q'|, |q''|, |q'''| from the grid's start and from its end, shape
        (G, 3, n) (read with ``quick_start``).
    quick_start
        Start from :func:`quick_change` instead of ``start``.
    factors, fine_factors
        Multiples of the bounds tried in the first and second round.
    u
        Check points in each constant-jerk phase, as shares of it, shape (P,).

    Returns
    -------
    tuple of float
        ``(distance, accel, jerk)``: m (inf when the joints leave no room), m/s², m/s³.
    """
    top = max(v_from, v_to)
    accel, jerk = change_bounds(peaks[0], peaks[1], peaks[2], top, a_limit, j_limit)
    best = (np.inf, accel, jerk)
    if accel > 0.0 and jerk > 0.0:
        best = (_distance(v_from, v_to, accel, jerk), accel, jerk)
    if quick_start:
        start = quick_change(
            s, d1, d2, d3, peaks, running_from_start, running_from_end,
            s_start, s_end, v_from, v_to, a_limit, j_limit,
        )  # fmt: skip
    if start[0] < best[0]:
        best = start
    if not np.isfinite(best[0]) or v_from == v_to or s.size < 2:
        return best
    for round_ in range(2):
        grid = factors if round_ == 0 else fine_factors
        n = grid.size
        a_grid = np.empty(n * n)
        j_grid = np.empty(n * n)
        for i in range(n):
            for k in range(n):
                a_grid[i * n + k] = min(best[1] * grid[i], MAX_PATH_ACCELERATION)
                j_grid[i * n + k] = min(best[2] * grid[k], MAX_PATH_JERK)
        ok, distance = changes_within_limits(
            s,
            d1,
            d2,
            d3,
            s_start,
            s_end,
            v_from,
            v_to,
            at_start,
            a_limit,
            j_limit,
            a_grid,
            j_grid,
            u,
        )
        pick = -1
        for k in range(n * n):
            if ok[k] and (pick < 0 or distance[k] < distance[pick]):
                pick = k
        if pick >= 0 and distance[pick] < best[0]:
            best = (distance[pick], a_grid[pick], j_grid[pick])
    return best
