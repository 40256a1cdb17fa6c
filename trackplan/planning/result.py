"""Results of planning and checking: frozen dataclasses, never None on failure."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

# moved to trackplan.check_report; importers outside this package keep working
from trackplan.check_report import (  # noqa: F401
    IGNORED_UNLESS_BROKEN,
    TASK_KINDS,
    CellReport,
    CheckReport,
    Violation,
)
from trackplan.jointpath import JointPath
from trackplan.paths import NominalPath, Path
from trackplan.planning.energy import EnergyFigures
from trackplan.planning.sequence import Sequence
from trackplan.robots.model import LIMIT_KINDS
from trackplan.status import Status
from trackplan.timing.protocol import SlowDown
from trackplan.tool.weave import WeaveReached


@dataclass(frozen=True, eq=False, kw_only=True)
class Trajectory:
    """Joint trajectory sampled at the controller period, from rest to rest.

    Attributes
    ----------
    sample_time
        Ts, s.
    t
        Sample times, shape (N,), s; ``t[k] = k · Ts``.
    s
        Arc length on the planned path at each sample, shape (N,), m.
    q
        Joint positions, shape (N, n), rad.
    qd, qdd, qddd
        Backward differences of ``q`` at Ts with the robot at rest before the first
        sample (docs/conventions.md), shape (N, n), rad/s, rad/s², rad/s³.
    tool_position
        Tool point by FK in the base frame, shape (N, 3), m.
    speed
        Cartesian speed of the tool point (backward difference), shape (N,), m/s.
    spin
        Spin about the tool axis (``docs/tool.md``), shape (N,), rad.
    """

    sample_time: float
    t: np.ndarray
    s: np.ndarray
    q: np.ndarray
    qd: np.ndarray
    qdd: np.ndarray
    qddd: np.ndarray
    tool_position: np.ndarray
    speed: np.ndarray
    spin: np.ndarray = field(default_factory=lambda: np.zeros(0))

    @classmethod
    def empty(cls, n_dof: int, sample_time: float) -> Trajectory:
        """A trajectory with no samples (a placement that could not be planned)."""
        nothing = np.zeros((0, n_dof))
        return cls(
            sample_time=sample_time,
            t=np.zeros(0),
            s=np.zeros(0),
            q=nothing,
            qd=nothing,
            qdd=nothing,
            qddd=nothing,
            tool_position=np.zeros((0, 3)),
            speed=np.zeros(0),
        )

    @property
    def n_samples(self) -> int:
        """Number of samples N."""
        return len(self.t)

    @property
    def duration(self) -> float:
        """Time of the last sample, s."""
        return float(self.t[-1])


SEAM = "seam"
APPROACH = "approach"
RETRACT = "retract"
AIR = "air"
MOVE_KINDS = (APPROACH, RETRACT, AIR)
"""Labels of the moves between seams (a seam's samples carry its name)."""


@dataclass(frozen=True, eq=False, kw_only=True)
class Span:
    """One time span of a plan: a seam, or a move between configurations.

    Attributes
    ----------
    kind
        ``seam``, ``approach``, ``retract`` or ``air``.
    label
        The ``segment`` value of its samples: the seam name, or the kind.
    first, last
        Indices of its first and last sample in the plan's trajectory (inclusive; a span
        shares its first sample with the previous span's last).
    seam
        Index of the seam (as written) for seam, approach and retract spans, else None.
    reversed
        For a seam span: run end to start.
    via
        The via configuration of an air move through one, shape (n,), rad, else None.
    """

    kind: str
    label: str
    first: int
    last: int
    seam: int | None = None
    reversed: bool = False
    via: np.ndarray | None = None


@dataclass(frozen=True, eq=False, kw_only=True)
class SeamPlan:
    """One seam as planned at the plan's placement.

    Attributes
    ----------
    index
        The seam's index as written.
    name
        Its name.
    reversed
        Welded end to start.
    plan
        Its own single-seam plan (trajectory from rest to rest, its check).
    q_approach, q_retract
        Approach and retract configurations, shape (n,), rad (the seam's first and last
        configuration when the approach distance is 0).
    """

    index: int
    name: str
    reversed: bool
    plan: PlanResult
    q_approach: np.ndarray
    q_retract: np.ndarray


def _no_labels() -> np.ndarray:
    return np.zeros(0, dtype=object)


def _no_sequence() -> Sequence:
    return Sequence(visits=(), cost=float("nan"), exact=False)


@dataclass(frozen=True, eq=False, kw_only=True)
class PlanResult:
    """A case planned end to end at one placement: every seam, the moves between them, the
    whole trajectory and its check.

    With one seam, given sequence, no approach and no home, the trajectory is the seam's
    and every figure is that seam's. With several seams, the per-seam figures are stated
    below for the whole plan.

    Attributes
    ----------
    case_name
        Name of the case.
    placement
        X = (x, y, z, roll, pitch, yaw), shape (6,).
    success
        True when the checker found no violation (``status`` is ``FEASIBLE``).
    status
        See :class:`trackplan.status.Status`.
    message
        One line saying what happened (the first violation when infeasible; with several
        seams it names the seam).
    timing
        The time law (``smooth`` or ``paper``).
    branch
        IK branch used (closed form: its label; tracked: the solution of the first
        pose): the first welded seam's (the branch may differ from seam to seam, see :attr:`seams`).
    trajectory
        The sampled trajectory from rest to rest (empty arrays when no trajectory could be
        built); ``s`` is the arc length along the seam being welded (0 on moves).
    check
        The checker's report on ``trajectory``: joint limits and clearance at every
        sample, each seam's task checks (with several seams, violation messages name the
        seam, times in the whole trajectory).
    objective
        J of Eq. 8 from the written q (the whole trajectory).
    duration
        s (the whole cycle).
    path_length
        Length of the nominal paths, m: the sum over the seams.
    rated_speed_fraction
        Share of the straight-piece length run at the rated speed: length-weighted over
        the seams.
    min_corner_speed
        Lowest plateau speed on arcs and blends, m/s (rated speed when there are none):
        the lowest over the seams.
    slowdowns
        Where straight pieces run below the rated speed: every seam's in welding order
        (``s`` along its own seam).
    references
        Reference durations when computed: ``toppra_duration``, ``topp3_duration`` (s);
        one seam only.
    joint_path
        The placed path's poses and IK on the planning grid
        (:class:`trackplan.jointpath.JointPath`): the first welded seam's (with several
        seams, each seam's is in :attr:`seams`); the first unplanned seam's when some
        seam could not be planned.
    energy
        Mechanical energy, copper loss and peak torque ratio
        (:class:`trackplan.planning.energy.EnergyFigures`) of the whole trajectory when the
        robot has dynamics and a trajectory was built, else None.
    segment
        Label of every sample, shape (N,), str: the seam's name, or ``approach``,
        ``retract``, ``air``. The sample two spans share (at rest) carries the earlier
        span's label.
    spans
        The spans (seams and moves) in time order.
    seams
        The seams in the order welded (:class:`SeamPlan`).
    sequence
        The order and directions, and their estimated cost.
    seam_checks
        Each seam's own check (tracking, orientation, speed, coverage) in welding order.
    seam_time, air_time
        Time spent welding, and on approach, retract and air moves, s.
    approach_deviation
        Largest distance of the tool point from the tool axis line during approach and
        retract moves, m (0 without moves).
    unplanned
        Seam plans that failed (seam name → plan), when the seams could not be joined.
    weave
        The weave the samples reached (amplitude, frequency; ``task.weave``), or None; a
        case of several seams has each seam's on its plan in :attr:`seams`.
    """

    case_name: str
    placement: np.ndarray
    success: bool
    status: Status
    message: str
    timing: str
    branch: int
    trajectory: Trajectory
    check: CheckReport
    objective: float
    duration: float
    path_length: float
    rated_speed_fraction: float
    min_corner_speed: float
    slowdowns: tuple[SlowDown, ...]
    references: dict[str, float]
    joint_path: JointPath
    energy: EnergyFigures | None = None
    segment: np.ndarray = field(default_factory=_no_labels)
    spans: tuple[Span, ...] = ()
    seams: tuple[SeamPlan, ...] = ()
    sequence: Sequence = field(default_factory=_no_sequence)
    seam_checks: tuple[CheckReport, ...] = ()
    seam_time: float = float("nan")
    air_time: float = float("nan")
    approach_deviation: float = 0.0
    unplanned: dict[str, PlanResult] = field(default_factory=dict)
    weave: WeaveReached | None = None

    @property
    def planned_path(self) -> Path:
        """The planned (blended) path (the first welded seam's)."""
        return self.joint_path.geometry.planned

    @property
    def nominal_path(self) -> NominalPath:
        """The path as the user gave it (the first welded seam's)."""
        return self.joint_path.geometry.nominal

    @property
    def feasible(self) -> bool:
        """Alias of :attr:`success`: the plan passed every check."""
        return self.success


__all__ = [
    "AIR",
    "APPROACH",
    "LIMIT_KINDS",
    "MOVE_KINDS",
    "RETRACT",
    "SEAM",
    "TASK_KINDS",
    "CellReport",
    "CheckReport",
    "PlanResult",
    "SeamPlan",
    "Span",
    "Trajectory",
    "Violation",
]
