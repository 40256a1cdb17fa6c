"""The controller languages' number literals (trackplan.writers.numbers.fixed)."""

from __future__ import annotations

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from trackplan.writers.numbers import fixed


@pytest.mark.parametrize(
    ("value", "decimals", "keep", "text"),
    [
        (1.5, 3, None, "1.500"),
        (1.5, 3, 1, "1.5"),
        (2.0, 3, 1, "2.0"),
        (2.0, 3, 0, "2"),
        (-0.0001, 3, None, "0.000"),
        (-0.0001, 3, 1, "0.0"),
        (-0.0001, 3, 0, "0"),
        (-12.34567, 4, 0, "-12.3457"),
        (1e-20, 6, 1, "0.0"),
        (1e20, 2, 0, "100000000000000000000"),
        (7.0, 0, None, "7"),
    ],
)
def test_fixed_keeps_the_decimals_asked_for(
    value: float, decimals: int, keep: int | None, text: str
) -> None:
    assert fixed(value, decimals, keep=keep) == text


@settings(max_examples=300, deadline=None)
@given(
    st.floats(-1e9, 1e9, allow_nan=False),
    st.integers(0, 9),
    st.sampled_from([None, 0, 1]),
)
def test_fixed_reads_back_to_the_rounded_value(
    value: float, decimals: int, keep: int | None
) -> None:
    text = fixed(value, decimals, keep=keep)
    assert "e" not in text.lower()
    assert float(text) == float(f"{value:.{decimals}f}")
    assert text != "-0" and not (float(text) == 0.0 and text.startswith("-"))
