"""Export a run through a registered writer, picked by name or file suffix.

:func:`export` makes the :class:`~trackplan.writers.source.ExportSource`, picks the writer
(:mod:`trackplan.writers.protocol`), lets it write its files into a fresh staging folder
beside the output, refuses any file that would replace one of the run's own, and moves
each file into place by an atomic rename; it holds no branch per format. A writer that
fails leaves nothing behind.
"""

from __future__ import annotations

import os
import shutil
import tempfile
from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

from trackplan.errors import CaseError
from trackplan.io.run_folder import OWNED_FILES
from trackplan.planning.result import Trajectory
from trackplan.programs.replay import ReplayedRun
from trackplan.writers.protocol import WRITERS, Writer, writer_for_file, writer_named
from trackplan.writers.source import ExportSource

if TYPE_CHECKING:
    from trackplan.case import Case

STAGING_PREFIX = ".trackplan-export-"
"""Name prefix of the hidden folder a writer writes into before its files move into place."""


def export(
    source: Path | str | Trajectory | ReplayedRun | ExportSource,
    output: Path | str | None = None,
    *,
    format: str | None = None,
    joint_names: Sequence[str] | None = None,
    case: Case | Path | str | None = None,
    **options: Any,
) -> Path:
    """Export a run with the writer of ``format``, or of ``output``'s suffix.

    Parameters
    ----------
    source
        A run directory, its ``trajectory.csv``, a trajectory in memory, a replayed run
        (:func:`~trackplan.programs.replay.replay_plan`) or an
        :class:`~trackplan.writers.source.ExportSource`. A program format needs a run
        (a folder, or a replayed run).
    output
        One-file writers: the file to write; by default the writer's ``default_file`` next
        to ``trajectory.csv`` (``trajectory.export.csv``, ``trajectory.json``,
        ``trajectory.ros.yaml``); an existing directory receives that name. Writers of
        several files (``folder``): the folder to write them into, created when missing;
        by default ``default_file`` next to ``trajectory.csv`` (``RUN/krl/``). Required
        for a source held in memory.
    format
        A registered writer's name (any case). When None, the one-file writer whose
        suffix ends ``output``'s name (``.csv``, ``.json``, ``.yaml``).
    joint_names
        Overrides the joint names (else ``result.json``'s ``joint_names``, else ``q1..qn``).
    case
        The case the run was planned from (a Case or a case file) for a program format;
        default the ``case_file`` that ``result.json`` records.
    **options
        Passed to the writer: ``frame_id`` (``header.frame_id``) for ``ros``; ``motion``,
        ``name``, ``period``, ``max_points``, ``force`` for the program formats.

    Returns
    -------
    pathlib.Path
        The main file written (the first the writer names).

    Raises
    ------
    CaseError
        For an unknown format, no format and no output file to pick one by, a missing or
        malformed ``trajectory.csv`` or ``result.json``, wrong joint names, an output that
        is one of the run's files or not a regular file (a folder writer's: not a folder),
        no ``output`` for a source held in memory, or what the writer refuses (a run that
        does not replay, a robot the format cannot drive).
    """
    return export_files(
        source, output, format=format, joint_names=joint_names, case=case, **options
    )[0]


def export_files(
    source: Path | str | Trajectory | ReplayedRun | ExportSource,
    output: Path | str | None = None,
    *,
    format: str | None = None,
    joint_names: Sequence[str] | None = None,
    case: Case | Path | str | None = None,
    **options: Any,
) -> tuple[Path, ...]:
    """:func:`export`, returning every file written, main file first."""
    writer = _chosen_writer(format, None if output is None else Path(output))
    made = ExportSource.of(source, joint_names=joint_names, case=case)
    if output is not None:
        target = Path(output)
    elif made.csv_file is not None:
        target = made.csv_file.parent / writer.default_file
    else:
        raise CaseError(
            f"an output {'folder' if writer.folder else 'file'} is needed to export a "
            "trajectory held in memory",
            key="output",
        )
    if writer.folder:
        if target.exists() and not target.is_dir():
            raise CaseError(f"{str(target)!r} is not a folder; give a folder", key="output")
        destination = target
    else:
        if target.is_dir():
            target = target / writer.default_file
        _check_file(target, made.csv_file)
        destination = target.parent
        options = {**options, "file_name": target.name}
    return _write_through_staging(writer, made, destination, options)


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


def _write_through_staging(
    writer: Writer, source: ExportSource, destination: Path, options: dict[str, Any]
) -> tuple[Path, ...]:
    """Let the writer write into a staging folder in ``destination``, then move its files.

    Every file is checked before any is moved (none may be the run's own, or replace
    something that is not a regular file); then each moves by an atomic rename. A writer
    that raises leaves nothing behind: the staging folder goes, and so does
    every folder this call created for ``destination``.
    """
    created = None if destination.exists() else destination  # the first folder made here
    while created is not None and not created.parent.exists():
        created = created.parent
    try:
        destination.mkdir(parents=True, exist_ok=True)
        staging = Path(tempfile.mkdtemp(prefix=STAGING_PREFIX, dir=destination))
    except OSError as error:
        raise CaseError(
            f"cannot write to {str(destination)!r}: {error.strerror}", key="output"
        ) from None
    try:
        names = writer.write(source, staging, **options)
        _check_names(writer, names, staging)
        targets = tuple(destination / name for name in names)
        for target in targets:
            _check_file(target, source.csv_file)
        for name, target in zip(names, targets, strict=True):
            os.replace(staging / name, target)
    except BaseException:
        shutil.rmtree(staging, ignore_errors=True)
        if created is not None:
            shutil.rmtree(created, ignore_errors=True)
        raise
    shutil.rmtree(staging, ignore_errors=True)
    return targets


def _check_names(writer: Writer, names: tuple[str, ...], staging: Path) -> None:
    """The writer's names: at least one, plain, distinct, each a file it wrote (else a
    programming error, ValueError)."""
    if not names or len(set(names)) != len(names):
        raise ValueError(f"the {writer.name!r} writer must name each file it wrote once")
    for name in names:
        if Path(name).name != name or name in (".", "..") or not (staging / name).is_file():
            raise ValueError(f"the {writer.name!r} writer names {name!r}, not a file it wrote")


def _check_file(target: Path, csv_file: Path | None) -> None:
    """Refuse a target that exists but is no regular file, or is one of the run's files."""
    if target.exists() and not target.is_file():  # a device or a FIFO: never replaced
        raise CaseError(f"{str(target)!r} is not a regular file; give a file name", key="output")
    if csv_file is not None:
        _refuse_run_file(target, csv_file)


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
