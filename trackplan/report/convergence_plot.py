"""``convergence.png``: the placement search's best and mean fitness and feasible share."""

from __future__ import annotations

from collections.abc import Mapping
from typing import TYPE_CHECKING

import numpy as np

from trackplan.report.figure_style import Canvas, new_figure
from trackplan.run_files import HISTORY_KEYS

if TYPE_CHECKING:
    from matplotlib.figure import Figure


def convergence_canvas() -> Canvas:
    """The figure of :func:`convergence_figure` with its three axes."""
    figure = new_figure(9.0, 8.0, layout=None)
    figure.subplots_adjust(left=0.1, right=0.98, bottom=0.07, top=0.95, hspace=0.08)
    return figure, figure.subplots(3, 1, sharex=True)


def history_columns(
    history: Mapping[str, Mapping[str, np.ndarray]],
) -> dict[str, dict[str, np.ndarray]]:
    """Check a history table and return it as float arrays of equal length per method."""
    columns: dict[str, dict[str, np.ndarray]] = {}
    for method, table in history.items():
        missing = [key for key in HISTORY_KEYS if key not in table]
        if missing:
            raise ValueError(f"history of {method!r} lacks {', '.join(missing)}")
        arrays = {key: np.asarray(table[key], dtype=float).ravel() for key in HISTORY_KEYS}
        lengths = {len(a) for a in arrays.values()}
        if len(lengths) != 1:
            raise ValueError(
                f"history of {method!r} has columns of different lengths {sorted(lengths)}"
            )
        columns[method] = arrays
    return columns


MINOR_DECADES = 2.0
"""Log fitness axes spanning more decades than this get no minor ticks."""

LOG_RATIO = 10.0
"""Fitness axes whose largest value is less than this times their smallest are linear."""


def convergence_figure(
    history: Mapping[str, Mapping[str, np.ndarray]], canvas: Canvas | None = None
) -> Figure:
    """Best and mean fitness and feasible share per generation, one colour per method.

    Each generation is drawn at its cumulative number of placement evaluations, the
    budget all methods share (their population sizes differ). Fitness axes are
    logarithmic when every value is positive and they span a decade or more (penalised
    candidates sit decades above feasible ones), with labelled minor ticks when they span
    at most :data:`MINOR_DECADES` decades and a tick per decade otherwise; within a decade
    (:data:`LOG_RATIO`) they are linear, labelled with as many digits as the ticks need.

    Parameters
    ----------
    history
        ``{method: {"generation", "evaluations", "best", "mean", "feasible_share",
        "wall_time"}}``, arrays of shape (G,) per method; fitness unitless, share in [0, 1],
        wall time in s.
    canvas
        The blank figure (:func:`blank_canvases`), made here when not given.

    Returns
    -------
    matplotlib.figure.Figure
        Three axes (best, mean, feasible share), one line per method in each
        (``gid=method``).
    """
    from matplotlib.ticker import LogFormatter, MaxNLocator, NullLocator, ScalarFormatter

    columns = history_columns(history)
    figure, (ax_best, ax_mean, ax_share) = canvas or convergence_canvas()
    for k, (method, c) in enumerate(columns.items()):
        color = f"C{k}"
        final = f"{method}: best {c['best'][-1]:.4g} after {c['evaluations'][-1]:.0f} evaluations"
        final += f", {c['wall_time'][-1]:.3g} s"
        ax_best.plot(
            c["evaluations"], c["best"], "-", color=color, marker=".", gid=method, label=final
        )
        ax_mean.plot(
            c["evaluations"], c["mean"], "--", color=color, marker=".", gid=method, label=method
        )
        ax_share.plot(
            c["evaluations"],
            100 * c["feasible_share"],
            "-",
            color=color,
            marker=".",
            gid=method,
            label=method,
        )
    for ax, key, label in (
        (ax_best, "best", "best fitness"),
        (ax_mean, "mean", "mean fitness"),
    ):
        values = np.concatenate([c[key] for c in columns.values()])
        if values.size and np.all(values > 0) and values.max() < LOG_RATIO * values.min():
            # within a decade a log axis has no decade to label and its minor labels all
            # round to the same digit ("7e−01"): a linear axis with plain numbers, as many
            # digits as the ticks need to differ
            ax.yaxis.set_major_locator(MaxNLocator(nbins=5))
            ax.yaxis.set_major_formatter(ScalarFormatter(useOffset=False))
        elif values.size and np.all(values > 0):
            ax.set_yscale("log")
            # plain-text labels: the default ones are mathtext, whose parser costs more
            # than the rest of the figure
            ax.yaxis.set_major_formatter(LogFormatter())
            if np.log10(values.max() / values.min()) > MINOR_DECADES:
                # a labelled tick per decade is enough; eight minor ticks per decade
                # cost more than the rest of the figure
                ax.yaxis.set_minor_locator(NullLocator())
            else:
                ax.yaxis.set_minor_formatter(LogFormatter(labelOnlyBase=False))
        ax.set_ylabel(f"{label} [–]")
    ax_share.set_ylabel("feasible share [%]")
    ax_share.set_ylim(-2, 102)
    ax_share.set_xlabel("placement evaluations (one marker per generation)")
    for ax in (ax_best, ax_mean, ax_share):
        ax.grid(alpha=0.3, lw=0.5, which="both")
    ax_best.legend(fontsize=8)
    figure.suptitle("placement search: convergence per method", fontsize=10)
    return figure
