"""``speed.png``: the tool speed against vᵣ and vₜᵐᵃˣ, and the tracking error against ρ."""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING

import numpy as np

from trackplan.case import Case
from trackplan.planning.result import PlanResult
from trackplan.report.figure_style import Canvas, mark_violations, new_figure, status_line
from trackplan.report.path_plots import PlotKinematics
from trackplan.report.scene import tracking_error, violation_samples

if TYPE_CHECKING:
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure


def speed_canvas() -> Canvas:
    """The figure of :func:`speed_figure` with its two axes sharing the time axis."""
    figure = new_figure(11.0, 6.5, layout=None)
    figure.subplots_adjust(left=0.07, right=0.76, bottom=0.08, top=0.94, hspace=0.08)
    return figure, figure.subplots(2, 1, sharex=True)


def speed_figure(
    result: PlanResult,
    case: Case,
    kinematics: PlotKinematics | None = None,
    canvas: Canvas | None = None,
) -> Figure:
    """Tool speed against v_r and v_t^max, and the tracking error against ρ, over time.

    Top (``gid="speed"``): Cartesian speed of the tool point with the rated speed
    (``gid="rated-speed"``) and the corner speed cap (``gid="corner-speed"``); slow-downs on
    straight pieces shaded. Bottom (``gid="tracking-error"``): distance of the tool point
    from the nominal path (sharp corners kept) with the tolerance ρ (``gid="tolerance"``).
    Samples inside a speed or tracking violation window the checker reported are red
    markers (``gid="violation"``).

    Parameters
    ----------
    result
        The planned placement (speed in m/s, shown in mm/s).
    case
        The case (task bounds, nominal path).
    kinematics
        The run's :func:`plot_kinematics` (for the tracking error), computed here when not
        given.
    canvas
        The blank figure (:func:`blank_canvases`), made here when not given.

    Returns
    -------
    matplotlib.figure.Figure
        Two axes sharing the time axis.
    """
    trajectory = result.trajectory
    task = case.task
    t = trajectory.t
    figure, (ax_speed, ax_error) = canvas or speed_canvas()

    ax_speed.plot(
        t, 1e3 * trajectory.speed, color="tab:blue", lw=1.2, label="tool speed", gid="speed"
    )
    ax_speed.axhline(
        1e3 * task.rated_speed,
        ls="--",
        color="tab:green",
        label=f"rated speed vᵣ = {1e3 * task.rated_speed:.4g} mm/s",
        gid="rated-speed",
    )
    ax_speed.axhline(
        1e3 * task.corner_speed,
        ls=":",
        color="tab:orange",
        lw=1.5,
        label=f"corner speed cap vₜᵐᵃˣ = {1e3 * task.corner_speed:.4g} mm/s",
        gid="corner-speed",
    )
    ax_speed.set_ylabel("tool speed [mm/s]")
    top = max(task.rated_speed, task.corner_speed, float(np.max(trajectory.speed, initial=0.0)))
    ax_speed.set_ylim(0.0, 1.15e3 * top)
    if trajectory.n_samples and result.slowdowns:
        _mark_slowdowns(ax_speed, result, t)

    error = tracking_error(result, case) if kinematics is None else kinematics.tracking_error
    ax_error.plot(
        t, 1e3 * error, color="tab:purple", lw=1.2, label="tracking error", gid="tracking-error"
    )
    ax_error.axhline(
        1e3 * task.tolerance,
        ls="--",
        color="0.3",
        label=f"tolerance ρ = {1e3 * task.tolerance:.4g} mm",
        gid="tolerance",
    )
    ax_error.set_ylabel("tracking error [mm]")
    ax_error.set_xlabel("time [s]")
    ax_error.set_ylim(0.0, 1.15e3 * max(task.tolerance, float(np.max(error, initial=0.0))))

    # the speed cap depends on where the tool is (corner or straight): mark what the
    # checker reported rather than guess the cap here
    for ax, values, kind in ((ax_speed, trajectory.speed, "speed"), (ax_error, error, "tracking")):
        reported = [v for v in result.check.violations if v.limit == kind]
        inside = violation_samples(trajectory, reported)
        if inside.any():
            mark_violations(ax, (t[inside], 1e3 * values[inside]), f"{kind} violation")
        ax.grid(alpha=0.3, lw=0.5)
        ax.legend(fontsize=8, loc="upper left", bbox_to_anchor=(1.01, 1.0), frameon=False)
    note = "" if trajectory.n_samples else f" — no trajectory: {result.message}"
    figure.suptitle(f"{status_line(result)}: tool speed and tracking error{note}", fontsize=10)
    return figure


SLOWDOWN_COLOR = "tab:orange"
SLOWDOWN_REASONS = 6
"""Most distinct slow-down reasons listed in the legend of ``speed.png``; the rest are in
the report's slow-down table."""


def _mark_slowdowns(ax: Axes, result: PlanResult, t: np.ndarray) -> None:
    """Shade the slow-downs of ``result`` on the speed axes ``ax`` and number them (1, 2, …
    in the order of ``result.slowdowns``, as the report's table and the summary list them).

    The numbers stand in one row at the top of the axes, each at the start of its slow-down
    (``gid="slowdown-label"``); slow-downs too close to be labelled apart share a label
    ("3–5"). The reason of each slow-down is given once per distinct reason in the legend,
    after the numbers it applies to. Labels are laid out from their measured widths, so
    none overlaps another or leaves the axes.
    """
    from matplotlib.patches import Patch
    from matplotlib.transforms import blended_transform_factory

    trajectory = result.trajectory
    spans = [
        np.interp([slowdown.s_start, slowdown.s_end], trajectory.s, t)
        for slowdown in result.slowdowns
    ]
    for k, (t0, t1) in enumerate(spans):
        ax.axvspan(
            t0,
            t1,
            color=SLOWDOWN_COLOR,
            alpha=0.15,
            lw=0,
            gid="slowdown",
            label="slow-down below vᵣ (numbered)" if k == 0 else None,
        )
    figure = ax.figure
    renderer = figure.canvas.get_renderer()  # type: ignore[attr-defined]
    ax.get_xlim()  # settles the autoscaled time axis before positions are measured
    to_pixels = ax.transData.transform
    box = ax.get_window_extent(renderer)
    gap = 4.0 * figure.dpi / 72.0  # 4 pt between labels

    def label_text(first: int, last: int) -> str:
        return str(first + 1) if first == last else f"{first + 1}–{last + 1}"

    def width(text: str) -> float:
        probe = ax.text(0.0, 0.0, text, fontsize=7)
        extent = probe.get_window_extent(renderer).width
        probe.remove()
        return float(extent)

    # left to right: a label starts at its first slow-down unless the previous label
    # reaches there, which then takes this slow-down too
    labels: list[list] = []  # [first, last, left px, width px]
    for k, (t0, _) in enumerate(spans):
        x = float(to_pixels((t0, 0.0))[0])
        if labels and x < labels[-1][2] + labels[-1][3] + gap:
            labels[-1][1] = k
            labels[-1][3] = width(label_text(labels[-1][0], k))
        else:
            labels.append([k, k, max(x, box.x0), width(label_text(k, k))])
    # right to left: labels that would leave the axes move left, and push their
    # neighbours left as far as needed
    limit = box.x1
    for label in reversed(labels):
        label[2] = min(label[2], limit - label[3])
        limit = label[2] - gap
    transform = blended_transform_factory(figure.dpi_scale_trans, ax.transAxes)
    for first, last, left, _ in labels:
        ax.text(
            left / figure.dpi,
            0.97,
            label_text(first, last),
            transform=transform,
            ha="left",
            va="top",
            fontsize=7,
            color="0.15",
            gid="slowdown-label",
        )
    reasons: dict[str, list[int]] = {}
    for k, slowdown in enumerate(result.slowdowns):
        reasons.setdefault(slowdown.limit, []).append(k + 1)
    listed = list(reasons.items())[:SLOWDOWN_REASONS]
    for reason, numbers in listed:
        ax.add_artist(Patch(visible=False, label=_wrap(f"{_ranges(numbers)}: {reason}")))
    if len(reasons) > len(listed):
        ax.add_artist(
            Patch(visible=False, label=f"{len(reasons) - len(listed)} more reasons: see report")
        )


def _ranges(numbers: Sequence[int]) -> str:
    """Sorted integers as runs: 1, 2, 3, 5 → "1–3, 5"."""
    runs: list[list[int]] = []
    for n in numbers:
        if runs and n == runs[-1][1] + 1:
            runs[-1][1] = n
        else:
            runs.append([n, n])
    return ", ".join(str(a) if a == b else f"{a}–{b}" for a, b in runs)


def _wrap(text: str, width: int = 36) -> str:
    """``text`` in lines of at most ``width`` characters (the legend column of
    ``speed.png`` holds about 40)."""
    import textwrap

    return "\n".join(textwrap.wrap(text, width)) or text
