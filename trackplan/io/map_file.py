"""``map.csv``: the placement map, one grid point per row."""

from __future__ import annotations

import csv
from pathlib import Path

from trackplan.search.placement_map import REASONS, PlacementMap

MAP_CSV = "map.csv"
COLUMNS = ("x", "y", "z", "roll", "pitch", "yaw", "reason", "J")


def write_map_csv(pmap: PlacementMap, out_dir: Path) -> Path:
    """Write ``map.csv``: placement (m, rad), reason (``feasible``, ``reach``,
    ``joint limit``, ``collision``) and J (empty where infeasible)."""
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    path = out_dir / MAP_CSV
    X = pmap.placements().reshape(-1, 6)
    with path.open("w", newline="", encoding="utf-8") as handle:
        writer = csv.writer(handle)
        writer.writerow(COLUMNS)
        for row, code, J in zip(X, pmap.reason.ravel(), pmap.objective.ravel(), strict=True):
            writer.writerow(
                [*(f"{v:.6g}" for v in row), REASONS[code], f"{J:.6g}" if code == 0 else ""]
            )
    return path
