"""The robot file schema: the pydantic models of robot files (DH and URDF), their
payload, collision and controller blocks, and the checks and conversions of those blocks.

:mod:`trackplan.io.robot_file` reads robot files with these models; the case file
(:mod:`trackplan.io.case_file`) uses the payload block too. docs/files.md documents
the keys.
"""

from __future__ import annotations

import math
from typing import Annotated, Any, Literal

import numpy as np
from pydantic import Field, PlainValidator
from pydantic_core import PydanticCustomError

from trackplan.errors import CaseError
from trackplan.frames import pose_matrix, rpy_matrix
from trackplan.io.robot_bounds import (
    MAX_ANGLE,
    MAX_LENGTH,
    Angle,
    Friction,
    GearRatio,
    InertiaEntry,
    Length,
    Mass,
    MotorConstant,
    MotorInertia,
    Rate,
    Torque,
    Viscous,
)
from trackplan.io.urdf import DEFAULT_CONTINUOUS_RANGE
from trackplan.io.yaml_input import (
    NonEmptyStr,
    Problem,
    Range,
    StrictModel,
    Vec3,
    list_default,
)
from trackplan.robots.collision import Capsules, frame_name, transform_capsule
from trackplan.robots.controller import ControllerConvention
from trackplan.robots.dynamics_parameters import (
    STANDARD_GRAVITY,
    Payload,
    inertia_matrix,
    inertia_problem,
)
from trackplan.robots.families import ik_family
from trackplan.robots.model import IKChoice, Robot

ROBOT_FILE_SUFFIXES = (".yaml", ".yml", ".urdf")
ASSUMED_ACCELERATION_TIME = 0.25
"""s: with ``assume_limits``, a joint reaches its rated velocity in this time."""
ASSUMED_JERK_TIME = 0.1
"""s: with ``assume_limits``, a joint reaches its acceleration limit in this time."""


Inertia6 = Annotated[list[InertiaEntry], Field(min_length=6, max_length=6)]
"""``[Ixx, Iyy, Izz, Ixy, Iyz, Ixz]``, kg·m²."""
Coulomb = Annotated[list[Friction], Field(min_length=2, max_length=2)]
"""``[Tc+, Tc−]``, N·m, motor side."""


class JointModel(StrictModel):
    """One joint: DH parameters (m, rad) and limits (rad, rad/s, rad/s², rad/s³)."""

    d: Length
    a: Length
    alpha: Angle
    offset: Angle = 0.0
    position: Range
    velocity: Rate
    acceleration: Rate
    jerk: Rate
    mass: Mass | None = None
    com: Vec3 | None = None
    inertia: Inertia6 | None = None
    torque: Torque | None = None
    motor_inertia: MotorInertia = 0.0
    gear_ratio: GearRatio = 1.0
    viscous: Viscous = 0.0
    coulomb: Coulomb = list_default(0.0, 0.0)
    motor_constant: MotorConstant | None = None


DYNAMICS_KEYS = ("mass", "com", "inertia", "torque")
"""Per-joint keys that every joint needs once any joint has dynamics."""


class PayloadModel(StrictModel):
    """A load at the TCP: mass (kg), centre of mass and inertia about it (TCP frame)."""

    mass: Mass
    com: Vec3 = list_default(0.0, 0.0, 0.0)
    inertia: Inertia6 = list_default(0.0, 0.0, 0.0, 0.0, 0.0, 0.0)


class ToolModel(StrictModel):
    """Tool transform in the flange: ``Trans(xyz) · RPY(rpy)`` (m, rad)."""

    xyz: Vec3 = list_default(0.0, 0.0, 0.0)
    rpy: Vec3 = list_default(0.0, 0.0, 0.0)


def _link_reference(value: Any) -> int | str:
    """A ``collision[i].link``: a frame number or a non-empty link name, nothing else."""
    if isinstance(value, bool) or not isinstance(value, int | str) or value == "":
        raise PydanticCustomError(
            "link_type", "expected a link number (0 = base, i = joint i) or a URDF link name"
        )
    return value


LinkReference = Annotated[int | str, PlainValidator(_link_reference)]
"""A link by number (checked against the chain later) or by URDF link name."""


class CollisionCapsuleModel(StrictModel):
    """A link capsule: the link (number 0..n, or a URDF link's name), axis end points
    ``from``, ``to`` in that link's frame (m) and radius (m)."""

    link: LinkReference
    from_: Vec3 = Field(alias="from")
    to: Vec3
    radius: Annotated[float, Field(gt=0, le=MAX_LENGTH)]


Collision = Annotated[list[CollisionCapsuleModel], Field(min_length=1)]
"""The ``collision:`` key of a robot file: the robot's link capsules (``docs/cell.md``)."""


class LimitsModel(StrictModel):
    """Per-joint limits that a URDF lacks or that override it, in chain order."""

    acceleration: list[Rate] | None = None
    jerk: list[Rate] | None = None
    velocity: list[Rate] | None = None


class URDFDynamicsModel(StrictModel):
    """Dynamics of a URDF robot that add to or replace the URDF's, one entry per joint.

    ``mass``, ``com`` and ``inertia`` (about the centre of mass) are in the joints' child
    frames, which are the URDF frames of the links the joints move; given, they replace
    every ``<inertial>`` of the chain. ``torque`` replaces the ``<limit effort>`` values.
    """

    mass: list[Mass] | None = None
    com: list[Vec3] | None = None
    inertia: list[Inertia6] | None = None
    torque: list[Torque] | None = None
    motor_inertia: list[MotorInertia] | None = None
    gear_ratio: list[GearRatio] | None = None
    viscous: list[Viscous] | None = None
    coulomb: list[Coulomb] | None = None
    motor_constant: list[MotorConstant] | None = None


class CouplingModel(StrictModel):
    """A joint coupling: the controller's ``joint`` adds ``factor`` · the model's ``driver``
    (1-based joint numbers; rad per rad)."""

    joint: int
    driver: int
    factor: float


class ControllerWorldModel(StrictModel):
    """The controller's world frame in the model's base frame: ``Trans(xyz) · RPY(rpy)``
    (m, rad)."""

    xyz: Vec3 = list_default(0.0, 0.0, 0.0)
    rpy: Vec3 = list_default(0.0, 0.0, 0.0)


class ControllerModel(StrictModel):
    """The ``controller:`` block: how the robot's controller counts the joints
    (:class:`~trackplan.robots.controller.ControllerConvention`)."""

    vendor: Literal["kuka", "abb", "fanuc", "ur", "generic"]  # VENDORS (a test checks)
    signs: list[float] | None = None
    offsets: list[Angle] | None = None
    coupling: CouplingModel | None = None
    world: ControllerWorldModel | None = None
    cycle: Annotated[float, Field(gt=0, le=1.0)] | None = None
    source: str = ""


def controller_problems(controller: ControllerModel | None, n_dof: int) -> list[Problem]:
    """Per-joint lists of another length than the chain, signs other than ±1, coupled
    joints out of range or the same, a factor that is not finite."""
    if controller is None:
        return []
    problems: list[Problem] = []
    loc = ("controller",)
    for key in ("signs", "offsets"):
        values = getattr(controller, key)
        if values is not None and len(values) != n_dof:
            problems.append(
                ((*loc, key), f"expected {n_dof} entries, one per joint, got {len(values)}")
            )
    for i, sign in enumerate(controller.signs or []):
        if sign not in (1.0, -1.0):
            problems.append(((*loc, "signs", i), f"a sign is 1 or -1, got {sign:g}"))
    coupling = controller.coupling
    if coupling is not None:
        for key in ("joint", "driver"):
            number = getattr(coupling, key)
            if not 1 <= number <= n_dof:
                problems.append(
                    ((*loc, "coupling", key), f"expected a joint number 1..{n_dof}, got {number}")
                )
        if coupling.joint == coupling.driver:
            problems.append(
                (
                    (*loc, "coupling", "driver"),
                    f"a joint is not coupled to itself: the driver must differ from joint "
                    f"{coupling.joint}",
                )
            )
        if not math.isfinite(coupling.factor):
            problems.append(((*loc, "coupling", "factor"), "expected a finite number"))
    return problems


def controller_convention(
    controller: ControllerModel | None, n_dof: int
) -> ControllerConvention | None:
    """The convention of a validated ``controller:`` block (None when not given); joint
    numbers become 0-based."""
    if controller is None:
        return None
    coupling = controller.coupling
    world = controller.world or ControllerWorldModel()
    return ControllerConvention(
        vendor=controller.vendor,
        signs=np.array(controller.signs if controller.signs is not None else [1.0] * n_dof),
        offsets=np.array(controller.offsets if controller.offsets is not None else [0.0] * n_dof),
        coupling=None
        if coupling is None
        else (coupling.joint - 1, coupling.driver - 1, float(coupling.factor)),
        world=pose_matrix(np.array(world.xyz), rpy_matrix(np.array(world.rpy))),
        source=controller.source,
        cycle=controller.cycle,
    )


class IKModel(StrictModel):
    """The ``ik:`` block: the IK family (``auto`` detects it) and, for a 7-joint arm in the
    numeric family, the joint (1-based) that carries the redundancy."""

    family: Literal["auto", "opw", "ur", "srs", "panda", "crx", "numeric"] = "auto"
    free_joint: Annotated[int, Field(ge=1)] | None = None


def ik_problems(ik: IKModel | None, n_dof: int) -> list[Problem]:
    """A ``free_joint`` past the chain, or given to an arm that is not a 7-joint one."""
    if ik is None or ik.free_joint is None:
        return []
    if n_dof != 7:
        return [(("ik", "free_joint"), f"only a 7-joint arm has a free joint; this has {n_dof}")]
    if ik.free_joint > n_dof:
        return [(("ik", "free_joint"), f"expected a joint 1 … {n_dof}, got {ik.free_joint}")]
    return []


def checked_family(robot: Robot, file: str | None) -> Robot:
    """The robot, after its ``ik.family`` (when not ``auto``) was checked to fit its chain.

    Raises
    ------
    CaseError
        Naming the file and ``ik.family`` when the chain does not have that structure.
    """
    if robot.ik.family != "auto":
        try:
            ik_family(robot)
        except CaseError as error:
            raise CaseError(error.message, file=file, key=error.key) from None
    return robot


def ik_choice(ik: IKModel | None) -> IKChoice:
    """The :class:`~trackplan.robots.model.IKChoice` of a validated ``ik:`` block."""
    if ik is None:
        return IKChoice()
    free = None if ik.free_joint is None else ik.free_joint - 1
    return IKChoice(family=ik.family, free_joint=free)


class URDFRobotFileModel(StrictModel):
    """Schema of a robot file that points at a URDF."""

    name: NonEmptyStr
    urdf: NonEmptyStr
    source: str = ""
    base_link: NonEmptyStr | None = None
    tip_link: NonEmptyStr | None = None
    tool: ToolModel | None = None
    limits: LimitsModel = Field(default_factory=LimitsModel)
    continuous_range: Annotated[float, Field(gt=0, le=MAX_ANGLE)] = DEFAULT_CONTINUOUS_RANGE
    dynamics: URDFDynamicsModel | None = None
    gravity: Vec3 = list_default(*STANDARD_GRAVITY)
    payload: PayloadModel | None = None
    assumptions: list[str] = Field(default_factory=list)
    collision: Collision | None = None
    controller: ControllerModel | None = None
    ik: IKModel | None = None


class RobotFileModel(StrictModel):
    """Schema of a DH robot file."""

    name: NonEmptyStr
    source: str = ""
    joints: Annotated[list[JointModel], Field(min_length=1)]
    tool: ToolModel | None = None
    gravity: Vec3 = list_default(*STANDARD_GRAVITY)
    payload: PayloadModel | None = None
    collision: Collision | None = None
    controller: ControllerModel | None = None
    ik: IKModel | None = None


def payload_problems(payload: PayloadModel, loc: tuple[str | int, ...]) -> list[Problem]:
    """Negative mass or an unphysical inertia of a payload."""
    problems: list[Problem] = []
    if payload.mass < 0:
        problems.append(((*loc, "mass"), f"mass must be >= 0 kg, got {payload.mass:g}"))
    problem = inertia_problem(inertia_matrix(payload.inertia))
    if problem:
        problems.append(((*loc, "inertia"), f"inertia {problem}"))
    return problems


def as_payload(payload: PayloadModel) -> Payload:
    """The payload of a validated ``payload`` block."""
    return Payload(
        mass=payload.mass,
        com=np.array(payload.com),
        inertia=inertia_matrix(np.array(payload.inertia)),
    )


def collision_problems(
    capsules: list[CollisionCapsuleModel] | None,
    n_dof: int,
    link_frames: dict[str, tuple[int, np.ndarray]],
) -> list[Problem]:
    """Link numbers past the chain and link names the URDF does not put on it."""
    problems: list[Problem] = []
    for i, capsule in enumerate(capsules or []):
        if isinstance(capsule.link, int):
            if not 0 <= capsule.link <= n_dof:
                problems.append(
                    (
                        ("collision", i, "link"),
                        f"expected a link number 0..{n_dof} (0 = base), got {capsule.link}",
                    )
                )
        elif capsule.link not in link_frames:
            if link_frames:
                known = ", ".join(sorted(link_frames))
                message = f"no link {capsule.link!r} on the URDF's chain: use one of {known}"
            else:
                message = (
                    f"unknown link {capsule.link!r}: a DH robot numbers its links "
                    f"0..{n_dof} (0 = base)"
                )
            problems.append((("collision", i, "link"), message))
    return problems


def link_capsules(
    capsules: list[CollisionCapsuleModel] | None,
    link_frames: dict[str, tuple[int, np.ndarray]],
) -> Capsules | None:
    """The validated ``collision:`` capsules on the chain's frames (None when not given).

    A capsule given by a URDF link name is moved from that link's frame into the chain
    frame the link is fixed to (:func:`~trackplan.io.urdf_geometry.read_urdf_link_geometry`).
    """
    if capsules is None:
        return None
    frames, segments, names = [], [], []
    for capsule in capsules:
        if isinstance(capsule.link, int):
            frame, T_frame_link, name = capsule.link, np.eye(4), frame_name(capsule.link)
        else:
            (frame, T_frame_link), name = link_frames[capsule.link], capsule.link
        frames.append(frame)
        segments.append(transform_capsule(np.array([capsule.from_, capsule.to]), T_frame_link))
        names.append(name)
    return Capsules(
        np.array(frames), np.array(segments), np.array([c.radius for c in capsules]), tuple(names)
    )
