"""Jerk-limited speed changes and phase integration."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from tests.tolerances import assert_ulp_close
from trackplan.derivatives import backward_derivatives
from trackplan.timing.profile import (
    SpeedProfile,
    speed_change_distance,
    speed_change_phases,
    speed_change_time,
)

speeds = st.floats(0.0, 0.5)
bounds = st.floats(0.05, 20.0)


@settings(max_examples=200, deadline=None, derandomize=True)
@given(v_from=speeds, v_to=speeds, accel=bounds, jerk=bounds)
def test_speed_change_reaches_target_within_bounds(v_from, v_to, accel, jerk):
    phases = speed_change_phases(v_from, v_to, accel, jerk)
    profile = SpeedProfile.from_phases([(0.0, 0.0), *phases], length=np.inf)
    t = np.linspace(0.0, profile.duration, 400)
    v_start = v_from  # SpeedProfile starts at rest: shift by v_from
    _, v, a = profile.evaluate(t)
    assert v[-1] + v_start == pytest.approx(v_to, abs=1e-12)
    assert np.all(np.abs(a) <= accel * (1 + 1e-9))
    assert np.all(np.abs(np.array([j for _, j in phases])) <= jerk * (1 + 1e-12))
    assert profile.duration == pytest.approx(speed_change_time(abs(v_to - v_from), accel, jerk))
    assert a[-1] == pytest.approx(0.0, abs=1e-9 * max(accel, 1.0))


def test_distance_is_mean_speed_times_duration():
    v_from, v_to, accel, jerk = 0.05, 0.15, 1.0, 10.0
    phases = speed_change_phases(0.0, v_to - v_from, accel, jerk)
    profile = SpeedProfile.from_phases(phases, length=np.inf)
    t = np.linspace(0, profile.duration, 20001)
    _, v, _ = profile.evaluate(t)
    moved = np.trapezoid(v + v_from, t)
    assert moved == pytest.approx(speed_change_distance(v_from, v_to, accel, jerk), rel=1e-6)


def test_sampled_jerk_bounded_by_continuous_jerk():
    """Backward differences of a profile with bounded jerk stay within that bound."""
    accel, jerk = 0.8, 5.0
    phases = [*speed_change_phases(0.0, 0.15, accel, jerk), (1.0, 0.0)]
    phases += speed_change_phases(0.15, 0.0, accel, jerk)
    profile = SpeedProfile.from_phases(phases, length=10.0)
    Ts = 1e-3
    t = np.arange(int(profile.duration / Ts) + 1) * Ts
    s, _, _ = profile.evaluate(t)
    _, sdd, sddd = backward_derivatives(s[:, None], Ts)
    assert np.abs(sdd).max() <= accel * (1 + 1e-6)
    assert np.abs(sddd).max() <= jerk * (1 + 1e-6)


def test_acceleration_step_breaks_sampled_jerk():
    """The paper's constant-acceleration start: a step in acceleration is a jerk spike."""
    Ts = 1e-3
    t = np.arange(200) * Ts
    s = 0.5 * 1.0 * t**2
    _, _, sddd = backward_derivatives(s[:, None], Ts)
    # the unit acceleration step is spread over two samples: 0.5/Ts each
    assert np.abs(sddd).max() == pytest.approx(0.5 / Ts, rel=1e-6)


def test_compiled_positions_are_those_of_evaluate():
    """SpeedProfile.position (compiled) gives evaluate's s to a few ULP, clipped, even
    outside [0, duration]."""
    phases = [(0.02, 40.0), (0.05, 0.0), (0.02, -40.0), (0.3, 0.0), (0.03, -30.0), (0.03, 30.0)]
    profile = SpeedProfile.from_phases(phases, 0.05)
    t = np.linspace(-0.01, profile.duration + 0.01, 997)
    assert_ulp_close(profile.position(t), profile.evaluate(t)[0])
    # times out of order, repeated, on the phase starts and NaN: each phase by binary search
    rng = np.random.default_rng(3)
    t = np.concatenate([rng.permutation(t), profile.t_start, profile.t_start[::-1], t[:40]])
    t[[5, 500, 1040]] = np.nan
    assert_ulp_close(profile.position(t), profile.evaluate(t)[0])
