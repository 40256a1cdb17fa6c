"""Paths: the user's path (nominal) and the planned path (lines, arcs, corner blends).

``NominalPath.from_specs(start, segments)`` builds the path as given;
``build_path(nominal, tolerance, mode)`` plans it on one arc-length parameter s;
``Path.sample(s)`` evaluates position and its arc-length derivatives, ``Path.points(s)``
position and tangent alone.
"""

from trackplan.paths.blending import (
    corrected_corner_radius,
    paper_corner_angle,
    paper_corner_radius,
)
from trackplan.paths.curves import Arc, Line, QuinticBlend
from trackplan.paths.fitting import PolylineFit, fit_polyline
from trackplan.paths.nominal import Corner, NominalPath
from trackplan.paths.piece_table import PieceTable
from trackplan.paths.pieces import Piece
from trackplan.paths.planned import Path, PathSample, build_path
from trackplan.paths.projection import PieceIndex
from trackplan.paths.specs import ArcSpec, LineSpec, PointsSpec, SegmentSpec
from trackplan.paths.validation import check_segments

__all__ = [
    "Arc",
    "ArcSpec",
    "Corner",
    "Line",
    "LineSpec",
    "NominalPath",
    "Path",
    "PathSample",
    "Piece",
    "PieceIndex",
    "PieceTable",
    "PointsSpec",
    "PolylineFit",
    "QuinticBlend",
    "SegmentSpec",
    "build_path",
    "check_segments",
    "corrected_corner_radius",
    "fit_polyline",
    "paper_corner_angle",
    "paper_corner_radius",
]
