"""What both program forms share: joint moves, speed shares, zones and each seam's
tolerance budget.
"""

from __future__ import annotations

import math

import numpy as np

from trackplan.case import Case
from trackplan.check_report import CheckReport
from trackplan.jointpath import JointPath
from trackplan.programs.model import JointMove, Target
from trackplan.robots.model import Robot

START_SPEED = 0.1
"""Share of the rated joint velocities of the joint move to the planned start: the robot
comes from a configuration the plan does not know, so the move is slow."""

MIN_SPEED_SHARE = 0.01
"""Smallest share of the rated joint velocities a joint move is given."""

MIN_TCP_SPEED = 1e-3
"""Smallest TCP speed a Cartesian move is given, m/s (a move over a stretch where the
plan stands still)."""

ZONE_STEP = 1e-5
"""Zones are rounded down to this, m (0.01 mm), so that a writer printing them to
0.01 mm never widens them."""

MIN_CHORD = 1e-6
"""Smallest chord error a spline is fitted to, m: a seam whose plan leaves it no budget
(an infeasible run exported with ``--force``) still gets a finite program."""


def joint_move(
    robot: Robot,
    q_model: np.ndarray,
    speed: float,
    *,
    zone: float = 0.0,
    duration: float | None = None,
) -> JointMove:
    """A joint move to the model joints ``q_model``, rad, in the controller's convention:
    shape (n,) for the arm, or (n + e,) with the external axes after the arm's
    (:attr:`JointMove.external`, SI units)."""
    q = np.array(q_model, dtype=float)
    n = robot.n_dof
    return JointMove(
        joints=robot.convention.to_controller(q[:n]),
        model_joints=q[:n],
        speed=float(speed),
        duration=duration,
        zone=float(zone),
        external=q[n:],
    )


def speed_share(v_max: np.ndarray, qd: np.ndarray) -> float:
    """The peak joint rate of samples ``qd`` (K, n), rad/s (m/s for a track), as a share
    of the rated velocities ``v_max`` (n,): the largest over joints and samples, in
    [:data:`MIN_SPEED_SHARE`, 1]."""
    if len(qd) == 0:
        return MIN_SPEED_SHARE
    share = float(np.max(np.abs(qd) / v_max))
    return float(np.clip(share, MIN_SPEED_SHARE, 1.0))


def zone_within(room: float) -> float:
    """A blend radius of at most ``room`` m, rounded down to :data:`ZONE_STEP` (0 when
    there is no room)."""
    if not room > 0.0:
        return 0.0
    # a room of whole steps to round-off is that many steps, never more than the room
    return min(math.floor(room / ZONE_STEP + 1e-9) * ZONE_STEP, room)


def zones_within(room: np.ndarray) -> np.ndarray:
    """:func:`zone_within` of each value of ``room`` (M,), m, shape (M,)."""
    room = np.asarray(room, dtype=float)
    kept = np.where(room > 0.0, room, 0.0)
    floored: np.ndarray = np.minimum(np.floor(kept / ZONE_STEP + 1e-9) * ZONE_STEP, kept)
    return floored


def seam_budget(case: Case, seam_index: int, check: CheckReport) -> tuple[float, float]:
    """A seam's task tolerance and its plan's largest tracking error, m.

    A check that measured no tracking error (NaN) leaves no budget: the tracking error is
    taken as the whole tolerance.
    """
    tolerance = float(case.seams[seam_index].task.tolerance)
    tracking = float(check.max_tracking_error)
    if not math.isfinite(tracking):
        tracking = tolerance
    return tolerance, tracking


def path_targets(
    robot: Robot, joint_path: JointPath, s: np.ndarray, external: np.ndarray | None = None
) -> list[Target]:
    """Targets at arc lengths ``s`` (M,), m, of a seam's planned path, with the external
    axes ``external`` (M, e) there (None: none).

    The pose is the planned TCP in the part frame there (the planned path's point and the
    tool orientation, spin included); the joints are the path IK on the plan's branch at
    that pose, each on the winding of the planning grid nearest in s
    (:meth:`~trackplan.jointpath.JointPath.joints`): exact IK solutions, so that the
    forward kinematics of the joints is the pose to the IK's round-off.
    """
    s = np.asarray(s, dtype=float)
    _, position, _ = joint_path.geometry.planned.points(s)
    rotation = joint_path.R_part_tool(s)
    q_model = joint_path.joints(s)[:, : robot.n_dof]
    outside = np.zeros((len(s), 0)) if external is None else np.asarray(external, dtype=float)
    q_controller = robot.convention.to_controller(q_model)
    poses = np.zeros((len(s), 4, 4))
    poses[:, :3, :3] = rotation
    poses[:, :3, 3] = position
    poses[:, 3, 3] = 1.0
    return [
        Target(pose=poses[k], joints=q_controller[k], model_joints=q_model[k], external=outside[k])
        for k in range(len(s))
    ]


__all__ = [
    "MIN_CHORD",
    "MIN_SPEED_SHARE",
    "MIN_TCP_SPEED",
    "START_SPEED",
    "ZONE_STEP",
    "joint_move",
    "path_targets",
    "seam_budget",
    "speed_share",
    "zone_within",
    "zones_within",
]
