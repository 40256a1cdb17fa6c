"""Numeric CSV tables written fast and exactly: the shortest text that reads back bit for bit.

Each value is written as Python's ``repr`` writes it (``0.001``, ``2.8368999995743955``,
``1e-05``, ``-0.0``, ``5e-324``, ``nan``, ``inf``): the shortest decimal that reads back
to the same double, by the compiled kernel :func:`trackplan.io._kernels.format_rows` (Ryū).
Any correctly rounded reader (``float``, ``numpy.loadtxt``, pandas, a C ``strtod``)
gets the same bits back.

Why a compiled kernel and not the standard library, which writes the same bytes
(``python -m benchmarks csv``, 2026-12-06, CPU times on a shared 2-core machine): the
trajectory.csv of a 10-minute cycle at Ts = 4 ms (149,179 rows × 30 columns, 81 MB) takes
0.37 s here, 2.74 s by ``float.__repr__`` mapped and joined, 3.86 s by ``csv.writer``
and 2.76 s by ``numpy.savetxt`` with ``%.17g``; the whole ``trackplan plan --no-report``
of that run takes 3.0 s of CPU, to which the standard library would add 78 %. On the
longest shipped case (9,676 rows) it would add 10 %.
"""

from __future__ import annotations

import csv
import io
from collections.abc import Iterator, Sequence
from functools import cache
from pathlib import Path

import numpy as np

from trackplan._kernels import read_only
from trackplan.io._kernels import MAX_TEXT, POW5_BITS, format_rows

CHUNK_ROWS = 8192
"""Rows formatted per kernel call: bounds the text buffer (8192 rows × 30 columns ≈ 6 MB)."""


@cache
def ryu_tables() -> tuple[np.ndarray, np.ndarray]:
    """Ryū's tables as (low, high) ``uint64`` words: ``(inv_split (342, 2), split (326, 2))``.

    ``inv_split[i] = ⌊2^(bits(5^i) − 1 + 125) / 5^i⌋ + 1`` and ``split[i]`` is 5^i scaled to
    its leading 125 bits, where ``bits(n)`` is the bit length of n.
    """
    mask = (1 << 64) - 1
    inverse, direct = [], []
    for i in range(342):
        power = 5**i
        value = (1 << (power.bit_length() - 1 + POW5_BITS)) // power + 1
        inverse.append((value & mask, value >> 64))
    for i in range(326):
        power = 5**i
        shift = power.bit_length() - POW5_BITS
        value = power >> shift if shift >= 0 else power << -shift
        direct.append((value & mask, value >> 64))
    return np.array(inverse, dtype=np.uint64), np.array(direct, dtype=np.uint64)


def format_table(table: np.ndarray) -> bytes:
    """CSV lines of a numeric table, each value the shortest text that reads back exactly.

    Parameters
    ----------
    table
        Shape (n_rows, n_columns), converted to float64.

    Returns
    -------
    bytes
        ASCII: values separated by commas, every row ended by a newline.
    """
    return b"".join(_chunks(np.asarray(table, dtype=np.float64)))


def write_csv_table(file: Path, table: np.ndarray, header: Sequence[str]) -> None:
    """Write a header line and a numeric table as CSV, each value exactly (see module).

    Parameters
    ----------
    file
        The file to write (replaced). Callers writing a run folder write into its staging
        folder, so a reader never sees a partial file.
    table
        Shape (n_rows, len(header)), converted to float64.
    header
        Column names on the first line, quoted as the ``csv`` module quotes (only a name
        holding a comma, a quote or a line break is quoted).
    """
    table = np.asarray(table, dtype=np.float64)
    line = io.StringIO()
    csv.writer(line, lineterminator="\n").writerow(header)
    with Path(file).open("wb") as handle:
        handle.write(line.getvalue().encode("utf-8"))
        for chunk in _chunks(table):
            handle.write(chunk)


def _chunks(table: np.ndarray) -> Iterator[bytes]:
    """The formatted text of ``table`` (n_rows, n_columns), :data:`CHUNK_ROWS` rows at a time."""
    if table.ndim != 2:
        raise ValueError(f"a table has 2 dimensions, got shape {table.shape}")
    inv_split, split = ryu_tables()
    n_rows, n_columns = table.shape
    buffer = np.empty(min(n_rows, CHUNK_ROWS) * n_columns * (MAX_TEXT + 1), dtype=np.uint8)
    for first in range(0, n_rows, CHUNK_ROWS):
        bits = np.ascontiguousarray(table[first : first + CHUNK_ROWS]).view(np.uint64)
        used = format_rows(read_only(bits), buffer, read_only(inv_split), read_only(split))
        yield buffer[:used].tobytes()
