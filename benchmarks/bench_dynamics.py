"""Inverse dynamics throughput against roboticstoolbox-python, and the Pareto run's wall time.

Run with ``.venv/bin/python -m benchmarks dynamics``. Both sides are single-threaded, so
their throughput is measured in process CPU time (``time.process_time``), which other load
on the machine hardly changes; each figure is the best of several repeats. The Pareto run
is wall time.
roboticstoolbox is measured two ways on the same robot and states: ``rne`` called once per
sample (how a planner loop calls it; the issue's ≥ 100× target is stated against this one),
and ``rne`` on the whole (N, 6) batch (its C code loops over the rows).
"""

from __future__ import annotations

import time
import warnings
from pathlib import Path

import numpy as np

from benchmarks import best_time
from trackplan.io.case_file import load_case
from trackplan.robots.builtin import puma560
from trackplan.robots.dynamics.rne import inverse_dynamics
from trackplan.search.pareto import pareto_front

N_SAMPLES = 200_000
N_RTB_SINGLE = 2_000
TARGET_RATIO = 100.0
CORNER = Path(__file__).resolve().parents[1] / "cases" / "paper-corner.yaml"


def rtb_puma():
    """roboticstoolbox's Puma560 with our DH table (d1 = 0, d3 = 0.15) and its dynamics."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        import roboticstoolbox as rtb
    robot = rtb.models.DH.Puma560()
    robot.links[0].d = 0.0
    robot.links[2].d = 0.15
    return robot


def main() -> None:
    """Print samples/s of the RNE kernel and of roboticstoolbox, and the Pareto run time."""
    rng = np.random.default_rng(0)
    robot = puma560()
    q = rng.uniform(-np.pi, np.pi, (N_SAMPLES, 6))
    qd = rng.uniform(-3, 3, (N_SAMPLES, 6))
    qdd = rng.uniform(-10, 10, (N_SAMPLES, 6))
    ours = N_SAMPLES / best_time(lambda: inverse_dynamics(robot, q, qd, qdd))
    ref = rtb_puma()
    np.testing.assert_allclose(
        inverse_dynamics(robot, q[:500], qd[:500], qdd[:500]),
        ref.rne(q[:500], qd[:500], qdd[:500]),
        rtol=1e-9,
        atol=1e-12,
    )
    n = N_RTB_SINGLE
    single = n / best_time(lambda: [ref.rne(q[k], qd[k], qdd[k]) for k in range(n)], repeats=3)
    batch = N_SAMPLES / best_time(lambda: ref.rne(q, qd, qdd), repeats=3)
    print(f"RNE, PUMA560 with motor inertia and friction, {N_SAMPLES} random states:")
    print(f"  trackplan (numba, 1 core)        {ours:12.3e} samples/s (CPU time)")
    print(
        f"  roboticstoolbox rne per sample   {single:12.3e} samples/s   ratio {ours / single:7.1f}x"
    )
    print(
        f"  roboticstoolbox rne on the batch {batch:12.3e} samples/s   ratio {ours / batch:7.1f}x"
    )
    verdict = "met" if ours / single >= TARGET_RATIO else "NOT met"
    print(
        f"  target >= {TARGET_RATIO:.0f}x roboticstoolbox's rne called per sample: {verdict} "
        f"({ours / single:.0f}x); against its batch call {ours / batch:.1f}x"
    )

    case = load_case(CORNER)
    start = time.perf_counter()
    result = pareto_front(case, ("travel", "copper"), generations=40)
    wall = time.perf_counter() - start
    print(
        f"Pareto travel-copper, {CORNER.name}, population {case.optimizer.population} x 40 "
        f"generations ({result.evaluations} evaluations), {len(result.plans)} front points "
        f"re-planned: {wall:.1f} s (target <= 60 s)"
    )
