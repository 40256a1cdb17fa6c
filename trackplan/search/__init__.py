"""Placement search: where to put the workpiece so the path is feasible and cheap.

:func:`optimize_placement` runs a pymoo search (the paper's GA, CMA-ES, DE or random
sampling) over X = (x, y, z, roll, pitch, yaw) with a batched, geometrically screened
fitness (Eq. 30) and returns an :class:`OptimizeResult` whose final plan has been
re-planned at the full sample time and re-checked.
"""

from trackplan.search.optimize import (
    GenerationRecord,
    OptimizeResult,
    SearchHistory,
    optimize_placement,
)

__all__ = [
    "GenerationRecord",
    "OptimizeResult",
    "SearchHistory",
    "optimize_placement",
]
