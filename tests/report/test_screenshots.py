"""Screenshots of the report's 3D view compared with stored ones, so that a regression shows.

Two reports, written as a run writes them
(:func:`~trackplan.report.run_report.write_run_report`):

- ``walkthrough``: the README's walk-through, ``cases/bracket-weld.yaml`` at its
  ``placement.example`` (what ``trackplan plan cases/bracket-weld.yaml`` plans);
- ``corner-cell``: ``cases/paper-corner-cell.yaml`` at the feasible placement docs/cell.md
  gives (``trackplan optimize`` finds it; the case file has no ``placement.example``), with its
  table, wall, floor and fixture plate.

Each report is opened in headless Chromium (Debian's, ``make browser``; driven by playwright)
in a 1280 × 900 window, the 3D view's camera set to :data:`CAMERA`, plotly's toolbar hidden,
and the view's div (at the first frame) is shot and compared with
``tests/report/screenshots/NAME.png``: they agree when at most :data:`DIFFERING` of the drawn
pixels (not white in either) differ by more than :data:`LEVELS` grey levels. On failure the
new shot and a diff image (differing pixels red over the stored shot, faded) are saved and
named in the message.

Regenerate the stored shots after an intended change of the view with
``python -m tests.report.test_screenshots`` (docs/architecture.md, "Tests").
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest
from matplotlib import image

from tests.conftest import CASES
from tests.docs.screenshots import CHROMIUM, CHROMIUM_ARGS

STORED = Path(__file__).resolve().parent / "screenshots"
"""The stored shots, ``NAME.png``."""
WINDOW = (1280, 900)
"""The browser window, CSS px (one device pixel each)."""
CAMERA = {"eye": {"x": 1.6, "y": -1.6, "z": 1.0}, "center": {"x": 0, "y": 0, "z": 0}}
"""The 3D view's camera in every shot (plotly scene camera)."""
LEVELS = 16
"""A pixel differs when its grey level (0–255) differs by more than this."""
DIFFERING = 0.02
"""Two shots agree when at most this share of their drawn pixels differ."""
VIEW_ID = "robot-view"

CELL_PLACEMENT = (0.3812, 0.6416, 0.2490, 0.9657, -0.0866, -0.9575)
"""The feasible placement of paper-corner-cell that docs/cell.md states (optimize, seed 0)."""
SHOTS = {
    "walkthrough": ("bracket-weld.yaml", None),
    "corner-cell": ("paper-corner-cell.yaml", CELL_PLACEMENT),
}
"""Shot name -> (case file in cases/, placement X or None for ``placement.example``)."""


def write_report(name: str, folder: Path) -> Path:
    """The report of shot ``name``, written into ``folder`` as a run writes it."""
    from trackplan.io.case_file import load_case
    from trackplan.planning.plan import plan
    from trackplan.report.run_report import write_run_report

    file, placement = SHOTS[name]
    case = load_case(CASES / file)
    X = case.bounds.example if placement is None else np.array(placement)
    _, report = write_run_report(plan(case, X), case, folder, parallel=False)
    return report


def shoot(report: Path, target: Path) -> Path:
    """The 3D view of ``report`` (at its first frame, :data:`CAMERA`) as ``target``."""
    from playwright.sync_api import sync_playwright

    with sync_playwright() as playwright:
        browser = playwright.chromium.launch(executable_path=str(CHROMIUM), args=CHROMIUM_ARGS)
        try:
            page = browser.new_page(viewport={"width": WINDOW[0], "height": WINDOW[1]})
            page.set_default_timeout(180_000)  # a loaded machine parses plotly.js slowly
            page.goto(report.as_uri())
            page.wait_for_function(
                f"() => {{ const gd = document.getElementById('{VIEW_ID}');"
                " return gd && gd._fullLayout && gd._transitionData"
                " && gd._transitionData._frames.length > 0; }"
            )
            page.add_style_tag(content=".modebar-container { display: none !important; }")
            page.evaluate(
                "async ([id, camera]) => {"
                " await Plotly.relayout(document.getElementById(id), {'scene.camera': camera});"
                " await new Promise((done) => requestAnimationFrame(() =>"
                " requestAnimationFrame(done))); }",
                [VIEW_ID, CAMERA],
            )
            view = page.locator(f"#{VIEW_ID}")
            view.scroll_into_view_if_needed()
            page.mouse.move(0, 0)
            box = view.bounding_box()
            assert box is not None
            clip = {
                "x": round(box["x"]),
                "y": round(box["y"]),
                "width": round(box["width"]),
                "height": round(box["height"]),
            }
            page.screenshot(path=str(target), clip=clip)
        finally:
            browser.close()
    return target


def _grey(file: Path) -> np.ndarray:
    """A PNG's RGB levels, shape (H, W, 3), 0–255 as floats."""
    pixels = image.imread(file)[..., :3].astype(float)
    if pixels.max() <= 1.0:
        pixels = pixels * 255.0
    return pixels


def differing_share(stored: Path, new: Path) -> tuple[float, np.ndarray | None]:
    """The share of drawn pixels (not white in either shot) whose grey level differs by more
    than :data:`LEVELS`, and the mask of those pixels (None when the sizes differ: share 1)."""
    one, two = _grey(stored), _grey(new)
    if one.shape != two.shape:
        return 1.0, None
    weights = np.array([0.299, 0.587, 0.114])
    differs = np.abs(one @ weights - two @ weights) > LEVELS
    drawn = (one < 250).any(axis=2) | (two < 250).any(axis=2)
    return float(differs.sum() / max(int(drawn.sum()), 1)), differs


def save_diff(stored: Path, differs: np.ndarray, target: Path) -> Path:
    """The stored shot faded, the differing pixels red, as ``target``."""
    faded = 255.0 - 0.3 * (255.0 - _grey(stored))
    faded[differs] = (255.0, 0.0, 0.0)
    image.imsave(target, faded.astype(np.uint8))
    return target


@pytest.fixture(scope="module")
def chromium_ready():
    pytest.importorskip(
        "playwright.sync_api", reason="BROWSER TEST SKIPPED: the playwright package is missing"
    )
    if not CHROMIUM.exists():
        pytest.skip(f"BROWSER TEST SKIPPED: no Chromium at {CHROMIUM}; run `make browser`")


def test_the_comparison_sees_a_moved_robot_and_forgives_noise(tmp_path):
    """The tolerance: 1 % of the drawn pixels off by 40 levels passes, a shape moved fails."""
    canvas = np.full((200, 300, 3), 255, np.uint8)
    canvas[50:150, 50:150] = 90
    stored, noisy, moved = tmp_path / "a.png", tmp_path / "b.png", tmp_path / "c.png"
    image.imsave(stored, canvas)
    rng = np.random.default_rng(0)
    noise = canvas.copy()
    pick = rng.random(canvas.shape[:2]) < 0.01
    noise[pick & (canvas[..., 0] < 250)] = 130
    image.imsave(noisy, noise)
    image.imsave(moved, np.roll(canvas, 30, axis=1))
    assert differing_share(stored, noisy)[0] <= DIFFERING
    share, differs = differing_share(stored, moved)
    assert share > 0.3 and differs is not None
    diff = image.imread(save_diff(stored, differs, tmp_path / "diff.png"))
    assert diff.shape[:2] == canvas.shape[:2]


@pytest.mark.browser
@pytest.mark.slow
@pytest.mark.parametrize("name", sorted(SHOTS))
def test_the_3d_view_looks_as_stored(name, chromium_ready, tmp_path):
    stored = STORED / f"{name}.png"
    new = shoot(write_report(name, tmp_path), tmp_path / f"{name}.png")
    assert stored.is_file(), f"no stored shot {stored}: python -m tests.report.test_screenshots"
    share, differs = differing_share(stored, new)
    if share > DIFFERING:
        diff = (
            save_diff(stored, differs, tmp_path / f"{name}.diff.png")
            if differs is not None
            else None
        )
        pytest.fail(
            f"{name}: {100 * share:.1f} % of the drawn pixels differ by more than {LEVELS} grey "
            f"levels (allowed {100 * DIFFERING:.0f} %); new shot {new}, diff {diff}. After an "
            "intended change: python -m tests.report.test_screenshots"
        )


def main() -> int:
    """Rewrite the stored shots from fresh reports (prints each shot and its change)."""
    import tempfile

    STORED.mkdir(exist_ok=True)
    with tempfile.TemporaryDirectory() as scratch:
        for name in sorted(SHOTS):
            folder = Path(scratch) / name
            folder.mkdir()
            new = shoot(write_report(name, folder), folder / f"{name}.png")
            stored = STORED / f"{name}.png"
            share = differing_share(stored, new)[0] if stored.is_file() else 1.0
            stored.write_bytes(new.read_bytes())
            print(f"{stored}: written ({100 * share:.1f} % of the drawn pixels changed)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
