"""Every IK solution of a pose by multi-start Newton: the numeric family's branches.

A pose of a general 6R arm has up to 16 solutions; no seed reaches them all. The
numeric family (:class:`~trackplan.robots.families.numeric.NumericFamily`) therefore
starts damped Newton (:func:`~trackplan.robots._ik_kernels.newton_into`) from a fixed,
deterministic set of configurations (:func:`start_configurations`): the eight structured
seeds of :func:`~trackplan.robots.families.numeric.numeric_seeds` and
:data:`N_SOBOL` points of a scrambled Sobol sequence over the joint limits (scipy's
``qmc.Sobol``, seed :data:`SOBOL_SEED`). A converged start (position and orientation
error ≤ :data:`SOLVED_TOL`) is moved by multiples of 2π into the limits (the lowest that
fits), dropped where it fits nowhere or repeats a solution found before it (every joint
within the caller's ``same``: the families' ``SAME_SOLUTION``), and the distinct ones are
ordered by their structural signature, then by their margin to the limits
(:func:`select_solutions`), at most K kept. One compiled call runs all poses × starts
(:func:`multi_start`).

The signature is ``4·s + 2·e + w`` with s, e, w = 1 where these measures
(:func:`structure_measures`) are negative: the shoulder ``z₂ · (z₁ × (w − o₁))`` (zero with
the wrist point w on axis 1), the elbow ``z_e · ((o_e − o₂) × (w − o_e))`` (zero with the arm
stretched or folded; e the third joint, the fourth of a 7-joint arm) and the wrist
``z_{n−1} · (z_{n−2} × z_n)`` (zero with the last three axes coplanar); ``o_i``, ``z_i``
are the origin and axis of joint i and w the origin of joint n − 1.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from trackplan.robots._ik_kernels import fk_jacobian_into, newton_into, work_size_kernel

N_SOBOL = 64
"""Scrambled Sobol starts per pose, besides the eight structured seeds."""

SOBOL_SEED = 20261207
"""Seed of the scrambling: the starts, and so the solutions found, are reproducible."""

SOLVED_TOL = 1e-10
"""Largest position (m) and orientation (rad) error of a solution that is kept."""

MAX_ITER = 100
"""Most Newton iterations from one start."""

POLISH_TOL = 1e-15
POLISH_ITER = 3
"""A converged start takes up to 3 more Newton steps towards 1e-15 (kept while the error
falls): its joints then agree with the exact solution to round-off over the condition of
the Jacobian, not to ``SOLVED_TOL`` over it (about 1e-6 rad near a singularity), so that
deduplication and the comparison with a closed form hold there too."""


def start_configurations(
    structured: np.ndarray, q_min: np.ndarray, q_max: np.ndarray
) -> np.ndarray:
    """The structured seeds followed by :data:`N_SOBOL` scrambled Sobol points.

    The Sobol points cover each joint's limits, or the 2π window centred in them for a
    joint whose range exceeds a turn (the other windings are the same solutions).

    Parameters
    ----------
    structured
        Shape (S0, n), rad.
    q_min, q_max
        Shape (n,), rad.

    Returns
    -------
    numpy.ndarray
        Shape (S0 + N_SOBOL, n), rad, C-contiguous.
    """
    n = q_min.shape[0]
    middle = 0.5 * (q_min + q_max)
    half = np.minimum(0.5 * (q_max - q_min), np.pi)
    from scipy.stats import qmc  # a robot without a closed form only (startup time)

    unit = qmc.Sobol(d=n, scramble=True, seed=SOBOL_SEED).random_base2(int(math.log2(N_SOBOL)))
    sobol = middle + (2.0 * unit - 1.0) * half
    return np.ascontiguousarray(np.vstack([structured, sobol]))


@njit(cache=True, error_model="numpy")
def structure_measures(
    axes: np.ndarray, elbow: int, out: np.ndarray
) -> None:  # pragma: no cover - compiled
    """Kernel: the shoulder, elbow and wrist measures (see the module) into out (3,).

    ``axes`` (n, 6): each joint's axis and origin in the base frame
    (:func:`~trackplan.robots._ik_kernels.fk_jacobian_into`); ``elbow`` the elbow joint.
    """
    n = axes.shape[0]
    w = n - 2
    # shoulder: z₂ · (z₁ × (w − o₁))
    dx = axes[w, 3] - axes[0, 3]
    dy = axes[w, 4] - axes[0, 4]
    dz = axes[w, 5] - axes[0, 5]
    cx = axes[0, 1] * dz - axes[0, 2] * dy
    cy = axes[0, 2] * dx - axes[0, 0] * dz
    cz = axes[0, 0] * dy - axes[0, 1] * dx
    out[0] = axes[1, 0] * cx + axes[1, 1] * cy + axes[1, 2] * cz
    # elbow: z_e · ((o_e − o₂) × (w − o_e))
    ux = axes[elbow, 3] - axes[1, 3]
    uy = axes[elbow, 4] - axes[1, 4]
    uz = axes[elbow, 5] - axes[1, 5]
    vx = axes[w, 3] - axes[elbow, 3]
    vy = axes[w, 4] - axes[elbow, 4]
    vz = axes[w, 5] - axes[elbow, 5]
    out[1] = (
        axes[elbow, 0] * (uy * vz - uz * vy)
        + axes[elbow, 1] * (uz * vx - ux * vz)
        + axes[elbow, 2] * (ux * vy - uy * vx)
    )
    # wrist: z_{n−1} · (z_{n−2} × z_n)
    a = n - 3
    c = n - 1
    out[2] = (
        axes[w, 0] * (axes[a, 1] * axes[c, 2] - axes[a, 2] * axes[c, 1])
        + axes[w, 1] * (axes[a, 2] * axes[c, 0] - axes[a, 0] * axes[c, 2])
        + axes[w, 2] * (axes[a, 0] * axes[c, 1] - axes[a, 1] * axes[c, 0])
    )


@njit(cache=True, error_model="numpy")
def multi_start(
    chain: np.ndarray,
    tool: np.ndarray,
    T: np.ndarray,
    starts: np.ndarray,
    locked: int,
    free: np.ndarray,
    elbow: int,
    tol: float,
    max_iter: int,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:  # pragma: no cover - compiled
    """Kernel: Newton from every start towards every pose.

    Parameters
    ----------
    chain, tool
        From :func:`trackplan.robots.ik_numeric.chain_arrays`.
    T
        Tool poses, shape (N, 4, 4), m.
    starts
        Start configurations, shape (S, n), rad.
    locked, free
        Joint ``locked`` (≥ 0) held at ``free[i]`` (shape (N,), rad) for pose i; −1: none.
    elbow
        The elbow joint of :func:`structure_measures`.
    tol, max_iter
        Newton tolerance (m and rad) and iteration limit.

    Returns
    -------
    q, solved, measures
        Shapes (N, S, n) rad (not wrapped), (N, S) bool and (N, S, 3) (shoulder, elbow,
        wrist measures of the solution).
    """
    n_poses = T.shape[0]
    n_starts, n = starts.shape
    q = np.empty((n_poses, n_starts, n))
    solved = np.empty((n_poses, n_starts), dtype=np.bool_)
    measures = np.zeros((n_poses, n_starts, 3))
    work = np.empty(work_size_kernel(n))
    T_k = np.empty((4, 4))
    J = np.empty((6, n))
    axes = np.empty((n, 6))
    for i in range(n_poses):
        for s in range(n_starts):
            x = q[i, s]
            for j in range(n):
                x[j] = starts[s, j]
            if locked >= 0:
                x[locked] = free[i]
            ok = newton_into(chain, tool, T[i], x, tol, max_iter, work, locked)[0]
            solved[i, s] = ok
            if ok:  # polish to round-off: near a singularity 1e-10 m is 1e-6 rad
                newton_into(chain, tool, T[i], x, POLISH_TOL, POLISH_ITER, work, locked)
                fk_jacobian_into(chain, tool, x, T_k, J, axes)
                structure_measures(axes, elbow, measures[i, s])
    return q, solved, measures


@njit(cache=True, error_model="numpy")
def select_solutions(
    q: np.ndarray,
    solved: np.ndarray,
    measures: np.ndarray,
    q_min: np.ndarray,
    q_max: np.ndarray,
    n_keep: int,
    same: float,
) -> tuple[np.ndarray, np.ndarray]:  # pragma: no cover - compiled
    """Kernel: the distinct solutions of each pose inside the limits, in a fixed order.

    Each solved start (q (N, S, n), solved (N, S)) is moved joint by joint by the lowest
    multiple of 2π that puts it above q_min; it is dropped where a joint then exceeds
    q_max, or where every joint is within ``same`` rad of a solution kept before it (in
    start order). The distinct ones are sorted by signature ``4·s + 2·e + w`` (bits set
    where the measures (N, S, 3) are negative), then by margin to the limits, largest
    first, then by start; the first ``n_keep`` are kept.

    Returns
    -------
    q, found
        Shapes (N, n_keep, n) (NaN where not found) and (N, n_keep), the found first.
    """
    n_poses, n_starts, n = q.shape
    two_pi = 2.0 * math.pi
    out = np.full((n_poses, n_keep, n), np.nan)
    found = np.zeros((n_poses, n_keep), dtype=np.bool_)
    kept = np.empty((n_starts, n))
    key = np.empty(n_starts)
    margin = np.empty(n_starts)
    order = np.empty(n_starts, dtype=np.int64)
    lifted = np.empty(n)
    for i in range(n_poses):
        count = 0
        for s in range(n_starts):
            if not solved[i, s]:
                continue
            fits = True
            room = np.inf
            for j in range(n):
                value = q[i, s, j] + two_pi * math.ceil((q_min[j] - q[i, s, j]) / two_pi)
                lifted[j] = value
                if value > q_max[j]:
                    fits = False
                room = min(room, value - q_min[j], q_max[j] - value)
            if not fits:
                continue
            repeat = False
            for k in range(count):
                close = True
                for j in range(n):
                    if abs(kept[k, j] - lifted[j]) > same:
                        close = False
                        break
                if close:
                    repeat = True
                    break
            if repeat:
                continue
            for j in range(n):
                kept[count, j] = lifted[j]
            signature = 0
            if measures[i, s, 0] < 0.0:
                signature += 4
            if measures[i, s, 1] < 0.0:
                signature += 2
            if measures[i, s, 2] < 0.0:
                signature += 1
            key[count] = signature
            margin[count] = room
            order[count] = count
            count += 1
        for a in range(1, count):  # insertion sort: signature up, margin down, stable
            item = order[a]
            b = a - 1
            while b >= 0 and (
                key[order[b]] > key[item]
                or (key[order[b]] == key[item] and margin[order[b]] < margin[item])
            ):
                order[b + 1] = order[b]
                b -= 1
            order[b + 1] = item
        for c in range(min(count, n_keep)):
            for j in range(n):
                out[i, c, j] = kept[order[c], j]
            found[i, c] = True
    return out, found
