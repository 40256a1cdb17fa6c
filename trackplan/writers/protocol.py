"""The writer protocol and the registry of writers by name.

A writer turns a :class:`~trackplan.io.export.TrajectoryTable` into one file of its format.
:func:`register_writer` adds one to :data:`WRITERS`; :func:`writer_named` and
:func:`writer_for_file` pick one by name or by the output file's suffix, so the code that
exports (:func:`trackplan.writers.export`) has no branch per format. See ``docs/results.md``.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any, Protocol, runtime_checkable

from trackplan.errors import CaseError
from trackplan.io.export import TrajectoryTable


@runtime_checkable
class Writer(Protocol):
    """One export format.

    Attributes
    ----------
    name
        The format's name as ``--format`` takes it (lower case, unique).
    suffix
        The file suffix that picks this writer when no format is given (``".csv"``), lower case.
    default_file
        The file name written next to ``trajectory.csv`` when no output is given; it ends
        with ``suffix``.
    """

    @property
    def name(self) -> str:
        """The format's name (``csv``)."""
        ...

    @property
    def suffix(self) -> str:
        """The file suffix that picks the writer (``.csv``)."""
        ...

    @property
    def default_file(self) -> str:
        """The file written next to ``trajectory.csv`` by default."""
        ...

    def write(self, table: TrajectoryTable, output: Path, **options: Any) -> None:
        """Write ``table`` to the file ``output`` (a new file: the caller renames it into place).

        Parameters
        ----------
        table
            The trajectory: times (N,) in s, joint columns (N, n) in rad and their rates.
        output
            The file to write; its folder exists.
        **options
            Format options (``frame_id`` for ROS); a writer ignores those it does not take.
        """
        ...


WRITERS: dict[str, Writer] = {}
"""The registered writers by name, in registration order."""


def register_writer(writer: Writer) -> Writer:
    """Add a writer to :data:`WRITERS`.

    Parameters
    ----------
    writer
        Any object with ``name``, ``suffix``, ``default_file`` and ``write``.

    Returns
    -------
    Writer
        ``writer`` itself, so the call can decorate an instance's assignment.

    Raises
    ------
    ValueError
        When the name or the suffix is taken by another writer, or the default file does not
        end with the suffix (a programming error, not bad input).
    """
    name, suffix = writer.name.lower(), writer.suffix.lower()
    if name in WRITERS and WRITERS[name] is not writer:
        raise ValueError(f"a writer named {name!r} is registered already")
    taken = [other.name for other in WRITERS.values() if other.suffix == suffix]
    if taken and taken != [name]:
        raise ValueError(f"the suffix {suffix!r} belongs to the {taken[0]!r} writer already")
    if not writer.default_file.lower().endswith(suffix):
        raise ValueError(f"{writer.default_file!r} does not end with {suffix!r}")
    WRITERS[name] = writer
    return writer


def writer_named(name: str) -> Writer:
    """The writer called ``name`` (any case).

    Raises
    ------
    CaseError
        ``unknown export format``, listing the registered names (key ``format``).
    """
    name = name.lower()
    writer = WRITERS.get(name)
    if writer is None:
        raise CaseError(
            f"unknown export format {name!r}: use one of {', '.join(WRITERS)}", key="format"
        )
    return writer


def writer_for_file(output: Path) -> Writer:
    """The writer whose suffix ends ``output``'s name (the longest suffix wins).

    Raises
    ------
    CaseError
        When no writer's suffix matches, listing the suffixes (key ``format``).
    """
    file_name = output.name.lower()
    matches = [writer for writer in WRITERS.values() if file_name.endswith(writer.suffix)]
    if not matches:
        suffixes = ", ".join(f"{writer.suffix} ({writer.name})" for writer in WRITERS.values())
        raise CaseError(
            f"no export format for {output.name!r}: give --format, or a file ending in "
            f"one of {suffixes}",
            key="format",
        )
    return max(matches, key=lambda writer: len(writer.suffix))
