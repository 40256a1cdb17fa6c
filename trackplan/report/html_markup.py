"""The HTML building blocks of the report's pages: escaping, numbers, tables, the page.

``report.html``, a cycle's report and ``map.html`` are all built from these, in one look
(one style sheet).
"""

from __future__ import annotations

import html
import math
from collections.abc import Iterable, Sequence

Cell = str | tuple[str, str]
"""A table cell: escaped HTML, or (escaped HTML, css class)."""

_CSS = """
body { font-family: system-ui, -apple-system, "Segoe UI", Helvetica, Arial, sans-serif;
       margin: 0 auto; max-width: 1400px; padding: 0 1.5rem 3rem; color: #222; }
h1 { margin: 1.2rem 0 0.3rem; font-size: 1.6rem; }
h2 { border-bottom: 2px solid #ddd; padding-bottom: 0.2rem; margin-top: 2.2rem; }
h3 { margin: 1.2rem 0 0.4rem; font-size: 1.05rem; }
h4 { margin: 0.9rem 0 0.3rem; font-size: 0.95rem; }
nav a { margin-right: 1rem; }
.verdict { display: inline-block; padding: 0.2rem 0.7rem; border-radius: 4px; font-weight: 600; }
.ok { background: #e3f4e1; color: #1d6b16; }
.bad { background: #fbe3e3; color: #a31515; }
.low { background: #fff3d6; color: #8a5a00; }
table { border-collapse: collapse; margin: 0.3rem 0 0.8rem; font-size: 0.9rem; }
th, td { border: 1px solid #ddd; padding: 0.25rem 0.6rem; text-align: right; }
th { background: #f5f5f5; }
td.text, th.text { text-align: left; }
.cols { display: flex; flex-wrap: wrap; gap: 0 2.5rem; align-items: flex-start; }
figure { margin: 1rem 0 2rem; }
figure img { max-width: 100%; border: 1px solid #eee; }
figcaption { color: #555; font-size: 0.9rem; max-width: 70rem; }
.muted { color: #777; }
"""


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


def html_page(title: str, body: str) -> str:
    """A self-contained page in the report's look: ``title`` (text) and ``body`` (HTML)
    with the report's style sheet. ``report.html``, a cycle's report and ``map.html`` are
    all built with it."""
    return (
        '<!DOCTYPE html>\n<html lang="en"><head><meta charset="utf-8">'
        '<meta name="viewport" content="width=device-width, initial-scale=1">'
        f"<title>{esc(title)}</title><style>{_CSS}</style></head>"
        f"<body>{body}</body></html>\n"
    )


PLACEMENT_KEYS = ("x", "y", "z", "roll", "pitch", "yaw")
PLACEMENT_HEADER = ["x [m]", "y [m]", "z [m]", "roll [rad]", "pitch [rad]", "yaw [rad]"]
"""Columns of a placement X in the report's tables."""
