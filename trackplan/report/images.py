"""A run's report from its folder: ``report.html`` rewritten, or still images for documents.

``trackplan report RUN`` (:func:`rewrite_report`) and ``trackplan report RUN --png``
(:func:`report_images`). The run folder is read as ``trackplan export`` reads it
(:func:`~trackplan.programs.replay.replay_run`: the folder is verified, the case re-planned
where the run was planned and checked to reproduce ``trajectory.csv``), so the report shows
the run as this version of trackplan plans and draws it.

The still images are the report's PNG plots, drawn by the report's own builders
(:func:`~trackplan.report.figures.plot_figures`), and the 3D view (the report's figure,
:func:`~trackplan.report.html.view_figure`) drawn by a headless Chromium driven by
playwright, at the first sample and, for a case with a cell, at the animation frame nearest
the closest approach to the cell. Chromium is the system's (Debian's ``chromium``, which
``make browser`` installs); playwright never downloads a browser here.
"""

from __future__ import annotations

import os
import shutil
import tempfile
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from trackplan.case import Case
from trackplan.errors import CaseError
from trackplan.io.run_folder import STAGING_PREFIX
from trackplan.planning.result import PlanResult
from trackplan.run_files import HISTORY_FILE, REPORT_FILE

IMAGES_DIR = "images"
"""The folder of a run's still images, inside the run folder (the default)."""
VIEW_START = "view-start.png"
"""The 3D view at the first sample."""
VIEW_CLOSEST = "view-closest.png"
"""The 3D view at the animation frame nearest the closest approach to the cell."""
VIEW_SIZE = (1280, 800)
"""Width and height of the 3D view's images, px."""
CHROMIUM_ENV = "TRACKPLAN_CHROMIUM"
"""Environment variable naming the Chromium executable to use (default: found on PATH)."""
CHROMIUM_NAMES = ("chromium", "chromium-browser", "google-chrome", "google-chrome-stable")
"""Executables looked for on PATH, in order."""
CHROMIUM_ARGS = (
    "--headless",
    "--no-sandbox",
    "--disable-gpu",
    "--no-first-run",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
    "--force-device-scale-factor=1",
)
"""Chromium's command-line switches: headless, offline, one device pixel per CSS pixel."""
NO_CHROMIUM = (
    "no Chromium to draw the 3D view with: install it (`make browser`, or "
    f"`apt-get install chromium`) or name it in ${CHROMIUM_ENV}"
)
NO_PLAYWRIGHT = (
    "the playwright package, which drives Chromium, is missing: pip install 'trackplan[images]'"
)
_INFO_KEYS = ("robot", "optimizer", "initial", "interrupted", "status", "plan_status")
"""The ``result.json`` blocks the report lays out beside the plan (the run's ``extra``)."""


@dataclass(frozen=True)
class RunReport:
    """What a run's report is drawn from, read back from its folder.

    Attributes
    ----------
    folder
        The run folder.
    result
        The run re-planned (:func:`~trackplan.programs.replay.replay_run`).
    case
        Its case.
    history
        The search history per method (``history.csv``), or None.
    info
        The ``result.json`` blocks shown beside the plan (robot, optimizer, initial plan).
    """

    folder: Path
    result: PlanResult
    case: Case
    history: dict[str, dict[str, np.ndarray]] | None
    info: dict[str, object]


def read_run(run: Path | str, case: Case | Path | str | None = None) -> RunReport:
    """A run folder read back for its report (raises ``CaseError`` as ``export`` does).

    Parameters
    ----------
    run
        The run folder (or its ``trajectory.csv``).
    case
        The case, a case file, or None for the case file ``result.json`` records.
    """
    from trackplan.programs.replay import replay_run

    if not Path(run).exists():
        raise CaseError(
            "no run folder here: write one with `trackplan plan CASE --out DIR` first",
            file=str(run),
        )
    replayed = replay_run(run, case)
    assert replayed.folder is not None
    summary = replayed.summary
    history = None
    if (replayed.folder / HISTORY_FILE).is_file():
        from trackplan.io.history import read_history_csv

        optimizer = summary.get("optimizer")
        method = optimizer.get("method") if isinstance(optimizer, Mapping) else None
        columns = read_history_csv(replayed.folder / HISTORY_FILE).as_columns()
        history = {str(method or "search"): columns}
    info = {key: summary[key] for key in _INFO_KEYS if key in summary}
    return RunReport(replayed.folder, replayed.plan, replayed.case, history, info)


def rewrite_report(run: Path | str, case: Case | Path | str | None = None) -> Path:
    """Rewrite a run folder's plots and ``report.html`` from its files, each atomically.

    Parameters
    ----------
    run
        The run folder (or its ``trajectory.csv``).
    case
        The case, a case file, or None for the case file ``result.json`` records.

    Returns
    -------
    pathlib.Path
        The report file.
    """
    from trackplan.report.run_report import write_run_report

    loaded = read_run(run, case)
    with _staging(loaded.folder) as staging:
        plots, report = write_run_report(
            loaded.result, loaded.case, staging, loaded.history, loaded.info, parallel=False
        )
        for path in plots:
            os.replace(path, loaded.folder / path.name)
        os.replace(report, loaded.folder / REPORT_FILE)
    return loaded.folder / REPORT_FILE


def report_images(
    run: Path | str,
    out: Path | str | None = None,
    *,
    case: Case | Path | str | None = None,
    size: tuple[int, int] = VIEW_SIZE,
) -> list[Path]:
    """Write a run's report as PNG files: the 3D view and every plot, for documents.

    Parameters
    ----------
    run
        The run folder (or its ``trajectory.csv``).
    out
        The folder to write into (created); default ``images/`` in the run folder. Each
        file is written into a staging folder there and renamed into place.
    case
        The case, a case file, or None for the case file ``result.json`` records.
    size
        Width and height of the 3D view's images, px.

    Returns
    -------
    list of pathlib.Path
        ``view-start.png``, ``view-closest.png`` (a case with a cell and a finite
        clearance), then the plots in report order (``joints.png``, ``speed.png``, …).

    Raises
    ------
    CaseError
        When the run folder cannot be read back, Chromium or playwright is missing (checked
        before any work), or the folder cannot be written.
    """
    executable = chromium()
    loaded = read_run(run, case)
    target = Path(out) if out is not None else loaded.folder / IMAGES_DIR
    try:
        target.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise CaseError(f"cannot write the images: {exc.strerror}", file=str(target)) from None
    with _staging(target) as staging:
        views = _view_images(loaded, staging, executable, size)
        plots = _plot_images(loaded, staging)
        written = []
        for path in [*views, *plots]:
            os.replace(path, target / path.name)
            written.append(target / path.name)
    return written


def chromium() -> Path:
    """The Chromium executable to draw with (``$TRACKPLAN_CHROMIUM``, else the first of
    :data:`CHROMIUM_NAMES` on PATH), once playwright is known to be there.

    Raises
    ------
    CaseError
        With one line saying how to install what is missing (exit code 2).
    """
    try:
        import playwright.sync_api  # noqa: F401
    except ImportError:
        raise CaseError(NO_PLAYWRIGHT, key="--png") from None
    named = os.environ.get(CHROMIUM_ENV)
    if named:
        if not (Path(named).is_file() and os.access(named, os.X_OK)):
            raise CaseError(f"${CHROMIUM_ENV} names no executable: {named}", key="--png")
        return Path(named)
    for name in CHROMIUM_NAMES:
        found = shutil.which(name)
        if found:
            return Path(found)
    raise CaseError(NO_CHROMIUM, key="--png")


class _staging:
    """A hidden staging folder inside ``folder`` (removed on exit, with what is left)."""

    def __init__(self, folder: Path) -> None:
        self.folder = folder

    def __enter__(self) -> Path:
        try:
            self.path = Path(tempfile.mkdtemp(prefix=STAGING_PREFIX, dir=self.folder))
        except OSError as exc:
            raise CaseError(f"cannot write: {exc.strerror}", file=str(self.folder)) from None
        return self.path

    def __exit__(self, *exc: object) -> None:
        shutil.rmtree(self.path, ignore_errors=True)


def _plot_images(loaded: RunReport, folder: Path) -> list[Path]:
    """The report's plots drawn into ``folder``, in report order."""
    from trackplan.report.drawing import draw_plots
    from trackplan.report.figures import plot_figures

    builders = plot_figures(loaded.result, loaded.case, loaded.history)
    plots = [(folder / name, plot) for name, plot in builders.items()]
    draw_plots(plots, parallel=False, meanwhile=lambda: None)
    return [path for path, _ in plots]


def closest_frame(result: PlanResult, n_frames: int) -> int | None:
    """The animation frame (0-based, of ``n_frames`` evenly spread over the samples) nearest
    the sample of the closest approach to the cell, or None without a cell or clearance."""
    from trackplan.report.scene import frame_indices

    cell = result.check.cell
    if cell is None or not np.isfinite(cell.min_clearance) or result.trajectory.n_samples == 0:
        return None
    idx = frame_indices(result.trajectory.n_samples, n_frames)
    return int(np.argmin(np.abs(idx - int(cell.point))))


def still_figure(result: PlanResult, case: Case, size: tuple[int, int], n_frames: int) -> dict:
    """The report's 3D view (:func:`~trackplan.report.html.view_figure`) for a still image:
    ``size`` px, without the slider and the play buttons."""
    from trackplan.report.html import view_figure

    figure = view_figure(result, case, n_frames)
    layout = dict(figure["layout"])
    layout.update(width=size[0], height=size[1], sliders=[], updatemenus=[])
    return {**figure, "layout": layout}


# Draw frame `k` (or stay at the first) and resolve once plotly.js has drawn it.
_SHOW_FRAME = """async ([id, k, title]) => {
    const gd = document.getElementById(id);
    if (k !== null) {
        const name = gd._transitionData._frames[k].name;
        await Plotly.animate(gd, [name], {mode: 'immediate',
            frame: {duration: 0, redraw: true}, transition: {duration: 0}});
    }
    await Plotly.relayout(gd, {'title.text': title});
    await new Promise((done) => requestAnimationFrame(() => requestAnimationFrame(done)));
}"""


def _view_images(
    loaded: RunReport, folder: Path, executable: Path, size: tuple[int, int], n_frames: int = 150
) -> list[Path]:
    """The 3D view at the start and at the closest approach, as PNG files in ``folder``."""
    from playwright.sync_api import Error, sync_playwright

    from trackplan.report.html_markup import html_page
    from trackplan.report.plotly_html import plotly_div
    from trackplan.report.robot_view import VIEW_ID

    result, case = loaded.result, loaded.case
    if result.trajectory.n_samples == 0:
        return []
    t = result.trajectory.t
    k_closest = closest_frame(result, n_frames)
    shots: list[tuple[str, int | None, str]] = [
        (VIEW_START, None, f"{case.name}: start, t = {t[0]:.3f} s")
    ]
    if k_closest is not None:
        cell = result.check.cell
        assert cell is not None
        shots.append(
            (
                VIEW_CLOSEST,
                k_closest,
                f"{case.name}: closest approach, {1e3 * cell.min_clearance:.1f} mm "
                f"({cell.closest[0]} – {cell.closest[1]}) near t = {cell.t_closest:.3f} s",
            )
        )
    figure = still_figure(result, case, size, n_frames)
    page_file = folder / "view.html"
    div = plotly_div(figure, VIEW_ID, config={"displayModeBar": False, "responsive": False})
    page_file.write_text(html_page(case.name, div, "3D view"), encoding="utf-8")  # staging
    written = []
    try:
        with sync_playwright() as playwright:
            browser = playwright.chromium.launch(
                executable_path=str(executable), args=list(CHROMIUM_ARGS)
            )
            try:
                page = browser.new_page(viewport={"width": size[0] + 100, "height": size[1] + 300})
                page.set_default_timeout(180_000)  # a loaded machine parses plotly.js slowly
                page.goto(page_file.as_uri())
                page.wait_for_function(
                    f"() => {{ const gd = document.getElementById('{VIEW_ID}');"
                    " return gd && gd._fullLayout && gd._transitionData"
                    " && gd._transitionData._frames.length > 0; }"
                )
                for name, k, title in shots:
                    page.evaluate(_SHOW_FRAME, [VIEW_ID, k, title])
                    box = page.locator(f"#{VIEW_ID}").bounding_box()
                    assert box is not None
                    x, y = round(box["x"]), round(box["y"])  # whole pixels: size exactly
                    page.screenshot(
                        path=str(folder / name),
                        clip={"x": x, "y": y, "width": size[0], "height": size[1]},
                    )
                    written.append(folder / name)
            finally:
                browser.close()
    except Error as error:
        first = str(error).strip().splitlines()[0] if str(error).strip() else type(error).__name__
        raise CaseError(
            f"Chromium at {executable} could not draw the 3D view: {first}", key="--png"
        ) from None
    finally:
        page_file.unlink(missing_ok=True)
    return written
