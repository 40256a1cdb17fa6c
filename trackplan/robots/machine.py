"""The arm with its external axes: a linear track that carries it, a positioner that turns
the part.

A welding cell moves more than the arm (``docs/positioner.md``). Its joint vector is one
array, in this order: the arm's joints, then the track (when there is one), then the
positioner's axes. The frames:

- the **cell frame** is the arm's base frame with the track at 0 (without a track, exactly
  the arm's base frame); gravity is −z of the cell frame;
- the track moves the arm's base along its unit ``axis`` (cell frame) by its position:
  ``T_cell_base(t) = Trans(axis · t)``;
- the positioner's base stands at ``pose`` in the cell; its chain (a revolute serial
  chain, the layout of :class:`~trackplan.robots.model.Robot`) ends at its flange, the
  **carrier frame** the part's placement X is given in: ``T_cell_flange(p) = T_pose ·
  FK(p)``; without a positioner the carrier is the cell frame.

The planner follows the seam relative to the carrier: the tool pose the arm must reach is
``T_base_tool = T_base_carrier(e) · T_X · T_part_tool(s)``, with ``e`` the external axes
at that point.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import numpy as np

from trackplan.errors import CaseError
from trackplan.frames import placement_transform
from trackplan.robots.kinematics import forward_kinematics, joint_frames
from trackplan.robots.model import Robot

AXIS_KINDS = ("robot", "track", "positioner")
"""What moves each joint of a machine's joint vector (result.json ``axes[].kind``)."""


def _frozen(value: object) -> np.ndarray:
    array = np.array(value, dtype=float)
    array.flags.writeable = False
    return array


@dataclass(frozen=True, eq=False)
class Track:
    """A linear axis under the arm's base (case key ``track``).

    Attributes
    ----------
    axis
        Unit direction of travel in the cell frame, shape (3,).
    lower, upper
        Travel range, m (the base at ``axis · t``).
    velocity, acceleration, jerk
        Symmetric limits, m/s, m/s², m/s³.
    name
        The axis's name in trajectory.csv (``track``).
    """

    axis: np.ndarray
    lower: float
    upper: float
    velocity: float
    acceleration: float
    jerk: float
    name: str = "track"

    def __post_init__(self) -> None:
        axis = np.array(self.axis, dtype=float)
        norm = float(np.linalg.norm(axis)) if axis.shape == (3,) else 0.0
        if axis.shape != (3,) or not np.isfinite(norm) or norm < 1e-9:
            raise CaseError(
                f"must be a non-zero direction [x, y, z], got {np.asarray(self.axis).tolist()}",
                key="track.axis",
            )
        object.__setattr__(self, "axis", _frozen(axis / norm))
        if not (np.isfinite(self.lower) and np.isfinite(self.upper) and self.lower < self.upper):
            raise CaseError(
                f"must be [min, max] with min < max (m), got [{self.lower}, {self.upper}]",
                key="track.position",
            )
        for key in ("velocity", "acceleration", "jerk"):
            value = getattr(self, key)
            if not (np.isfinite(value) and value > 0):
                raise CaseError(f"must be a finite number > 0, got {value!r}", key=f"track.{key}")


@dataclass(frozen=True, eq=False)
class Positioner:
    """A positioner: a revolute chain that turns the part, standing at a pose in the cell.

    Attributes
    ----------
    chain
        Its axes as a :class:`~trackplan.robots.model.Robot` (chain, limits, link capsules,
        source, assumptions); its flange (``T_tip``; no tool) is the carrier frame.
    pose
        Its base in the cell frame, (x, y, z, roll, pitch, yaw), shape (6,), m and rad.
    lower, upper
        Search ranges of the pose, shape (6,) each (equal where the pose is fixed), or None
        when the pose is fixed.
    model
        The built-in name or the file it came from.
    """

    chain: Robot
    pose: np.ndarray
    lower: np.ndarray | None = None
    upper: np.ndarray | None = None
    model: str = ""

    def __post_init__(self) -> None:
        pose = np.array(self.pose, dtype=float)
        if pose.shape != (6,) or not np.all(np.isfinite(pose)):
            raise CaseError(
                "must be [x, y, z, roll, pitch, yaw] (m, rad), "
                f"got {np.asarray(self.pose).tolist()}",
                key="positioner.pose",
            )
        object.__setattr__(self, "pose", _frozen(pose))
        if (self.lower is None) != (self.upper is None):
            raise CaseError("give both bounds of the pose or neither", key="positioner.pose")
        if self.lower is not None and self.upper is not None:
            object.__setattr__(self, "lower", _frozen(self.lower))
            object.__setattr__(self, "upper", _frozen(self.upper))

    @property
    def n_dof(self) -> int:
        """Number of positioner axes."""
        return self.chain.n_dof

    @property
    def searched(self) -> np.ndarray:
        """Indices (of x, y, z, roll, pitch, yaw) of the pose's searched keys, shape (k,)."""
        if self.lower is None or self.upper is None:
            return np.zeros(0, dtype=int)
        return np.flatnonzero(self.upper > self.lower)

    @cached_property
    def T_cell_base(self) -> np.ndarray:
        """The positioner's base in the cell frame, shape (4, 4)."""
        T = placement_transform(self.pose)
        T.flags.writeable = False
        return T

    def at(self, pose: np.ndarray) -> Positioner:
        """The same positioner standing at another pose (bounds kept), shape (6,)."""
        return Positioner(self.chain, pose, self.lower, self.upper, self.model)


@dataclass(frozen=True, eq=False)
class Machine:
    """The arm with a track, a positioner, or both: one joint vector, one set of limits.

    The joint vector is ``[arm (n_arm), track (0 or 1), positioner (n_positioner)]``; the
    limit arrays (:attr:`q_min` … :attr:`j_max`) and :attr:`joint_names` follow it, so that
    the time laws and the checker read a machine as they read a robot.

    Attributes
    ----------
    arm
        The robot arm (its IK, dynamics and tool).
    track
        The linear axis under the arm, or None.
    positioner
        The positioner that turns the part, or None.
    """

    arm: Robot
    track: Track | None = None
    positioner: Positioner | None = None

    @property
    def name(self) -> str:
        """The arm's name."""
        return self.arm.name

    @property
    def n_arm(self) -> int:
        """Joints of the arm."""
        return self.arm.n_dof

    @property
    def n_track(self) -> int:
        """1 with a track, else 0."""
        return 0 if self.track is None else 1

    @property
    def n_positioner(self) -> int:
        """Axes of the positioner (0 without)."""
        return 0 if self.positioner is None else self.positioner.n_dof

    @property
    def n_external(self) -> int:
        """Track and positioner axes."""
        return self.n_track + self.n_positioner

    @property
    def n_dof(self) -> int:
        """Every joint of the joint vector."""
        return self.n_arm + self.n_external

    @property
    def track_index(self) -> int | None:
        """Column of the track in the joint vector, or None."""
        return None if self.track is None else self.n_arm

    @property
    def positioner_columns(self) -> slice:
        """Columns of the positioner's axes in the joint vector."""
        first = self.n_arm + self.n_track
        return slice(first, first + self.n_positioner)

    @property
    def dynamics(self) -> None:
        """None: a machine's torques are the arm's (:attr:`arm`), checked on its columns."""
        return None

    @property
    def assumptions(self) -> tuple[str, ...]:
        """The arm's and the positioner's assumed limits."""
        own = () if self.positioner is None else self.positioner.chain.assumptions
        return self.arm.assumptions + own

    def _stack(self, arm: np.ndarray, track: float | None, positioner: np.ndarray) -> np.ndarray:
        parts = [np.asarray(arm, dtype=float)]
        if self.track is not None and track is not None:
            parts.append(np.array([track]))
        if self.positioner is not None:
            parts.append(np.asarray(positioner, dtype=float))
        return _frozen(np.concatenate(parts))

    def _limits(self, key: str, track_value: float) -> np.ndarray:
        chain = None if self.positioner is None else self.positioner.chain
        own = np.zeros(0) if chain is None else getattr(chain, key)
        return self._stack(getattr(self.arm, key), track_value, own)

    @cached_property
    def q_min(self) -> np.ndarray:
        """Lower position limits, shape (n,), rad or m."""
        return self._limits("q_min", self.track.lower if self.track else 0.0)

    @cached_property
    def q_max(self) -> np.ndarray:
        """Upper position limits, shape (n,), rad or m."""
        return self._limits("q_max", self.track.upper if self.track else 0.0)

    @cached_property
    def v_max(self) -> np.ndarray:
        """Velocity limits, shape (n,), rad/s or m/s."""
        return self._limits("v_max", self.track.velocity if self.track else 0.0)

    @cached_property
    def a_max(self) -> np.ndarray:
        """Acceleration limits, shape (n,), rad/s² or m/s²."""
        return self._limits("a_max", self.track.acceleration if self.track else 0.0)

    @cached_property
    def j_max(self) -> np.ndarray:
        """Jerk limits, shape (n,), rad/s³ or m/s³."""
        return self._limits("j_max", self.track.jerk if self.track else 0.0)

    def limits(self, kind: str) -> np.ndarray:
        """Symmetric bound of one limit kind, shape (n,) (as :meth:`Robot.limits`)."""
        return {"velocity": self.v_max, "acceleration": self.a_max, "jerk": self.j_max}[kind]

    @cached_property
    def joint_names(self) -> tuple[str, ...]:
        """The arm's joint names, ``track``, then the positioner's axis names (each with
        ``positioner_`` before it when one would repeat a name)."""
        names = list(self.arm.joint_names)
        if self.track is not None:
            names.append(self.track.name)
        if self.positioner is not None:
            own = self.positioner.chain.joint_names
            if set(own) & set(names):  # one name for one joint: a clash gets a prefix
                own = tuple(f"positioner_{name}" for name in own)
            names.extend(own)
        return tuple(names)

    @cached_property
    def kinds(self) -> tuple[str, ...]:
        """The kind of every joint (:data:`AXIS_KINDS`)."""
        return (
            ("robot",) * self.n_arm
            + ("track",) * self.n_track
            + ("positioner",) * self.n_positioner
        )

    @cached_property
    def units(self) -> tuple[str, ...]:
        """The unit of every joint's position: ``rad``, or ``m`` for the track."""
        return tuple("m" if kind == "track" else "rad" for kind in self.kinds)

    def with_positioner_pose(self, pose: np.ndarray) -> Machine:
        """The machine with its positioner standing at ``pose``, shape (6,)."""
        if self.positioner is None:
            raise CaseError("the machine has no positioner", key="positioner")
        return Machine(self.arm, self.track, self.positioner.at(pose))

    # --- kinematics, batched over any leading shape of the joint vector -----------------

    def T_cell_base(self, q: np.ndarray) -> np.ndarray:
        """The arm's base in the cell frame, shape (..., 4, 4), from q (..., n)."""
        q = np.asarray(q, dtype=float)
        T = np.broadcast_to(np.eye(4), (*q.shape[:-1], 4, 4)).copy()
        if self.track is not None:
            T[..., :3, 3] = q[..., self.n_arm, None] * self.track.axis
        return T

    def T_cell_carrier(self, q: np.ndarray) -> np.ndarray:
        """The carrier frame (the positioner's flange, else the cell) in the cell frame,
        shape (..., 4, 4), from q (..., n)."""
        q = np.asarray(q, dtype=float)
        if self.positioner is None:
            return np.broadcast_to(np.eye(4), (*q.shape[:-1], 4, 4)).copy()
        flange = forward_kinematics(self.positioner.chain, q[..., self.positioner_columns])
        T: np.ndarray = self.positioner.T_cell_base @ flange
        return T

    def T_base_carrier(self, q: np.ndarray) -> np.ndarray:
        """The carrier frame in the arm's base frame, shape (..., 4, 4)."""
        base = self.T_cell_base(q)
        carrier = self.T_cell_carrier(q)
        inverse = np.empty_like(base)  # a pure translation: its inverse is the negation
        inverse[...] = base
        inverse[..., :3, 3] = -base[..., :3, 3]
        T: np.ndarray = inverse @ carrier
        return T

    def T_base_tool(self, q: np.ndarray) -> np.ndarray:
        """The tool in the arm's base frame (the arm's FK), shape (..., 4, 4)."""
        q = np.asarray(q, dtype=float)
        return forward_kinematics(self.arm, q[..., : self.n_arm])

    def base_carrier_at(self, external: np.ndarray) -> np.ndarray:
        """:meth:`T_base_carrier` at the external axes' positions alone, shape (..., e) (the
        arm's joints do not move the carrier), shape (..., 4, 4)."""
        q = np.zeros((*np.shape(external)[:-1], self.n_dof))
        q[..., self.n_arm :] = external
        return self.T_base_carrier(q)

    def T_cell_tool(self, q: np.ndarray) -> np.ndarray:
        """The tool in the cell frame, shape (..., 4, 4)."""
        T: np.ndarray = self.T_cell_base(q) @ self.T_base_tool(q)
        return T

    def T_carrier_tool(self, q: np.ndarray) -> np.ndarray:
        """The tool in the carrier frame (relative to the part's holder), shape (..., 4, 4)."""
        T: np.ndarray = np.linalg.inv(self.T_base_carrier(q)) @ self.T_base_tool(q)
        return T

    def arm_frames_in_cell(self, q: np.ndarray) -> np.ndarray:
        """The arm's chain frames (:func:`~trackplan.robots.kinematics.joint_frames`) in
        the cell frame, shape (..., n_arm + 2, 4, 4)."""
        q = np.asarray(q, dtype=float)
        frames = joint_frames(self.arm, q[..., : self.n_arm])
        T: np.ndarray = self.T_cell_base(q)[..., None, :, :] @ frames
        return T

    def positioner_frames_in_cell(self, q: np.ndarray) -> np.ndarray:
        """The positioner's chain frames in the cell frame, shape (..., m + 2, 4, 4)
        (base, links, flange); shape (..., 0, 4, 4) without a positioner."""
        q = np.asarray(q, dtype=float)
        if self.positioner is None:
            return np.zeros((*q.shape[:-1], 0, 4, 4))
        frames = joint_frames(self.positioner.chain, q[..., self.positioner_columns])
        T: np.ndarray = self.positioner.T_cell_base @ frames
        return T


def carried_poses(machine: Robot | Machine, external: np.ndarray, poses: np.ndarray) -> np.ndarray:
    """Tool poses given in the carrier frame, in the arm's base frame:
    ``T_base_carrier(e) · T_carrier_tool``.

    Parameters
    ----------
    machine
        A machine (a robot: the poses unchanged).
    external
        The external axes at every pose, shape (..., e), m and rad.
    poses
        Tool poses in the carrier frame, shape (..., 4, 4).

    Returns
    -------
    numpy.ndarray
        Shape (..., 4, 4).
    """
    if not isinstance(machine, Machine):
        return poses
    carried: np.ndarray = machine.base_carrier_at(external) @ poses
    return carried


def carrier_tool(robot: Robot | Machine, q: np.ndarray) -> np.ndarray:
    """The tool in the frame the placement X refers to: the base frame of a robot
    (its FK), a machine's carrier frame (:meth:`Machine.T_carrier_tool`); shape (..., 4, 4)."""
    if isinstance(robot, Machine):
        return robot.T_carrier_tool(q)
    return forward_kinematics(robot, q)


def arm_of(robot: Robot | Machine) -> Robot:
    """The arm of a robot or a machine."""
    return robot.arm if isinstance(robot, Machine) else robot


def machine_of(robot: Robot | Machine) -> Machine:
    """A machine of a robot (no external axes) or the machine itself."""
    return robot if isinstance(robot, Machine) else Machine(robot)
