"""Reading the link inertials and joint effort limits of a URDF chain (yourdfpy).

Each link's ``<inertial>`` (mass, ``<origin>`` of the centre of mass and of the inertia's
axes, inertia about the centre of mass) is moved into the child frame of the moving joint
it rides on, which is the frame the inverse dynamics works in
(:mod:`trackplan.robots.dynamics_parameters`): a URDF link's frame is its parent joint's
frame, turned by the joint. Links fixed to that link (fixed joints, on or off the chain) are
merged into it by the parallel-axis theorem; links fixed to the base do not move and are left
out, as are links behind moving joints that are not on the chain. Effort limits come from
each moving joint's ``<limit effort=…>``; a missing or zero effort is no limit. See
``docs/dynamics.md``.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from trackplan.errors import CaseError
from trackplan.io.urdf import load_urdf_model
from trackplan.robots.dynamics_parameters import combine_bodies, inertia_problem


@dataclass(frozen=True, eq=False)
class URDFInertials:
    """The inertials and effort limits of a URDF chain, in the joints' child frames.

    Attributes
    ----------
    mass
        Mass riding on each moving joint, shape (n,), kg.
    com
        Its centre of mass in the joint's child frame, shape (n, 3), m.
    inertia
        Its inertia about the centre of mass, child-frame axes, shape (n, 3, 3), kg·m².
    effort
        ``<limit effort>`` of each moving joint, shape (n,), N·m; NaN where missing or 0.
    has_inertials
        Whether any link on the chain (past the first moving joint) has an ``<inertial>``.
    """

    mass: np.ndarray
    com: np.ndarray
    inertia: np.ndarray
    effort: np.ndarray
    has_inertials: bool


def read_urdf_inertials(
    file: str | Path, joint_names: tuple[str, ...], base_link: str | None = None
) -> URDFInertials:
    """Link inertials and effort limits of the chain of moving joints ``joint_names``.

    Parameters
    ----------
    file
        Path of the URDF (already read by :func:`~trackplan.io.urdf.read_urdf_chain`).
    joint_names
        The chain's moving joints, base to tip.
    base_link
        The chain's first link; default the URDF's root.

    Returns
    -------
    URDFInertials

    Raises
    ------
    CaseError
        For a negative or non-finite mass, an inertia that is not positive semi-definite or
        breaks the triangle inequality, or a negative effort; the error names the link or
        joint.
    """

    path = str(file)
    robot = load_urdf_model(path)
    joints = {joint.name: joint for joint in robot.joints}
    by_child = {joint.child: joint for joint in robot.joints}
    base = base_link or next(link.name for link in robot.links if link.name not in by_child)
    anchors = {joints[name].child: i for i, name in enumerate(joint_names)}
    anchors[base] = -1
    n = len(joint_names)
    bodies: list[list[tuple[float, np.ndarray, np.ndarray]]] = [[] for _ in range(n)]
    has_inertials = False
    for link in robot.links:
        frame, T_frame_link = _anchor(link.name, anchors, by_child)
        if frame is None or frame < 0 or link.inertial is None:
            continue
        has_inertials = True
        bodies[frame].append(_link_inertial(link, T_frame_link, path))
    mass, com, inertia = np.zeros(n), np.zeros((n, 3)), np.zeros((n, 3, 3))
    for i, parts in enumerate(bodies):
        if parts:
            mass[i], com[i], inertia[i] = combine_bodies(
                np.array([m for m, _, _ in parts]),
                np.array([c for _, c, _ in parts]),
                np.array([I for _, _, I in parts]),
            )
    effort = np.full(n, np.nan)
    for i, name in enumerate(joint_names):
        limit = joints[name].limit
        value = None if limit is None else limit.effort
        if value is None:
            continue
        if not (np.isfinite(value) and value >= 0):
            raise CaseError(
                f"joint {name!r} has effort limit {value}: give a torque limit >= 0 N·m "
                "(0 means none)",
                file=path,
            )
        if value > 0:
            effort[i] = float(value)
    return URDFInertials(mass, com, inertia, effort, has_inertials)


def _anchor(
    name: str, anchors: dict[str, int], by_child: dict[str, Any]
) -> tuple[int | None, np.ndarray]:
    """The chain frame a link is fixed to (-1 the base, None: none) and its pose in it."""
    T_frame_link = np.eye(4)
    while name not in anchors:
        joint = by_child.get(name)
        if joint is None or joint.type != "fixed":
            return None, T_frame_link
        origin = np.eye(4) if joint.origin is None else np.asarray(joint.origin, dtype=float)
        T_frame_link = origin @ T_frame_link
        name = joint.parent
    return anchors[name], T_frame_link


def _link_inertial(
    link: object, T_frame_link: np.ndarray, path: str
) -> tuple[float, np.ndarray, np.ndarray]:
    """A link's ``(mass, com, inertia)`` in the chain frame it is fixed to, checked."""
    inertial = link.inertial  # type: ignore[attr-defined]
    name = link.name  # type: ignore[attr-defined]
    mass = 0.0 if inertial.mass is None else float(inertial.mass)
    if not (np.isfinite(mass) and mass >= 0):
        raise CaseError(f"link {name!r} has mass {mass:g}: a mass must be >= 0 kg", file=path)
    inertia = np.zeros((3, 3)) if inertial.inertia is None else np.asarray(inertial.inertia)
    problem = inertia_problem(inertia)
    if problem:
        raise CaseError(f"link {name!r}: inertia {problem}", file=path)
    origin = np.eye(4) if inertial.origin is None else np.asarray(inertial.origin, dtype=float)
    T = T_frame_link @ origin
    R = T[:3, :3]
    return mass, T[:3, 3].copy(), R @ inertia @ R.T
