"""Which robots a controller language drives, and the one-line refusal of the others.

A program writer drives its vendor's robots and generic ones (a robot file without a
``controller:`` vendor, or ``vendor: generic``), up to the language's number of robot
axes; every writer refuses the others with the same sentence (key ``--format``).
"""

from __future__ import annotations

from dataclasses import dataclass

from trackplan.errors import CaseError
from trackplan.programs.model import Program

NATIVE_FORMATS = {"kuka": "krl", "abb": "rapid", "fanuc": "fanuc", "ur": "urscript"}
"""The program format of each controller family."""

VENDOR_NAMES = {
    "kuka": "KUKA",
    "abb": "ABB",
    "fanuc": "FANUC",
    "ur": "Universal Robots",
    "generic": "generic",
}
"""Controller families as a sentence names them."""


@dataclass(frozen=True, kw_only=True)
class Drives:
    """What one program language drives.

    Attributes
    ----------
    format
        The ``--format`` name (``krl``).
    language
        The language's name in messages (``KRL``).
    vendors
        The controller families it drives (its own, and ``generic`` where it can).
    min_axes, max_axes
        The robot axes it drives.
    max_external
        The external axes (track, positioner) it writes.
    no_external
        Why it writes none (the refusal's reason), when ``max_external`` is 0.
    coordinated
        True when it moves the part frame with a positioner in path moves (coordinated
        motion); False refuses ``--motion cartesian`` with a positioner.
    """

    format: str
    language: str
    vendors: tuple[str, ...]
    min_axes: int = 6
    max_axes: int = 6
    max_external: int = 0
    no_external: str = ""
    coordinated: bool = False


def check_drivable(program: Program, drives: Drives) -> None:
    """Refuse a program whose robot the language does not drive.

    Raises
    ------
    CaseError
        One line, key ``--format``: the robot's controller family and the format that
        drives it, or its joint count and the formats that export any robot's joints.
    """
    if program.vendor not in drives.vendors:
        native = NATIVE_FORMATS.get(program.vendor)
        use = (
            f"use --format {native}"
            if native
            else f"give it a robot file whose controller: vendor is {drives.vendors[0]}"
        )
        names = " or ".join(VENDOR_NAMES.get(vendor, vendor) for vendor in drives.vendors)
        family = VENDOR_NAMES.get(program.vendor, program.vendor)
        article = "an" if family[:1] in "AEIOU" else "a"
        raise CaseError(
            f"{drives.language} drives {names} robots, and robot {program.robot!r} has "
            f"{article} {family} controller: {use}",
            key="--format",
        )
    if not drives.min_axes <= program.n_dof <= drives.max_axes:
        axes = (
            str(drives.max_axes)
            if drives.min_axes == drives.max_axes
            else f"{drives.min_axes} to {drives.max_axes}"
        )
        raise CaseError(
            f"{drives.language} drives {axes} robot axes, and robot {program.robot!r} has "
            f"{program.n_dof} joints: --format csv, json or ros export any robot's joints",
            key="--format",
        )
    check_external(program, drives)


def check_external(program: Program, drives: Drives) -> None:
    """Refuse a program whose external axes the language cannot write.

    Raises
    ------
    CaseError
        One line: a language that writes no external axes (key ``--format``), more
        external axes than it writes (key ``--format``), or a Cartesian program with a
        positioner in a language that writes no coordinated motion (key ``--motion``).
    """
    axes = program.external_axes
    if not axes:
        return
    listed = ", ".join(axis.name for axis in axes)
    if drives.max_external == 0:
        raise CaseError(
            f"{drives.language}: {drives.no_external or 'it writes no external axes'}, and "
            f"the case has {len(axes)} ({listed}): --format csv, json or ros export every "
            "axis",
            key="--format",
        )
    if len(axes) > drives.max_external:
        raise CaseError(
            f"{drives.language} writes at most {drives.max_external} external axes, and the "
            f"case has {len(axes)} ({listed}): --format csv, json or ros export every axis",
            key="--format",
        )
    if program.motion == "cartesian" and program.coordinated and not drives.coordinated:
        raise CaseError(
            f"{drives.language} programs here write no coordinated motion with a positioner "
            "(the path moves would not follow the turning part): use --motion joint",
            key="--motion",
        )


__all__ = ["NATIVE_FORMATS", "VENDOR_NAMES", "Drives", "check_drivable", "check_external"]
