"""Every arm the project loads, on one common weld: IK rate per family, optimize time and J.

Run with ``python -m benchmarks arms``. For every built-in robot (DH and URDF library) it
prints:

- the IK family and its rate in poses/s on one core (process CPU time, best of 3, poses of
  random configurations inside the limits): all branches of the closed forms (with a random
  free parameter for a redundant arm), the distinct solutions of a pose for the tracked
  families (:meth:`IKFamily.seed_solutions`), and Newton tracking from a nearby reference
  (:func:`~trackplan.robots.ik_numeric.track_poses`, what the samples of a tracked arm need);
- ``trackplan.optimize`` of one weld for all (a closed rounded rectangle, 160 × 100 mm with
  20 mm corners, 20 mm/s, 0.5 mm, Ts 4 ms, the torch down and tilted 0.3 rad, the placement
  box scaled to the robot's reach, every joint weighted 1, the GA of 20 × 10 with seed 1,
  acceleration and jerk assumed where the robot has none): wall time, verdict, J;
- for each 7-joint arm the same optimize with its redundancy frozen at the middle of its
  range (``task.redundancy: {mode: fixed}``), and J frozen / J chosen: what the profile buys;
  then :data:`DRAWS` random placements in the box (seed :data:`SEED`) planned both ways:
  how many are feasible, and the median and worst J ratio where both are.

The reference of the timing column is the KR6 R700 sixx (an OPW arm) in the same run.
"""

from __future__ import annotations

import math
import time

import numpy as np

from benchmarks import best_time
from trackplan.case import Case
from trackplan.io.case_file import load_case_text
from trackplan.io.robot_file import builtin_names, builtin_robot
from trackplan.planning.plan import plan
from trackplan.robots.families import ik_family
from trackplan.robots.ik_numeric import track_poses
from trackplan.robots.kinematics import forward_kinematics
from trackplan.robots.model import Robot
from trackplan.search.optimize import optimize

DRAWS = 20
"""Random placements per seven-joint arm for the chosen-against-frozen table."""
SEED = 30
N_CLOSED = 20_000
N_TRACKED = 500
REFERENCE = "kuka_kr6_r700_sixx"
WELD = """
name: arms-{robot}
robot: {robot}
path:
  start: [0.02, 0, 0]
  segments:
    - line: {{to: [0.14, 0, 0]}}
    - arc: {{center: [0.14, 0.02, 0], normal: [0, 0, 1], angle: 1.5707963267948966}}
    - line: {{to: [0.16, 0.08, 0]}}
    - arc: {{center: [0.14, 0.08, 0], normal: [0, 0, 1], angle: 1.5707963267948966}}
    - line: {{to: [0.02, 0.10, 0]}}
    - arc: {{center: [0.02, 0.08, 0], normal: [0, 0, 1], angle: 1.5707963267948966}}
    - line: {{to: [0, 0.02, 0]}}
    - arc: {{center: [0.02, 0.02, 0], normal: [0, 0, 1], angle: 1.5707963267948966}}
task:
  rated_speed: 0.02
  corner_speed: 0.015
  tolerance: 0.0005
  sample_time: 0.004
  tool_rpy: [3.141592653589793, 0.3, 0]
{redundancy}
placement:
  x: [{x0:.4f}, {x1:.4f}]
  y: [{y0:.4f}, {y1:.4f}]
  z: [{z0:.4f}, {z1:.4f}]
  roll: [-0.3, 0.3]
  pitch: [-0.3, 0.3]
  yaw: [-3.14, 3.14]
objective: {{weights: {weights}}}
optimizer: {{method: ga, seed: 1, population: 20, budget: 200}}
"""


def weld_case(name: str, frozen: bool = False) -> Case:
    """The common weld on robot ``name`` (its redundancy frozen at the middle with ``frozen``)."""
    robot = builtin_robot(name)
    reach = robot.reach
    redundancy = "  redundancy: {mode: fixed}" if frozen else ""
    text = WELD.format(
        robot=name,
        weights=[1] * robot.n_dof,
        redundancy=redundancy,
        x0=0.3 * reach,
        x1=0.7 * reach,
        y0=-0.3 * reach,
        y1=0.2 * reach,
        z0=-0.4 * reach,
        z1=0.2 * reach,
    )
    return load_case_text(text, assume_limits=True)


def random_poses(robot: Robot, count: int, seed: int = 0) -> tuple[np.ndarray, np.ndarray]:
    """FK poses (count, 4, 4) of random configurations inside the limits, and the joints."""
    rng = np.random.default_rng(seed)
    low = np.maximum(robot.q_min, -math.pi)
    high = np.minimum(robot.q_max, math.pi)
    q = rng.uniform(low, high, (count, robot.n_dof))
    return forward_kinematics(robot, q), q


def ik_rates(robot: Robot) -> tuple[str, str]:
    """The family's rates as text: all-branch (or distinct solutions) and tracking."""
    family = ik_family(robot)
    parameter = family.redundancy
    count = N_CLOSED if family.closed_form else N_TRACKED
    T, q = random_poses(robot, count)
    free = None
    if parameter is not None:
        free = q[:, parameter.joint] if parameter.joint is not None else None
        if free is None:  # the arm angle
            free = np.random.default_rng(1).uniform(parameter.lower, parameter.upper, count)
    if family.closed_form:
        seconds = best_time(lambda: family.solve_flat(T, free=free, with_aux=False), 3)
    else:
        seconds = best_time(
            lambda: family.seed_solutions(T, robot.q_min, robot.q_max, free=free), 3
        )
    solve = f"{count / seconds:9.3g}"
    T_track, q_track = random_poses(robot, N_CLOSED, seed=2)
    reference = q_track + np.random.default_rng(3).normal(0.0, 1e-3, q_track.shape)
    locked = -1 if parameter is None or parameter.joint is None else parameter.joint
    held = None if locked < 0 else q_track[:, locked]
    if locked >= 0:
        reference[:, locked] = held
    R, p = T_track[:, :3, :3], T_track[:, :3, 3]
    seconds = best_time(lambda: track_poses(robot, R, p, reference, held, free_joint=locked), 3)
    return solve, f"{N_CLOSED / seconds:9.3g}"


def timed_optimize(name: str, frozen: bool = False) -> tuple[float, object]:
    """Wall time of one optimize of the common weld, s, and the search result."""
    case = weld_case(name, frozen)
    start = time.perf_counter()
    result = optimize(case)
    return time.perf_counter() - start, result


def main() -> None:
    """Print the table."""
    timed_optimize(REFERENCE)  # compile the kernels once
    reference, _ = timed_optimize(REFERENCE)
    print(f"reference: optimize the weld on {REFERENCE}: {reference:.2f} s")
    print(
        f"{'robot':<22} {'family':<8} {'n':>2} {'solve/s':>9} {'track/s':>9} "
        f"{'optimize s':>10} {'/ ref':>6} {'verdict':<16} {'J':>8} {'J frozen':>9} {'ratio':>6}"
    )
    for name in builtin_names():
        robot = builtin_robot(name)
        family = ik_family(robot)
        solve, track = ik_rates(robot)
        seconds, result = timed_optimize(name)
        final = result.final  # type: ignore[attr-defined]
        frozen_text, ratio = "-", "-"
        if family.redundancy is not None:
            _, frozen = timed_optimize(name, frozen=True)
            frozen_final = frozen.final  # type: ignore[attr-defined]
            frozen_text = f"{frozen_final.objective:9.4f}" if frozen_final.success else "infeasible"
            if final.success and frozen_final.success:
                ratio = f"{frozen_final.objective / final.objective:6.2f}"
        print(
            f"{name:<22} {family.name:<8} {robot.n_dof:>2} {solve} {track} {seconds:>10.2f} "
            f"{seconds / reference:>6.2f} {final.status.value:<16} {final.objective:>8.4f} "
            f"{frozen_text:>9} {ratio:>6}",
            flush=True,
        )

    redundant_over_draws()


def redundant_over_draws() -> None:
    """Random placements of the weld per seven-joint arm, planned with the redundancy chosen
    and frozen at its middle: feasible counts and the J ratio where both are feasible."""
    print(f"\nseven-joint arms at {DRAWS} random placements (seed {SEED}):")
    print(f"{'robot':<22} {'chosen ok':>9} {'frozen ok':>9} {'J ratio median':>15} {'worst':>6}")
    for name in builtin_names():
        if ik_family(builtin_robot(name)).redundancy is None:
            continue
        chosen_case, frozen_case = weld_case(name), weld_case(name, frozen=True)
        bounds = chosen_case.bounds
        rng = np.random.default_rng(SEED)
        draws = rng.uniform(bounds.lower, bounds.upper, (DRAWS, 6))
        chosen = [plan(chosen_case, x) for x in draws]
        frozen = [plan(frozen_case, x) for x in draws]
        both = [
            f.objective / c.objective
            for c, f in zip(chosen, frozen, strict=True)
            if c.success and f.success
        ]
        median = f"{np.median(both):15.3f}" if both else f"{'-':>15}"
        worst = f"{np.min(both):6.3f}" if both else f"{'-':>6}"
        print(
            f"{name:<22} {sum(c.success for c in chosen):>9} {sum(f.success for f in frozen):>9} "
            f"{median} {worst}",
            flush=True,
        )


if __name__ == "__main__":
    main()
