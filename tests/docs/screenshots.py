"""Screenshots of the pages trackplan writes (``report.html``, ``summary.html``), taken with
headless Chromium in a 1280 × 900 window, and how far two pictures differ.

``tests/docs/stated.py`` lists the shots: the top of the walk-through's report, its 3D view
with the time slider clicked 40 % of the way along, the study's feasibility matrix (plotly's
hover toolbar hidden). Chromium is Debian's (``make
browser``), driven by the ``playwright`` package (``playwright install`` is never run: it
would download a browser).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np
from matplotlib import image

CHROMIUM = Path("/usr/bin/chromium")
CHROMIUM_ARGS = [
    "--headless",
    "--no-sandbox",
    "--disable-gpu",
    "--disable-quic",
    "--no-first-run",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
    "--force-device-scale-factor=1",
]
WIDTH, HEIGHT = 1280, 900
SLIDER_AT = 0.4
VIEW_ID = "robot-view"

LEVELS = 32
"""A pixel differs when one of its channels differs by more than this (of 255)."""
DIFFERING = 0.02
"""Two screenshots agree when at most this fraction of their drawn pixels differ."""


@dataclass(frozen=True)
class Shot:
    """One screenshot the docs show: ``page`` (an HTML file, relative to the folder the
    ``command`` that writes it runs in), the element shown (None: the window at the top of
    the page), whether the 3D view's time slider is clicked first, and the plotly figure
    to wait for."""

    name: str
    command: str
    page: str
    element: str | None
    ready: str
    slide: bool = False


def unavailable() -> str | None:
    """Why screenshots cannot be taken here, or None."""
    try:
        import playwright.sync_api  # noqa: F401
    except ImportError:
        return "the playwright package is missing (pip install -e '.[test]')"
    if not CHROMIUM.exists():
        return f"no Chromium at {CHROMIUM}; run `make browser`"
    return None


def take(shots: tuple[Shot, ...], root: Path, folder: Path) -> dict[str, Path]:
    """The ``shots`` of the pages under ``root``, into ``folder``, by file name."""
    from playwright.sync_api import sync_playwright

    taken: dict[str, Path] = {}
    with sync_playwright() as playwright:
        browser = playwright.chromium.launch(executable_path=str(CHROMIUM), args=CHROMIUM_ARGS)
        try:
            for shot in shots:
                page = browser.new_page(viewport={"width": WIDTH, "height": HEIGHT})
                page.set_default_timeout(180_000)  # a loaded machine parses plotly.js slowly
                page.goto((root / shot.page).as_uri())
                page.wait_for_function(
                    f"() => {{ const gd = document.getElementById('{shot.ready}');"
                    " return gd && gd.data && gd._fullLayout; }"
                )
                if shot.slide:
                    _slide(page)
                # the toolbar plotly shows while the pointer is over a plot is not drawn
                page.add_style_tag(content=".modebar-container { display: none !important; }")
                page.mouse.move(0, 0)
                target = folder / shot.name
                if shot.element is None:
                    page.screenshot(path=str(target))
                else:
                    page.locator(shot.element).screenshot(path=str(target))
                taken[shot.name] = target
                page.close()
        finally:
            browser.close()
    return taken


def _slide(page) -> None:  # type: ignore[no-untyped-def]
    """Click the 3D view's time slider SLIDER_AT of the way along and wait for the frame."""
    page.wait_for_function(
        f"() => document.getElementById('{VIEW_ID}')._transitionData._frames.length > 0"
    )
    page.evaluate(
        "(id) => { window.sliderDone = false; document.getElementById(id)"
        ".on('plotly_animated', () => { window.sliderDone = true; }); }",
        VIEW_ID,
    )
    rail = page.locator(f"#{VIEW_ID} .slider-rail-touch-rect")
    box = rail.bounding_box()
    rail.click(position={"x": SLIDER_AT * box["width"], "y": 0.5 * box["height"]})
    page.wait_for_function("() => window.sliderDone")


def difference(a: Path, b: Path) -> float:
    """The fraction of drawn pixels (not white in either picture) whose colour differs by more
    than LEVELS in some channel; 1 when the sizes differ."""
    one, two = _rgb(a), _rgb(b)
    if one.shape != two.shape:
        return 1.0
    drawn = (one < 250).any(axis=2) | (two < 250).any(axis=2)
    differs = (np.abs(one - two) > LEVELS).any(axis=2)
    return float(differs.sum() / max(drawn.sum(), 1))


def _rgb(path: Path) -> np.ndarray:
    pixels = image.imread(path)
    if pixels.dtype != np.uint8:
        pixels = np.round(pixels * 255)
    return pixels[..., :3].astype(np.int16)
