"""Dynamic parameters of a serial robot, in the generic chain convention.

The chain (as a URDF writes it): joint i sits at ``T_parent_joint[i]`` in the frame of the
link before it and turns about ``axis[i]`` (a unit vector in its own frame); the link it
moves has its frame at the joint, rotated with it (the joint's *child frame*). Every
inertial below is expressed in that child frame.

Standard DH converts into it exactly (:func:`dh_chain`, :func:`inertials_from_dh`): the child
frame of joint i is DH frame i-1 turned by ``Rz(q_i + offset_i)``, and DH frame i is that
frame followed by ``Tz(d_i) · Tx(a_i) · Rx(alpha_i)``.

Actuator and friction terms follow roboticstoolbox's DH robots: the torque at joint i is the
rigid-body torque plus ``G² Jm q̈`` plus ``G² B q̇ + |G| Tc±`` (``Tc+`` when ``q̇ > 0``,
``Tc−`` when ``q̇ < 0``, nothing at rest), with ``Jm``, ``B`` and ``Tc`` on the motor side.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike

from trackplan.errors import CaseError

STANDARD_GRAVITY = (0.0, 0.0, -9.81)
"""Gravity in the base frame of a floor-mounted robot, m/s²."""
INERTIA_TOLERANCE = 1e-12
"""Round-off allowed in the PSD and triangle-inequality checks, kg·m²."""


def inertia_matrix(values: ArrayLike) -> np.ndarray:
    """Symmetric inertia matrices from ``(Ixx, Iyy, Izz, Ixy, Iyz, Ixz)``.

    Parameters
    ----------
    values
        Shape (..., 6), kg·m².

    Returns
    -------
    numpy.ndarray
        Shape (..., 3, 3), kg·m².
    """
    v = np.asarray(values, dtype=float)
    xx, yy, zz, xy, yz, xz = np.moveaxis(v, -1, 0)
    return np.stack(
        [np.stack([xx, xy, xz], -1), np.stack([xy, yy, yz], -1), np.stack([xz, yz, zz], -1)], -2
    )


def inertia_problem(inertia: np.ndarray, triangle: bool = True) -> str | None:
    """Why a 3x3 inertia about the centre of mass is not physical, or None when it is.

    A rigid body's inertia is symmetric positive semi-definite and its principal moments
    satisfy the triangle inequality (each at most the sum of the other two).

    Parameters
    ----------
    inertia
        Shape (3, 3), kg·m².
    triangle
        Also require the triangle inequality (fitted parameter sets such as the PUMA560's
        need not meet it; every file input must).
    """
    inertia = np.asarray(inertia, dtype=float)
    if not np.all(np.isfinite(inertia)):
        return "must be finite"
    if not np.allclose(inertia, inertia.T, rtol=0.0, atol=INERTIA_TOLERANCE):
        return "must be symmetric"
    moments = np.linalg.eigvalsh(inertia)
    if moments[0] < -INERTIA_TOLERANCE:
        return (
            "is not positive semi-definite (principal moments "
            + ", ".join(f"{m:.4g}" for m in moments)
            + " kg·m²)"
        )
    if triangle and moments[2] > moments[0] + moments[1] + INERTIA_TOLERANCE:
        return (
            f"breaks the triangle inequality: principal moment {moments[2]:.4g} exceeds "
            f"{moments[0]:.4g} + {moments[1]:.4g} kg·m²"
        )
    return None


@dataclass(frozen=True, eq=False)
class Payload:
    """A rigid load carried at the tool centre point (TCP).

    Attributes
    ----------
    mass
        kg, >= 0.
    com
        Centre of mass in the TCP frame, shape (3,), m.
    inertia
        Inertia about the centre of mass in the TCP frame, shape (3, 3), kg·m² (zero: a
        point mass).
    """

    mass: float
    com: np.ndarray = field(default_factory=lambda: np.zeros(3))
    inertia: np.ndarray = field(default_factory=lambda: np.zeros((3, 3)))

    def __post_init__(self) -> None:
        if not np.isfinite(self.mass) or self.mass < 0:
            raise CaseError(f"payload mass must be >= 0 kg, got {self.mass}", key="payload.mass")
        com = _frozen(self.com, (3,), "payload.com")
        inertia = _frozen(self.inertia, (3, 3), "payload.inertia")
        problem = inertia_problem(inertia)
        if problem:
            raise CaseError(f"inertia {problem}", key="payload.inertia")
        object.__setattr__(self, "mass", float(self.mass))
        object.__setattr__(self, "com", com)
        object.__setattr__(self, "inertia", inertia)


@dataclass(frozen=True, eq=False)
class RobotDynamics:
    """Per-joint dynamic parameters, inertials in the joints' child frames.

    Attributes
    ----------
    mass
        Link masses, shape (n,), kg.
    com
        Link centres of mass in the child frames, shape (n, 3), m.
    inertia
        Link inertias about their centres of mass, child-frame axes, shape (n, 3, 3), kg·m².
    torque_max
        Symmetric torque limits on the link side, shape (n,), N·m.
    motor_inertia
        Jm on the motor side, shape (n,), kg·m² (None given: zeros; the same for the three
        below: ``G = 1``, no friction).
    gear_ratio
        G (motor turns per joint turn, sign as in the source), shape (n,).
    viscous
        B on the motor side, shape (n,), N·m·s/rad.
    coulomb
        ``(Tc+, Tc−)`` on the motor side, shape (n, 2), N·m (Tc− is usually negative).
    motor_constant
        ``k_m = k_t / √R`` of each motor, shape (n,), N·m/√W; the copper loss
        ``Σ (τ / (G k_m))²`` is then in W. None: copper loss in (N·m)² (no motor data).
    gravity
        Gravity in the base frame, shape (3,), m/s².
    payload
        Load at the TCP, or None.
    source
        Where the numbers come from.
    """

    mass: np.ndarray
    com: np.ndarray
    inertia: np.ndarray
    torque_max: np.ndarray
    motor_inertia: np.ndarray | None = None
    gear_ratio: np.ndarray | None = None
    viscous: np.ndarray | None = None
    coulomb: np.ndarray | None = None
    motor_constant: np.ndarray | None = None
    gravity: np.ndarray = field(default_factory=lambda: np.array(STANDARD_GRAVITY))
    payload: Payload | None = None
    source: str = ""

    def __post_init__(self) -> None:
        n = len(np.asarray(self.mass))
        mass = _frozen(self.mass, (n,), "mass")
        negative = np.flatnonzero(mass < 0)
        if negative.size:
            j = int(negative[0])
            raise CaseError(f"mass must be >= 0 kg, got {mass[j]:g}", key=f"joints[{j}].mass")
        object.__setattr__(self, "mass", mass)
        object.__setattr__(self, "com", _frozen(self.com, (n, 3), "com"))
        inertia = _frozen(self.inertia, (n, 3, 3), "inertia")
        for j in range(n):
            problem = inertia_problem(inertia[j], triangle=False)
            if problem:
                raise CaseError(f"inertia {problem}", key=f"joints[{j}].inertia")
        object.__setattr__(self, "inertia", inertia)
        torque_max = _frozen(self.torque_max, (n,), "torque_max")
        not_positive = np.flatnonzero(~(torque_max > 0))
        if not_positive.size:
            j = int(not_positive[0])
            raise CaseError(
                f"torque limit must be > 0 N·m, got {torque_max[j]:g}", key=f"joints[{j}].torque"
            )
        object.__setattr__(self, "torque_max", torque_max)
        defaults = {
            "motor_inertia": np.zeros(n),
            "gear_ratio": np.ones(n),
            "viscous": np.zeros(n),
            "coulomb": np.zeros((n, 2)),
        }
        for key, default in defaults.items():
            value = getattr(self, key)
            object.__setattr__(
                self, key, _frozen(default if value is None else value, default.shape, key)
            )
        if np.any(np.asarray(self.motor_inertia) < 0):
            raise CaseError("motor inertia must be >= 0 kg·m²", key="motor_inertia")
        if np.any(np.asarray(self.gear_ratio) == 0):
            raise CaseError("gear ratio must not be 0", key="gear_ratio")
        if self.motor_constant is not None:
            k_m = _frozen(self.motor_constant, (n,), "motor_constant")
            if np.any(k_m <= 0):
                raise CaseError("motor constant must be > 0 N·m/√W", key="motor_constant")
            object.__setattr__(self, "motor_constant", k_m)
        object.__setattr__(self, "gravity", _frozen(self.gravity, (3,), "gravity"))

    @property
    def n_dof(self) -> int:
        """Number of joints."""
        return len(self.mass)

    @property
    def copper_loss_unit(self) -> str:
        """Unit of the copper loss integral: W·s with motor constants, else (N·m)²·s."""
        return "W·s" if self.motor_constant is not None else "(N·m)²·s"


def _frozen(value: object, shape: tuple[int, ...], key: str) -> np.ndarray:
    """A read-only float copy of ``value`` with the expected shape and finite entries."""
    array = np.array(value, dtype=float)
    if array.shape != shape:
        raise CaseError(f"expected shape {shape}, got {array.shape}", key=key)
    if not np.all(np.isfinite(array)):
        raise CaseError(f"must be finite, got {array.tolist()}", key=key)
    array.flags.writeable = False
    return array


def dh_link_transforms(d: np.ndarray, a: np.ndarray, alpha: np.ndarray) -> np.ndarray:
    """``D_i = Tz(d_i) · Tx(a_i) · Rx(alpha_i)``: from joint i's child frame to DH frame i.

    Parameters
    ----------
    d, a, alpha
        DH parameters, shape (n,), m and rad.

    Returns
    -------
    numpy.ndarray
        Shape (n, 4, 4).
    """
    d, a, alpha = (np.asarray(x, dtype=float) for x in (d, a, alpha))
    D = np.zeros((len(d), 4, 4))
    ca, sa = np.cos(alpha), np.sin(alpha)
    D[:, 0, 0] = 1.0
    D[:, 1, 1], D[:, 1, 2] = ca, -sa
    D[:, 2, 1], D[:, 2, 2] = sa, ca
    D[:, 0, 3], D[:, 2, 3] = a, d
    D[:, 3, 3] = 1.0
    return D


def _rz(angle: np.ndarray) -> np.ndarray:
    """Rotations about z as (n, 4, 4) transforms."""
    c, s = np.cos(angle), np.sin(angle)
    T = np.zeros((len(angle), 4, 4))
    T[:, 0, 0], T[:, 0, 1], T[:, 1, 0], T[:, 1, 1] = c, -s, s, c
    T[:, 2, 2] = T[:, 3, 3] = 1.0
    return T


@dataclass(frozen=True, eq=False)
class JointChain:
    """Kinematics of a serial chain in the generic form.

    Attributes
    ----------
    T_parent_joint
        Joint i's frame in the child frame of joint i-1 (the base for i = 0), shape (n, 4, 4).
    axis
        Joint axes in their own frames, unit vectors, shape (n, 3).
    T_last_flange
        The flange in the child frame of the last joint, shape (4, 4).
    """

    T_parent_joint: np.ndarray
    axis: np.ndarray
    T_last_flange: np.ndarray


def dh_chain(d: np.ndarray, a: np.ndarray, alpha: np.ndarray, offset: np.ndarray) -> JointChain:
    """The generic chain of a standard-DH robot.

    ``A_i = Rz(q_i + offset_i) · D_i`` gives joint i at ``D_{i-1} · Rz(offset_i)`` (the base
    for i = 0: ``Rz(offset_1)``), turning about z; the flange is ``D_n`` after the last
    joint.

    Parameters
    ----------
    d, a, alpha, offset
        DH parameters, shape (n,), m and rad.

    Returns
    -------
    JointChain
    """
    D = dh_link_transforms(d, a, alpha)
    R_offset = _rz(np.asarray(offset, dtype=float))
    T_parent_joint = R_offset.copy()
    T_parent_joint[1:] = D[:-1] @ R_offset[1:]
    axis = np.tile([0.0, 0.0, 1.0], (len(D), 1))
    return JointChain(T_parent_joint=T_parent_joint, axis=axis, T_last_flange=D[-1])


def inertials_from_dh(
    d: np.ndarray,
    a: np.ndarray,
    alpha: np.ndarray,
    com_dh: np.ndarray,
    inertia_dh: np.ndarray,
) -> tuple[np.ndarray, np.ndarray]:
    """Link inertials given in DH link frames (roboticstoolbox's ``r`` and ``I``), in child frames.

    Link i's DH frame is its child frame followed by ``D_i`` (see :func:`dh_link_transforms`):
    ``com = D_i · com_dh`` and ``I = R_i · I_dh · R_iᵀ`` with ``R_i`` the rotation of ``D_i``.

    Parameters
    ----------
    d, a, alpha
        DH parameters, shape (n,), m and rad.
    com_dh
        Centres of mass in DH frames, shape (n, 3), m.
    inertia_dh
        Inertias about the centres of mass, DH-frame axes, shape (n, 3, 3), kg·m².

    Returns
    -------
    tuple of numpy.ndarray
        ``(com, inertia)`` in the child frames, shapes (n, 3) and (n, 3, 3).
    """
    D = dh_link_transforms(d, a, alpha)
    R = D[:, :3, :3]
    com = np.einsum("nij,nj->ni", R, np.asarray(com_dh, dtype=float)) + D[:, :3, 3]
    inertia = R @ np.asarray(inertia_dh, dtype=float) @ np.swapaxes(R, -1, -2)
    return com, inertia


def combine_payload(
    mass: float,
    com: np.ndarray,
    inertia: np.ndarray,
    payload: Payload,
    T_link_tcp: np.ndarray,
) -> tuple[float, np.ndarray, np.ndarray]:
    """One link's inertial with a rigidly attached payload (parallel-axis theorem).

    Parameters
    ----------
    mass, com, inertia
        The link: kg, (3,) m and (3, 3) kg·m² about its centre of mass, link frame.
    payload
        The payload, in the TCP frame.
    T_link_tcp
        The TCP in the link frame, shape (4, 4).

    Returns
    -------
    tuple
        ``(mass, com (3,), inertia (3, 3))`` of the combined body, link frame.
    """
    R = T_link_tcp[:3, :3]
    com_p = R @ payload.com + T_link_tcp[:3, 3]
    inertia_p = R @ payload.inertia @ R.T
    return combine_bodies(
        np.array([mass, payload.mass]),
        np.array([com, com_p]),
        np.array([inertia, inertia_p]),
    )


def combine_bodies(
    mass: np.ndarray, com: np.ndarray, inertia: np.ndarray
) -> tuple[float, np.ndarray, np.ndarray]:
    """The inertial of rigidly joined bodies (parallel-axis theorem), all in one frame.

    Parameters
    ----------
    mass
        Shape (k,), kg.
    com
        Centres of mass, shape (k, 3), m.
    inertia
        Inertias about the centres of mass, shape (k, 3, 3), kg·m².

    Returns
    -------
    tuple
        ``(mass, com (3,), inertia (3, 3))`` of the whole, about its centre of mass (zero
        mass: the origin and a zero inertia).
    """
    mass = np.asarray(mass, dtype=float)
    com = np.asarray(com, dtype=float).reshape(-1, 3)
    inertia = np.asarray(inertia, dtype=float).reshape(-1, 3, 3)
    total = float(mass.sum())
    if total == 0.0:
        return 0.0, np.zeros(3), np.zeros((3, 3))
    com_c = mass @ com / total
    r = com - com_c
    shift = np.einsum("k,ki,ki->k", mass, r, r)[:, None, None] * np.eye(3) - mass[:, None, None] * (
        r[:, :, None] * r[:, None, :]
    )
    return total, com_c, (inertia + shift).sum(axis=0)
