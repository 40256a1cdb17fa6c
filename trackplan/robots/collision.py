"""Link geometry of a robot: capsules on the chain's frames, and capsules that enclose shapes.

A robot carries its link capsules (:attr:`trackplan.robots.model.Robot.collision`), each
in the frame of the link it moves with (:func:`trackplan.robots.kinematics.joint_frames`
numbers them: 0 the base, i the link of joint i). They come from the ``collision:`` key of a
robot file, from a URDF's ``<collision>`` elements (each fitted with an enclosing capsule by
the functions here), or from the built-in models below (``docs/cell.md``).

Every fit encloses its shape: a capsule model is conservative, the distance it reports is
never larger than the real one.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True, eq=False)
class Capsules:
    """Capsules attached to the frames of a chain (robot links, tool).

    Attributes
    ----------
    frame
        Index of the frame each capsule moves with, shape (K,), int: 0 the robot base,
        i the frame of link i (1..n), n + 1 the TCP (see
        :func:`trackplan.robots.kinematics.joint_frames`).
    segment
        End points of each capsule's axis in its frame, shape (K, 2, 3), m.
    radius
        Shape (K,), m.
    name
        Name of each capsule for reports (``link 3``, ``tool``), length K.
    """

    frame: np.ndarray
    segment: np.ndarray
    radius: np.ndarray
    name: tuple[str, ...]

    def __post_init__(self) -> None:
        for key, dtype in (("frame", np.int64), ("segment", float), ("radius", float)):
            value = np.array(getattr(self, key), dtype=dtype)
            value.flags.writeable = False
            object.__setattr__(self, key, value)
        object.__setattr__(self, "segment", self.segment.reshape(-1, 2, 3))
        object.__setattr__(self, "name", tuple(self.name))

    @classmethod
    def empty(cls) -> Capsules:
        """No capsule."""
        return cls(np.zeros(0, np.int64), np.zeros((0, 2, 3)), np.zeros(0), ())

    def __len__(self) -> int:
        return len(self.radius)

    def __add__(self, other: Capsules) -> Capsules:
        return Capsules(
            np.concatenate([self.frame, other.frame]),
            np.concatenate([self.segment, other.segment]),
            np.concatenate([self.radius, other.radius]),
            self.name + other.name,
        )


def frame_name(frame: int) -> str:
    """The report name of a capsule given by its frame number: ``base`` or ``link i``."""
    return "base" if frame == 0 else f"link {frame}"


def box_capsule(half: np.ndarray) -> tuple[np.ndarray, float]:
    """The capsule that encloses a box, along its longest axis.

    Its radius is the half diagonal of the box's cross-section across that axis and its
    axis spans the box's length along it: every corner lies on the capsule's cylinder.

    Parameters
    ----------
    half
        Half extents of a box centred at the origin of its frame, shape (3,), m.

    Returns
    -------
    segment
        Axis end points in the box frame, shape (2, 3), m.
    radius
        m.
    """
    half = np.abs(np.asarray(half, dtype=float))
    axis = int(np.argmax(half))
    across = np.delete(half, axis)
    segment = np.zeros((2, 3))
    segment[0, axis], segment[1, axis] = -half[axis], half[axis]
    return segment, float(np.hypot(*across))


def cylinder_capsule(radius: float, length: float) -> tuple[np.ndarray, float]:
    """The capsule that encloses a cylinder along z, centred at the origin of its frame.

    A cylinder at least as long as its diameter gets its own axis and radius; a flatter one
    (a disc) the sphere through its rims.

    Parameters
    ----------
    radius, length
        Cylinder radius and full length, m.

    Returns
    -------
    segment
        Axis end points in the cylinder frame, shape (2, 3), m.
    radius
        m.
    """
    half = 0.5 * length
    if length >= 2.0 * radius:
        return np.array([[0.0, 0.0, -half], [0.0, 0.0, half]]), float(radius)
    return np.zeros((2, 3)), float(np.hypot(radius, half))


def sphere_capsule(radius: float) -> tuple[np.ndarray, float]:
    """The capsule of a sphere centred at the origin of its frame: a point and its radius."""
    return np.zeros((2, 3)), float(radius)


def points_capsule(points: np.ndarray) -> tuple[np.ndarray, float]:
    """A capsule that encloses a point cloud (a mesh's vertices, hence the mesh).

    The axis is the cloud's principal axis through its centroid. The radius is the
    smallest that holds every point's distance from that line; the end points are then
    the closest pair along the axis with every point within the radius of the segment
    (point k at axial position t_k and distance ρ_k from the axis needs the segment to
    reach ``t_k ∓ sqrt(r² − ρ_k²)``). A capsule is convex, so it encloses the points'
    convex hull, and with it the mesh.

    Parameters
    ----------
    points
        Shape (V, 3), V ≥ 1, m.

    Returns
    -------
    segment
        Axis end points in the points' frame, shape (2, 3), m.
    radius
        m.
    """
    points = np.asarray(points, dtype=float).reshape(-1, 3)
    centre = points.mean(axis=0)
    offsets = points - centre
    _, _, vt = np.linalg.svd(offsets, full_matrices=False)
    axis = vt[0]
    t = offsets @ axis
    rho = np.linalg.norm(offsets - t[:, None] * axis, axis=1)
    radius = float(rho.max())
    reach = np.sqrt(np.maximum(radius**2 - rho**2, 0.0))
    low, high = float(np.min(t + reach)), float(np.max(t - reach))
    if low > high:  # every point fits around one point of the axis
        low = high = 0.5 * (low + high)
    return centre + np.outer([low, high], axis), radius


def transform_capsule(segment: np.ndarray, T_frame_local: np.ndarray) -> np.ndarray:
    """Capsule end points (2, 3) in a local frame, expressed in the frame ``T_frame_local``
    (4, 4) is given in."""
    segment = np.asarray(segment, dtype=float)
    moved: np.ndarray = segment @ T_frame_local[:3, :3].T + T_frame_local[:3, 3]
    return moved


def _capsules(rows: list[tuple[int, tuple[float, ...], tuple[float, ...], float]]) -> Capsules:
    return Capsules(
        frame=np.array([r[0] for r in rows]),
        segment=np.array([[r[1], r[2]] for r in rows]),
        radius=np.array([r[3] for r in rows]),
        name=tuple(frame_name(r[0]) for r in rows),
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
    elbow, 0.093 m wrist 1, summing to d4 = 0.10915 m) place the upper arm and forearm. The
    upper arm tube (0.05 m) passes the base (0.075 m) 11 mm apart when it swings down.
    """
    return _capsules(
        [
            (0, (0.0, 0.0, 0.0), (0.0, 0.0, 0.03), 0.075),  # base, below the shoulder
            (1, (0.0, 0.0, -0.02), (0.0, 0.0, 0.136), 0.075),  # shoulder on the z1 axis
            (2, (0.425, 0.0, 0.136), (0.0, 0.0, 0.136), 0.05),  # upper arm tube
            (2, (0.0, 0.0, 0.016), (0.0, 0.0, 0.136), 0.06),  # elbow along z2
            (3, (0.39225, 0.0, 0.016), (0.0, 0.0, 0.016), 0.05),  # forearm
            (3, (0.0, 0.0, 0.016), (0.0, 0.0, 0.10915), 0.04),  # wrist 1 along z3
            (4, (0.0, 0.0, 0.0), (0.0, 0.0, 0.09465), 0.04),  # wrist 2 along z4
            (5, (0.0, 0.0, 0.0), (0.0, 0.0, 0.06), 0.04),  # wrist 3 along z5
        ]
    )
