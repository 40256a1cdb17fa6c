"""Closed-form inverse kinematics of 6R arms with a spherical wrist (PUMA560 family).

Supported DH structure (:func:`has_closed_form`), standard DH as in docs/conventions.md::

    joint  alpha    a    d
    1      +π/2     0    d1
    2       0       a2   d2
    3      −π/2     a3   d3
    4      +π/2     0    d4
    5      −π/2     0    0
    6      any      any  any

with any link lengths (``a2 ≠ 0``, ``a3² + d4² > 0``), any joint offsets, any last link
(d6, a6, alpha6) and any ``T_flange_tool``. Joints 4, 5 and 6 intersect at the wrist
centre, the origin of DH frames 4 and 5.

Branches
--------
Every reachable pose has eight solutions, numbered ``b = 4·shoulder + 2·elbow + wrist``
(θ_i = q_i + offset_i, ``D = d2 + d3`` the lateral shoulder offset, ``β = atan2(d4, a3)``):

- shoulder (bit 2): the sign of ``r``, the horizontal distance of the wrist centre in
  front of joint 1's axis, measured along x1 (the direction the upper-arm plane faces).
  0: ``r ≥ 0``, the wrist centre is in front of the shoulder; 1: ``r < 0``, the arm
  reaches back over the shoulder. roboticstoolbox's Puma560 calls these 'r' and 'l'.
  The two meet at the shoulder singularity ``r = 0`` (wrist centre on the cylinder of
  radius |D| about joint 1's axis).
- elbow (bit 1): the sign of ``sin(θ3 + β)``, the angle from the upper arm (elbow minus
  shoulder) to the forearm (wrist centre minus elbow) about z1. For the PUMA (a2 > 0)
  with shoulder 0, elbow 0 puts the elbow above the shoulder–wrist line ('u' in
  roboticstoolbox), elbow 1 below it ('d'). They meet when the arm is stretched or
  folded (``sin(θ3 + β) = 0``).
- wrist (bit 0): the sign of ``sin θ5``. 0: ``θ5 ∈ [0, π]``; 1: ``θ5 ∈ (−π, 0)``, the
  flipped wrist, equal to branch 0's wrist with θ4 + π, −θ5, θ6 + π. They meet at the
  wrist singularity ``θ5 = 0`` (joint 4 and 6 axes aligned). There only θ4 + θ6 is
  defined: the solver then sets ``q4 = 0`` (wrist 0) or ``q4 = π`` (wrist 1) and puts
  the whole rotation on joint 6.

Joint limits are not applied here (:mod:`trackplan.robots.path_ik` maps paths into them).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numba import njit

from trackplan.errors import CaseError
from trackplan.robots.model import Robot

N_BRANCHES = 8
"""Number of closed-form solutions of a pose."""

_ALPHA = (np.pi / 2, 0.0, -np.pi / 2, np.pi / 2, -np.pi / 2)
_STRUCTURE_TOL = 1e-12
_RHO_TOL = 1e-12  # m², how far inside the shoulder cylinder still counts as on it
_K_TOL = 1e-12  # how far past a stretched/folded elbow still counts as reachable
_WRIST_SINGULAR = 1e-12  # |sin θ5| below which θ4 is set, not solved

# Layout of the geometry vector handed to the kernels.
_D1, _D, _A2, _L3, _CB, _SB, _BETA, _UP, _C4, _S4 = range(10)
_OFFSET = 10  # offsets of joints 1..6 follow
N_AUX = 14
"""Per-pose branch quantities written by the kernel: |r| (m), |sin(θ3 + β)|, then for
each arm solution a = 2·shoulder + elbow the vector z3 × z5 (base frame), whose norm
is |sin θ5|."""


@dataclass(frozen=True, eq=False)
class ClosedFormIK:
    """All eight closed-form solutions of a batch of poses.

    Attributes
    ----------
    q
        Joint positions, shape (..., 8, n), rad, in (−π, π]; NaN where not ``valid``.
        Axis −2 is the branch ``b = 4·shoulder + 2·elbow + wrist`` (module docstring).
    valid
        Shape (..., 8), bool: the branch reaches the pose (joint limits not applied).
    """

    q: np.ndarray
    valid: np.ndarray

    @property
    def reachable(self) -> np.ndarray:
        """Shape (...,), bool: at least one branch reaches the pose."""
        return np.any(self.valid, axis=-1)


def branch_bits(branch: int) -> tuple[int, int, int]:
    """The (shoulder, elbow, wrist) bits of a branch number 0…7."""
    return (branch >> 2) & 1, (branch >> 1) & 1, branch & 1


def describe_branch(branch: int) -> str:
    """A short human-readable name of a branch, e.g. ``"front/elbow up/q5 ≥ 0"``."""
    shoulder, elbow, wrist = branch_bits(branch)
    return "/".join(
        (
            ("front", "back")[shoulder],
            ("elbow up", "elbow down")[elbow],
            ("q5 ≥ 0", "q5 < 0")[wrist],
        )
    )


def has_closed_form(robot: Robot) -> bool:
    """True when :func:`solve_ik_closed_form` applies to ``robot``.

    That is a 6R chain with the DH structure in the module docstring: alpha1..5 equal
    to (π/2, 0, −π/2, π/2, −π/2) and a1 = a4 = a5 = d5 = 0 to 1e-12, a2 ≠ 0 and a
    forearm of non-zero length. Link 6, the offsets and the tool are free.
    """
    if robot.n_dof != 6:
        return False
    alpha_error = np.angle(np.exp(1j * (robot.alpha[:5] - np.array(_ALPHA))))
    zeros = np.array([robot.a[0], robot.a[3], robot.a[4], robot.d[4]])
    return bool(
        np.all(np.abs(alpha_error) <= _STRUCTURE_TOL)
        and np.all(np.abs(zeros) <= _STRUCTURE_TOL)
        and abs(robot.a[1]) > _STRUCTURE_TOL
        and math.hypot(robot.a[2], robot.d[3]) > _STRUCTURE_TOL
    )


def closed_form_geometry(robot: Robot) -> tuple[np.ndarray, np.ndarray]:
    """The numbers the kernels need: a geometry vector and the wrist-to-tool inverse.

    Returns
    -------
    geometry
        Shape (16,): d1, D = d2 + d3, a2, L3 = hypot(a3, d4), cos β, sin β, β, the sign
        of sin(θ3 + β) for elbow up with shoulder 0, cos and sin of offset4, offsets 1..6
        (metres, radians).
    tail_inv
        Shape (4, 4): ``(Tz(d6) Tx(a6) Rx(alpha6) · T_flange_tool)⁻¹``, which maps a tool
        pose to the wrist frame ``T_0_5 · Rz(θ6)``.

    Raises
    ------
    CaseError
        When the robot has no closed form.
    """
    if not has_closed_form(robot):
        raise CaseError(
            f"robot {robot.name!r} has no closed-form IK (not a PUMA-type spherical-wrist "
            "DH structure): use trackplan.robots.ik_numeric",
            key="robot",
        )
    d, a = robot.d, robot.a
    beta = math.atan2(d[3], a[2])
    geometry = np.empty(_OFFSET + 6)
    geometry[:_OFFSET] = (
        d[0],
        d[1] + d[2],
        a[1],
        math.hypot(a[2], d[3]),
        math.cos(beta),
        math.sin(beta),
        beta,
        -1.0 if a[1] > 0.0 else 1.0,
        math.cos(robot.offset[3]),
        math.sin(robot.offset[3]),
    )
    geometry[_OFFSET:] = robot.offset
    ca, sa = math.cos(robot.alpha[5]), math.sin(robot.alpha[5])
    link6 = np.array(
        [[1.0, 0.0, 0.0, a[5]], [0.0, ca, -sa, 0.0], [0.0, sa, ca, d[5]], [0.0, 0.0, 0.0, 1.0]]
    )
    tail = link6 @ robot.T_flange_tool
    tail_inv = np.eye(4)
    tail_inv[:3, :3] = tail[:3, :3].T
    tail_inv[:3, 3] = -tail[:3, :3].T @ tail[:3, 3]
    return geometry, tail_inv


def solve_ik_closed_form(robot: Robot, T_base_tool: np.ndarray) -> ClosedFormIK:
    """All eight IK solutions of tool poses, in closed form.

    Parameters
    ----------
    robot
        A robot for which :func:`has_closed_form` is True.
    T_base_tool
        Tool poses in the base frame, shape (..., 4, 4), metres. The tool transform
        ``robot.T_flange_tool`` is removed here.

    Returns
    -------
    ClosedFormIK
        ``q`` of shape (..., 8, 6) in (−π, π] and ``valid`` of shape (..., 8).

    Raises
    ------
    CaseError
        When the robot has no closed form or the poses are not (..., 4, 4).
    """
    T = np.asarray(T_base_tool, dtype=float)
    if T.ndim < 2 or T.shape[-2:] != (4, 4):
        raise CaseError(f"T_base_tool must have shape (..., 4, 4), got {T.shape}")
    lead = T.shape[:-2]
    q, valid, _ = solve_flat(robot, T.reshape(-1, 4, 4))
    return ClosedFormIK(q.reshape(*lead, N_BRANCHES, 6), valid.reshape(*lead, N_BRANCHES))


def solve_flat(robot: Robot, T_base_tool: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The eight solutions of a flat batch of poses, with the branch quantities.

    Each chunk of poses goes through three passes: a compiled pass computes the
    arguments of every arctangent, numpy's SIMD ``arctan2`` evaluates them (about 8×
    faster than libm's scalar atan2, which dominates a scalar kernel), and a compiled pass
    assembles the branches.

    Parameters
    ----------
    robot
        A robot for which :func:`has_closed_form` is True.
    T_base_tool
        Tool poses, shape (N, 4, 4), metres.

    Returns
    -------
    q
        Shape (N, 8, 6), rad in (−π, π], NaN where not valid.
    valid
        Shape (N, 8), bool.
    aux
        Shape (N, N_AUX): the branch-defining quantities (see ``N_AUX``), NaN out of reach.
    """
    geometry, tail_inv = closed_form_geometry(robot)
    T = np.ascontiguousarray(T_base_tool, dtype=float)
    n_poses = T.shape[0]
    q = np.empty((n_poses, N_BRANCHES, 6))
    valid = np.empty((n_poses, N_BRANCHES), dtype=np.bool_)
    aux = np.empty((n_poses, N_AUX))
    size = min(_CHUNK, n_poses)
    Y = np.empty((size, _N_ANGLES))
    X = np.empty((size, _N_ANGLES))
    angles = np.empty((size, _N_ANGLES))
    for start in range(0, n_poses, _CHUNK):
        stop = min(start + _CHUNK, n_poses)
        m = stop - start
        _arctan_arguments(
            geometry, tail_inv, T[start:stop], Y[:m], X[:m], valid[start:stop], aux[start:stop]
        )
        np.arctan2(Y[:m], X[:m], out=angles[:m])
        _assemble(geometry, angles[:m], valid[start:stop], q[start:stop])
    return q, valid, aux


# Slots of the arctangents of one pose: θ1 of shoulder 0 and 1, the elbow angle
# φ0 = |θ3 + β|, θ2 of the four arms a = 2·shoulder + elbow, then θ4, θ5, θ6 of each arm.
_TH1, _PHI, _TH2, _WRIST = 0, 2, 3, 7
_N_ANGLES = 19
_CHUNK = 2048  # poses per pass: the scratch stays in the L2 cache


@njit(cache=True, error_model="numpy")
def _arctan_arguments(
    geometry: np.ndarray,
    tail_inv: np.ndarray,
    T: np.ndarray,
    Y: np.ndarray,
    X: np.ndarray,
    valid: np.ndarray,
    aux: np.ndarray,
) -> None:  # pragma: no cover - compiled
    """Kernel: arctangent arguments (Y, X) (N, 19), reachability (N, 8) and aux (N, 14)."""
    D = geometry[_D]
    a2 = geometry[_A2]
    L3 = geometry[_L3]
    cb = geometry[_CB]
    sb = geometry[_SB]
    up = geometry[_UP]
    w = np.empty((3, 4))  # wrist frame T · tail_inv (rotation, centre)
    for k in range(T.shape[0]):
        Tk = T[k]
        for i in range(3):
            for j in range(4):
                w[i, j] = (
                    Tk[i, 0] * tail_inv[0, j]
                    + Tk[i, 1] * tail_inv[1, j]
                    + Tk[i, 2] * tail_inv[2, j]
                    + Tk[i, 3] * tail_inv[3, j]
                )
        px = w[0, 3]
        py = w[1, 3]
        h = w[2, 3] - geometry[_D1]
        rho = px * px + py * py - D * D
        K = (rho + h * h - a2 * a2 - L3 * L3) / (2.0 * a2 * L3)
        reachable = rho >= -_RHO_TOL and abs(K) <= 1.0 + _K_TOL
        for b in range(N_BRANCHES):
            valid[k, b] = reachable
        if not reachable:
            for j in range(_N_ANGLES):
                Y[k, j] = 0.0
                X[k, j] = 1.0
            for j in range(N_AUX):
                aux[k, j] = np.nan
            continue
        r0 = math.sqrt(max(rho, 0.0))
        K = min(max(K, -1.0), 1.0)
        sphi0 = math.sqrt((1.0 - K) * (1.0 + K))
        Y[k, _PHI] = sphi0
        X[k, _PHI] = K
        aux[k, 0] = r0
        aux[k, 1] = sphi0
        u = a2 + L3 * K
        for shoulder in range(2):
            r = r0 if shoulder == 0 else -r0
            c1, s1 = _unit(r * px - D * py, D * px + r * py)
            Y[k, _TH1 + shoulder] = s1
            X[k, _TH1 + shoulder] = c1
            for elbow in range(2):
                arm = 2 * shoulder + elbow
                sphi = (up if shoulder == elbow else -up) * sphi0
                c3 = K * cb + sphi * sb
                s3 = sphi * cb - K * sb
                c2, s2 = _unit(r * u + h * L3 * sphi, h * u - r * L3 * sphi)
                Y[k, _TH2 + arm] = s2
                X[k, _TH2 + arm] = c2
                c23 = c2 * c3 - s2 * s3
                s23 = s2 * c3 + c2 * s3
                # Columns of R_0_3: x3 = (c1 c23, s1 c23, s23), y3 = (−s1, c1, 0),
                # z3 = (−c1 s23, −s1 s23, c23); M = R_0_3ᵀ R_w = Rz(θ4) Ry(−θ5) Rz(θ6).
                z3x = -c1 * s23
                z3y = -s1 * s23
                m00 = c1 * c23 * w[0, 0] + s1 * c23 * w[1, 0] + s23 * w[2, 0]
                m02 = c1 * c23 * w[0, 2] + s1 * c23 * w[1, 2] + s23 * w[2, 2]
                m10 = -s1 * w[0, 0] + c1 * w[1, 0]
                m12 = -s1 * w[0, 2] + c1 * w[1, 2]
                m20 = z3x * w[0, 0] + z3y * w[1, 0] + c23 * w[2, 0]
                m22 = z3x * w[0, 2] + z3y * w[1, 2] + c23 * w[2, 2]
                aux[k, 2 + 3 * arm] = z3y * w[2, 2] - c23 * w[1, 2]
                aux[k, 3 + 3 * arm] = c23 * w[0, 2] - z3x * w[2, 2]
                aux[k, 4 + 3 * arm] = z3x * w[1, 2] - z3y * w[0, 2]
                s5 = math.sqrt(m02 * m02 + m12 * m12)
                c5 = m22
                if s5 > _WRIST_SINGULAR:
                    c4 = -m02 / s5
                    s4 = -m12 / s5
                else:
                    c4 = geometry[_C4]
                    s4 = geometry[_S4]
                # θ6 from Ry(θ5) Rz(−θ4) M = Rz(θ6): exact for any θ4 once θ5 is exact.
                n00 = c4 * m00 + s4 * m10
                n10 = -s4 * m00 + c4 * m10
                slot = _WRIST + 3 * arm
                Y[k, slot] = s4
                X[k, slot] = c4
                Y[k, slot + 1] = s5
                X[k, slot + 1] = c5
                Y[k, slot + 2] = n10
                X[k, slot + 2] = c5 * n00 + s5 * m20


@njit(cache=True, error_model="numpy", inline="always")
def _unit(c: float, s: float) -> tuple[float, float]:  # pragma: no cover - compiled
    """(cos, sin) of the angle of the vector (c, s); (1, 0) for the zero vector."""
    norm = math.sqrt(c * c + s * s)
    if norm > 0.0:
        return c / norm, s / norm
    return 1.0, 0.0


@njit(cache=True, error_model="numpy", inline="always")
def _wrap(x: float) -> float:  # pragma: no cover - compiled
    """Angle in (−π, π]."""
    if -math.pi < x <= math.pi:
        return x
    return x + 2.0 * math.pi * math.floor((math.pi - x) / (2.0 * math.pi))


@njit(cache=True, error_model="numpy")
def _assemble(
    geometry: np.ndarray, angles: np.ndarray, valid: np.ndarray, q: np.ndarray
) -> None:  # pragma: no cover - compiled
    """Kernel: joint angles q (N, 8, 6) of the eight branches from the arctangents (N, 19)."""
    off = geometry[_OFFSET:]
    up = geometry[_UP]
    beta = geometry[_BETA]
    for k in range(angles.shape[0]):
        if not valid[k, 0]:
            for b in range(N_BRANCHES):
                for j in range(6):
                    q[k, b, j] = np.nan
            continue
        a = angles[k]
        for shoulder in range(2):
            th1 = _wrap(a[_TH1 + shoulder] - off[0])
            for elbow in range(2):
                arm = 2 * shoulder + elbow
                sign = up if shoulder == elbow else -up
                th2 = _wrap(a[_TH2 + arm] - off[1])
                th3 = _wrap(sign * a[_PHI] - beta - off[2])
                th4 = a[_WRIST + 3 * arm] - off[3]
                th5 = a[_WRIST + 3 * arm + 1]
                th6 = a[_WRIST + 3 * arm + 2] - off[5]
                b = 4 * shoulder + 2 * elbow
                q[k, b, 0] = th1
                q[k, b, 1] = th2
                q[k, b, 2] = th3
                q[k, b, 3] = _wrap(th4)
                q[k, b, 4] = _wrap(th5 - off[4])
                q[k, b, 5] = _wrap(th6)
                q[k, b + 1, 0] = th1
                q[k, b + 1, 1] = th2
                q[k, b + 1, 2] = th3
                q[k, b + 1, 3] = _wrap(th4 + math.pi)
                q[k, b + 1, 4] = _wrap(-th5 - off[4])
                q[k, b + 1, 5] = _wrap(th6 + math.pi)
