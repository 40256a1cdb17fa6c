"""trackplan: offline trajectory planning for industrial robots that follow a path.

Given a path (weld seam, glue bead, deburring edge), a speed and a tolerance, trackplan
plans the joint trajectory under the robot's position, velocity, acceleration and jerk
limits, and searches where to place the workpiece so the motion is feasible and cheap.

Public API
----------
load_case(file) -> Case
    Read and validate a case file (see ``docs/files.md``).
load_robot(file) -> Robot
    Read and validate a robot file.
builtin_robot(name) -> Robot, BUILTIN_ROBOTS
    The built-in robots (``puma560`` of the reference paper, ``ur5``).
Case, Robot
    The validated case and the robot model: frozen dataclasses of numpy arrays.
forward_kinematics(robot, q) -> T_base_tool
    Tool poses, q of shape (..., n) in rad, result (..., 4, 4).
jacobian(robot, q) -> J
    Geometric Jacobian at the tool point in the base frame, shape (..., 6, n).
CaseError, TrackplanError
    Bad input (with the file and key path), and the root of trackplan's exceptions.

Names are imported on first use, so ``import trackplan`` stays cheap and the
computational subpackages can be imported without the file-format dependencies.
"""

from __future__ import annotations

import importlib
from importlib.metadata import PackageNotFoundError, version
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from trackplan.case import Case
    from trackplan.errors import CaseError, TrackplanError
    from trackplan.io.case_file import load_case
    from trackplan.io.robot_file import load_robot
    from trackplan.robots.builtin import BUILTIN_ROBOTS, builtin_robot
    from trackplan.robots.kinematics import forward_kinematics, jacobian
    from trackplan.robots.model import Robot

try:
    __version__ = version("trackplan")
except PackageNotFoundError:  # running from a source tree that is not installed
    __version__ = "0+unknown"

_EXPORTS = {
    "BUILTIN_ROBOTS": "trackplan.robots.builtin",
    "Case": "trackplan.case",
    "CaseError": "trackplan.errors",
    "Robot": "trackplan.robots.model",
    "TrackplanError": "trackplan.errors",
    "builtin_robot": "trackplan.robots.builtin",
    "forward_kinematics": "trackplan.robots.kinematics",
    "jacobian": "trackplan.robots.kinematics",
    "load_case": "trackplan.io.case_file",
    "load_robot": "trackplan.io.robot_file",
}

__all__ = [
    "BUILTIN_ROBOTS",
    "Case",
    "CaseError",
    "Robot",
    "TrackplanError",
    "__version__",
    "builtin_robot",
    "forward_kinematics",
    "jacobian",
    "load_case",
    "load_robot",
]


def __getattr__(name: str) -> Any:
    """Import a public name on first use (PEP 562)."""
    module = _EXPORTS.get(name)
    if module is None:
        raise AttributeError(f"module 'trackplan' has no attribute {name!r}")
    value = getattr(importlib.import_module(module), name)
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    """Public names, for tab completion."""
    return sorted({*globals(), *_EXPORTS})
