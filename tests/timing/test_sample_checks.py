"""The joint rate check a time law runs on its samples, against the checker's differences."""

from __future__ import annotations

import numpy as np

from trackplan.derivatives import backward_derivatives
from trackplan.motion import JointSamples
from trackplan.timing.sample_checks import (
    LIMIT_MARGIN,
    RateLimits,
    TorqueLimits,
    run_checks,
    run_motion_checks,
)


def test_rate_limits_flag_exactly_the_samples_over_a_limit(puma):
    sample_time = 1e-3
    t = np.arange(3000) * sample_time
    q = 0.3 * np.sin(np.outer(t**2, np.linspace(2.0, 6.0, 6)))  # chirps: every limit broken late
    sample, order, ratio = RateLimits(puma)(q, sample_time)
    derivatives = backward_derivatives(q, sample_time, pad_end=True)
    bounds = (puma.v_max, puma.a_max, puma.j_max)
    expected_sample, expected_ratio = [], []
    for values, bound in zip(derivatives, bounds, strict=True):
        use = (np.abs(values) / ((1.0 - LIMIT_MARGIN) * bound)).max(axis=1)
        bad = np.flatnonzero(use > 1.0)
        expected_sample.append(np.minimum(bad, len(q) - 1))
        expected_ratio.append(use[bad])
    for k in (1, 2, 3):  # every order has samples that pass and samples that do not
        assert 0 < np.count_nonzero(order == k) < len(q)
    np.testing.assert_array_equal(sample, np.concatenate(expected_sample))
    np.testing.assert_array_equal(ratio, np.concatenate(expected_ratio))
    counts = [len(s) for s in expected_sample]
    np.testing.assert_array_equal(order, np.repeat([1, 2, 3], counts))


def test_checks_read_a_motion_as_they_read_its_samples(puma):
    sample_time = 1e-3
    t = np.arange(2000) * sample_time
    q = 0.4 * np.sin(np.outer(t**2, np.linspace(3.0, 9.0, 6)))  # fast enough to break torques
    calls = []

    def plain(q_samples, Ts):  # a check that knows nothing of motions
        calls.append(len(q_samples))
        return np.array([0]), np.array([1]), np.array([2.0])

    checks = (RateLimits(puma), TorqueLimits(puma), plain)
    motion = JointSamples(puma, q, sample_time)
    by_motion = run_motion_checks(checks, motion)
    by_samples = run_checks(checks, q, sample_time)
    assert motion.torque is not None  # the torque check's RNE pass is kept for the checker
    assert TorqueLimits(puma).check_motion(motion)[0].size > 0  # torques broken somewhere
    assert calls == [len(q), len(q)]
    for a, b in zip(by_motion, by_samples, strict=True):
        np.testing.assert_array_equal(a, b)
