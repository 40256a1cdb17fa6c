"""Collision screening: the compiled kernel against the exact library, and the search's cost.

Run with ``python -m benchmarks collision``. Prints, in one run:

- screening throughput of :meth:`trackplan.cell.screening.CellGeometry.screen` on the
  shipped cell case (``cases/paper-corner-cell.yaml``): random PUMA560 configurations and
  placements, every link/tool capsule against every obstacle and workpiece body plus the
  self pairs, in pair checks/s and candidate-samples/s on one core (target ≥ 5 M pair
  checks/s), against coal (:class:`trackplan.cell.exact.ExactDistance`) on the same pairs,
  one call per pair;
- ``trackplan optimize`` on the cell case against the same case without its cell, each
  as a whole process (``python -m trackplan optimize``, fresh interpreter, numba caches
  warm), wall and CPU time (target ≤ 2×).

Each throughput figure is the least CPU time of several repeats (one thread).
"""

from __future__ import annotations

import os
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from benchmarks import best_time
from trackplan.cell.exact import ExactDistance
from trackplan.cell.screening import CellGeometry
from trackplan.frames import placement_transform
from trackplan.io.case_file import load_case
from trackplan.robots.kinematics import joint_frames

ROOT = Path(__file__).resolve().parent.parent
CELL_CASE = ROOT / "cases" / "paper-corner-cell.yaml"
PLAIN_CASE = ROOT / "cases" / "paper-corner.yaml"
N_CANDIDATES = 30
N_POSES = 150
N_EXACT = 3000
TARGET_RATE = 5e6
TARGET_SLOWDOWN = 2.0


def screening() -> None:
    """Kernel pair checks per second against coal per pair, on the cell case."""
    case = load_case(CELL_CASE)
    robot = case.robot
    assert case.cell is not None
    geometry = CellGeometry.from_cell(case.cell, robot)
    rng = np.random.default_rng(0)
    q = rng.uniform(robot.q_min, robot.q_max, (N_CANDIDATES * N_POSES, robot.n_dof))
    X = rng.uniform(case.bounds.lower, case.bounds.upper, (N_CANDIDATES, 6))
    T_base_part = placement_transform(X)
    group = np.repeat(np.arange(N_CANDIDATES), N_POSES)
    frames = joint_frames(robot, q)
    n_samples = len(q)
    n_pairs = geometry.n_pairs

    seconds = best_time(lambda: geometry.screen(frames, T_base_part, group))
    rate = n_samples * n_pairs / seconds
    frames_seconds = best_time(lambda: joint_frames(robot, q))
    print(
        f"screening: {N_CANDIDATES} candidates x {N_POSES} samples x {n_pairs} pairs "
        f"({len(geometry.pair_capsule)} capsule-body, {len(geometry.self_pairs)} self)"
    )
    print(
        f"  kernel       {seconds * 1e3:8.2f} ms  {rate / 1e6:7.1f} M pair checks/s  "
        f"{n_samples / seconds / 1e6:6.2f} M candidate-samples/s  "
        f"(target >= {TARGET_RATE / 1e6:.0f} M pair checks/s: "
        f"{'met' if rate >= TARGET_RATE else 'NOT met'})"
    )
    print(
        f"  link frames  {frames_seconds * 1e3:8.2f} ms  (joint_frames, numpy, before the kernel)"
    )

    oracle = ExactDistance()
    capsules = geometry.capsules
    n_body_pairs = len(geometry.pair_capsule)
    picks = rng.integers(0, n_samples, N_EXACT)
    pairs = rng.integers(0, n_body_pairs, N_EXACT)

    def exact() -> None:
        for s, p in zip(picks, pairs, strict=True):
            k, o = geometry.pair_capsule[p], geometry.pair_body[p]
            T = frames[s, capsules.frame[k]]
            a, b = capsules.segment[k] @ T[:3, :3].T + T[:3, 3]
            T_world = T_base_part[group[s]] if o >= geometry.n_obstacles else np.eye(4)
            oracle.capsule_body(a, b, capsules.radius[k], geometry.bodies[o], T_world)

    exact_seconds = best_time(exact, repeats=2)
    exact_rate = N_EXACT / exact_seconds
    print(
        f"  coal         {exact_seconds / N_EXACT * 1e6:8.2f} us per pair  "
        f"{exact_rate / 1e6:7.3f} M pair checks/s  "
        f"(kernel / coal: {rate / exact_rate:.0f}x)"
    )


def optimize_process(case: Path) -> tuple[float, float]:
    """Wall and CPU time of ``python -m trackplan optimize CASE`` in a fresh process, s.

    Raises
    ------
    RuntimeError
        When the search does not end with a feasible plan (exit code other than 0).
    """
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    start = time.perf_counter()
    with tempfile.TemporaryDirectory() as out:
        run = subprocess.run(
            [sys.executable, "-m", "trackplan", "optimize", str(case), "--out", out, "--no-report"],
            check=False,
            capture_output=True,
            text=True,
            env={**os.environ, "PYTHONPATH": str(ROOT)},
        )
    if run.returncode != 0:
        raise RuntimeError(
            f"optimize {case.name} exited {run.returncode}: {run.stdout}{run.stderr}"
        )
    wall = time.perf_counter() - start
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    return wall, cpu


def optimize_cost() -> None:
    """Whole-process optimize with and without the cell."""
    optimize_process(CELL_CASE)  # warm the numba caches
    plain_wall, plain_cpu = optimize_process(PLAIN_CASE)
    cell_wall, cell_cpu = optimize_process(CELL_CASE)
    print("optimize as a whole process (python -m trackplan optimize, default settings)")
    print(f"  {PLAIN_CASE.name:24s} wall {plain_wall:7.1f} s  CPU {plain_cpu:7.1f} s")
    print(f"  {CELL_CASE.name:24s} wall {cell_wall:7.1f} s  CPU {cell_cpu:7.1f} s")
    ratio = cell_cpu / plain_cpu
    print(
        f"  cell / no cell: CPU {ratio:.2f}x, wall {cell_wall / plain_wall:.2f}x "
        f"(target <= {TARGET_SLOWDOWN:.0f}x: {'met' if ratio <= TARGET_SLOWDOWN else 'NOT met'})"
    )


def main() -> None:
    """Run the collision benchmarks."""
    screening()
    optimize_cost()


if __name__ == "__main__":
    main()
