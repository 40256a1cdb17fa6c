"""Export a run's trajectory through a registered writer, picked by name or file suffix.

:func:`export` reads the table (:func:`~trackplan.io.export.read_trajectory_table`), picks
the writer (:mod:`trackplan.writers.protocol`), refuses an output that is one of the run's own
files, and writes atomically; it holds no branch per format.
"""

from __future__ import annotations

import os
from collections.abc import Sequence
from dataclasses import replace
from pathlib import Path
from typing import Any

from trackplan.errors import CaseError
from trackplan.io.export import (
    TrajectoryTable,
    checked_joint_names,
    read_trajectory_table,
    trajectory_file,
)
from trackplan.io.run_folder import OWNED_FILES, verified_trajectory, write_atomically
from trackplan.planning.result import Trajectory
from trackplan.writers.protocol import WRITERS, Writer, writer_for_file, writer_named


def export(
    source: Path | str | Trajectory,
    output: Path | str | None = None,
    *,
    format: str | None = None,
    joint_names: Sequence[str] | None = None,
    **options: Any,
) -> Path:
    """Export a trajectory with the writer of ``format``, or of ``output``'s suffix.

    Parameters
    ----------
    source
        A run directory, its ``trajectory.csv``, or a trajectory in memory.
    output
        The file to write; by default the writer's ``default_file`` next to
        ``trajectory.csv`` (``trajectory.export.csv``, ``trajectory.json``,
        ``trajectory.ros.yaml``); an existing directory receives that name. Required when
        ``source`` is a :class:`~trackplan.planning.result.Trajectory`.
    format
        A registered writer's name (``csv``, ``json``, ``ros``; any case). When None, the
        writer whose suffix ends ``output``'s name (``.csv``, ``.json``, ``.yaml``).
    joint_names
        Overrides the joint names (else ``result.json``'s ``joint_names``, else ``q1..qn``).
    **options
        Passed to the writer: ``frame_id`` (``header.frame_id``) for ``ros``.

    Returns
    -------
    pathlib.Path
        The file written.

    Raises
    ------
    CaseError
        For an unknown format, no format and no output file to pick one by, a missing or
        malformed ``trajectory.csv`` or ``result.json``, wrong joint names, an output that
        is one of the run's files or not a regular file, or no ``output`` for an in-memory
        trajectory.
    """
    writer = _chosen_writer(format, None if output is None else Path(output))
    csv_file: Path | None = None
    if isinstance(source, Trajectory):
        if output is None:
            raise CaseError(
                "an output file is needed to export a trajectory held in memory", key="output"
            )
        if source.n_samples == 0:
            raise CaseError("the trajectory has no sample", key="trajectory")
        table = TrajectoryTable.from_trajectory(source, joint_names)
        target = Path(output)
    else:
        source = Path(source)
        csv_file = verified_trajectory(source) if source.is_dir() else trajectory_file(source)
        table = read_trajectory_table(csv_file)
        if joint_names is not None:
            names = checked_joint_names(joint_names, table.q.shape[1], "joint_names", None)
            table = replace(table, joint_names=names)
        target = csv_file.parent / writer.default_file if output is None else Path(output)
    if target.is_dir():
        target = target / writer.default_file
    if target.exists() and not target.is_file():  # a device or a FIFO: never replaced
        raise CaseError(f"{str(target)!r} is not a regular file; give a file name", key="output")
    if csv_file is not None:
        _refuse_run_file(target, csv_file)
    target.parent.mkdir(parents=True, exist_ok=True)
    write_atomically(target, lambda file: writer.write(table, file, **options))
    return target


def export_trajectory(
    source: Path | str | Trajectory,
    fmt: str,
    output: Path | str | None = None,
    *,
    joint_names: Sequence[str] | None = None,
    frame_id: str = "",
) -> Path:
    """:func:`export` with the format first: ``export_trajectory(run, "ros")``."""
    return export(source, output, format=fmt, joint_names=joint_names, frame_id=frame_id)


def _chosen_writer(format: str | None, output: Path | None) -> Writer:
    """The writer named ``format``, else the one of ``output``'s suffix."""
    if format is not None:
        return writer_named(format)
    if output is None or output.is_dir():
        raise CaseError(
            f"no export format: give one of {', '.join(WRITERS)}, or an output file", key="format"
        )
    return writer_for_file(output)


def _refuse_run_file(target: Path, csv_file: Path) -> None:
    """Refuse an output that is the source ``trajectory.csv`` or another file of its run.

    Paths are compared resolved (``..``, symbolic links), and by inode when both exist
    (hard links).
    """
    run_files = {csv_file, *(csv_file.parent / name for name in OWNED_FILES)}
    resolved = target.resolve()
    for own in run_files:
        same = resolved == own.resolve()
        if not same and target.exists() and own.exists():
            same = os.path.samefile(target, own)
        if same:
            raise CaseError(
                f"{str(target)!r} is the run's own {own.name}: exporting there would replace "
                "it; give another file",
                key="output",
            )
