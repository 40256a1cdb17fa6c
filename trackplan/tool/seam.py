"""The seam frame along the planned path: its tangent and surface normal, rounded to C2.

:class:`SeamTangent` rounds the planned path's tangent at every junction and
:class:`SeamNormal` blends per-segment normals across the same windows;
:func:`seam_problems` says where the seam frame of a spec is undefined on a path.
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass

import numpy as np

from trackplan.paths.nominal import NominalPath
from trackplan.paths.path_geometry import PathGeometry
from trackplan.paths.pieces import Piece
from trackplan.paths.specs import PointsSpec
from trackplan.tool.spec import MIN_NORMAL_LENGTH, ToolFrame, ToolSpec
from trackplan.tool.weld_normal import (
    ConstantNormal,
    NormalField,
    PointsNormal,
    declared_lengths,
    declares_normals,
    nominal_normals,
    segment_fields,
    segment_starts,
)

PARALLEL_SINE = 1e-3
"""A normal whose component across the tangent is below this share of its length is parallel."""
ZONE_STEP = 1e-3
"""Arc-length step on which the seam frame is checked for a normal along the path, m."""
SEAM_SMOOTHING = 5e-3
"""Half-width of the window in which the seam tangent is rounded at a junction, m."""


@dataclass(frozen=True, eq=False)
class SeamTangent:
    """The planned path's tangent, rounded at every junction so that it is C2 in s.

    A G2 blend keeps the tangent's turning rate continuous but not its derivative, so a
    seam frame that followed the tangent exactly would jump in angular acceleration at
    every junction of the planned path and jolt the wrist. Within ``h`` of a junction
    (``h`` the smaller of :data:`SEAM_SMOOTHING` and half of each neighbouring piece) the
    tangent is ``(1 − w) T_a + w T_b`` normalised: ``T_a`` the incoming piece's tangent,
    continued past the junction by its second-order Taylor expansion (tangent, curvature
    vector and its derivative there), ``T_b`` the outgoing one continued backwards, and
    ``w`` the quintic step ``6u⁵ − 15u⁴ + 10u³`` of ``u`` from 0 to 1 across the window
    (zero first and second derivatives at both ends). Outside the windows it is the exact
    tangent. :func:`trackplan.planning.tool_zones.transition_zones` measures the deviation.

    Attributes
    ----------
    geometry
        The case's paths.
    junctions
        Per junction: s (m), h (m), then the incoming and outgoing tangent, curvature vector
        and its derivative there, shape (J, 20).
    """

    geometry: PathGeometry
    junctions: np.ndarray

    @classmethod
    def from_geometry(cls, geometry: PathGeometry) -> SeamTangent:
        """The junctions of the planned path and their windows."""
        pieces = geometry.planned.pieces
        rows = []
        for a, b in itertools.pairwise(pieces):
            h = junction_window(a, b)
            if h <= 0.0:
                continue
            end = a.curve.evaluate(np.array([a.length]))
            start = b.curve.evaluate(np.array([0.0]))
            jets = [end.tangent, end.curvature, end.curvature_derivative]
            jets += [start.tangent, start.curvature, start.curvature_derivative]
            rows.append(np.concatenate([[b.s_start, h], *[j[0] for j in jets]]))
        return cls(geometry, np.array(rows, dtype=float).reshape(-1, 20))

    def __call__(self, s: np.ndarray, tangent: np.ndarray | None = None) -> np.ndarray:
        """Unit tangents at arc lengths ``s`` (M,), shape (M, 3).

        ``tangent`` (M, 3), the planned path's at ``s``, saves sampling the path again.
        """
        s = np.asarray(s, dtype=float)
        exact = self.geometry.planned.sample(s).tangent if tangent is None else tangent
        result = np.array(exact, dtype=float)
        for row in self.junctions:
            s_j, h = row[0], row[1]
            near = np.abs(s - s_j) < h
            if not near.any():
                continue
            d = (s[near] - s_j)[:, None]
            t_a, k_a, dk_a, t_b, k_b, dk_b = row[2:].reshape(6, 3)
            before = d < 0.0
            T_a = np.where(before, exact[near], t_a + k_a * d + 0.5 * dk_a * d**2)
            T_b = np.where(before, t_b + k_b * d + 0.5 * dk_b * d**2, exact[near])
            w = smooth_step((d + h) / (2 * h))
            mixed = (1.0 - w) * T_a + w * T_b
            norm = np.linalg.norm(mixed, axis=1, keepdims=True)
            result[near] = np.where(norm > 1e-9, mixed / np.maximum(norm, 1e-300), exact[near])
        return result


def junction_window(a: Piece, b: Piece) -> float:
    """Half-width h of the window in which the seam frame is rounded at the junction of
    planned pieces a and b: :data:`SEAM_SMOOTHING`, at most half of either piece, m."""
    return min(SEAM_SMOOTHING, 0.5 * a.length, 0.5 * b.length)


def smooth_step(u: np.ndarray) -> np.ndarray:
    """The quintic step ``6u⁵ − 15u⁴ + 10u³`` from 0 to 1 for u in [0, 1] (zero first and
    second derivatives at both ends), shape of u."""
    return u**3 * (10.0 - 15.0 * u + 6.0 * u**2)


@dataclass(frozen=True, eq=False)
class SeamNormal:
    """The surface normal along the planned path, C2 in s.

    Each planned piece gets the segment of the nominal path its ends lie on (the nearest
    segment whose tangent agrees, never going back along the path), and the segment's
    normal field (:func:`~trackplan.tool.weld_normal.segment_fields`: the tool's constant
    normal, or the segment's own turning weld normal). Where the segment changes, the
    normal changes from the one segment's ``n_a`` to the next one's ``n_b`` as
    ``(1 − w) n_a + w n_b`` normalised (both fields evaluated at the point), ``w`` the
    :func:`smooth_step` across a window: the blend piece that joins the two segments
    widened by the seam tangent's windows at its ends (:func:`junction_window`), or ``± h``
    around a junction of two pieces. These are the windows in which :class:`SeamTangent`
    rounds the tangent, so a normal jump is blended where a tangent jump is, and the normal
    is the segment's everywhere else.

    A field given by arc length along its segment (per-point normals) is evaluated at
    ``σ = (s − s_a) L / (s_b − s_a)``: ``L`` the nominal segment's length and ``[s_a, s_b]``
    its span on the planned path (from the middle of the blend or the junction before it
    to the one after it), an affine map, so the normal stays C2 in s.

    Attributes
    ----------
    geometry
        The case's paths.
    starts
        s of each planned piece's start, shape (P,), m.
    piece_segment
        The segment of each planned piece outside the windows, shape (P,).
    fields
        The normal field of each segment.
    scale
        Per segment: s_a (m) and L / (s_b − s_a), shape (S, 2).
    windows
        Per change of the segment: s0, s1 (m), then the segments a and b, shape (K, 4).
    """

    geometry: PathGeometry
    starts: np.ndarray
    piece_segment: np.ndarray
    fields: tuple[NormalField, ...]
    scale: np.ndarray
    windows: np.ndarray

    @classmethod
    def from_geometry(cls, spec: ToolSpec, geometry: PathGeometry) -> SeamNormal:
        """The segments of the planned pieces and the windows where the normal changes."""
        pieces = geometry.planned.pieces
        nominal = geometry.nominal
        segment = _piece_segments(geometry)
        fields = tuple(segment_fields(spec, nominal))
        h = [junction_window(a, b) for a, b in itertools.pairwise(pieces)] + [0.0]
        windows: list[list[float]] = []
        bounds: dict[int, float] = {}  # s on the planned path where segment g + 1 starts
        for k, piece in enumerate(pieces):
            before = h[k - 1] if k > 0 else 0.0
            a, b = int(segment[k, 0]), int(segment[k, 1])
            if a != b:  # a blend from one segment into the next
                windows.append([piece.s_start - before, piece.s_end + h[k], a, b])
                bounds.setdefault(a, 0.5 * (piece.s_start + piece.s_end))
            if k + 1 < len(pieces) and b != segment[k + 1, 0]:
                windows.append([piece.s_end - h[k], piece.s_end + h[k], b, int(segment[k + 1, 0])])
                bounds.setdefault(b, piece.s_end)
        windows = [
            row
            for row in windows
            if row[1] > row[0] and not _same_constant(fields[int(row[2])], fields[int(row[3])])
        ]
        ratio = geometry.planned.length / nominal.length
        nominal_starts = segment_starts(nominal)
        nominal_ends = np.append(nominal_starts[1:], nominal.length)
        scale = np.empty((len(fields), 2))
        for g in range(len(fields)):
            s_a = bounds.get(g - 1, nominal_starts[g] * ratio) if g > 0 else 0.0
            s_b = bounds.get(g, nominal_ends[g] * ratio)
            if g == len(fields) - 1:
                s_b = geometry.planned.length
            span = nominal_ends[g] - nominal_starts[g]
            scale[g] = s_a, span / (s_b - s_a) if s_b > s_a else 1.0
        starts = np.array([piece.s_start for piece in pieces])
        return cls(
            geometry,
            starts,
            segment[:, 0].copy(),
            fields,
            scale,
            np.array(windows, dtype=float).reshape(-1, 4),
        )

    def _unit(self, g: int, s: np.ndarray, position: np.ndarray | None) -> np.ndarray:
        """Unit normals of segment g's field at planned arc lengths ``s`` (M,), (M, 3)."""
        field = self.fields[g]
        if position is None and not isinstance(field, ConstantNormal | PointsNormal):
            position = self.geometry.planned.sample(s).position
        s_a, ratio = self.scale[g]
        n = field(np.zeros((len(s), 3)) if position is None else position, (s - s_a) * ratio)
        return np.asarray(n / np.linalg.norm(n, axis=1, keepdims=True), dtype=float)

    def __call__(self, s: np.ndarray, position: np.ndarray | None = None) -> np.ndarray:
        """Unit surface normals at arc lengths ``s`` (M,) of the planned path, shape (M, 3).

        ``position`` (M, 3), the planned path's points at ``s``, saves sampling the path
        again (fields that turn with the point need them).
        """
        s = np.asarray(s, dtype=float)
        if position is None and any(
            not isinstance(field, ConstantNormal | PointsNormal) for field in self.fields
        ):
            position = self.geometry.planned.sample(s).position
        piece = np.clip(np.searchsorted(self.starts, s, side="right") - 1, 0, len(self.starts) - 1)
        segment = self.piece_segment[piece]
        result = np.empty((len(s), 3))
        for g in np.unique(segment):
            on = segment == g
            result[on] = self._unit(int(g), s[on], None if position is None else position[on])
        for s0, s1, a, b in self.windows:
            inside = (s > s0) & (s < s1)
            if not inside.any():
                continue
            at = None if position is None else position[inside]
            w = smooth_step((s[inside] - s0) / (s1 - s0))[:, None]
            n_a = self._unit(int(a), s[inside], at)
            n_b = self._unit(int(b), s[inside], at)
            mixed = (1.0 - w) * n_a + w * n_b
            result[inside] = mixed / np.linalg.norm(mixed, axis=1, keepdims=True)
        return result


def _same_constant(a: NormalField, b: NormalField) -> bool:
    """Whether two fields are the same constant normal (no window needed between them)."""
    if not isinstance(a, ConstantNormal) or not isinstance(b, ConstantNormal):
        return False
    unit_a = a.normal / np.linalg.norm(a.normal)
    return bool(np.array_equal(unit_a, b.normal / np.linalg.norm(b.normal)))


def _piece_segments(geometry: PathGeometry) -> np.ndarray:
    """The nominal segment at the start and at the end of each planned piece, (P, 2) ints.

    A point just inside each end (1 µm, or a quarter of a shorter piece) is assigned the
    nearest nominal piece (within 1e-9 m of the nearest) whose tangent agrees with the
    planned one, and the first such piece at or after the previous assignment, so that a
    path that doubles back on itself keeps its order.
    """
    pieces, nominal = geometry.planned.pieces, geometry.nominal
    inset = np.array(
        [[min(1e-6, 0.25 * p.length), p.length - min(1e-6, 0.25 * p.length)] for p in pieces]
    )
    jets = [piece.curve.evaluate(sigma) for piece, sigma in zip(pieces, inset, strict=True)]
    points = np.concatenate([jet.position for jet in jets])
    tangents = np.concatenate([jet.tangent for jet in jets])
    distance = np.empty((len(points), len(nominal.pieces)))
    agrees = np.empty(distance.shape, dtype=bool)
    for j, curve in enumerate(nominal.curves):
        sigma, distance[:, j] = curve.project(points)
        agrees[:, j] = np.einsum("nk,nk->n", curve.evaluate(sigma).tangent, tangents) > 0.0
    near = distance <= distance.min(axis=1, keepdims=True) + 1e-9
    candidate = near & agrees
    none = ~candidate.any(axis=1)
    candidate[none] = near[none]
    assigned = np.empty(len(points), dtype=int)
    previous = 0
    for i, row in enumerate(candidate):
        later = np.flatnonzero(row[previous:])
        previous = previous + int(later[0]) if later.size else int(np.flatnonzero(row)[0])
        assigned[i] = previous
    return nominal.segment_index[assigned].reshape(-1, 2)


def seam_problems(spec: ToolSpec, nominal: NominalPath) -> list[tuple[int | None, str]]:
    """Why the seam frame is undefined on this path (empty when it is defined).

    Each segment's normal (the tool's, or the segment's own weld normal) must have a
    component across the tangent everywhere on the segment; checked on every piece at its
    ends and on a 1 mm grid. An interpolated normal must not pass through zero between two
    points, and the normals either side of a junction must not be opposite (their blend
    would pass through zero).

    Returns
    -------
    list of (int or None, str)
        The index into ``normals`` the problem is about (None for the one ``normal``),
        or the path segment's with its own normal, and the message.
    """
    if spec.frame is not ToolFrame.SEAM:
        return []
    given = spec.normals if spec.normals is not None else spec.normal
    own = declares_normals(nominal.segments)
    if (given is None and not own) or (
        given is not None
        and not np.all(np.linalg.norm(np.atleast_2d(given), axis=1) >= MIN_NORMAL_LENGTH)
    ):  # refused by the file's own check
        return []
    if own and not np.all(declared_lengths(nominal.segments) >= MIN_NORMAL_LENGTH):
        return []  # refused by the case file's check of the segments
    table = nominal.table
    s = np.unique(
        np.concatenate(
            [
                np.linspace(0.0, nominal.length, max(2, int(nominal.length / ZONE_STEP))),
                table.s_start,
                table.s_start + table.length - 1e-12,
            ]
        )
    )
    s = np.clip(s, 0.0, nominal.length)
    jet, piece = nominal.evaluate(s)
    segment = nominal.segment_index[piece]
    raw = nominal_normals(spec, nominal, s, piece) if own else spec.segment_normals(segment)
    length = np.linalg.norm(raw, axis=1)
    tangent = jet.tangent
    n = raw / np.maximum(length, 1e-300)[:, None]
    across = np.linalg.norm(n - np.einsum("mk,mk->m", tangent, n)[:, None] * tangent, axis=1)
    fails = across < PARALLEL_SINE
    if own:
        fails |= length < 0.1  # a spline of unit normals shrinks only where they turn about
    bad = np.flatnonzero(fails)
    if len(bad):
        at = bad[0]
        g = int(segment[at])
        index = None if spec.normals is None and not own else g
        whose = "" if index is None else f" of path.segments[{index}]"
        segment_spec = nominal.segments[g]
        if isinstance(segment_spec, PointsSpec) and segment_spec.normals is not None:
            steps = np.linalg.norm(np.diff(nominal.vertices(g), axis=0), axis=1)
            sigma = s[at] - table.s_start[np.flatnonzero(nominal.segment_index == g)[0]]
            whose += f" (near its point {int(np.argmin(np.abs(np.cumsum(steps) - sigma)))})"
        if length[at] < 0.1:
            return [
                (
                    index,
                    f"the normals of path.segments[{g}] turn by nearly half a turn between two "
                    f"points near s = {s[at]:.4g} m: they cannot be interpolated there; give "
                    "the normal of more points where it turns",
                )
            ]
        return [
            (
                index,
                f"the normal {np.round(n[at], 6).tolist()}{whose} is parallel to the path "
                f"tangent at s = {s[at]:.4g} m: the seam frame is undefined there; give a "
                "normal across the path (the surface normal)",
            )
        ]
    if spec.normals is not None or own:
        first = table.s_start[np.r_[0, np.flatnonzero(np.diff(nominal.segment_index)) + 1]]
        last_piece = np.r_[np.flatnonzero(np.diff(nominal.segment_index)), table.n_pieces - 1]
        ends = table.s_start[last_piece] + table.length[last_piece]
        start_normals = nominal_normals(spec, nominal, first, nominal.evaluate(first)[1])
        end_normals = nominal_normals(spec, nominal, ends, last_piece)
        unit_a = end_normals[:-1] / np.linalg.norm(end_normals[:-1], axis=1, keepdims=True)
        unit_b = start_normals[1:] / np.linalg.norm(start_normals[1:], axis=1, keepdims=True)
        opposite = np.flatnonzero(np.einsum("mk,mk->m", unit_a, unit_b) < -1.0 + 1e-9)
        if len(opposite):
            i = int(opposite[0])
            return [
                (
                    i + 1,
                    f"the normals of path.segments[{i}] and [{i + 1}] are opposite: the normal "
                    "cannot turn smoothly between them; give the surface normal of each side",
                )
            ]
    return []
