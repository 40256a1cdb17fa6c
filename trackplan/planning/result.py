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
from trackplan.robots.model import LIMIT_KINDS
from trackplan.status import Status
from trackplan.timing.protocol import SlowDown


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


@dataclass(frozen=True, eq=False, kw_only=True)
class PlanResult:
    """One placement planned end to end.

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
        One line saying what happened (the first violation when infeasible).
    timing
        The time law (``smooth`` or ``paper``).
    branch
        IK branch used (closed form: 0-7; numeric: the seed index).
    trajectory
        The sampled trajectory (empty arrays when no trajectory could be built).
    check
        The checker's report on ``trajectory``.
    objective
        J of Eq. 8 from the written q.
    duration
        s.
    path_length
        Length of the nominal path, m.
    rated_speed_fraction
        Share of the straight-piece length run at the rated speed.
    min_corner_speed
        Lowest plateau speed on arcs and blends, m/s (rated speed when there are none).
    slowdowns
        Where straight pieces run below the rated speed.
    references
        Reference durations when computed: ``toppra_duration``, ``topp3_duration`` (s).
    joint_path
        The placed path's poses and IK on the planning grid
        (:class:`trackplan.jointpath.JointPath`).
    energy
        Mechanical energy, copper loss and peak torque ratio
        (:class:`trackplan.planning.energy.EnergyFigures`) when the robot has dynamics and
        a trajectory was built, else None.
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

    @property
    def planned_path(self) -> Path:
        """The planned (blended) path."""
        return self.joint_path.geometry.planned

    @property
    def nominal_path(self) -> NominalPath:
        """The path as the user gave it."""
        return self.joint_path.geometry.nominal

    @property
    def feasible(self) -> bool:
        """Alias of :attr:`success`: the plan passed every check."""
        return self.success


__all__ = [
    "LIMIT_KINDS",
    "TASK_KINDS",
    "CellReport",
    "CheckReport",
    "PlanResult",
    "Trajectory",
    "Violation",
]
