"""The writer protocol and the registry of writers by name.

A writer writes one export format: a trajectory file (``csv``, ``json``, ``ros``) or a
controller program (``krl``, ``rapid``, ``fanuc``, ``urscript``) of one or several files.
It takes an :class:`~trackplan.writers.source.ExportSource` (the trajectory table, and on
demand the replayed run and the program built from it) and writes its files into a fresh
staging folder; :func:`trackplan.writers.export` moves them into place.
:func:`register_writer` adds a writer to :data:`WRITERS`; :func:`writer_named` and
:func:`writer_for_file` pick one by name or by the output file's suffix, so the code that
exports has no branch per format. See ``docs/results.md``.
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Any, Protocol, runtime_checkable

from trackplan.errors import CaseError

if TYPE_CHECKING:
    from trackplan.writers.source import ExportSource


@runtime_checkable
class Writer(Protocol):
    """One export format.

    Attributes
    ----------
    name
        The format's name as ``--format`` takes it (lower case, unique).
    suffix
        The suffix of its (main) file (``".csv"``, ``".src"``, ``".script"``), lower case;
        it picks a one-file writer when no format is given.
    default_file
        The default output next to ``trajectory.csv``: a file name ending with ``suffix``,
        or for a writer of several files the folder's name (``"krl"``).
    folder
        True for a writer of several files: its output is a folder, and it names its files
        itself; False for a writer of one file (written as ``options["file_name"]``).
    """

    @property
    def name(self) -> str:
        """The format's name (``csv``)."""
        ...

    @property
    def suffix(self) -> str:
        """The suffix of the (main) file (``.csv``)."""
        ...

    @property
    def default_file(self) -> str:
        """The file, or folder, written next to ``trajectory.csv`` by default."""
        ...

    @property
    def folder(self) -> bool:
        """True when the writer writes several files into a folder."""
        ...

    def write(self, source: ExportSource, folder: Path, **options: Any) -> tuple[str, ...]:
        """Write the format's files into ``folder`` and return their names, main file first.

        Parameters
        ----------
        source
            What to export: ``source.table`` (times (N,) s, joints (N, n) rad and their
            rates), ``source.run`` (the replayed run) and ``source.program(...)`` (the
            program in no language) for the program writers.
        folder
            A fresh, empty staging folder; the caller moves the files into place
            atomically, each by a rename, and removes the folder.
        **options
            ``file_name`` (the file a one-file writer writes), and format options:
            ``frame_id`` (ROS), ``motion``, ``name``, ``period``, ``max_points``, ``force``
            (programs); a writer ignores those it does not take.

        Returns
        -------
        tuple of str
            The names of the files written, plain names in ``folder``, main file first.
        """
        ...


WRITERS: dict[str, Writer] = {}
"""The registered writers by name, in registration order."""


def register_writer(writer: Writer) -> Writer:
    """Add a writer to :data:`WRITERS`.

    Parameters
    ----------
    writer
        Any object with ``name``, ``suffix``, ``default_file``, ``folder`` and ``write``.

    Returns
    -------
    Writer
        ``writer`` itself, so the call can decorate an instance's assignment.

    Raises
    ------
    ValueError
        When the name or the suffix is taken by another writer, or a one-file writer's
        default file does not end with the suffix (a programming error, not bad input).
    """
    name, suffix = writer.name.lower(), writer.suffix.lower()
    if name in WRITERS and WRITERS[name] is not writer:
        raise ValueError(f"a writer named {name!r} is registered already")
    taken = [other.name for other in WRITERS.values() if other.suffix == suffix]
    if taken and taken != [name]:
        raise ValueError(f"the suffix {suffix!r} belongs to the {taken[0]!r} writer already")
    if not writer.folder and not writer.default_file.lower().endswith(suffix):
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
    """The one-file writer whose suffix ends ``output``'s name (the longest suffix wins).

    A writer of several files writes a folder: it is picked by name only.

    Raises
    ------
    CaseError
        When no writer's suffix matches, listing the suffixes (key ``format``).
    """
    file_name = output.name.lower()
    single = [writer for writer in WRITERS.values() if not writer.folder]
    matches = [writer for writer in single if file_name.endswith(writer.suffix)]
    if not matches:
        suffixes = ", ".join(f"{writer.suffix} ({writer.name})" for writer in single)
        raise CaseError(
            f"no export format for {output.name!r}: give --format, or a file ending in "
            f"one of {suffixes}",
            key="format",
        )
    return max(matches, key=lambda writer: len(writer.suffix))


def write_text_files(
    folder: Path, texts: dict[str, str], *, line_end: str = "\n"
) -> tuple[str, ...]:
    """Write program texts into ``folder`` as ASCII files, lines ended by ``line_end``.

    Controllers read program files as ASCII (KRL, RAPID, TP, URScript); the writers
    print ASCII only, so a character outside it is a programming error here.

    Parameters
    ----------
    folder
        The staging folder the exporter gave the writer.
    texts
        File name → text with ``\\n`` line ends, the main file first.
    line_end
        ``"\\n"``, or ``"\\r\\n"`` for a controller that expects it (KUKA).

    Returns
    -------
    tuple[str, ...]
        The names written, in the order of ``texts``.
    """
    for file_name, text in texts.items():
        (folder / file_name).write_bytes(text.replace("\n", line_end).encode("ascii"))
    return tuple(texts)
