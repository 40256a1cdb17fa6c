"""Placement search: where to put the workpiece so that every seam is feasible and cheap.

:func:`trackplan.search.optimize.optimize` runs a search (multi-start local CMA-ES, the
paper's GA, CMA-ES, DE or random sampling) over X = (x, y, z, roll, pitch, yaw, spins...)
with a batched, geometrically screened fitness summed over the case's seams plus the moves
between them (Eq. 30), and returns a :class:`SearchResult` whose final plan has been
re-planned at the full sample time and re-checked. The function is not re-exported here:
``trackplan.search.optimize`` names its module (``trackplan.optimize`` is the function).
"""

from trackplan.search.driver import GenerationRecord, SearchHistory, StopReason
from trackplan.search.optimize import SearchResult

__all__ = [
    "GenerationRecord",
    "SearchHistory",
    "SearchResult",
    "StopReason",
]
