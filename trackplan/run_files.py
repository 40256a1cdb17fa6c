"""The names of the files in a run folder, one place for every reader and writer."""

from __future__ import annotations

TRAJECTORY_FILE = "trajectory.csv"
"""Joint trajectory sampled at Ts (``docs/results.md``)."""
RESULT_FILE = "result.json"
"""Summary of the plan or search."""
HISTORY_FILE = "history.csv"
"""Per-generation figures of a search."""
REPORT_FILE = "report.html"
"""The self-contained HTML report."""
HISTORY_KEYS = ("generation", "evaluations", "best", "mean", "feasible_share", "wall_time")
"""Columns of the search history (``history.csv`` and the report's convergence plot)."""
PARETO_FILE = "pareto.csv"
"""Front of ``optimize --pareto``: placements, objectives, feasibility (``docs/dynamics.md``)."""
PARETO_PLOT = "pareto.png"
"""The front as a plot."""
PARETO_PAGE = "pareto.html"
"""The interactive front: clicking a point shows its plan."""
FRONT_POINT_DIR = "front/{index:02d}"
"""Run folder of front point ``index`` (0-based, by the first objective)."""
