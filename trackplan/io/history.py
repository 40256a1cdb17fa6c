"""``history.csv`` of a placement search: one row per generation, and reading it back.

A writer of the search's output: it sits above :mod:`trackplan.search` and imports it.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from trackplan.errors import CaseError
from trackplan.io.results import result_summary
from trackplan.run_files import HISTORY_FILE, HISTORY_KEYS
from trackplan.search.optimize import SearchHistory, SearchResult


def write_history_csv(history: SearchHistory, file: Path) -> None:
    """Write ``generation,evaluations,best,mean,feasible_share,wall_time``, one row a generation.

    Fitness values are unitless (Eq. 30), the feasible share in [0, 1], wall time in s;
    floats at full precision so that the file reads back identically.
    """
    columns = history.as_columns()
    table = np.column_stack([np.asarray(columns[key], dtype=float) for key in HISTORY_KEYS])
    formats = ["%d", "%d", "%.17g", "%.17g", "%.17g", "%.6f"]
    np.savetxt(
        file,
        table.reshape(-1, len(HISTORY_KEYS)),
        delimiter=",",
        header=",".join(HISTORY_KEYS),
        comments="",
        fmt=formats,
    )


def read_history_csv(file: Path) -> SearchHistory:
    """Read a ``history.csv`` written by :func:`write_history_csv`.

    Raises
    ------
    CaseError
        When the file is missing or its header is not the history's.
    """
    file = Path(file)
    if not file.is_file():
        raise CaseError("history file not found", file=str(file))
    table = np.genfromtxt(file, delimiter=",", names=True, ndmin=1)
    names = table.dtype.names or ()
    if names != HISTORY_KEYS:
        raise CaseError(
            f"expected the header {','.join(HISTORY_KEYS)}, got {','.join(names)}",
            file=str(file),
            key="header",
        )
    integer = ("generation", "evaluations")
    return SearchHistory(
        **{
            key: np.atleast_1d(table[key]).astype(int if key in integer else float)
            for key in HISTORY_KEYS
        }
    )


def optimizer_summary(result: SearchResult, joint_names: tuple[str, ...]) -> dict:
    """The ``optimizer`` and ``initial`` blocks of an optimize run's ``result.json``.

    Parameters
    ----------
    result
        The search result.
    joint_names
        The robot's joint names.

    Returns
    -------
    dict
        ``{"optimizer": {method, seed, evaluations, generations, stop_reason,
        wall_time_s, ..., on_bounds}, "initial": {placement, feasible, status, message, objective,
        violations}}`` in plain JSON types.
    """
    initial = result_summary(result.initial, joint_names)
    return {
        "optimizer": {
            "method": result.method,
            "seed": int(result.seed),
            "evaluations": int(result.evaluations),
            "generations": int(result.generations),
            "stop_reason": result.stop_reason,
            "runs": int(result.runs),
            "wall_time_s": float(result.wall_time_s),
            "status": result.status.value,
            "message": result.message,
            "fitness": float(result.fitness),
            "unreachable_seams": list(result.unreachable),
            "rejected_candidates": [list(map(float, X)) for X in result.rejected],
            "on_bounds": [hit.as_dict() for hit in result.on_bounds],
        },
        "initial": {
            key: initial[key]
            for key in ("placement", "feasible", "status", "message", "objective", "violations")
        },
    }


def write_history(result: SearchResult, out_dir: Path) -> Path:
    """Write the search history of a result as ``history.csv`` into ``out_dir``."""
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    path = out_dir / HISTORY_FILE
    write_history_csv(result.history, path)
    return path
