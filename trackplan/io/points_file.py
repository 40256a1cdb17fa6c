"""Points files: the sampled curve of a ``points: {file: seam.csv}`` segment, x,y,z per row."""

from __future__ import annotations

import io
import math
from pathlib import Path

import numpy as np

from trackplan.errors import CaseError
from trackplan.io.yaml_input import read_text

MIN_POINTS = 2
"""Fewest points of a ``points`` segment (one point is a ``line``)."""


def load_points_csv(
    file: str | Path, case_file: str | None = None, key: str | None = None
) -> np.ndarray:
    """Read the points of a sampled curve from a CSV file.

    One point per row: ``x,y,z`` in metres, comma separated. Blank lines and lines
    starting with ``#`` are skipped; the first row may be a header (``x,y,z``).

    Parameters
    ----------
    file
        The CSV file.
    case_file, key
        The case file and key that name the CSV, where a missing file is reported.

    Returns
    -------
    numpy.ndarray
        Shape (K, 3), m, K ≥ 2.

    Raises
    ------
    CaseError
        When the file is missing or unreadable (reported at ``key`` of the case file),
        or a row is not three finite numbers, or there are fewer than two points
        (reported against the CSV file, with its line number as the key).
    """
    text = read_text(file, what="points file", referrer=case_file, key=key)
    fast = _parse_fast(text)
    if fast is not None:
        return fast
    points: list[list[float]] = []
    for number, line in enumerate(text.splitlines(), start=1):
        row = line.strip()
        if not row or row.startswith("#"):
            continue
        fields = [field.strip() for field in row.split(",")]
        try:
            point = [float(field) for field in fields]
        except ValueError:
            if not points and not any(_is_number(field) for field in fields):
                continue  # a header row
            point = []
        if len(point) != 3 or not all(math.isfinite(value) for value in point):
            raise CaseError(
                f"expected three finite numbers x,y,z, got {row!r}",
                file=str(file),
                key=f"line {number}",
            )
        points.append(point)
    if len(points) < MIN_POINTS:
        raise CaseError(
            f"expected at least {MIN_POINTS} rows x,y,z, got {len(points)}", file=str(file)
        )
    return np.array(points, dtype=float)


def _parse_fast(text: str) -> np.ndarray | None:
    """The points of a well-formed file, parsed in C (a million rows in about a second).

    Returns None when the rows after the header are anything but three finite numbers each
    (a comment or a blank line among them included), or fewer than :data:`MIN_POINTS`: the
    line-by-line reader then takes the file, and names the row at fault.
    """
    start = 0
    while True:  # skip blank and comment lines, and a header row, before the first point
        end = text.find("\n", start)
        end = len(text) if end < 0 else end
        row = text[start:end].strip()
        if row and not row.startswith("#"):
            if not any(_is_number(field) for field in row.split(",")):
                start = end + 1
            break
        if end >= len(text):
            return None
        start = end + 1
    body = text[start:]
    if "#" in body:
        return None
    try:
        points = np.loadtxt(io.StringIO(body), delimiter=",", comments=None, ndmin=2)
    except ValueError:
        return None
    if points.shape[1:] != (3,) or len(points) < MIN_POINTS or not np.all(np.isfinite(points)):
        return None
    return points


def _is_number(text: str) -> bool:
    try:
        float(text)
    except ValueError:
        return False
    return True
