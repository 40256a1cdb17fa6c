"""trackplan: offline trajectory planning for industrial robots that follow a path.

Given a path (weld seam, glue bead, deburring edge), a speed and a tolerance, trackplan
plans the joint trajectory under the robot's position, velocity, acceleration and jerk
limits, and searches where to place the workpiece so the motion is feasible and cheap.

Public API (``docs/api.md``)
----------------------------
load_case(file) -> Case
    Read and validate a case file (see ``docs/files.md``).
load_robot(file) -> Robot
    Read and validate a robot file.
builtin_robot(name) -> Robot, builtin_names() -> names
    The built-in robots: the paper's ``puma560``, ``ur5`` and a library of industrial
    arms read from URDFs (``docs/robots.md``).
Case, Robot
    The validated case and the robot model: frozen dataclasses of numpy arrays.
forward_kinematics(robot, q) -> T_base_tool
    Tool poses, q of shape (..., n) in rad, result (..., 4, 4).
jacobian(robot, q) -> J
    Geometric Jacobian at the tool point in the base frame, shape (..., 6, n).
plan_placement(case, X, *, timing, branch) -> PlanResult
    Plan and check the case with the workpiece at placement X (shape (6,), m and rad).
optimize_placement(case, *, method, seed, budget, restarts, ...) -> OptimizeResult
    Search the placement; ``method`` may also be a pymoo Algorithm.
check_trajectory(robot, q, sample_time, reference) -> CheckReport
    The checker: every sample against every limit (and the path, given a reference).
check_case_trajectory(case, X, q, sample_time) -> CheckReport
    The checker in one call for a case at a placement (``trackplan check``).
inverse_dynamics(robot, q, qd, qdd) -> tau, gravity_load(robot, q) -> tau
    Joint torques (N·m, shape (..., n)) of a robot with dynamics (``docs/dynamics.md``).
RobotDynamics, Payload
    Masses, inertias, actuators, friction, torque limits; a load at the TCP.
energy_figures(robot, q, sample_time) -> EnergyFigures
    Mechanical energy, copper loss and peak torque ratio of a sampled trajectory.
OBJECTIVES
    The search objectives by name (``travel``, ``time``, ``energy``, ``copper``).
pareto_front(case, (A, B), ...) -> ParetoResult
    NSGA-II front of two objectives over the placement, every point re-planned.
JointPath
    Poses and IK of a placed path on its planning grid, computed once per plan.
TIME_LAWS, time_law(name)
    The time laws by name (``smooth``, ``paper``).
plan_air_move(q_start, q_end, ...) -> AirMove, air_time_estimate, trapezoid_time
    Jerk-limited rest-to-rest joint moves through the air (ruckig), and their time estimates.
plan_cycle(case, X) -> CycleResult, optimize_cycle(case, ...) -> CycleSearchResult
    A case with several seams (``paths:``): one placement, approach, retract and air moves,
    the sequence; ``check_cycle_trajectory`` re-checks its trajectory (``docs/seams.md``).
best_sequence(...) -> Sequence, given_sequence, sequence_cost, Visit
    The order and direction of several seams (``docs/seams.md``).
Status, Timing, Method, Penalty
    The outcome vocabulary and the named choices.
PlanResult, OptimizeResult, CheckReport, Trajectory, TimeLaw
    The results.
run_study(study, out, client=None) -> StudyResult
    Run a batch study (cases × robots × sweeps × seeds) on Dask (see ``docs/studies.md``).
CaseError, TrackplanError
    Bad input (with the file and key path), and the root of trackplan's exceptions.

A notebook needs five lines::

    import trackplan
    case = trackplan.load_case("cases/paper-corner.yaml")
    result = trackplan.plan_placement(case, case.bounds.example)
    print(result.status, result.duration)

Names (and ``__version__``) are imported on first use, so ``import trackplan`` stays
cheap and the computational subpackages can be imported without the file-format
dependencies.
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from trackplan.case import Case
    from trackplan.choices import Method, Penalty, Timing
    from trackplan.errors import CaseError, TrackplanError
    from trackplan.io.case_file import load_case
    from trackplan.io.robot_file import BUILTIN_ROBOTS, builtin_names, builtin_robot, load_robot
    from trackplan.jointpath import JointPath
    from trackplan.planning.checker import check_trajectory
    from trackplan.planning.cycle import CycleResult, check_cycle_trajectory, plan_cycle
    from trackplan.planning.energy import EnergyFigures, energy_figures
    from trackplan.planning.objectives import OBJECTIVES
    from trackplan.planning.plan import check_case_trajectory, plan_placement
    from trackplan.planning.result import CheckReport, PlanResult, Trajectory
    from trackplan.planning.sequence import (
        Sequence,
        Visit,
        best_sequence,
        given_sequence,
        sequence_cost,
    )
    from trackplan.robots.dynamics.parameters import Payload, RobotDynamics
    from trackplan.robots.dynamics.rne import gravity_load, inverse_dynamics
    from trackplan.robots.kinematics import forward_kinematics, jacobian
    from trackplan.robots.model import Robot
    from trackplan.search import OptimizeResult, optimize_placement
    from trackplan.search.cycle_search import CycleSearchResult, optimize_cycle
    from trackplan.search.pareto import ParetoResult, pareto_front
    from trackplan.status import Status
    from trackplan.study.runner import run_study
    from trackplan.timing import TIME_LAWS, TimeLaw, time_law
    from trackplan.timing.airmove import AirMove, air_time_estimate, plan_air_move, trapezoid_time

_EXPORTS = {
    "optimize_spin": "trackplan.search.spin",
    "ToolSpec": "trackplan.tool",
    "placement_map": "trackplan.search.placement_map",
    "PlacementMap": "trackplan.search.placement_map",
    "CellReport": "trackplan.planning.result",
    "Cell": "trackplan.cell",
    "BUILTIN_ROBOTS": "trackplan.io.robot_file",
    "OBJECTIVES": "trackplan.planning.objectives",
    "TIME_LAWS": "trackplan.timing",
    "Case": "trackplan.case",
    "CaseError": "trackplan.errors",
    "CheckReport": "trackplan.planning.result",
    "EnergyFigures": "trackplan.planning.energy",
    "JointPath": "trackplan.jointpath",
    "Method": "trackplan.choices",
    "OptimizeResult": "trackplan.search",
    "ParetoResult": "trackplan.search.pareto",
    "Payload": "trackplan.robots.dynamics.parameters",
    "Penalty": "trackplan.choices",
    "PlanResult": "trackplan.planning.result",
    "Robot": "trackplan.robots.model",
    "RobotDynamics": "trackplan.robots.dynamics.parameters",
    "Status": "trackplan.status",
    "TimeLaw": "trackplan.timing",
    "Timing": "trackplan.choices",
    "TrackplanError": "trackplan.errors",
    "Trajectory": "trackplan.planning.result",
    "builtin_names": "trackplan.io.robot_file",
    "builtin_robot": "trackplan.io.robot_file",
    "check_case_trajectory": "trackplan.planning.plan",
    "check_trajectory": "trackplan.planning.checker",
    "energy_figures": "trackplan.planning.energy",
    "forward_kinematics": "trackplan.robots.kinematics",
    "gravity_load": "trackplan.robots.dynamics.rne",
    "inverse_dynamics": "trackplan.robots.dynamics.rne",
    "jacobian": "trackplan.robots.kinematics",
    "load_case": "trackplan.io.case_file",
    "load_robot": "trackplan.io.robot_file",
    "optimize_placement": "trackplan.search",
    "pareto_front": "trackplan.search.pareto",
    "plan_placement": "trackplan.planning.plan",
    "time_law": "trackplan.timing",
    "run_study": "trackplan.study.runner",
    "AirMove": "trackplan.timing.airmove",
    "plan_air_move": "trackplan.timing.airmove",
    "air_time_estimate": "trackplan.timing.airmove",
    "trapezoid_time": "trackplan.timing.airmove",
    "Sequence": "trackplan.planning.sequence",
    "Visit": "trackplan.planning.sequence",
    "best_sequence": "trackplan.planning.sequence",
    "given_sequence": "trackplan.planning.sequence",
    "sequence_cost": "trackplan.planning.sequence",
    "plan_cycle": "trackplan.planning.cycle",
    "CycleResult": "trackplan.planning.cycle",
    "check_cycle_trajectory": "trackplan.planning.cycle",
    "optimize_cycle": "trackplan.search.cycle_search",
    "CycleSearchResult": "trackplan.search.cycle_search",
}

__all__ = [
    "BUILTIN_ROBOTS",
    "OBJECTIVES",
    "TIME_LAWS",
    "AirMove",
    "Case",
    "CaseError",
    "CheckReport",
    "CycleResult",
    "CycleSearchResult",
    "EnergyFigures",
    "JointPath",
    "Method",
    "OptimizeResult",
    "ParetoResult",
    "Payload",
    "Penalty",
    "PlanResult",
    "Robot",
    "RobotDynamics",
    "Sequence",
    "Status",
    "TimeLaw",
    "Timing",
    "TrackplanError",
    "Trajectory",
    "Visit",
    "__version__",
    "air_time_estimate",
    "best_sequence",
    "builtin_names",
    "builtin_robot",
    "check_case_trajectory",
    "check_cycle_trajectory",
    "check_trajectory",
    "energy_figures",
    "forward_kinematics",
    "given_sequence",
    "gravity_load",
    "inverse_dynamics",
    "jacobian",
    "load_case",
    "load_robot",
    "optimize_cycle",
    "optimize_placement",
    "pareto_front",
    "plan_air_move",
    "plan_cycle",
    "plan_placement",
    "run_study",
    "sequence_cost",
    "time_law",
    "trapezoid_time",
]


def __getattr__(name: str) -> Any:
    """Import a public name on first use (PEP 562)."""
    if name == "__version__":
        globals()[name] = _version()
        return globals()[name]
    module = _EXPORTS.get(name)
    if module is None:
        raise AttributeError(f"module 'trackplan' has no attribute {name!r}")
    value = getattr(importlib.import_module(module), name)
    globals()[name] = value
    return value


def _version() -> str:
    """The installed distribution's version (importlib.metadata costs 0.1 s: read on first
    use)."""
    from importlib.metadata import PackageNotFoundError, version

    try:
        return version("trackplan")
    except PackageNotFoundError:  # running from a source tree that is not installed
        return "0+unknown"


def __dir__() -> list[str]:
    """Public names, for tab completion."""
    return sorted({*globals(), *_EXPORTS, "__version__"})
