"""Air moves: jerk-limited, time-optimal joint moves from rest to rest (``docs/seams.md``).

Between two seams the tool moves through the air. :func:`plan_air_move` plans that move with
ruckig (offline, one ``Ruckig(n_dof, Ts)`` calculation): every joint from rest to rest under
its velocity, acceleration and jerk limits, the joints synchronised to arrive together, the
duration rounded up to a whole number of samples (``DurationDiscretization.Discrete``).

The limits handed to ruckig are the robot's less :data:`PLANNING_MARGIN` (relative). The
backward differences at Ts of a sampled motion are averages of its continuous derivatives
over the last one, two or three periods (with the robot at rest before and after), so they
never exceed the continuous bounds ruckig keeps, up to round-off (about 1e-9 relative for
the jerk at Ts = 4 ms). The margin is twice the
:data:`~trackplan.timing.sample_checks.LIMIT_MARGIN` every time law keeps, so the samples
pass the laws' own sample checks (:class:`~trackplan.timing.sample_checks.RateLimits`, which
flag anything above ``1 - LIMIT_MARGIN`` of a limit), not only the checker.

ruckig knows no dynamics: sample checks handed in (the torque limits) slow a move that
fails them down as a whole, a stretch in time. A move through a via configuration is two
rest-to-rest moves (the community version of ruckig plans intermediate waypoints only
online); the via is one of the samples.

:func:`air_time_estimate` and :func:`trapezoid_time` are closed forms, vectorised over any
number of moves, for sequencing: the time of the slowest joint alone, with and without the
jerk limit. Both are lower bounds of the planned duration.
"""

from __future__ import annotations

from dataclasses import dataclass
from itertools import pairwise
from typing import Any

import numpy as np
from ruckig import DurationDiscretization, InputParameter, Result, Ruckig, Trajectory

from trackplan.timing.sample_checks import LIMIT_MARGIN, SampleCheck, run_checks

PLANNING_MARGIN = 2.0 * LIMIT_MARGIN
"""Relative margin under each joint limit that air moves are planned with (see the module)."""
MAX_SLOWDOWNS = 8
"""Rounds of slowing a move down for the sample checks it is given."""


@dataclass(frozen=True, eq=False)
class AirMove:
    """A joint move from rest to rest, sampled at Ts.

    Attributes
    ----------
    q
        Joint positions, shape (N, n), rad, one row per period ``sample_time``; ``q[0]`` is
        the start and ``q[-1]`` the end configuration, exactly.
    sample_time
        Ts, s.
    via
        The via configuration the move passes through (at rest), shape (n,), rad; None for
        a direct move.
    speed_factor
        1, or the factor ``x`` < 1 the move was slowed down by for the sample checks it was
        planned with (the time-optimal move at velocity, acceleration and jerk limits
        ``x v``, ``x² a``, ``x³ j``: the full-speed move stretched in time by ``1/x``).
    """

    q: np.ndarray
    sample_time: float
    via: np.ndarray | None
    speed_factor: float = 1.0

    @property
    def duration(self) -> float:
        """``(N - 1) · Ts``, s."""
        return (len(self.q) - 1) * self.sample_time


def plan_air_move(
    q_start: np.ndarray,
    q_end: np.ndarray,
    velocity: np.ndarray,
    acceleration: np.ndarray,
    jerk: np.ndarray,
    sample_time: float,
    *,
    via: np.ndarray | None = None,
    checks: tuple[SampleCheck, ...] = (),
) -> AirMove:
    """The time-optimal jerk-limited move from rest at ``q_start`` to rest at ``q_end``.

    Parameters
    ----------
    q_start, q_end
        Start and end configurations, shape (n,), rad.
    velocity, acceleration, jerk
        Joint limits (symmetric), shape (n,), in rad/s, rad/s², rad/s³; planned
        :data:`PLANNING_MARGIN` under them.
    sample_time
        Ts, s; the duration is a whole number of periods.
    via
        A configuration to pass through, shape (n,), rad: the move stops there (two
        rest-to-rest moves). None moves directly.
    checks
        Sample checks the move must pass besides the rate limits, e.g. the torque limits
        (:func:`~trackplan.timing.sample_checks.robot_checks`). Where one fails, the whole
        move is slowed down by the speed factor the check asks for (all limits scaled as a
        stretch in time) and planned again, at most :data:`MAX_SLOWDOWNS` times; the last
        move is returned either way, for the checker to judge.

    Returns
    -------
    AirMove
        The samples, ``q[0] == q_start`` and ``q[-1] == q_end`` exactly.

    Raises
    ------
    ValueError
        When the shapes disagree, a limit is not positive, ``sample_time`` is not positive,
        or ruckig rejects the input.
    """
    q_start = np.asarray(q_start, dtype=float)
    q_end = np.asarray(q_end, dtype=float)
    n_dof = q_start.shape[-1] if q_start.ndim else 0
    limits = [
        np.broadcast_to(np.asarray(x, dtype=float), (n_dof,))
        for x in (velocity, acceleration, jerk)
    ]
    points = [q_start, q_end] if via is None else [q_start, np.asarray(via, dtype=float), q_end]
    if any(p.shape != (n_dof,) for p in points) or n_dof == 0:
        raise ValueError(
            f"air move: configurations must all have shape (n,), got {[p.shape for p in points]}"
        )
    if not all(np.all(np.isfinite(p)) for p in points):
        raise ValueError("air move: a configuration is not finite")
    if not all(np.all(lim > 0.0) and np.all(np.isfinite(lim)) for lim in limits):
        raise ValueError("air move: velocity, acceleration and jerk limits must be positive")
    if not sample_time > 0.0:
        raise ValueError(f"air move: sample_time {sample_time} must be positive")
    v_max, a_max, j_max = ((1.0 - PLANNING_MARGIN) * lim for lim in limits)
    factor = 1.0
    for round_ in range(MAX_SLOWDOWNS + 1):
        pieces = [
            _rest_to_rest(a, b, factor * v_max, factor**2 * a_max, factor**3 * j_max, sample_time)
            for a, b in pairwise(points)
        ]
        q = np.concatenate([pieces[0], *(piece[1:] for piece in pieces[1:])])
        if not checks or round_ == MAX_SLOWDOWNS:
            break
        _, order, ratio = run_checks(checks, q, sample_time)
        if ratio.size == 0:
            break
        factor *= float(np.min(ratio ** (-1.0 / order)))
    return AirMove(
        q=q,
        sample_time=float(sample_time),
        via=None if via is None else points[1],
        speed_factor=factor,
    )


def _rest_to_rest(
    q_start: np.ndarray,
    q_end: np.ndarray,
    v_max: np.ndarray,
    a_max: np.ndarray,
    j_max: np.ndarray,
    sample_time: float,
) -> np.ndarray:
    """One ruckig move, sampled at Ts, shape (N, n); ends set exactly."""
    n_dof = len(q_start)
    if np.array_equal(q_start, q_end):
        return q_start[None, :].copy()
    planner = Ruckig(n_dof, sample_time)
    given = InputParameter(n_dof)
    given.current_position = q_start.tolist()
    given.target_position = q_end.tolist()
    given.max_velocity = v_max.tolist()
    given.max_acceleration = a_max.tolist()
    given.max_jerk = j_max.tolist()
    given.duration_discretization = DurationDiscretization.Discrete
    trajectory = Trajectory(n_dof)
    outcome = planner.calculate(given, trajectory)
    if outcome not in (Result.Working, Result.Finished):
        raise ValueError(f"air move: ruckig rejected the move ({outcome.name})")
    n_periods = round(trajectory.duration / sample_time)
    t = np.arange(n_periods + 1) * sample_time
    q = np.column_stack([_sample_profile(profile, t) for profile in trajectory.profiles[0]])
    q[0] = q_start
    q[-1] = q_end
    return q


def _sample_profile(profile: Any, t: np.ndarray) -> np.ndarray:
    """One joint's seven-phase ruckig profile at the times ``t`` (s), shape (N,), rad.

    Each phase runs at constant jerk from the state at its start; after the last phase the
    joint holds its final position. A rest-to-rest profile has no brake or pre-phase.
    """
    durations = np.asarray(profile.t, dtype=float)
    start = np.concatenate([[0.0], np.cumsum(durations)])
    p = np.asarray(profile.p, dtype=float)
    v = np.asarray(profile.v, dtype=float)
    a = np.asarray(profile.a, dtype=float)
    j = np.asarray(profile.j, dtype=float)
    phase = np.clip(np.searchsorted(start, t, side="right") - 1, 0, len(durations) - 1)
    dt = t - start[phase]
    q = p[phase] + dt * (v[phase] + dt * (a[phase] / 2.0 + dt * j[phase] / 6.0))
    return np.where(t >= start[-1], float(profile.pf), q)


def air_time_estimate(
    q_start: np.ndarray,
    q_end: np.ndarray,
    velocity: np.ndarray,
    acceleration: np.ndarray,
    jerk: np.ndarray,
) -> np.ndarray:
    """The jerk-limited rest-to-rest time of the slowest joint, in closed form.

    Per joint, the time-optimal profile over the distance ``D = |q_end - q_start|`` under
    ``v``, ``a``, ``j``: with ``t_a(w) = w/a + a/j`` when ``w j >= a²`` (the acceleration
    limit is reached) and ``2 sqrt(w/j)`` otherwise, the time to reach speed ``w`` from
    rest, a joint reaching ``v`` takes ``t_a(v) + D/v``; one that does not (``D < v t_a(v)``)
    peaks at the ``w`` with ``w t_a(w) = D`` and takes ``2 t_a(w)``. Synchronising the
    joints never shortens the slowest, and rounding to whole periods only lengthens, so
    this is a lower bound of :func:`plan_air_move`'s duration (at the unshrunk limits).

    Parameters
    ----------
    q_start, q_end
        Configurations, shape (..., n), rad (broadcast together).
    velocity, acceleration, jerk
        Joint limits, shape (n,) (or broadcastable to (..., n)), rad/s, rad/s², rad/s³.

    Returns
    -------
    numpy.ndarray
        Shape (...), s.
    """
    D = np.abs(np.asarray(q_end, dtype=float) - np.asarray(q_start, dtype=float))
    v = np.asarray(velocity, dtype=float)
    a = np.asarray(acceleration, dtype=float)
    j = np.asarray(jerk, dtype=float)
    t_cruise = np.where(v * j >= a * a, v / a + a / j, 2.0 * np.sqrt(v / j))
    reaches_v = D >= v * t_cruise
    # peak speed when v is not reached: w²/a + (a/j) w = D with the acceleration limit
    # reached, else 2 w sqrt(w/j) = D
    r = a / j
    w_acc = 0.5 * a * (np.sqrt(r * r + 4.0 * D / a) - r)
    w_jerk = np.cbrt(0.25 * j * D * D)
    w = np.where(w_acc * j >= a * a, w_acc, w_jerk)
    t_peak = np.where(w * j >= a * a, 2.0 * (w / a + r), 4.0 * np.sqrt(w / j))
    time = np.where(reaches_v, t_cruise + D / v, t_peak)
    return np.asarray(time.max(axis=-1))


def trapezoid_time(
    q_start: np.ndarray,
    q_end: np.ndarray,
    velocity: np.ndarray,
    acceleration: np.ndarray,
) -> np.ndarray:
    """The rest-to-rest time of the slowest joint without a jerk limit (trapezoidal speed).

    Per joint, ``D/v + v/a`` when ``D >= v²/a`` (the speed limit is reached), else
    ``2 sqrt(D/a)``; a lower bound of :func:`air_time_estimate`.

    Parameters
    ----------
    q_start, q_end
        Configurations, shape (..., n), rad (broadcast together).
    velocity, acceleration
        Joint limits, shape (n,) (or broadcastable to (..., n)), rad/s, rad/s².

    Returns
    -------
    numpy.ndarray
        Shape (...), s.
    """
    D = np.abs(np.asarray(q_end, dtype=float) - np.asarray(q_start, dtype=float))
    v = np.asarray(velocity, dtype=float)
    a = np.asarray(acceleration, dtype=float)
    time = np.where(D >= v * v / a, D / v + v / a, 2.0 * np.sqrt(D / a))
    return np.asarray(time.max(axis=-1))
