"""What every time law takes and gives.

A :class:`TimeLaw` turns a :class:`~trackplan.jointpath.JointPath` and the task into a
:class:`TimedPath`: samples ``s(k·Ts)`` and ``q(k·Ts)`` from rest to rest. Laws are
looked up by name in :data:`trackplan.timing.TIME_LAWS`; a new law is a module with a
:class:`TimeLaw`, added there (``docs/architecture.md``).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from trackplan.choices import Timing
from trackplan.jointpath import JointPath
from trackplan.motion import JointSamples
from trackplan.paths.path_geometry import PathMode
from trackplan.status import Status
from trackplan.task import Task


@dataclass(frozen=True)
class SlowDown:
    """A stretch of a straight piece run below the rated speed.

    Attributes
    ----------
    s_start, s_end
        Arc length on the planned path, m.
    speed
        Speed held there, m/s.
    rated_speed
        The rated speed, m/s.
    limit
        What forced it (e.g. ``"joint 4 velocity"``).
    """

    s_start: float
    s_end: float
    speed: float
    rated_speed: float
    limit: str


@dataclass(frozen=True, eq=False)
class TimedPath:
    """What a time law gives: arc length and joints at each Ts, from rest to rest.

    Attributes
    ----------
    timing
        The law that made it.
    success
        True when samples were produced that the law itself planned within every limit
        (the checker still decides feasibility).
    status
        :attr:`Status.FEASIBLE`, or why there are no samples (or why the law gave up).
    message
        One line: empty on success, else what went wrong and where.
    sample_time
        Ts, s.
    s
        Arc length on the planned path at each sample, shape (N,), m (empty when nothing
        could be sampled).
    q
        Joint positions at each sample, shape (N, n), rad.
    slowdowns
        Where straight pieces run below the rated speed, and why.
    corner_speed
        Lowest speed planned on arcs and blends, m/s (nan when the law does not say).
    iterations
        Rebuilds the law needed (1 for a law that builds once).
    motion
        The samples ``q`` with the derivatives and torques the law's sample checks computed
        (:class:`~trackplan.motion.JointSamples`), for the checker to read again; None
        when the law checked nothing.
    """

    timing: Timing
    success: bool
    status: Status
    message: str
    sample_time: float
    s: np.ndarray
    q: np.ndarray
    slowdowns: tuple[SlowDown, ...] = ()
    corner_speed: float = float("nan")
    iterations: int = 1
    motion: JointSamples | None = None

    @property
    def duration(self) -> float:
        """Time of the last sample, s (0 without samples)."""
        return max(len(self.s) - 1, 0) * self.sample_time


TimeLawPlanner = Callable[[JointPath, Task], TimedPath]
"""``plan(joint_path, task) -> TimedPath``: the signature of every law."""


@dataclass(frozen=True)
class TimeLaw:
    """A time law: its name, the planned path it needs and the function that times it.

    Attributes
    ----------
    timing
        Its name.
    path_mode
        The planned path it needs (``g2`` blends, or the paper's tangent arcs).
    plan
        The law itself.
    follows_joint_path
        True when the samples are exact IK solutions of the planned path, so that the
        joint travel J of the geometric joint path is the plan's J. False for a law that
        makes its own joints (the paper's resolved-rate IK): a search must then plan every
        candidate to know its J.
    """

    timing: Timing
    path_mode: PathMode
    plan: TimeLawPlanner
    follows_joint_path: bool = True


def unsampled(
    timing: Timing, status: Status, message: str, sample_time: float, n_dof: int
) -> TimedPath:
    """A law that produced no samples, with why."""
    return TimedPath(
        timing=timing,
        success=False,
        status=status,
        message=message,
        sample_time=sample_time,
        s=np.zeros(0),
        q=np.zeros((0, n_dof)),
    )
