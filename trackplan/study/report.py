"""The summary page of a study (``summary.html``): which robot for which part.

One self-contained page (plotly.js embedded once, nothing fetched): the counts, the best
robot per part, a robot × part feasibility matrix, the distributions of J and cycle time
per robot, and the comparison table of every job with links to each run's report, in the
look of every trackplan page (:mod:`trackplan.report.page_style`).
"""

from __future__ import annotations

import html
import math
from collections.abc import Iterable, Sequence
from pathlib import Path
from typing import Any

from trackplan.report.page_style import page as html_page
from trackplan.study.jobs import JOBS_DIR, Study
from trackplan.study.summary import JobRow

SUMMARY_HTML = "summary.html"
MATRIX_ID = "feasibility-matrix"
"""div id of the feasibility matrix (``summary.html#feasibility-matrix``)."""


def write_study_report(study: Study, rows: Sequence[JobRow], out_dir: str | Path) -> Path:
    """Write ``summary.html`` of a study into ``out_dir``.

    Parameters
    ----------
    study
        The study (its order of cases and robots).
    rows
        The rows of the jobs that ran, in the study's order.
    out_dir
        The study's output folder (run reports are linked at ``jobs/<key>/report.html``).

    Returns
    -------
    pathlib.Path
        The page.
    """
    out_dir = Path(out_dir)
    feasible = sum(row.success for row in rows)
    failed = sum(row.failed for row in rows)
    counts = (
        f"{len(study.jobs)} jobs; {len(rows)} with a result row: {feasible} feasible, "
        f"{len(rows) - feasible - failed} infeasible, {failed} failed"
    )
    figures = [
        matrix_figure(study, rows),
        distribution_figure(rows, "J", "J (Eq. 8), rad"),
        distribution_figure(rows, "cycle_time_s", "cycle time, s"),
    ]
    divs = [
        figure.to_html(
            full_html=False,
            include_plotlyjs=index == 0,
            div_id=MATRIX_ID if index == 0 else None,
            config={"displaylogo": False, "responsive": True},
        )
        for index, figure in enumerate(figures)
    ]
    body = "".join(
        [
            f"<h1>Study {_esc(study.name)}</h1>",
            f"<p>{_esc(counts)}. Source: {_esc(study.source or 'built in code')}.</p>",
            "<h2>Best robot per part</h2>",
            '<p class="muted">Per case and sweep, the feasible job with the least joint travel J '
            "(ties: the shorter cycle time), over every seed.</p>",
            _best_table(rows, out_dir),
            "<h2>Feasibility</h2>",
            '<p class="muted">Share of the jobs of each robot and case (over sweeps and seeds) '
            "whose final plan passed the checker.</p>",
            divs[0],
            "<h2>Distributions per robot</h2>",
            '<p class="muted">Feasible jobs only, one point per job.</p>',
            f'<div class="cols"><div>{divs[1]}</div><div>{divs[2]}</div></div>',
            "<h2>Every job</h2>",
            _jobs_table(rows, out_dir),
        ]
    )
    page = html_page(f"trackplan study: {study.name}", body, "study")
    path = out_dir / SUMMARY_HTML
    path.write_text(page, encoding="utf-8")
    return path


def feasibility_matrix(
    study: Study, rows: Iterable[JobRow]
) -> tuple[list[list[int]], list[list[int]]]:
    """Feasible jobs and jobs with a row, per robot (rows) and case (columns).

    Returns
    -------
    tuple of list of list of int
        ``(feasible, total)``, each of shape (n_robots, n_cases) in the study's order.
    """
    feasible = [[0] * len(study.cases) for _ in study.robots]
    total = [[0] * len(study.cases) for _ in study.robots]
    for row in rows:
        i, j = study.robots.index(row.robot), study.cases.index(row.case)
        total[i][j] += 1
        feasible[i][j] += row.success
    return feasible, total


def matrix_figure(study: Study, rows: Sequence[JobRow]) -> Any:
    """A plotly heatmap of the feasible share per robot × case, cells labelled ``k/n``."""
    import plotly.graph_objects as go

    feasible, total = feasibility_matrix(study, rows)
    share = [
        [f / n if n else None for f, n in zip(fs, ns, strict=True)]
        for fs, ns in zip(feasible, total, strict=True)
    ]
    text = [
        [f"{f}/{n}" if n else "–" for f, n in zip(fs, ns, strict=True)]
        for fs, ns in zip(feasible, total, strict=True)
    ]
    figure = go.Figure(
        go.Heatmap(
            z=share,
            x=list(study.cases),
            y=list(study.robots),
            text=text,
            texttemplate="%{text}",
            textfont={"size": 16},
            zmin=0.0,
            zmax=1.0,
            colorscale=[[0.0, "#d9534f"], [0.5, "#f0ad4e"], [1.0, "#5cb85c"]],
            colorbar={"title": {"text": "feasible"}, "tickformat": ".0%"},
            hovertemplate="robot %{y}<br>case %{x}<br>feasible %{text}<extra></extra>",
        )
    )
    figure.update_layout(
        xaxis={"title": {"text": "case"}, "type": "category"},
        yaxis={"title": {"text": "robot"}, "type": "category", "autorange": "reversed"},
        height=140 + 60 * len(study.robots),
        width=260 + 140 * len(study.cases),
        margin={"t": 30, "b": 60},
    )
    return figure


def distribution_figure(rows: Sequence[JobRow], column: str, label: str) -> Any:
    """Box plots of one column of the feasible jobs, one box per robot, points shown."""
    import plotly.graph_objects as go

    figure = go.Figure()
    for robot in dict.fromkeys(row.robot for row in rows):
        values = [getattr(row, column) for row in rows if row.robot == robot and row.success]
        jobs = [row.job for row in rows if row.robot == robot and row.success]
        figure.add_trace(
            go.Box(y=values, name=robot, boxpoints="all", jitter=0.3, text=jobs, hoverinfo="y+text")
        )
    figure.update_layout(
        yaxis={"title": {"text": label}},
        showlegend=False,
        height=380,
        width=520,
        margin={"t": 30},
    )
    return figure


def best_per_part(rows: Iterable[JobRow]) -> dict[tuple[str, str], JobRow | None]:
    """Per (case, sweep): the feasible row with the least J (then cycle time), else None."""
    best: dict[tuple[str, str], JobRow | None] = {}
    for row in rows:
        part = (row.case, row.sweep)
        current = best.get(part)
        if row.success and (current is None or _rank(row) < _rank(current)):
            best[part] = row
        else:
            best.setdefault(part, None)
    return best


def _rank(row: JobRow) -> tuple[float, float]:
    return (row.J, row.cycle_time_s)


def _best_table(rows: Sequence[JobRow], out_dir: Path) -> str:
    header = ("case", "sweep", "best robot", "J rad", "cycle time s", "seed", "feasible robots")
    lines = []
    for (case, sweep), row in best_per_part(rows).items():
        robots = {r.robot for r in rows if (r.case, r.sweep) == (case, sweep) and r.success}
        tried = {r.robot for r in rows if (r.case, r.sweep) == (case, sweep)}
        share = f"{len(robots)}/{len(tried)}"
        if row is None:
            cells = [_esc(case), _esc(sweep), '<span class="bad">none feasible</span>', "–", "–"]
            lines.append([*cells, "–", share])
            continue
        lines.append(
            [
                _esc(case),
                _esc(sweep),
                f'<span class="ok">{_link(row, out_dir, row.robot)}</span>',
                _num(row.J),
                _num(row.cycle_time_s),
                str(row.seed),
                share,
            ]
        )
    return _table(header, lines, text_columns=3)


def _jobs_table(rows: Sequence[JobRow], out_dir: Path) -> str:
    header = (
        "job",
        "case",
        "robot",
        "sweep",
        "seed",
        "status",
        "J rad",
        "duration s",
        "cycle time s",
        "tracking error mm",
        "worst margin",
        "wall time s",
        "worker",
        "message",
    )
    lines = []
    for row in rows:
        css = "ok" if row.success else "bad"
        lines.append(
            [
                _link(row, out_dir, row.job),
                _esc(row.case),
                _esc(row.robot),
                _esc(row.sweep),
                str(row.seed),
                f'<span class="{css}">{_esc(row.status.value)}</span>',
                _num(row.J),
                _num(row.duration_s),
                _num(row.cycle_time_s),
                _num(row.tracking_error_m * 1e3),
                _num(row.worst_margin, 3),
                _num(row.wall_time_s, 3),
                _esc(row.worker),
                f'<span class="text">{_esc(row.message)}</span>',
            ]
        )
    return _table(header, lines, text_columns=6)


def _link(row: JobRow, out_dir: Path, label: str) -> str:
    """``label`` linked to the run's report when it has one."""
    report = Path(JOBS_DIR) / row.job / "report.html"
    if (out_dir / report).is_file():
        return f'<a href="{_esc(report.as_posix())}">{_esc(label)}</a>'
    return _esc(label)


def _table(header: Sequence[str], lines: Iterable[Sequence[str]], text_columns: int) -> str:
    """A table of escaped HTML cells; the first ``text_columns`` columns are left-aligned."""

    def css(i: int) -> str:
        return ' class="text"' if i < text_columns else ""

    head = "".join(f"<th{css(i)}>{_esc(h)}</th>" for i, h in enumerate(header))
    body = "".join(
        "<tr>" + "".join(f"<td{css(i)}>{cell}</td>" for i, cell in enumerate(line)) + "</tr>"
        for line in lines
    )
    return f"<table><thead><tr>{head}</tr></thead><tbody>{body}</tbody></table>"


def _esc(value: object) -> str:
    return html.escape(str(value))


def _num(value: float, digits: int = 4) -> str:
    return "–" if not math.isfinite(value) else f"{value:.{digits}g}"
