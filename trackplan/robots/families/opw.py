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
from dataclasses import dataclass

import numpy as np

from trackplan.robots.families import _opw_kernels as kern
from trackplan.robots.families.base import FusedClosedForm, describe_bits
from trackplan.robots.kinematics import axis_frames
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


def opw_from_chain(robot: Robot) -> OPWParameters | None:
    """The OPW parameters of a 6-joint chain, or None when it is not an OPW arm.

    The axes at q = 0 are examined: joint 1 along the base z axis, joints 2 and 3
    parallel and perpendicular to it, joint 4 perpendicular to them, and the axes of
    joints 4, 5 and 6 meeting in one point. The lengths, offsets and signs follow from the
    positions of the axes; the result is then checked against the chain's own forward
    kinematics on random configurations (to 1e-9), so a chain that is only nearly OPW
    (an axis tilted by a degree) is rejected.
    """
    if robot.n_dof != 6:
        return None
    frames = axis_frames(robot, np.zeros(6))
    z = frames[1:7, :3, 2]
    p = frames[1:7, :3, 3]
    scale = max(robot.reach, 1e-3)
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
    wrist = _closest_point(p[3], z[3], p[4], z[4])
    if max(_line_distance(wrist, p[i], z[i]) for i in (3, 4, 5)) > tol * scale:
        return None
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
    flange = frames[-1] @ np.linalg.inv(robot.T_flange_tool)
    c4 = float((flange[:3, 3] - wrist) @ (G @ _ry(theta0[4]))[:, 2])
    if c4 < 0.0:
        theta0[4] += math.pi
        c4 = -c4
        sign[5] = -1.0
    theta0 = np.angle(np.exp(1j * theta0))
    if c2 <= tol * scale or math.hypot(a2, c3) <= tol * scale:
        return None
    params = OPWParameters(
        a1=a1,
        a2=a2,
        b=b,
        c1=c1,
        c2=c2,
        c3=c3,
        c4=c4,
        offsets=tuple(float(v) for v in theta0),
        signs=tuple(float(v) for v in sign),
        base=(float(base[0]), float(base[1])),
        T_tail=np.eye(4),
    )
    shift = np.eye(4)
    shift[:2, 3] = base[:2]
    at_zero = shift @ params.forward(theta0)
    T_tail = np.linalg.inv(at_zero) @ flange
    params = OPWParameters(**{**params.__dict__, "T_tail": T_tail})
    q = np.random.default_rng(0).uniform(-np.pi, np.pi, (_N_CHECK, 6))
    from trackplan.robots.kinematics import forward_kinematics

    expected = forward_kinematics(robot, q) @ np.linalg.inv(robot.T_flange_tool)
    model = shift @ params.forward(q * sign + theta0) @ T_tail
    error = np.abs(expected - model)
    if error[..., :3, 3].max() > _CHECK_TOL * scale or error[..., :3, :3].max() > _CHECK_TOL:
        return None
    return params


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
