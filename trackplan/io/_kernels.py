"""Compiled kernels of the io package: shortest round-trip text of float64 values.

The Python API is :mod:`trackplan.io.csv_table`. The digits are those of Ryū (Ulf Adams,
"Ryū: fast float-to-string conversion", PLDI 2018): the shortest decimal that reads back to
the same double, and of those the nearest. The text is laid out as Python's ``repr`` lays
it out (``0.001``, ``1e-05``, ``1e+16``, ``-0.0``, ``nan``, ``inf``).

It stays compiled because the standard library, which writes the same text, would take
about 7 times as long and add about 78 % to the run of a 10-minute cycle
(:mod:`trackplan.io.csv_table`, ``python -m benchmarks csv``).

The 128-bit products Ryū needs are built from 32-bit halves; every integer is ``uint64``
(numba turns ``uint64`` mixed with ``int64`` into float64, hence the typed constants).
"""

from __future__ import annotations

import numpy as np
from numba import njit

POW5_BITS = 125
"""Bits kept of each power of 5 (and of each inverse) in the tables."""

MAX_TEXT = 24
"""Longest text of one value (``-2.2250738585072014e-308``), bytes."""

_ZERO = np.uint64(0)
_ONE = np.uint64(1)
_TWO = np.uint64(2)
_FOUR = np.uint64(4)
_FIVE = np.uint64(5)
_TEN = np.uint64(10)
_MASK32 = np.uint64(0xFFFFFFFF)
_MASK52 = np.uint64((1 << 52) - 1)
_HIDDEN = np.uint64(1 << 52)
_MASK11 = np.uint64(0x7FF)
_SHIFT32 = np.uint64(32)
_SHIFT52 = np.uint64(52)
_SHIFT63 = np.uint64(63)
_SHIFT64 = np.uint64(64)

_ASCII_0 = 48
_ASCII_MINUS = 45
_ASCII_PLUS = 43
_ASCII_DOT = 46
_ASCII_E = 101
_ASCII_COMMA = 44
_ASCII_NEWLINE = 10


@njit(cache=True)
def _high_product(a: np.uint64, b: np.uint64) -> tuple[np.uint64, np.uint64]:  # pragma: no cover
    """Kernel: the 128-bit product ``a b`` as (low, high) 64-bit words."""
    a_lo, a_hi = a & _MASK32, a >> _SHIFT32
    b_lo, b_hi = b & _MASK32, b >> _SHIFT32
    b00 = a_lo * b_lo
    b01 = a_lo * b_hi
    b10 = a_hi * b_lo
    b11 = a_hi * b_hi
    mid1 = b10 + (b00 >> _SHIFT32)
    mid2 = b01 + (mid1 & _MASK32)
    high = b11 + (mid1 >> _SHIFT32) + (mid2 >> _SHIFT32)
    low = (mid2 << _SHIFT32) | (b00 & _MASK32)
    return low, high


@njit(cache=True)
def _mul_shift(
    m: np.uint64, mul_lo: np.uint64, mul_hi: np.uint64, j: int
) -> np.uint64:  # pragma: no cover
    """Kernel: ``(m · mul) >> j`` for m < 2⁵⁵, a 128-bit ``mul`` and 64 ≤ j < 192."""
    low1, high1 = _high_product(m, mul_hi)
    _, high0 = _high_product(m, mul_lo)
    total = high0 + low1
    if total < high0:
        high1 += _ONE
    shift = j - 64
    if shift == 0:
        return total
    if shift >= 64:
        return high1 >> np.uint64(shift - 64)
    return (high1 << np.uint64(64 - shift)) | (total >> np.uint64(shift))


@njit(cache=True)
def _pow5_factor(value: np.uint64) -> int:  # pragma: no cover
    """Kernel: the exponent of 5 in ``value`` > 0."""
    count = 0
    while value % _FIVE == _ZERO:
        value //= _FIVE
        count += 1
    return count


@njit(cache=True)
def _pow5_bits(e: int) -> int:  # pragma: no cover
    """Kernel: ⌈log2(5^e)⌉ for 0 < e ≤ 3528 (1 for e = 0)."""
    return ((e * 1217359) >> 19) + 1


@njit(cache=True)
def shortest_digits(
    mantissa: np.uint64, exponent: int, inv_split: np.ndarray, split: np.ndarray
) -> tuple[np.uint64, int]:  # pragma: no cover
    """Kernel: Ryū's shortest decimal of a positive finite double, ``digits · 10^power``.

    Parameters
    ----------
    mantissa, exponent
        The IEEE 754 fraction (52 bits) and biased exponent (1..2046, or 0 for subnormals).
    inv_split, split
        Ryū's tables (342, 2) and (326, 2) ``uint64`` (low, high words): the inverse powers of
        5 and the powers of 5 to :data:`POW5_BITS` bits.

    Returns
    -------
    tuple
        ``digits`` (at most 17 decimal digits) and ``power``.
    """
    if exponent == 0:
        e2 = 1 - 1023 - 52 - 2
        m2 = mantissa
    else:
        e2 = exponent - 1023 - 52 - 2
        m2 = mantissa | _HIDDEN
    accept_bounds = (m2 & _ONE) == _ZERO
    mv = _FOUR * m2
    mm_shift = _ONE if (mantissa != _ZERO or exponent <= 1) else _ZERO
    vm_trailing = False
    vr_trailing = False
    if e2 >= 0:
        q = ((e2 * 78913) >> 18) - (1 if e2 > 3 else 0)
        e10 = q
        k = POW5_BITS + _pow5_bits(q) - 1
        i = -e2 + q + k
        lo, hi = inv_split[q, 0], inv_split[q, 1]
        vr = _mul_shift(mv, lo, hi, i)
        vp = _mul_shift(mv + _TWO, lo, hi, i)
        vm = _mul_shift(mv - _ONE - mm_shift, lo, hi, i)
        if q <= 21:
            if mv % _FIVE == _ZERO:
                vr_trailing = _pow5_factor(mv) >= q
            elif accept_bounds:
                vm_trailing = _pow5_factor(mv - _ONE - mm_shift) >= q
            elif _pow5_factor(mv + _TWO) >= q:
                vp -= _ONE
    else:
        q = ((-e2 * 732923) >> 20) - (1 if -e2 > 1 else 0)
        e10 = q + e2
        i = -e2 - q
        k = _pow5_bits(i) - POW5_BITS
        j = q - k
        lo, hi = split[i, 0], split[i, 1]
        vr = _mul_shift(mv, lo, hi, j)
        vp = _mul_shift(mv + _TWO, lo, hi, j)
        vm = _mul_shift(mv - _ONE - mm_shift, lo, hi, j)
        if q <= 1:
            vr_trailing = True
            if accept_bounds:
                vm_trailing = mm_shift == _ONE
            else:
                vp -= _ONE
        elif q < 63:
            vr_trailing = (mv & ((_ONE << np.uint64(q)) - _ONE)) == _ZERO
    removed = 0
    last_removed = _ZERO
    if vm_trailing or vr_trailing:
        while vp // _TEN > vm // _TEN:
            vm_trailing = vm_trailing and vm % _TEN == _ZERO
            vr_trailing = vr_trailing and last_removed == _ZERO
            last_removed = vr % _TEN
            vr //= _TEN
            vp //= _TEN
            vm //= _TEN
            removed += 1
        if vm_trailing:
            while vm % _TEN == _ZERO:
                vr_trailing = vr_trailing and last_removed == _ZERO
                last_removed = vr % _TEN
                vr //= _TEN
                vp //= _TEN
                vm //= _TEN
                removed += 1
        if vr_trailing and last_removed == _FIVE and vr % _TWO == _ZERO:
            last_removed = _FOUR  # an exact tie: round to even
        up = bool((vr == vm and (not accept_bounds or not vm_trailing)) or last_removed >= _FIVE)
    else:
        round_up = False
        while vp // _TEN > vm // _TEN:
            round_up = bool(vr % _TEN >= _FIVE)
            vr //= _TEN
            vp //= _TEN
            vm //= _TEN
            removed += 1
        up = bool(vr == vm or round_up)
    return vr + (_ONE if up else _ZERO), e10 + removed


@njit(cache=True)
def _write_text(
    bits: np.uint64, out: np.ndarray, at: int, inv_split: np.ndarray, split: np.ndarray
) -> int:  # pragma: no cover
    """Kernel: write the text of the double with IEEE ``bits`` into ``out`` at ``at``; new end."""
    mantissa = bits & _MASK52
    exponent = int((bits >> _SHIFT52) & _MASK11)
    negative = (bits >> _SHIFT63) != _ZERO
    if exponent == 0x7FF:
        if mantissa != _ZERO:
            out[at], out[at + 1], out[at + 2] = 110, 97, 110  # nan
            return at + 3
        if negative:
            out[at] = _ASCII_MINUS
            at += 1
        out[at], out[at + 1], out[at + 2] = 105, 110, 102  # inf
        return at + 3
    if negative:
        out[at] = _ASCII_MINUS
        at += 1
    if exponent == 0 and mantissa == _ZERO:
        out[at], out[at + 1], out[at + 2] = _ASCII_0, _ASCII_DOT, _ASCII_0
        return at + 3
    digits, power = shortest_digits(mantissa, exponent, inv_split, split)
    n_digits = 1
    bound = _TEN
    while n_digits < 17 and digits >= bound:
        n_digits += 1
        bound *= _TEN
    point = n_digits + power  # the decimal point sits after this many digits
    if point <= -4 or point > 16:
        # d.ddde±XX: the digits go in from the last, leaving a slot for the point.
        end = at + n_digits + (1 if n_digits > 1 else 0)
        for position in range(end - 1, at, -1):
            if position == at + 1:
                out[position] = _ASCII_DOT
            else:
                out[position] = _ASCII_0 + int(digits % _TEN)
                digits //= _TEN
        out[at] = _ASCII_0 + int(digits)
        at = end
        out[at] = _ASCII_E
        scale = point - 1
        out[at + 1] = _ASCII_MINUS if scale < 0 else _ASCII_PLUS
        scale = abs(scale)
        at += 2
        if scale >= 100:
            out[at] = _ASCII_0 + scale // 100
            at += 1
        out[at] = _ASCII_0 + (scale // 10) % 10
        out[at + 1] = _ASCII_0 + scale % 10
        return at + 2
    if point <= 0:
        out[at], out[at + 1] = _ASCII_0, _ASCII_DOT
        at += 2
        for _ in range(-point):
            out[at] = _ASCII_0
            at += 1
        for position in range(at + n_digits - 1, at - 1, -1):
            out[position] = _ASCII_0 + int(digits % _TEN)
            digits //= _TEN
        return at + n_digits
    if point >= n_digits:
        for position in range(at + n_digits - 1, at - 1, -1):
            out[position] = _ASCII_0 + int(digits % _TEN)
            digits //= _TEN
        at += n_digits
        for _ in range(point - n_digits):
            out[at] = _ASCII_0
            at += 1
        out[at], out[at + 1] = _ASCII_DOT, _ASCII_0
        return at + 2
    end = at + n_digits + 1
    for position in range(end - 1, at - 1, -1):
        if position == at + point:
            out[position] = _ASCII_DOT
        else:
            out[position] = _ASCII_0 + int(digits % _TEN)
            digits //= _TEN
    return end


_NO_BYTES = 0


@njit(cache=True)
def format_rows(
    bits: np.ndarray, out: np.ndarray, inv_split: np.ndarray, split: np.ndarray
) -> int:  # pragma: no cover
    """Kernel: CSV lines of a table of doubles, given as their IEEE bits.

    Parameters
    ----------
    bits
        The table viewed as ``uint64``, shape (n_rows, n_columns).
    out
        Byte buffer (``uint8``) of at least ``n_rows · n_columns · (MAX_TEXT + 1)`` bytes.
    inv_split, split
        Ryū's tables, see :func:`shortest_digits`.

    Returns
    -------
    int
        Bytes written: each row's values separated by commas, each row ended by a newline.
    """
    n_rows, n_columns = bits.shape
    at = int(_NO_BYTES)  # not the constant 0: _write_text would compile a version for it
    for row in range(n_rows):
        for column in range(n_columns):
            at = _write_text(bits[row, column], out, at, inv_split, split)
            out[at] = _ASCII_COMMA if column + 1 < n_columns else _ASCII_NEWLINE
            at += 1
    return at
