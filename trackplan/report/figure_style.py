"""The report's figure style and plumbing: colours, the Agg figure, PNG writing, banded plots.

Shared by every module that draws a plot of a run (``joints_plot``, ``path_plots``,
``speed_plot``, ``convergence_plot``, ``cell_figures``, the plot worker). matplotlib is
imported inside the functions so that importing trackplan stays fast.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any, Literal

import numpy as np

from trackplan.planning.result import PlanResult

if TYPE_CHECKING:
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure
    from mpl_toolkits.mplot3d import Axes3D

DPI = 100
AXIS_COLORS = ("tab:red", "tab:green", "tab:blue")  # frame axes x, y, z
BEFORE_COLOR = "tab:purple"
AFTER_COLOR = "tab:orange"
VIOLATION_COLOR = "red"
SYMLOG_RATIO = 20.0  # data spanning more than this many limit ranges get a symlog axis


def new_figure(
    width: float, height: float, layout: Literal["constrained"] | None = "constrained"
) -> Figure:
    """A figure on its own Agg canvas (no pyplot, no global figure registry)."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    figure = Figure(figsize=(width, height), dpi=DPI, layout=layout)
    FigureCanvasAgg(figure)
    return figure


def mark_violations(ax: Axes | Axes3D, coordinates: Sequence[np.ndarray], label: str) -> None:
    """Red markers (``gid="violation"``) at the given x, y (and z) coordinates."""
    ax.plot(
        *coordinates,
        ls="none",
        marker="o",
        ms=3.5,
        color=VIOLATION_COLOR,
        label=label,
        gid="violation",
    )


def status_line(result: PlanResult) -> str:
    """The title line of a run's plots: its case and verdict."""
    verdict = "feasible" if result.feasible else f"infeasible ({result.status.value})"
    return f"{result.case_name}: {verdict}"


PNG_COMPRESSION = 1
"""zlib level of the PNG files: level 1 encodes several times faster than the default 6,
for files about a third larger."""


def save_png(figure: Figure, path: Path) -> None:
    """Write ``figure`` as a PNG file at :data:`DPI`."""
    figure.savefig(path, dpi=DPI, pil_kwargs={"compress_level": PNG_COMPRESSION})


def figure_pixels(figure: Figure) -> np.ndarray:
    """``figure`` drawn at :data:`DPI`, as RGBA pixels of shape (height, width, 4), uint8."""
    figure.canvas.draw()
    return np.array(figure.canvas.buffer_rgba())  # type: ignore[attr-defined]


def save_pixels(pixels: np.ndarray, path: Path) -> None:
    """Write RGBA pixels (height, width, 4) as a PNG file as :func:`save_png` writes one."""
    from matplotlib.image import imsave

    imsave(path, pixels, dpi=DPI, pil_kwargs={"compress_level": PNG_COMPRESSION})


@dataclass(frozen=True)
class BandedFigure:
    """A plot drawn as horizontal bands, each its own figure of the same width; its image is
    the bands stacked top to bottom. The bands can be drawn in different processes
    (:func:`~trackplan.report.drawing.draw_plots`).

    Attributes
    ----------
    bands
        Builders of the band figures, top to bottom.
    """

    bands: tuple[Callable[[], Figure], ...]

    def save(self, path: Path, pixels: Sequence[np.ndarray] | None = None) -> None:
        """Write the PNG file from the bands' pixels (:func:`figure_pixels`), drawn here when
        not given."""
        if pixels is None:
            pixels = [figure_pixels(build()) for build in self.bands]
        save_pixels(np.concatenate(pixels, axis=0), path)


PlotBuilder = Callable[[], "Figure"] | BandedFigure
"""How a plot of a run is drawn: one figure, or bands stacked into one image."""


Canvas = tuple["Figure", Any]
"""A figure with its axes (as :meth:`matplotlib.figure.Figure.subplots` returns them) on
which nothing is drawn yet."""


def inside_ticks(locator: object, low: float, high: float) -> np.ndarray:
    """The ticks ``locator`` (a matplotlib tick locator) places from ``low`` to ``high``,
    without those it adds beyond them: matplotlib makes a tick (two marks, a grid line, two
    labels) for every location its locator gives, drawn or not, a third more in the joint
    grid."""
    ticks = np.asarray(locator.tick_values(low, high))  # type: ignore[attr-defined]
    tolerance = 1e-10 * (high - low)
    return ticks[(ticks >= low - tolerance) & (ticks <= high + tolerance)]
