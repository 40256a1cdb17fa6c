"""Robot files that point at a URDF: the chain, its limits, collision capsules and
dynamics read from the URDF and the robot file's own blocks, into one
:class:`~trackplan.robots.model.Robot`.

:mod:`trackplan.io.urdf` parses the URDF; :mod:`trackplan.io.robot_file` dispatches
robot files here (docs/robots.md).
"""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path
from typing import Any

import numpy as np

from trackplan.errors import CaseError
from trackplan.frames import pose_matrix, rpy_matrix
from trackplan.io.robot_schema import (
    ASSUMED_ACCELERATION_TIME,
    ASSUMED_JERK_TIME,
    LimitsModel,
    ToolModel,
    URDFDynamicsModel,
    URDFRobotFileModel,
    as_payload,
    checked_family,
    collision_problems,
    controller_convention,
    controller_problems,
    ik_choice,
    ik_problems,
    link_capsules,
    payload_problems,
)
from trackplan.io.urdf import read_urdf_chain
from trackplan.io.urdf_geometry import read_urdf_link_geometry, read_urdf_visuals
from trackplan.io.urdf_inertials import read_urdf_inertials
from trackplan.io.yaml_input import (
    Problem,
    raise_first,
    validate_model,
)
from trackplan.robots.collision import Capsules
from trackplan.robots.dynamics_parameters import (
    STANDARD_GRAVITY,
    RobotDynamics,
    inertia_matrix,
    inertia_problem,
)
from trackplan.robots.model import Robot


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
    geometry = read_urdf_link_geometry(file, chain.joint_names)
    robot = replace(
        robot,
        dynamics=urdf_dynamics(file, chain, None, None, str(file)),
        visuals=read_urdf_visuals(file, geometry.link_frames),
    )
    return replace(robot, collision=geometry.capsules) if len(geometry.capsules) else robot


def load_urdf_robot_file(data: Any, file: str | None, assume_limits: bool) -> Robot:
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
    problems += controller_problems(model.controller, n)
    problems += ik_problems(model.ik, n)
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
    controller = controller_convention(model.controller, n)
    frames = read_urdf_link_geometry(
        base / model.urdf, chain.joint_names, model.base_link, collisions=False
    ).link_frames
    robot = replace(
        robot,
        dynamics=dynamics,
        collision=collision,
        controller=controller,
        visuals=read_urdf_visuals(base / model.urdf, frames),
        ik=ik_choice(model.ik),
    )
    return checked_family(robot, file)


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
