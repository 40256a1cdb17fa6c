"""``pareto.csv`` of a Pareto run (each point's own files are those of a plan run)."""

from __future__ import annotations

import csv
from pathlib import Path

from trackplan.case import PLACEMENT_KEYS
from trackplan.run_files import FRONT_POINT_DIR, PARETO_FILE
from trackplan.search.pareto import ParetoResult


def pareto_rows(result: ParetoResult) -> list[dict[str, object]]:
    """The rows of ``pareto.csv``: placement, branch, objectives (screened and planned),
    feasibility and the point's folder."""
    a, b = result.objectives
    rows = []
    for i, X in enumerate(result.X):
        row: dict[str, object] = {"point": i}
        row.update({key: float(value) for key, value in zip(PLACEMENT_KEYS, X, strict=True)})
        row.update(
            {
                "branch": int(result.branch[i]),
                f"{a}_screened": float(result.screened[i, 0]),
                f"{b}_screened": float(result.screened[i, 1]),
                a: float(result.values[i, 0]),
                b: float(result.values[i, 1]),
                "feasible": bool(result.feasible[i]),
                "nondominated": bool(result.nondominated[i]),
                "folder": FRONT_POINT_DIR.format(index=i),
            }
        )
        rows.append(row)
    return rows


def write_pareto_csv(result: ParetoResult, out_dir: Path) -> list[dict[str, object]]:
    """Write ``pareto.csv`` into ``out_dir`` (created).

    Returns
    -------
    list of dict
        Its rows (:func:`pareto_rows`).
    """
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    rows = pareto_rows(result)
    header = list(rows[0]) if rows else ["point", *PLACEMENT_KEYS, "feasible"]
    with open(out_dir / PARETO_FILE, "w", newline="", encoding="utf-8") as stream:
        writer = csv.DictWriter(stream, fieldnames=header)
        writer.writeheader()
        writer.writerows(rows)
    return rows
