"""Capsule models of the built-in robots, and which capsule pairs are checked.

Each built-in arm ships capsules, per link in its DH frame, that enclose the real links
(sizes from the makers' drawings, rounded up). A capsule model is conservative: it reports
a distance no larger than the real one.
"""

from __future__ import annotations

import numpy as np

from trackplan.cell.model import Capsules
from trackplan.errors import CaseError
from trackplan.robots.model import Robot


def _capsules(rows: list[tuple[int, tuple[float, ...], tuple[float, ...], float]]) -> Capsules:
    return Capsules(
        frame=np.array([r[0] for r in rows]),
        segment=np.array([[r[1], r[2]] for r in rows]),
        radius=np.array([r[3] for r in rows]),
        name=tuple("base" if r[0] == 0 else f"link {r[0]}" for r in rows),
    )


def puma560_capsules() -> Capsules:
    """PUMA560 in the paper's DH frames (base frame at the shoulder, d1 = 0).

    Pedestal below the shoulder, the trunk and shoulder housing, the upper arm from the
    shoulder to the elbow beside the trunk (0.2435 m along the shoulder axis, the real arm's
    offset; the forearm comes back by 0.0934 m to the table's d3 = 0.15 m), the forearm up to
    the wrist, and the wrist around the wrist centre (the paper's TCP, frame 6).
    """
    return _capsules(
        [
            (0, (0.0, 0.0, -0.67), (0.0, 0.0, -0.22), 0.09),  # pedestal
            (1, (0.0, -0.22, 0.0), (0.0, 0.0, 0.0), 0.09),  # trunk (y1 is the base z axis)
            (1, (0.0, 0.0, -0.09), (0.0, 0.0, 0.2435), 0.09),  # shoulder housing on z1
            (2, (-0.4318, 0.0, 0.2435), (0.0, 0.0, 0.2435), 0.07),  # upper arm
            (2, (0.0, 0.0, 0.2435), (0.0, 0.0, 0.15), 0.06),  # elbow, back to the forearm
            (3, (0.0, 0.0, 0.0), (0.0, 0.0, 0.36), 0.05),  # forearm up to the wrist
            (6, (0.0, 0.0, -0.03), (0.0, 0.0, 0.0), 0.035),  # wrist around the wrist centre
        ]
    )


def ur5_capsules() -> Capsules:
    """UR5 (CB3) in its published DH frames.

    The links' offsets along the parallel joint axes 2-4 (0.13585 m shoulder, −0.1197 m
    elbow, 0.093 m wrist 1, summing to d4 = 0.10915 m) place the upper arm and forearm.
    """
    return _capsules(
        [
            (0, (0.0, 0.0, 0.0), (0.0, 0.0, 0.03), 0.075),  # base, below the shoulder
            (1, (0.0, 0.0, -0.02), (0.0, 0.0, 0.136), 0.075),  # shoulder on the z1 axis
            (2, (0.425, 0.0, 0.136), (0.0, 0.0, 0.136), 0.06),  # upper arm
            (2, (0.0, 0.0, 0.016), (0.0, 0.0, 0.136), 0.06),  # elbow along z2
            (3, (0.39225, 0.0, 0.016), (0.0, 0.0, 0.016), 0.05),  # forearm
            (3, (0.0, 0.0, 0.016), (0.0, 0.0, 0.10915), 0.04),  # wrist 1 along z3
            (4, (0.0, 0.0, 0.0), (0.0, 0.0, 0.09465), 0.04),  # wrist 2 along z4
            (5, (0.0, 0.0, 0.0), (0.0, 0.0, 0.06), 0.04),  # wrist 3 along z5
        ]
    )


BUILTIN_CAPSULES = {"puma560": puma560_capsules, "ur5": ur5_capsules}


def builtin_link_capsules(robot: Robot) -> Capsules:
    """The capsule model shipped for a built-in robot.

    Raises
    ------
    CaseError
        When the robot has no built-in capsule model (give ``cell.links`` in the case).
    """
    try:
        return BUILTIN_CAPSULES[robot.name.lower()]()
    except KeyError:
        known = ", ".join(sorted(BUILTIN_CAPSULES))
        raise CaseError(
            f"robot {robot.name!r} has no built-in capsule model (built-in: {known}); "
            "give its link capsules under cell.links",
            key="cell",
        ) from None


def self_collision_pairs(frame: np.ndarray) -> np.ndarray:
    """Capsule pairs checked for self-collision: bodies that are not neighbours in the chain.

    Bodies are the frames that carry capsules, in chain order; two bodies are neighbours
    when no other body lies between them (a wrist link without capsules does not separate
    the forearm from the flange).

    Parameters
    ----------
    frame
        Frame of each capsule, shape (K,), int.

    Returns
    -------
    numpy.ndarray
        Index pairs (i, j), i < j, shape (P, 2), int.
    """
    bodies = np.unique(frame)
    rank = np.searchsorted(bodies, frame)
    i, j = np.triu_indices(len(frame), k=1)
    keep = np.abs(rank[i] - rank[j]) > 1
    return np.stack([i[keep], j[keep]], axis=1).astype(np.int64)
