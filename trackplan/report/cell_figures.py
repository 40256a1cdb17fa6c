"""Plots of the work cell: the placement map and clearance versus time (matplotlib, Agg).

matplotlib is imported inside the functions so that importing trackplan stays fast.
"""

from __future__ import annotations

import base64
import html
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from trackplan.planning.result import PlanResult
from trackplan.report.figure_style import DPI, new_figure
from trackplan.report.html_markup import PLACEMENT_HEADER, grid, html_page, num
from trackplan.search.placement_map import REASONS, PlacementMap

if TYPE_CHECKING:
    from matplotlib.figure import Figure

MAP_FILE = "map.png"
MAP_REPORT_FILE = "map.html"
REASON_COLORS = {"reach": "#d0d0d0", "joint limit": "#f2b36b", "collision": "#d9534f"}


def map_figure(pmap: PlacementMap) -> Figure:
    """The placement map: infeasible points by reason, feasible ones coloured by J.

    The robot base (origin) and the reference placement are marked.
    """
    from matplotlib.colors import ListedColormap
    from matplotlib.patches import Patch

    figure = new_figure(7.0, 6.0)
    ax = figure.add_subplot()
    extent = (pmap.x[0], pmap.x[-1], pmap.y[0], pmap.y[-1])
    codes = np.where(pmap.reason == 0, np.nan, pmap.reason.astype(float))
    colors = ListedColormap([REASON_COLORS[name] for name in REASONS[1:]])
    ax.imshow(
        codes,
        origin="lower",
        extent=extent,
        cmap=colors,
        vmin=0.5,
        vmax=3.5,
        interpolation="nearest",
        aspect="equal",
        gid="map-reasons",
    )
    if np.isfinite(pmap.objective).any():
        image = ax.imshow(
            pmap.objective,
            origin="lower",
            extent=extent,
            cmap="viridis",
            interpolation="nearest",
            aspect="equal",
            gid="map-objective",
        )
        figure.colorbar(image, ax=ax, label="J (Eq. 8) where feasible")
    ax.plot(0.0, 0.0, marker="+", color="black", markersize=12, gid="robot-base")
    marked = bool(np.all(np.isfinite(pmap.reference[:2])))
    if marked:
        ax.plot(
            *pmap.reference[:2],
            marker="*",
            color="white",
            markeredgecolor="black",
            markersize=14,
            gid="reference",
        )
    handles = [Patch(color=REASON_COLORS[name], label=name) for name in REASONS[1:]]
    ax.legend(handles=handles, loc="upper right", fontsize=8, framealpha=0.9)
    roll, pitch, yaw = pmap.rpy
    ax.set_title(
        f"{pmap.case_name}: placement map at z = {pmap.z:.3f} m, "
        f"rpy = ({roll:.3f}, {pitch:.3f}, {yaw:.3f}) rad\n"
        f"feasible on {100 * pmap.feasible_share:.0f} % of the grid "
        f"({'★ the search best, ' if marked else ''}+ robot base)",
        fontsize=9,
    )
    ax.set_xlabel("x of the definition frame origin, m")
    ax.set_ylabel("y, m")
    return figure


def clearance_figure(result: PlanResult) -> Figure:
    """Least distance between the robot and the cell over time, the clearance and the
    closest approach."""
    cell = result.check.cell
    assert cell is not None
    figure = new_figure(8.0, 3.2)
    ax = figure.add_subplot()
    t = result.trajectory.t
    ax.plot(t, 1e3 * cell.distance, color="tab:blue", lw=1.2, label="least distance")
    ax.axhline(1e3 * cell.clearance, color="red", ls="--", lw=1.0, gid="limit", label="clearance")
    ax.axhline(0.0, color="black", lw=0.6)
    ax.plot(
        cell.t_closest,
        1e3 * cell.min_clearance,
        marker="o",
        color="red",
        gid="closest",
        label="closest approach",
    )
    who, other = cell.closest
    ax.annotate(
        f"{who} – {other}: {1e3 * cell.min_clearance:.1f} mm at t = {cell.t_closest:.3f} s",
        (cell.t_closest, 1e3 * cell.min_clearance),
        textcoords="offset points",
        xytext=(8, 8),
        fontsize=8,
    )
    ax.set_xlabel("t, s")
    ax.set_ylabel("distance, mm")
    ax.legend(fontsize=8, loc="upper right")
    return figure


def write_map_report(pmap: PlacementMap, out_dir: Path) -> list[Path]:
    """Write ``map.png`` and ``map.html`` into ``out_dir``: the map in the report's look
    (:func:`~trackplan.report.html_markup.html_page`), its grid, height, orientation, the share of
    each class and the least J in tables, the plot as a captioned figure."""
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    png = out_dir / MAP_FILE
    map_figure(pmap).savefig(png, dpi=DPI)
    data = base64.b64encode(png.read_bytes()).decode("ascii")
    best = np.nanmin(pmap.objective) if np.isfinite(pmap.objective).any() else float("nan")
    name = html.escape(pmap.case_name)
    table = grid(
        ["grid", "x range [m]", "y range [m]", *PLACEMENT_HEADER[2:], "least J"],
        [
            [
                f"{len(pmap.x)} × {len(pmap.y)}",
                f"{num(pmap.x[0])} – {num(pmap.x[-1])}",
                f"{num(pmap.y[0])} – {num(pmap.y[-1])}",
                num(pmap.z),
                *(num(v) for v in pmap.rpy),
                num(best, 6),
            ]
        ],
    )
    shares = grid(
        list(REASONS),
        [[(f"{100 * np.mean(pmap.reason == code):.0f} %", "") for code in range(len(REASONS))]],
        row_header=False,
    )
    body = (
        f"<h1>Placement map: {name}</h1>"
        '<section id="placement-map"><h2>Placements</h2>'
        '<p class="muted">Every placement of the grid at the height and orientation below, '
        "classified by the first reason it fails, or feasible and coloured by its J "
        "(docs/cell.md).</p>"
        f"{table}<h3>Share of the grid</h3>{shares}"
        f'<figure id="plot-map"><h3>Map</h3>'
        f'<img alt="placement map" src="data:image/png;base64,{data}">'
        "<figcaption>x–y grid of placement origins in the robot base frame: infeasible "
        "points by reason, feasible ones coloured by J; the robot base and the reference "
        f"placement are marked. (file: {MAP_FILE})</figcaption></figure></section>"
    )
    page_file = out_dir / MAP_REPORT_FILE
    page_file.write_text(
        html_page(f"trackplan placement map: {pmap.case_name}", body, "placement map"), "utf-8"
    )
    return [png, page_file]
