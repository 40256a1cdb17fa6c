"""Eq. 8 and the checker's backward differences."""

from __future__ import annotations

import numpy as np
import pytest

from trackplan.derivatives import backward_derivatives
from trackplan.planning.objectives import joint_travel


def test_joint_travel_matches_definition(rng):
    q = rng.normal(size=(50, 6))
    weights = np.array([0.3, 0.2, 0.2, 0.1, 0.1, 0.1])
    expected = sum(weights[i] * abs(q[k, i] - q[k - 1, i]) for k in range(1, 50) for i in range(6))
    assert joint_travel(q, weights) == pytest.approx(expected)
    batched = joint_travel(np.stack([q, 2 * q]), weights)
    assert batched == pytest.approx([expected, 2 * expected])


def test_backward_differences_at_rest_before_and_after(rng):
    Ts = 0.01
    q = np.cumsum(rng.normal(size=(20, 2)), axis=0)
    qd, qdd, qddd = backward_derivatives(q, Ts)
    padded = np.vstack([q[:1]] * 3 + [q])
    np.testing.assert_allclose(qd, np.diff(padded, 1, axis=0)[2:] / Ts)
    np.testing.assert_allclose(qdd, np.diff(padded, 2, axis=0)[1:] / Ts**2)
    np.testing.assert_allclose(qddd, np.diff(padded, 3, axis=0) / Ts**3)
    assert np.all(qd[0] == 0)
    qd_end, _, qddd_end = backward_derivatives(q, Ts, pad_end=True)
    assert len(qd_end) == len(q) + 3
    np.testing.assert_allclose(qd_end[-3:], 0.0)
    assert np.abs(qddd_end[-3:]).max() > 0  # stopping abruptly shows up after the end


@pytest.mark.parametrize("shape", [(1, 6), (2, 3), (40, 6), (40,)])
@pytest.mark.parametrize("pad_end", [False, True])
def test_backward_differences_in_one_pass_are_numpys_to_the_bit(rng, shape, pad_end):
    """The compiled pass does numpy's subtractions and divisions: the same bits."""
    Ts = 1e-3
    q = np.cumsum(rng.normal(scale=1e-3, size=shape), axis=0)
    parts = [q[:1]] * 3 + [q] + ([q[-1:]] * 3 if pad_end else [])
    padded = np.concatenate(parts, axis=0)
    first = np.diff(padded, axis=0)
    second = np.diff(first, axis=0)
    third = np.diff(second, axis=0)
    expected = (first[2:] / Ts, second[1:] / Ts**2, third / Ts**3)
    for found, wanted in zip(backward_derivatives(q, Ts, pad_end), expected, strict=True):
        assert found.shape == wanted.shape
        np.testing.assert_array_equal(found, wanted)


def test_backward_differences_of_no_samples_are_empty():
    assert all(d.shape == (0, 6) for d in backward_derivatives(np.zeros((0, 6)), 1e-3, True))
