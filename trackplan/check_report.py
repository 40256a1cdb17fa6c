"""What a check finds: :class:`Violation`, :class:`CellReport` and :class:`CheckReport`.

The checker (:mod:`trackplan.planning.checker`) and the cell check
(:mod:`trackplan.cell.check`) both return these; they sit below both so that the cell
check never imports the planning layer. A :class:`CheckReport` carries a
:class:`~trackplan.status.Status` derived from its violations.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from trackplan.status import Status

TASK_KINDS = ("tracking", "orientation", "speed", "coverage")
"""The task limits the checker reports margins for."""

CELL_KINDS = frozenset({"collision", "clearance"})
"""Violation kinds of the cell check: a report whose only violations are these has status
:attr:`Status.COLLISION`."""

IGNORED_UNLESS_BROKEN = frozenset({"speed", "coverage"})
"""Task margins that count towards the worst margin only when negative (broken).

A plan drives the tool at the rated speed wherever it can, so its speed margin is 0 by
design, and the coverage margin is a pass (1) or fail (−1) flag, not an unused fraction.
"""


@dataclass(frozen=True, kw_only=True)
class Violation:
    """One limit broken over a time window.

    Attributes
    ----------
    limit
        A joint limit kind (``position``, ``velocity``, ``acceleration``, ``jerk``,
        ``torque``), a task kind (``tracking``, ``orientation``, ``spin``, ``spin rate``,
        ``speed``, ``coverage``) or a cell kind (``collision``, ``clearance``).
    joint
        1-based joint number for joint limits, None for task and cell limits.
    t_first, t_last
        First and last sample time at which the limit is exceeded, s.
    worst
        The worst value (signed for joint limits), in the limit's unit.
    bound
        The limit it exceeds (same unit).
    message
        One line: "joint 6 jerk 31.2 rad/s³ exceeds 20 at t = 2.415 s".
    """

    limit: str
    joint: int | None
    t_first: float
    t_last: float
    worst: float
    bound: float
    message: str

    @property
    def status(self) -> Status:
        """:attr:`Status.COLLISION` for a cell kind, else :attr:`Status.LIMITS_VIOLATED`."""
        return Status.COLLISION if self.limit in CELL_KINDS else Status.LIMITS_VIOLATED


def violations_status(violations: tuple[Violation, ...] | list[Violation]) -> Status:
    """The status a set of violations amounts to.

    Parameters
    ----------
    violations
        What a check found.

    Returns
    -------
    Status
        :attr:`Status.FEASIBLE` when there are none, :attr:`Status.COLLISION` when every
        one is a cell kind (:data:`CELL_KINDS`: every limit met, the clearance broken),
        else :attr:`Status.LIMITS_VIOLATED`.
    """
    if not violations:
        return Status.FEASIBLE
    if all(violation.limit in CELL_KINDS for violation in violations):
        return Status.COLLISION
    return Status.LIMITS_VIOLATED


@dataclass(frozen=True, eq=False, kw_only=True)
class CellReport:
    """What the cell check (:func:`trackplan.cell.check.check_cell`) found.

    Attributes
    ----------
    min_clearance
        Least signed distance over every checked pair and sample, m (negative: overlap).
    closest
        (robot body, other body) names of the pair where it occurs.
    t_closest
        Time of the closest approach, s.
    point
        Sample index of the closest approach.
    clearance
        The required clearance, m.
    margin
        ``(min_clearance − clearance) / max(clearance, 1 mm)``, capped at 1: the unused
        share in the checker's sign convention (negative when violated).
    distance
        Least distance over all pairs at each sample, shape (N,), m (clearance vs time).
    violations
        One per pair that breaks the clearance (kind ``collision`` when the bodies
        overlap, ``clearance`` otherwise), in time order.
    """

    min_clearance: float
    closest: tuple[str, str]
    t_closest: float
    point: int
    clearance: float
    margin: float
    distance: np.ndarray
    violations: tuple[Violation, ...]

    @property
    def success(self) -> bool:
        """True when every pair keeps the clearance at every sample."""
        return not self.violations

    @property
    def status(self) -> Status:
        """:attr:`Status.FEASIBLE` when the clearance is kept, else :attr:`Status.COLLISION`."""
        return Status.FEASIBLE if self.success else Status.COLLISION


@dataclass(frozen=True, kw_only=True)
class DownhandFigures:
    """The weld's position reached over the samples (the downhand rule, ``docs/positioner.md``).

    Attributes
    ----------
    max_slope
        Largest angle of the travel direction to the horizontal, rad.
    max_rotation
        Largest angle of the weld normal to straight up, rad.
    slope, rotation
        The rule's bounds, rad.
    share
        Share of the samples within both bounds, in [0, 1].
    """

    max_slope: float
    max_rotation: float
    slope: float
    rotation: float
    share: float

    def as_dict(self) -> dict[str, float]:
        """The figures as result.json writes them (rad, share)."""
        return {
            "max_slope": self.max_slope,
            "max_rotation": self.max_rotation,
            "slope": self.slope,
            "rotation": self.rotation,
            "share": self.share,
        }


@dataclass(frozen=True, eq=False, kw_only=True)
class CheckReport:
    """What the checker found, sample by sample.

    Attributes
    ----------
    success
        True when nothing is violated.
    joint_margins
        Per joint limit kind, shape (n,): the smallest unused fraction of the limit
        over all samples (1 = unused, 0 = reached, negative = exceeded). G <= 0 style:
        ``-margin`` is the normalised constraint value.
    task_margins
        Per task kind, the unused fraction of the task bound (tracking: of ρ; speed: of
        the speed cap; orientation: of the orientation tolerance; coverage: 1 or < 0).
    violations
        Every violation, in time order within each kind.
    max_tracking_error
        Largest distance of the tool point from the nominal path, m.
    max_orientation_error
        Largest tool orientation error, rad.
    binding
        For each joint limit kind, the (joint, time) at which it is closest to binding.
    cell
        The cell check, when the case has a cell.
    unchecked
        The status of a report with nothing checked (no trajectory: ``success`` false and
        no violations): why there was no trajectory. Ignored otherwise.
    downhand
        The weld's slope and rotation reached, when the task has a downhand rule.
    """

    success: bool
    joint_margins: dict[str, np.ndarray]
    task_margins: dict[str, float]
    violations: tuple[Violation, ...]
    max_tracking_error: float
    max_orientation_error: float
    binding: dict[str, tuple[int, float]] = field(default_factory=dict)
    cell: CellReport | None = None
    unchecked: Status = Status.UNREACHABLE
    downhand: DownhandFigures | None = None

    @classmethod
    def of_nothing(cls, status: Status) -> CheckReport:
        """The report on no trajectory: nothing checked, because of ``status``."""
        return cls(
            success=False,
            joint_margins={},
            task_margins={},
            violations=(),
            max_tracking_error=float("nan"),
            max_orientation_error=float("nan"),
            unchecked=status,
        )

    @property
    def status(self) -> Status:
        """The outcome of the check (:func:`violations_status` of the violations).

        :attr:`Status.FEASIBLE` when nothing is violated, :attr:`Status.COLLISION` when the
        only violations are the cell's, else :attr:`Status.LIMITS_VIOLATED`; a report of no
        trajectory (``success`` false, no violations) has :attr:`unchecked`.
        """
        if not self.success and not self.violations:
            return self.unchecked
        return violations_status(self.violations)

    def worst_margin(self) -> float:
        """The smallest margin over every limit (negative when infeasible); the margins of
        :data:`IGNORED_UNLESS_BROKEN` count only when negative. NaN when none counts."""
        values = [float(np.min(m)) for m in self.joint_margins.values()]
        values += [
            float(value)
            for kind, value in self.task_margins.items()
            if kind not in IGNORED_UNLESS_BROKEN or value < 0
        ]
        return min(values) if values else float("nan")


__all__ = [
    "CELL_KINDS",
    "IGNORED_UNLESS_BROKEN",
    "TASK_KINDS",
    "CellReport",
    "CheckReport",
    "Violation",
    "violations_status",
]
