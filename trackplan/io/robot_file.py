"""Robot files: a standard-DH robot YAML, a URDF, or a robot YAML pointing at a URDF.

A DH robot file (see ``docs/files.md``)::

    name: puma560
    source: "where the numbers come from"      # optional
    joints:                                    # one entry per joint, base to flange
      - {d: 0, a: 0, alpha: 1.5707963267948966, offset: 0,
         position: [-3.141592653589793, 3.141592653589793],
         velocity: 8, acceleration: 10, jerk: 30}
    tool: {xyz: [0, 0, 0], rpy: [0, 0, 0]}     # optional
    collision:                                 # optional: link capsules (docs/cell.md)
      - {link: 2, from: [-0.4318, 0, 0.2435], to: [0, 0, 0.2435], radius: 0.07}

Lengths in metres, angles in radians, limits in rad/s, rad/s², rad/s³.
``T_flange_tool = Trans(xyz) · RPY(rpy)`` with ``RPY = Rz(yaw) · Ry(pitch) · Rx(roll)``.

Dynamics (optional, see ``docs/dynamics.md``): per joint ``mass`` (kg), ``com`` (m, DH link
frame), ``inertia`` ``[Ixx, Iyy, Izz, Ixy, Iyz, Ixz]`` (kg·m², about the centre of mass, DH
link frame axes) and ``torque`` (N·m, link side), given for every joint or none; optionally
``motor_inertia`` (kg·m²), ``gear_ratio``, ``viscous`` (N·m·s/rad) and ``coulomb``
``[Tc+, Tc-]`` (N·m), all on the motor side, and ``motor_constant`` (N·m/√W). Beside the
joints: ``gravity`` (m/s², base frame, default ``[0, 0, -9.81]``) and ``payload``
``{mass, com, inertia}`` at the tool centre point (TCP frame).

A robot file for a URDF (paths relative to the file; see ``docs/robots.md``)::

    name: my-irb2400
    urdf: irb2400.urdf
    base_link: base_link          # default: the URDF's root link
    tip_link: tool0               # default: the single leaf of the chain
    tool: {xyz: [0, 0, 0.25], rpy: [0, 0.3, 0]}
    limits:                       # per joint, in chain order
      acceleration: [5, 5, 5, 10, 10, 15]
      jerk: [25, 25, 25, 50, 50, 75]
      velocity: [2.6, 2.6, 2.6, 6.2, 6.2, 7.8]   # optional override of the URDF
    continuous_range: 6.283185307179586          # optional: continuous joints' half range
    source: "where the numbers come from"        # optional
    assumptions: ["acceleration and jerk assumed: …"]   # optional
    dynamics:                     # optional, per joint in chain order (docs/dynamics.md)
      torque: [150, 150, 150, 28, 28, 28]        # N·m, replaces the URDF's effort limits
      gear_ratio: [101, 101, 101, 101, 101, 101]  # and motor_inertia, viscous, coulomb,
                                                  # motor_constant, mass, com, inertia
    gravity: [0, 0, -9.81]        # optional, m/s², base frame
    payload: {mass: 2.0, com: [0, 0, 0.05]}      # optional, TCP frame
    collision:                    # optional: replaces the URDF's <collision> elements
      - {link: link_2, from: [0, 0, 0], to: [0, 0, 0.705], radius: 0.12}

``collision`` lists link capsules: ``link`` is a frame number (0 the base, i the link of
joint i) or, for a URDF, a link name; ``a`` and ``b`` are the axis end points in that link's
frame (m, the DH frame for a DH robot). Without it, a URDF's ``<collision>`` boxes,
cylinders, spheres and meshes are each fitted with an enclosing capsule.

A URDF gives no acceleration or jerk limits. Without them the robot is refused, unless
``assume_limits`` is set: then acceleration = velocity / :data:`ASSUMED_ACCELERATION_TIME`
and jerk = acceleration / :data:`ASSUMED_JERK_TIME`, recorded in ``Robot.assumptions``.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import replace
from functools import partial
from pathlib import Path
from typing import Annotated, Any

import numpy as np
import yaml
from pydantic import Field, PlainValidator
from pydantic_core import PydanticCustomError

from trackplan.errors import CaseError
from trackplan.frames import pose_matrix, rpy_from_matrix, rpy_matrix
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
from trackplan.io.urdf import DEFAULT_CONTINUOUS_RANGE, read_urdf_chain, read_urdf_link_geometry
from trackplan.io.urdf_inertials import read_urdf_inertials
from trackplan.io.yaml_input import (
    NonEmptyStr,
    Problem,
    Range,
    StrictModel,
    Vec3,
    list_default,
    parse_yaml,
    raise_first,
    read_text,
    show,
    validate_model,
)
from trackplan.robots.builtin import DH_ROBOTS
from trackplan.robots.collision import Capsules, frame_name, transform_capsule
from trackplan.robots.dynamics.parameters import (
    STANDARD_GRAVITY,
    Payload,
    RobotDynamics,
    inertia_matrix,
    inertia_problem,
    inertials_from_dh,
)
from trackplan.robots.model import Robot

ROBOT_FILE_SUFFIXES = (".yaml", ".yml", ".urdf")
ASSUMED_ACCELERATION_TIME = 0.25
"""s: with ``assume_limits``, a joint reaches its rated velocity in this time."""
ASSUMED_JERK_TIME = 0.1
"""s: with ``assume_limits``, a joint reaches its acceleration limit in this time."""
LIBRARY_DIR = Path(__file__).resolve().parent.parent / "robots" / "library"
"""Package data: one URDF and one robot file per built-in industrial arm."""


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


class RobotFileModel(StrictModel):
    """Schema of a DH robot file."""

    name: NonEmptyStr
    source: str = ""
    joints: Annotated[list[JointModel], Field(min_length=1)]
    tool: ToolModel | None = None
    gravity: Vec3 = list_default(*STANDARD_GRAVITY)
    payload: PayloadModel | None = None
    collision: Collision | None = None


def load_robot(file: str | Path, *, assume_limits: bool = False) -> Robot:
    """Read a robot file: a DH robot YAML, a URDF, or a robot YAML pointing at a URDF.

    Parameters
    ----------
    file
        Path of the robot file (``.yaml``/``.yml`` or ``.urdf``).
    assume_limits
        Fill missing acceleration and jerk limits by the documented rule (module
        docstring) instead of refusing the robot; the robot records the assumption.

    Returns
    -------
    Robot

    Raises
    ------
    CaseError
        When the file is missing or unreadable, is not valid YAML, or any value is
        wrong; the error names the file and the key (``joints[2].velocity``).
    """
    if str(file).lower().endswith(".urdf"):
        return robot_from_urdf_file(file, assume_limits=assume_limits)
    text = read_text(file, what="robot file")
    return load_robot_text(text, file=str(file), assume_limits=assume_limits)


def robot_from_urdf_file(file: str | Path, *, assume_limits: bool = False) -> Robot:
    """A robot from a URDF alone: its chain from the root to the single leaf.

    Raises
    ------
    CaseError
        As :func:`~trackplan.io.urdf.read_urdf_chain`, and when limits are missing.
    """
    chain = read_urdf_chain(file)
    robot = _urdf_robot(
        chain, chain.name, LimitsModel(), np.eye(4), "", [], assume_limits, str(file)
    )
    capsules = read_urdf_link_geometry(file, chain.joint_names).capsules
    robot = replace(robot, dynamics=urdf_dynamics(file, chain, None, None, str(file)))
    return replace(robot, collision=capsules) if len(capsules) else robot


def load_robot_text(text: str, file: str | None = None, *, assume_limits: bool = False) -> Robot:
    """Build a robot from the text of a robot file.

    Parameters
    ----------
    text
        YAML text in the robot file format.
    file
        The file the text came from, for error messages.

    Returns
    -------
    Robot

    Raises
    ------
    CaseError
        On the first problem in the text.
    """
    data = parse_yaml(text, file)
    if isinstance(data, dict) and "urdf" in data:
        return _load_urdf_robot_file(data, file, assume_limits)
    model = validate_model(RobotFileModel, data, file)
    problems: list[Problem] = [
        (
            ("joints", i, "position"),
            f"expected [min, max] with min < max, got {show(joint.position)}",
        )
        for i, joint in enumerate(model.joints)
        if joint.position[0] >= joint.position[1]
    ]
    problems += _dynamics_problems(model)
    problems += collision_problems(model.collision, len(model.joints), {})
    raise_first(problems, data, file)
    tool = model.tool or ToolModel()
    columns = {
        key: np.array([getattr(joint, key) for joint in model.joints], dtype=float)
        for key in ("d", "a", "alpha", "offset", "velocity", "acceleration", "jerk")
    }
    position = np.array([joint.position for joint in model.joints], dtype=float)
    return Robot.from_dh(
        name=model.name,
        d=columns["d"],
        a=columns["a"],
        alpha=columns["alpha"],
        offset=columns["offset"],
        q_min=position[:, 0],
        q_max=position[:, 1],
        v_max=columns["velocity"],
        a_max=columns["acceleration"],
        j_max=columns["jerk"],
        T_flange_tool=pose_matrix(np.array(tool.xyz), rpy_matrix(np.array(tool.rpy))),
        source=model.source,
        dynamics=_dynamics(model, columns),
        collision=link_capsules(model.collision, {}),
    )


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


def _dynamics_problems(model: RobotFileModel) -> list[Problem]:
    """Missing dynamic keys, negative masses, unphysical inertias, torque limits <= 0."""
    problems: list[Problem] = []
    given = [
        any(getattr(joint, key) is not None for key in DYNAMICS_KEYS) for joint in model.joints
    ]
    if any(given):
        for i, joint in enumerate(model.joints):
            for key in DYNAMICS_KEYS:
                if getattr(joint, key) is None:
                    problems.append(
                        (
                            ("joints", i),
                            f"missing {key}: give mass, com, inertia and torque for every joint "
                            "or for none",
                        )
                    )
                    break
    for i, joint in enumerate(model.joints):
        if joint.mass is not None and joint.mass < 0:
            problems.append((("joints", i, "mass"), f"mass must be >= 0 kg, got {joint.mass:g}"))
        if joint.torque is not None and joint.torque <= 0:
            problems.append(
                (("joints", i, "torque"), f"torque limit must be > 0 N·m, got {joint.torque:g}")
            )
        if joint.inertia is not None:
            problem = inertia_problem(inertia_matrix(joint.inertia))
            if problem:
                problems.append((("joints", i, "inertia"), f"inertia {problem}"))
        if joint.gear_ratio == 0:
            problems.append((("joints", i, "gear_ratio"), "gear ratio must not be 0"))
    if model.payload is not None:
        problems += payload_problems(model.payload, ("payload",))
        if not any(given):
            problems.append(
                (("payload",), "a payload needs the robot's dynamics (mass, com, inertia, torque)")
            )
    return problems


def _dynamics(model: RobotFileModel, columns: dict[str, np.ndarray]) -> RobotDynamics | None:
    """The robot's dynamics from a validated file, inertials converted to child frames."""
    joints = model.joints
    if joints[0].mass is None:
        return None
    com, inertia = inertials_from_dh(
        columns["d"],
        columns["a"],
        columns["alpha"],
        np.array([joint.com for joint in joints]),
        inertia_matrix(np.array([joint.inertia for joint in joints])),
    )
    motor_constants = [joint.motor_constant for joint in joints]
    return RobotDynamics(
        mass=np.array([joint.mass for joint in joints]),
        com=com,
        inertia=inertia,
        torque_max=np.array([joint.torque for joint in joints]),
        motor_inertia=np.array([joint.motor_inertia for joint in joints]),
        gear_ratio=np.array([joint.gear_ratio for joint in joints]),
        viscous=np.array([joint.viscous for joint in joints]),
        coulomb=np.array([joint.coulomb for joint in joints]),
        motor_constant=(
            None if any(k is None for k in motor_constants) else np.array(motor_constants)
        ),
        gravity=np.array(model.gravity),
        payload=None if model.payload is None else as_payload(model.payload),
        source=model.source,
    )


def _load_urdf_robot_file(data: Any, file: str | None, assume_limits: bool) -> Robot:
    """A robot from the data of a robot file with a ``urdf`` key."""
    model = validate_model(URDFRobotFileModel, data, file)
    base = Path(file).parent if file else Path(".")
    chain = read_urdf_chain(
        base / model.urdf,
        model.base_link,
        model.tip_link,
        continuous_range=model.continuous_range,
        referrer=file,
    )
    n = len(chain.joint_names)
    problems: list[Problem] = [
        (
            ("limits", key),
            f"expected {n} entries, one per joint of the chain "
            f"({', '.join(chain.joint_names)}), got {len(values)}",
        )
        for key in ("acceleration", "jerk", "velocity")
        if (values := getattr(model.limits, key)) is not None and len(values) != n
    ]
    raise_first(problems, data, file)
    tool = model.tool or ToolModel()
    T_tool = pose_matrix(np.array(tool.xyz), rpy_matrix(np.array(tool.rpy)))
    robot = _urdf_robot(
        chain,
        model.name,
        model.limits,
        T_tool,
        model.source,
        model.assumptions,
        assume_limits,
        file,
    )
    dynamics = urdf_dynamics(base / model.urdf, chain, model, data, file)
    collision = _urdf_collision(model, base / model.urdf, chain, data, file)
    return replace(robot, dynamics=dynamics, collision=collision)


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
    frame the link is fixed to (:func:`~trackplan.io.urdf.read_urdf_link_geometry`).
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


def _urdf_collision(
    model: URDFRobotFileModel, urdf: Path, chain: Any, data: Any, file: str | None
) -> Capsules | None:
    """The link capsules of a URDF robot file: its ``collision:`` key, else the URDF's
    ``<collision>`` elements fitted with capsules (None when it has neither)."""
    geometry = read_urdf_link_geometry(
        urdf, chain.joint_names, model.base_link, collisions=model.collision is None
    )
    if model.collision is None:
        return geometry.capsules if len(geometry.capsules) else None
    n_dof = len(chain.joint_names)
    raise_first(collision_problems(model.collision, n_dof, geometry.link_frames), data, file)
    return link_capsules(model.collision, geometry.link_frames)


def urdf_dynamics(
    urdf: str | Path,
    chain: Any,
    model: URDFRobotFileModel | None,
    data: Any,
    file: str | None,
) -> RobotDynamics | None:
    """The dynamics of a URDF robot: the URDF's inertials and efforts, then the robot file's.

    The robot has dynamics when the chain has inertials (``<inertial>`` or
    ``dynamics.mass``) and every joint a torque limit (``effort`` > 0 or
    ``dynamics.torque``). A bare URDF short of either has none (no torque check); a robot
    file that gives ``dynamics``, ``payload`` or ``gravity`` and is short of either is an
    error.

    Parameters
    ----------
    urdf
        The URDF file.
    chain
        Its chain (:class:`~trackplan.io.urdf.URDFChain`).
    model
        The validated robot file pointing at the URDF, or None for a bare URDF.
    data, file
        The robot file's data and path, for error messages.

    Returns
    -------
    RobotDynamics or None

    Raises
    ------
    CaseError
        On a bad value in the URDF's inertials or the robot file's dynamics.
    """
    names = chain.joint_names
    inertials = read_urdf_inertials(urdf, names, None if model is None else model.base_link)
    extra = model.dynamics if model is not None else None
    dyn = extra or URDFDynamicsModel()
    raise_first(_urdf_dynamics_problems(dyn, model, names), data, file)
    if dyn.mass is not None and dyn.com is not None and dyn.inertia is not None:
        mass, com = np.array(dyn.mass), np.array(dyn.com)
        inertia = inertia_matrix(np.array(dyn.inertia))
    elif inertials.has_inertials:
        mass, com, inertia = inertials.mass, inertials.com, inertials.inertia
    else:
        mass = None
    torque = np.array(dyn.torque) if dyn.torque is not None else inertials.effort
    explicit = model is not None and (
        extra is not None or model.payload is not None or "gravity" in model.model_fields_set
    )
    if mass is None or np.any(np.isnan(torque)):
        if not explicit:
            return None
        if mass is None:
            why = (
                "the URDF has no <inertial> on the chain's links: add them or give "
                "dynamics.mass, dynamics.com and dynamics.inertia"
            )
        else:
            missing = ", ".join(names[i] for i in np.flatnonzero(np.isnan(torque)))
            why = (
                f"no torque limit for joints {missing}: give effort > 0 in their <limit> "
                "in the URDF or dynamics.torque"
            )
        raise CaseError(why, file=file, key="dynamics")
    return RobotDynamics(
        mass=mass,
        com=com,
        inertia=inertia,
        torque_max=torque,
        motor_inertia=None if dyn.motor_inertia is None else np.array(dyn.motor_inertia),
        gear_ratio=None if dyn.gear_ratio is None else np.array(dyn.gear_ratio),
        viscous=None if dyn.viscous is None else np.array(dyn.viscous),
        coulomb=None if dyn.coulomb is None else np.array(dyn.coulomb),
        motor_constant=None if dyn.motor_constant is None else np.array(dyn.motor_constant),
        gravity=np.array(STANDARD_GRAVITY if model is None else model.gravity),
        payload=None if model is None or model.payload is None else as_payload(model.payload),
        source="" if model is None else model.source,
    )


def _urdf_dynamics_problems(
    dyn: URDFDynamicsModel, model: URDFRobotFileModel | None, names: tuple[str, ...]
) -> list[Problem]:
    """Wrong list lengths, negative masses, unphysical inertias, torque limits <= 0."""
    n = len(names)
    problems: list[Problem] = []
    for key in URDFDynamicsModel.model_fields:
        values = getattr(dyn, key)
        if values is not None and len(values) != n:
            problems.append(
                (
                    ("dynamics", key),
                    f"expected {n} entries, one per joint of the chain ({', '.join(names)}), "
                    f"got {len(values)}",
                )
            )
    if problems:
        return problems
    inertial = [getattr(dyn, key) is not None for key in ("mass", "com", "inertia")]
    if any(inertial) and not all(inertial):
        problems.append(
            (("dynamics",), "give mass, com and inertia together (they replace the URDF's)")
        )
    for i in range(n):
        if dyn.mass is not None and dyn.mass[i] < 0:
            problems.append((("dynamics", "mass", i), f"mass must be >= 0 kg, got {dyn.mass[i]:g}"))
        if dyn.torque is not None and dyn.torque[i] <= 0:
            problems.append(
                (
                    ("dynamics", "torque", i),
                    f"torque limit must be > 0 N·m, got {dyn.torque[i]:g}",
                )
            )
        if dyn.inertia is not None:
            problem = inertia_problem(inertia_matrix(dyn.inertia[i]))
            if problem:
                problems.append((("dynamics", "inertia", i), f"inertia {problem}"))
        if dyn.gear_ratio is not None and dyn.gear_ratio[i] == 0:
            problems.append((("dynamics", "gear_ratio", i), "gear ratio must not be 0"))
    if model is not None and model.payload is not None:
        problems += payload_problems(model.payload, ("payload",))
    return problems


def _urdf_robot(
    chain: Any,
    name: str,
    limits: LimitsModel,
    T_tool: np.ndarray,
    source: str,
    assumptions: list[str],
    assume_limits: bool,
    file: str | None,
) -> Robot:
    """The robot of a URDF chain with the limits a robot file adds (or assumed ones)."""
    notes = list(assumptions)
    velocity = chain.v_max if limits.velocity is None else np.array(limits.velocity)
    if np.any(np.isnan(velocity)):
        missing = [chain.joint_names[i] for i in np.flatnonzero(np.isnan(velocity))]
        raise CaseError(
            f"no velocity limit for joints {', '.join(missing)}: add velocity to their "
            "<limit> in the URDF or limits.velocity to a robot file",
            file=file,
        )
    acceleration = None if limits.acceleration is None else np.array(limits.acceleration)
    jerk = None if limits.jerk is None else np.array(limits.jerk)
    if acceleration is None or jerk is None:
        missing_keys = [
            key for key, value in (("acceleration", acceleration), ("jerk", jerk)) if value is None
        ]
        if not assume_limits:
            raise CaseError(
                f"a URDF gives no {' or '.join(missing_keys)} limits: add "
                f"{', '.join('limits.' + key for key in missing_keys)} (one per joint) to a "
                "robot file pointing at the URDF (docs/robots.md), or pass --assume-limits",
                file=file,
            )
        if acceleration is None:
            acceleration = velocity / ASSUMED_ACCELERATION_TIME
            notes.append(
                f"acceleration assumed: velocity / {ASSUMED_ACCELERATION_TIME} s (--assume-limits)"
            )
        if jerk is None:
            jerk = acceleration / ASSUMED_JERK_TIME
            notes.append(f"jerk assumed: acceleration / {ASSUMED_JERK_TIME} s (--assume-limits)")
    return Robot(
        name=name,
        origins=chain.origins,
        axes=chain.axes,
        q_min=chain.q_min,
        q_max=chain.q_max,
        v_max=velocity,
        a_max=acceleration,
        j_max=jerk,
        T_tip=chain.T_tip,
        T_flange_tool=T_tool,
        source=source,
        joint_names=chain.joint_names,
        assumptions=tuple(notes),
    )


def library_robots() -> dict[str, Path]:
    """The built-in URDF robots: name → robot file in the package data."""
    return {path.stem: path for path in sorted(LIBRARY_DIR.glob("*.yaml"))}


def builtin_names() -> tuple[str, ...]:
    """Names of every built-in robot (DH and URDF), sorted."""
    return tuple(sorted({*DH_ROBOTS, *library_robots()}))


BUILTIN_ROBOTS: dict[str, Callable[[], Robot]] = {
    **DH_ROBOTS,
    **{name: partial(load_robot, path) for name, path in library_robots().items()},
}
"""Every built-in robot: name → a function that builds it (``trackplan robots`` lists them)."""


def builtin_robot(name: str) -> Robot:
    """The built-in robot called ``name`` (``trackplan robots`` lists them).

    Raises
    ------
    CaseError
        When no built-in robot has that name.
    """
    key = name.lower()
    if key in DH_ROBOTS:
        return DH_ROBOTS[key]()
    library = library_robots()
    if key in library:
        return load_robot(library[key])
    raise CaseError(
        f"unknown robot {name!r}: use one of {', '.join(builtin_names())} or a path to a "
        "robot file (.yaml or .urdf)",
        key="robot",
    )


def is_robot_file(name_or_path: str) -> bool:
    """True when a case file's ``robot`` value names a file rather than a built-in robot.

    A value naming a file ends in ``.yaml``, ``.yml`` or ``.urdf`` or contains a path
    separator.
    """
    return name_or_path.lower().endswith(ROBOT_FILE_SUFFIXES) or any(
        separator in name_or_path for separator in ("/", "\\")
    )


def load_robot_spec(
    name_or_path: str,
    base_dir: str | Path,
    *,
    case_file: str | None = None,
    assume_limits: bool = False,
) -> Robot:
    """The robot a case file names: a built-in robot or a robot file.

    Parameters
    ----------
    name_or_path
        A built-in robot name (``puma560``, ``ur5``) or the path of a robot file,
        relative to ``base_dir`` unless absolute (see :func:`is_robot_file`).
    base_dir
        The folder of the case file.
    case_file
        The case file, so that an unknown name or a missing robot file is reported
        at its ``robot`` key.
    assume_limits
        As for :func:`load_robot`.

    Returns
    -------
    Robot

    Raises
    ------
    CaseError
        For an unknown robot name, a missing robot file, or a problem inside the robot
        file (then reported against the robot file).
    """
    if is_robot_file(name_or_path):
        path = Path(base_dir) / name_or_path
        if name_or_path.lower().endswith(".urdf"):
            if not path.is_file():
                raise CaseError(f"robot file not found: {path}", file=case_file, key="robot")
            return robot_from_urdf_file(path, assume_limits=assume_limits)
        text = read_text(path, what="robot file", referrer=case_file, key="robot")
        return load_robot_text(text, file=str(path), assume_limits=assume_limits)
    try:
        return builtin_robot(name_or_path)
    except CaseError as exc:
        raise CaseError(exc.message, file=case_file, key="robot") from None


class _FlowMapping(dict[str, Any]):
    """A mapping written on one line (``{d: 0.0, a: 0.4318, ...}``)."""


class _Dumper(yaml.SafeDumper):
    """Safe dumper that writes :class:`_FlowMapping` in flow style and indents list items."""

    def increase_indent(self, flow: bool = False, indentless: bool = False) -> None:
        """Indent block sequences inside mappings (``joints:`` then ``  - {...}``)."""
        super().increase_indent(flow, False)


_Dumper.add_representer(
    _FlowMapping,
    lambda dumper, data: dumper.represent_mapping(
        "tag:yaml.org,2002:map", list(data.items()), flow_style=True
    ),
)

_HEADER = """\
# trackplan robot file: standard DH, A_i = Rz(q_i + offset) · Tz(d) · Tx(a) · Rx(alpha).
# Units: m and rad; per joint: position [min, max] rad, velocity rad/s,
# acceleration rad/s², jerk rad/s³. tool: T_flange_tool = Trans(xyz) · RPY(rpy).
# Link capsules (collision): axis end points a, b (m) in DH frame `link` (0 = base), radius m.
"""


def robot_to_yaml(robot: Robot) -> str:
    """The robot file text of a robot, e.g. to start a new file from a built-in robot.

    Numbers are written with full precision: :func:`load_robot_text` of the result
    gives the same robot (the tool rotation up to rounding).

    Parameters
    ----------
    robot
        A robot built from a DH table (``robot.dh`` is set).

    Returns
    -------
    str
        YAML text in the robot file format, with a comment header.

    Raises
    ------
    CaseError
        For a robot read from a URDF.
    """
    if robot.dh is None:
        raise CaseError(
            f"robot {robot.name!r} is read from a URDF, not a DH table: copy its URDF and "
            "robot file (docs/robots.md) instead",
            key="robot",
        )
    joints = [
        _FlowMapping(
            d=float(robot.dh[i, 0]),
            a=float(robot.dh[i, 1]),
            alpha=float(robot.dh[i, 2]),
            offset=float(robot.dh[i, 3]),
            position=[float(robot.q_min[i]), float(robot.q_max[i])],
            velocity=float(robot.v_max[i]),
            acceleration=float(robot.a_max[i]),
            jerk=float(robot.j_max[i]),
        )
        for i in range(robot.n_dof)
    ]
    data: dict[str, Any] = {"name": robot.name}
    if robot.source:
        data["source"] = robot.source
    data["joints"] = joints
    if robot.has_tool:
        data["tool"] = _FlowMapping(
            xyz=[float(value) for value in robot.T_flange_tool[:3, 3]],
            rpy=[float(value) for value in rpy_from_matrix(robot.T_flange_tool[:3, :3])],
        )
    if robot.collision is not None:
        data["collision"] = [
            _FlowMapping(
                link=int(robot.collision.frame[k]),
                **{"from": [float(value) for value in robot.collision.segment[k, 0]]},
                to=[float(value) for value in robot.collision.segment[k, 1]],
                radius=float(robot.collision.radius[k]),
            )
            for k in range(len(robot.collision))
        ]
    body = yaml.dump(data, Dumper=_Dumper, sort_keys=False, allow_unicode=True, width=1_000_000)
    return _HEADER + body
