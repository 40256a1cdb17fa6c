"""FANUC TP position data: W, P, R angles, the ``CONFIG`` string and the ``/POS`` records.

The orientation of a FANUC Cartesian position is ``R = Rz(R)·Ry(P)·Rx(W)`` with W, P, R in
degrees about the fixed X, Y and Z axes (RoboDK's ``Pose_2_Fanuc``/``xyzrpw_2_pose`` in
RoboDK/RoboDK-API ``Python/robodk/robomath.py``). The configuration string
``'F/N U/D T/B, t1, t4, t6'`` is computed from the planned joints as described on
``docs/export-fanuc.md``:

- **F/N** (wrist flip): ``F`` when the controller's J5 ≥ 0, else ``N``. Sources: RoboDK's
  FANUC post (ros-industrial-attic/robodk_postprocessors ``Fanuc_R30iA.py``: "F means axis 5
  >= 0") and onerobotics.com, "The perils of six-axis robots" (an R-2000iB position reads
  ``NUT 000`` at J5 = −51.975° and ``FUT 000`` at J5 = +51.975°).
- **U/D** (elbow): ``U`` when the elbow (the J3 axis) lies above the line from the J2 axis to
  the wrist centre, seen in the arm's plane with the wrist in front (the sign of the elbow
  angle), else ``D``.
- **T/B** (arm): ``T`` when the wrist centre is in front of the J1 axis (on the side the arm
  faces), ``B`` behind it. The facing direction is where the wrist centre lies at the zero
  pose turned by J1.
- **t1, t4, t6**: the turn numbers of J1, J4 and J6: 0 on (−180°, 180°), +1 on
  [180°, 540°), −1 on (−540°, −180°] (RoboDK's ``angle_2_turn`` in ``Fanuc_R30iA.py``).

FANUC's own manual text for these fields was not found in a public source; the docs page
says which parts are secondary.
"""

from __future__ import annotations

import numpy as np

from trackplan.frames import rpy_from_matrix
from trackplan.robots.kinematics import axis_frames
from trackplan.robots.model import Robot
from trackplan.robots.wrist import wrist_centres
from trackplan.writers.numbers import fixed

MM = 1000.0
"""mm per m."""


def wpr_from_matrix(R: np.ndarray) -> np.ndarray:
    """FANUC W, P, R of rotation matrices (``R = Rz(R)·Ry(P)·Rx(W)``): the
    :func:`~trackplan.frames.rpy_from_matrix` angles in degrees (at the gimbal lock,
    P = ±90°, W is 0 and R carries the rotation about the common axis).

    Parameters
    ----------
    R
        Rotation matrices, shape (..., 3, 3).

    Returns
    -------
    numpy.ndarray
        (W, P, R), shape (..., 3), degrees; P in [−90, 90].
    """
    return np.degrees(rpy_from_matrix(R))


def xyzwpr(pose: np.ndarray) -> np.ndarray:
    """X, Y, Z (mm) and W, P, R (deg) of poses.

    Parameters
    ----------
    pose
        Shape (..., 4, 4), m.

    Returns
    -------
    numpy.ndarray
        Shape (..., 6): X, Y, Z in mm, W, P, R in degrees.
    """
    pose = np.asarray(pose, dtype=float)
    return np.concatenate([pose[..., :3, 3] * MM, wpr_from_matrix(pose[..., :3, :3])], axis=-1)


def turn_numbers(angles_deg: np.ndarray) -> np.ndarray:
    """FANUC turn numbers: 0 on (−180°, 180°), ±1 a turn further, and so on.

    Parameters
    ----------
    angles_deg
        Joint angles, shape (...,), degrees.

    Returns
    -------
    numpy.ndarray
        Integers, shape (...,): ``sign(a)·floor((|a| + 180) / 360)``.
    """
    a = np.asarray(angles_deg, dtype=float)
    return (np.sign(a) * np.floor((np.abs(a) + 180.0) / 360.0)).astype(int)


def wrist_centre(robot: Robot, q: np.ndarray) -> np.ndarray:
    """Wrist centres (:func:`~trackplan.robots.wrist.wrist_centres`) of model joints
    ``q``, shape (N, n), rad; shape (N, 3), m, in the base frame."""
    return wrist_centres(axis_frames(robot, q))


def arm_configuration(robot: Robot, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The elbow (U/D) and the arm (T/B) of each configuration, from the geometry.

    Parameters
    ----------
    robot
        A six-axis robot.
    q
        Model joints, shape (N, n), rad.

    Returns
    -------
    tuple[numpy.ndarray, numpy.ndarray]
        ``up`` and ``front``, booleans of shape (N,): the elbow above the shoulder–wrist
        line, the wrist centre in front of the J1 axis.
    """
    q = np.atleast_2d(np.asarray(q, dtype=float))
    frames = axis_frames(robot, q)
    p1, z1 = frames[:, 1, :3, 3], frames[:, 1, :3, 2]
    p2, p3 = frames[:, 2, :3, 3], frames[:, 3, :3, 3]
    pw = wrist_centre(robot, q)
    # the facing direction: the wrist centre at the zero pose turned by J1, made horizontal
    reference = np.zeros_like(q)
    reference[:, 0] = q[:, 0]
    pw_zero = wrist_centre(robot, reference)
    facing = pw_zero - p1
    facing -= np.einsum("ni,ni->n", facing, z1)[:, None] * z1
    front = np.einsum("ni,ni->n", pw - p1, facing) >= 0.0
    lateral = np.cross(z1, facing)
    bend = np.einsum("ni,ni->n", np.cross(p3 - p2, pw - p3), lateral)
    up = bend >= 0.0
    return up, front


def config_strings(robot: Robot, model_joints: np.ndarray, joints: np.ndarray) -> list[str]:
    """``CONFIG`` strings of configurations: ``'N U T, 0, 0, 0'``.

    Parameters
    ----------
    robot
        The six-axis robot (its model geometry).
    model_joints
        Model joints, shape (N, 6), rad.
    joints
        The same configurations in the controller's convention, shape (N, 6), rad.

    Returns
    -------
    list[str]
        One string per configuration, without quotes.
    """
    model_joints = np.atleast_2d(np.asarray(model_joints, dtype=float))
    degrees = np.degrees(np.atleast_2d(np.asarray(joints, dtype=float)))
    up, front = arm_configuration(robot, model_joints)
    turns = turn_numbers(degrees[:, [0, 3, 5]])
    flip = degrees[:, 4] >= 0.0
    return [
        f"{'F' if f else 'N'} {'U' if u else 'D'} {'T' if t else 'B'}, {n[0]}, {n[1]}, {n[2]}"
        for f, u, t, n in zip(flip, up, front, turns.tolist(), strict=True)
    ]


def number(value: float, decimals: int) -> str:
    """A TP number: fixed point, every decimal, no exponent, ``-0`` printed as ``0``."""
    return fixed(value, decimals)


def cartesian_record(
    index: int,
    values: np.ndarray,
    config: str,
    uframe: int,
    utool: int,
    *,
    extended: str = "",
    group2: str = "",
) -> str:
    """A ``/POS`` record of a Cartesian position.

    Parameters
    ----------
    index
        The position number ``P[index]``.
    values
        X, Y, Z (mm), W, P, R (deg), shape (6,).
    config
        The configuration string, without quotes.
    uframe, utool
        The user frame and tool frame numbers the position is taught in.
    extended
        Group 1's extended axes (:func:`extended_fields`), or empty.
    group2
        The ``GP2`` block (:func:`group_block`), or empty.
    """
    decimals = (3, 3, 3, 4, 4, 4)
    x, y, z, w, p, r = (number(float(v), d) for v, d in zip(values, decimals, strict=True))
    return (
        f"P[{index}]{{\n"
        "   GP1:\n"
        f"\tUF : {uframe}, UT : {utool},\t\tCONFIG : '{config}',\n"
        f"\tX = {x:>12}  mm,\tY = {y:>12}  mm,\tZ = {z:>12}  mm,\n"
        f"\tW = {w:>12} deg,\tP = {p:>12} deg,\tR = {r:>12} deg"
        + (f",\n\t{extended}" if extended else "")
        + "\n"
        + group2
        + "};"
    )


def joint_record(
    index: int,
    degrees: np.ndarray,
    uframe: int,
    utool: int,
    *,
    extended: str = "",
    group2: str = "",
) -> str:
    """A ``/POS`` record of a joint position (``J1 = … deg``).

    Parameters
    ----------
    index
        The position number ``P[index]``.
    degrees
        Controller joints, shape (n,), degrees (printed to 1e-4°).
    uframe, utool
        The user frame and tool frame numbers.
    extended
        Group 1's extended axes (:func:`extended_fields`), or empty.
    group2
        The ``GP2`` block (:func:`group_block`), or empty.
    """
    body = _joint_rows(degrees)
    if extended:
        body += f",\n\t{extended}"
    return f"P[{index}]{{\n   GP1:\n\tUF : {uframe}, UT : {utool},\n{body}\n{group2}}};"


def _joint_rows(degrees: np.ndarray) -> str:
    """``J1= … deg`` fields, three to a row."""
    fields = [f"J{i + 1}= {number(float(v), 4):>12} deg" for i, v in enumerate(degrees)]
    rows = [",\t".join(fields[k : k + 3]) for k in range(0, len(fields), 3)]
    return ",\n".join(f"\t{row}" for row in rows)


def extended_fields(millimetres: np.ndarray) -> str:
    """Group 1's extended axes ``E1= … mm`` (a track), empty for none."""
    return ",\t".join(f"E{i + 1}= {number(float(v), 3):>12}  mm" for i, v in enumerate(millimetres))


def group_block(degrees: np.ndarray, uframe: int, utool: int) -> str:
    """A ``GP2`` block of a position: the positioner's axes ``J1= … deg`` (motion group
    2), empty for none."""
    if len(degrees) == 0:
        return ""
    return f"   GP2:\n\tUF : {uframe}, UT : {utool},\n{_joint_rows(degrees)}\n"


__all__ = [
    "arm_configuration",
    "cartesian_record",
    "config_strings",
    "extended_fields",
    "group_block",
    "joint_record",
    "number",
    "turn_numbers",
    "wpr_from_matrix",
    "wrist_centre",
    "xyzwpr",
]
