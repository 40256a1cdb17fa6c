"""Large sampled paths, written on demand: a smooth helix case and a points file.

Used by ``tests/paths/test_large.py`` and ``python -m benchmarks robustness``; nothing big is
committed. The helix has radius 0.1 m and rises 0.3 m in 3 turns (1.91 m long); the case
plans it with the PUMA 560 at 50 mm/s, ρ = 1 mm and Ts = 1 ms, at :data:`HELIX_PLACEMENT`.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

HELIX_RADIUS = 0.1
"""m."""
HELIX_TURNS = 3
HELIX_RISE = 0.3
"""m over all the turns."""
HELIX_PLACEMENT = (0.5, 0.0, 0.0, 0.0, 0.0, 0.0)
"""A placement where the PUMA 560 follows the helix (x, y, z m, roll, pitch, yaw rad)."""

HELIX_CASE = """name: helix-{n_points}
robot: puma560
path:
  start: [0, 0, -0.001]
  segments:
    - points: {{file: {csv}}}
task:
  rated_speed: 0.05
  tolerance: 0.001
  sample_time: 0.001
  tool_rpy: [3.141592653589793, 0, 0]
"""


def helix_points(n_points: int) -> np.ndarray:
    """``n_points`` points evenly spaced in angle along the helix, shape (n_points, 3), m.

    The first point is the origin; the helix winds about the axis x = −r, y = 0.
    """
    turns = np.linspace(0.0, 2.0 * np.pi * HELIX_TURNS, n_points)
    return np.column_stack(
        [
            HELIX_RADIUS * np.cos(turns) - HELIX_RADIUS,
            HELIX_RADIUS * np.sin(turns),
            HELIX_RISE * turns / (2.0 * np.pi * HELIX_TURNS),
        ]
    )


def write_points_csv(file: Path, points: np.ndarray) -> Path:
    """Write ``points`` (K, 3), m, as a points file with an ``x,y,z`` header; returns ``file``."""
    np.savetxt(file, points, delimiter=",", header="x,y,z", comments="", fmt="%.17g")
    return file


def write_helix_case(folder: Path, n_points: int = 20_000) -> Path:
    """Write ``helix-<n_points>.yaml`` and its points file into ``folder``; return the case."""
    csv = write_points_csv(folder / f"helix-{n_points}.csv", helix_points(n_points))
    case = folder / f"helix-{n_points}.yaml"
    case.write_text(HELIX_CASE.format(n_points=n_points, csv=csv.name))
    return case
