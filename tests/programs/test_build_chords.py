"""Points of a curved stretch within a chord error (trackplan.programs.chords)."""

from __future__ import annotations

import numpy as np
import pytest

from tests.programs.roundtrip import planned_run
from trackplan.programs.chords import chord_errors, spline_points


def blend_path():  # type: ignore[no-untyped-def]
    path = planned_run("paper-corner").plan.seams[0].plan.joint_path.geometry.planned
    piece = next(p for p in path.pieces if p.kind == "blend")
    return path, piece.s_start, piece.s_end


@pytest.mark.parametrize("chord", [1e-4, 2e-5, 1e-6])
def test_the_points_keep_the_polyline_within_the_chord(chord: float) -> None:
    path, s0, s1 = blend_path()
    s, error = spline_points(path, s0, s1, chord)
    assert s[-1] == s1 and np.all(np.diff(s) > 0) and s[0] > s0
    assert 0.0 < error <= chord
    # measured again on a finer sample of every chord: the bound holds there too
    _, points, _ = path.points(np.concatenate([[s0], s]))
    fine = np.linspace(s0, s1, 20001)
    _, curve, _ = path.points(fine)
    index = np.clip(
        np.searchsorted(np.concatenate([[s0], s]), fine, side="right") - 1, 0, len(s) - 1
    )
    a, b = points[index], points[index + 1]
    ab = b - a
    along = np.clip(np.sum((curve - a) * ab, axis=1) / np.sum(ab * ab, axis=1), 0, 1)
    distance = np.linalg.norm(curve - a - along[:, None] * ab, axis=1)
    assert distance.max() <= chord * (1 + 1e-3)
    # not wasteful: a tenth of the points would break the bound
    coarse = np.linspace(s0, s1, max(2, len(s) // 10 + 1))
    if len(s) >= 20:
        assert chord_errors(path, coarse).max() > chord


def test_a_straight_or_vanishing_stretch_is_one_point() -> None:
    path, s0, _ = blend_path()
    line = path.pieces[0]
    s, error = spline_points(path, line.s_start, line.s_end, 1e-5)
    assert s.tolist() == [line.s_end] and error < 1e-12
    s, error = spline_points(path, s0, s0 + 1e-15, 1e-5)
    assert s.tolist() == [s0 + 1e-15] and error < 1e-20
    s, error = spline_points(path, s0, s0, 1e-5)
    assert s.tolist() == [s0] and error == 0.0
