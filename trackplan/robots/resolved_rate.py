"""Resolved-rate IK along a pose path: the paper's Eq. 19–27, and an improved variant.

The paper (section 3.1.4) starts from a known configuration q(0) at the first pose and
steps through the poses with the inverse Jacobian (Eq. 22)::

    q(k+1) = q(k) + J(q(k))⁻¹ Δ

where Δ (Eq. 23–27) is the increment from the pose actually reached by q(k) (forward
kinematics, step ii: the "compensation" of the linearisation error) to the next target
pose: ``Δ = (t(k+1) − t_a(k), vex(R(k+1) R_a(k)ᵀ − I))`` with vex taking the upper
triangle (Eq. 26–27). The result still drifts by a second-order error per step and at
singularities J⁻¹ amplifies it: docs/paper.md, departure 4.

Modes of :func:`solve_path_resolved_rate`:

- ``"paper"``: exactly the loop above (steps i–v).
- ``"uncompensated"``: Eq. 22 with Δ between consecutive *target* poses (no step ii):
  the linearisation error accumulates; kept to measure what the compensation buys.
- ``"newton"``: the improved generic mode: the same predictor with the exact rotation
  increment ``log(R(k+1) R_a(k)ᵀ)``, then damped Newton
  (:func:`trackplan.robots.ik_numeric.newton_into`) polishes every sample, the first
  included, to ``tol`` (1e-10 m and rad).

J⁻¹Δ is computed as ``(JᵀJ + εI)⁻¹ JᵀΔ`` with ε = 1e-12, equal to J⁻¹Δ to about 1e-12
away from singularities and finite at them.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from trackplan.errors import CaseError
from trackplan.robots._ik_kernels import (
    damped_solve_into,
    fk_jacobian_into,
    newton_into,
    pose_error_into,
    work_size_kernel,
)
from trackplan.robots.ik_numeric import chain_arrays, check_poses_and_joints
from trackplan.robots.model import Robot

MODES = ("paper", "uncompensated", "newton")
"""Modes of :func:`solve_path_resolved_rate`."""

_PAPER, _UNCOMPENSATED, _NEWTON = range(3)
_EPSILON = 1e-12  # damping of J⁻¹, m²


def solve_path_resolved_rate(
    robot: Robot,
    T_base_tool: np.ndarray,
    q0: np.ndarray,
    *,
    mode: str = "paper",
    tol: float = 1e-10,
    max_iter: int = 20,
) -> np.ndarray:
    """Joint paths along pose paths by resolved rate (paper Eq. 19–27).

    Parameters
    ----------
    robot
        Any DH chain.
    T_base_tool
        Target tool poses in the base frame, shape (..., M, 4, 4), metres.
    q0
        Configuration at the first pose, shape (..., n), rad (the paper's step i);
        leading axes broadcast against the poses'.
    mode
        ``"paper"``, ``"uncompensated"`` or ``"newton"`` (module docstring).
    tol, max_iter
        Newton tolerance (m and rad) and iterations per sample, ``"newton"`` mode only.

    Returns
    -------
    numpy.ndarray
        Joint paths, shape (..., M, n), rad, continuous from q0 (not wrapped).

    Raises
    ------
    CaseError
        When the mode or the shapes are invalid.
    """
    if mode not in MODES:
        raise CaseError(f"mode must be one of {', '.join(MODES)}, got {mode!r}")
    T, start, lead = check_poses_and_joints(robot, T_base_tool, q0, "q0", path=True)
    n = robot.n_dof
    n_poses = T.shape[-3]
    T_flat = np.broadcast_to(T, (*lead, n_poses, 4, 4)).reshape(-1, n_poses, 4, 4)
    q0_flat = np.ascontiguousarray(np.broadcast_to(start, (*lead, n)).reshape(-1, n))
    q = np.empty((q0_flat.shape[0], n_poses, n))
    _resolved_rate(
        *chain_arrays(robot),
        np.ascontiguousarray(T_flat),
        q0_flat,
        MODES.index(mode),
        float(tol),
        int(max_iter),
        q,
    )
    return q.reshape(*lead, n_poses, n)


@njit(cache=True, error_model="numpy")
def _resolved_rate(
    chain: np.ndarray,
    tool: np.ndarray,
    T: np.ndarray,
    q0: np.ndarray,
    mode: int,
    tol: float,
    max_iter: int,
    q: np.ndarray,
) -> None:  # pragma: no cover - compiled
    """Kernel: resolved-rate paths q (P, M, n) through T (P, M, 4, 4) from q0 (P, n)."""
    n_paths, n_poses = T.shape[0], T.shape[1]
    n = chain.shape[0]
    T_a = np.empty((4, 4))
    J = np.empty((6, n))
    axes = np.empty((n, 6))
    delta = np.empty(6)
    dq = np.empty(n)
    m = min(n, 6)
    H = np.empty((m, m))
    g = np.empty(max(n, 6))
    work = np.empty(work_size_kernel(n))
    for p in range(n_paths):
        for j in range(n):
            q[p, 0, j] = q0[p, j]
        if mode == _NEWTON:
            newton_into(chain, tool, T[p, 0], q[p, 0], tol, max_iter, work)
        for k in range(n_poses - 1):
            fk_jacobian_into(chain, tool, q[p, k], T_a, J, axes)  # step ii: the reached pose
            source = T[p, k] if mode == _UNCOMPENSATED else T_a
            target = T[p, k + 1]
            if mode == _NEWTON:
                pose_error_into(target, source, delta)
            else:
                _paper_increment(source, target, delta)
            damped_solve_into(J, delta, _EPSILON, dq, H, g)
            for j in range(n):
                q[p, k + 1, j] = q[p, k, j] + dq[j]
            if mode == _NEWTON:
                newton_into(chain, tool, target, q[p, k + 1], tol, max_iter, work)


@njit(cache=True, error_model="numpy")
def _paper_increment(
    source: np.ndarray, target: np.ndarray, delta: np.ndarray
) -> None:  # pragma: no cover - compiled
    """Kernel: Eq. 24–27, Δ = (t₁ − t₀, vex(R₁ R₀ᵀ − I)) with vex from the upper triangle."""
    for r in range(3):
        delta[r] = target[r, 3] - source[r, 3]
    # Upper triangle of R₁ R₀ᵀ (the − I does not touch it): (0,1) = −Δφz, (0,2) = Δφy,
    # (1,2) = −Δφx (Eq. 26).
    s01 = target[0, 0] * source[1, 0] + target[0, 1] * source[1, 1] + target[0, 2] * source[1, 2]
    s02 = target[0, 0] * source[2, 0] + target[0, 1] * source[2, 1] + target[0, 2] * source[2, 2]
    s12 = target[1, 0] * source[2, 0] + target[1, 1] * source[2, 1] + target[1, 2] * source[2, 2]
    delta[3] = -s12
    delta[4] = s02
    delta[5] = -s01
