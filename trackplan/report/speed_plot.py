"""``speed.png``: the tool speed against vᵣ and vₜᵐᵃˣ, and the tracking error against ρ."""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING

import numpy as np

from trackplan.case import Case
from trackplan.planning.result import SEAM, PlanResult
from trackplan.report.figure_style import Canvas, mark_violations, new_figure, status_line
from trackplan.report.joints_plot import move_samples
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
    seams = seam_spans(result, case)
    tasks = [task] if seams is None else [case.seams[k].task for k, *_ in seams]
    for label, style, attribute, gid in (
        ("rated speed vᵣ", {"ls": "--", "color": "tab:green"}, "rated_speed", "rated-speed"),
        (
            "corner speed cap vₜᵐᵃˣ",
            {"ls": ":", "color": "tab:orange", "lw": 1.5},
            "corner_speed",
            "corner-speed",
        ),
    ):
        levels = [1e3 * getattr(each, attribute) for each in tasks]
        text = f"{label} = {', '.join(dict.fromkeys(f'{v:.4g}' for v in levels))} mm/s"
        if seams is None:
            ax_speed.axhline(levels[0], label=text, gid=gid, **style)
        else:  # each seam's own, over its span
            for k, (_, _, t0, t1) in enumerate(seams):
                ax_speed.hlines(levels[k], t0, t1, label=text if k == 0 else None, gid=gid, **style)
    ax_speed.set_ylabel("tool speed [mm/s]")
    # a cycle's axis fits the welding: its moves run far faster and would flatten the seams
    welding = trajectory.speed if seams is None else trajectory.speed[~move_samples(result)]
    top = max(
        *(max(each.rated_speed, each.corner_speed) for each in tasks),
        float(np.max(welding, initial=0.0)),
    )
    headroom = 1.15 if seams is None else 1.35  # a cycle's seam names stand over the speeds
    ax_speed.set_ylim(0.0, headroom * 1e3 * top)
    fastest = float(np.max(trajectory.speed, initial=0.0))
    if fastest > headroom * top:  # said in the legend, clear of the slow-down numbers
        from matplotlib.patches import Patch

        peak = Patch(visible=False, label=f"moves: up to {1e3 * fastest:.4g} mm/s, off the axis")
        peak.set_gid("move-peak")
        ax_speed.add_artist(peak)
    if trajectory.n_samples and result.slowdowns:
        _mark_slowdowns(ax_speed, result, slowdown_times(result))

    error = tracking_error(result, case) if kinematics is None else kinematics.tracking_error
    ax_error.plot(
        t, 1e3 * error, color="tab:purple", lw=1.2, label="tracking error", gid="tracking-error"
    )
    tolerances = [1e3 * each.tolerance for each in tasks]
    text = f"tolerance ρ = {', '.join(dict.fromkeys(f'{v:.4g}' for v in tolerances))} mm"
    if seams is None:
        ax_error.axhline(tolerances[0], ls="--", color="0.3", label=text, gid="tolerance")
    else:
        for k, (_, _, t0, t1) in enumerate(seams):
            ax_error.hlines(
                tolerances[k],
                t0,
                t1,
                ls="--",
                color="0.3",
                label=text if k == 0 else None,
                gid="tolerance",
            )
        _mark_seams(ax_speed, ax_error, result, seams)
    ax_error.set_ylabel("tracking error [mm]")
    ax_error.set_xlabel("time [s]")
    largest = float(np.max(error, initial=0.0, where=np.isfinite(error)))
    ax_error.set_ylim(0.0, 1.15 * max(*tolerances, 1e3 * largest))

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


def seam_spans(result: PlanResult, case: Case) -> list[tuple[int, str, float, float]] | None:
    """The seams of a plan joined by moves as ``(index as written, label, t start,
    t end)`` in welding order (s), or None for one seam alone (no moves)."""
    spans = result.spans
    if len(spans) <= 1 and all(span.kind == SEAM for span in spans):
        return None
    sample_time = result.trajectory.sample_time
    names = case.seam_names
    return [
        (names.index(span.label), span.label, span.first * sample_time, span.last * sample_time)
        for span in spans
        if span.kind == SEAM
    ]


def slowdown_times(result: PlanResult) -> list[tuple[float, float]]:
    """When each of ``result.slowdowns`` happens, ``(t start, t end)`` in s: its arc
    length ``s`` looked up on the trajectory's, within its seam's span for a plan of
    several seams (``s`` runs along each seam on its own there)."""
    trajectory = result.trajectory
    t = trajectory.t
    times: list[tuple[float, float]] = []
    if len(result.spans) <= 1:
        for d in result.slowdowns:
            t0, t1 = np.interp([d.s_start, d.s_end], trajectory.s, t)
            times.append((float(t0), float(t1)))
        return times
    for seam in result.seams:
        span = next(p for p in result.spans if p.kind == SEAM and p.seam == seam.index)
        rows = slice(span.first, span.last + 1)
        s_span = np.maximum.accumulate(trajectory.s[rows])  # s never runs back in a seam
        for d in seam.plan.slowdowns:
            t0, t1 = np.interp([d.s_start, d.s_end], s_span, t[rows])
            times.append((float(t0), float(t1)))
    return times


def _mark_seams(
    ax_speed: Axes, ax_error: Axes, result: PlanResult, seams: list[tuple[int, str, float, float]]
) -> None:
    """Mark the cycle on both axes: each move between seams shaded grey (``gid="move"``),
    each seam's name over its span on the speed axes (``gid="seam-label"``)."""
    from matplotlib.transforms import blended_transform_factory

    sample_time = result.trajectory.sample_time
    for k, span in enumerate(p for p in result.spans if p.kind != SEAM):
        for ax in (ax_speed, ax_error):
            ax.axvspan(
                span.first * sample_time,
                span.last * sample_time,
                color="0.5",
                alpha=0.12,
                lw=0,
                gid="move",
                label="approach, retract, air" if k == 0 and ax is ax_speed else None,
            )
    transform = blended_transform_factory(ax_speed.transData, ax_speed.transAxes)
    for _, label, t0, t1 in seams:
        ax_speed.text(
            0.5 * (t0 + t1),
            0.91,  # under the slow-down numbers, above the welding speed (headroom)
            label,
            transform=transform,
            ha="center",
            va="top",
            fontsize=7,
            color="0.15",
            clip_on=True,
            gid="seam-label",
        )


def _mark_slowdowns(ax: Axes, result: PlanResult, spans: list[tuple[float, float]]) -> None:
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
