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
from trackplan.tool.spec import MIN_NORMAL_LENGTH, ToolFrame, ToolSpec

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
    """The surface normal along the planned path for per-segment normals, C2 in s.

    Each planned piece gets the segment of the nominal path its ends lie on (the nearest
    segment whose tangent agrees, never going back along the path). Where the segment
    changes, the normal changes from the one segment's ``n_a`` to the next one's ``n_b``
    as ``(1 − w) n_a + w n_b`` normalised, ``w`` the :func:`smooth_step` across a window:
    the blend piece that joins the two segments widened by the seam tangent's windows at
    its ends (:func:`junction_window`), or ``± h`` around a junction of two pieces. These
    are the windows in which :class:`SeamTangent` rounds the tangent, so a normal jump is
    blended where a tangent jump is, and the normal is exact everywhere else.

    Attributes
    ----------
    starts
        s of each planned piece's start, shape (P,), m.
    piece_normals
        Unit normal of each planned piece outside the windows, shape (P, 3).
    windows
        Per change of the normal: s0, s1 (m), then n_a and n_b, shape (K, 8).
    """

    starts: np.ndarray
    piece_normals: np.ndarray
    windows: np.ndarray

    @classmethod
    def from_geometry(cls, spec: ToolSpec, geometry: PathGeometry) -> SeamNormal:
        """The segments of the planned pieces and the windows where the normal changes."""
        pieces = geometry.planned.pieces
        segment = _piece_segments(geometry)
        unit = spec.segment_normals(segment.ravel()).reshape(-1, 2, 3)
        h = [junction_window(a, b) for a, b in itertools.pairwise(pieces)] + [0.0]
        windows = []
        for k, piece in enumerate(pieces):
            before = h[k - 1] if k > 0 else 0.0
            if segment[k, 0] != segment[k, 1]:  # a blend from one segment into the next
                s0, s1 = piece.s_start - before, piece.s_end + h[k]
                windows.append([s0, s1, *unit[k, 0], *unit[k, 1]])
            if k + 1 < len(pieces) and segment[k, 1] != segment[k + 1, 0]:
                s0, s1 = piece.s_end - h[k], piece.s_end + h[k]
                windows.append([s0, s1, *unit[k, 1], *unit[k + 1, 0]])
        windows = [row for row in windows if row[1] > row[0] and row[2:5] != row[5:8]]
        starts = np.array([piece.s_start for piece in pieces])
        return cls(starts, unit[:, 0].copy(), np.array(windows, dtype=float).reshape(-1, 8))

    def __call__(self, s: np.ndarray) -> np.ndarray:
        """Unit surface normals at arc lengths ``s`` (M,) of the planned path, shape (M, 3)."""
        s = np.asarray(s, dtype=float)
        piece = np.clip(np.searchsorted(self.starts, s, side="right") - 1, 0, len(self.starts) - 1)
        result = self.piece_normals[piece]
        for s0, s1, *ends in self.windows:
            inside = (s > s0) & (s < s1)
            if not inside.any():
                continue
            w = smooth_step((s[inside] - s0) / (s1 - s0))[:, None]
            n_a, n_b = np.reshape(ends, (2, 3))
            mixed = (1.0 - w) * n_a + w * n_b
            result[inside] = mixed / np.linalg.norm(mixed, axis=1, keepdims=True)
        return result


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

    Each segment's normal must have a component across the tangent everywhere on the
    segment; checked on every piece at its ends and on a 1 mm grid. Per-segment normals of
    neighbouring segments must not be opposite (their blend would pass through zero).

    Returns
    -------
    list of (int or None, str)
        The index into ``normals`` the problem is about (None for the one ``normal``) and
        the message.
    """
    if spec.frame is not ToolFrame.SEAM:
        return []
    given = spec.normals if spec.normals is not None else spec.normal
    if given is None or not np.all(
        np.linalg.norm(np.atleast_2d(given), axis=1) >= MIN_NORMAL_LENGTH
    ):  # refused by the file's own check
        return []
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
    n = spec.segment_normals(segment)
    tangent = jet.tangent
    across = np.linalg.norm(n - np.einsum("mk,mk->m", tangent, n)[:, None] * tangent, axis=1)
    bad = np.flatnonzero(across < PARALLEL_SINE)
    if len(bad):
        at = bad[0]
        index = None if spec.normals is None else int(segment[at])
        whose = "" if index is None else f" of path.segments[{index}]"
        return [
            (
                index,
                f"the normal {np.round(n[at], 6).tolist()}{whose} is parallel to the path "
                f"tangent at s = {s[at]:.4g} m: the seam frame is undefined there; give a "
                "normal across the path (the surface normal)",
            )
        ]
    if spec.normals is not None:
        unit = spec.segment_normals(np.arange(len(spec.normals)))
        opposite = np.flatnonzero(np.einsum("mk,mk->m", unit[:-1], unit[1:]) < -1.0 + 1e-9)
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
