"""Text cells of the CSV files trackplan writes, safe to open in a spreadsheet."""

from __future__ import annotations

FORMULA_STARTS = frozenset("=+-@\t\r")
"""First characters that make a spreadsheet read a text cell as a formula."""


def neutralised(cell: str) -> str:
    """A text cell made safe to open in a spreadsheet (OWASP's CSV injection advice).

    A cell that starts with ``=``, ``+``, ``-``, ``@``, a tab or a carriage return would
    be taken as a formula: it is written with a leading single quote (and so is a cell
    that already looks neutralised, so that :func:`restored` gives every text back). Other
    text is kept. Only text cells go through here: numbers are written as numbers.
    """
    if cell[:1] in FORMULA_STARTS or restored(cell) != cell:
        return "'" + cell
    return cell


def restored(cell: str) -> str:
    """The text a :func:`neutralised` cell was made from."""
    if cell[:1] == "'" and (cell[1:2] in FORMULA_STARTS or cell[1:2] == "'"):
        return cell[1:]
    return cell
