"""Violations and margins from sampled signals: the checker's shared vocabulary.

Every check (:mod:`trackplan.planning.check_joints`, :mod:`trackplan.planning.check_task`,
:mod:`trackplan.planning.check_tool`) turns the samples where a limit is exceeded into one
:class:`~trackplan.check_report.Violation` here, with the same units, slack and wording.
"""

from __future__ import annotations

import numpy as np

from trackplan.check_report import Violation

UNITS = {
    "position": "rad",
    "velocity": "rad/s",
    "acceleration": "rad/s²",
    "jerk": "rad/s³",
    "torque": "N·m",
    "tracking": "m",
    "orientation": "rad",
    "spin": "rad",
    "spin rate": "rad/m",
    "speed": "m/s",
    "coverage": "m",
    "weave": "m",
    "clearance": "m",
    "downhand": "rad",
}
RELATIVE_SLACK = 1e-9
"""Values within this relative amount of a limit count as meeting it (float round-off)."""


def plural(n: int, noun: str) -> str:
    """``1 sample``, ``2 samples``."""
    return f"{n} {noun}" if n == 1 else f"{n} {noun}s"


def met(margin: np.ndarray | float, slack: float) -> np.ndarray:
    """A margin within the round-off slack of a limit counts as met: reported as 0, not < 0."""
    if isinstance(margin, float):  # one number: no array round trip
        return np.asarray(0.0 if -slack <= margin < 0 else margin)
    margin = np.asarray(margin, dtype=float)
    return np.where((margin < 0) & (margin >= -slack), 0.0, margin)


def violation_over(
    kind: str, joint: int | None, t: np.ndarray, values: np.ndarray, use: np.ndarray, bound: float
) -> Violation:
    """Summarise the samples where ``use > 1`` into one :class:`Violation`."""
    bad = np.flatnonzero(use > 1.0 + RELATIVE_SLACK)
    worst = int(bad[np.argmax(use[bad])])
    value = float(values[worst])
    who = f"joint {joint} {kind}" if joint is not None else kind
    message = (
        f"{who} {abs(value):.4g} {UNITS[kind]} exceeds {abs(bound):.4g} at t = {t[worst]:.3f} s"
        f" ({plural(len(bad), 'sample')} from t = {t[bad[0]]:.3f} to {t[bad[-1]]:.3f} s)"
    )
    return Violation(
        limit=kind,
        joint=joint,
        t_first=float(t[bad[0]]),
        t_last=float(t[bad[-1]]),
        worst=value,
        bound=bound,
        message=message,
    )


def violations_of(violations: list[Violation], limit: str) -> list[Violation]:
    """The violations of one limit."""
    return [violation for violation in violations if violation.limit == limit]
