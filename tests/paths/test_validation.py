"""check_segments: degenerate geometry is reported with the key path of the bad value."""

from __future__ import annotations

import numpy as np
import pytest

from trackplan.errors import CaseError
from trackplan.paths import ArcSpec, LineSpec, NominalPath, PointsSpec, check_segments

START = np.zeros(3)
GOOD_LINE = LineSpec(np.array([0.1, 0.0, 0.0]))
GOOD_ARC = ArcSpec(np.array([0.1, 0.0, 0.1]), np.array([0.0, 1.0, 0.0]), 0.5)


def _points(n: int) -> np.ndarray:
    t = np.linspace(0.01, 0.1, n)
    return np.c_[0.2 + t, np.zeros(n), t**2]


BAD_CASES = [
    pytest.param(
        [GOOD_LINE, LineSpec(np.array([0.1, 0.0, 0.2])), LineSpec(np.array([0.1, 0.0, 0.2]))],
        "path.segments[2].line.to",
        "zero length",
        id="zero-length-line",
    ),
    pytest.param(
        [GOOD_LINE, ArcSpec(np.array([0.1, 0.0, 0.0]), np.array([0, 1.0, 0]), 1.0)],
        "path.segments[1].arc.center",
        "zero radius",
        id="arc-center-is-current-point",
    ),
    pytest.param(
        [GOOD_LINE, ArcSpec(np.array([0.0, 0.0, 0.0]), np.array([1.0, 0, 0]), 1.0)],
        "path.segments[1].arc.center",
        "zero radius",
        id="current-point-on-axis",
    ),
    pytest.param(
        [GOOD_LINE, ArcSpec(np.array([0.1, 0.0, 0.1]), np.zeros(3), 1.0)],
        "path.segments[1].arc.normal",
        "non-zero",
        id="zero-normal",
    ),
    pytest.param(
        [GOOD_LINE, ArcSpec(np.array([0.1, 0.0, 0.1]), np.array([0.0, 1.0, 1.0]), 1.0)],
        "path.segments[1].arc.normal",
        "perpendicular",
        id="normal-not-perpendicular",
    ),
    pytest.param(
        [GOOD_LINE, ArcSpec(np.array([0.1, 0.0, 0.1]), np.array([0.0, 1.0, 0.0]), 0.0)],
        "path.segments[1].arc.angle",
        "non-zero",
        id="zero-angle",
    ),
    pytest.param(
        [GOOD_LINE, GOOD_ARC, GOOD_LINE, PointsSpec(np.insert(_points(8), 5, _points(8)[4], 0))],
        "path.segments[3].points[5]",
        "repeats point 4",
        id="duplicate-point",
    ),
    pytest.param(
        [GOOD_LINE, PointsSpec(np.array([[0.1, 0.0, 0.0], [0.2, 0.0, 0.0]]))],
        "path.segments[1].points[0]",
        "current point",
        id="first-point-is-current-point",
    ),
    pytest.param(
        [GOOD_LINE, PointsSpec(np.array([[0.2, 0.0, 0.0]]))],
        "path.segments[1].points",
        "at least 2",
        id="one-point",
    ),
    pytest.param(
        [GOOD_LINE, PointsSpec(np.array([[0.2, 0.0, np.nan], [0.3, 0.0, 0.0]]))],
        "path.segments[1].points",
        "finite",
        id="nan-point",
    ),
]


@pytest.mark.parametrize(("segments", "key", "phrase"), BAD_CASES)
def test_degenerate_segment_is_reported_with_its_key(segments, key, phrase):
    problems = check_segments(START, segments)
    assert len(problems) == 1
    assert problems[0][0] == key
    assert phrase in problems[0][1]


@pytest.mark.parametrize(("segments", "key", "phrase"), BAD_CASES)
def test_nominal_path_refuses_degenerate_segments(segments, key, phrase):
    with pytest.raises(CaseError) as raised:
        NominalPath.from_specs(START, segments)
    assert raised.value.key == key


def test_sound_path_has_no_problems():
    segments = [GOOD_LINE, GOOD_ARC, LineSpec(np.array([0.2, 0.0, 0.0])), PointsSpec(_points(8))]
    assert check_segments(START, segments) == []


def test_all_problems_are_reported_in_order():
    segments = [
        LineSpec(START),
        ArcSpec(np.zeros(3), np.zeros(3), 0.0),
        PointsSpec(np.array([[1.0, 0, 0], [1.0, 0, 0], [2.0, 0, 0], [2.0, 0, 0]])),
    ]
    keys = [key for key, _ in check_segments(START, segments)]
    assert keys == [
        "path.segments[0].line.to",
        "path.segments[1].arc.normal",
        "path.segments[1].arc.angle",
        "path.segments[2].points[1]",
        "path.segments[2].points[3]",
    ]
