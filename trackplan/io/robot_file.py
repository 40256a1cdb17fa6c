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

This module reads robot files and serves the built-in library; the file schema is
:mod:`trackplan.io.robot_schema`, robot files for a URDF are read by
:mod:`trackplan.io.urdf_robot`.
"""

from __future__ import annotations

from collections.abc import Callable
from functools import partial
from pathlib import Path
from typing import Any

import numpy as np
import yaml

from trackplan.errors import CaseError
from trackplan.frames import pose_matrix, rpy_from_matrix, rpy_matrix

# moved to robot_schema and urdf_robot; importers outside this package keep working
from trackplan.io.robot_schema import ASSUMED_ACCELERATION_TIME as ASSUMED_ACCELERATION_TIME
from trackplan.io.robot_schema import ASSUMED_JERK_TIME as ASSUMED_JERK_TIME
from trackplan.io.robot_schema import (
    DYNAMICS_KEYS,
    ROBOT_FILE_SUFFIXES,
    RobotFileModel,
    ToolModel,
    checked_family,
    collision_problems,
    controller_convention,
    controller_problems,
    ik_choice,
    ik_problems,
    link_capsules,
)
from trackplan.io.robot_schema import PayloadModel as PayloadModel
from trackplan.io.robot_schema import as_payload as as_payload
from trackplan.io.robot_schema import payload_problems as payload_problems
from trackplan.io.urdf_robot import load_urdf_robot_file, robot_from_urdf_file
from trackplan.io.yaml_input import (
    Problem,
    parse_yaml,
    raise_first,
    read_text,
    show,
    validate_model,
)
from trackplan.robots.builtin import DH_ROBOTS
from trackplan.robots.controller import ControllerConvention
from trackplan.robots.dynamics_parameters import (
    RobotDynamics,
    inertia_matrix,
    inertia_problem,
    inertials_from_dh,
)
from trackplan.robots.model import Robot

LIBRARY_DIR = Path(__file__).resolve().parent.parent / "robots" / "library"
"""Package data: one URDF and one robot file per built-in industrial arm."""


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
        return load_urdf_robot_file(data, file, assume_limits)
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
    problems += controller_problems(model.controller, len(model.joints))
    problems += ik_problems(model.ik, len(model.joints))
    raise_first(problems, data, file)
    tool = model.tool or ToolModel()
    columns = {
        key: np.array([getattr(joint, key) for joint in model.joints], dtype=float)
        for key in ("d", "a", "alpha", "offset", "velocity", "acceleration", "jerk")
    }
    position = np.array([joint.position for joint in model.joints], dtype=float)
    robot = Robot.from_dh(
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
        controller=controller_convention(model.controller, len(model.joints)),
        ik=ik_choice(model.ik),
    )
    return checked_family(robot, file)


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


class _Dumper(yaml.SafeDumper):  # type: ignore[misc]  # PyYAML ships no type stubs
    """Safe dumper that writes :class:`_FlowMapping` in flow style and indents list items."""

    def increase_indent(self, flow: bool = False, indentless: bool = False) -> None:
        """Indent block sequences inside mappings (``joints:`` then ``  - {...}``)."""
        super().increase_indent(flow, False)


class _FlowList(list[Any]):
    """A list written on one line (``[1.0, -1.0, 1.0]``)."""


_Dumper.add_representer(
    _FlowList,
    lambda dumper, data: dumper.represent_sequence(
        "tag:yaml.org,2002:seq", list(data), flow_style=True
    ),
)
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
    if robot.controller is not None:
        data["controller"] = _controller_block(robot.controller)
    body: str = yaml.dump(
        data, Dumper=_Dumper, sort_keys=False, allow_unicode=True, width=1_000_000
    )
    return _HEADER + body


def _controller_block(controller: ControllerConvention) -> dict[str, Any]:
    """The ``controller:`` block of a convention: the keys that differ from their defaults
    (joint numbers 1-based)."""
    block: dict[str, Any] = {"vendor": controller.vendor}
    if np.any(controller.signs != 1.0):
        block["signs"] = _FlowList(float(sign) for sign in controller.signs)
    if np.any(controller.offsets):
        block["offsets"] = _FlowList(float(offset) for offset in controller.offsets)
    if controller.coupling is not None:
        joint, driver, factor = controller.coupling
        block["coupling"] = _FlowMapping(joint=joint + 1, driver=driver + 1, factor=float(factor))
    if not np.array_equal(controller.world, np.eye(4)):
        block["world"] = _FlowMapping(
            xyz=[float(value) for value in controller.world[:3, 3]],
            rpy=[float(value) for value in rpy_from_matrix(controller.world[:3, :3])],
        )
    if controller.cycle is not None:
        block["cycle"] = float(controller.cycle)
    if controller.source:
        block["source"] = controller.source
    return block
