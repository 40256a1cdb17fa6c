"""trackplan: offline trajectory planning for industrial robots that follow a path.

Given a path (weld seam, glue bead, deburring edge), a speed and a tolerance, trackplan
plans the joint trajectory under the robot's position, velocity, acceleration and jerk
limits, and searches where to place the workpiece so the motion is feasible and cheap.

The front door (``docs/api.md``)
--------------------------------
load_case(file) -> Case, load_robot(file) -> Robot, builtin_robot(name) -> Robot
    Read and validate a case or robot file; the built-in robots (``docs/robots.md``).
load_positioner(file) -> Robot, builtin_positioner(name) -> Robot
    Read a positioner file; the built-in positioners (``docs/positioner.md``).
load_part(file) -> PartModel
    Read a part's CAD model, STEP or mesh: its faces and edges (``docs/cad.md``).
plan(case, X, ...) -> PlanResult
    Plan and check a case (one seam or several) with the workpiece at placement X
    (shape (6,), m and rad).
optimize(case, ...) -> SearchResult
    Search the placement and plan the best one.
check(case, X, q, sample_time, ...) -> CheckReport
    Check a sampled joint trajectory q (N, n) against a case at placement X.
export(source, output=None, *, format=None, ...) -> Path
    Write a run's trajectory through a writer (CSV, JSON, ROS 2, ...: ``trackplan.writers``).
study(study, out, client=None, ...) -> StudyResult
    Run a batch study on Dask (``docs/studies.md``).
Case, Robot, PlanResult, SearchResult, CheckReport, StudyResult, Status
    The inputs, the results and the one outcome vocabulary.
TrackplanError, CaseError
    The root of trackplan's exceptions, and bad input (with the file and key path).

Every other name lives in its subpackage; the names this package exported before stay
importable from here for one release with a ``DeprecationWarning`` naming the new home.

A notebook needs five lines::

    import trackplan
    case = trackplan.load_case("cases/paper-corner.yaml")
    result = trackplan.plan(case, case.bounds.example)
    print(result.status, result.duration)

Names (and ``__version__``) are imported on first use, so ``import trackplan`` stays
cheap and the computational subpackages can be imported without the file-format
dependencies.
"""

from __future__ import annotations

import importlib
import warnings
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from trackplan.case import Case
    from trackplan.check_report import CheckReport
    from trackplan.errors import CaseError, TrackplanError
    from trackplan.io.case_file import load_case
    from trackplan.io.part_file import load_part as load_part
    from trackplan.io.positioner_file import builtin_positioner as builtin_positioner
    from trackplan.io.positioner_file import load_positioner as load_positioner
    from trackplan.io.robot_file import builtin_robot, load_robot
    from trackplan.planning.plan import check, plan
    from trackplan.planning.result import PlanResult
    from trackplan.report.images import report_images as report_images
    from trackplan.robots.model import Robot
    from trackplan.search.optimize import SearchResult, optimize
    from trackplan.status import Status
    from trackplan.study.runner import StudyResult
    from trackplan.writers import export

_EXPORTS = {
    "load_case": "trackplan.io.case_file",
    "load_robot": "trackplan.io.robot_file",
    "builtin_robot": "trackplan.io.robot_file",
    # positioners: importable from here like the robots, kept out of ``__all__`` (the
    # front door's verbs and result types)
    "load_positioner": "trackplan.io.positioner_file",
    "builtin_positioner": "trackplan.io.positioner_file",
    # a part's CAD model (STEP or mesh), importable from here, outside ``__all__``
    "load_part": "trackplan.io.part_file",
    # a run's report as still images (``trackplan report RUN --png``), outside ``__all__``
    "report_images": "trackplan.report.images",
    "plan": "trackplan.planning.plan",
    "check": "trackplan.planning.plan",
    "optimize": "trackplan.search.optimize",
    "export": "trackplan.writers",
    "Case": "trackplan.case",
    "Robot": "trackplan.robots.model",
    "PlanResult": "trackplan.planning.result",
    "SearchResult": "trackplan.search.optimize",
    "CheckReport": "trackplan.check_report",
    "StudyResult": "trackplan.study.runner",
    "Status": "trackplan.status",
    "TrackplanError": "trackplan.errors",
    "CaseError": "trackplan.errors",
}
"""The front door: name -> the module that defines it. ``study`` is the package
:mod:`trackplan.study` itself, which is callable (its ``__call__`` runs
:func:`trackplan.study.runner.study`), so ``trackplan.study(...)`` and
``import trackplan.study.runner`` both keep working."""

_DEPRECATED = {
    # old name: (module, attribute there, what to use instead)
    "plan_placement": ("trackplan.planning.plan", "plan", "trackplan.plan"),
    "plan_cycle": ("trackplan.planning.plan", "plan", "trackplan.plan"),
    "optimize_placement": ("trackplan.search.optimize", "optimize", "trackplan.optimize"),
    "optimize_cycle": ("trackplan.search.optimize", "optimize", "trackplan.optimize"),
    "check_case_trajectory": ("trackplan.planning.plan", "check", "trackplan.check"),
    "check_cycle_trajectory": ("trackplan.planning.plan", "check", "trackplan.check"),
    "CycleResult": ("trackplan.planning.result", "PlanResult", "trackplan.PlanResult"),
    "OptimizeResult": ("trackplan.search.optimize", "SearchResult", "trackplan.SearchResult"),
    "CycleSearchResult": ("trackplan.search.optimize", "SearchResult", "trackplan.SearchResult"),
    "run_study": ("trackplan.study.runner", "study", "trackplan.study"),
    "check_trajectory": ("trackplan.planning.checker", "check_trajectory", ""),
    "forward_kinematics": ("trackplan.robots.kinematics", "forward_kinematics", ""),
    "jacobian": ("trackplan.robots.kinematics", "jacobian", ""),
    "builtin_names": ("trackplan.io.robot_file", "builtin_names", ""),
    "BUILTIN_ROBOTS": ("trackplan.io.robot_file", "BUILTIN_ROBOTS", ""),
    "inverse_dynamics": ("trackplan.robots.dynamics.rne", "inverse_dynamics", ""),
    "gravity_load": ("trackplan.robots.dynamics.rne", "gravity_load", ""),
    "RobotDynamics": ("trackplan.robots.dynamics_parameters", "RobotDynamics", ""),
    "Payload": ("trackplan.robots.dynamics_parameters", "Payload", ""),
    "energy_figures": ("trackplan.planning.energy", "energy_figures", ""),
    "EnergyFigures": ("trackplan.planning.energy", "EnergyFigures", ""),
    "OBJECTIVES": ("trackplan.planning.objectives", "OBJECTIVES", ""),
    "pareto_front": ("trackplan.search.pareto", "pareto_front", ""),
    "ParetoResult": ("trackplan.search.pareto", "ParetoResult", ""),
    "optimize_spin": ("trackplan.search.spin", "optimize_spin", ""),
    "placement_map": ("trackplan.search.placement_map", "placement_map", ""),
    "PlacementMap": ("trackplan.search.placement_map", "PlacementMap", ""),
    "JointPath": ("trackplan.jointpath", "JointPath", ""),
    "TIME_LAWS": ("trackplan.timing", "TIME_LAWS", ""),
    "time_law": ("trackplan.timing", "time_law", ""),
    "TimeLaw": ("trackplan.timing", "TimedPath", ""),
    "AirMove": ("trackplan.timing.airmove", "AirMove", ""),
    "plan_air_move": ("trackplan.timing.airmove", "plan_air_move", ""),
    "air_time_estimate": ("trackplan.timing.airmove", "air_time_estimate", ""),
    "trapezoid_time": ("trackplan.timing.airmove", "trapezoid_time", ""),
    "Sequence": ("trackplan.planning.sequence", "Sequence", ""),
    "Visit": ("trackplan.planning.sequence", "Visit", ""),
    "best_sequence": ("trackplan.planning.sequence", "best_sequence", ""),
    "given_sequence": ("trackplan.planning.sequence", "given_sequence", ""),
    "sequence_cost": ("trackplan.planning.sequence", "sequence_cost", ""),
    "Trajectory": ("trackplan.planning.result", "Trajectory", ""),
    "CellReport": ("trackplan.check_report", "CellReport", ""),
    "Cell": ("trackplan.cell", "Cell", ""),
    "ToolSpec": ("trackplan.tool", "ToolSpec", ""),
    "Method": ("trackplan.choices", "Method", ""),
    "Penalty": ("trackplan.choices", "Penalty", ""),
    "Timing": ("trackplan.choices", "Timing", ""),
}
"""Names exported before the front door, importable for one release with a warning: old
name -> (module, attribute, the new name; empty when only the import path changes)."""

__all__ = [
    "Case",
    "CaseError",
    "CheckReport",
    "PlanResult",
    "Robot",
    "SearchResult",
    "Status",
    "StudyResult",
    "TrackplanError",
    "__version__",
    "builtin_robot",
    "check",
    "export",
    "load_case",
    "load_robot",
    "optimize",
    "plan",
    "study",
]


def __getattr__(name: str) -> Any:
    """Import a public name on first use (PEP 562); warn for a deprecated one."""
    if name == "__version__":
        globals()[name] = _version()
        return globals()[name]
    if name == "study":  # the callable package; importing it binds it here
        return importlib.import_module("trackplan.study")
    module = _EXPORTS.get(name)
    if module is not None:
        value = getattr(importlib.import_module(module), name)
        globals()[name] = value
        return value
    if name in _DEPRECATED:
        module, attribute, instead = _DEPRECATED[name]
        use = f"use {instead}" if instead else f"import {attribute} from {module}"
        warnings.warn(
            f"trackplan.{name} is deprecated and leaves the top-level package in the next "
            f"release: {use}",
            DeprecationWarning,
            stacklevel=2,
        )
        return getattr(importlib.import_module(module), attribute)
    raise AttributeError(f"module 'trackplan' has no attribute {name!r}")


def _version() -> str:
    """The installed distribution's version (importlib.metadata costs 0.1 s: read on first
    use)."""
    from importlib.metadata import PackageNotFoundError, version

    try:
        return version("trackplan")
    except PackageNotFoundError:  # running from a source tree that is not installed
        return "0+unknown"


def __dir__() -> list[str]:
    """The front door's names, for tab completion."""
    return sorted({*globals(), *__all__})
