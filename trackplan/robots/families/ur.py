"""Closed-form IK of UR-type arms: three parallel axes and an offset wrist (Hawkins 2013).

K. P. Hawkins, "Analytic inverse kinematics for the Universal Robots UR-5/UR-10 arms"
(Georgia Tech, 2013). In standard DH (``A_i = Rz(θ_i) Tz(d_i) Tx(a_i) Rx(α_i)``)::

    α = (π/2, 0, 0, π/2, −π/2, 0),  a = (0, a2, a3, 0, 0, 0),  d = (d1, 0, 0, d4, d5, d6)

with ``θ = sign · q + θ0`` per joint and ``T_base_tool = Trans(base) · T_06(θ) · T_tail``.
The DH values, offsets and signs are derived from the chain at q = 0
(:func:`ur_from_chain`); ``T_tail`` carries the flange frame and the tool exactly.

Branches ``b = 4·shoulder + 2·elbow + wrist``: shoulder 0 and 1 are the two solutions
of θ1, wrist 0 has sin θ5 ≥ 0, elbow 0 has sin θ3 ≥ 0. At the wrist singularity
(sin θ5 = 0, axis 6 parallel to axes 2–4) joint 6 is put at q6 = 0 (wrist 0) or π away.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from trackplan.robots.families import _ur_kernels as kern
from trackplan.robots.families.base import FusedClosedForm, branch_bits
from trackplan.robots.kinematics import axis_frames, forward_kinematics
from trackplan.robots.model import Robot

_PARALLEL_TOL = 1e-9
_N_CHECK = 64
_CHECK_TOL = 1e-9
UR_ALPHA = (np.pi / 2, 0.0, 0.0, np.pi / 2, -np.pi / 2, 0.0)


@dataclass(frozen=True)
class URParameters:
    """The UR description of an arm (lengths m, angles rad).

    Attributes
    ----------
    d1, a2, a3, d4, d5, d6
        The DH lengths (a2, a3 ≤ 0 as Universal Robots publishes them).
    offsets
        θ0 per joint, shape (6,).
    signs
        +1 or −1 per joint: ``θ = sign · q + θ0``.
    base
        Position of joint 1's axis in the base x-y plane, shape (2,).
    T_tail
        Fixed transform from DH frame 6 to the robot's flange.
    """

    d1: float
    a2: float
    a3: float
    d4: float
    d5: float
    d6: float
    offsets: tuple[float, ...]
    signs: tuple[float, ...]
    base: tuple[float, float]
    T_tail: np.ndarray

    def dh_robot(self) -> Robot:
        """The bare DH chain of these parameters (offsets θ0, no signs, no tail)."""
        zeros = np.zeros(6)
        return Robot.from_dh(
            name="ur-model",
            d=np.array([self.d1, 0.0, 0.0, self.d4, self.d5, self.d6]),
            a=np.array([0.0, self.a2, self.a3, 0.0, 0.0, 0.0]),
            alpha=np.array(UR_ALPHA),
            offset=np.array(self.offsets),
            q_min=zeros - np.pi,
            q_max=zeros + np.pi,
            v_max=zeros + 1,
            a_max=zeros + 1,
            j_max=zeros + 1,
        )


def _angle_about(u: np.ndarray, v: np.ndarray, axis: np.ndarray) -> float:
    """The angle from u to v about ``axis`` (all ⊥ axis), rad."""
    return math.atan2(float(np.cross(u, v) @ axis), float(u @ v))


def _meet(
    p1: np.ndarray, u1: np.ndarray, p2: np.ndarray, u2: np.ndarray
) -> tuple[np.ndarray, float]:
    """Closest point of line 2 to line 1 (non-parallel), and the distance between the lines."""
    w = p1 - p2
    b = u1 @ u2
    d, e = u1 @ w, u2 @ w
    denom = 1.0 - b * b
    s = (b * e - d) / denom
    t = (e - b * d) / denom
    return p2 + t * u2, float(np.linalg.norm(p1 + s * u1 - p2 - t * u2))


def ur_from_chain(robot: Robot) -> URParameters | None:
    """The UR parameters of a 6-joint chain, or None when it is not a UR-type arm.

    At q = 0: joint 1 along the base z axis; joints 2, 3, 4 parallel and perpendicular to
    it, axis 2 meeting axis 1; axis 5 perpendicular to and meeting axis 4; axis 6
    perpendicular to and meeting axis 5. The DH frames are built on these lines and the
    result is checked against the chain's forward kinematics on random configurations.
    """
    if robot.n_dof != 6:
        return None
    frames = axis_frames(robot, np.zeros(6))
    z = frames[1:7, :3, 2]
    p = frames[1:7, :3, 3]
    scale = max(robot.reach, 1e-3)
    tol = _PARALLEL_TOL
    ez = np.array([0.0, 0.0, 1.0])

    def parallel(u: np.ndarray, v: np.ndarray) -> bool:
        return bool(np.linalg.norm(np.cross(u, v)) <= tol)

    def perpendicular(u: np.ndarray, v: np.ndarray) -> bool:
        return bool(abs(u @ v) <= tol)

    if not (
        parallel(z[0], ez)
        and perpendicular(z[1], ez)
        and parallel(z[1], z[2])
        and parallel(z[1], z[3])
        and perpendicular(z[4], z[3])
        and perpendicular(z[5], z[4])
    ):
        return None
    sign = np.ones(6)
    sign[0] = np.sign(z[0] @ ez)
    base = np.array([p[0, 0], p[0, 1], 0.0])
    u = z[1]
    o1, gap = _meet(base, ez, p[1], u)
    if gap > tol * scale:
        return None
    d1 = float(o1[2])
    sign[2] = np.sign(z[2] @ u)
    sign[3] = np.sign(z[3] @ u)
    x1 = np.cross(ez, u)

    def foot(point: np.ndarray) -> np.ndarray:  # the axis through point, in o1's plane ⊥ u
        projected: np.ndarray = point - ((point - o1) @ u) * u
        return projected

    o2, o3 = foot(p[2]), foot(p[3])
    if np.linalg.norm(o2 - o1) <= tol * scale or np.linalg.norm(o3 - o2) <= tol * scale:
        return None
    x2 = -(o2 - o1) / np.linalg.norm(o2 - o1)
    a2 = -float(np.linalg.norm(o2 - o1))
    x3 = -(o3 - o2) / np.linalg.norm(o3 - o2)
    a3 = -float(np.linalg.norm(o3 - o2))
    o4, gap = _meet(p[4], z[4], p[3], u)
    if gap > tol * scale:
        return None
    d4 = float((o4 - o3) @ u)
    z4 = z[4]
    x4 = np.cross(u, z4)
    o5, gap = _meet(p[5], z[5], p[4], z4)
    if gap > tol * scale:
        return None
    d5 = float((o5 - o4) @ z4)
    z5 = z[5]
    x5 = np.cross(z5, z4)
    flange = frames[-1] @ np.linalg.inv(robot.T_flange_tool)
    d6 = float((flange[:3, 3] - o5) @ z5)
    theta0 = np.array(
        [
            math.atan2(x1[1], x1[0]),
            _angle_about(x1, x2, u),
            _angle_about(x2, x3, u),
            _angle_about(x3, x4, u),
            _angle_about(x4, x5, z4),
            0.0,
        ]
    )
    frame6 = np.eye(4)
    frame6[:3, 0], frame6[:3, 1], frame6[:3, 2] = x5, np.cross(z5, x5), z5
    frame6[:3, 3] = o5 + d6 * z5
    params = URParameters(
        d1=d1,
        a2=a2,
        a3=a3,
        d4=d4,
        d5=d5,
        d6=d6,
        offsets=tuple(float(v) for v in theta0),
        signs=tuple(float(v) for v in sign),
        base=(float(base[0]), float(base[1])),
        T_tail=np.linalg.inv(frame6) @ flange,
    )
    shift = np.eye(4)
    shift[:2, 3] = base[:2]
    model = params.dh_robot()
    at_zero = shift @ forward_kinematics(model, np.zeros(6))
    params = replace(params, T_tail=np.linalg.inv(at_zero) @ flange)
    q = np.random.default_rng(0).uniform(-np.pi, np.pi, (_N_CHECK, 6))
    expected = forward_kinematics(robot, q) @ np.linalg.inv(robot.T_flange_tool)
    got = shift @ forward_kinematics(model, q * sign) @ params.T_tail
    error = np.abs(expected - got)
    if error[..., :3, 3].max() > _CHECK_TOL * scale or error[..., :3, :3].max() > _CHECK_TOL:
        return None
    return params


class URFamily(FusedClosedForm):
    """The UR closed form of one robot (:class:`~trackplan.robots.families.base.IKFamily`)."""

    name = "ur"
    _all_branches = staticmethod(kern.ur_solve)
    _one_branch = staticmethod(kern.ur_solve_branch)

    def __init__(self, robot: Robot, params: URParameters):
        self.params = params
        g = np.empty(kern.U_SIZE)
        theta60 = params.offsets[5]
        g[: kern.U_THETA0] = (
            params.d1,
            params.a2,
            params.a3,
            params.d4,
            params.d5,
            params.d6,
            params.base[0],
            params.base[1],
            math.cos(theta60),
            math.sin(theta60),
        )
        g[kern.U_THETA0 : kern.U_SIGN] = params.offsets
        g[kern.U_SIGN :] = params.signs
        self._geometry = g
        self._tail_inv = np.ascontiguousarray(np.linalg.inv(params.T_tail @ robot.T_flange_tool))

    def parameters(self) -> dict[str, object]:
        """d1 … d6 (m), offsets θ0 (rad), signs, base position (m)."""
        p = self.params
        return {
            "d1": p.d1,
            "a2": p.a2,
            "a3": p.a3,
            "d4": p.d4,
            "d5": p.d5,
            "d6": p.d6,
            "offsets": list(p.offsets),
            "signs": list(p.signs),
            "base": list(p.base),
        }

    def describe_branch(self, branch: int) -> str:
        """E.g. ``"shoulder 0/sin θ3 ≥ 0/sin θ5 ≥ 0"``."""
        shoulder, elbow, wrist = branch_bits(branch)
        return "/".join(
            (
                f"shoulder {shoulder}",
                ("sin θ3 ≥ 0", "sin θ3 < 0")[elbow],
                ("sin θ5 ≥ 0", "sin θ5 < 0")[wrist],
            )
        )
