"""Placement search: where to put the workpiece so that every seam is feasible and cheap.

:func:`optimize` runs a search (multi-start local CMA-ES, the paper's GA, CMA-ES, DE or
random sampling) over X = (x, y, z, roll, pitch, yaw, spins...) with a batched,
geometrically screened fitness summed over the case's seams plus the moves between them
(Eq. 30), and returns a :class:`SearchResult` whose final plan has been re-planned at the
full sample time and re-checked.
"""

from trackplan.search.driver import GenerationRecord, SearchHistory
from trackplan.search.optimize import SearchResult, optimize

__all__ = [
    "GenerationRecord",
    "SearchHistory",
    "SearchResult",
    "optimize",
]
