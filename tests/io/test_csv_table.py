"""The exact CSV writer: Python's repr text for every double, read back bit for bit."""

from __future__ import annotations

import io
import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from trackplan.io.csv_table import format_table, ryu_tables, write_csv_table

SPECIAL = [
    0.0,
    -0.0,
    5e-324,  # the smallest subnormal
    -2.225073858507201e-308,  # the largest subnormal
    2.2250738585072014e-308,  # the smallest normal
    1e-300,
    1.7976931348623157e308,
    1e-05,
    0.0001,
    1e15,
    1e16,
    123456789012345680.0,
    0.1,
    1 / 3,
    2.0**-1074 * 3,
    9007199254740993.0,
    math.inf,
    -math.inf,
    math.nan,
]


def _repr_lines(table: np.ndarray) -> str:
    return "".join(",".join(map(repr, row)) + "\n" for row in table.tolist())


def _bits(table: np.ndarray) -> np.ndarray:
    return np.ascontiguousarray(table, dtype=np.float64).view(np.uint64)


def test_special_values_are_written_as_repr_and_read_back_bit_for_bit(tmp_path):
    table = np.array([SPECIAL, [-x for x in SPECIAL]])
    text = format_table(table).decode("ascii")
    assert text == _repr_lines(table)
    file = tmp_path / "table.csv"
    write_csv_table(file, table, [f"c{i}" for i in range(table.shape[1])])
    back = np.loadtxt(file, delimiter=",", skiprows=1, ndmin=2)
    finite = np.isfinite(table)
    assert np.array_equal(_bits(back)[finite], _bits(table)[finite])  # negative zero too
    assert np.array_equal(np.isnan(back), np.isnan(table))
    assert np.array_equal(back[np.isinf(table)], table[np.isinf(table)])


def test_random_bit_patterns_match_repr_and_round_trip():
    # Every exponent, subnormals included, with random mantissas.
    rng = np.random.default_rng(3)
    table = rng.integers(0, 2**64, size=(20_000, 6), dtype=np.uint64).view(np.float64)
    text = format_table(table).decode("ascii")
    assert text == _repr_lines(table)
    back = np.loadtxt(io.StringIO(text), delimiter=",", ndmin=2)
    finite = np.isfinite(table)
    assert np.array_equal(_bits(back)[finite], _bits(table)[finite])


def test_trajectory_like_values_match_repr():
    # Short decimals (times k·Ts), integers, powers of ten and their neighbours: where the
    # shortest text is much shorter than 17 digits and ties are decided.
    k = np.arange(100_000, dtype=float)
    powers = 10.0 ** np.arange(-30, 31)
    columns = [
        k * 0.001,
        k,
        np.resize(powers, k.size),
        np.resize(np.nextafter(powers, 0.0), k.size),
        np.resize(np.nextafter(powers, np.inf), k.size),
        np.sin(k) * 1e-8,
        2.0 ** np.resize(np.arange(-1074, 1024), k.size),
    ]
    table = np.column_stack(columns)
    assert format_table(table).decode("ascii") == _repr_lines(table)


@settings(max_examples=200, deadline=None)
@given(st.lists(st.floats(allow_nan=False), min_size=1, max_size=40))
def test_any_double_reads_back_exactly(values):
    table = np.array(values, dtype=float)[None, :]
    text = format_table(table).decode("ascii")
    assert text == _repr_lines(table)
    back = np.array([float(word) for word in text.strip().split(",")])
    assert np.array_equal(_bits(back), _bits(table[0]))


def test_tables_are_ryus():
    inv_split, split = ryu_tables()
    assert inv_split.shape == (342, 2) and split.shape == (326, 2)
    # First entries of Ryū's published d2s tables: 2^125 + 1 and 2^124.
    assert (int(inv_split[0, 1]) << 64) + int(inv_split[0, 0]) == 2**125 + 1
    assert (int(split[0, 1]) << 64) + int(split[0, 0]) == 2**124
    assert (int(split[1, 1]) << 64) + int(split[1, 0]) == 5 * 2**122


def test_empty_table_writes_the_header_only(tmp_path):
    file = tmp_path / "empty.csv"
    write_csv_table(file, np.zeros((0, 3)), ["a", "b", "c"])
    assert file.read_text() == "a,b,c\n"


def test_a_table_must_be_two_dimensional():
    with pytest.raises(ValueError, match="2 dimensions"):
        format_table(np.zeros(3))
