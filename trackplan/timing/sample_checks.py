"""Checks of sampled joints that a time law's rebuild loop runs before it returns.

A sample check is any callable ``check(q, sample_time) -> (sample, order, ratio)``:

- ``q``: joint positions at Ts, shape (N, n), rad, from rest to rest;
- ``sample``: indices of the samples that break the check, shape (V,), int (clipped to
  ``N - 1`` for the rest samples after the end);
- ``order``: how the broken quantity scales with the path speed, shape (V,), int (1 for a
  velocity, 2 for an acceleration, 3 for a jerk): a zone cruising at ``v`` slows down
  to ``v · ratio^(-1/order)``;
- ``ratio``: the value over the level it must stay under, shape (V,), > 1.

:class:`RateLimits` is the joint velocity, acceleration and jerk check; :class:`TorqueLimits`
the joint torque check of a robot with dynamics (``docs/dynamics.md``). :func:`robot_checks`
is what a law checks by default: both, the second when the robot has dynamics. Both also
read a :class:`~trackplan.motion.JointSamples` (:class:`MotionCheck`), so that the torques
they compute are those the checker and the energy figures then read.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Protocol, runtime_checkable

import numpy as np

from trackplan.motion import JointSamples
from trackplan.robots.dynamics.rne import inverse_dynamics
from trackplan.robots.machine import Machine
from trackplan.robots.model import Robot
from trackplan.timing import _kernels_samples

LIMIT_MARGIN = 1e-6
"""Relative margin kept under every limit a law plans against, so that round-off in the
samples never fails the checker (which allows ``1e-9`` relative): a sample above
``(1 - LIMIT_MARGIN)`` of a limit counts as a violation."""

MIN_SPEED_FACTOR = 0.1
"""Smallest speed factor :class:`TorqueLimits` asks for in one round of the rebuild loop
(a sample whose torque has almost no room above its speed-independent part would otherwise
ask for a near-standstill at once; the next round asks again if needed)."""

SampleCheck = Callable[[np.ndarray, float], tuple[np.ndarray, np.ndarray, np.ndarray]]
"""``check(q (N, n), Ts) -> (sample (V,), order (V,), ratio (V,))`` (see the module)."""

Found = tuple[np.ndarray, np.ndarray, np.ndarray]
"""``(sample (V,), order (V,), ratio (V,))`` of a check (see the module)."""


@runtime_checkable
class MotionCheck(Protocol):
    """A sample check that also reads a :class:`~trackplan.motion.JointSamples`."""

    def check_motion(self, motion: JointSamples) -> Found:
        """The check of ``motion.q`` at ``motion.sample_time`` (see the module)."""
        ...


@dataclass(frozen=True, eq=False)
class RateLimits:
    """Joint velocity, acceleration and jerk by backward differences at Ts, as the checker.

    One compiled pass over the samples (:func:`trackplan.timing._kernels_samples.rate_ratios`).

    Attributes
    ----------
    robot
        The robot whose ``v_max``, ``a_max``, ``j_max`` (each shape (n,)) apply.
    margin
        Relative margin kept under each limit.
    """

    robot: Robot | Machine
    margin: float = LIMIT_MARGIN

    def __call__(self, q: np.ndarray, sample_time: float) -> Found:
        """Samples where a rate limit (less the margin) is exceeded; see the module."""
        return self.check_motion(JointSamples(self.robot, q, sample_time))

    def check_motion(self, motion: JointSamples) -> Found:
        """:meth:`__call__` of the motion's samples."""
        q, sample_time = motion.q, motion.sample_time
        scale = 1.0 - self.margin
        limits = np.stack(
            [scale * self.robot.v_max, scale * self.robot.a_max, scale * self.robot.j_max]
        )
        steps = np.array([sample_time, sample_time**2, sample_time**3])
        ratio = _kernels_samples.rate_ratios(np.ascontiguousarray(q, dtype=float), steps, limits)
        samples, orders, ratios = [], [], []
        for order in (1, 2, 3):
            bad = np.flatnonzero(ratio[:, order - 1] > 1.0)
            samples.append(np.minimum(bad, len(q) - 1))
            orders.append(np.full(bad.size, order))
            ratios.append(ratio[bad, order - 1])
        return np.concatenate(samples), np.concatenate(orders), np.concatenate(ratios)


@dataclass(frozen=True, eq=False)
class TorqueLimits:
    """Torque limits by inverse dynamics of the backward differences at Ts, as the checker.

    The torque splits by how it scales with the path speed ``v`` along a fixed joint path:
    ``τ = τ_s + τ_1 + τ_2`` with ``τ_s`` gravity plus Coulomb friction (independent of ``v``),
    ``τ_1 = G² B q̇`` (∝ v) and ``τ_2`` the rest: inertia, Coriolis and motor inertia (∝ v²
    at a steady speed). The check reports order 2 with the ratio that brings
    ``|τ_s| + |τ_1| x + |τ_2| x²`` under the limit at the speed factor ``x = ratio^(-1/2)``.
    Where ``|τ_s|`` alone exceeds the limit no speed helps: the check then asks for nothing
    and leaves the trajectory to the checker, which names it "infeasible at any speed". One
    round asks for a speed factor of at least :data:`MIN_SPEED_FACTOR`.

    Attributes
    ----------
    robot
        A robot with dynamics.
    margin
        Relative margin kept under each limit.
    """

    robot: Robot
    margin: float = LIMIT_MARGIN

    def __call__(self, q: np.ndarray, sample_time: float) -> Found:
        """Samples where a torque limit (less the margin) is exceeded and a slower speed helps.

        Parameters
        ----------
        q
            Joint positions at Ts, shape (N, n), rad, from rest to rest.
        sample_time
            Ts, s.

        Returns
        -------
        tuple of numpy.ndarray
            ``sample (V,)`` (clipped to ``N - 1``), ``order (V,)`` (2) and ``ratio (V,)`` (> 1).
        """
        return self.check_motion(JointSamples(self.robot, q, sample_time))

    def check_motion(self, motion: JointSamples) -> Found:
        """:meth:`__call__` of the motion's samples, reading its torques."""
        dynamics = self.robot.dynamics
        if dynamics is None or motion.torque is None:
            empty = np.zeros(0)
            return empty.astype(int), empty.astype(int), empty
        q, qd, q_held, tau = motion.q, motion.qd, motion.q_held, motion.torque
        cap = (1.0 - self.margin) * dynamics.torque_max
        # the rows of the values over a cap (numpy's any over a short axis is slow; these
        # are usually none)
        rows = np.unique(np.flatnonzero(np.abs(tau) > cap) // tau.shape[1])
        if not rows.size:
            empty = np.zeros(0)
            return empty.astype(int), empty.astype(int), empty
        # only the breaking samples are split into their parts
        q_held, qd, tau = q_held[rows], qd[rows], tau[rows]
        zero = np.zeros_like(qd)
        G = np.abs(np.asarray(dynamics.gear_ratio))
        coulomb = np.asarray(dynamics.coulomb) * G[:, None]
        static = inverse_dynamics(self.robot, q_held, zero, zero, friction=False)
        static += np.where(qd > 0, coulomb[:, 0], np.where(qd < 0, coulomb[:, 1], 0.0))
        first = G**2 * np.asarray(dynamics.viscous) * qd
        second = tau - static - first
        over = np.abs(tau) > cap
        room = cap - np.abs(static)
        if np.any(over & (room <= 0.0)):
            # gravity (and Coulomb friction) alone break a limit: no speed helps, and slowing
            # down elsewhere would not make the trajectory feasible
            empty = np.zeros(0)
            return empty.astype(int), empty.astype(int), empty
        helps = over
        a, b = np.abs(second), np.abs(first)
        # largest x in (0, 1] with a x² + b x <= room (a, b >= 0, room > 0)
        with np.errstate(divide="ignore", invalid="ignore"):
            root = np.where(
                a > 0.0,
                (-b + np.sqrt(b * b + 4.0 * a * room)) / (2.0 * a),
                room / b,
            )
        x = np.clip(np.where(helps, root, 1.0), MIN_SPEED_FACTOR, 1.0)
        ratio_joint = np.where(helps, x**-2.0, 1.0)
        ratio = ratio_joint.max(axis=1)
        bad = ratio > 1.0
        return np.minimum(rows[bad], len(q) - 1), np.full(int(bad.sum()), 2), ratio[bad]


def robot_checks(robot: Robot | Machine) -> tuple[SampleCheck, ...]:
    """The sample checks of a robot: its rate limits, and its torque limits when it has
    dynamics."""
    if isinstance(robot, Machine) or robot.dynamics is None:
        return (RateLimits(robot),)
    return (RateLimits(robot), TorqueLimits(robot))


def run_checks(checks: tuple[SampleCheck, ...], q: np.ndarray, sample_time: float) -> Found:
    """Every check's violations, concatenated (``sample``, ``order``, ``ratio``)."""
    return _concatenated([check(q, sample_time) for check in checks])


def run_motion_checks(checks: tuple[SampleCheck, ...], motion: JointSamples) -> Found:
    """:func:`run_checks` on a motion's samples: a :class:`MotionCheck` reads the motion
    itself (its torques are then those the checker reads again)."""
    found = []
    for check in checks:
        # a MotionCheck, by its method: isinstance against a protocol costs Python 3.11
        # more than the check itself
        check_motion = getattr(check, "check_motion", None)
        if check_motion is not None:
            found.append(check_motion(motion))
        else:
            found.append(check(motion.q, motion.sample_time))
    return _concatenated(found)


def _concatenated(found: list[Found]) -> Found:
    """The checks' violations as one ``(sample, order, ratio)``."""
    return (
        np.concatenate([f[0] for f in found]).astype(int),
        np.concatenate([f[1] for f in found]).astype(int),
        np.concatenate([f[2] for f in found]).astype(float),
    )
