"""One look for every page trackplan writes: the style sheet, colours, header and footer.

``report.html`` (:mod:`trackplan.report.html`), the placement map's ``map.html``
(:mod:`trackplan.report.cell_figures`) and the batch study's ``summary.html``
(:mod:`trackplan.study.report`) are all built with :func:`page`; no page carries a style sheet
of its own. A page's kind stands in its header (``report``, ``placement map``, ``study``).
"""

from __future__ import annotations

import html
from functools import cache

COLOURS = {
    "text": "#222",
    "muted": "#777",
    "rule": "#ddd",
    "head": "#f5f5f5",
    "accent": "#1f4e79",
    "ok": "#1d6b16",
    "ok-bg": "#e3f4e1",
    "bad": "#a31515",
    "bad-bg": "#fbe3e3",
    "low": "#8a5a00",
    "low-bg": "#fff3d6",
}
"""The colour scheme of the pages (CSS colours): text, rules, the header's accent, and the
verdict colours (``ok`` feasible or margin ≥ 10 %, ``low`` margin under 10 %, ``bad``)."""

HEADER_CLASS = "trackplan-header"
"""css class of every page's header."""
FOOTER_CLASS = "trackplan-footer"
"""css class of every page's footer."""

_CSS = """
body { font-family: system-ui, -apple-system, "Segoe UI", Helvetica, Arial, sans-serif;
       margin: 0 auto; max-width: 1400px; padding: 0 1.5rem 3rem; color: %(text)s; }
header.trackplan-header { display: flex; gap: 16px; align-items: baseline; line-height: 24px;
       border-bottom: 3px solid %(accent)s; padding: 10px 0 5px; }
header.trackplan-header .brand { font-weight: 700; color: %(accent)s; letter-spacing: 0.03em; }
header.trackplan-header .kind { color: %(muted)s; }
footer.trackplan-footer { margin-top: 3rem; border-top: 1px solid %(rule)s; padding-top: 0.4rem;
       color: %(muted)s; font-size: 0.85rem; }
h1 { margin: 1.2rem 0 0.3rem; font-size: 1.6rem; }
h2 { border-bottom: 2px solid %(rule)s; padding-bottom: 0.2rem; margin-top: 2.2rem; }
h3 { margin: 1.2rem 0 0.4rem; font-size: 1.05rem; }
h4 { margin: 0.9rem 0 0.3rem; font-size: 0.95rem; }
a { color: %(accent)s; }
nav a { margin-right: 1rem; }
.verdict { display: inline-block; padding: 0.2rem 0.7rem; border-radius: 4px; font-weight: 600; }
.ok { background: %(ok-bg)s; color: %(ok)s; }
.bad { background: %(bad-bg)s; color: %(bad)s; }
.low { background: %(low-bg)s; color: %(low)s; }
table { border-collapse: collapse; margin: 0.3rem 0 0.8rem; font-size: 0.9rem; }
th, td { border: 1px solid %(rule)s; padding: 0.25rem 0.6rem; text-align: right; }
th { background: %(head)s; }
td.text, th.text, .text { text-align: left; }
.cols { display: flex; flex-wrap: wrap; gap: 0 2.5rem; align-items: flex-start; }
figure { margin: 1rem 0 2rem; }
figure img { max-width: 100%%; border: 1px solid #eee; }
figcaption { color: #555; font-size: 0.9rem; max-width: 70rem; }
.muted { color: %(muted)s; }
"""


@cache
def style_sheet() -> str:
    """The pages' one style sheet (CSS text), in the colours of :data:`COLOURS`. The header
    is a whole number of pixels high (42 px), so that what follows it keeps the pixel grid
    it had without a header (the docs' screenshots of a page's parts stay sharp alike)."""
    return _CSS % COLOURS


def _version() -> str:
    from importlib.metadata import PackageNotFoundError, version

    try:
        return version("trackplan")
    except PackageNotFoundError:  # run from a source tree that is not installed
        return "(source)"


def header(kind: str) -> str:
    """The header every page opens with (HTML): the program's name and the page's kind."""
    return (
        f'<header class="{HEADER_CLASS}"><span class="brand">trackplan</span>'
        f'<span class="kind">{html.escape(kind)}</span></header>'
    )


def footer() -> str:
    """The footer every page closes with (HTML): what wrote it."""
    return (
        f'<footer class="{FOOTER_CLASS}">Written by trackplan {html.escape(_version())}; '
        "self-contained, works offline.</footer>"
    )


def page(title: str, body: str, kind: str = "report") -> str:
    """A self-contained page in trackplan's look.

    Parameters
    ----------
    title
        The page's title (text; escaped here).
    body
        The content between the header and the footer (HTML).
    kind
        What the page is, shown in the header (text): ``report``, ``placement map``, ``study``.

    Returns
    -------
    str
        The whole HTML document.
    """
    return (
        '<!DOCTYPE html>\n<html lang="en"><head><meta charset="utf-8">'
        '<meta name="viewport" content="width=device-width, initial-scale=1">'
        f"<title>{html.escape(title)}</title><style>{style_sheet()}</style>"
        f"</head><body>{header(kind)}{body}{footer()}</body></html>\n"
    )
