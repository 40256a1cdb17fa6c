"""A robot's link capsules in the cell, and which capsule pairs are checked.

Each built-in arm ships capsules, per link in its link frame, that enclose the real links
(:mod:`trackplan.robots.collision`; sizes from the makers' drawings, rounded up). A capsule
model is conservative: it reports a distance no larger than the real one.
"""

from __future__ import annotations

import numpy as np

from trackplan.cell.model import Capsules
from trackplan.errors import CaseError
from trackplan.robots.model import Robot


def builtin_link_capsules(robot: Robot) -> Capsules:
    """The robot's own link capsules (:attr:`~trackplan.robots.model.Robot.collision`).

    Raises
    ------
    CaseError
        When the robot has no link geometry (give ``cell.links`` in the case, or
        ``collision`` in its robot file).
    """
    if robot.collision is None:
        raise CaseError(
            f"robot {robot.name!r} has no link capsules: give them under cell.links in the "
            "case or under collision in its robot file (docs/cell.md)",
            key="cell",
        )
    return robot.collision


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


def link_capsules_line(robot: Robot) -> str:
    """One line on the robot's link geometry, for ``trackplan robots NAME``.

    ``link capsules: 9 on 6 bodies; 23 capsule pairs of non-adjacent bodies checked for
    self-collision``, or what a cell case then needs.
    """
    if robot.collision is None:
        return "link capsules: none (a cell case must give cell.links)"
    frame = robot.collision.frame
    n_pairs = len(self_collision_pairs(frame))
    return (
        f"link capsules: {len(frame)} on {len(np.unique(frame))} bodies; {n_pairs} capsule "
        "pairs of non-adjacent bodies checked for self-collision"
    )
