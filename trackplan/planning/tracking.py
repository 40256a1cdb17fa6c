"""Where each tool sample is along the nominal path, in the order of travel.

The nearest point alone is ambiguous where the path folds back on itself (a reversal, or a
closed circle whose end meets its start). Each sample is assigned to a nominal piece whose
direction agrees with the tool's motion, moving forward through the pieces; the checker
then sees a path run backwards or a skipped segment as what it is.
"""

from __future__ import annotations

import numpy as np

from trackplan.frames import vector_norms
from trackplan.paths.curves import unwrap_closed_arc
from trackplan.paths.nominal import NominalPath
from trackplan.planning._kernels import assign_pieces

DIRECTION_SLACK = 0.2
"""A piece agrees with the motion when tangent · velocity ≥ −slack · |velocity|."""

LOCATE_BLOCK = 1 << 13
"""Samples located at once (their candidate pieces are held together)."""


def locate_on_nominal(
    nominal: NominalPath,
    points: np.ndarray,
    velocity: np.ndarray,
    tolerance: float,
    speed: np.ndarray | None = None,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Arc length along the nominal path of each sample, its distance, and its piece.

    Only the pieces within ρ of the nearest one are candidates, found through the path's
    spatial index (:class:`~trackplan.paths.projection.PieceIndex`): time and memory grow
    with the samples and the pieces, not with their product.

    Parameters
    ----------
    nominal
        :class:`trackplan.paths.NominalPath`.
    points
        Tool points in the definition frame, shape (N, 3), m, in time order.
    velocity
        Their velocities, shape (N, 3), m/s (only the direction is used).
    tolerance
        ρ, m: pieces within ρ of the nearest one are candidates.
    speed
        The velocities' lengths, shape (N,), m/s, when known; default: computed.

    Returns
    -------
    s
        Arc length on the nominal path, shape (N,), m (periodic arcs unwrapped).
    distance
        Distance to the nearest point of the nominal path, shape (N,), m.
    piece
        Index of the nominal piece each sample is assigned to, shape (N,).
    """
    points = np.asarray(points, dtype=float)
    table = nominal.table
    speed = vector_norms(velocity) if speed is None else speed
    nearest = np.empty(len(points))
    assigned = np.empty(len(points), dtype=int)
    local = np.empty(len(points))
    current = -1
    for first in range(0, len(points), LOCATE_BLOCK):  # blocks bound the memory of the pairs
        block = slice(first, first + LOCATE_BLOCK)
        found = nominal.index.candidates(points[block], max(tolerance, 1e-12))
        nearest[block] = found.nearest
        # a sample near one piece only keeps it; where several are near, those that agree
        # with the motion, or every one when none agrees; then in order of travel
        chosen = assign_pieces(
            found.row,
            found.piece,
            found.sigma,
            table.direction,
            table.is_arc,
            table.radius,
            table.e1,
            table.e2,
            velocity[block],
            speed[block],
            DIRECTION_SLACK,
            current,
        )
        assigned[block], local[block] = found.piece[chosen], found.sigma[chosen]
        current = int(assigned[block][-1])
    closed = table.is_arc & (table.angle >= 2 * np.pi - 1e-9)
    for p in np.unique(assigned[closed[assigned]]):
        on_piece = assigned == p
        local[on_piece] = unwrap_closed_arc(
            local[on_piece], 2 * np.pi * table.radius[p], table.length[p]
        )
    return table.s_start[assigned] + local, nearest, assigned


def jump_allowance(nominal: NominalPath, tolerance: float) -> np.ndarray:
    """How far the nominal arc length may jump when leaving each piece, m.

    Near a corner of turning angle θ a point within ρ of both legs projects to feet up to
    ρ·tan(θ/2) from the vertex on each leg, so crossing a blended corner may skip
    2ρ·tan(θ/2) of nominal arc length (capped by the pieces' lengths).

    Returns
    -------
    numpy.ndarray
        Shape (P,), m; entry p applies to the step from piece p to the next.
    """
    lengths = nominal.table.length
    allowance = np.zeros(len(lengths))
    p = nominal.corner_junctions
    half = np.minimum(np.pi / 2 - 1e-6, nominal.junction_angles[p] / 2)
    following = np.append(lengths, 0.0)[p + 1]
    allowance[p] = np.minimum(2.0 * tolerance * np.tan(half), lengths[p] + following)
    return allowance


BETWEEN_STEP = 0.25
"""Largest chord between the tool points the checker takes inside one controller period, as
a fraction of ρ.

A controller interpolating the joint positions linearly at Ts moves the tool along a curve
between two samples, not through the samples only. Each period k → k+1 is split into
m_k = max(2, ceil(|p_k+1 − p_k| / (BETWEEN_STEP · ρ))) equal parts of q, and the tool's
points at the interior ones are checked: at least the midpoint, and points no more than ρ/4
of chord apart (a period that jumps across a corner is sampled densely enough to see it).
The checker computes them with the samples' task frames in one compiled pass
(:func:`trackplan.planning._kernels.task_frames`)."""

MAX_BETWEEN_PER_PERIOD = 10_000
"""Most parts of one controller period (see :data:`BETWEEN_STEP`)."""
