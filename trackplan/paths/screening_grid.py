"""The coarse grid of a planned path on which candidates are screened.

The placement search screens every candidate on it (``docs/search.md``, "Screening"), and a
redundant arm's free parameter is chosen on it (:mod:`trackplan.redundancy`), by the search
and by the plan of one placement alike.
"""

from __future__ import annotations

import numpy as np

from trackplan.paths.path_geometry import PathGeometry

SCREEN_POSES = 150
"""Target number of poses of the screening grid along the planned path. 100 poses screen a
third faster and keep the paper cases' J, but miss what varies between poses: with the
GA, the free-spin circle ends 3.5 % higher (seeds 1, 2) and the payload case's holding
torque peaks slip between poses (every screened optimum failed the final torque check)."""
CURVED_POSES = 9
"""Poses at least in every curved zone (arcs, corner blends) of the screening grid."""


def screening_grid(geometry: PathGeometry, n_poses: int = SCREEN_POSES) -> np.ndarray:
    """Coarse arc lengths covering the planned path, shape (M,), m.

    A grid of about ``n_poses`` points with every zone boundary
    (:meth:`PathGeometry.grid`), plus :data:`CURVED_POSES` points across each curved zone
    so that short corner blends are represented.
    """
    planned = geometry.planned
    s = [geometry.grid(planned.length / max(n_poses - 1, 1))]
    s += [np.linspace(s0, s1, CURVED_POSES) for s0, s1, kind in planned.zones if kind == "curved"]
    return np.unique(np.concatenate(s))
