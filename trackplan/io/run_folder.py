"""A run folder written as a whole, and verified before it is read back.

A run owns a fixed set of files in its folder (:data:`OWNED_FILES`, :data:`OWNED_PATTERNS`).
:func:`write_run_folder` writes every new file into a hidden staging folder inside the run
folder, then moves them into place, each by an atomic rename: ``result.json`` is removed
first and renamed into place last, and every owned file the new run did not write (an
earlier run's ``report.html``, plots or ``history.csv``) is deleted. So at any instant,
even when a signal kills the process half-way:

- no output is ever truncated (each is either the complete old or the complete new file);
- a folder with a ``result.json`` holds one run's files only, and ``result.json`` records
  the SHA-256 and sample count of its ``trajectory.csv``.

:func:`verified_trajectory` is what ``check`` and ``export`` read a folder through: a folder
whose ``result.json`` is missing or does not match its ``trajectory.csv`` is refused.
"""

from __future__ import annotations

import hashlib
import json
import os
import secrets
import shutil
import tempfile
from collections.abc import Callable
from pathlib import Path

from trackplan.errors import CaseError
from trackplan.run_files import HISTORY_FILE, REPORT_FILE, RESULT_FILE, TRAJECTORY_FILE

OWNED_FILES = (
    TRAJECTORY_FILE,
    RESULT_FILE,
    HISTORY_FILE,
    REPORT_FILE,
    "joints.png",
    "path.png",
    "speed.png",
    "convergence.png",
)
"""Files a run writes; an earlier run's copies are removed when the new run lacks them."""

OWNED_PATTERNS = ("*.png",)
"""More files a run owns: plots the report may add."""

STAGING_PREFIX = ".trackplan-staging-"
"""Name prefix of the hidden folder a run is written into before it is moved into place."""

HASH_KEY = "trajectory_sha256"
"""Key of ``result.json`` holding the SHA-256 (hex) of ``trajectory.csv``."""


def file_sha256(file: Path) -> str:
    """SHA-256 of a file's bytes, hex."""
    digest = hashlib.sha256()
    with Path(file).open("rb") as handle:
        for block in iter(lambda: handle.read(1 << 20), b""):
            digest.update(block)
    return digest.hexdigest()


def write_run_folder(out_dir: Path, write: Callable[[Path], None]) -> None:
    """Write a run's files with ``write(staging)`` and move them into ``out_dir`` as a whole.

    Parameters
    ----------
    out_dir
        The run folder (created with its parents when missing).
    write
        Writes every output of the run into the folder it is given (``result.json`` is
        moved into place after all the others).

    Raises
    ------
    CaseError
        When ``out_dir`` cannot be created or written.
    """
    out_dir = Path(out_dir)
    try:
        out_dir.mkdir(parents=True, exist_ok=True)
        for left in out_dir.glob(f"{STAGING_PREFIX}*"):  # of a run killed while writing
            shutil.rmtree(left, ignore_errors=True)
        staging = Path(tempfile.mkdtemp(prefix=STAGING_PREFIX, dir=out_dir))
    except OSError as exc:
        raise CaseError(f"cannot write the run folder: {exc.strerror}", file=str(out_dir)) from None
    try:
        write(staging)
        new = {entry.name for entry in staging.iterdir()}
        (out_dir / RESULT_FILE).unlink(missing_ok=True)
        for stale in _owned(out_dir) - new:
            (out_dir / stale).unlink(missing_ok=True)
        for name in sorted(new - {RESULT_FILE}):
            os.replace(staging / name, out_dir / name)
        if RESULT_FILE in new:
            os.replace(staging / RESULT_FILE, out_dir / RESULT_FILE)
    finally:
        shutil.rmtree(staging, ignore_errors=True)


def write_atomically(target: Path, write: Callable[[Path], None]) -> None:
    """Write one file through a temporary file beside it, renamed over ``target`` at the end.

    A reader (or a signal) never sees a half-written ``target``: it is the old file or
    the complete new one. The file gets the permissions of any file the process creates
    (``0o666`` less the umask), as a run's other outputs do.
    """
    target = Path(target)
    temporary = _new_file_beside(target)
    try:
        write(temporary)
        os.replace(temporary, target)
    finally:
        temporary.unlink(missing_ok=True)


def _new_file_beside(target: Path) -> Path:
    """A new, empty, hidden file in ``target``'s folder, created with mode ``0o666`` less
    the umask (``tempfile.mkstemp`` would create it ``0o600``)."""
    for _ in range(tempfile.TMP_MAX):
        candidate = target.parent / f".{target.name}.{secrets.token_hex(4)}"
        try:
            os.close(os.open(candidate, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o666))
        except FileExistsError:
            continue
        return candidate
    raise FileExistsError(f"no free temporary name beside {target}")


def _owned(folder: Path) -> set[str]:
    """Names of the owned files present in a folder."""
    names = {name for name in OWNED_FILES if (folder / name).is_file()}
    for pattern in OWNED_PATTERNS:
        names |= {path.name for path in folder.glob(pattern) if path.is_file()}
    return names


def verified_trajectory(source: Path) -> Path:
    """The ``trajectory.csv`` to read from a run folder, once the folder proves consistent.

    Parameters
    ----------
    source
        A run folder, or a CSV file (taken as it is: any tool may have written it).

    Returns
    -------
    Path
        The CSV file.

    Raises
    ------
    CaseError
        When the folder has no ``trajectory.csv``, no readable ``result.json``, or a
        ``result.json`` whose recorded hash differs from the CSV's (a run interrupted while
        it was written, or files mixed from two runs).
    """
    source = Path(source)
    if not source.is_dir():
        if not source.exists():
            raise CaseError("trajectory not found", file=str(source))
        if not source.is_file():  # a device or a FIFO: never opened
            raise CaseError(
                "trajectory is not a regular file, expected a CSV file or a run folder",
                file=str(source),
            )
        return source
    csv = source / TRAJECTORY_FILE
    result = source / RESULT_FILE
    if not csv.is_file():
        raise CaseError(f"no {TRAJECTORY_FILE} in the run folder", file=str(source))
    if not result.is_file():
        raise CaseError(
            f"no {RESULT_FILE} beside {TRAJECTORY_FILE}: the run was interrupted while it "
            "was written; run it again",
            file=str(source),
        )
    try:
        summary = json.loads(result.read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError, ValueError) as exc:
        raise CaseError(
            f"unreadable {RESULT_FILE}: {exc}".splitlines()[0], file=str(result)
        ) from None
    recorded = summary.get(HASH_KEY) if isinstance(summary, dict) else None
    if recorded is None:
        raise CaseError(
            f"{RESULT_FILE} records no {HASH_KEY}: it cannot vouch for {TRAJECTORY_FILE}; "
            "run it again",
            file=str(result),
        )
    if recorded != file_sha256(csv):
        raise CaseError(
            f"{TRAJECTORY_FILE} is not the one this {RESULT_FILE} was written with "
            f"({HASH_KEY} differs): files of two runs are mixed; run it again",
            file=str(source),
        )
    return csv
