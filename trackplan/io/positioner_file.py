"""Positioners: the built-in library and positioner files (``docs/positioner.md``).

A positioner's axes are a revolute serial chain, so a positioner is read as a
:class:`~trackplan.robots.model.Robot` by the robot-file reader: a positioner file has the
keys of a robot file that points at a URDF (``name``, ``urdf``, ``base_link``, ``tip_link``,
``limits`` with ``acceleration`` and ``jerk``, ``source``, ``assumptions``, ``collision``)::

    name: my-turntable
    urdf: turntable.urdf           # relative to this file
    base_link: base_link           # the positioner's base: its pose in the cell is the case's
    tip_link: tool0                # the flange: the carrier frame the part is placed on
    limits:
      acceleration: [10.0]         # rad/s², one per axis
      jerk: [100.0]                # rad/s³
    source: "where the numbers come from"

What a positioner cannot be is refused with one line: a DH robot file or a bare URDF (a
positioner file points at a URDF and states its acceleration and jerk), a ``tool`` (the
flange is the URDF's ``tip_link``), or more than :data:`MAX_POSITIONER_AXES` axes.

The built-in positioners are positioner files in the package data
(``trackplan/robots/library/positioners/``); ``trackplan positioners`` lists them.
"""

from __future__ import annotations

from pathlib import Path

from trackplan.errors import CaseError
from trackplan.io.robot_file import LIBRARY_DIR
from trackplan.io.robot_schema import ROBOT_FILE_SUFFIXES
from trackplan.io.urdf_robot import load_urdf_robot_file
from trackplan.io.yaml_input import parse_yaml, read_text
from trackplan.robots.model import Robot

POSITIONER_DIR = LIBRARY_DIR / "positioners"
"""Package data: one URDF and one positioner file per built-in positioner."""

MAX_POSITIONER_AXES = 3
"""Most axes of a positioner: the industrial ones have one to three (turntable, tilt-rotate,
a tilt-rotate on a turning arm); a longer chain is an arm, not a positioner."""

MODEL_KEY = "positioner.model"
"""The case file's key that names the positioner."""


def library_positioners() -> dict[str, Path]:
    """The built-in positioners: name → positioner file in the package data."""
    return {path.stem: path for path in sorted(POSITIONER_DIR.glob("*.yaml"))}


def positioner_names() -> tuple[str, ...]:
    """Names of every built-in positioner, sorted."""
    return tuple(library_positioners())


def load_positioner(file: str | Path, *, assume_limits: bool = False) -> Robot:
    """Read a positioner file: a robot file that points at a URDF (module docstring).

    Parameters
    ----------
    file
        Path of the positioner file (``.yaml``/``.yml``).
    assume_limits
        Fill missing acceleration and jerk limits by the robots' documented rule
        (``docs/robots.md``) instead of refusing the file; the chain records the assumption.

    Returns
    -------
    Robot
        The positioner's axes as a revolute chain; its flange (``T_tip``) is the carrier
        frame and it has no tool.

    Raises
    ------
    CaseError
        When the file is missing or unreadable, is not a robot file pointing at a URDF,
        gives a ``tool``, has more than :data:`MAX_POSITIONER_AXES` axes, or any value is
        wrong; the error names the file and the key.
    """
    name = str(file)
    if name.lower().endswith(".urdf"):
        raise CaseError(
            "a positioner is a positioner file (.yaml) that points at the URDF and gives "
            "its acceleration and jerk limits (docs/positioner.md), not a bare URDF",
            file=name,
        )
    text = read_text(file, what="positioner file")
    return _positioner_from_text(text, name, assume_limits)


def _positioner_from_text(text: str, file: str, assume_limits: bool) -> Robot:
    data = parse_yaml(text, file)
    if not isinstance(data, dict) or "urdf" not in data:
        raise CaseError(
            "a positioner file points at a URDF: give urdf, base_link, tip_link, limits "
            "(acceleration and jerk) and source (docs/positioner.md)",
            file=file,
            key="urdf",
        )
    if "tool" in data:
        raise CaseError(
            "a positioner has no tool: its flange, where the part is placed, is the URDF's "
            "tip_link",
            file=file,
            key="tool",
        )
    chain = load_urdf_robot_file(data, file, assume_limits)
    if chain.n_dof > MAX_POSITIONER_AXES:
        raise CaseError(
            f"a positioner has 1 to {MAX_POSITIONER_AXES} axes, this chain has {chain.n_dof} "
            f"({', '.join(chain.joint_names)}): choose base_link and tip_link around its axes",
            file=file,
            key="tip_link",
        )
    return chain


def builtin_positioner(name: str) -> Robot:
    """The built-in positioner called ``name`` (``trackplan positioners`` lists them).

    Raises
    ------
    CaseError
        When no built-in positioner has that name.
    """
    library = library_positioners()
    key = name.lower()
    if key not in library:
        raise CaseError(
            f"unknown positioner {name!r}: use one of {', '.join(library)} or a path to a "
            "positioner file (.yaml)",
            key=MODEL_KEY,
        )
    return load_positioner(library[key])


def is_positioner_file(model: str) -> bool:
    """True when a case file's ``positioner.model`` names a file rather than a built-in
    positioner: it ends in ``.yaml``, ``.yml`` or ``.urdf`` or holds a path separator."""
    return model.lower().endswith(ROBOT_FILE_SUFFIXES) or any(
        separator in model for separator in ("/", "\\")
    )


def load_positioner_spec(
    model: str, base_dir: str | Path, *, case_file: str | None, assume_limits: bool = False
) -> Robot:
    """The positioner a case file names: a built-in positioner or a positioner file.

    Parameters
    ----------
    model
        A built-in name (``two-axis-500``) or the path of a positioner file, relative to
        ``base_dir`` unless absolute.
    base_dir
        The folder of the case file.
    case_file
        The case file, so that an unknown name or a missing file is reported at its
        ``positioner.model`` key.
    assume_limits
        As for :func:`load_positioner`.

    Raises
    ------
    CaseError
        For an unknown name, a missing file (at the case's key), or a problem inside the
        positioner file (reported against that file).
    """
    if not is_positioner_file(model):
        try:
            return builtin_positioner(model)
        except CaseError as exc:
            raise CaseError(exc.message, file=case_file, key=MODEL_KEY) from None
    path = Path(base_dir) / model
    if model.lower().endswith(".urdf"):
        raise CaseError(
            f"{model}: a positioner is a positioner file (.yaml) that points at the URDF and "
            "gives its acceleration and jerk limits (docs/positioner.md)",
            file=case_file,
            key=MODEL_KEY,
        )
    text = read_text(path, what="positioner file", referrer=case_file, key=MODEL_KEY)
    return _positioner_from_text(text, str(path), assume_limits)
