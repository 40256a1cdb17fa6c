"""Speed caps and speed-change bounds from the joint demand along the path."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from trackplan.timing.demand import (
    ZoneDemand,
    change_distances,
    speed_change,
    uniform_change_bounds,
    uniform_change_bounds_many,
)
from trackplan.timing.profile import SpeedProfile, speed_change_distance, speed_change_phases

SHARE = 0.97
LENGTH = 0.3
"""Zone length of the synthetic joint paths, m."""


def _wavy_path(amplitude: np.ndarray, rate: np.ndarray, phase: np.ndarray, slope: np.ndarray):
    """q_j(s) = slope_j s + amplitude_j sin(rate_j s + phase_j) and its exact derivatives."""

    def derivatives(s: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        angle = rate * s[:, None] + phase
        d1 = slope + amplitude * rate * np.cos(angle)
        d2 = -amplitude * rate**2 * np.sin(angle)
        d3 = -amplitude * rate**3 * np.cos(angle)
        return d1, d2, d3

    return derivatives


def _demand(derivatives, step: float = 2e-3) -> ZoneDemand:  # type: ignore[no-untyped-def]
    s = np.linspace(0.0, LENGTH, round(LENGTH / step) + 1)
    return ZoneDemand(s, *derivatives(s))


def test_a_straight_joint_path_gets_the_plain_bounds(puma):
    """q' constant, q'' = q''' = 0: |q'| s̈ ≤ q̈max and |q'| s⃛ ≤ q⃛max exactly."""
    slope = np.array([2.0, -1.0, 0.5, 3.0, 0.0, 1.0])
    path = _wavy_path(np.zeros(6), np.ones(6), np.zeros(6), slope)
    change = speed_change(puma, _demand(path), 0.0, LENGTH, 0.0, 0.15, True, SHARE)
    moving = slope != 0
    assert change.accel == pytest.approx(np.min(SHARE * puma.a_max[moving] / np.abs(slope[moving])))
    assert change.jerk == pytest.approx(np.min(SHARE * puma.j_max[moving] / np.abs(slope[moving])))


def test_the_refined_change_is_never_longer_than_the_zone_wide_one(puma):
    path = _wavy_path(np.full(6, 0.05), np.full(6, 20.0), np.arange(6.0), np.full(6, 1.0))
    demand = _demand(path)
    for v_from, v_to in ((0.0, 0.15), (0.15, 0.02), (0.05, 0.1)):
        accel, jerk = uniform_change_bounds(puma, demand.peaks(), max(v_from, v_to), SHARE)
        zone_wide = speed_change_distance(v_from, v_to, accel, jerk)
        refined = speed_change(puma, demand, 0.0, LENGTH, v_from, v_to, v_to > v_from, SHARE)
        assert refined.distance <= zone_wide
    # starting from rest, the joints are slow where the demand is high: much shorter
    assert refined.distance < zone_wide


@settings(max_examples=25, deadline=None, derandomize=True)
@given(
    amplitude=st.floats(0.0, 0.1),
    rate=st.floats(1.0, 40.0),
    slope=st.floats(-3.0, 3.0),
    v_from=st.floats(0.0, 0.2),
    v_to=st.floats(0.0, 0.2),
    at_start=st.booleans(),
)
def test_a_speed_change_meets_the_joint_limits_along_its_stretch(
    puma, amplitude, rate, slope, v_from, v_to, at_start
):
    """Oracle: the exact derivatives of q(s) along the change's own s(t), densely sampled."""
    joints = np.arange(6.0)
    path = _wavy_path(
        np.full(6, amplitude), rate * (1 + 0.1 * joints), joints, slope * (1 - 0.2 * joints)
    )
    demand = _demand(path)
    change = speed_change(puma, demand, 0.0, LENGTH, v_from, v_to, at_start, SHARE)
    if v_from == v_to or not np.isfinite(change.distance) or change.distance > LENGTH:
        return
    phases = speed_change_phases(v_from, v_to, change.accel, change.jerk)
    profile = SpeedProfile.from_phases([(0.0, 0.0), *phases], np.inf)
    t = np.linspace(0.0, profile.duration, 2001)
    travelled, dv, a = profile.evaluate(t)
    v = v_from + dv
    s = (0.0 if at_start else LENGTH - change.distance) + v_from * t + travelled
    k = np.clip(np.searchsorted(profile.t_start, t, side="right") - 1, 0, None)
    j = profile.jerk[k]
    d1, d2, d3 = path(s)
    joint_accel = np.abs(d1 * a[:, None] + d2 * v[:, None] ** 2)
    joint_jerk = np.abs(d1 * j[:, None] + 3 * d2 * (v * a)[:, None] + d3 * v[:, None] ** 3)
    # the change is planned at SHARE of each limit on a 2 mm grid: the rest is the room
    # the grid's linear interpolation may need
    assert np.all(joint_accel <= puma.a_max)
    assert np.all(joint_jerk <= puma.j_max)


def test_vectorised_bounds_match_the_scalar_ones(puma):
    rng = np.random.default_rng(4)
    peaks = tuple(rng.uniform(0.1, 30.0, (3, 6)))
    tops = np.array([0.01, 0.05, 0.1, 0.2])
    accel, jerk = uniform_change_bounds_many(puma, peaks, tops, SHARE)
    for k, top in enumerate(tops):
        assert (accel[k], jerk[k]) == pytest.approx(uniform_change_bounds(puma, peaks, top, SHARE))
    distances = change_distances(np.zeros(4), tops, accel, jerk)
    expected = [
        speed_change_distance(0.0, v, a, j) for v, a, j in zip(tops, accel, jerk, strict=True)
    ]
    np.testing.assert_allclose(distances, np.where(np.array(expected) > 0, expected, np.inf))


def test_stretch_peaks_are_the_maxima_over_the_stretch():
    s = np.linspace(0.0, 0.1, 51)
    rng = np.random.default_rng(5)
    demand = ZoneDemand(s, *rng.normal(size=(3, 51, 6)))
    for distance in (0.0, 0.013, 0.05, 0.1):
        for at_start in (True, False):
            got = demand.stretch_peaks(np.array([distance]), at_start)[0]
            stretch = (0.0, distance) if at_start else (0.1 - distance, 0.1)
            np.testing.assert_array_equal(got, np.array(demand.peaks(*stretch)))
