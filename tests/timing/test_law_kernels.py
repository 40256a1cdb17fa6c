"""The time law's compiled kernels against the numpy expressions they replace, to the bit
(the sample checks' rate ratios, the zones' local caps), and the final
stop's jerk bisection against its fixed 80 rounds."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from tests.tolerances import assert_ulp_close
from trackplan.derivatives import backward_derivatives
from trackplan.timing._kernels_samples import rate_ratios
from trackplan.timing.demand import ZoneDemand
from trackplan.timing.profile import speed_change_time
from trackplan.timing.zones import _jerk_for_duration


@settings(max_examples=60, deadline=None)
@given(
    seed=st.integers(0, 2**32 - 1),
    n_samples=st.integers(1, 60),
    n_dof=st.integers(1, 7),
    nan=st.booleans(),
)
def test_rate_ratios_are_the_largest_backward_difference_ratios(seed, n_samples, n_dof, nan):
    rng = np.random.default_rng(seed)
    q = np.cumsum(rng.normal(scale=1e-3, size=(n_samples, n_dof)), axis=0)
    if nan:
        q[rng.integers(n_samples), rng.integers(n_dof)] = np.nan
    Ts = 1e-3
    limits = rng.uniform(0.5, 5.0, size=(3, n_dof)) * [[1.0], [10.0], [100.0]]
    ratio = rate_ratios(q, np.array([Ts, Ts**2, Ts**3]), limits)
    derivatives = backward_derivatives(q, Ts, pad_end=True)
    for order, values in enumerate(derivatives):
        use = np.abs(values) / limits[order]
        # the running maximum from 0 over the joints in order, as Python's max(a, b):
        # b only where b > a (a NaN b is passed over)
        expected = np.zeros(len(use))
        for j in range(n_dof):
            expected = np.where(use[:, j] > expected, use[:, j], expected)
        np.testing.assert_array_equal(ratio[:, order], expected)


@settings(max_examples=60, deadline=None)
@given(
    seed=st.integers(0, 2**32 - 1),
    n_rows=st.integers(1, 40),
    n_dof=st.integers(1, 7),
    zeros=st.booleans(),
    odd=st.sampled_from([None, np.nan, np.inf]),
)
def test_local_caps_are_the_numpy_expression(seed, n_rows, n_dof, zeros, odd):
    rng = np.random.default_rng(seed)
    d1, d2, d3 = rng.normal(size=(3, n_rows, n_dof)) * [[[1.0]], [[10.0]], [[100.0]]]
    if zeros:  # joints that do not move: no cap from them
        d1[:, 0] = d2[:, 0] = d3[:, 0] = 0.0
    if odd is not None:
        d3[rng.integers(n_rows), rng.integers(n_dof)] = odd
    demand = ZoneDemand(np.arange(n_rows, dtype=float), d1, d2, d3)
    robot = SimpleNamespace(
        v_max=rng.uniform(1, 3, n_dof),
        a_max=rng.uniform(5, 15, n_dof),
        j_max=rng.uniform(50, 90, n_dof),
    )
    share = 0.97
    q1, q2, q3 = demand.absolute
    with np.errstate(divide="ignore", invalid="ignore"):
        ratio = [
            np.where(q > 0, share * limit / q, np.inf)
            for q, limit in ((q1, robot.v_max), (q2, robot.a_max), (q3, robot.j_max))
        ]
    expected = np.minimum(
        np.minimum(ratio[0].min(axis=1), np.sqrt(ratio[1]).min(axis=1)),
        np.cbrt(ratio[2]).min(axis=1),
    )
    # the kernel's cbrt and numpy's SIMD cbrt round differently: a few ULP apart
    assert_ulp_close(demand.local_caps(robot, share), expected)


def _jerk_for_duration_80(delta: float, accel: float, jerk: float, duration: float) -> float:
    """The bisection as it ran before: always 80 rounds."""
    low, high = 0.0, jerk
    for _ in range(80):
        mid = 0.5 * (low + high)
        if mid > 0.0 and speed_change_time(delta, accel, mid) > duration:
            low = mid
        else:
            high = mid
    return high


@settings(max_examples=200, deadline=None)
@given(
    delta=st.floats(1e-4, 2.0),
    accel=st.floats(0.1, 50.0),
    jerk=st.floats(1.0, 5000.0),
    longer=st.floats(0.0, 3.0),
)
def test_jerk_bisection_stopping_at_rest_is_the_full_bisection(delta, accel, jerk, longer):
    duration = speed_change_time(delta, accel, jerk) * (1.0 + longer)
    assert _jerk_for_duration(delta, accel, jerk, duration) == _jerk_for_duration_80(
        delta, accel, jerk, duration
    )
