"""The HTML building blocks of the report's pages: escaping, numbers, tables, the page.

``report.html``, a cycle's report and ``map.html`` are all built from these, in one look
(one style sheet, header and footer: :mod:`trackplan.report.page_style`).
"""

from __future__ import annotations

import html
import math
from collections.abc import Iterable, Sequence

from trackplan.report.page_style import page

Cell = str | tuple[str, str]
"""A table cell: escaped HTML, or (escaped HTML, css class)."""


def esc(value: object) -> str:
    """``value`` as text, escaped for HTML."""
    return html.escape(str(value))


def num(value: float | None, digits: int = 4, scale: float = 1.0, unit: str = "") -> str:
    """A number with ``digits`` significant digits, or an en dash when missing."""
    if value is None or not math.isfinite(float(value)):
        return "–"
    text = f"{float(value) * scale:.{digits}g}"
    return f"{text} {unit}".rstrip()


def percent(fraction: float) -> str:
    """A fraction as a percentage with one decimal, or an en dash when not finite."""
    return "–" if not math.isfinite(float(fraction)) else f"{100 * float(fraction):.1f} %"


def margin_class(fraction: float) -> str:
    """The css class of a margin cell: ``bad`` below 0, ``low`` below 10 %, else ``ok``."""
    if not math.isfinite(float(fraction)) or fraction < 0:
        return "bad"
    return "low" if fraction < 0.1 else "ok"


def vector(values: Iterable[float], digits: int = 4) -> str:
    """Numbers as ``(a, b, c)``, each with ``digits`` significant digits."""
    return "(" + ", ".join(num(v, digits) for v in values) + ")"


def key_values(rows: Iterable[tuple[str, str]]) -> str:
    """A two-column table; values are already-escaped HTML."""
    body = "".join(
        f'<tr><th class="text">{esc(k)}</th><td class="text">{v}</td></tr>' for k, v in rows
    )
    return f"<table>{body}</table>"


def grid(header: Sequence[str], rows: Iterable[Sequence[Cell]], row_header: bool = True) -> str:
    """A table with a header row.

    Cells are escaped HTML, or ``(html, css class)`` pairs for coloured cells; the first
    cell of a row is a row header unless ``row_header`` is False.
    """
    head = "".join(
        f'<th class="{"text" if i == 0 else ""}">{esc(h)}</th>' for i, h in enumerate(header)
    )
    body = ""
    for row in rows:
        cells = []
        for i, cell in enumerate(row):
            content, css = cell if isinstance(cell, tuple) else (cell, "text" if i == 0 else "")
            tag = "th" if (i == 0 and row_header) else "td"
            cells.append(f'<{tag} class="{css}">{content}</{tag}>')
        body += "<tr>" + "".join(cells) + "</tr>"
    return f"<table><thead><tr>{head}</tr></thead><tbody>{body}</tbody></table>"


def html_page(title: str, body: str, kind: str = "report") -> str:
    """A self-contained page in the report's look: ``title`` (text) and ``body`` (HTML)
    between the shared header and footer, with the one style sheet of
    :mod:`trackplan.report.page_style`. ``report.html``, a cycle's report and ``map.html``
    are all built with it; ``kind`` (text) names the page in its header."""
    return page(title, body, kind)


PLACEMENT_KEYS = ("x", "y", "z", "roll", "pitch", "yaw")
PLACEMENT_HEADER = ["x [m]", "y [m]", "z [m]", "roll [rad]", "pitch [rad]", "yaw [rad]"]
"""Columns of a placement X in the report's tables."""
