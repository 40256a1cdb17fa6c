"""What a writer exports: a trajectory table, and on demand the replayed run and its program.

:class:`ExportSource` is the one argument of :meth:`Writer.write
<trackplan.writers.protocol.Writer.write>`. The trajectory writers read :attr:`table`; the
program writers call :meth:`ExportSource.program`, which replays the run folder
(:func:`~trackplan.programs.replay.replay_run`, once) and builds the program in no language
(:func:`trackplan.programs.build.build_program`, once per set of arguments).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field, replace
from functools import cached_property
from pathlib import Path
from typing import TYPE_CHECKING, Any

from trackplan.errors import CaseError
from trackplan.io.export import (
    TrajectoryTable,
    checked_joint_names,
    read_trajectory_table,
    trajectory_file,
)
from trackplan.io.run_folder import verified_trajectory
from trackplan.planning.result import Trajectory
from trackplan.programs.build import build_program
from trackplan.programs.replay import ReplayedRun, replay_run
from trackplan.run_files import RESULT_FILE, TRAJECTORY_FILE

if TYPE_CHECKING:
    from trackplan.case import Case
    from trackplan.programs.model import MotionForm, Program
    from trackplan.robots.model import Robot


@dataclass(eq=False, kw_only=True)
class ExportSource:
    """A trajectory to export, with the run it comes from when there is one.

    Attributes
    ----------
    table
        The trajectory: times (N,) s, joints (N, n) rad, their rates, with joint names.
    folder
        The run folder (``trajectory.csv`` with its ``result.json``), or None for a
        trajectory held in memory or a CSV file that is no run's.
    case
        The case the run was planned from, when given (a Case or a case file; ``--case``);
        None: the case file ``result.json`` records.
    replayed
        The replayed run when already known (a plan in memory,
        :func:`~trackplan.programs.replay.replay_plan`); else :attr:`run` replays
        :attr:`folder` on first use.
    csv_file
        The CSV file the table was read from (the run's ``trajectory.csv``, or any CSV
        file), or None for a trajectory held in memory: an export never replaces it.
    """

    table: TrajectoryTable
    folder: Path | None = None
    case: Case | Path | str | None = None
    replayed: ReplayedRun | None = None
    csv_file: Path | None = None
    _programs: dict[tuple[Any, ...], Program] = field(default_factory=dict, init=False, repr=False)

    @classmethod
    def of(
        cls,
        source: Path | str | Trajectory | ReplayedRun | ExportSource,
        *,
        joint_names: Sequence[str] | None = None,
        case: Case | Path | str | None = None,
    ) -> ExportSource:
        """The export source of a run folder, a CSV file, a trajectory or a replayed run.

        Parameters
        ----------
        source
            A run folder (read through
            :func:`~trackplan.io.run_folder.verified_trajectory`: its hash is checked), a
            ``trajectory.csv`` (of a run when a ``result.json`` is beside it), a
            :class:`~trackplan.planning.result.Trajectory` in memory, a
            :class:`~trackplan.programs.replay.ReplayedRun`, or an :class:`ExportSource`
            (returned as it is, the arguments below applied).
        joint_names
            Replace the table's joint names (else ``result.json``'s, else ``q1..qn``).
        case
            The case the run was planned from, for the program writers.

        Raises
        ------
        CaseError
            For a missing or malformed trajectory or ``result.json``, an empty trajectory
            in memory, or wrong joint names.
        """
        if isinstance(source, ExportSource):
            made = source
        elif isinstance(source, ReplayedRun):
            csv_file = None if source.folder is None else source.folder / TRAJECTORY_FILE
            made = cls(table=source.table, folder=source.folder, replayed=source, csv_file=csv_file)
        elif isinstance(source, Trajectory):
            if source.n_samples == 0:
                raise CaseError("the trajectory has no sample", key="trajectory")
            made = cls(table=TrajectoryTable.from_trajectory(source, joint_names))
        else:
            path = Path(source)
            csv_file = verified_trajectory(path) if path.is_dir() else trajectory_file(path)
            folder = path if path.is_dir() else _run_folder_of(csv_file)
            made = cls(table=read_trajectory_table(csv_file), folder=folder, csv_file=csv_file)
        if joint_names is not None:
            names = checked_joint_names(joint_names, made.table.q.shape[1], "joint_names", None)
            made = replace(made, table=replace(made.table, joint_names=names))
        if case is not None:
            made = replace(made, case=case)
        return made

    @cached_property
    def run(self) -> ReplayedRun:
        """The run replayed (:func:`~trackplan.programs.replay.replay_run`), once.

        Raises
        ------
        CaseError
            When there is no run folder, or the run cannot be replayed (no case, another
            case, an edited trajectory: key ``--case``).
        """
        if self.replayed is not None:
            return self.replayed
        if self.folder is None:
            raise CaseError(
                "a program needs a run folder (trajectory.csv with its result.json), not a "
                "trajectory held in memory or a bare CSV file",
                key="run",
            )
        return replay_run(self.folder, self.case)

    def program(
        self,
        *,
        motion: MotionForm = "cartesian",
        name: str | None = None,
        period: float | None = None,
        force: bool = False,
    ) -> Program:
        """The run's program in no language, built once per set of arguments.

        Parameters
        ----------
        motion
            ``cartesian`` (the seams in path moves) or ``joint`` (the verified samples).
        name
            The program name (made a valid identifier by the writer); default the case's.
        period
            Time between joint targets with ``joint``, s: a multiple of the run's sample
            time (the builder checks it); default every sample.
        force
            Build the program of an infeasible run too (the verdict goes to the header).

        Returns
        -------
        Program
            :func:`trackplan.programs.build.build_program` of :attr:`run`.

        Raises
        ------
        CaseError
            From :attr:`run`, or from the builder (an infeasible run without ``force``, a
            bad period).
        """
        key = (motion, name, period, force)
        if key not in self._programs:
            self._programs[key] = build_program(
                self.run, motion=motion, name=name, period=period, force=force
            )
        return self._programs[key]

    def program_of(self, options: Mapping[str, Any]) -> Program:
        """:meth:`program` with the export options a writer is given (``motion``,
        ``name``, ``period``, ``force``; the others are ignored)."""
        return self.program(
            motion=options.get("motion") or "cartesian",
            name=options.get("name"),
            period=options.get("period"),
            force=bool(options.get("force", False)),
        )

    @property
    def robot(self) -> Robot:
        """The robot of the run (:attr:`run`'s case)."""
        return self.run.case.robot


def _run_folder_of(csv_file: Path) -> Path | None:
    """The run folder of a ``trajectory.csv`` with a ``result.json`` beside it, else None."""
    if csv_file.name == TRAJECTORY_FILE and (csv_file.parent / RESULT_FILE).is_file():
        return csv_file.parent
    return None


__all__ = ["ExportSource"]
