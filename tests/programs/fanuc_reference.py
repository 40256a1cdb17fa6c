"""FANUC's configuration fields computed from joints, written once for the tests.

Independent of :mod:`trackplan.writers.fanuc_config`: one configuration at a time, with the
arm drawn in its own plane. The definition (``docs/export-fanuc.md``):

- F/N: ``F`` when the controller's J5 ≥ 0° (RoboDK's FANUC post; an R-2000iB reads ``NUT``
  at J5 = −51.975° and ``FUT`` at +51.975°, onerobotics.com "The perils of six-axis robots").
- U/D: ``U`` when the elbow (J3 axis) is above the line from the J2 axis to the wrist
  centre, in the arm's plane drawn with the wrist in front.
- T/B: ``T`` when the wrist centre is in front of the J1 axis, on the side the arm faces
  (where the wrist centre is at the zero pose turned by J1).
- t1, t4, t6: the turns of J1, J4, J6: 0 on (−180°, 180°), one more per turn beyond.
"""

from __future__ import annotations

import numpy as np

from trackplan.robots.kinematics import axis_frames
from trackplan.robots.model import Robot


def turn(angle_deg: float) -> int:
    """The turn number of one joint angle (deg), counting whole turns away from 0."""
    count = 0
    if angle_deg >= 180.0:  # one way only: a half turn counts away from 0 (180° is +1)
        while angle_deg >= 180.0:
            angle_deg -= 360.0
            count += 1
    else:
        while angle_deg <= -180.0:
            angle_deg += 360.0
            count -= 1
    return count


def _wrist_centre(frames: np.ndarray) -> np.ndarray:
    """Midpoint of the shortest segment between the J4 and J5 axes (axis frames 4, 5)."""
    p4, u4 = frames[4, :3, 3], frames[4, :3, 2]
    p5, u5 = frames[5, :3, 3], frames[5, :3, 2]
    (s, t), *_ = np.linalg.lstsq(np.stack([u4, -u5], axis=1), p5 - p4, rcond=None)
    return 0.5 * ((p4 + s * u4) + (p5 + t * u5))


def fanuc_config(robot: Robot, model_joints: np.ndarray, joints: np.ndarray) -> dict[str, object]:
    """The configuration fields of one configuration, as the parser reports them.

    Parameters
    ----------
    robot
        A six-axis robot.
    model_joints
        Model joints, shape (6,), rad.
    joints
        Controller joints, shape (6,), rad.

    Returns
    -------
    dict
        ``{"flip": "F"|"N", "elbow": "U"|"D", "front": "T"|"B", "turns": (t1, t4, t6)}``.
    """
    frames = axis_frames(robot, np.asarray(model_joints, dtype=float))
    zero = np.zeros(6)
    zero[0] = model_joints[0]
    frames_zero = axis_frames(robot, zero)
    axis_point, up = frames[1, :3, 3], frames[1, :3, 2]
    wrist = _wrist_centre(frames)
    ahead = _wrist_centre(frames_zero) - axis_point
    ahead = ahead - (ahead @ up) * up
    ahead /= np.linalg.norm(ahead)
    front = (wrist - axis_point) @ ahead >= 0.0
    # the arm in its plane: x ahead, y up
    shoulder, elbow = frames[2, :3, 3], frames[3, :3, 3]
    upper = np.array([(elbow - shoulder) @ ahead, (elbow - shoulder) @ up])
    fore = np.array([(wrist - elbow) @ ahead, (wrist - elbow) @ up])
    # the forearm turns clockwise from the upper arm's direction: the elbow is above the
    # shoulder–wrist line
    elbow_up = upper[0] * fore[1] - upper[1] * fore[0] <= 0.0
    degrees = np.degrees(np.asarray(joints, dtype=float))
    return {
        "flip": "F" if degrees[4] >= 0.0 else "N",
        "elbow": "U" if elbow_up else "D",
        "front": "T" if front else "B",
        "turns": (turn(degrees[0]), turn(degrees[3]), turn(degrees[5])),
    }
