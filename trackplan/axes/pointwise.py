"""The positioner's axes that turn a weld normal straight up, point by point (closed form).

A positioner is a revolute chain (:class:`~trackplan.robots.model.Robot`): its flange's
rotation in the cell is ``R = R_pose · O_1 Rot(a_1, p_1) · … · O_n Rot(a_n, p_n) · R_tip``
(``O_i`` the joints' fixed origins, ``a_i`` their unit axes, read from the chain). The weld
normal ``m`` in the carrier frame (the flange) is up in the cell when ``R m = z``. With the
last two axes free (the others held), this is Paden–Kahan subproblem 2 (two rotations about
axes in general position that carry one unit vector onto another; Murray, Li & Sastry, *A
Mathematical Introduction to Robotic Manipulation*, 1994, §3.2.2): two branches (the
intersection points of two cones), ``±γ`` below. With one free axis it is subproblem 1
(the rotation about one axis that brings a vector nearest to another), one branch. Where
exact "straight up" is out of reach (the cones miss each other), the branch is the nearest
point (γ = 0). An axis whose angle does not matter at a sample (the vector on its axis)
comes out NaN; :func:`fill_undetermined` takes its neighbours' angle.
"""

from __future__ import annotations

import numpy as np

from trackplan.robots.model import Robot

MEET = 0.05
"""|γ| (the share of the cones' common vector across both axes) below which the two
branches meet closely enough for a smooth path to pass from one to the other."""
PARALLEL = 1e-9
"""|component across an axis| below which a vector counts as on the axis (its angle free)."""
UP = np.array([0.0, 0.0, 1.0])


def axis_rotation(axis: np.ndarray, angle: np.ndarray) -> np.ndarray:
    """Rotations by ``angle`` (M,) about the unit ``axis`` (3,) (Rodrigues), shape (M, 3, 3)."""
    angle = np.asarray(angle, dtype=float)
    k = np.asarray(axis, dtype=float)
    K = np.array([[0.0, -k[2], k[1]], [k[2], 0.0, -k[0]], [-k[1], k[0], 0.0]])
    s, c = np.sin(angle)[..., None, None], np.cos(angle)[..., None, None]
    R: np.ndarray = np.eye(3) + s * K + (1.0 - c) * (K @ K)
    return R


def _turn_angle(axis: np.ndarray, source: np.ndarray, target: np.ndarray) -> np.ndarray:
    """Angle (M,) about the unit ``axis`` (3,) that turns ``source`` (M, 3) nearest to
    ``target`` (M, 3) (subproblem 1); NaN where either lies on the axis."""
    a = source - (source @ axis)[:, None] * axis
    b = target - (target @ axis)[:, None] * axis
    angle = np.arctan2(np.cross(a, b) @ axis, np.einsum("mk,mk->m", a, b))
    on_axis = (np.linalg.norm(a, axis=1) < PARALLEL) | (np.linalg.norm(b, axis=1) < PARALLEL)
    return np.where(on_axis, np.nan, angle)


def hold_values(chain: Robot) -> np.ndarray:
    """Where a positioner holds still: 0 where 0 is inside an axis's range, else the
    middle of the range, shape (n,), rad."""
    inside = (chain.q_min <= 0.0) & (chain.q_max >= 0.0)
    return np.where(inside, 0.0, 0.5 * (chain.q_min + chain.q_max))


def _prefix(chain: Robot, R_pose: np.ndarray, held: np.ndarray, first_free: int) -> np.ndarray:
    """The rotation before the first free axis's turn: ``R_pose · O_1 Rot … O_first``."""
    R = R_pose @ chain.origins[0, :3, :3]
    for i in range(first_free):
        R = R @ axis_rotation(chain.axes[i], np.array(held[i])) @ chain.origins[i + 1, :3, :3]
    return R


def upright_branches(
    chain: Robot, R_pose: np.ndarray, normal: np.ndarray, held: np.ndarray | None = None
) -> tuple[np.ndarray, np.ndarray]:
    """The positioner angles that turn carrier-frame normals straight up in the cell.

    Parameters
    ----------
    chain
        The positioner's chain (revolute axes).
    R_pose
        The positioner base's rotation in the cell, shape (3, 3).
    normal
        Unit weld normals in the carrier (flange) frame, shape (M, 3).
    held
        Angles of the axes before the last two, which stay still, shape (n,) (only their
        first n − 2 entries are read); None: :func:`hold_values`.

    Returns
    -------
    branches
        Shape (B, M, n), rad in (−π, π]: B = 2 branches (γ ≥ 0 and γ ≤ 0) with two or
        more axes, 1 with one axis or two parallel ones (the last held); NaN where an
        axis's angle does not matter.
    gamma
        |γ| per sample, shape (M,): where it passes near 0 the branches meet (zeros with
        one axis).
    """
    n = chain.n_dof
    held = hold_values(chain) if held is None else np.asarray(held, dtype=float)
    normal = np.asarray(normal, dtype=float)
    M = len(normal)
    u = normal @ chain.T_tip[:3, :3].T  # the normal in the last joint's (turned) frame
    first_free = max(n - 2, 0)
    prefix = _prefix(chain, R_pose, held, first_free)
    w = np.broadcast_to(prefix.T @ UP, (M, 3))  # "up" in the first free joint's frame
    fixed = np.broadcast_to(held[:first_free], (M, first_free))
    if n == 1:
        # Rot(a_1, p) u = w  ⇔  p turns u onto w
        angle = _turn_angle(chain.axes[0], u, w)
        return angle[None, :, None], np.zeros(M)
    a1 = chain.axes[first_free]
    O2 = chain.origins[first_free + 1, :3, :3]
    b = O2 @ chain.axes[first_free + 1]  # the second free axis in the first one's frame
    u2 = u @ O2.T
    k = float(a1 @ b)
    if 1.0 - k * k < PARALLEL:  # parallel axes turn the normal alike: the first one alone
        turned = u2 @ axis_rotation(b, np.array(held[first_free + 1])).T
        p1 = _turn_angle(a1, turned, w)
        last = np.full(M, held[first_free + 1])
        return np.column_stack([fixed, p1, last])[None], np.zeros(M)
    cross = np.cross(a1, b)
    sine2 = 1.0 - k * k
    A = w @ a1  # c · a1 is kept by the first rotation
    B = u2 @ b  # c · b is kept by the second one
    alpha = (A - k * B) / sine2
    beta = (B - k * A) / sine2
    gamma2 = (1.0 - alpha**2 - beta**2 - 2.0 * alpha * beta * k) / sine2
    gamma = np.sqrt(np.maximum(gamma2, 0.0))
    branches = []
    for sign in (1.0, -1.0):
        c = alpha[:, None] * a1 + beta[:, None] * b + (sign * gamma)[:, None] * cross
        c /= np.linalg.norm(c, axis=1, keepdims=True)
        p2 = _turn_angle(b, u2, c)  # Rot(b, p2) u2 = c
        p1 = _turn_angle(a1, c, w)  # Rot(a1, p1) c = w
        branches.append(np.column_stack([fixed, p1, p2]))
    return np.stack(branches), gamma * np.sqrt(sine2)


def crossed_branches(branches: np.ndarray, gamma: np.ndarray) -> np.ndarray:
    """The two branches (2, M, n) swapped at every place they meet (the smallest |γ| of
    each run of samples below :data:`MEET`), shape (2, M, n): the paths that pass through
    a meeting smoothly instead of turning back."""
    near = np.concatenate([[False], gamma < MEET, [False]])
    edges = np.flatnonzero(np.diff(near.astype(np.int8)))
    starts, ends = edges[0::2], edges[1::2]
    if len(starts) == 0:
        return branches
    index = np.arange(len(gamma))
    runs = (index[None, :] >= starts[:, None]) & (index[None, :] < ends[:, None])
    meets = np.argmin(np.where(runs, gamma[None, :], np.inf), axis=1)
    swapped = (np.searchsorted(meets, index, side="right") % 2).astype(bool)[:, None]
    first = np.where(swapped, branches[1], branches[0])
    second = np.where(swapped, branches[0], branches[1])
    return np.stack([first, second])


def fill_undetermined(angles: np.ndarray, default: np.ndarray) -> np.ndarray:
    """Angles (M, n) with every NaN replaced by the nearest determined angle before it
    (after it at the start), or by ``default`` (n,) for an axis never determined."""
    angles = np.array(angles, dtype=float)
    M = len(angles)
    index = np.arange(M)[:, None]
    known = ~np.isnan(angles)
    last = np.maximum.accumulate(np.where(known, index, -1), axis=0)
    first = np.minimum.accumulate(np.where(known, index, M)[::-1], axis=0)[::-1]
    source = np.where(last >= 0, last, first)
    never = ~known.any(axis=0)
    source = np.where(never[None, :], 0, source)
    filled = np.take_along_axis(angles, np.clip(source, 0, M - 1), axis=0)
    return np.where(never[None, :], np.asarray(default, dtype=float)[None, :], filled)
