"""Closed-form IK of seven-joint S-R-S arms, parameterised by the arm angle ψ.

An S-R-S arm (KUKA LBR iiwa, Yaskawa SIA, DLR LWR) has a spherical shoulder S (axes 1, 2,
3 meet), an elbow (axis 4) and a spherical wrist W (axes 5, 6, 7 meet). In its zero
position the arm is a straight column along the base z axis; with ``θ = sign · q + θ0``
per joint::

    R07 = Rz(θ1) Ry(θ2) Rz(θ3) Ry(θ4) Rz(θ5) Ry(θ6) Rz(θ7)
    S = (0, 0, d_bs),  E = S + Rz(θ1) Ry(θ2) (0, 0, d_se)
    W = E + Rz(θ1) Ry(θ2) Rz(θ3) Ry(θ4) (0, 0, d_ew),  flange = W + d_wf · R07 e_z
    T_base_tool = Trans(base) · T_srs · T_tail

The parameters, offsets θ0 and signs are derived from the chain at q = 0
(:func:`srs_from_chain`), never typed in; ``T_tail`` carries the flange frame and the tool.

The redundancy is the **arm angle** ψ of Shimizu, Kakuya, Yoon, Kitagaki and Kosuge,
"Analytical Inverse Kinematic Computation for 7-DOF Redundant Manipulators With Joint
Limits and Its Application to Redundancy Resolution", IEEE Transactions on Robotics
24(5):1131–1142, 2008: the rotation about the S→W line of the arm plane (S, E, W) from the
reference plane, the plane of the arm with the same wrist centre and θ3 = 0 (the vertical
plane through S and W). Equivalently, ψ turns the reference elbow axis
``b° = (−sin θ1°, cos θ1°, 0)``, θ1° = atan2(W_y − S_y, W_x − S_x), into the arm's
axis 4 about S→W. The reference plane is undefined with W straight above or below S
(then b° = (0, 1, 0) is used): there the arm angle of a fixed arm jumps.

Branches ``b = 4·shoulder + 2·elbow + wrist``: bit 0 is the model angle θ2, θ4, θ6
≥ 0, bit 1 < 0 (the global configuration GC2, GC4, GC6 of Shimizu et al.); the shoulder and
wrist flips are ``(θ1 + π, −θ2, θ3 + π)`` and ``(θ5 + π, −θ6, θ7 + π)``. At the shoulder
singularity (axes 1 and 3 aligned) joint 1 is put at q1 = 0 (bit 0) or π away; at the
wrist singularity (axes 5 and 7 aligned) joint 5 likewise.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from trackplan.robots.families import _srs_kernels as kern
from trackplan.robots.families.base import (
    FusedClosedForm,
    RedundancyParameter,
    branch_bits,
)
from trackplan.robots.families.opw import _closest_point, _line_distance, _ry, _rz
from trackplan.robots.kinematics import axis_frames, forward_kinematics
from trackplan.robots.model import Robot

_PARALLEL_TOL = 1e-9  # |sin| of the angle between axes that counts as parallel/perpendicular
_N_CHECK = 64  # random configurations the derived model must reproduce
_CHECK_TOL = 1e-9  # m (relative to the reach) and rad
N_JOINTS = kern.N_JOINTS
ARM_ANGLE = RedundancyParameter("arm angle", -math.pi, math.pi)


@dataclass(frozen=True)
class SRSParameters:
    """The S-R-S description of an arm (lengths m, angles rad).

    Attributes
    ----------
    d_bs, d_se, d_ew, d_wf
        Base to shoulder (along axis 1), shoulder to elbow, elbow to wrist, wrist to the
        S-R-S flange (along axis 7).
    offsets
        θ0 per joint: the model angle at q = 0, shape (7,).
    signs
        +1 or −1 per joint: ``θ = sign · q + θ0``, shape (7,).
    base
        Position of joint 1's axis in the base x-y plane, shape (2,).
    T_tail
        Fixed transform from the S-R-S flange to the robot's flange.
    """

    d_bs: float
    d_se: float
    d_ew: float
    d_wf: float
    offsets: tuple[float, ...]
    signs: tuple[float, ...]
    base: tuple[float, float]
    T_tail: np.ndarray

    def forward(self, theta: np.ndarray) -> np.ndarray:
        """S-R-S flange poses (without the base shift or tail), θ (..., 7) → (..., 4, 4)."""
        theta = np.asarray(theta, dtype=float)
        t = [theta[..., j] for j in range(N_JOINTS)]
        R02 = _rz(t[0]) @ _ry(t[1])
        R04 = R02 @ _rz(t[2]) @ _ry(t[3])
        R07 = R04 @ _rz(t[4]) @ _ry(t[5]) @ _rz(t[6])
        T = np.zeros((*theta.shape[:-1], 4, 4))
        T[..., :3, :3] = R07
        T[..., :3, 3] = self.d_se * R02[..., :, 2] + self.d_ew * R04[..., :, 2]
        T[..., :3, 3] += self.d_wf * R07[..., :, 2]
        T[..., 2, 3] += self.d_bs
        T[..., 3, 3] = 1.0
        return T

    def theta(self, q: np.ndarray) -> np.ndarray:
        """Model angles θ = sign · q + θ0 of joint positions q (..., 7), rad."""
        theta: np.ndarray = np.asarray(q, dtype=float) * np.array(self.signs) + np.array(
            self.offsets
        )
        return theta


def _zero_angle(v: np.ndarray) -> tuple[float, float]:
    """The angle t about z that turns e_y onto ±v (v ⊥ z), |t| ≤ π/2, and the sign ±."""
    t = math.atan2(-v[0], v[1])
    if abs(t) > math.pi / 2:
        return math.atan2(v[0], -v[1]), -1.0
    return t, 1.0


def srs_from_chain(robot: Robot) -> SRSParameters | None:
    """The S-R-S parameters of a 7-joint chain, or None when it is not an S-R-S arm.

    At q = 0 (:func:`~trackplan.robots.kinematics.axis_frames`): axes 1, 3, 5, 7 along the
    base z axis and axes 2, 4, 6 perpendicular to it; axes 1, 2, 3 meet at the shoulder S,
    axes 5, 6, 7 at the wrist W, axis 4 meets the S–W line at the elbow (no lateral
    offsets). The lengths, offsets and signs follow from the axes; the model is accepted
    only if it reproduces the chain's own forward kinematics on 64 random configurations
    to 1e-9, so a chain with an axis tilted by a degree or a 5 mm offset is rejected.
    """
    if robot.n_dof != N_JOINTS:
        return None
    frames = axis_frames(robot, np.zeros(N_JOINTS))
    z = frames[1:8, :3, 2]
    p = frames[1:8, :3, 3]
    scale = max(robot.reach, 1e-3)
    ez = np.array([0.0, 0.0, 1.0])
    tol = _PARALLEL_TOL
    if not all(np.linalg.norm(np.cross(z[i], ez)) <= tol for i in (0, 2, 4, 6)):
        return None
    if not all(abs(z[i] @ ez) <= tol for i in (1, 3, 5)):
        return None
    shoulder = _closest_point(p[0], z[0], p[1], z[1])
    wrist = _closest_point(p[4], z[4], p[5], z[5])
    elbow = _closest_point(p[2], z[2], p[3], z[3])
    meets = (
        [_line_distance(shoulder, p[i], z[i]) for i in (0, 1, 2)]
        + [_line_distance(wrist, p[i], z[i]) for i in (2, 4, 5, 6)]
        + [_line_distance(elbow, p[i], z[i]) for i in (2, 3, 4)]
    )
    if max(meets) > tol * scale:
        return None
    d_se = float(np.linalg.norm(elbow - shoulder))
    d_ew = float(np.linalg.norm(wrist - elbow))
    if d_se <= tol * scale or d_ew <= tol * scale:
        return None
    sign = np.ones(N_JOINTS)
    theta0 = np.zeros(N_JOINTS)
    sign[0] = np.sign(z[0] @ ez)
    theta0[0], sign[1] = _zero_angle(z[1])
    F = _rz(theta0[0])
    theta0[1] = 0.0 if (elbow - shoulder) @ ez > 0.0 else math.pi
    F = F @ _ry(theta0[1])
    sign[2] = np.sign(z[2] @ F[:, 2])
    theta0[2], sign[3] = _zero_angle(F.T @ z[3])
    F = F @ _rz(theta0[2])
    theta0[3] = 0.0 if (wrist - elbow) @ F[:, 2] > 0.0 else math.pi
    F = F @ _ry(theta0[3])
    sign[4] = np.sign(z[4] @ F[:, 2])
    theta0[4], sign[5] = _zero_angle(F.T @ z[5])
    F = F @ _rz(theta0[4])
    flange = frames[-1] @ np.linalg.inv(robot.T_flange_tool)
    d_wf = float((flange[:3, 3] - wrist) @ F[:, 2])
    if d_wf < 0.0:
        theta0[5] = math.pi
        d_wf = -d_wf
    F = F @ _ry(theta0[5])
    sign[6] = np.sign(z[6] @ F[:, 2])
    params = SRSParameters(
        d_bs=float(shoulder[2]),
        d_se=d_se,
        d_ew=d_ew,
        d_wf=d_wf,
        offsets=tuple(float(v) for v in np.angle(np.exp(1j * theta0))),
        signs=tuple(float(v) for v in sign),
        base=(float(shoulder[0]), float(shoulder[1])),
        T_tail=np.eye(4),
    )
    shift = _shift(params)
    at_zero = shift @ params.forward(params.theta(np.zeros(N_JOINTS)))
    params = replace(params, T_tail=np.linalg.inv(at_zero) @ flange)
    q = np.random.default_rng(0).uniform(-np.pi, np.pi, (_N_CHECK, N_JOINTS))
    expected = forward_kinematics(robot, q) @ np.linalg.inv(robot.T_flange_tool)
    model = shift @ params.forward(params.theta(q)) @ params.T_tail
    error = np.abs(expected - model)
    if error[..., :3, 3].max() > _CHECK_TOL * scale or error[..., :3, :3].max() > _CHECK_TOL:
        return None
    return params


def _shift(params: SRSParameters) -> np.ndarray:
    """Trans(base): the base shift of the model, (4, 4)."""
    shift = np.eye(4)
    shift[:2, 3] = params.base
    return shift


class SRSFamily(FusedClosedForm):
    """The S-R-S closed form of one robot (:class:`~trackplan.robots.families.base.IKFamily`),
    redundant: every solve takes the arm angle ψ per pose (``free``, rad)."""

    name = "srs"
    _n_joints = 7
    _all_branches = staticmethod(kern.srs_solve)
    _one_branch = staticmethod(kern.srs_solve_branch)
    redundancy: RedundancyParameter | None = ARM_ANGLE

    def __init__(self, robot: Robot, params: SRSParameters):
        self.params = params
        g = np.empty(kern.S_SIZE)
        theta10, theta50 = params.offsets[0], params.offsets[4]
        g[: kern.S_THETA0] = (
            params.d_bs,
            params.d_se,
            params.d_ew,
            params.d_wf,
            params.base[0],
            params.base[1],
            params.d_se**2,
            params.d_ew**2,
            2.0 * params.d_se * params.d_ew,
            math.cos(theta10),
            math.sin(theta10),
            math.cos(theta50),
            math.sin(theta50),
        )
        g[kern.S_THETA0 : kern.S_SIGN] = params.offsets
        g[kern.S_SIGN :] = params.signs
        self._geometry = g
        self._tail_inv = np.ascontiguousarray(np.linalg.inv(params.T_tail @ robot.T_flange_tool))

    def parameters(self) -> dict[str, object]:
        """d_bs, d_se, d_ew, d_wf (m), offsets θ0 (rad), signs, base position (m)."""
        p = self.params
        return {
            "d_bs": p.d_bs,
            "d_se": p.d_se,
            "d_ew": p.d_ew,
            "d_wf": p.d_wf,
            "offsets": list(p.offsets),
            "signs": list(p.signs),
            "base": list(p.base),
        }

    def describe_branch(self, branch: int) -> str:
        """E.g. ``"shoulder +/elbow −/wrist +"``: the signs of the model angles θ2, θ4, θ6
        (with the joint's own sign in brackets where the joint has no offset, e.g.
        ``"elbow − (q4 > 0)"`` on an arm whose axis 4 is reversed)."""
        parts = []
        bits = branch_bits(branch)
        for name, joint, bit in zip(("shoulder", "elbow", "wrist"), (1, 3, 5), bits, strict=True):
            text = f"{name} {'+−'[bit]}"
            if abs(self.params.offsets[joint]) <= 1e-12:
                relation = (("≥", "<"), ("≤", ">"))[self.params.signs[joint] < 0][bit]
                text += f" (q{joint + 1} {relation} 0)"
            parts.append(text)
        return "/".join(parts)

    def arm_angle(self, q: np.ndarray) -> np.ndarray:
        """The arm angle ψ of joint positions q (..., 7), rad in (−π, π], shape (...,).

        The angle about S→W from the reference elbow axis b° to the arm's axis 4
        (module docstring); defined with the arm stretched too (axis 4 is).
        """
        th = self.params.theta(q)
        t1, t2, t3, t4 = th[..., 0], th[..., 1], th[..., 2], th[..., 3]
        c1, s1, c2, s2 = np.cos(t1), np.sin(t1), np.cos(t2), np.sin(t2)
        c3, s3, c4, s4 = np.cos(t3), np.sin(t3), np.cos(t4), np.sin(t4)
        a = np.stack([c1 * s2, s1 * s2, c2], axis=-1)  # R03 e_z
        b = np.stack([-c1 * c2 * s3 - s1 * c3, -s1 * c2 * s3 + c1 * c3, s2 * s3], axis=-1)
        c = np.cross(b, a)  # R03 e_x
        f = s4[..., None] * c + c4[..., None] * a
        w = self.params.d_se * a + self.params.d_ew * f  # W − S
        u = w / np.linalg.norm(w, axis=-1, keepdims=True)
        horizontal = np.hypot(w[..., 0], w[..., 1])
        flat = horizontal > 0.0
        safe = np.where(flat, horizontal, 1.0)
        c1r = np.where(flat, w[..., 0] / safe, 1.0)
        s1r = np.where(flat, w[..., 1] / safe, 0.0)
        b0 = np.stack([-s1r, c1r, np.zeros_like(c1r)], axis=-1)
        n = np.cross(b0, u)
        psi: np.ndarray = np.arctan2(-np.sum(b * n, axis=-1), np.sum(b * b0, axis=-1))
        return psi
