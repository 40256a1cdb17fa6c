"""Reading a serial chain from a URDF file (yourdfpy), and its links' collision geometry.

The chain runs from ``base_link`` (default: the URDF's root link) to ``tip_link``
(default: the single leaf of the tree). Fixed joints are folded into the next joint's
origin, or into the flange transform after the last moving joint. Revolute and
continuous joints are supported; continuous joints get the range
``[−continuous_range, continuous_range]``. Prismatic, floating and planar joints, and
mimic joints, are refused with a clear error. See ``docs/robots.md``.

:func:`read_urdf_link_geometry` maps every link onto the chain's frames and fits each
``<collision>`` element with an enclosing capsule; only it loads collision meshes
(``docs/cell.md``).
"""

from __future__ import annotations

import logging
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from trackplan.errors import CaseError
from trackplan.robots.collision import (
    Capsules,
    box_capsule,
    cylinder_capsule,
    points_capsule,
    sphere_capsule,
    transform_capsule,
)

DEFAULT_CONTINUOUS_RANGE = 2 * np.pi
"""Half range of a continuous joint, rad: [−2π, 2π] unless a robot file says otherwise."""


@dataclass(frozen=True, eq=False)
class URDFChain:
    """The moving joints of a URDF chain, base to tip.

    Attributes
    ----------
    name
        The URDF's robot name.
    joint_names
        Names of the n moving joints.
    origins
        Shape (n, 4, 4): each joint's fixed transform from the previous joint's frame
        (fixed joints before it folded in), m.
    axes
        Shape (n, 3): unit joint axes in the joint frames.
    q_min, q_max
        Position limits, shape (n,), rad.
    v_max
        Velocity limits, shape (n,), rad/s (NaN where the URDF gives none).
    T_tip
        Fixed transform from the last joint's frame to the tip link, shape (4, 4).
    """

    name: str
    joint_names: tuple[str, ...]
    origins: np.ndarray
    axes: np.ndarray
    q_min: np.ndarray
    q_max: np.ndarray
    v_max: np.ndarray
    T_tip: np.ndarray


def load_urdf_model(path: str) -> Any:
    """yourdfpy's parsed robot model of a URDF (no meshes, no scene graph), its log quiet.

    Raises whatever yourdfpy raises on a file it cannot parse.
    """
    import yourdfpy

    logger = logging.getLogger("yourdfpy")
    level = logger.level
    logger.setLevel(logging.CRITICAL)
    try:
        return yourdfpy.URDF.load(
            path, build_scene_graph=False, load_meshes=False, load_collision_meshes=False
        ).robot
    finally:
        logger.setLevel(level)


def read_urdf_chain(
    file: str | Path,
    base_link: str | None = None,
    tip_link: str | None = None,
    *,
    continuous_range: float = DEFAULT_CONTINUOUS_RANGE,
    referrer: str | None = None,
) -> URDFChain:
    """The serial chain of a URDF between two links.

    Parameters
    ----------
    file
        Path of the URDF.
    base_link, tip_link
        The chain's first and last link; default the root and the single leaf.
    continuous_range
        Half range given to continuous joints, rad.
    referrer
        The robot file that names the URDF, for error messages about the link names.

    Returns
    -------
    URDFChain

    Raises
    ------
    CaseError
        When the file is missing or malformed, a named link does not exist, the tree
        branches and no tip link is named, or the chain holds a mimic, prismatic,
        planar or floating joint.
    """

    path = str(file)
    if not Path(path).is_file():
        raise CaseError("URDF file not found", file=path)
    try:
        robot = load_urdf_model(path)
    except Exception as exc:  # yourdfpy raises whatever its XML parsing meets
        raise CaseError(
            f"not a valid URDF ({type(exc).__name__}: {exc}): check the XML against the URDF "
            "specification",
            file=path,
        ) from None
    links = {link.name for link in robot.links}
    by_child = {}
    children: dict[str, list[str]] = {name: [] for name in links}
    for joint in robot.joints:
        if joint.parent not in links or joint.child not in links:
            raise CaseError(
                f"joint {joint.name!r} connects links that are not defined "
                f"({joint.parent!r} → {joint.child!r})",
                file=path,
            )
        by_child[joint.child] = joint
        children[joint.parent].append(joint.child)
    roots = sorted(links - set(by_child))
    if len(roots) != 1:
        raise CaseError(f"a URDF must have one root link, found {roots}", file=path)
    key_file = referrer or path
    for key, link in (("base_link", base_link), ("tip_link", tip_link)):
        if link is not None and link not in links:
            known = ", ".join(sorted(links))
            raise CaseError(
                f"the URDF has no link {link!r}: use one of {known}", file=key_file, key=key
            )
    base = base_link or roots[0]
    if tip_link is None:
        leaves = sorted(name for name, below in children.items() if not below)
        if len(leaves) != 1:
            raise CaseError(
                f"the URDF is a branching tree (leaves {', '.join(leaves)}): name the chain's "
                "end with tip_link in a robot file",
                file=path,
            )
        tip_link = leaves[0]
    chain = []
    link = tip_link
    while link != base:
        joint = by_child.get(link)
        if joint is None:
            raise CaseError(
                f"link {tip_link!r} does not descend from {base!r}: choose base_link and "
                "tip_link on one chain",
                file=key_file,
                key="tip_link",
            )
        chain.append(joint)
        link = joint.parent
    chain.reverse()
    names: list[str] = []
    origins: list[np.ndarray] = []
    axes: list[np.ndarray] = []
    limits: list[tuple[float, float, float]] = []
    pending = np.eye(4)
    for joint in chain:
        origin = np.eye(4) if joint.origin is None else np.asarray(joint.origin, dtype=float)
        if joint.mimic is not None:
            raise CaseError(
                f"joint {joint.name!r} is a mimic joint, which trackplan does not support: "
                "remove it from the chain or make it fixed",
                file=path,
            )
        if joint.type == "fixed":
            pending = pending @ origin
            continue
        if joint.type not in ("revolute", "continuous"):
            raise CaseError(
                f"joint {joint.name!r} is {joint.type}: trackplan supports revolute and "
                "continuous joints only",
                file=path,
            )
        axis = np.array([1.0, 0.0, 0.0] if joint.axis is None else joint.axis, dtype=float)
        if not np.linalg.norm(axis) > 0.0:
            raise CaseError(f"joint {joint.name!r} has a zero axis", file=path)
        limit = joint.limit
        velocity = np.nan if limit is None or limit.velocity is None else float(limit.velocity)
        if joint.type == "continuous":
            low, high = -continuous_range, continuous_range
        elif limit is None or limit.lower is None or limit.upper is None:
            raise CaseError(
                f"revolute joint {joint.name!r} has no lower/upper limit: add "
                '<limit lower="…" upper="…" velocity="…" effort="…"/>',
                file=path,
            )
        else:
            low, high = float(limit.lower), float(limit.upper)
            if not low < high:
                raise CaseError(f"joint {joint.name!r} has lower {low} ≥ upper {high}", file=path)
        names.append(joint.name)
        origins.append(pending @ origin)
        axes.append(axis / np.linalg.norm(axis))
        limits.append((low, high, velocity))
        pending = np.eye(4)
    if not names:
        raise CaseError(f"the chain {base!r} → {tip_link!r} has no moving joint", file=path)
    table = np.array(limits)
    return URDFChain(
        name=robot.name,
        joint_names=tuple(names),
        origins=np.array(origins),
        axes=np.array(axes),
        q_min=table[:, 0],
        q_max=table[:, 1],
        v_max=table[:, 2],
        T_tip=pending,
    )


@dataclass(frozen=True, eq=False)
class URDFLinkGeometry:
    """Where a URDF's links sit on the chain, and their collision geometry as capsules.

    Attributes
    ----------
    link_frames
        Link name → (frame, ``T_frame_link``): the chain frame the link moves with (0 the
        base link, i the child link of the i-th moving joint; see
        :func:`trackplan.robots.kinematics.joint_frames`) and the link's fixed pose in it,
        shape (4, 4). Only links on the chain or fixed to it appear.
    capsules
        One capsule per ``<collision>`` element of those links, enclosing its box,
        cylinder, sphere or mesh, in the chain frame; named after the link.
    """

    link_frames: dict[str, tuple[int, np.ndarray]]
    capsules: Capsules


def read_urdf_link_geometry(
    file: str | Path,
    joint_names: tuple[str, ...],
    base_link: str | None = None,
    *,
    collisions: bool = True,
) -> URDFLinkGeometry:
    """The chain frames of a URDF's links and capsules enclosing their ``<collision>`` shapes.

    A link belongs to frame i when fixed joints alone connect it to the child link of the
    chain's i-th moving joint (or to the base link, frame 0). Boxes, cylinders and spheres
    are fitted in closed form, meshes (read by trimesh, only here) from their vertices
    (:mod:`trackplan.robots.collision`).

    Parameters
    ----------
    file
        Path of the URDF.
    joint_names
        The chain's moving joints, base to tip (:attr:`URDFChain.joint_names`).
    base_link
        The chain's base link; default the root.
    collisions
        Read the ``<collision>`` elements (False: only the link frames).

    Returns
    -------
    URDFLinkGeometry

    Raises
    ------
    CaseError
        When a collision mesh is missing or cannot be read, or a shape has a size ≤ 0.
    """

    path = str(file)
    robot = load_urdf_model(path)
    by_child = {joint.child: joint for joint in robot.joints}
    base = base_link or next(link.name for link in robot.links if link.name not in by_child)
    anchors = {base: 0}
    for i, name in enumerate(joint_names):
        anchors[next(j.child for j in robot.joints if j.name == name)] = i + 1
    link_frames: dict[str, tuple[int, np.ndarray]] = {}
    for link in robot.links:
        T_anchor_link = np.eye(4)
        name = link.name
        while name not in anchors:
            joint = by_child.get(name)
            if joint is None or joint.type != "fixed":
                break
            origin = np.eye(4) if joint.origin is None else np.asarray(joint.origin, float)
            T_anchor_link = origin @ T_anchor_link
            name = joint.parent
        else:
            link_frames[link.name] = (anchors[name], T_anchor_link)
    frames, segments, radii, names = [], [], [], []
    for link in robot.links if collisions else ():
        if link.name not in link_frames:
            continue
        frame, T_frame_link = link_frames[link.name]
        for collision in link.collisions:
            segment, radius = _collision_capsule(collision, link.name, path)
            T_link_shape = (
                np.eye(4) if collision.origin is None else np.asarray(collision.origin, float)
            )
            frames.append(frame)
            segments.append(transform_capsule(segment, T_frame_link @ T_link_shape))
            radii.append(radius)
            names.append(link.name)
    capsules = Capsules(
        np.array(frames, dtype=np.int64), np.array(segments), np.array(radii), tuple(names)
    )
    return URDFLinkGeometry(link_frames, capsules)


def _collision_capsule(collision: Any, link: str, path: str) -> tuple[np.ndarray, float]:
    """The enclosing capsule of one ``<collision>`` element, in its own frame."""
    geometry = collision.geometry
    where = f"link {link!r} <collision>"
    if geometry is None:
        raise CaseError(f"{where} has no geometry", file=path)
    if geometry.box is not None:
        size = np.asarray(geometry.box.size, dtype=float)
        _positive(size, f"{where} box size", path)
        return box_capsule(0.5 * size)
    if geometry.cylinder is not None:
        cylinder = geometry.cylinder
        _positive(
            np.array([cylinder.radius, cylinder.length]), f"{where} cylinder radius, length", path
        )
        return cylinder_capsule(float(cylinder.radius), float(cylinder.length))
    if geometry.sphere is not None:
        _positive(np.array([geometry.sphere.radius]), f"{where} sphere radius", path)
        return sphere_capsule(float(geometry.sphere.radius))
    if geometry.mesh is not None:
        return points_capsule(_mesh_vertices(geometry.mesh, where, path))
    raise CaseError(f"{where} has no box, cylinder, sphere or mesh", file=path)


def _positive(values: np.ndarray, what: str, path: str) -> None:
    if not np.all(np.isfinite(values)) or np.any(values <= 0):
        raise CaseError(f"{what} must be > 0 m, got {values.tolist()}", file=path)


def _mesh_vertices(mesh: Any, where: str, path: str) -> np.ndarray:
    """The scaled vertices of a collision mesh (package:// and relative names resolved)."""
    import trimesh
    import yourdfpy

    name = yourdfpy.filename_handler_magic(mesh.filename, dir=str(Path(path).parent))
    if not Path(name).is_file():
        raise CaseError(f"{where} mesh {mesh.filename!r} not found", file=path)
    try:
        loaded = trimesh.load(name, force="mesh")
        vertices = np.asarray(getattr(loaded, "vertices"), dtype=float).reshape(-1, 3)  # noqa: B009
    except Exception as exc:  # trimesh raises whatever its format readers meet
        reason = str(exc).splitlines()[0] if str(exc) else type(exc).__name__
        raise CaseError(
            f"{where} mesh {mesh.filename!r} cannot be read as a mesh: {reason}", file=path
        ) from None
    if len(vertices) == 0:
        raise CaseError(
            f"{where} mesh {mesh.filename!r} cannot be read as a mesh: no vertices found "
            "(expected STL, OBJ, PLY, …)",
            file=path,
        )
    scale = np.ones(3) if mesh.scale is None else np.asarray(mesh.scale, dtype=float)
    return np.asarray(vertices * scale)
