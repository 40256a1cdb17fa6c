"""Checks of sampled joints that a time law's rebuild loop runs before it returns.

A sample check is any callable ``check(q, sample_time) -> (sample, order, ratio)``:

- ``q``: joint positions at Ts, shape (N, n), rad, from rest to rest;
- ``sample``: indices of the samples that break the check, shape (V,), int (clipped to
  ``N - 1`` for the rest samples after the end);
- ``order``: how the broken quantity scales with the path speed, shape (V,), int (1 for a
  velocity, 2 for an acceleration, 3 for a jerk): a zone cruising at ``v`` slows down
  to ``v · ratio^(-1/order)``;
- ``ratio``: the value over the level it must stay under, shape (V,), > 1.

:class:`RateLimits` is the joint velocity, acceleration and jerk check; a new limit (motor
torque, say) is one more callable handed to the law, without touching the law.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from trackplan.derivatives import backward_derivatives
from trackplan.robots.model import Robot

LIMIT_MARGIN = 1e-6
"""Relative margin kept under every limit a law plans against, so that round-off in the
samples never fails the checker (which allows ``1e-9`` relative): a sample above
``(1 - LIMIT_MARGIN)`` of a limit counts as a violation."""

SampleCheck = Callable[[np.ndarray, float], tuple[np.ndarray, np.ndarray, np.ndarray]]
"""``check(q (N, n), Ts) -> (sample (V,), order (V,), ratio (V,))`` (see the module)."""


@dataclass(frozen=True, eq=False)
class RateLimits:
    """Joint velocity, acceleration and jerk by backward differences at Ts, as the checker.

    Attributes
    ----------
    robot
        The robot whose ``v_max``, ``a_max``, ``j_max`` (each shape (n,)) apply.
    margin
        Relative margin kept under each limit.
    """

    robot: Robot
    margin: float = LIMIT_MARGIN

    def __call__(
        self, q: np.ndarray, sample_time: float
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Samples where a rate limit (less the margin) is exceeded; see the module."""
        qd, qdd, qddd = backward_derivatives(q, sample_time, pad_end=True)
        scale = 1.0 - self.margin
        samples, orders, ratios = [], [], []
        for order, values, bound in (
            (1, qd, self.robot.v_max),
            (2, qdd, self.robot.a_max),
            (3, qddd, self.robot.j_max),
        ):
            ratio = (np.abs(values) / (scale * bound)).max(axis=1)
            bad = np.flatnonzero(ratio > 1.0)
            samples.append(np.minimum(bad, len(q) - 1))
            orders.append(np.full(bad.size, order))
            ratios.append(ratio[bad])
        return np.concatenate(samples), np.concatenate(orders), np.concatenate(ratios)


def run_checks(
    checks: tuple[SampleCheck, ...], q: np.ndarray, sample_time: float
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Every check's violations, concatenated (``sample``, ``order``, ``ratio``)."""
    found = [check(q, sample_time) for check in checks]
    return (
        np.concatenate([f[0] for f in found]).astype(int),
        np.concatenate([f[1] for f in found]).astype(int),
        np.concatenate([f[2] for f in found]).astype(float),
    )
