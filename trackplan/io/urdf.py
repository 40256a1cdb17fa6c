"""Reading a serial chain from a URDF file (yourdfpy).

The chain runs from ``base_link`` (default: the URDF's root link) to ``tip_link``
(default: the single leaf of the tree). Fixed joints are folded into the next joint's
origin, or into the flange transform after the last moving joint. Revolute and
continuous joints are supported; continuous joints get the range
``[−continuous_range, continuous_range]``. Prismatic, floating and planar joints, and
mimic joints, are refused with a clear error. See ``docs/robots.md``.

The links' collision geometry is read by :mod:`trackplan.io.urdf_geometry`.
"""

from __future__ import annotations

import logging
import math
import re
import stat
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from trackplan.errors import CaseError
from trackplan.io.robot_bounds import (
    MAX_ANGLE,
    MAX_INERTIA,
    MAX_LENGTH,
    MAX_MASS,
    MAX_MESH_SCALE,
    MAX_RATE,
    MAX_TORQUE,
    MIN_RATE,
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


@contextmanager
def _quiet(*names: str) -> Iterator[None]:
    """These libraries' logs silenced (yourdfpy, trimesh): a log line would be a second line
    beside our one, printed by Python's last-resort handler."""
    loggers = [logging.getLogger(name) for name in names]
    levels = [logger.level for logger in loggers]
    for logger in loggers:
        logger.setLevel(logging.CRITICAL)
    try:
        yield
    finally:
        for logger, level in zip(loggers, levels, strict=True):
            logger.setLevel(level)


def load_urdf_model(path: str) -> Any:
    """yourdfpy's parsed robot model of a URDF (no meshes, no scene graph), its log quiet.

    Raises whatever yourdfpy raises on a file it cannot parse; :func:`check_urdf_xml`
    checks the file strictly first.
    """
    import yourdfpy

    with _quiet("yourdfpy"):
        return yourdfpy.URDF.load(
            path, build_scene_graph=False, load_meshes=False, load_collision_meshes=False
        ).robot


MIN_AXIS_LENGTH = 1e-6
"""Shortest joint axis (any length is normalised): a shorter one is refused as zero."""

MOVING = ("revolute", "continuous")
"""Joint types whose axis and velocity limit trackplan uses."""

# (tag, attribute) → (count, low, high, unit): the numbers an attribute holds and their range;
# the velocity of moving joints is checked apart.
_NUMBERS: dict[tuple[str, str], tuple[int, float, float, str]] = {
    ("origin", "xyz"): (3, -MAX_LENGTH, MAX_LENGTH, "m"),
    ("origin", "rpy"): (3, -MAX_ANGLE, MAX_ANGLE, "rad"),
    ("axis", "xyz"): (3, -MAX_LENGTH, MAX_LENGTH, ""),
    ("limit", "lower"): (1, -MAX_ANGLE, MAX_ANGLE, "rad"),
    ("limit", "upper"): (1, -MAX_ANGLE, MAX_ANGLE, "rad"),
    ("limit", "velocity"): (1, 0.0, MAX_RATE, "rad/s"),
    ("limit", "effort"): (1, 0.0, MAX_TORQUE, "N·m"),
    ("mass", "value"): (1, 0.0, MAX_MASS, "kg"),
    ("box", "size"): (3, 0.0, MAX_LENGTH, "m"),
    ("cylinder", "radius"): (1, 0.0, MAX_LENGTH, "m"),
    ("cylinder", "length"): (1, 0.0, MAX_LENGTH, "m"),
    ("sphere", "radius"): (1, 0.0, MAX_LENGTH, "m"),
    ("mesh", "scale"): (3, -MAX_MESH_SCALE, MAX_MESH_SCALE, ""),
    **{
        ("inertia", name): (1, -MAX_INERTIA, MAX_INERTIA, "kg·m²")
        for name in ("ixx", "ixy", "ixz", "iyy", "iyz", "izz")
    },
}


def check_urdf_xml(path: str) -> None:
    """Check a URDF strictly before yourdfpy reads it (yourdfpy recovers from broken XML).

    - The file is well-formed XML (lxml's strict parser: an unquoted attribute, an unclosed
      element are errors), with a ``<robot>`` root.
    - No two links and no two joints share a name.
    - Every number attribute that trackplan reads (origins, axes, limits, masses, inertias,
      shape sizes, mesh scales) holds the right count of finite numbers within its range
      (:mod:`trackplan.io.robot_bounds`); a revolute or continuous joint's axis is at least
      :data:`MIN_AXIS_LENGTH` long and its velocity limit at least
      :data:`~trackplan.io.robot_bounds.MIN_RATE`.

    Raises
    ------
    CaseError
        The first problem, naming the line, the element (its joint or link) and the attribute.
    """
    from lxml import etree

    parser = etree.XMLParser(resolve_entities=False, no_network=True, remove_comments=True)
    try:
        root = etree.parse(path, parser).getroot()
    except etree.XMLSyntaxError as exc:
        line, column = exc.position
        text = str(exc.msg).splitlines()[0] if str(exc.msg) else type(exc).__name__
        message = re.sub(r", line \d+, column \d+$", "", text).strip()
        raise CaseError(
            f"not well-formed XML at line {line}, column {column}: {message}", file=path
        ) from None
    except OSError as exc:
        raise CaseError(f"cannot read the URDF: {exc}".splitlines()[0], file=path) from None
    if root.tag != "robot":
        raise CaseError(
            f"line {root.sourceline}: expected a <robot> root element, got <{root.tag}>",
            file=path,
        )
    for tag in ("link", "joint"):
        first: dict[str, int] = {}
        for element in root.iterchildren(tag):
            name = element.get("name")
            if name in first:
                raise CaseError(
                    f"line {element.sourceline}: {tag} name {name!r} is given twice (first at "
                    f"line {first[name]}): {tag} names must be unique",
                    file=path,
                )
            first[str(name)] = int(element.sourceline or 0)
    for joint in root.iterchildren("joint"):
        if joint.get("type") in MOVING:
            _check_moving_joint(joint, path)
    for element in root.iter():
        for attribute, text in element.attrib.items():
            rule = _NUMBERS.get((str(element.tag), str(attribute)))
            if rule is not None:
                _check_numbers(element, str(attribute), str(text), rule, path)


def _where(element: Any, attribute: str) -> str:
    """``line 12: joint 'j1' <limit velocity>``: where an attribute is, for messages."""
    tags = []
    owner = element
    while owner is not None and owner.tag not in ("joint", "link", "robot"):
        if owner.tag != "geometry":
            tags.append(f"<{owner.tag}>")
        owner = owner.getparent()
    tags.reverse()
    tags[-1] = f"<{element.tag} {attribute}>"
    whose = "" if owner is None or owner.tag == "robot" else f"{owner.tag} {owner.get('name')!r} "
    return f"line {element.sourceline}: {whose}{' '.join(tags)}"


def _shown(text: str, limit: int = 60) -> str:
    """An attribute's text for a message, at most ``limit`` characters."""
    return text if len(text) <= limit else text[: limit - 1] + "…"


def _numbers(text: str) -> list[float] | None:
    try:
        return [float(word) for word in text.split()]
    except ValueError:
        return None


def _check_numbers(
    element: Any, attribute: str, text: str, rule: tuple[int, float, float, str], path: str
) -> None:
    count, low, high, unit = rule
    values = _numbers(text)
    shown = _shown(text)
    what = "a number" if count == 1 else f"{count} numbers"
    unit = f" {unit}" if unit else ""
    if values is None or len(values) != count:
        raise CaseError(f"{_where(element, attribute)}: expected {what}, got {shown!r}", file=path)
    if not all(low <= value <= high for value in values):  # NaN fails too
        within = f"within ±{high:g}" if low == -high else f"in [{low:g}, {high:g}]"
        raise CaseError(
            f"{_where(element, attribute)}: expected {what} {within}{unit}, got {shown!r}",
            file=path,
        )


def _check_moving_joint(joint: Any, path: str) -> None:
    """A revolute or continuous joint's axis is not (nearly) zero, and its velocity limit is
    at least :data:`~trackplan.io.robot_bounds.MIN_RATE`."""
    axis = joint.find("axis")
    if axis is not None and axis.get("xyz") is not None:
        values = _numbers(str(axis.get("xyz")))
        if values is not None and len(values) == 3 and math.hypot(*values) < MIN_AXIS_LENGTH:
            raise CaseError(
                f"{_where(axis, 'xyz')}: expected a joint axis of length ≥ {MIN_AXIS_LENGTH:g}, "
                f"got {_shown(str(axis.get('xyz')))!r}",
                file=path,
            )
    limit = joint.find("limit")
    velocity = None if limit is None else limit.get("velocity")
    values = None if velocity is None else _numbers(velocity)
    if values is not None and len(values) == 1 and not values[0] >= MIN_RATE:
        raise CaseError(
            f"{_where(limit, 'velocity')}: expected a number in [{MIN_RATE:g}, {MAX_RATE:g}] "
            f"rad/s, got {_shown(str(velocity))!r}",
            file=path,
        )


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
    check_urdf_xml(path)
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


def file_kind(file: Path) -> str | None:
    """Why ``file`` is no mesh file: "not found", "is a directory, not a regular file", …;
    None for a regular file."""
    try:
        mode = file.stat().st_mode
    except OSError:
        return "not found"
    if stat.S_ISREG(mode):
        return None
    kinds = (
        (stat.S_ISDIR, "a directory"),
        (stat.S_ISCHR, "a character device"),
        (stat.S_ISBLK, "a block device"),
        (stat.S_ISFIFO, "a named pipe"),
        (stat.S_ISSOCK, "a socket"),
    )
    what = next((text for test, text in kinds if test(mode)), "a special file")
    return f"is {what}, not a regular file"
