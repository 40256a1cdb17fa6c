"""The robot model: a generic serial chain of revolute joints with per-joint limits.

The chain is written the way a URDF writes it (``docs/robots.md``): joint i has a fixed
transform ``origin_i`` from the frame of joint i − 1 (the base frame for i = 1) and a unit
axis ``axis_i`` in its own frame, so that

    ``T_0_i(q) = T_0_{i-1}(q) · origin_i · Rot(axis_i, q_i)``,
    ``T_base_tool(q) = T_0_n(q) · T_tip · T_flange_tool``.

``T_tip`` is the fixed transform from the last joint's frame to the flange (the tip link);
``T_flange_tool`` is the user's tool. A standard-DH table converts into this form
(:meth:`Robot.from_dh`). The model is immutable and shared; every computation keeps its
scratch space local (pinocchio's Model/Data split).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from functools import cached_property

import numpy as np

from trackplan._kernels import read_only
from trackplan.errors import CaseError
from trackplan.robots._kernels import fk_flat
from trackplan.robots.collision import Capsules
from trackplan.robots.controller import ControllerConvention
from trackplan.robots.dynamics_parameters import RobotDynamics
from trackplan.robots.visuals import LinkVisual

LIMIT_KINDS = ("position", "velocity", "acceleration", "jerk")
DH_COLUMNS = ("d", "a", "alpha", "offset")
REACH_SAMPLES = 20_000
"""Configurations sampled to estimate :attr:`Robot.reach`."""
PLACEMENT_REACH_FRACTIONS = (0.15, 0.9)
"""Default placement reach range as fractions of :attr:`Robot.reach`."""
_AXIS_TOL = 1e-9


def _frozen(value: np.ndarray) -> np.ndarray:
    array = np.array(value, dtype=float)
    array.flags.writeable = False
    return array


def rotation_z_to(axis: np.ndarray) -> np.ndarray:
    """A rotation matrix (3, 3) whose z column is the unit vector ``axis``.

    The identity for +z, a half turn about x for −z, else the shortest rotation.
    """
    z = np.array([0.0, 0.0, 1.0])
    c = float(np.dot(z, axis))
    if c > 1.0 - 1e-15:
        return np.eye(3)
    if c < -1.0 + 1e-15:
        return np.diag([1.0, -1.0, -1.0])
    v = np.cross(z, axis)
    s = np.linalg.norm(v)
    k = v / s
    K = np.array([[0.0, -k[2], k[1]], [k[2], 0.0, -k[0]], [-k[1], k[0], 0.0]])
    R: np.ndarray = np.eye(3) + s * K + (1.0 - c) * (K @ K)
    return R


def dh_transform(d: float, a: float, alpha: float) -> np.ndarray:
    """``Tz(d) · Tx(a) · Rx(alpha)``, shape (4, 4)."""
    ca, sa = math.cos(alpha), math.sin(alpha)
    return np.array(
        [[1.0, 0.0, 0.0, a], [0.0, ca, -sa, 0.0], [0.0, sa, ca, d], [0.0, 0.0, 0.0, 1.0]]
    )


def rz(theta: float) -> np.ndarray:
    """Rotation about z, shape (4, 4)."""
    c, s = math.cos(theta), math.sin(theta)
    return np.array([[c, -s, 0.0, 0.0], [s, c, 0.0, 0.0], [0.0, 0.0, 1.0, 0.0], [0, 0, 0, 1.0]])


IK_FAMILIES = ("auto", "opw", "ur", "srs", "panda", "crx", "numeric")
"""The IK family names a robot file's ``ik.family`` takes (``docs/robots.md``)."""


@dataclass(frozen=True)
class IKChoice:
    """A robot file's ``ik:`` block: which IK family solves the arm.

    Attributes
    ----------
    family
        One of :data:`IK_FAMILIES`; ``auto`` detects it from the chain.
    free_joint
        For a 7-joint arm in the numeric family, the joint (0-based) that carries the
        redundancy; None: the family's default.
    """

    family: str = "auto"
    free_joint: int | None = None


@dataclass(frozen=True, eq=False)
class Robot:
    """A serial robot of revolute joints.

    Attributes
    ----------
    name
        Robot name.
    origins
        Fixed transform of each joint from the previous joint's frame, shape (n, 4, 4), m.
    axes
        Unit axis of each joint in its own frame, shape (n, 3).
    q_min, q_max
        Joint position limits, shape (n,), rad.
    v_max, a_max, j_max
        Symmetric joint velocity, acceleration and jerk limits, shape (n,),
        rad/s, rad/s², rad/s³.
    T_tip
        Fixed transform from the last joint's frame to the flange, shape (4, 4).
    T_flange_tool
        Tool transform in the flange, shape (4, 4).
    source
        Where the numbers come from (free text, shown by ``trackplan robots``).
    joint_names
        One name per joint; default ``q1 … qn`` (also used in exported trajectories).
    assumptions
        Limits that were assumed rather than published, one sentence each (recorded in
        results).
    dh
        The standard-DH table the chain was built from, shape (n, 4): d, a, alpha,
        offset (m, rad); None for a chain read from a URDF.
    placement_reach
        The default range [min, max] of the path's distance from the base origin for a
        placement search, m; None: derived from :attr:`reach` (:attr:`default_placement_reach`).
    dynamics
        Masses, inertias, actuators, friction and torque limits, or None when the robot has
        no published dynamics (then it has no torque check).
    collision
        Link capsules on frames 0 (base) to n (:mod:`trackplan.robots.collision`), or None
        when the robot has no link geometry (then a cell case must give ``cell.links``).
    controller
        How the robot's controller counts the joints and where its world frame is
        (:class:`~trackplan.robots.controller.ControllerConvention`); None: as the model
        (:attr:`convention` gives the identity then).
    visuals
        How the links look: triangle meshes on frames 0 (base) to n
        (:class:`~trackplan.robots.visuals.LinkVisual`), read from a URDF's ``<visual>``
        elements; None when the robot has none (the report then draws its capsules).
    ik
        Which IK family solves the arm (a robot file's ``ik:`` block; default: detected).
    """

    name: str
    origins: np.ndarray
    axes: np.ndarray
    q_min: np.ndarray
    q_max: np.ndarray
    v_max: np.ndarray
    a_max: np.ndarray
    j_max: np.ndarray
    T_tip: np.ndarray = field(default_factory=lambda: np.eye(4))
    T_flange_tool: np.ndarray = field(default_factory=lambda: np.eye(4))
    source: str = ""
    joint_names: tuple[str, ...] = ()
    assumptions: tuple[str, ...] = ()
    dh: np.ndarray | None = None
    dynamics: RobotDynamics | None = None
    placement_reach: tuple[float, float] | None = None
    collision: Capsules | None = None
    controller: ControllerConvention | None = None
    visuals: tuple[LinkVisual, ...] | None = None
    ik: IKChoice = field(default_factory=IKChoice)

    def __post_init__(self) -> None:
        origins = np.array(self.origins, dtype=float)
        if origins.ndim != 3 or origins.shape[1:] != (4, 4) or origins.shape[0] < 1:
            raise CaseError(f"origins must have shape (n, 4, 4), got {origins.shape}")
        n = origins.shape[0]
        axes = np.array(self.axes, dtype=float)
        if axes.shape != (n, 3):
            raise CaseError(f"axes must have shape ({n}, 3), got {axes.shape}")
        norms = np.linalg.norm(axes, axis=1)
        if not np.all(np.isfinite(axes)) or np.any(norms < _AXIS_TOL):
            raise CaseError(f"every joint axis must be a non-zero vector, got {axes.tolist()}")
        object.__setattr__(self, "origins", _frozen(origins))
        object.__setattr__(self, "axes", _frozen(axes / norms[:, None]))
        for key in ("q_min", "q_max", "v_max", "a_max", "j_max"):
            value = np.array(getattr(self, key), dtype=float)
            if value.shape != (n,):
                raise CaseError(f"{key} must have {n} entries, got shape {value.shape}", key=key)
            if not np.all(np.isfinite(value)):
                raise CaseError(f"{key} must be finite, got {value.tolist()}", key=key)
            object.__setattr__(self, key, _frozen(value))
        for key in ("T_tip", "T_flange_tool"):
            value = np.array(getattr(self, key), dtype=float)
            if value.shape != (4, 4) or not np.all(np.isfinite(value)):
                raise CaseError(f"{key} must be a finite (4, 4) transform")
            object.__setattr__(self, key, _frozen(value))
        names = tuple(self.joint_names) or tuple(f"q{i + 1}" for i in range(n))
        if len(names) != n:
            raise CaseError(f"joint_names must have {n} entries, got {len(names)}")
        object.__setattr__(self, "joint_names", names)
        object.__setattr__(self, "assumptions", tuple(self.assumptions))
        if self.dh is not None:
            object.__setattr__(self, "dh", _frozen(self.dh))
        if self.dynamics is not None and self.dynamics.n_dof != n:
            raise CaseError(
                f"dynamics must have {n} joints, got {self.dynamics.n_dof}", key="dynamics"
            )
        if self.collision is not None and np.any(self.collision.frame > n):
            raise CaseError(f"link capsules must be on frames 0..{n}", key="collision")
        if self.visuals is not None:
            object.__setattr__(self, "visuals", tuple(self.visuals))
            if any(not 0 <= visual.frame <= n for visual in self.visuals):
                raise CaseError(f"link visuals must be on frames 0..{n}", key="visuals")
        if self.controller is not None and self.controller.n_dof != n:
            raise CaseError(
                f"the controller convention must have {n} joints, got {self.controller.n_dof}",
                key="controller",
            )

    @classmethod
    def from_dh(
        cls,
        *,
        name: str,
        d: np.ndarray,
        a: np.ndarray,
        alpha: np.ndarray,
        offset: np.ndarray,
        **limits_and_more: object,
    ) -> Robot:
        """A robot from a standard-DH table.

        Link transform: ``A_i = Rz(q_i + offset_i) · Tz(d_i) · Tx(a_i) · Rx(alpha_i)``; the
        flange is DH frame n. As a chain: ``origin_1 = Rz(offset_1)``,
        ``origin_i = Tz(d_{i-1}) Tx(a_{i-1}) Rx(alpha_{i-1}) Rz(offset_i)``, every axis z,
        ``T_tip = Tz(d_n) Tx(a_n) Rx(alpha_n)``.

        Parameters
        ----------
        name
            Robot name.
        d, a, alpha, offset
            DH parameters, shape (n,), m and rad.
        **limits_and_more
            The other :class:`Robot` fields (``q_min`` … ``j_max``, ``T_flange_tool``,
            ``source`` …).

        Raises
        ------
        CaseError
            When the columns do not have one entry per joint or are not finite.
        """
        table = np.stack([np.asarray(c, dtype=float).ravel() for c in (d, a, alpha, offset)], 1)
        columns = [np.asarray(c, dtype=float) for c in (d, a, alpha, offset)]
        for key, column in zip(DH_COLUMNS, columns, strict=True):
            if column.shape != columns[0].shape or column.ndim != 1:
                raise CaseError(
                    f"{key} must have {columns[0].size} entries, got shape {column.shape}", key=key
                )
            if not np.all(np.isfinite(column)):
                raise CaseError(f"{key} must be finite, got {column.tolist()}", key=key)
        n = table.shape[0]
        origins = np.empty((n, 4, 4))
        for i in range(n):
            previous = np.eye(4) if i == 0 else dh_transform(*table[i - 1, :3])
            origins[i] = previous @ rz(table[i, 3])
        axes = np.tile([0.0, 0.0, 1.0], (n, 1))
        return cls(
            name=name,
            origins=origins,
            axes=axes,
            T_tip=dh_transform(*table[-1, :3]),
            dh=table,
            **limits_and_more,  # type: ignore[arg-type]
        )

    @property
    def n_dof(self) -> int:
        """Number of joints."""
        return int(self.origins.shape[0])

    @property
    def convention(self) -> ControllerConvention:
        """The controller convention: :attr:`controller`, or the identity when None."""
        if self.controller is not None:
            return self.controller
        return ControllerConvention.identity(self.n_dof)

    @property
    def has_tool(self) -> bool:
        """True when the tool transform is not the identity."""
        return not np.allclose(self.T_flange_tool, np.eye(4))

    def limits(self, kind: str) -> np.ndarray:
        """Symmetric bound of one limit kind, shape (n,).

        For ``position`` this is not symmetric: use :attr:`q_min`, :attr:`q_max`.
        """
        return {"velocity": self.v_max, "acceleration": self.a_max, "jerk": self.j_max}[kind]

    @cached_property
    def kernel_chain(self) -> tuple[np.ndarray, np.ndarray]:
        """The chain with every axis turned onto z, the layout of the compiled kernels.

        Returns
        -------
        chain
            Shape (n, 4, 4): ``C_i = R_{i-1}ᵀ · origin_i · R_i`` with ``R_i`` a rotation
            whose z column is ``axis_i`` (``R_0 = I``), so ``T_0_n(q) = Π C_i Rz(q_i)``
            up to the last ``R_n``.
        tail
            Shape (4, 4): ``R_nᵀ · T_tip · T_flange_tool``.
        """
        n = self.n_dof
        chain = np.empty((n, 4, 4))
        previous = np.eye(4)
        for i in range(n):
            turn = np.eye(4)
            turn[:3, :3] = rotation_z_to(self.axes[i])
            chain[i] = previous.T @ self.origins[i] @ turn
            previous = turn
        tail = previous.T @ self.T_tip @ self.T_flange_tool
        chain.flags.writeable = False
        tail.flags.writeable = False
        return chain, tail

    @cached_property
    def link_frames(self) -> np.ndarray:
        """Each link's frame relative to its joint's frame in :attr:`kernel_chain`, (n, 4, 4).

        The frame a link is described in: for a robot built from a DH table, DH frame i
        (``Tz(d_i) Tx(a_i) Rx(alpha_i)`` after joint i); for a URDF chain, the child link
        frame of joint i (the axis turned back from z).
        """
        n = self.n_dof
        links = np.empty((n, 4, 4))
        for i in range(n):
            if self.dh is not None:
                links[i] = dh_transform(*self.dh[i, :3])
            else:
                links[i] = np.eye(4)
                links[i, :3, :3] = rotation_z_to(self.axes[i]).T
        links.flags.writeable = False
        return links

    @cached_property
    def reach(self) -> float:
        """The largest distance of the tool point from the base origin, m.

        Estimated on :data:`REACH_SAMPLES` configurations drawn with a fixed seed inside the
        position limits (a lower bound of the true maximum, within about 1 %).
        """
        rng = np.random.default_rng(0)
        q = rng.uniform(self.q_min, self.q_max, (REACH_SAMPLES, self.n_dof))
        chain, tail = self.kernel_chain  # forward kinematics (kinematics.py) of the samples
        T = fk_flat(read_only(chain), read_only(tail), read_only(q))
        return float(np.linalg.norm(T[:, :3, 3], axis=1).max())

    @property
    def default_placement_reach(self) -> tuple[float, float]:
        """:attr:`placement_reach`, or :data:`PLACEMENT_REACH_FRACTIONS` of :attr:`reach`, m."""
        if self.placement_reach is not None:
            return self.placement_reach
        low, high = PLACEMENT_REACH_FRACTIONS
        return (round(low * self.reach, 6), round(high * self.reach, 6))
