"""Every IK solution of FANUC CRX-type arms: an OPW arm whose wrist is offset.

The CRX cobots (CRX-5iA … CRX-30iA) have axis 1 vertical, axes 2 and 3 parallel and
perpendicular to it, axis 4 along the forearm, axis 5 perpendicular to axis 4 and meeting
it, and axis 6 perpendicular to axis 5 and meeting it a distance l5 along it: the three
wrist axes do not meet (not OPW), and axes 2, 3, 4 are not parallel (not UR). With
``θ = sign · q + θ0`` per joint::

    R  = Rz(θ1) Ry(θ2 + θ3) Rz(θ4) Ry(θ5) Rz(θ6)
    O5 = Rz(θ1) [(a1, b, c1) + Ry(θ2) (0, 0, c2) + Ry(θ2 + θ3) (a2, 0, c3)]
    flange = O5 + l5 · Rz(θ1) Ry(θ2 + θ3) Rz(θ4) e_y + c4 · R e_z

and ``T_base_tool = Trans(base) · T_crx · T_tail``: the OPW model (:mod:`.opw`) plus the
offset l5. The parameters are derived from the chain at q = 0 (:func:`crx_from_chain`).

A pose has up to 16 solutions (M. Abbes, G. Poisson, "Geometric Approach for Inverse
Kinematics of the FANUC CRX Collaborative Robot", Robotics 13(6):91, 2024). They are found
through one angle, θ6 (which places the point where axes 4 and 5 meet on a circle about
axis 6): a scalar residual of it in closed form, all its roots by sampling, bracketing and
false position, each root turned into the joints and checked by FK
(:mod:`._crx_kernels`). The arm is cuspidal: it can move from one solution to another
without a singularity, so a solution's number does not keep a meaning along a path, and
the family is *tracked* (``closed_form`` False): the path IK starts a branch at each
solution of the path's first pose (:meth:`CRXFamily.seed_solutions`) and follows it by
Newton steps.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from trackplan._kernels import read_only
from trackplan.robots.families import _crx_kernels as kern
from trackplan.robots.families import _crx_roots as roots
from trackplan.robots.families.base import (
    RedundancyParameter,
    TrackedFamily,
    wrap_and_deduplicate,
)
from trackplan.robots.families.opw import _PARALLEL_TOL, _ry, _rz, arm_axes, arm_parameters
from trackplan.robots.model import Robot


@dataclass(frozen=True)
class CRXParameters:
    """The CRX description of an arm (lengths m, angles rad).

    Attributes
    ----------
    a1, b, c1
        Joint 2's axis from the base: along the arm, lateral, height.
    c2
        The upper arm, joint 2 to joint 3.
    a2, c3
        The forearm from joint 3 to O5 (where axes 4 and 5 meet), across and along axis 4.
    l5
        O5 to O6 (where axes 5 and 6 meet) along axis 5, signed.
    c4
        O6 to the model's flange along axis 6.
    offsets
        θ0 per joint: the model angle at q = 0, shape (6,).
    signs
        +1 or −1 per joint: ``θ = sign · q + θ0``, shape (6,).
    base
        Position of joint 1's axis in the base x-y plane, shape (2,).
    T_tail
        Fixed transform from the model's flange to the robot's flange.
    """

    a1: float
    b: float
    c1: float
    c2: float
    a2: float
    c3: float
    l5: float
    c4: float
    offsets: tuple[float, ...]
    signs: tuple[float, ...]
    base: tuple[float, float]
    T_tail: np.ndarray

    def forward(self, theta: np.ndarray) -> np.ndarray:
        """Model flange poses (without the base shift or tail), θ (..., 6) → (..., 4, 4)."""
        theta = np.asarray(theta, dtype=float)
        t1, t2, t23 = theta[..., 0], theta[..., 1], theta[..., 1] + theta[..., 2]
        F4 = _rz(t1) @ _ry(t23) @ _rz(theta[..., 3])
        R = F4 @ _ry(theta[..., 4]) @ _rz(theta[..., 5])
        x = self.a1 + self.c2 * np.sin(t2) + self.a2 * np.cos(t23) + self.c3 * np.sin(t23)
        z = self.c1 + self.c2 * np.cos(t2) - self.a2 * np.sin(t23) + self.c3 * np.cos(t23)
        c, s = np.cos(t1), np.sin(t1)
        T = np.zeros((*theta.shape[:-1], 4, 4))
        T[..., :3, :3] = R
        T[..., 0, 3] = c * x - s * self.b
        T[..., 1, 3] = s * x + c * self.b
        T[..., 2, 3] = z
        T[..., :3, 3] += self.l5 * F4[..., :, 1] + self.c4 * R[..., :, 2]
        T[..., 3, 3] = 1.0
        return T

    @property
    def dual(self) -> bool:
        """True when a1 = b = a2 = 0: the two shoulders of a solution share its θ6."""
        scale = max(abs(self.c2), abs(self.c3), 1e-3)
        return max(abs(self.a1), abs(self.b), abs(self.a2)) <= _PARALLEL_TOL * scale


def crx_from_chain(robot: Robot) -> CRXParameters | None:
    """The CRX parameters of a 6-joint chain, or None when it is not a CRX-type arm.

    At q = 0: axis 1 along the base z axis, axes 2 and 3 parallel and perpendicular to
    it, axis 4 perpendicular to axis 3, axis 5 perpendicular to axis 4 and meeting it (in
    O5), axis 6 perpendicular to axis 5 and meeting it (in O6) away from O5 (an arm whose
    O5 and O6 coincide is OPW), and O5 in the plane of axes 1 and 4 (no lateral offset b,
    as on every CRX). The lengths, offsets and signs follow from the axes as for
    :func:`~trackplan.robots.families.opw.opw_from_chain` (the shared
    :func:`~trackplan.robots.families.opw.arm_parameters`, c4 measured from O6); the model
    is then checked against the chain's forward kinematics on 64 random configurations
    (to 1e-9).
    """
    axes = arm_axes(robot)
    if axes is None:
        return None
    o5, o6 = axes.meet(3, 4), axes.meet(4, 5)
    if o5 is None or o6 is None:
        return None
    tol = _PARALLEL_TOL * axes.scale
    l5 = float((o6 - o5) @ axes.z[4])
    if abs(l5) <= tol:
        return None  # the wrist axes meet: OPW
    arm = arm_parameters(robot, axes, o5, o6)
    if arm is None:
        return None
    if abs(arm.b) > tol:
        # A lateral offset leaves each shoulder's residual undefined where O5 passes within
        # b of axis 1, and its roots near there are missed: such an arm is left numeric.
        return None
    params = CRXParameters(
        a1=arm.a1,
        b=arm.b,
        c1=arm.c1,
        c2=arm.c2,
        a2=arm.a2,
        c3=arm.c3,
        l5=l5,
        c4=arm.c4,
        offsets=arm.offsets,
        signs=arm.signs,
        base=arm.base,
        T_tail=np.eye(4),
    )
    params = replace(params, T_tail=arm.tail(params.forward))
    return params if arm.reproduces(robot, params.forward, params.T_tail) else None


class CRXFamily(TrackedFamily):
    """Every IK solution of a CRX-type arm, tracked along a path
    (:class:`~trackplan.robots.families.base.IKFamily`)."""

    name = "crx"
    n_branches = kern.N_MAX
    redundancy: RedundancyParameter | None = None

    def __init__(self, robot: Robot, params: CRXParameters):
        self.params = params
        g = np.empty(roots.C_SIZE)
        g[: roots.C_THETA0] = (
            params.a1,
            params.a2,
            params.b,
            params.c1,
            params.c2,
            params.c3,
            params.c4,
            params.l5,
            params.base[0],
            params.base[1],
            1.0 if params.dual else 0.0,
            kern.FK_TOL,
        )
        g[roots.C_THETA0 : roots.C_SIGN] = params.offsets
        g[roots.C_SIGN :] = params.signs
        self._geometry = g
        self._tail_inv = np.ascontiguousarray(np.linalg.inv(params.T_tail @ robot.T_flange_tool))
        t = 2.0 * np.pi * np.arange(kern.N_SAMPLES) / kern.N_SAMPLES
        self._cos_t = np.cos(t)
        self._sin_t = np.sin(t)

    def parameters(self) -> dict[str, object]:
        """a1, b, c1, c2, a2, c3, l5, c4 (m), offsets θ0 (rad), signs, base position (m)."""
        p = self.params
        return {
            "a1": p.a1,
            "b": p.b,
            "c1": p.c1,
            "c2": p.c2,
            "a2": p.a2,
            "c3": p.c3,
            "l5": p.l5,
            "c4": p.c4,
            "offsets": list(p.offsets),
            "signs": list(p.signs),
            "base": list(p.base),
        }

    def describe_branch(self, branch: int) -> str:
        """``"solution b of the path's first pose"``."""
        return f"solution {branch} of the path's first pose"

    def solutions(self, T_base_tool: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Every IK solution of tool poses (N, 4, 4), m, joint limits not applied.

        Returns
        -------
        q
            Shape (N, 16, 6), rad in (−π, π], NaN past the found ones; in the order of
            their θ6 root in [0, 2π), then shoulder, then elbow.
        valid
            Shape (N, 16), bool: the found ones first.
        """
        q, valid, _ = self.solutions_with_angle(T_base_tool)
        return q, valid

    def solutions_with_angle(
        self, T_base_tool: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """:meth:`solutions` and, per solution, its root: the model angle θ6 in [0, 2π)
        (shape (N, 16), rad; NaN where not valid)."""
        T = np.ascontiguousarray(T_base_tool, dtype=float).reshape(-1, 4, 4)
        n_poses = T.shape[0]
        q = np.empty((n_poses, kern.N_MAX, 6))
        valid = np.empty((n_poses, kern.N_MAX), dtype=np.bool_)
        angle = np.empty((n_poses, kern.N_MAX))
        kern.crx_solve(
            read_only(self._geometry),
            read_only(self._tail_inv),
            read_only(T),
            read_only(self._cos_t),
            read_only(self._sin_t),
            q,
            valid,
            angle,
        )
        return q, valid, angle

    def seed_solutions(
        self,
        T_base_tool: np.ndarray,
        q_min: np.ndarray,
        q_max: np.ndarray,
        *,
        free: np.ndarray | None = None,
    ) -> tuple[np.ndarray, np.ndarray]:
        """The solutions of poses (N, 4, 4) inside the limits, deduplicated
        (:func:`~trackplan.robots.families.base.wrap_and_deduplicate`), in the order of
        :meth:`solutions`.

        Returns
        -------
        q, found
            Shapes (N, 16, 6) (NaN where not found) and (N, 16).
        """
        if free is not None:
            raise ValueError("this IK family has no redundancy parameter: pass free=None")
        q, valid = self.solutions(T_base_tool)
        return wrap_and_deduplicate(q, valid, q_min, q_max)
