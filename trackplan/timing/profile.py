"""Piecewise-constant-jerk speed profiles s(t): cruises and jerk-limited speed changes."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from trackplan.timing import _kernels_samples


def speed_change_phases(
    v_from: float, v_to: float, accel: float, jerk: float
) -> list[tuple[float, float]]:
    """Jerk phases of the fastest speed change under acceleration and jerk bounds.

    The acceleration rises at ``jerk``, may hold at ``accel``, and falls back to zero
    (a trapezoidal or triangular acceleration pulse), so the acceleration is continuous and
    the jerk bounded: the sampled profile passes a backward-difference jerk check.

    Parameters
    ----------
    v_from, v_to
        Speeds before and after, m/s.
    accel, jerk
        Bounds on |s̈| (m/s²) and |s⃛| (m/s³), both > 0.

    Returns
    -------
    list of (duration s, jerk m/s³)
        Empty when the speeds are equal.
    """
    delta = abs(v_to - v_from)
    if delta == 0.0:
        return []
    sign = 1.0 if v_to > v_from else -1.0
    if delta * jerk >= accel * accel:
        t_jerk = accel / jerk
        t_hold = delta / accel - t_jerk
    else:
        t_jerk = float(np.sqrt(delta / jerk))
        t_hold = 0.0
    phases = [(t_jerk, sign * jerk)]
    if t_hold > 0.0:
        phases.append((t_hold, 0.0))
    phases.append((t_jerk, -sign * jerk))
    return phases


def speed_change_time(delta: float, accel: float, jerk: float) -> float:
    """Duration of :func:`speed_change_phases` for a speed change ``delta`` (m/s), s."""
    if delta <= 0.0:
        return 0.0
    if delta * jerk >= accel * accel:
        return delta / accel + accel / jerk
    return 2.0 * math.sqrt(delta / jerk)  # libm's correctly rounded root, as np.sqrt


def speed_change_distance(v_from: float, v_to: float, accel: float, jerk: float) -> float:
    """Distance covered by the speed change, m (mean speed × duration: the pulse is symmetric)."""
    return 0.5 * (v_from + v_to) * speed_change_time(abs(v_to - v_from), accel, jerk)


@dataclass(frozen=True, eq=False)
class SpeedProfile:
    """s(t) made of constant-jerk phases, starting at s = 0 at rest.

    Attributes
    ----------
    t_start
        Start time of each phase, shape (P,), s.
    s0, v0, a0
        Path position, speed and acceleration at each phase start, shape (P,).
    jerk
        Constant s⃛ of each phase, shape (P,), m/s³.
    duration
        End time of the last phase, s.
    length
        Path length reached at the end, m.
    """

    t_start: np.ndarray
    s0: np.ndarray
    v0: np.ndarray
    a0: np.ndarray
    jerk: np.ndarray
    duration: float
    length: float

    @classmethod
    def from_phases(cls, phases: list[tuple[float, float]], length: float) -> SpeedProfile:
        """Integrate phases of (duration, jerk) from rest at s = 0.

        Parameters
        ----------
        phases
            (duration s, jerk m/s³) in order; cruise phases have zero jerk and must be
            preceded by the speed they hold.
        length
            Path length the profile must reach, m (the end is snapped to it).
        """
        durations = np.array([d for d, _ in phases])
        jerks = np.array([j for _, j in phases])
        n = len(phases)
        t0 = np.zeros(n)
        s0 = np.zeros(n)
        v0 = np.zeros(n)
        a0 = np.zeros(n)
        s = v = a = t = 0.0
        for k in range(n):  # loop over phases (a few per zone), not over samples
            t0[k], s0[k], v0[k], a0[k] = t, s, v, a
            d, j = durations[k], jerks[k]
            s += v * d + a * d * d / 2.0 + j * d**3 / 6.0
            v += a * d + j * d * d / 2.0
            a += j * d
            t += d
        return cls(t0, s0, v0, a0, jerks, float(t), float(length))

    def evaluate(self, t: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Path position, speed and acceleration at times ``t``.

        Parameters
        ----------
        t
            Times, shape (N,), s, within [0, duration].

        Returns
        -------
        tuple of numpy.ndarray
            ``(s, v, a)``, each shape (N,); ``s`` is clipped to [0, length].
        """
        t = np.asarray(t, dtype=float)
        k = self.phase_index(t)
        tau = t - self.t_start[k]
        j = self.jerk[k]
        v = self.v0[k] + self.a0[k] * tau + j * tau**2 / 2.0
        a = self.a0[k] + j * tau
        return self._position(k, tau), v, a

    def position(self, t: np.ndarray) -> np.ndarray:
        """Path position at times ``t`` (N,), s: the ``s`` of :meth:`evaluate` alone, shape
        (N,), m, clipped to [0, length] (compiled, same operations:
        :func:`trackplan.timing._kernels_samples.profile_position`)."""
        return _kernels_samples.profile_position(
            self.t_start,
            self.s0,
            self.v0,
            self.a0,
            self.jerk,
            self.length,
            np.ascontiguousarray(t, dtype=float),
        )

    def _position(self, k: np.ndarray, tau: np.ndarray) -> np.ndarray:
        """Path position at ``tau`` (N,) s into phases ``k`` (N,), clipped, m."""
        j = self.jerk[k]
        s = self.s0[k] + self.v0[k] * tau + self.a0[k] * tau**2 / 2.0 + j * tau**3 / 6.0
        clipped: np.ndarray = np.clip(s, 0.0, self.length, out=s)
        return clipped

    def phase_index(self, t: np.ndarray) -> np.ndarray:
        """Index of the phase each time falls in, shape (N,)."""
        return np.clip(np.searchsorted(self.t_start, t, side="right") - 1, 0, len(self.t_start) - 1)
