"""The weave's shapes and offsets (``trackplan.tool.weave``, docs/positioner.md#weaving)."""

from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np
import pytest

import trackplan
from trackplan.errors import CaseError
from trackplan.paths.path_geometry import WEAVE_GRID_POINTS, PathGeometry
from trackplan.paths.specs import ArcSpec, LineSpec
from trackplan.tool import ToolOrientation, ToolSpec
from trackplan.tool.weave import (
    TRIANGLE_ROUNDING,
    Weave,
    WeavePattern,
    WovenPath,
    weave_offsets,
    weave_reached,
    weave_shape,
)

CASES = Path(__file__).parents[2] / "cases"

STEP = 1e-5
"""Phase step of the finite differences, periods."""


def _derivatives(pattern: WeavePattern, dwell: float) -> list[np.ndarray]:
    u = np.arange(-1.0, 2.0, STEP)
    w = weave_shape(pattern, u, dwell)
    d1 = np.diff(w) / STEP
    d2 = np.diff(d1) / STEP
    return [w, d1, d2, np.diff(d2) / STEP]


@pytest.mark.parametrize(
    ("pattern", "dwell"),
    [(WeavePattern.SINE, 0.0), (WeavePattern.TRIANGLE, 0.0), (WeavePattern.TRAPEZOID, 0.1)],
)
def test_shape_peaks_at_one_and_is_c2(pattern: WeavePattern, dwell: float) -> None:
    w, d1, d2, d3 = _derivatives(pattern, dwell)
    assert w.max() == pytest.approx(1.0, abs=1e-9)
    assert w.min() == pytest.approx(-1.0, abs=1e-9)
    assert weave_shape(pattern, np.array([0.0]), dwell)[0] == pytest.approx(0.0, abs=1e-12)
    assert d1[int(1.0 / STEP)] > 0.0  # rising at u = 0
    # C2: the second derivative never jumps (its steps shrink with the step), the third
    # stays bounded (a bounded jerk)
    assert np.abs(np.diff(d2)).max() < 1e-3 * np.abs(d2).max()
    assert np.abs(d3).max() < 5e3


def test_triangle_has_straight_flanks_outside_the_rounding() -> None:
    u = np.linspace(TRIANGLE_ROUNDING + 0.01 - 0.25, 0.25 - TRIANGLE_ROUNDING - 0.01, 50)
    w = weave_shape(WeavePattern.TRIANGLE, u)
    slope = np.diff(w) / np.diff(u)
    np.testing.assert_allclose(slope, slope[0], rtol=1e-9)
    assert slope[0] == pytest.approx(1.0 / (0.25 - 3.0 * TRIANGLE_ROUNDING / 8.0))


def test_trapezoid_holds_each_side_for_the_dwell() -> None:
    weave = Weave(pattern="trapezoid", amplitude=0.002, frequency=2.0, dwell=0.05)
    held = weave.dwell * weave.frequency  # periods
    u = 0.25 + np.linspace(-held / 2, held / 2, 11)
    np.testing.assert_allclose(weave_shape(weave.pattern, u, held), 1.0, atol=1e-12)
    np.testing.assert_allclose(weave_shape(weave.pattern, u + 0.5, held), -1.0, atol=1e-12)


def test_offset_phase_runs_over_arc_length_at_the_rated_speed() -> None:
    track = Weave(pattern="sine", amplitude=0.002, frequency=2.0).along(0.02)
    assert track.wavelength == pytest.approx(0.01)
    s = np.array([0.0, 0.0025, 0.005, 0.0075, 0.0125])
    np.testing.assert_allclose(track.offset(s), [0, 0.002, 0, -0.002, 0.002], atol=1e-12)


def _line(weave: Weave | None) -> PathGeometry:
    segments = [LineSpec(to=np.array([0.1, 0.0, 0.0]))]
    track = None if weave is None else weave.along(0.02)
    return PathGeometry.build(np.zeros(3), segments, 5e-4, weave=track)


def test_the_grid_resolves_the_weave() -> None:
    weave = Weave(amplitude=0.002, frequency=2.0)
    (grid,) = _line(weave).zone_grids()
    assert np.diff(grid).max() <= 0.01 / WEAVE_GRID_POINTS * (1 + 1e-9)
    (plain,) = _line(None).zone_grids()
    assert len(plain) < len(grid)


def test_seam_weave_runs_along_the_seam_y_axis_and_unweaves() -> None:
    weave = Weave(pattern="triangle", amplitude=0.002, frequency=2.0)
    geometry = _line(weave)
    spec = ToolSpec(frame="seam", normal=np.array([0.0, 0.0, 1.0]), travel_angle=-0.3)
    tool = ToolOrientation.choose(spec, geometry)
    s = np.linspace(0.0, 0.1, 401)
    s, position, tangent = geometry.planned.points(s)
    rotations = tool.rotations(s, tangent)
    offsets = weave_offsets(geometry.weave, tool, s, tangent, rotations)  # type: ignore[arg-type]
    # the seam frame's y axis on a line along +x with the normal +z: −y
    np.testing.assert_allclose(offsets[:, [0, 2]], 0.0, atol=1e-15)
    np.testing.assert_allclose(
        -offsets[:, 1], weave.amplitude * weave_shape(weave.pattern, s / 0.01)
    )
    woven = WovenPath(geometry.weave, geometry.planned, tool)  # type: ignore[arg-type]
    centre, lateral, expected, found = woven.unweave(position + offsets, rotations)
    np.testing.assert_allclose(found, s, atol=1e-9)
    np.testing.assert_allclose(centre, position, atol=1e-12)
    np.testing.assert_allclose(lateral, expected, atol=1e-12)


def test_tool_plane_follows_the_tools_y_axis() -> None:
    weave = Weave(pattern="sine", plane="tool", amplitude=0.001, frequency=1.0)
    geometry = _line(weave)
    spec = ToolSpec(frame="seam", normal=np.array([0.0, 0.0, 1.0]), spin="fixed", spin_value=0.4)
    tool = ToolOrientation.choose(spec, geometry)
    s, _, tangent = geometry.planned.points(np.linspace(0.0, 0.1, 50))
    rotations = tool.rotations(s, tangent)
    offsets = weave_offsets(geometry.weave, tool, s, tangent, rotations)  # type: ignore[arg-type]
    np.testing.assert_allclose(
        offsets,
        geometry.weave.offset(s)[:, None] * rotations[:, :, 1],
        atol=1e-15,  # type: ignore[union-attr]
    )


def test_a_weave_wider_than_a_curve_is_refused_in_one_line() -> None:
    """kuka-weld's sharp corner is blended with a radius of about 1.6 mm (tolerance
    0.5 mm): a 2 mm weave would fold on its inner side."""
    case = trackplan.load_case(CASES / "kuka-weld.yaml")
    task = dataclasses.replace(case.task, weave=Weave(amplitude=0.002, frequency=2.0))
    with pytest.raises(CaseError, match=r"task\.weave\.amplitude: .*radius 0\.0016 m") as error:
        PathGeometry.from_case(dataclasses.replace(case, task=task))
    assert "\n" not in str(error.value)
    # a 1 mm weave fits
    task = dataclasses.replace(case.task, weave=Weave(amplitude=0.001, frequency=2.0))
    assert PathGeometry.from_case(dataclasses.replace(case, task=task)).weave is not None


def test_unweave_on_an_arc_is_exact() -> None:
    """A 4 mm weave round a 30 mm arc: the samples' arc lengths and centre line to well
    below the IK's tolerance (the checker's speed differences of centre points read them)."""
    weave = Weave(pattern="sine", amplitude=0.004, frequency=2.0)
    arc = ArcSpec(center=np.array([0.0, 0.03, 0.0]), normal=np.array([0.0, 0.0, 1.0]), angle=1.5)
    geometry = PathGeometry.build(np.zeros(3), [arc], 5e-4, weave=weave.along(0.02))
    spec = ToolSpec(frame="seam", normal=np.array([0.0, 0.0, 1.0]))
    tool = ToolOrientation.choose(spec, geometry)
    s, position, tangent = geometry.planned.points(np.linspace(0.0, geometry.planned.length, 301))
    rotations = tool.rotations(s, tangent)
    woven = WovenPath(geometry.weave, geometry.planned, tool)  # type: ignore[arg-type]
    points = position + weave_offsets(woven.track, tool, s, tangent, rotations)
    centre, lateral, expected, found = woven.unweave(points, rotations)
    np.testing.assert_allclose(found, s, atol=1e-12)
    np.testing.assert_allclose(centre, position, atol=1e-12)
    np.testing.assert_allclose(lateral, expected, atol=1e-12)
    assert np.abs(expected).max() == pytest.approx(0.004, rel=1e-3)


def test_weave_reached_from_samples_at_and_below_the_rated_speed() -> None:
    """A sine weave sampled at 4 ms: 1.2 s at the rated speed 0.02 m/s, then 2.4 s at
    half of it. The amplitude is the weave's; the frequency is read where the seam runs at
    its rated speed (2 Hz), not the slower stretch's 1 Hz."""
    weave = Weave(pattern="sine", amplitude=0.002, frequency=2.0)
    geometry = _line(weave)
    tool = ToolOrientation.choose(
        ToolSpec(frame="seam", normal=np.array([0.0, 0.0, 1.0])), geometry
    )
    t = np.arange(0.0, 3.6, 0.004)
    s = np.where(t < 1.2, 0.02 * t, 0.024 + 0.01 * (t - 1.2))
    s, position, tangent = geometry.planned.points(s)
    rotations = tool.rotations(s, tangent)
    woven = WovenPath(geometry.weave, geometry.planned, tool)  # type: ignore[arg-type]
    points = position + weave_offsets(woven.track, tool, s, tangent, rotations)
    reached = weave_reached(woven, points, rotations, 0.004, 0.02)
    assert reached.amplitude == pytest.approx(0.002, rel=1e-3)
    assert reached.frequency == pytest.approx(2.0, rel=1e-6)
    assert reached.as_dict()["pattern"] == "sine"
    # never at the rated speed: every period counts
    slow = weave_reached(woven, points[t >= 1.2], rotations[t >= 1.2], 0.004, 0.02)
    assert slow.frequency == pytest.approx(1.0, rel=1e-6)
