"""Transition zones: where the checker allows the tool axis to leave the spec, and how far.

The planned tool orientation (:mod:`trackplan.tool`) follows the spec on the planned path
with a smoothed seam tangent. Blends, corner arcs, fitted curves and the smoothing make
it leave the spec taken on the nominal path near junctions; everywhere else it is exact.
``docs/tool.md`` documents the bound.
"""

from __future__ import annotations

import numpy as np

from trackplan.paths import NominalPath
from trackplan.paths.path_geometry import PathGeometry
from trackplan.planning.tracking import locate_on_nominal
from trackplan.tool import ToolFrame, ToolOrientation, ToolSpec
from trackplan.tool.weld_normal import declares_normals, nominal_normals

ZONE_STEP = 1e-3
"""Four grid steps of the deviation measurement, m."""
EXACT_AXIS = 1e-7
"""Tool axis deviation below which a point counts as exact (outside transition zones), rad."""


def nominal_tangents(nominal: NominalPath, s: np.ndarray, piece: np.ndarray) -> np.ndarray:
    """Unit tangents of the nominal path at arc lengths ``s`` (N,) on pieces ``piece`` (N,).

    Returns
    -------
    numpy.ndarray
        Shape (N, 3).
    """
    return nominal.tangents(s, piece)


def nominal_rotations(
    spec: ToolSpec, nominal: NominalPath, s: np.ndarray, piece: np.ndarray
) -> np.ndarray:
    """The spec's ``R_part_tool`` at zero spin on the nominal path, shape (N, 3, 3).

    At arc lengths ``s`` (N,) on pieces ``piece`` (N,): the nominal tangent there and the
    normal of the segment the piece belongs to (per-segment ``normals``, or the segment's
    own weld normal there), so the spec's normal jumps exactly at the segment junctions.
    A part-frame spec does not depend on the tangent.
    """
    if spec.frame is ToolFrame.PART:
        return spec.base_rotations(np.zeros((len(s), 3)))
    tangent = nominal_tangents(nominal, s, piece)
    if declares_normals(nominal.segments):
        return spec.base_rotations(tangent, nominal_normals(spec, nominal, s, piece))
    if spec.normals is None:
        return spec.base_rotations(tangent)
    return spec.base_rotations(tangent, spec.segment_normals(nominal.segment_index[piece]))


def transition_zones(spec: ToolSpec, geometry: PathGeometry, tolerance: float) -> np.ndarray:
    """Where the planned tool axis may leave the spec on the nominal path, and how far.

    The planned orientation follows the spec on the planned path with the smoothed seam
    tangent (:class:`trackplan.tool.SeamTangent`) and normal
    (:class:`trackplan.tool.SeamNormal`); it leaves the spec taken on the nominal path in
    blends, corner arcs and fitted curves (pieces of the planned path off the nominal path)
    and where the smoothing rounds a junction or blends a normal jump. On a grid of
    ``ZONE_STEP / 4`` along the planned path the deviation of the tool axis is measured;
    every run of grid points deviating more than ``EXACT_AXIS`` (padded by ten points) is
    a transition zone. Its bound is the largest deviation measured in it plus the largest
    change between neighbouring grid points (what can hide between them).

    Parameters
    ----------
    spec
        The tool spec.
    geometry
        The case's paths.
    tolerance
        ρ, m: the grid points are located on the nominal path as the checker locates the
        samples (:func:`~trackplan.planning.tracking.locate_on_nominal`).

    Returns
    -------
    numpy.ndarray
        Shape (K, 3): nominal arc length at the zone's start and end (m) and the bound
        (rad).
    """
    planned, nominal = geometry.planned, geometry.nominal
    step = 0.25 * ZONE_STEP
    s = np.linspace(0.0, planned.length, max(3, int(np.ceil(planned.length / step)) + 1))
    sample = planned.sample(s)
    axis = ToolOrientation.choose(spec, geometry).base_rotations(s, sample.tangent)[:, :, 2]
    s_nominal, _, piece = locate_on_nominal(nominal, sample.position, sample.tangent, tolerance)
    expected = nominal_rotations(spec, nominal, s_nominal, piece)[:, :, 2]
    deviation = np.arccos(np.clip(np.einsum("mi,mi->m", axis, expected), -1.0, 1.0))
    off = deviation > EXACT_AXIS
    off = np.convolve(off.astype(float), np.ones(21), mode="same") > 0  # pad: 10 points
    edges = np.flatnonzero(np.diff(np.concatenate([[0], off.astype(int), [0]])))
    zones = []
    for first, end in zip(edges[::2], edges[1::2], strict=True):
        run = slice(first, end)
        change = np.abs(np.diff(deviation[max(first - 1, 0) : end + 1]))
        bound = deviation[run].max() + (change.max() if change.size else 0.0) + EXACT_AXIS
        zones.append((s_nominal[run].min(), s_nominal[run].max(), bound))
    return np.array(zones, dtype=float).reshape(-1, 3)
