"""The report's placement search tables, from the ``optimizer`` and ``initial`` blocks of
``result.json`` and the search history."""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np

from trackplan.planning.result import PlanResult
from trackplan.report.convergence_plot import history_columns
from trackplan.report.html_markup import (
    PLACEMENT_HEADER,
    PLACEMENT_KEYS,
    Cell,
    esc,
    grid,
    key_values,
    num,
    percent,
)


def _format_value(value: object) -> str:
    if isinstance(value, bool):
        return "yes" if value else "no"
    if isinstance(value, float | np.floating):
        return num(float(value), 6)
    if isinstance(value, np.ndarray | list | tuple):
        items = np.asarray(value).ravel().tolist()
        return (
            "("
            + ", ".join(_format_value(v) for v in items[:12])
            + (", …)" if len(items) > 12 else ")")
        )
    if isinstance(value, Mapping):
        return key_values((str(k), _format_value(v)) for k, v in value.items())
    return esc(value)


_SEARCH_KEYS = ("optimizer", "initial", "robot", "status", "plan_status", "interrupted")
"""Keys of ``optimizer_info`` (the ``result.json`` blocks of a run) that the placement
search section lays out as tables, or leaves out (``robot``: in the Case section)."""


def _search_tables(info: Mapping[str, object], result: PlanResult) -> str:
    """The search (method, budget, time, stop) and the placements before, after and
    rejected, as tables with named columns, from the ``optimizer`` and ``initial`` blocks
    of ``result.json`` (:func:`trackplan.io.history.optimizer_summary`)."""
    parts = []
    optimizer = info.get("optimizer")
    if isinstance(optimizer, Mapping):
        header = [
            "method",
            "seed",
            "runs",
            "generations",
            "evaluations",
            "wall time [s]",
            "best fitness",
            "stopped",
        ]
        row: list[Cell] = [
            esc(optimizer.get("method", "–")),
            *(
                esc(optimizer.get(key, "–"))
                for key in ("seed", "runs", "generations", "evaluations")
            ),
            num(optimizer.get("wall_time_s")),
            num(optimizer.get("fitness"), 6),
            (esc(optimizer.get("stop_reason", "–")), "text"),
        ]
        parts.append(grid(header, [row]))
    interrupted = info.get("interrupted")
    if isinstance(interrupted, Mapping) and "message" in interrupted:
        parts.append(f'<p class="bad">{esc(interrupted["message"])}</p>')
    rows: list[list[Cell]] = []
    initial = info.get("initial")
    if isinstance(initial, Mapping) and isinstance(initial.get("placement"), Mapping):
        placement = initial["placement"]
        verdict = initial.get("status", "feasible" if initial.get("feasible") else "infeasible")
        rows.append(
            [
                "before (centre of the bounds)",
                *(num(placement.get(key)) for key in PLACEMENT_KEYS),
                (esc(verdict), "text"),
                num(initial.get("objective"), 6),
            ]
        )
    rows.append(
        [
            "after (best found)",
            *(num(v) for v in result.placement),
            (esc(result.status.value), "text"),
            num(result.objective, 6),
        ]
    )
    rejected = optimizer.get("rejected_candidates", []) if isinstance(optimizer, Mapping) else []
    for k, X in enumerate(rejected or []):  # type: ignore[union-attr]
        rows.append(
            [
                f"rejected {k + 1} (failed the final check)",
                *(num(v) for v in X),
                ("rejected", "text"),
                "–",
            ]
        )
    parts.append(
        "<h4>Placements</h4>" + grid(["placement", *PLACEMENT_HEADER, "verdict", "J"], rows)
    )
    return "".join(parts)


def optimizer_section(
    optimizer_info: Mapping[str, object] | None,
    history: Mapping[str, Mapping[str, np.ndarray]] | None,
    result: PlanResult,
) -> str:
    """The placement search part of the Result section: the search's tables, other
    figures of ``optimizer_info`` and the history per method; '' for a plain plan."""
    info = optimizer_info or {}
    searched = "optimizer" in info or "initial" in info
    others = [(str(k), v) for k, v in info.items() if k not in _SEARCH_KEYS]
    if not searched and not others and not history:
        return ""
    parts = ["<h3>Placement search</h3>"]
    if searched:
        parts.append(_search_tables(info, result))
    if others:
        parts.append(key_values((k, _format_value(v)) for k, v in others))
    if history:
        rows = [
            [
                esc(method),
                str(len(c["generation"])),
                num(c["evaluations"][-1], 6),
                num(c["best"][-1], 6),
                num(c["mean"][-1], 4),
                percent(c["feasible_share"][-1]),
                num(c["wall_time"][-1], 4),
            ]
            for method, c in history_columns(history).items()
        ]
        header = [
            "method",
            "generations",
            "evaluations",
            "best",
            "last mean",
            "last feasible share",
            "wall time [s]",
        ]
        parts.append("<h4>History</h4>" + grid(header, rows))
    return "".join(parts)


def bounds_line(optimizer_info: Mapping[str, object] | None) -> str:
    """A line under the verdict when the search's placement lies on a bound of its box
    (``optimizer.on_bounds`` of result.json); '' otherwise."""
    search = (optimizer_info or {}).get("optimizer")
    hits = search.get("on_bounds") if isinstance(search, Mapping) else None
    if not hits:
        return ""
    from trackplan.search.space import BoundHit, bounds_note

    note = bounds_note([BoundHit(**hit) for hit in hits])
    return f'<p id="on-bounds">Note: {esc(note)}</p>'
