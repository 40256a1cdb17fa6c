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
