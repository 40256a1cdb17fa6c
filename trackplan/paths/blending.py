"""Corner blends: the G2 quintic blend, and the paper's tangent arc (Eq. 9–10).

G2 blend
--------
A junction whose curvature vector jumps (a corner, or a line meeting an arc) is replaced
by a quintic Bézier curve from the point at arc length d before the junction to the point
at d after it. Its end derivatives are second-order Hermite data of the curves it joins,
B'(0) = λ t0, B''(0) = λ² k0 (and likewise at u = 1), so position, unit tangent and
curvature vector are continuous (G2). For a line–line corner this puts P0, P1, P2 on the
first leg and P3, P4, P5 on the second, with zero curvature at both ends.

The setback d and the shape λ = c·d are chosen per junction: for each c the largest d
within the deviation budget and the reach of the neighbouring pieces, and over c the one
with the smallest peak curvature (the corner speed follows it). For line–line corners
the best c falls from ≈1.8 at 5° to ≈0.2 at 175° of turning, and the peak curvature is
8 % (small turns) to 15 % (175°) above that of the largest tangent arc within the same
deviation (which is only G1).

The deviation is bounded rigorously: the distance of the blend to the nearer of the two
curves it replaces is 1-Lipschitz in arc length, so between samples at arc-length spacing
h with distances a and b it is at most (a + b + h) / 2; intervals are halved until this
bound is within 0.1 % of the budget of the largest sample (:func:`blend_deviation`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from trackplan._kernels import read_only
from trackplan.paths._kernels import dense_pieces
from trackplan.paths.curves import (
    Arc,
    Line,
    Primitive,
    QuinticBlend,
    bezier_basis,
    end_jet,
    hermite_offsets,
    start_jet,
)
from trackplan.paths.piece_table import PieceTable
from trackplan.paths.scalar_search import find_root, minimize_bounded

# Parameter samples of a blend when measuring its deviation and peak curvature.
_N_SAMPLES = 513
_BASIS = [bezier_basis(np.linspace(0.0, 1.0, _N_SAMPLES), order) for order in range(3)]

# Slack of the rigorous deviation bound over the sampled maximum, as a share of the budget.
_RESOLUTION = 1e-3

# Range of the shape parameter c = λ / d searched.
_SHAPE_BOUNDS = (0.05, 2.5)


def paper_corner_angle(a: np.ndarray, b: np.ndarray, c: np.ndarray) -> float:
    """Corner angle β at B of the triangle ABC (paper Eq. 9).

    Parameters
    ----------
    a, b, c
        Points A, B (the corner) and C, each of shape (3,), m.

    Returns
    -------
    float
        β = arccos((AB² + BC² − AC²) / (2·AB·BC)), rad: π for a straight path.
    """
    ab, bc, ac = (float(np.linalg.norm(p - q)) for p, q in ((a, b), (b, c), (a, c)))
    return float(np.arccos(np.clip((ab**2 + bc**2 - ac**2) / (2.0 * ab * bc), -1.0, 1.0)))


def paper_corner_radius(beta: float, tolerance: float) -> float:
    """Corner arc radius as printed in the paper (Eq. 10): r = 2ρ / (1 − sin(β/2)).

    An arc of this radius tangent to both legs lies 2ρ from the sharp corner path
    (see :func:`corrected_corner_radius`).

    Parameters
    ----------
    beta
        Corner angle (Eq. 9), rad, in (0, π).
    tolerance
        ρ, m.
    """
    return 2.0 * corrected_corner_radius(beta, tolerance)


def corrected_corner_radius(beta: float, tolerance: float) -> float:
    """Largest arc tangent to both legs of a corner within ρ: r = ρ / (1 − sin(β/2)).

    The arc's farthest point from the legs is its midpoint, at r·(1 − sin(β/2)).

    Parameters
    ----------
    beta
        Corner angle (Eq. 9), rad, in (0, π).
    tolerance
        ρ, m.
    """
    radius: float = tolerance / (1.0 - np.sin(0.5 * beta))
    return radius


def tangent_corner_arc(incoming: Line, outgoing: Line, radius: float) -> tuple[Arc, float]:
    """The arc of ``radius`` (m) tangent to two lines meeting at a corner.

    Returns
    -------
    arc
        From the tangent point on ``incoming`` to the one on ``outgoing``.
    setback
        Distance of the tangent points from the corner, r / tan(β/2), m.
    """
    t_in, t_out = incoming.direction, outgoing.direction
    beta = np.pi - np.arctan2(np.linalg.norm(np.cross(t_in, t_out)), t_in @ t_out)
    setback = radius / np.tan(0.5 * beta)
    corner = outgoing.start
    arc = Arc.from_tangent(corner - setback * t_in, t_in, corner + setback * t_out)
    if not isinstance(arc, Arc):  # a corner always turns, so the tangent arc is no line
        raise RuntimeError("tangent arc of a collinear junction")
    return arc, float(setback)


def blend_deviation(
    blend: QuinticBlend,
    neighbours: tuple[Primitive, ...],
    resolution: float = 1e-7,
    enough: float = 0.0,
) -> float:
    """Upper bound of the distance from a blend to the curves it replaces, m.

    The distance to the nearest neighbour is 1-Lipschitz in arc length, so on an interval
    of arc length h between samples with distances a and b it is at most (a + b + h) / 2.
    Intervals whose bound exceeds both ``enough`` and the largest sampled distance plus
    ``resolution`` are halved until none does (or 40 halvings).

    Parameters
    ----------
    blend
        The blend.
    neighbours
        The curves meeting at the junction, whole (before trimming).
    resolution
        How far the bound may exceed the largest sampled distance, m.
    enough
        A bound below this is not tightened further, m.
    """
    u = np.linspace(0.0, 1.0, _N_SAMPLES)
    distance = _distances(blend.derivatives(u, 0)[0], neighbours)
    s = blend.arc_length(u)
    for _ in range(40):
        bound = 0.5 * (distance[:-1] + distance[1:] + np.diff(s))
        loose = np.flatnonzero(bound > max(distance.max() + resolution, enough))
        if loose.size == 0:
            break
        middle = 0.5 * (u[loose] + u[loose + 1])
        u = np.insert(u, loose + 1, middle)
        distance = np.insert(
            distance, loose + 1, _distances(blend.derivatives(middle, 0)[0], neighbours)
        )
        s = np.insert(s, loose + 1, blend.arc_length(middle))
    return float(np.max(0.5 * (distance[:-1] + distance[1:] + np.diff(s))))


def _distances(points: np.ndarray, neighbours: tuple[Primitive, ...]) -> np.ndarray:
    """Distance (N,) of ``points`` (N, 3) from the nearest of ``neighbours``, m (compiled:
    the blend search measures a few dozen points hundreds of times)."""
    t = PieceTable.from_curves(neighbours)
    return dense_pieces(
        read_only(np.ascontiguousarray(points, dtype=float)), 0.0, *t.kernel_arrays()
    )[4]


def _curvature(offsets: np.ndarray) -> np.ndarray:
    """Curvature (1/m) of the quintic with control ``offsets`` (6, 3) at the sample parameters."""
    first, second = _BASIS[1] @ offsets, _BASIS[2] @ offsets
    across = np.linalg.norm(np.cross(first, second), axis=-1)
    curvature: np.ndarray = across / np.linalg.norm(first, axis=-1) ** 3
    return curvature


@dataclass(frozen=True, eq=False)
class G2Blend:
    """A chosen G2 blend.

    Attributes
    ----------
    blend
        The quintic.
    setback
        d: arc length taken from each neighbouring curve, m.
    shape
        c = λ / d, the end parametric speed over the setback.
    deviation
        Upper bound of its distance from the neighbouring curves, m.
    """

    blend: QuinticBlend
    setback: float
    shape: float
    deviation: float


def g2_blend(incoming: Primitive, outgoing: Primitive, budget: float, reach: float) -> G2Blend:
    """The G2 blend with the smallest peak curvature within a deviation budget.

    The search measures the deviation at sample points (cheap); the chosen blend is then
    bounded rigorously (:func:`blend_deviation`) and its setback shrunk until the bound holds.

    Parameters
    ----------
    incoming, outgoing
        Lines or arcs ending and starting at the junction.
    budget
        Largest distance of the blend from the two curves, m, > 0.
    reach
        Largest setback d allowed on either curve, m, > 0.

    Returns
    -------
    G2Blend
        The blend and its setback, shape and deviation bound.
    """
    neighbours = (incoming, outgoing)

    def control(setback: float, shape: float) -> tuple[np.ndarray, np.ndarray]:
        """P0 (3,) and the control offsets (6, 3) of the blend with this setback and shape."""
        head = incoming.evaluate(np.array([incoming.length - setback]))
        tail = outgoing.evaluate(np.array([setback]))
        return head.position[0], hermite_offsets(head, tail, shape * setback)

    # The search uses the largest sampled distance (it misses the true maximum by ~κh²/8,
    # negligible); the chosen blend is then bounded rigorously.
    target = (1.0 - 2.0 * _RESOLUTION) * budget

    def excess(log_setback: float, shape: float) -> float:
        origin, offsets = control(np.exp(log_setback), shape)
        points = origin + _BASIS[0] @ offsets
        return float(np.max(_distances(points, neighbours))) - target

    last = [np.log(reach)]

    def largest_setback(shape: float) -> float:
        # The deviation grows with d (linearly at a corner, ~d³ at a G1 junction): root in
        # log d, bracketed first near the previous shape's root, which moves little.
        high = np.log(reach)
        if excess(high, shape) <= 0.0:
            return reach
        low = min(last[0] - 0.2, high)
        if excess(low, shape) > 0.0:
            low = high - 40.0
            if excess(low, shape) > 0.0:
                return float(np.exp(low))
        upper = min(last[0] + 0.2, high)
        if excess(upper, shape) <= 0.0:
            upper = high
        last[0] = find_root(lambda log_setback: excess(log_setback, shape), low, upper, 1e-6)
        return float(np.exp(last[0]))

    def peak(shape: float) -> float:
        return float(np.max(_curvature(control(largest_setback(shape), shape)[1])))

    shape = minimize_bounded(peak, *_SHAPE_BOUNDS, xatol=1e-2)
    setback = largest_setback(shape)
    while True:
        blend = QuinticBlend(*control(setback, shape))
        deviation = blend_deviation(blend, neighbours, _RESOLUTION * budget, budget)
        if deviation <= budget:
            return G2Blend(blend, setback, shape, deviation)
        setback *= 1.0 - 1e-3


def junction_jets(incoming: Primitive, outgoing: Primitive) -> tuple[np.ndarray, np.ndarray, float]:
    """Unit tangents (3,) at a junction and the jump of the curvature vector there (1/m)."""
    before, after = end_jet(incoming), start_jet(outgoing)
    jump = float(np.linalg.norm(before.curvature[0] - after.curvature[0]))
    return before.tangent[0], after.tangent[0], jump
