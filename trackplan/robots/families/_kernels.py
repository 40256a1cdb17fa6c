"""Compiled pieces the closed-form IK families share (OPW and UR).

The fused solvers are in :mod:`trackplan.robots.families._opw_kernels` and
:mod:`trackplan.robots.families._ur_kernels`; this module holds what both use: the branch
layout (:data:`N_BRANCHES`, :data:`AUX_SIZE`), :func:`atan2` (a compiled, branch-free
arctangent that LLVM vectorises; libm's scalar ``atan2`` and numpy's ``arctan2`` cost
about 25 ns each and dominated the former three-pass design), the wrist frame
``T · tail_inv`` of a pose (:func:`wrist_frame`, :func:`wrist_entry`), and
:func:`hold_and_wind`, which holds a branch's missed poses and winds its joints near a
reference in the one-branch kernels' call.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

N_BRANCHES = 8
AUX_SIZE = 5
REACH_TOL = 1e-12  # how far past a stretched arm or into the shoulder cylinder still counts
WRIST_SINGULAR = 1e-12  # |sin θ5| below which θ4 is set, not solved

# Arctangent: octant reduction to |s| ≤ tan(π/8), then atan(s) = s + s·z·P(z), z = s²,
# P a degree-11 Chebyshev fit of (atan √z − √z) / z^{3/2} on [0, 0.175] (error 1.5e-18;
# fitted with mpmath at 50 digits). Angles k·π/4 are split into hi + lo parts. Within
# 2 ulp of the correctly rounded arctangent (mean 0.07 ulp), the same signed zeros and
# quadrants as C's atan2, NaN in → NaN out.
TAN_PI_8 = 0.41421356237309503
TAN_3PI_8 = 2.414213562373095
PI_4_HI, PI_4_LO = 0.7853981633974483, 3.061616997868383e-17
PI_2_HI, PI_2_LO = 1.5707963267948966, 6.123233995736766e-17
PI3_4_HI, PI3_4_LO = 2.356194490192345, 9.184850993605148e-17
PI_HI, PI_LO = 3.141592653589793, 1.2246467991473532e-16
P0, P1, P2, P3 = (
    -0.3333333333333333,
    0.1999999999999976,
    -0.14285714285648926,
    0.1111111110410365,
)
P4, P5, P6, P7 = (
    -0.09090908701696371,
    0.0769229489243801,
    -0.06666398527043488,
    0.05878628988060137,
)
P8, P9, P10, P11 = (
    -0.05228266918352639,
    0.04541715636079406,
    -0.034319069932567094,
    0.016009822553531047,
)


@njit(cache=True, error_model="numpy", inline="always")
def atan2(y: float, x: float) -> float:  # pragma: no cover - compiled
    """The angle of the vector (x, y), rad in [−π, π], as C's ``atan2`` to 2 ulp."""
    ax = abs(x)
    ay = abs(y)
    neg = math.copysign(1.0, x) < 0.0
    if ay > TAN_3PI_8 * ax:
        num = -ax
        den = ay
        hi = PI_2_HI
        lo = PI_2_LO
    elif ay > TAN_PI_8 * ax:
        num = ay - ax
        den = ay + ax
        hi = PI3_4_HI if neg else PI_4_HI
        lo = PI3_4_LO if neg else PI_4_LO
    else:
        num = ay
        den = ax
        hi = PI_HI if neg else 0.0
        lo = PI_LO if neg else 0.0
    s = num / den if den != 0.0 else num  # den = 0 only for x = y = 0 (or NaN y)
    if neg:
        s = -s
    z = s * s
    z2 = z * z
    z4 = z2 * z2
    p = (
        ((P0 + P1 * z) + (P2 + P3 * z) * z2)
        + ((P4 + P5 * z) + (P6 + P7 * z) * z2) * z4
        + ((P8 + P9 * z) + (P10 + P11 * z) * z2) * (z4 * z4)
    )
    return math.copysign(hi + (s + (s * z * p + lo)), y)


@njit(cache=True, error_model="numpy", inline="always")
def atan2_all(Y: np.ndarray, X: np.ndarray, angles: np.ndarray) -> None:  # pragma: no cover
    """Kernel: ``angles ← atan2(Y, X)`` elementwise over a small buffer."""
    for j in range(Y.shape[0]):
        angles[j] = atan2(Y[j], X[j])


@njit(cache=True, error_model="numpy", inline="always")
def unit(c: float, s: float) -> tuple[float, float]:  # pragma: no cover - compiled
    """(cos, sin) of the angle of the vector (c, s); (1, 0) for the zero vector."""
    norm = math.sqrt(c * c + s * s)
    if norm > 0.0:
        return c / norm, s / norm
    return 1.0, 0.0


@njit(cache=True, error_model="numpy", inline="always")
def wrap(x: float) -> float:  # pragma: no cover - compiled
    """Angle in (−π, π]."""
    if -math.pi < x <= math.pi:
        return x
    return x + 2.0 * math.pi * math.floor((math.pi - x) / (2.0 * math.pi))


@njit(cache=True, error_model="numpy", inline="always")
def wrist_frame(
    T: np.ndarray, tail_inv: np.ndarray
) -> tuple[float, ...]:  # pragma: no cover - compiled
    """The first three rows of ``T · tail_inv``, row by row (12 scalars)."""
    return (
        T[0, 0] * tail_inv[0, 0]
        + T[0, 1] * tail_inv[1, 0]
        + T[0, 2] * tail_inv[2, 0]
        + T[0, 3] * tail_inv[3, 0],
        T[0, 0] * tail_inv[0, 1]
        + T[0, 1] * tail_inv[1, 1]
        + T[0, 2] * tail_inv[2, 1]
        + T[0, 3] * tail_inv[3, 1],
        T[0, 0] * tail_inv[0, 2]
        + T[0, 1] * tail_inv[1, 2]
        + T[0, 2] * tail_inv[2, 2]
        + T[0, 3] * tail_inv[3, 2],
        T[0, 0] * tail_inv[0, 3]
        + T[0, 1] * tail_inv[1, 3]
        + T[0, 2] * tail_inv[2, 3]
        + T[0, 3] * tail_inv[3, 3],
        T[1, 0] * tail_inv[0, 0]
        + T[1, 1] * tail_inv[1, 0]
        + T[1, 2] * tail_inv[2, 0]
        + T[1, 3] * tail_inv[3, 0],
        T[1, 0] * tail_inv[0, 1]
        + T[1, 1] * tail_inv[1, 1]
        + T[1, 2] * tail_inv[2, 1]
        + T[1, 3] * tail_inv[3, 1],
        T[1, 0] * tail_inv[0, 2]
        + T[1, 1] * tail_inv[1, 2]
        + T[1, 2] * tail_inv[2, 2]
        + T[1, 3] * tail_inv[3, 2],
        T[1, 0] * tail_inv[0, 3]
        + T[1, 1] * tail_inv[1, 3]
        + T[1, 2] * tail_inv[2, 3]
        + T[1, 3] * tail_inv[3, 3],
        T[2, 0] * tail_inv[0, 0]
        + T[2, 1] * tail_inv[1, 0]
        + T[2, 2] * tail_inv[2, 0]
        + T[2, 3] * tail_inv[3, 0],
        T[2, 0] * tail_inv[0, 1]
        + T[2, 1] * tail_inv[1, 1]
        + T[2, 2] * tail_inv[2, 1]
        + T[2, 3] * tail_inv[3, 1],
        T[2, 0] * tail_inv[0, 2]
        + T[2, 1] * tail_inv[1, 2]
        + T[2, 2] * tail_inv[2, 2]
        + T[2, 3] * tail_inv[3, 2],
        T[2, 0] * tail_inv[0, 3]
        + T[2, 1] * tail_inv[1, 3]
        + T[2, 2] * tail_inv[2, 3]
        + T[2, 3] * tail_inv[3, 3],
    )


@njit(cache=True, error_model="numpy", inline="always")
def wrist_entry(
    P: np.ndarray, b: int, r: int, c: int, tail_inv: np.ndarray
) -> float:  # pragma: no cover - compiled
    """Kernel: entry (r, c) of ``T · tail_inv`` for pose b of a block P (12, BLOCK), summed
    in :func:`wrist_frame`'s order."""
    entry: float = (
        P[4 * r, b] * tail_inv[0, c]
        + P[4 * r + 1, b] * tail_inv[1, c]
        + P[4 * r + 2, b] * tail_inv[2, c]
        + P[4 * r + 3, b] * tail_inv[3, c]
    )
    return entry


BLOCK = 32
"""Poses per block of the OPW kernels (:mod:`~trackplan.robots.families._opw_kernels`):
each pass over a block is a flat loop over its poses that LLVM turns into SIMD code."""


@njit(cache=True, error_model="numpy", inline="always")
def unreachable(
    valid: np.ndarray, aux: np.ndarray, first: int, stop: int
) -> None:  # pragma: no cover
    """Kernel: mark branches first … stop − 1 of one pose unreachable.

    Their arctangent slots keep finite values of an earlier pose and are not read.
    """
    for br in range(first, stop):
        valid[br] = False
        for j in range(AUX_SIZE):
            aux[br, j] = np.nan


@njit(cache=True, error_model="numpy", inline="always")
def interval(grid: np.ndarray, x: float, guess: int) -> int:  # pragma: no cover - compiled
    """Kernel: ``numpy.searchsorted(grid, x, side="right") - 1`` for a strictly increasing
    grid (G,): the interval [grid[i], grid[i + 1]) holding x, −1 before the grid, G − 1
    from its end on (and for NaN). The interval ``guess`` and the next one are tried
    first (samples in order move by at most one), then a bisection."""
    n_grid = grid.shape[0]
    for i in (guess, guess + 1):
        if 0 <= i < n_grid - 1 and grid[i] <= x < grid[i + 1]:
            return i
    lo = 0
    hi = n_grid
    while lo < hi:
        mid = (lo + hi) >> 1
        if x < grid[mid]:
            hi = mid
        else:
            lo = mid + 1
    return lo - 1


@njit(cache=True, error_model="numpy")
def hold_and_wind(
    q: np.ndarray, valid: np.ndarray, s: np.ndarray, s_grid: np.ndarray, q_grid: np.ndarray
) -> None:  # pragma: no cover - compiled
    """Kernel: one branch's joints held over the poses it misses and wound, in place.

    A pose the branch does not reach takes the joints of the reachable pose before it (the
    first reachable one before them all); every joint is then moved by the multiple of 2π
    that brings it nearest the reference, the linear interpolation of ``q_grid`` at ``s``
    (``numpy.interp``'s formula, its end values outside the grid). With no reachable pose
    the joints stay as they are (NaN).

    Parameters
    ----------
    q
        Joint positions, shape (M, n), rad (changed in place).
    valid
        Shape (M,), bool: the branch reaches the pose.
    s
        Where each pose lies, shape (M,).
    s_grid, q_grid
        Reference: strictly increasing abscissae (G,) and the joints there (G, n), rad.
    """
    n_poses, n = q.shape
    n_grid = s_grid.shape[0]
    two_pi = 2.0 * math.pi
    held = np.empty(n)
    first = -1
    for m in range(n_poses):
        if valid[m]:
            first = m
            break
    for j in range(n):
        held[j] = q[first, j] if first >= 0 else np.nan
    i = -1
    for m in range(n_poses):
        if first < 0 or valid[m]:
            for j in range(n):
                held[j] = q[m, j]
        x = s[m]
        i = interval(s_grid, x, i)
        for j in range(n):
            if i < 0:
                reference = q_grid[0, j]
            elif i >= n_grid - 1:
                reference = q_grid[n_grid - 1, j]
            else:
                slope = (q_grid[i + 1, j] - q_grid[i, j]) / (s_grid[i + 1] - s_grid[i])
                reference = slope * (x - s_grid[i]) + q_grid[i, j]
            q[m, j] = held[j] - two_pi * np.rint((held[j] - reference) / two_pi)
