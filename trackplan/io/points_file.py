"""Points files: the sampled curve of a ``points: {file: seam.csv}`` segment, x,y,z per row.

A file whose header is ``x,y,z,nx,ny,nz`` carries the weld's surface normal at each point too.
"""

from __future__ import annotations

import io
import re
from pathlib import Path

import numpy as np

from trackplan.errors import CaseError
from trackplan.io.input_text import read_text
from trackplan.io.sizes import MAX_POINTS_BYTES, MAX_POINTS_ROWS

MIN_POINTS = 2
"""Fewest points of a ``points`` segment (one point is a ``line``)."""

NUMBER = re.compile(r"[+-]?(?:[0-9]+(?:\.[0-9]*)?|\.[0-9]+)(?:[eE][+-]?[0-9]+)?", re.ASCII)
"""A decimal number as a CSV cell holds one: ASCII digits, an optional point and exponent.

Python's ``float`` also takes ``1_000``, full-width digits, ``infinity`` and ``nan``; a
points file does not."""

_FAST_CHARACTERS = re.compile(r"[^0-9eE+\-., \r\n]")
"""A character outside the rows of plain numbers the compiled parser is given."""

_LATE_HASH = re.compile(r"[^\n]#")
"""A ``#`` that does not start its line."""

_COMMENT_LINES = re.compile(r"^#[^\n]*(?:\n|$)", re.M)
"""Comment lines (``#`` in the first column), with their line ends."""

_SEPARATORS = re.compile(r"[,;\t]")
"""Separators a row may hold (only commas are accepted: the others are named in errors)."""

NORMAL_COLUMNS = ("x", "y", "z", "nx", "ny", "nz")
"""The header of a points file with normals (case and spaces ignored)."""


def load_points_csv(
    file: str | Path, case_file: str | None = None, key: str | None = None
) -> np.ndarray:
    """Read the points of a sampled curve from a CSV file.

    One point per row: ``x,y,z`` in metres, comma separated, each a plain decimal number
    (:data:`NUMBER`); with the header ``x,y,z,nx,ny,nz`` (:data:`NORMAL_COLUMNS`) each row
    also holds the weld's surface normal there (any length, checked by the case loader).
    Blank lines and lines starting with ``#`` are skipped; the first other row may be a
    header (a row without a number, such as ``x,y,z``); a byte order
    mark at the start is skipped. The file is a regular file of at most
    :data:`~trackplan.io.sizes.MAX_POINTS_BYTES` bytes and
    :data:`~trackplan.io.sizes.MAX_POINTS_ROWS` lines.

    Parameters
    ----------
    file
        The CSV file.
    case_file, key
        The case file and key that name the CSV, where a missing file is reported.

    Returns
    -------
    numpy.ndarray
        Shape (K, 3), m, K ≥ 2; shape (K, 6) with normals.

    Raises
    ------
    CaseError
        When the file is missing, not a regular file, too large or unreadable (a missing
        one reported at ``key`` of the case file), or a row is not three finite numbers
        separated by commas, or there are fewer than two points (reported against the CSV
        file, with its line number as the key).
    """
    text = read_text(
        file,
        what="points file",
        referrer=case_file,
        key=key,
        max_bytes=MAX_POINTS_BYTES,
        hint="; split the curve into several points segments",
    )
    n_lines = text.count("\n") + (not text.endswith("\n"))
    if n_lines > MAX_POINTS_ROWS:
        raise CaseError(
            f"the file has {n_lines} lines, more than the {MAX_POINTS_ROWS} a points file may "
            "have; split the curve into several points segments",
            file=str(file),
        )
    width = 6 if _header_cells(text) == NORMAL_COLUMNS else 3
    fast = _parse_fast(text, width)
    if fast is not None:
        return fast
    bad = _first_bad_row(text, width)
    if bad is not None:
        raise CaseError(bad[1], file=str(file), key=f"line {bad[0]}")
    # no bad row, but lines the compiled parser does not take (a line of spaces, say)
    points: list[list[float]] = []
    first = True
    for number, line in enumerate(text.split("\n"), start=1):
        row = line.strip()
        if not row or row.startswith("#"):
            continue
        header, first = first and _is_header(row), False
        if header:
            continue
        point = _point(row, width)
        if isinstance(point, str):
            raise CaseError(point, file=str(file), key=f"line {number}")
        points.append(point)
    if len(points) < MIN_POINTS:
        names = ",".join(NORMAL_COLUMNS[:width])
        raise CaseError(
            f"the file has {len(points)} rows {names}, expected at least {MIN_POINTS}",
            file=str(file),
        )
    return np.array(points, dtype=float)


_PLAIN = r"[+-]?(?:[0-9]{1,20}(?:\.[0-9]*)?|\.[0-9]+)(?:[eE][+-]?[0-9]{1,2})?"
"""A number of :data:`NUMBER` that is surely finite (at most 20 digits before the point,
an exponent of at most 2 digits)."""

_SUSPECT_LINE = {
    width: re.compile(
        rf"^(?![ \t]*(?:#[^\n]*|{_PLAIN}(?: *, *{_PLAIN}){{{width - 1}}})?[ \t]*$)[^\n]*",
        re.M | re.ASCII,
    )
    for width in (3, 6)
}
"""Per row width: a line that is not surely blank, a comment or a good row (the ones to
look at closely)."""

_FIRST_CONTENT = re.compile(r"^[ \t]*[^#\s]", re.M)
"""The start of the first line that is neither blank nor a comment (a header, maybe)."""


def _header_cells(text: str) -> tuple[str, ...]:
    """The cells of the header row (lower case, stripped), or () when there is none."""
    first = _FIRST_CONTENT.search(text)
    if first is None:
        return ()
    start = text.rfind("\n", 0, first.start()) + 1
    end = text.find("\n", start)
    row = text[start : len(text) if end < 0 else end].strip()
    if not _is_header(row):
        return ()
    return tuple(cell.strip().lower() for cell in row.split(","))


def _first_bad_row(text: str, width: int = 3) -> tuple[int, str] | None:
    """The first row the line-by-line reader would refuse: its line number and message.

    The lines are screened by one regular expression (in C); only the lines it cannot
    vouch for are looked at in Python, so a bad row at the end of a million is found in
    about the time the compiled parser takes.
    """
    first = _FIRST_CONTENT.search(text)
    header_at = -1 if first is None else text.rfind("\n", 0, first.start()) + 1
    for match in _SUSPECT_LINE[width].finditer(text):
        row = match.group(0).strip()
        if not row or row.startswith("#"):
            continue
        if match.start() == header_at and _is_header(row):
            continue
        problem = _point(row, width)
        if isinstance(problem, str):
            return text.count("\n", 0, match.start()) + 1, problem
    return None


def _is_header(row: str) -> bool:
    """A first row without a number in any of its cells (split at ``,``, ``;`` or tabs)."""
    return not any(NUMBER.fullmatch(cell.strip()) for cell in _SEPARATORS.split(row))


def _point(row: str, width: int = 3) -> list[float] | str:
    """The point of a data row of ``width`` numbers, or the message saying what is wrong."""
    expected = (
        "expected three finite numbers x,y,z separated by commas"
        if width == 3
        else "expected six finite numbers x,y,z,nx,ny,nz separated by commas"
    )
    other = next((mark for mark in (";", "\t") if mark in row), None)
    if other is not None:
        shown = "';'" if other == ";" else "a tab"
        return f"{expected}, got {shown} between the numbers in {_show(row)}"
    cells = [cell.strip() for cell in row.split(",")]
    if len(cells) != width:
        count = "1 value" if len(cells) == 1 else f"{len(cells)} values"
        hint = " (a file with normals starts with the header x,y,z,nx,ny,nz)"
        return f"{expected}, got {count} in {_show(row)}" + (hint if len(cells) == 6 else "")
    bad = next((cell for cell in cells if not NUMBER.fullmatch(cell)), None)
    if bad is not None:
        return f"{expected}, got {_show(bad)} in {_show(row)}"
    point = [float(cell) for cell in cells]
    if not all(abs(value) < float("inf") for value in point):
        return f"{expected}, got a number beyond the double range in {_show(row)}"
    return point


def _show(text: str, limit: int = 80) -> str:
    """``text`` quoted for a message, cut to about ``limit`` characters."""
    return repr(text if len(text) <= limit else text[:limit] + "…")


def _parse_fast(text: str, width: int = 3) -> np.ndarray | None:
    """The points of a well-formed file, parsed in C (a million rows in about a second).

    Comment lines (``#`` in the first column) and empty lines among the rows are skipped.
    Returns None when the rows after the header are anything else than ``width`` plain
    numbers each (an indented comment, a comment after the numbers or a line of spaces included),
    or fewer than :data:`MIN_POINTS`: the line-by-line reader then takes the file, and
    names the row at fault.
    """
    start = 0
    while True:  # skip blank and comment lines, and a header row, before the first point
        end = text.find("\n", start)
        end = len(text) if end < 0 else end
        row = text[start:end].strip()
        if row and not row.startswith("#"):
            if _is_header(row):
                start = end + 1
            break
        if end >= len(text):
            return None
        start = end + 1
    body = text[start:]
    if "#" in body:
        if _LATE_HASH.search(body):  # an indented comment, or one after the numbers
            return None
        body = _COMMENT_LINES.sub("", body)
    if _FAST_CHARACTERS.search(body) or not body.strip():
        return None
    try:
        points = np.loadtxt(io.StringIO(body), delimiter=",", comments=None, ndmin=2)
    except ValueError:
        return None
    if points.shape[1:] != (width,) or len(points) < MIN_POINTS or not np.all(np.isfinite(points)):
        return None
    return points
