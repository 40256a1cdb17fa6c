"""Reading the text of an input file safely: a regular UTF-8 file of bounded size.

Shared by every input reader (case, robot, study, points and spin profile files): a
FIFO, a device or a file over the size limit is refused before it is read, and every
problem is one :class:`~trackplan.errors.CaseError` line.
"""

from __future__ import annotations

import os
import stat
from pathlib import Path

from trackplan.errors import CaseError

MAX_TEXT_BYTES = 16 * 2**20
"""Largest input file read by default, bytes: a YAML file's limit
(:data:`trackplan.io.yaml_input.MAX_YAML_BYTES`); long sampled curves belong in a points file."""


def read_text(
    file: str | Path,
    *,
    what: str,
    referrer: str | None = None,
    key: str | None = None,
    max_bytes: int | None = None,
    hint: str = "",
) -> str:
    """The text of an input file: a regular file of at most ``max_bytes``, UTF-8.

    A FIFO, a device or a socket is refused before anything is read from it (a FIFO
    without a writer would block, ``/dev/zero`` never ends), and so is a file larger than
    ``max_bytes``. A byte order mark at the start is dropped, and line ends are read as
    ``\\n`` whether written ``\\r\\n``, ``\\r`` or ``\\n``.

    Parameters
    ----------
    file
        The file to read.
    what
        What the file is, for messages (``"case file"``, ``"robot file"``, ``"points file"``).
    referrer, key
        The file and key that name ``file``, if another file does; a missing file is then
        reported there. Otherwise the problem is reported against ``file`` itself.
    max_bytes
        Largest size accepted, bytes; :data:`MAX_TEXT_BYTES` when None.
    hint
        What to do about a file over ``max_bytes``, appended to that message.

    Raises
    ------
    CaseError
        When the file is missing, is a directory or not a regular file, is larger than
        ``max_bytes``, cannot be read or is not UTF-8 text.
    """
    path = Path(file)
    limit = MAX_TEXT_BYTES if max_bytes is None else max_bytes
    if referrer is None:  # the line starts with the file's name: do not repeat it
        where, at, name = str(path), None, what
    else:
        shown = str(path) if len(str(path)) <= 200 else str(path)[:200] + "…"
        where, at, name = referrer, key, f"{what} {shown!r}"
    try:
        if not path.exists():
            raise CaseError(f"{name} not found", file=where, key=at)
        if path.is_dir():
            raise CaseError(f"{name} is a directory, expected a file", file=where, key=at)
    except OSError as exc:  # a name too long for the system, say
        reason = (exc.strerror or type(exc).__name__).lower()
        raise CaseError(f"cannot read {name}: {reason}", file=where, key=at) from None
    try:
        # O_NONBLOCK: opening a FIFO must not wait for a writer (a regular file ignores it)
        handle = os.open(path, os.O_RDONLY | getattr(os, "O_NONBLOCK", 0))
    except OSError as exc:
        reason = exc.strerror or type(exc).__name__
        raise CaseError(f"cannot read {what}: {reason.lower()}", file=str(path)) from None
    with os.fdopen(handle, "rb") as opened:
        mode = os.fstat(opened.fileno()).st_mode
        if not stat.S_ISREG(mode):
            raise CaseError(
                f"{name} is not a regular file ({_file_kind(mode)}), expected a file",
                file=where,
                key=at,
            )
        size = os.fstat(opened.fileno()).st_size
        if size <= limit:
            try:
                data = opened.read(limit + 1)  # one more: a file that grew meanwhile
            except OSError as exc:
                reason = exc.strerror or type(exc).__name__
                raise CaseError(f"cannot read {what}: {reason.lower()}", file=str(path)) from None
            size = len(data)
    if size > limit:
        raise CaseError(
            f"the {what} has {size} bytes, more than the {limit} accepted" + hint, file=str(path)
        )
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError as exc:
        raise CaseError(
            f"{what} is not UTF-8 text (byte {exc.start} cannot be decoded)", file=str(path)
        ) from None
    if "\r" in text:  # universal newlines, as a file opened in text mode reads them
        text = text.replace("\r\n", "\n").replace("\r", "\n")
    return text[1:] if text.startswith(BYTE_ORDER_MARK) else text


BYTE_ORDER_MARK = "\ufeff"
"""U+FEFF at the start of a file (spreadsheets write it at the start of UTF-8 CSV files)."""


def _file_kind(mode: int) -> str:
    """What a file that is not regular is, for messages (``a FIFO``, ``a character device``)."""
    for test, kind in (
        (stat.S_ISFIFO, "a FIFO"),
        (stat.S_ISCHR, "a character device"),
        (stat.S_ISBLK, "a block device"),
        (stat.S_ISSOCK, "a socket"),
    ):
        if test(mode):
            return kind
    return "not a file"
