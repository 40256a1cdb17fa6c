"""Closed-form IK of Panda-type 7-joint arms, joint 7 given (He & Liu 2021).

Y. He and S. Liu, "Analytical Inverse Kinematics for Franka Emika Panda – a Geometrical
Solver for 7-DOF Manipulators with Unconventional Design", 9th International Conference
on Control, Mechatronics and Automation (ICCMA), IEEE, 2021. The arm in modified
(Craig) DH, ``T_{i−1,i} = Rx(α_i) Tx(a_i) Rz(θ_i) Tz(d_i)``, listed per joint i::

    α = (0, −π/2, π/2, π/2, −π/2, π/2, π/2)
    a = (0, 0, 0, a4, a5, 0, a7),  d = (d1, 0, d3, 0, d5, 0, 0)

with ``θ = sign · q + θ0`` per joint and ``T_base_tool = Trans(base) · T_07(θ) · T_tail``
(the Panda: a4 = 0.0825, a5 = −0.0825, a7 = 0.088, d1 = 0.333, d3 = 0.316, d5 = 0.384 m and
the flange 0.107 m along z7). Axes 1, 2 and 3 meet in the shoulder point p2, axes 5 and 6 in
O6; the offsets a4, a5 (the elbow) and a7 (the wrist) make the arm not S-R-S. The DH values,
offsets and signs are derived from the chain at q = 0 (:func:`panda_from_chain`);
``T_tail`` carries the flange frame and the tool exactly.

Joint 7 is the free parameter (``free``, its position per pose, rad): with θ7 given, DH
frame 6 is known and the other six joints follow in closed form, eight solutions in all
(He & Liu keep the four with θ4 in the Panda's limits; the other elbow is exact too).
Branches ``b = 4·shoulder + 2·elbow + wrist``:

- elbow 0 has ``sin(θ4 − φ4) ≤ 0`` (``φ4 = atan2(B, A)``, θ4 = φ4 is the stretched
  arm): the Panda's own elbow, joint 4 in [−3.07, −0.07] rad; elbow 1 the other;
- wrist 0 and 1 are the two θ6 with ``z5 · (O6 − p2)`` as the elbow requires
  (``θ6 = ψ ± δ``, wrist 0 the +);
- shoulder 1 is ``(θ1 + π, −θ2, θ3 + π)`` of shoulder 0, which has ``sin θ2 ≥ 0``.

Branch quantities (``aux``), for joint 7 fixed: the shoulder measure |sin θ2| (zero where
axis 3 lies on axis 1: θ1 is then put at q1 = 0, or π away for shoulder 1, and θ3 takes
the rotation); the elbow measure |sin(θ4 − φ4)| (zero with the arm stretched or folded);
the wrist vector ``±√(ρ² − c_z²) / L · z6`` (ρ: the length of O6 − p2 across axis 6, c_z
its component the elbow puts along z5, L its length), zero where the two θ6 meet — axis 6
in the plane of axes 3 and 5, or axis 5 through p2 — and reversing (the sign of
``(z5 × (O6 − p2)) · y3``) where a path passes through the latter. There frame 3 turns
freely about axis 5; y3 is put at −x5. Poses out of reach (and NaN poses or q7) are not
valid on any branch; joint limits are not applied (:meth:`PandaFamily.seed_solutions`
applies them).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from trackplan.robots.families import _panda_kernels as kern
from trackplan.robots.families.base import (
    FusedClosedForm,
    RedundancyParameter,
    branch_bits,
)
from trackplan.robots.kinematics import axis_frames, forward_kinematics
from trackplan.robots.model import Robot

_TOL = 1e-9  # |sin| of an angle that counts as parallel/perpendicular (and × reach, m)
_N_CHECK = 64
_CHECK_TOL = 1e-9
PANDA_ALPHA = (0.0, -np.pi / 2, np.pi / 2, np.pi / 2, -np.pi / 2, np.pi / 2, np.pi / 2)


@dataclass(frozen=True)
class PandaParameters:
    """The Panda description of an arm (modified DH, lengths m, angles rad).

    Attributes
    ----------
    d1, d3, d5
        The DH d of joints 1, 3, 5 (d2 = d4 = d6 = d7 = 0).
    a4, a5, a7
        The DH a of joints 4, 5, 7 (a1 = a2 = a3 = a6 = 0).
    d_flange
        The flange's distance along z7 (``T_tail``'s z translation).
    offsets
        θ0 per joint, shape (7,).
    signs
        +1 or −1 per joint: ``θ = sign · q + θ0``.
    base
        Position of joint 1's axis in the base x-y plane, shape (2,).
    T_tail
        Fixed transform from DH frame 7 to the robot's flange.
    """

    d1: float
    d3: float
    d5: float
    a4: float
    a5: float
    a7: float
    d_flange: float
    offsets: tuple[float, ...]
    signs: tuple[float, ...]
    base: tuple[float, float]
    T_tail: np.ndarray

    def forward(self, theta: np.ndarray) -> np.ndarray:
        """DH frame 7 in the base (without the tail), θ (..., 7) → (..., 4, 4)."""
        theta = np.asarray(theta, dtype=float)
        a = (0.0, 0.0, 0.0, self.a4, self.a5, 0.0, self.a7)
        d = (self.d1, 0.0, self.d3, 0.0, self.d5, 0.0, 0.0)
        T = np.broadcast_to(np.eye(4), (*theta.shape[:-1], 4, 4)).copy()
        T[..., 0, 3], T[..., 1, 3] = self.base
        for i in range(7):
            ca, sa = math.cos(PANDA_ALPHA[i]), math.sin(PANDA_ALPHA[i])
            ct, st = np.cos(theta[..., i]), np.sin(theta[..., i])
            A = np.zeros((*theta.shape[:-1], 4, 4))
            A[..., 0, 0], A[..., 0, 1], A[..., 0, 3] = ct, -st, a[i]
            A[..., 1, 0], A[..., 1, 1], A[..., 1, 2] = st * ca, ct * ca, -sa
            A[..., 1, 3] = -sa * d[i]
            A[..., 2, 0], A[..., 2, 1], A[..., 2, 2] = st * sa, ct * sa, ca
            A[..., 2, 3] = ca * d[i]
            A[..., 3, 3] = 1.0
            T = T @ A
        return T


def _angle_about(u: np.ndarray, v: np.ndarray, axis: np.ndarray) -> float:
    """The angle from u to v about ``axis`` (all ⊥ axis), rad."""
    return math.atan2(float(np.cross(u, v) @ axis), float(u @ v))


def _feet(
    p1: np.ndarray, u1: np.ndarray, p2: np.ndarray, u2: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """The feet of the common perpendicular of two non-parallel lines (on line 1, line 2)."""
    w = p1 - p2
    b = u1 @ u2
    d, e = u1 @ w, u2 @ w
    denom = 1.0 - b * b
    s = (b * e - d) / denom
    t = (e - b * d) / denom
    return p1 + s * u1, p2 + t * u2


def panda_from_chain(robot: Robot) -> PandaParameters | None:
    """The Panda parameters of a 7-joint chain, or None when it is not a Panda-type arm.

    At q = 0: axis 1 along the base z axis; each axis perpendicular to the next; axes 1,
    2 and 3 meeting in one point; axes 5 and 6 meeting; the common perpendiculars of axes
    3–4 and 4–5 meeting axis 4 in one point (d4 = 0) and those of axes 5–6 and 6–7
    meeting axis 6 in one point (d6 = 0). An arm with a4 = a5 = a7 = 0 is S-R-S (its own
    family) and is not taken. The DH frames are built on these lines (every DH z along
    the chain's axis, except z1 along +z and z4, z5, z7 turned where that gives a4 ≥ 0,
    a5 ≤ 0, a7 ≥ 0: a sign −1) and the result is checked against the chain's forward
    kinematics on 64 random configurations (in the limits) to 1e-9.
    """
    if robot.n_dof != 7:
        return None
    frames = axis_frames(robot, np.zeros(7))
    z = frames[1:8, :3, 2].copy()
    p = frames[1:8, :3, 3]
    scale = max(robot.reach, 1e-3)
    ez = np.array([0.0, 0.0, 1.0])
    if np.linalg.norm(np.cross(z[0], ez)) > _TOL:
        return None
    if any(abs(z[i] @ z[i + 1]) > _TOL for i in range(6)):
        return None
    sign = np.ones(7)
    sign[0] = np.sign(z[0] @ ez)
    z[0] = ez
    base = np.array([p[0, 0], p[0, 1], 0.0])
    p2, foot2 = _feet(base, z[0], p[1], z[1])
    if np.linalg.norm(p2 - foot2) > _TOL * scale:
        return None
    if np.linalg.norm(np.cross(p2 - p[2], z[2])) > _TOL * scale:  # axis 3 through p2
        return None
    o3, f4 = _feet(p2, z[2], p[3], z[3])
    f4b, g5 = _feet(p[3], z[3], p[4], z[4])
    o5, o5b = _feet(p[4], z[4], p[5], z[5])
    h6, f7 = _feet(p[5], z[5], p[6], z[6])
    if (
        np.linalg.norm(o5 - o5b) > _TOL * scale  # axes 5 and 6 meet
        or abs((f4b - f4) @ z[3]) > _TOL * scale  # d4 = 0
        or abs((h6 - o5) @ z[5]) > _TOL * scale  # d6 = 0
    ):
        return None
    # DH z along the chain's axes, but z4, z5, z7 turned where that makes a4 ≥ 0, a5 ≤ 0
    # and a7 ≥ 0, as Franka publishes them (each sets the x that a is measured along).
    a4 = float((f4 - o3) @ np.cross(z[2], z[3]))
    if a4 < 0.0:
        z[3], sign[3], a4 = -z[3], -1.0, -a4
    a5 = float((g5 - f4) @ np.cross(z[4], z[3]))  # α5 = −π/2: x4 = z5 × z4
    if a5 > 0.0:
        z[4], sign[4], a5 = -z[4], -1.0, -a5
    a7 = float((f7 - h6) @ np.cross(z[5], z[6]))
    if a7 < 0.0:
        z[6], sign[6], a7 = -z[6], -1.0, -a7
    if max(abs(a4), abs(a5), abs(a7)) <= _TOL * scale:
        return None  # S-R-S
    x = [
        np.cross(z[1], z[0]),  # α2 = −π/2: z2 = y1
        np.cross(z[1], z[2]),  # α3 = π/2: z3 = −y2
        np.cross(z[2], z[3]),
        np.cross(z[4], z[3]),
        np.cross(z[4], z[5]),
        np.cross(z[5], z[6]),
    ]
    theta0 = [math.atan2(x[0][1], x[0][0])]
    theta0 += [_angle_about(x[i - 1], x[i], z[i]) for i in range(1, 6)]
    theta0.append(0.0)
    flange = frames[-1] @ np.linalg.inv(robot.T_flange_tool)
    params = PandaParameters(
        d1=float(p2[2]),
        d3=float((o3 - p2) @ z[2]),
        d5=float((o5 - g5) @ z[4]),
        a4=a4,
        a5=a5,
        a7=a7,
        d_flange=0.0,
        offsets=tuple(float(v) for v in theta0),
        signs=tuple(float(v) for v in sign),
        base=(float(base[0]), float(base[1])),
        T_tail=np.eye(4),
    )
    tail = np.linalg.inv(params.forward(np.array(theta0))) @ flange
    params = replace(params, T_tail=tail, d_flange=float(tail[2, 3]))
    q = np.random.default_rng(0).uniform(robot.q_min, robot.q_max, (_N_CHECK, 7))
    expected = forward_kinematics(robot, q) @ np.linalg.inv(robot.T_flange_tool)
    got = params.forward(q * sign + theta0) @ tail
    error = np.abs(expected - got)
    if error[..., :3, 3].max() > _CHECK_TOL * scale or error[..., :3, :3].max() > _CHECK_TOL:
        return None
    return params


class PandaFamily(FusedClosedForm):
    """The Panda closed form of one robot, joint 7 free
    (:class:`~trackplan.robots.families.base.IKFamily`)."""

    name = "panda"
    _n_joints = 7
    _all_branches = staticmethod(kern.panda_solve)
    _one_branch = staticmethod(kern.panda_solve_branch)
    redundancy: RedundancyParameter | None

    def __init__(self, robot: Robot, params: PandaParameters):
        self.params = params
        self.redundancy = RedundancyParameter(
            "joint 7", float(robot.q_min[6]), float(robot.q_max[6]), joint=6
        )
        A = 2.0 * (params.a4 * params.a5 + params.d3 * params.d5)
        B = 2.0 * (params.d3 * params.a5 - params.a4 * params.d5)
        g = np.empty(kern.P_SIZE)
        g[: kern.P_THETA0] = (
            params.d1,
            params.d3,
            params.d5,
            params.a4,
            params.a5,
            params.a7,
            params.base[0],
            params.base[1],
            params.a4**2 + params.a5**2 + params.d3**2 + params.d5**2,
            A,
            B,
            math.hypot(A, B),
            math.cos(params.offsets[0]),
            math.sin(params.offsets[0]),
        )
        g[kern.P_THETA0 : kern.P_SIGN] = params.offsets
        g[kern.P_SIGN :] = params.signs
        self._geometry = g
        self._tail_inv = np.ascontiguousarray(np.linalg.inv(params.T_tail @ robot.T_flange_tool))

    def parameters(self) -> dict[str, object]:
        """d1, d3, d5, a4, a5, a7, the flange distance (m), offsets θ0 (rad), signs, base
        position (m)."""
        p = self.params
        return {
            "d1": p.d1,
            "d3": p.d3,
            "d5": p.d5,
            "a4": p.a4,
            "a5": p.a5,
            "a7": p.a7,
            "d_flange": p.d_flange,
            "offsets": list(p.offsets),
            "signs": list(p.signs),
            "base": list(p.base),
        }

    def describe_branch(self, branch: int) -> str:
        """E.g. ``"sin θ2 ≥ 0/elbow 0 (θ4 < φ4)/θ6 = ψ + δ"``."""
        shoulder, elbow, wrist = branch_bits(branch)
        return "/".join(
            (
                ("sin θ2 ≥ 0", "sin θ2 < 0")[shoulder],
                ("elbow 0 (θ4 < φ4)", "elbow 1 (θ4 > φ4)")[elbow],
                ("θ6 = ψ + δ", "θ6 = ψ − δ")[wrist],
            )
        )
