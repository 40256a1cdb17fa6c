"""How tests compare floating-point results (docs/architecture.md, "Tests and tolerances").

Two computations of the same quantity by different code (a compiled kernel and the numpy
expression it replaces, a batched pass and a loop of single calls, two kernels that share
equations) agree only to rounding: numpy's SIMD loops for ``cbrt``, ``exp`` or ``arctan2``
are accurate to a few units in the last place (ULP) and change between releases, LLVM's
instruction selection changes with numba and llvmlite, and BLAS and numpy's pairwise sums
change their order with the array size. Such results are compared to :data:`ULPS` units in
the last place. Exact comparisons are kept for contracts of exactness only: a file's round
trip, a seed's reproducibility within one install, integer and boolean results.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

ULPS = 8
"""Units in the last place allowed between two computations of one quantity: a few ULP of
each transcendental function on the way (numpy documents up to 4 ULP for its SIMD ``cbrt``,
``exp``, ``log``, ``sin`` and ``cos``), a handful of operations deep."""


def assert_ulp_close(actual: ArrayLike, expected: ArrayLike, ulps: int = ULPS) -> None:
    """Assert equal shapes, NaN and infinities at the same places, and every finite pair
    within ``ulps`` units in the last place of the larger magnitude.

    Parameters
    ----------
    actual, expected : array_like of float
        The two results, of one shape.
    ulps : int
        Largest allowed difference, in units in the last place.
    """
    a = np.asarray(actual, dtype=float)
    e = np.asarray(expected, dtype=float)
    assert a.shape == e.shape, f"shapes differ: {a.shape} != {e.shape}"
    np.testing.assert_array_equal(np.isnan(a), np.isnan(e), err_msg="NaN at other places")
    finite = np.isfinite(e)
    np.testing.assert_array_equal(a[~finite & ~np.isnan(e)], e[~finite & ~np.isnan(e)])
    np.testing.assert_array_equal(np.isfinite(a), finite, err_msg="infinities at other places")
    spacing = np.spacing(np.maximum(np.abs(a[finite]), np.abs(e[finite])))
    diff = np.abs(a[finite] - e[finite])
    worst = np.max(diff / spacing, initial=0.0)
    assert worst <= ulps, f"differ by {worst:.1f} ULP (at most {ulps} allowed)"
