"""Closed-form IK of ortho-parallel arms with a spherical wrist (OPW).

The geometry of Brandstötter, Angerer and Hofbaur (2014), "An analytical solution of
the inverse kinematics problem of industrial serial manipulators with an ortho-parallel
basis and a spherical wrist": in its zero position the arm points straight up; joint 1
turns about the base z axis; joints 2 and 3 about parallel axes along y; the wrist axes
4, 5, 6 meet at the wrist centre. Seven lengths describe it: a1 and c1 place joint 2,
c2 is the upper arm, a2 and c3 the forearm to the wrist centre, b the lateral offset and
c4 the wrist centre to the flange. With ``θ = sign · q + θ0`` per joint::

    R = Rz(θ1) Ry(θ2 + θ3) Rz(θ4) Ry(θ5) Rz(θ6)
    wrist centre = Rz(θ1) [(a1, b, c1) + Ry(θ2) (0, 0, c2) + Ry(θ2 + θ3) (a2, 0, c3)]
    flange = wrist centre + c4 · R e_z,  T_base_tool = Trans(base) · T_opw · T_tail

The parameters, offsets θ0 and signs are derived from the robot's chain at q = 0
(:func:`opw_from_chain`), never typed in; the fixed ``T_tail`` carries the flange frame
and the tool, so a tool offset is handled exactly.

Branches ``b = 4·shoulder + 2·elbow + wrist``: shoulder 0 puts the wrist centre in front
of joint 1's axis (``x' = +r`` in the arm plane), shoulder 1 behind it; elbow 0 is elbow
up (``sin(θ3 + ψ)`` > 0 in front, < 0 behind, ``ψ = atan2(a2, c3)``); wrist 1 is the
flipped wrist ``(θ4 + π, −θ5, θ6 + π)``. At the wrist singularity (θ5 = 0) joint 4 is
put at q4 = 0 (wrist 0) or π away (wrist 1) and joint 6 takes the whole rotation.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from trackplan.robots.families import _opw_kernels as kern
from trackplan.robots.families.base import FusedClosedForm, describe_bits
from trackplan.robots.kinematics import axis_frames, forward_kinematics
from trackplan.robots.model import Robot

_PARALLEL_TOL = 1e-9  # |sin| of the angle between axes that counts as parallel/perpendicular
_N_CHECK = 64  # random configurations the derived model must reproduce
_CHECK_TOL = 1e-9  # m (and rad, relative to the reach)


@dataclass(frozen=True)
class OPWParameters:
    """The OPW description of an arm (lengths m, angles rad).

    Attributes
    ----------
    a1, a2, b, c1, c2, c3, c4
        The seven lengths of Brandstötter et al. (2014).
    offsets
        θ0 per joint: the OPW angle at q = 0, shape (6,).
    signs
        +1 or −1 per joint: ``θ = sign · q + θ0``, shape (6,).
    base
        Position of joint 1's axis in the base x-y plane, shape (2,).
    T_tail
        Fixed transform from the OPW flange (c4 along axis 6) to the robot's flange.
    """

    a1: float
    a2: float
    b: float
    c1: float
    c2: float
    c3: float
    c4: float
    offsets: tuple[float, ...]
    signs: tuple[float, ...]
    base: tuple[float, float]
    T_tail: np.ndarray

    def forward(self, theta: np.ndarray) -> np.ndarray:
        """OPW flange poses (without the base shift or tail), θ (..., 6) → (..., 4, 4)."""
        theta = np.asarray(theta, dtype=float)
        t1, t2, t23 = theta[..., 0], theta[..., 1], theta[..., 1] + theta[..., 2]
        R = _rz(t1) @ _ry(t23) @ _rz(theta[..., 3]) @ _ry(theta[..., 4]) @ _rz(theta[..., 5])
        x = self.a1 + self.c2 * np.sin(t2) + self.a2 * np.cos(t23) + self.c3 * np.sin(t23)
        z = self.c1 + self.c2 * np.cos(t2) - self.a2 * np.sin(t23) + self.c3 * np.cos(t23)
        c, s = np.cos(t1), np.sin(t1)
        T = np.zeros((*theta.shape[:-1], 4, 4))
        T[..., :3, :3] = R
        T[..., 0, 3] = c * x - s * self.b
        T[..., 1, 3] = s * x + c * self.b
        T[..., 2, 3] = z
        T[..., :3, 3] += self.c4 * R[..., :, 2]
        T[..., 3, 3] = 1.0
        return T


def _rz(t: np.ndarray | float) -> np.ndarray:
    """Rotations about z by angles t (...,), shape (..., 3, 3)."""
    c, s = np.cos(t), np.sin(t)
    R = np.zeros((*np.shape(t), 3, 3))
    R[..., 0, 0], R[..., 0, 1], R[..., 1, 0], R[..., 1, 1] = c, -s, s, c
    R[..., 2, 2] = 1.0
    return R


def _ry(t: np.ndarray | float) -> np.ndarray:
    """Rotations about y by angles t (...,), shape (..., 3, 3)."""
    c, s = np.cos(t), np.sin(t)
    R = np.zeros((*np.shape(t), 3, 3))
    R[..., 0, 0], R[..., 0, 2], R[..., 2, 0], R[..., 2, 2] = c, s, -s, c
    R[..., 1, 1] = 1.0
    return R


def _closest_point(p1: np.ndarray, u1: np.ndarray, p2: np.ndarray, u2: np.ndarray) -> np.ndarray:
    """The midpoint of the common perpendicular of two non-parallel lines."""
    w = p1 - p2
    b = u1 @ u2
    d, e = u1 @ w, u2 @ w
    denom = 1.0 - b * b
    s = (b * e - d) / denom
    t = (e - b * d) / denom
    midpoint: np.ndarray = 0.5 * (p1 + s * u1 + p2 + t * u2)
    return midpoint


def _line_distance(point: np.ndarray, p: np.ndarray, u: np.ndarray) -> float:
    return float(np.linalg.norm(np.cross(point - p, u)))


@dataclass(frozen=True)
class ArmAxes:
    """The axes of a 6-joint chain at q = 0 with an ortho-parallel base: axis 1 along the
    base z axis, axes 2 and 3 parallel and perpendicular to it, each of axes 4, 5, 6
    perpendicular to the one before (the OPW and the CRX structure).

    Attributes
    ----------
    frames
        The axis frames at q = 0 (:func:`~trackplan.robots.kinematics.axis_frames`).
    z, p
        Axis directions and points, shape (6, 3).
    scale
        The robot's reach (at least 1 mm), m: lengths below ``tol · scale`` are zero.
    """

    frames: np.ndarray
    z: np.ndarray
    p: np.ndarray
    scale: float

    def meet(self, i: int, j: int) -> np.ndarray | None:
        """The point where axes i and j (0-based) meet, or None when they pass apart."""
        point = _closest_point(self.p[i], self.z[i], self.p[j], self.z[j])
        apart = max(_line_distance(point, self.p[k], self.z[k]) for k in (i, j))
        return None if apart > _PARALLEL_TOL * self.scale else point


def arm_axes(robot: Robot) -> ArmAxes | None:
    """The :class:`ArmAxes` of a chain, or None when it has not 6 joints or not that
    structure (to :data:`_PARALLEL_TOL`)."""
    if robot.n_dof != 6:
        return None
    frames = axis_frames(robot, np.zeros(6))
    z = frames[1:7, :3, 2]
    ez = np.array([0.0, 0.0, 1.0])
    tol = _PARALLEL_TOL

    def parallel(u: np.ndarray, v: np.ndarray) -> bool:
        return bool(np.linalg.norm(np.cross(u, v)) <= tol)

    def perpendicular(u: np.ndarray, v: np.ndarray) -> bool:
        return bool(abs(u @ v) <= tol)

    if not (
        parallel(z[0], ez)
        and perpendicular(z[1], ez)
        and parallel(z[1], z[2])
        and perpendicular(z[3], z[2])
        and perpendicular(z[4], z[3])
        and perpendicular(z[5], z[4])
    ):
        return None
    return ArmAxes(frames, z, frames[1:7, :3, 3], max(robot.reach, 1e-3))


@dataclass(frozen=True)
class ArmParameters:
    """What :func:`arm_parameters` derives of an ortho-parallel arm (lengths m, angles rad).

    Attributes
    ----------
    a1, a2, b, c1, c2, c3, c4
        The OPW lengths (Brandstötter et al. 2014; c4 measured from the given tip).
    theta0, sign
        The angle at q = 0 and the sign of each joint, shape (6,): ``θ = sign · q + θ0``.
    base
        Position of joint 1's axis in the base x-y plane, shape (2,).
    flange
        The flange at q = 0 without the tool, shape (4, 4).
    """

    a1: float
    a2: float
    b: float
    c1: float
    c2: float
    c3: float
    c4: float
    theta0: np.ndarray
    sign: np.ndarray
    base: tuple[float, float]
    flange: np.ndarray

    @property
    def offsets(self) -> tuple[float, ...]:
        """θ0 per joint, as a tuple."""
        return tuple(float(v) for v in self.theta0)

    @property
    def signs(self) -> tuple[float, ...]:
        """The sign per joint, as a tuple."""
        return tuple(float(v) for v in self.sign)

    @property
    def shift(self) -> np.ndarray:
        """The translation of the base to joint 1's axis, shape (4, 4)."""
        shift = np.eye(4)
        shift[:2, 3] = self.base
        return shift

    def tail(self, forward: Callable[[np.ndarray], np.ndarray]) -> np.ndarray:
        """The fixed transform from a model's flange (``forward`` of the angles at q = 0)
        to the robot's flange, shape (4, 4)."""
        tail: np.ndarray = np.linalg.inv(self.shift @ forward(self.theta0)) @ self.flange
        return tail

    def reproduces(
        self, robot: Robot, forward: Callable[[np.ndarray], np.ndarray], T_tail: np.ndarray
    ) -> bool:
        """Whether the model (``forward`` of angles (..., 6) to flange poses, then
        ``T_tail``) gives the chain's own forward kinematics on :data:`_N_CHECK` random
        configurations, to :data:`_CHECK_TOL` (m, scaled by the reach, and rad)."""
        q = np.random.default_rng(0).uniform(-np.pi, np.pi, (_N_CHECK, 6))
        expected = forward_kinematics(robot, q) @ np.linalg.inv(robot.T_flange_tool)
        model = self.shift @ forward(q * self.sign + self.theta0) @ T_tail
        error = np.abs(expected - model)
        scale = max(robot.reach, 1e-3)
        return bool(
            error[..., :3, 3].max() <= _CHECK_TOL * scale and error[..., :3, :3].max() <= _CHECK_TOL
        )


def arm_parameters(
    robot: Robot, axes: ArmAxes, wrist: np.ndarray, tip: np.ndarray
) -> ArmParameters | None:
    """The OPW lengths, offsets, signs and base of an ortho-parallel arm whose axis 4 meets
    axis 5 at ``wrist`` and whose flange lies along axis 6 from ``tip`` (the wrist centre of
    an OPW arm, O6 of a CRX), or None when the upper arm or the forearm has no length.

    Returns
    -------
    ArmParameters or None
    """
    z, p, scale, tol = axes.z, axes.p, axes.scale, _PARALLEL_TOL
    ez = np.array([0.0, 0.0, 1.0])
    sign = np.ones(6)
    sign[0] = np.sign(z[0] @ ez)
    base = np.array([p[0, 0], p[0, 1], 0.0])
    y_arm = z[1]
    x_arm = np.cross(y_arm, ez)
    a1 = float((p[1] - base) @ x_arm)
    # The arm plane faces the side with a1 ≥ 0; with a1 = 0 (the PUMA), the side that
    # joint 1's zero faces, so that θ1 = q1 + θ0 has |θ0| ≤ π/2.
    facing_back = abs(math.atan2(-y_arm[0], y_arm[1])) > math.pi / 2
    if a1 < -tol * scale or (abs(a1) <= tol * scale and facing_back):
        y_arm, x_arm, a1 = -y_arm, -x_arm, -a1
    sign[1] = np.sign(z[1] @ y_arm)
    sign[2] = np.sign(z[2] @ y_arm)
    theta0 = np.zeros(6)
    theta0[0] = math.atan2(-y_arm[0], y_arm[1])
    c1 = float(p[1, 2])
    x3, z3 = float((p[2] - base) @ x_arm), float(p[2, 2])
    c2 = math.hypot(x3 - a1, z3 - c1)
    theta0[1] = math.atan2(x3 - a1, z3 - c1)
    forearm = wrist - p[2]
    u4 = z[3] if forearm @ z[3] >= 0.0 else -z[3]
    sign[3] = np.sign(u4 @ z[3])
    t23 = math.atan2(u4 @ x_arm, u4 @ ez)
    fx, fz = float(forearm @ x_arm), float(forearm @ ez)
    a2 = fx * math.cos(t23) - fz * math.sin(t23)
    c3 = fx * math.sin(t23) + fz * math.cos(t23)
    theta0[2] = t23 - theta0[1]
    b = float((wrist - base) @ y_arm)
    F = _rz(theta0[0]) @ _ry(t23)
    z5 = F.T @ z[4]
    theta0[3] = math.atan2(-z5[0], z5[1])
    G = F @ _rz(theta0[3])
    z6 = G.T @ z[5]
    theta0[4] = math.atan2(z6[0], z6[2])
    flange = axes.frames[-1] @ np.linalg.inv(robot.T_flange_tool)
    c4 = float((flange[:3, 3] - tip) @ (G @ _ry(theta0[4]))[:, 2])
    if c4 < 0.0:
        theta0[4] += math.pi
        c4 = -c4
        sign[5] = -1.0
    theta0 = np.angle(np.exp(1j * theta0))
    if c2 <= tol * scale or math.hypot(a2, c3) <= tol * scale:
        return None
    base_xy = (float(base[0]), float(base[1]))
    return ArmParameters(a1, a2, b, c1, c2, c3, c4, theta0, sign, base_xy, flange)


def opw_from_chain(robot: Robot) -> OPWParameters | None:
    """The OPW parameters of a 6-joint chain, or None when it is not an OPW arm.

    The axes at q = 0 are examined (:func:`arm_axes`): joint 1 along the base z axis,
    joints 2 and 3 parallel and perpendicular to it, joint 4 perpendicular to them, and the
    axes of joints 4, 5 and 6 meeting in one point. The lengths, offsets and signs follow
    from the positions of the axes (:func:`arm_parameters`); the result is then checked
    against the chain's own forward kinematics on random configurations (to 1e-9), so a
    chain that is only nearly OPW (an axis tilted by a degree) is rejected.
    """
    axes = arm_axes(robot)
    if axes is None:
        return None
    wrist = axes.meet(3, 4)
    if wrist is None or _line_distance(wrist, axes.p[5], axes.z[5]) > _PARALLEL_TOL * axes.scale:
        return None
    arm = arm_parameters(robot, axes, wrist, wrist)
    if arm is None:
        return None
    params = OPWParameters(
        a1=arm.a1,
        a2=arm.a2,
        b=arm.b,
        c1=arm.c1,
        c2=arm.c2,
        c3=arm.c3,
        c4=arm.c4,
        offsets=arm.offsets,
        signs=arm.signs,
        base=arm.base,
        T_tail=np.eye(4),
    )
    T_tail = arm.tail(params.forward)
    params = OPWParameters(**{**params.__dict__, "T_tail": T_tail})
    return params if arm.reproduces(robot, params.forward, T_tail) else None


class OPWFamily(FusedClosedForm):
    """The OPW closed form of one robot (:class:`~trackplan.robots.families.base.IKFamily`)."""

    name = "opw"
    _all_branches = staticmethod(kern.opw_solve)
    _one_branch = staticmethod(kern.opw_solve_branch)

    def __init__(self, robot: Robot, params: OPWParameters):
        self.params = params
        g = np.empty(kern.O_SIZE)
        psi = math.atan2(params.a2, params.c3)
        theta40 = params.offsets[3]
        g[: kern.O_BX] = (
            params.a1,
            params.a2,
            params.b,
            params.c1,
            params.c2,
            params.c3,
            params.c4,
            math.hypot(params.a2, params.c3),
            math.cos(psi),
            math.sin(psi),
            psi,
        )
        g[kern.O_BX : kern.O_THETA0] = (
            params.base[0],
            params.base[1],
            math.cos(theta40),
            math.sin(theta40),
        )
        g[kern.O_THETA0 : kern.O_SIGN] = params.offsets
        g[kern.O_SIGN :] = params.signs
        self._geometry = g
        self._tail_inv = np.ascontiguousarray(np.linalg.inv(params.T_tail @ robot.T_flange_tool))

    def parameters(self) -> dict[str, object]:
        """a1 … c4 (m), offsets θ0 (rad), signs, base position (m)."""
        p = self.params
        return {
            "a1": p.a1,
            "a2": p.a2,
            "b": p.b,
            "c1": p.c1,
            "c2": p.c2,
            "c3": p.c3,
            "c4": p.c4,
            "offsets": list(p.offsets),
            "signs": list(p.signs),
            "base": list(p.base),
        }

    def describe_branch(self, branch: int) -> str:
        """E.g. ``"front/elbow up/q5 ≥ 0"``.

        The wrist bit is named by the sign of q5 when q5 = ±θ5 (no offset on joint 5, as
        on the PUMA560), else ``wrist 0`` / ``wrist flipped``.
        """
        name = describe_bits(branch)
        if abs(self.params.offsets[4]) > 1e-12:
            return name
        positive = self.params.signs[4] > 0
        wrist = (("q5 ≥ 0", "q5 < 0") if positive else ("q5 ≤ 0", "q5 > 0"))[branch & 1]
        return name.rsplit("/", 1)[0] + "/" + wrist
