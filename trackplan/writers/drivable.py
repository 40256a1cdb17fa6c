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
    """

    format: str
    language: str
    vendors: tuple[str, ...]
    min_axes: int = 6
    max_axes: int = 6


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


__all__ = ["NATIVE_FORMATS", "VENDOR_NAMES", "Drives", "check_drivable"]
