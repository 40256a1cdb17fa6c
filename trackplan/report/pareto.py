"""Plots of a Pareto front: ``pareto.png`` and the interactive ``pareto.html``.

In ``pareto.html`` clicking a point shows its plan: its figures beside the plot and, when the
run wrote per-point reports, that point's ``report.html`` below. matplotlib and plotly are
imported inside the functions.
"""

from __future__ import annotations

import html
import json
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from trackplan.planning.objectives import OBJECTIVES
from trackplan.run_files import PARETO_PAGE, PARETO_PLOT, REPORT_FILE
from trackplan.search.pareto import ParetoResult

if TYPE_CHECKING:
    from matplotlib.figure import Figure

FRONT_ID = "pareto-front"


def _label(name: str) -> str:
    return f"{name} [{OBJECTIVES[name].unit}]"


def pareto_figure(result: ParetoResult, case_name: str) -> Figure:
    """The front: planned values (line: non-dominated; grey: dominated after re-planning;
    red: infeasible) and the screened estimates.

    Parameters
    ----------
    result
        The front.
    case_name
        For the title.

    Returns
    -------
    matplotlib.figure.Figure
    """
    from matplotlib.figure import Figure

    figure = Figure(figsize=(6.4, 4.8), layout="constrained")
    ax = figure.subplots()
    a, b = result.objectives
    ax.plot(*result.screened.T, "x", color="0.6", label="screened estimate")
    ok = result.feasible
    front = result.nondominated
    ax.plot(*result.values[front].T, "o-", color="C0", label="planned, non-dominated")
    if np.any(ok & ~front):
        ax.plot(*result.values[ok & ~front].T, "o", color="0.5", label="planned, dominated")
    if np.any(~ok):
        ax.plot(*result.values[~ok].T, "o", mfc="none", color="C3", label="planned, infeasible")
    for i, (x, y) in enumerate(result.values):
        if np.isfinite(x) and np.isfinite(y):
            ax.annotate(str(i), (x, y), textcoords="offset points", xytext=(4, 4), fontsize=7)
    ax.set_xlabel(_label(a))
    ax.set_ylabel(_label(b))
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    ax.set_title(f"{case_name}: {a}–{b} front ({result.feasible.sum()} feasible)", fontsize=10)
    return figure


def pareto_html(result: ParetoResult, case_name: str, rows: list[dict[str, object]]) -> str:
    """A self-contained page: the front, and the plan of the clicked point.

    Parameters
    ----------
    result
        The front.
    case_name
        For the title.
    rows
        The ``pareto.csv`` rows (:func:`trackplan.io.pareto.pareto_rows`); ``folder`` locates
        each point's files.

    Returns
    -------
    str
        HTML.
    """
    import plotly.graph_objects as go

    a, b = result.objectives
    details = []
    for row, plan in zip(rows, result.plans, strict=True):
        energy = plan.energy
        details.append(
            {
                "point": row["point"],
                "folder": row["folder"],
                "placement": [round(float(v), 4) for v in plan.placement],
                "feasible": bool(plan.feasible),
                "nondominated": bool(result.nondominated[int(str(row["point"]))]),
                "message": plan.message,
                "J": float(plan.objective),
                "duration": float(plan.duration),
                "copper_loss": None if energy is None else energy.copper_loss,
                "mechanical_energy": None if energy is None else energy.mechanical_energy,
                "peak_torque_ratio": None if energy is None else energy.peak_torque_ratio,
            }
        )
    figure = go.Figure(
        go.Scatter(
            x=result.values[:, 0],
            y=result.values[:, 1],
            mode="markers+lines+text",
            text=[str(i) for i in range(len(result.X))],
            textposition="top right",
            marker={
                "size": 10,
                "color": ["#1f77b4" if ok else "#d62728" for ok in result.feasible],
            },
            customdata=np.arange(len(result.X)),
            hovertemplate=(
                f"point %{{customdata}}<br>{a} %{{x:.4g}}<br>{b} %{{y:.4g}}<extra></extra>"
            ),
        )
    )
    figure.update_layout(xaxis_title=_label(a), yaxis_title=_label(b), height=480, margin={"t": 30})
    script = (
        f"var details = {json.dumps(details)};"
        f"document.getElementById('{FRONT_ID}').on('plotly_click', function (event) {{"
        "  var d = details[event.points[0].customdata];"
        "  var rows = Object.keys(d).map(function (k) {"
        "    return '<tr><th>' + k + '</th><td>' + JSON.stringify(d[k]) + '</td></tr>'; });"
        "  document.getElementById('point').innerHTML = '<table>' + rows.join('') + '</table>';"
        f"  document.getElementById('plan').src = d.folder + '/{REPORT_FILE}';"
        "});"
    )
    div = figure.to_html(
        full_html=False,
        include_plotlyjs=True,
        div_id=FRONT_ID,
        config={"displaylogo": False, "responsive": True},
        post_script=script,
    )
    title = html.escape(f"{case_name}: {a}–{b} Pareto front")
    return (
        f"<!DOCTYPE html><html><head><meta charset='utf-8'><title>{title}</title>"
        "<style>body{font-family:sans-serif;margin:1em} th{text-align:left;padding-right:1em}"
        " iframe{width:100%;height:900px;border:1px solid #ccc}</style></head><body>"
        f"<h1>{title}</h1><p>{html.escape(result.message)}. Every point was planned at the "
        "full sample time and checked; click a point to see its plan.</p>"
        f"<div style='display:flex;gap:2em'><div style='flex:2'>{div}</div>"
        "<div id='point' style='flex:1'>(click a point)</div></div>"
        "<iframe id='plan' title='plan of the clicked point'></iframe></body></html>"
    )


def write_pareto_report(
    result: ParetoResult, case_name: str, rows: list[dict[str, object]], out_dir: Path
) -> None:
    """Write ``pareto.png`` and ``pareto.html`` into ``out_dir``."""
    out_dir = Path(out_dir)
    pareto_figure(result, case_name).savefig(out_dir / PARETO_PLOT, dpi=120)
    (out_dir / PARETO_PAGE).write_text(pareto_html(result, case_name, rows), encoding="utf-8")
