"""The planned path: lines, arcs and corner blends on one arc-length parameter s.

:func:`build_path` turns a :class:`~trackplan.paths.nominal.NominalPath` into a
:class:`Path`. In ``"g2"`` mode every junction where the curvature vector jumps gets a
G2 quintic blend (:mod:`trackplan.paths.blending`) within the tolerance ρ; in
``"paper"`` mode line–line corners get the paper's tangent arc (Eq. 10 as printed) and
other junctions stay as they are. Sampled curves are first fitted with lines and arcs
(:mod:`trackplan.paths.fitting`).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from functools import cached_property
from itertools import pairwise
from typing import Literal

import numpy as np

from trackplan.paths.blending import (
    g2_blend,
    junction_jets,
    paper_corner_angle,
    paper_corner_radius,
    tangent_corner_arc,
)
from trackplan.paths.curves import COLLINEAR_ANGLE, Arc, Curve, Line, Primitive, turning_angle
from trackplan.paths.fitting import fit_polyline
from trackplan.paths.nominal import NominalPath
from trackplan.paths.pieces import Piece, PointTable, chain, evaluate_pieces, evaluate_points
from trackplan.paths.specs import PointsSpec

#: Share of ρ that a blend of exact lines and arcs may use.
BLEND_SHARE = 0.95

#: Share of ρ that the line/arc fit of a sampled curve may use; its blends use
#: ``BLEND_SHARE`` minus the fit's own deviation, so the total stays ≤ 0.95 ρ.
FIT_SHARE = 0.45

#: A junction turning by more than π minus this (rad) is a reversal: a stop, not a blend.
REVERSAL_MARGIN = 1e-3

#: Curvature vectors closer than this (1/m) are continuous: the junction needs no blend.
CURVATURE_JUMP = 1e-6

#: Largest arc angle (rad) that a blend may take from an arc at either end.
ARC_REACH_ANGLE = 0.25 * np.pi

# Remainders of trimmed pieces shorter than this (m) are dropped.
_MIN_PIECE = 1e-12

Mode = Literal["g2", "paper"]


@dataclass(frozen=True, eq=False)
class PathSample:
    """The path at M arc-length values.

    Attributes
    ----------
    s
        Arc length, shape (M,), m.
    position
        p(s), shape (M, 3), m, in the definition frame.
    tangent
        dp/ds, unit, shape (M, 3).
    curvature
        d²p/ds², the curvature vector, shape (M, 3), 1/m.
    curvature_derivative
        d³p/ds³, shape (M, 3), 1/m².
    piece
        Index into ``Path.pieces``, shape (M,).
    """

    s: np.ndarray
    position: np.ndarray
    tangent: np.ndarray
    curvature: np.ndarray
    curvature_derivative: np.ndarray
    piece: np.ndarray


@dataclass(frozen=True, eq=False)
class Path:
    """The planned path.

    Attributes
    ----------
    nominal
        The path as the user gave it.
    pieces
        Lines, arcs and blends end to end on s ∈ [0, length].
    stops
        Interior arc lengths (m) where the speed must be zero: reversals, and in paper mode
        corners left sharp. The ends of the path are rest points and are not listed.
    tolerance
        ρ, m.
    mode
        ``"g2"`` or ``"paper"``.
    """

    nominal: NominalPath
    pieces: tuple[Piece, ...]
    stops: tuple[float, ...]
    tolerance: float
    mode: Mode

    @property
    def length(self) -> float:
        """Total arc length, m."""
        return self.pieces[-1].s_end

    @cached_property
    def zones(self) -> tuple[tuple[float, float, str], ...]:
        """Consecutive ``(s_start, s_end, kind)`` covering [0, length] in order.

        ``kind`` is ``"straight"`` on lines (rated speed applies) and ``"curved"`` on arcs
        and blends (corner speed applies).
        """
        zones: list[tuple[float, float, str]] = []
        for piece in self.pieces:
            kind = "straight" if piece.straight else "curved"
            if zones and zones[-1][2] == kind:
                zones[-1] = (zones[-1][0], piece.s_end, kind)
            else:
                zones.append((piece.s_start, piece.s_end, kind))
        return tuple(zones)

    def sample(self, s: np.ndarray) -> PathSample:
        """Position and arc-length derivatives at arc lengths ``s``.

        Parameters
        ----------
        s
            Shape (M,), m, in [0, length] (values outside by up to 1e-9 m are clipped).

        Raises
        ------
        ValueError
            If a value lies outside [0, length] by more than 1e-9 m.
        """
        s = self._clipped(s)
        jet, piece = evaluate_pieces(self.pieces, s)
        return PathSample(s, *jet, piece)

    def points(self, s: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The arc lengths, positions and unit tangents of :meth:`sample` alone.

        Parameters
        ----------
        s
            Shape (M,), m, in [0, length] (values outside by up to 1e-9 m are clipped).

        Returns
        -------
        tuple of numpy.ndarray
            ``s`` clipped, shape (M,), m; p(s), shape (M, 3), m; dp/ds, shape (M, 3).

        Raises
        ------
        ValueError
            If a value lies outside [0, length] by more than 1e-9 m.
        """
        s = self._clipped(s)
        position, tangent, _ = evaluate_points(self.pieces, s, self._point_table)
        return s, position, tangent

    @cached_property
    def _point_table(self) -> PointTable:
        """The pieces laid out for :meth:`points` (built once)."""
        return PointTable.from_pieces(self.pieces)

    def _clipped(self, s: np.ndarray) -> np.ndarray:
        s = np.atleast_1d(np.asarray(s, dtype=float))
        outside = (s < -1e-9) | (s > self.length + 1e-9)
        if np.any(outside):
            bad = float(s[np.argmax(outside)])
            raise ValueError(f"arc length {bad} m outside the path [0, {self.length}] m")
        clipped: np.ndarray = np.clip(s, 0.0, self.length)
        return clipped


@dataclass(frozen=True, eq=False)
class _Primitive:
    """A line or arc of the plan before blending, with its distance from the nominal path."""

    curve: Primitive
    deviation: float


def _primitives(nominal: NominalPath, tolerance: float) -> list[_Primitive]:
    """Lines and arcs of the nominal path, with sampled curves fitted."""
    out: list[_Primitive] = []
    for i, spec in enumerate(nominal.segments):
        if isinstance(spec, PointsSpec):
            fit = fit_polyline(nominal.vertices(i), FIT_SHARE * tolerance)
            pairs = zip(fit.curves, fit.deviation, strict=True)
            out.extend(_Primitive(curve, float(error)) for curve, error in pairs)
        else:
            out.extend(_Primitive(curve, 0.0) for curve in nominal.segment_curves(i))
    return out


def _classify(primitives: Sequence[_Primitive], mode: Mode) -> list[str]:
    """Treatment of each junction: ``"smooth"``, ``"blend"``, ``"arc"`` or ``"stop"``."""
    kinds = []
    for a, b in pairwise(primitives):
        t_in, t_out, jump = junction_jets(a.curve, b.curve)
        angle = turning_angle(t_in, t_out)
        corner = angle > COLLINEAR_ANGLE
        if angle > np.pi - REVERSAL_MARGIN:
            kinds.append("stop")
        elif not corner and jump <= CURVATURE_JUMP:
            kinds.append("smooth")
        elif mode == "g2":
            kinds.append("blend")
        elif corner and a.curve.kind == "line" and b.curve.kind == "line":
            kinds.append("arc")
        else:
            kinds.append("stop" if corner else "smooth")
    return kinds


def _reach(curve: Primitive) -> float:
    """Largest setback a blend may take from ``curve`` at one end, m.

    Half the curve, so that blends at its two ends never overlap and a line keeps at
    least half its length straight; on an arc at most ``ARC_REACH_ANGLE``.
    """
    reach = 0.5 * curve.length
    if isinstance(curve, Arc):
        reach = min(reach, ARC_REACH_ANGLE * curve.radius)
    return reach


def build_path(nominal: NominalPath, tolerance: float, mode: Mode = "g2") -> Path:
    """Plan the path: fit sampled curves, then blend or round its junctions.

    Parameters
    ----------
    nominal
        The user's path.
    tolerance
        ρ, the largest distance of the planned path from the nominal one, m, > 0.
    mode
        ``"g2"``: every junction where the curvature vector jumps gets a G2 quintic blend;
        the whole path stays within 0.95 ρ of the nominal one. ``"paper"``: line–line
        corners get the tangent arc of Eq. 10 as printed (2ρ from the corner, capped so
        that it fits its legs), sharp junctions involving arcs become stops, and tangent
        line–arc junctions are left as they are.

    Returns
    -------
    Path
        The planned path on s ∈ [0, length].
    """
    if not tolerance > 0.0:
        raise ValueError(f"tolerance must be > 0 m, got {tolerance}")
    if mode not in ("g2", "paper"):
        raise ValueError(f"mode must be 'g2' or 'paper', got {mode!r}")
    primitives = _primitives(nominal, tolerance)
    kinds = _classify(primitives, mode)
    n = len(primitives)
    head = np.zeros(n)
    tail = np.zeros(n)
    corners: dict[int, Curve] = {}
    for j, kind in enumerate(kinds):
        if kind not in ("blend", "arc"):
            continue
        a, b = primitives[j], primitives[j + 1]
        reach = min(_reach(a.curve), _reach(b.curve))
        if kind == "blend":
            budget = BLEND_SHARE * tolerance - max(a.deviation, b.deviation)
            chosen = g2_blend(a.curve, b.curve, budget, reach)
            corners[j], setback = chosen.blend, chosen.setback
        elif isinstance(a.curve, Line) and isinstance(b.curve, Line):  # a paper corner arc
            beta = paper_corner_angle(a.curve.start, b.curve.start, b.curve.end)
            radius = paper_corner_radius(beta, tolerance)
            # The paper does not say what happens when the arc does not fit its legs.
            radius = min(radius, reach * np.tan(0.5 * beta))
            corners[j], setback = tangent_corner_arc(a.curve, b.curve, radius)
        tail[j] = head[j + 1] = setback
    curves: list[Curve] = []
    junction_s_index: list[int] = []
    for k, primitive in enumerate(primitives):
        if primitive.curve.length - head[k] - tail[k] > _MIN_PIECE:
            curves.append(primitive.curve.trimmed(head[k], tail[k]))
        junction_s_index.append(len(curves))
        if k in corners:
            curves.append(corners[k])
    pieces = chain(curves)
    starts = [piece.s_start for piece in pieces] + [pieces[-1].s_end]
    stops = tuple(
        float(starts[junction_s_index[j]]) for j, kind in enumerate(kinds) if kind == "stop"
    )
    return Path(nominal, pieces, stops, float(tolerance), mode)
