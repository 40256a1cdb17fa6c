"""Speed caps and speed-change bounds from the joint demand along the path."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from tests.tolerances import assert_ulp_close
from trackplan.timing.demand import (
    ZoneDemand,
    _changes_within_limits,
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


@pytest.mark.parametrize(("first", "stop"), [(0, 51), (0, 7), (12, 40), (50, 51)])
def test_a_part_is_the_demand_of_its_rows(first, stop):
    """A part reads its zone's magnitudes: the same as a demand built from its rows."""
    s = np.linspace(0.0, 0.1, 51)
    rng = np.random.default_rng(7)
    demand = ZoneDemand(s, *rng.normal(size=(3, 51, 6)))
    part = demand.part(first, stop)
    built = ZoneDemand(s[first:stop], *(d[first:stop] for d in (demand.d1, demand.d2, demand.d3)))
    for name in ("s", "d1", "d2", "d3", "peak_array"):
        np.testing.assert_array_equal(getattr(part, name), getattr(built, name))
    for got, expected in zip(part.absolute, built.absolute, strict=True):
        np.testing.assert_array_equal(got, expected)
    for backward in (0, 1):
        np.testing.assert_array_equal(part.running_maxima(backward), built.running_maxima(backward))
    np.testing.assert_array_equal(part.peaks(0.03, 0.05), built.peaks(0.03, 0.05))


def test_stretch_peaks_are_the_maxima_over_the_stretch():
    s = np.linspace(0.0, 0.1, 51)
    rng = np.random.default_rng(5)
    demand = ZoneDemand(s, *rng.normal(size=(3, 51, 6)))
    for distance in (0.0, 0.013, 0.05, 0.1):
        for at_start in (True, False):
            got = demand.stretch_peaks(np.array([distance]), at_start)[0]
            stretch = (0.0, distance) if at_start else (0.1 - distance, 0.1)
            np.testing.assert_array_equal(got, np.array(demand.peaks(*stretch)))


@settings(max_examples=20, deadline=None, derandomize=True)
@given(
    amplitude=st.floats(0.0, 0.1),
    rate=st.floats(1.0, 40.0),
    slope=st.floats(-3.0, 3.0),
    share=st.floats(0.5, 1.0),
    rise=st.booleans(),
)
def test_compiled_quick_distances_match_the_numpy_bounds(puma, amplitude, rate, slope, share, rise):
    """The kernel against its numpy composition: zone-wide bounds, then stretch bounds."""
    joints = np.arange(6.0)
    path = _wavy_path(
        np.full(6, amplitude), rate * (1 + 0.1 * joints), joints, slope * (1 - 0.2 * joints)
    )
    demand = _demand(path)
    speeds = np.linspace(0.0, 0.3, 25)[1:]
    v_from, v_to = (np.zeros_like(speeds), speeds) if rise else (speeds, np.zeros_like(speeds))
    got = demand.quick_distances(v_from, v_to, rise, LENGTH, share * puma.a_max, share * puma.j_max)
    accel, jerk = uniform_change_bounds_many(puma, demand.peaks(), speeds, share)
    distance = change_distances(v_from, v_to, accel, jerk)
    stretch = np.minimum(distance, LENGTH)
    local = demand.stretch_peaks(np.where(np.isfinite(stretch), stretch, 0.0), rise)
    local_accel, local_jerk = uniform_change_bounds_many(puma, local, speeds, share)
    refined = change_distances(
        v_from, v_to, np.maximum(accel, local_accel), np.maximum(jerk, local_jerk)
    )
    expected = np.where(np.isfinite(distance) & (distance < LENGTH), refined, distance)
    np.testing.assert_allclose(got, expected, rtol=1e-12, atol=0.0)
    assert np.isfinite(got).any()


def _changes_within_limits_numpy(
    demand, s_start, s_end, v_from, v_to, at_start, a_lim, j_lim, accel, jerk
):  # type: ignore[no-untyped-def]
    """Reference of the compiled check in numpy: every candidate's check points at once."""
    delta = abs(v_to - v_from)
    sign = 1.0 if v_to > v_from else -1.0
    full = delta * jerk >= accel * accel
    peak = np.where(full, accel, np.sqrt(delta * jerk))
    t_jerk = peak / jerk
    t_hold = np.where(full, delta / np.where(full, accel, 1.0) - t_jerk, 0.0)
    distance = 0.5 * (v_from + v_to) * (2 * t_jerk + t_hold)
    tau = np.stack([t_jerk, t_hold, t_jerk], axis=1)[:, :, None] * np.linspace(0.0, 1.0, 6)
    j = (sign * jerk[:, None] * np.array([1.0, 0.0, -1.0]))[:, :, None]
    a0 = np.stack([np.zeros_like(peak), sign * peak, sign * peak], axis=1)[:, :, None]
    v1 = v_from + sign * 0.5 * jerk * t_jerk**2
    v2 = v1 + sign * peak * t_hold
    v0 = np.stack([np.full_like(peak, v_from), v1, v2], axis=1)[:, :, None]
    s1 = v_from * t_jerk + sign * jerk * t_jerk**3 / 6.0
    s2 = s1 + v1 * t_hold + sign * peak * t_hold**2 / 2.0
    s0 = np.stack([np.zeros_like(peak), s1, s2], axis=1)[:, :, None]
    a = a0 + j * tau
    v = v0 + a0 * tau + j * tau**2 / 2.0
    s = s0 + v0 * tau + a0 * tau**2 / 2 + j * tau**3 / 6
    origin = np.where(at_start, s_start, s_end - distance)
    where = np.clip(origin[:, None, None] + s, s_start, s_end).ravel()
    d1, d2, d3 = (
        np.stack([np.interp(where, demand.s, d[:, i]) for i in range(d.shape[1])], axis=1)
        for d in (demand.d1, demand.d2, demand.d3)
    )
    j = np.broadcast_to(j, tau.shape)
    v, a, j = v.ravel()[:, None], a.ravel()[:, None], j.ravel()[:, None]
    joint_accel = np.abs(d1 * a + d2 * v * v) / a_lim
    joint_jerk = np.abs(d1 * j + 3.0 * d2 * v * a + d3 * v**3) / j_lim
    worst = np.maximum(joint_accel, joint_jerk).max(axis=1).reshape(len(accel), -1).max(axis=1)
    return worst, distance


@settings(max_examples=20, deadline=None, derandomize=True)
@given(
    amplitude=st.floats(0.0, 0.1),
    rate=st.floats(1.0, 40.0),
    slope=st.floats(-3.0, 3.0),
    v_from=st.floats(0.0, 0.2),
    v_to=st.floats(0.0, 0.2),
    at_start=st.booleans(),
)
def test_compiled_change_check_matches_numpy(puma, amplitude, rate, slope, v_from, v_to, at_start):
    """Which candidate bounds pass, kernel against numpy (where not within round-off of a limit)."""
    if v_from == v_to:
        return
    joints = np.arange(6.0)
    path = _wavy_path(
        np.full(6, amplitude), rate * (1 + 0.1 * joints), joints, slope * (1 - 0.2 * joints)
    )
    demand = _demand(path)
    accel, jerk = (
        g.ravel() for g in np.meshgrid(np.geomspace(0.05, 20, 8), np.geomspace(1, 2000, 8))
    )
    a_lim, j_lim = SHARE * puma.a_max, SHARE * puma.j_max
    ok, distance = _changes_within_limits(
        puma, demand, 0.0, LENGTH, v_from, v_to, at_start, SHARE, accel, jerk
    )
    worst, expected = _changes_within_limits_numpy(
        demand, 0.0, LENGTH, v_from, v_to, at_start, a_lim, j_lim, accel, jerk
    )
    np.testing.assert_allclose(distance, expected, rtol=1e-12)
    clear = np.abs(worst - 1.0) > 1e-9
    np.testing.assert_array_equal(ok[clear], (worst <= 1.0)[clear])


def test_cruise_cap_is_numpys_least_root_and_its_joint(puma):
    """The scalar loop of cruise_cap against the numpy expression it replaces: the same
    speed to a few ULP (numpy's cbrt is a SIMD loop of its own) and the same binding joint
    and limit, zeros (no demand) included."""
    from trackplan.timing.demand import cruise_cap, safe_ratio

    rng = np.random.default_rng(3)
    for _ in range(300):
        peaks = [np.abs(rng.normal(size=6)) * 10.0 ** rng.uniform(-3, 3, 6) for _ in range(3)]
        for p in peaks:
            p[rng.random(6) < 0.2] = 0.0
        share = float(rng.uniform(0.5, 1.0))
        expected, reason = np.inf, ""
        for values, kind in (
            (safe_ratio(share * puma.v_max, peaks[0]), "velocity"),
            (np.sqrt(safe_ratio(share * puma.a_max, peaks[1])), "acceleration"),
            (np.cbrt(safe_ratio(share * puma.j_max, peaks[2])), "jerk"),
        ):
            j = int(np.argmin(values))
            if values[j] < expected:
                expected, reason = float(values[j]), f"joint {j + 1} {kind}"
        speed, why = cruise_cap(puma, tuple(peaks), share)
        assert_ulp_close(speed, expected)
        assert why == reason
