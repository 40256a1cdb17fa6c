"""A validated case: robot, path(s), task, placement bounds, objective and optimizer settings.

Pure data. :func:`trackplan.io.case_file.load_case` builds it from a YAML file;
a notebook can build it directly.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np

from trackplan.axes.rules import Downhand
from trackplan.cell.model import Cell
from trackplan.choices import Method, Penalty, choose
from trackplan.derived import derived
from trackplan.paths.specs import SegmentSpec
from trackplan.robots.machine import Machine, Positioner, Track
from trackplan.robots.model import Robot
from trackplan.task import Task

PLACEMENT_KEYS = ("x", "y", "z", "roll", "pitch", "yaw")


@dataclass(frozen=True, eq=False)
class PlacementBounds:
    """Search ranges of X = (x, y, z, roll, pitch, yaw) and the reach constraint (Eq. 28, 32).

    Attributes
    ----------
    lower, upper
        Shape (6,), metres and radians.
    reach
        (min, max) distance of (x, y, z) from the base origin, m.
    example
        A placement known to work (shape (6,)), or None.
    """

    lower: np.ndarray
    upper: np.ndarray
    reach: tuple[float, float]
    example: np.ndarray | None = None

    @property
    def center(self) -> np.ndarray:
        """Centre of the box, shape (6,)."""
        return 0.5 * (self.lower + self.upper)


@dataclass(frozen=True, eq=False)
class Objective:
    """Fitness settings (Eq. 8 and Eq. 30).

    Attributes
    ----------
    weights
        C_i of Eq. 8, shape (n,).
    time_weight
        Added to J per second of duration (0: the paper's objective).
    penalty
        ``"graded"``: infeasible candidates rank by distance from feasibility;
        ``"flat"``: the paper's constant M.
    flat_penalty
        The constant M of Eq. 30 for ``penalty="flat"``.
    kind
        What the search minimises: ``travel`` (Eq. 8, default), ``energy``, ``copper``,
        ``time`` or ``weighted`` (see :mod:`trackplan.planning.objectives`).
    mix
        For ``weighted``: coefficient of each objective by name.
    external_weights
        Weights of the external axes' travel (track per m, positioner axes per rad), in the
        machine's order; empty: 0 for each (only the arm's travel counts).
    """

    weights: np.ndarray
    time_weight: float = 0.0
    penalty: Penalty = Penalty.GRADED
    flat_penalty: float = 1.0e6
    kind: str = "travel"
    mix: dict[str, float] = field(default_factory=dict)
    external_weights: np.ndarray = field(default_factory=lambda: np.zeros(0))

    def __post_init__(self) -> None:
        object.__setattr__(self, "penalty", choose(Penalty, self.penalty, "objective.penalty"))


@dataclass(frozen=True)
class OptimizerSettings:
    """Placement search settings.

    Attributes
    ----------
    method
        The search method (:class:`trackplan.choices.Method`): ``multistart`` (default),
        ``ga`` (the paper's), ``cmaes``, ``de`` or ``random``.
    population
        Population size (candidates evaluated per batch; ``multistart`` sets its own
        batches).
    seed
        Fixes every random choice.
    budget
        Largest number of placement evaluations, or None for the method's own stop rule.
    restarts
        Independent runs of the method (fresh initial populations), the best kept; 1 is a
        single run as the paper made it. None: the method's own default (``ga``: 6, what
        it takes to land within 2 % of the best known J on every paper case and seed 0-4;
        ``multistart``: 1, see ``docs/search.md``).
    """

    method: Method = Method.MULTISTART
    population: int = 30
    seed: int = 0
    budget: int | None = None
    restarts: int | None = None

    def __post_init__(self) -> None:
        object.__setattr__(self, "method", choose(Method, self.method, "optimizer.method"))


@dataclass(frozen=True, eq=False)
class Seam:
    """One named path of a workpiece with several seams (``paths:`` in the case file).

    Attributes
    ----------
    name
        Seam name, unique in the case.
    start
        First point in the definition frame, shape (3,), m.
    segments
        The path segments, in order.
    task
        The seam's task: the case's ``task`` with the seam's own overrides.
    reversible
        Whether the seam may be welded end to start.
    """

    name: str
    start: np.ndarray
    segments: tuple[SegmentSpec, ...]
    task: Task
    reversible: bool = True


CSV_UNSAFE = ',"\t\r\n'
"""Characters a seam label may not hold: it is a field of trajectory.csv's ``segment``."""
FORMULA_START = "=+-@"
"""First characters a spreadsheet runs as a formula."""


def seam_label(name: str) -> str:
    """The name of a single-path case's seam: the case name as a trajectory.csv field
    (each of :data:`CSV_UNSAFE` replaced by ``_``, and ``_`` put before a first
    character of :data:`FORMULA_START`), as the case file asks of ``paths[i].name``."""
    label = "".join("_" if c in CSV_UNSAFE else c for c in name)
    return "_" + label if label[:1] in FORMULA_START and label else label


SEQUENCE_MODES = ("optimize", "given")
"""How the seams of a case are ordered: chosen (order and direction), or as written."""


@dataclass(frozen=True, eq=False)
class Sequencing:
    """How the seams of a case are joined into one cycle (``docs/seams.md``).

    Attributes
    ----------
    sequence
        ``given`` (as written, forward; the default) or ``optimize`` (order and
        directions chosen).
    approach
        Approach and retract distance along the tool axis at each seam end, m (≥ 0;
        0: the seam ends are the cycle's ends).
    home
        Joint configuration the cycle starts from and returns to, shape (n,), rad, or
        None to start at the first approach pose and end at the last retract pose.
    """

    sequence: str = "given"
    approach: float = 0.0
    home: np.ndarray | None = None


@dataclass(frozen=True, eq=False)
class Case:
    """Everything needed to plan and optimize a path-following task: a set of seams.

    A case built from ``start``, ``segments`` and ``task`` is one seam (named after the
    case, not reversible); a case with several seams (``paths:`` in the case file) gives
    them in ``seams``, and then ``start``, ``segments`` and ``task`` are those of its first
    seam.

    Attributes
    ----------
    name
        Case name.
    robot
        The robot.
    start
        First point of the (first) path in the definition frame, shape (3,), m.
    segments
        The (first) path's segments, in order.
    task, bounds, objective, optimizer
        See the classes.
    source
        The case file, if the case came from one.
    cell
        The work cell (obstacles, workpiece, tool and link bodies), or None to plan
        without collision checks.
    paths
        The seams of a case file's ``paths:``, or empty for the one path of ``start``,
        ``segments`` and ``task``; read them as :attr:`seams`.
    sequencing
        The sequence mode, approach distance and home configuration of the cycle.
    robot_tool
        When the case file gives the TCP (``tcp:``, ``docs/files.md``): the robot's own
        ``T_flange_tool`` that it replaced, shape (4, 4) (the identity for a robot without
        a tool); None when the TCP is the robot's own. ``robot.T_flange_tool`` is the TCP
        used either way.
    track
        The linear axis that carries the arm (``track:``), or None.
    positioner
        The positioner that turns the part (``positioner:``), or None; with one, the
        placement X places the part on its flange.
    downhand
        The downhand rule (``downhand:``), or None.
    """

    name: str
    robot: Robot
    start: np.ndarray
    segments: tuple[SegmentSpec, ...]
    task: Task
    bounds: PlacementBounds
    objective: Objective
    optimizer: OptimizerSettings = field(default_factory=OptimizerSettings)
    source: str | None = None
    cell: Cell | None = None
    paths: tuple[Seam, ...] = ()
    sequencing: Sequencing = field(default_factory=Sequencing)
    robot_tool: np.ndarray | None = None
    track: Track | None = None
    positioner: Positioner | None = None
    downhand: Downhand | None = None

    @property
    def travel_weights(self) -> np.ndarray:
        """The weight of every joint of :attr:`machine` in the travel (Eq. 8), shape (n,):
        ``objective.weights`` for the arm, ``objective.external_weights`` (or 0) for the
        external axes."""
        n_external = self.machine.n_dof - self.robot.n_dof
        external = np.asarray(self.objective.external_weights, dtype=float)
        if external.size == 0:
            external = np.zeros(n_external)
        return np.concatenate([np.asarray(self.objective.weights, dtype=float), external])

    @property
    def machine(self) -> Robot | Machine:
        """What the planner moves: the robot, or with a track or a positioner the
        :class:`~trackplan.robots.machine.Machine` of the robot and its external axes
        (one joint vector: the robot's joints, the track, the positioner's axes)."""
        if self.track is None and self.positioner is None:
            return self.robot
        return derived(self, "machine", lambda: Machine(self.robot, self.track, self.positioner))

    @property
    def tcp_source(self) -> str:
        """Where the TCP used (``robot.T_flange_tool``) comes from: ``case`` (the case
        file's ``tcp``), ``robot`` (the robot's own tool) or ``none`` (the flange)."""
        if self.robot_tool is not None:
            return "case"
        return "robot" if self.robot.has_tool else "none"

    @property
    def seams(self) -> tuple[Seam, ...]:
        """The seams, at least one: ``paths``, or the one seam of ``start``, ``segments``
        and ``task`` (named :func:`seam_label` of the case name, not reversible);
        :meth:`seam_case` gives the single-seam case of every seam."""
        if self.paths:
            return self.paths
        own = Seam(seam_label(self.name), self.start, self.segments, self.task, reversible=False)
        return (own,)

    @property
    def seam_names(self) -> tuple[str, ...]:
        """Seam names in the order written."""
        return tuple(seam.name for seam in self.seams)

    def seam_case(self, index: int) -> Case:
        """The single-seam case of seam ``index`` (its path and task, the case's robot,
        cell, bounds, objective and optimizer; named after the seam; given sequence, no
        approach, no home)."""
        seam = self.seams[index]
        if (
            len(self.seams) == 1
            and self.sequencing.approach == 0.0
            and self.sequencing.home is None
        ):
            return self
        return replace(
            self,
            name=seam.name,
            start=seam.start,
            segments=seam.segments,
            task=seam.task,
            paths=(),
            sequencing=Sequencing(),
        )
