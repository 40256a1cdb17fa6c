"""Several seams: what jerk costs an air move, and what sequencing costs to compute.

Run with ``python -m benchmarks seams``. Prints, in one run:

- air moves (:func:`trackplan.timing.airmove.plan_air_move`, ruckig) between random pairs
  of configurations of a built-in industrial robot inside its joint limits: the planned
  duration against the jerk-unlimited (trapezoidal) time of the slowest joint, median and
  worst ratio, "what jerk costs"; against the closed-form jerk-limited estimate the
  sequencing uses (what synchronising the joints and rounding to whole periods add); the
  compute time per move and per estimate;
- sequencing (:func:`trackplan.planning.sequence.best_sequence`) on random geometric
  instances (seams as segments in a square, air cost the distance between seam ends):
  compute time for m = 4, 6, 8 (dynamic programming) and 12, 20 (heuristic), the cost
  against the order as written; and the heuristic's gap to the optimum at m = 8, on such
  instances and on independent random costs;
- the shipped case ``cases/bracket-4-fillets.yaml`` (four fillets, one placement): the
  placement search (:func:`trackplan.search.optimize.optimize`, CPU time), then
  at its placement the cycle time with the optimised sequence against the order and
  directions as written (:func:`trackplan.planning.plan.plan`), and the air time of
  each.

Compute times are the least CPU time of several repeats (one thread).
"""

from __future__ import annotations

import time
from pathlib import Path

import numpy as np

from benchmarks import best_time
from trackplan.io.case_file import load_case
from trackplan.io.robot_file import builtin_robot
from trackplan.planning.plan import plan
from trackplan.planning.seams import seam_geometries
from trackplan.planning.sequence import best_sequence, given_sequence, sequence_cost
from trackplan.search.optimize import optimize
from trackplan.timing.airmove import air_time_estimate, plan_air_move, trapezoid_time

ROBOT = "kuka_kr10_r1420"
SAMPLE_TIME = 0.004
N_PAIRS = 200
SEQUENCE_SIZES = (4, 6, 8, 12, 20)
N_INSTANCES = 10
N_GAP_INSTANCES = 40
SHIPPED_CASE = Path(__file__).resolve().parents[1] / "cases" / "bracket-4-fillets.yaml"


def air_moves() -> None:
    """Planned air-move durations against the trapezoidal and closed-form estimates."""
    robot = builtin_robot(ROBOT)
    rng = np.random.default_rng(0)
    start = rng.uniform(robot.q_min, robot.q_max, (N_PAIRS, robot.n_dof))
    end = rng.uniform(robot.q_min, robot.q_max, (N_PAIRS, robot.n_dof))
    limits = (robot.v_max, robot.a_max, robot.j_max)

    def plan_all() -> list[float]:
        return [
            plan_air_move(a, b, *limits, SAMPLE_TIME).duration
            for a, b in zip(start, end, strict=True)
        ]

    duration = np.array(plan_all())
    seconds = best_time(plan_all, 3)
    trapezoid = trapezoid_time(start, end, robot.v_max, robot.a_max)
    estimate = air_time_estimate(start, end, *limits)
    estimate_seconds = best_time(lambda: air_time_estimate(start, end, *limits), repeats=20)
    jerk = duration / trapezoid
    sync = duration / estimate
    print(
        f"air moves: {N_PAIRS} random pairs of {ROBOT} configurations, Ts = "
        f"{SAMPLE_TIME * 1e3:g} ms, median move {np.median(duration):.3f} s"
    )
    print(
        f"  ruckig / trapezoid (what jerk costs): median {np.median(jerk):.3f}, "
        f"worst {jerk.max():.3f}, best {jerk.min():.3f}"
    )
    print(
        f"  ruckig / closed-form estimate (synchronising, whole periods): "
        f"median {np.median(sync):.4f}, worst {sync.max():.4f}"
    )
    print(
        f"  compute: {seconds / N_PAIRS * 1e3:.2f} ms per planned move (ruckig and sampling), "
        f"{estimate_seconds / N_PAIRS * 1e6:.2f} µs per estimate (batched)"
    )


def geometric_instance(rng: np.random.Generator, m: int) -> tuple[np.ndarray, ...]:
    """``m`` seams as segments in the unit square; air cost the distance between seam ends,
    from and back to a home point; every seam reversible."""
    a = rng.uniform(0.0, 1.0, (m, 2))
    b = a + rng.uniform(-0.2, 0.2, (m, 2))
    starts = np.stack([a, b], axis=1)
    ends = np.stack([b, a], axis=1)
    length = np.linalg.norm(b - a, axis=1)
    home = np.array([0.5, -0.2])
    air = np.linalg.norm(ends[:, :, None, None, :] - starts[None, None, :, :, :], axis=-1)
    return (
        np.stack([length, length], axis=1),
        air,
        np.linalg.norm(starts - home, axis=-1),
        np.linalg.norm(ends - home, axis=-1),
        np.ones(m, bool),
    )


def random_instance(rng: np.random.Generator, m: int) -> tuple[np.ndarray, ...]:
    """``m`` seams with independent random costs (no triangle inequality), every seam
    reversible."""
    return (
        rng.uniform(0.5, 2.0, (m, 2)),
        rng.uniform(0.0, 1.0, (m, 2, m, 2)),
        rng.uniform(0.0, 1.0, (m, 2)),
        rng.uniform(0.0, 1.0, (m, 2)),
        np.ones(m, bool),
    )


def sequencing() -> None:
    """Sequencing compute time and quality."""
    rng = np.random.default_rng(1)
    print(f"sequencing: {N_INSTANCES} random geometric instances per size")
    for m in SEQUENCE_SIZES:
        instances = [geometric_instance(rng, m) for _ in range(N_INSTANCES)]
        seconds = [best_time(lambda costs=costs: best_sequence(*costs), 3) for costs in instances]
        found = [best_sequence(*costs) for costs in instances]
        given = [sequence_cost(given_sequence(m).visits, *costs[:4]) for costs in instances]
        ratio = np.array([f.cost for f in found]) / np.array(given)
        kind = "dynamic programming" if found[0].exact else "heuristic"
        print(
            f"  m = {m:2d} ({kind:19s}): median {np.median(seconds) * 1e3:7.2f} ms, "
            f"worst {max(seconds) * 1e3:7.2f} ms; cost / order as written: "
            f"median {np.median(ratio):.3f}"
        )
    for kind, make in (("geometric", geometric_instance), ("random-cost", random_instance)):
        gaps = []
        for _ in range(N_GAP_INSTANCES):
            costs = make(rng, 8)
            exact = best_sequence(*costs)
            heuristic = best_sequence(*costs, exact_up_to=0)
            gaps.append(heuristic.cost / exact.cost - 1.0)
        gap = np.array(gaps)
        print(
            f"  heuristic against the optimum at m = 8 ({N_GAP_INSTANCES} {kind} instances): "
            f"mean gap {gap.mean():.2%}, worst {gap.max():.2%}, "
            f"optimal on {np.mean(gap < 1e-9):.0%}"
        )


def cycle() -> None:
    """The shipped four-fillet case: search, then the optimised sequence against the given."""
    case = load_case(SHIPPED_CASE)
    assert len(case.seams) > 1
    start = time.process_time()
    search = optimize(case)
    search_cpu = time.process_time() - start
    X = search.X
    geometries = seam_geometries(case)
    optimised = search.final
    given = plan(case, X, sequence=given_sequence(len(case.seams)), geometries=geometries)
    order = ", ".join(f"{s.name}{' (reversed)' if s.reversed else ''}" for s in optimised.seams)
    approach = case.sequencing.approach
    print(f"cycle: {SHIPPED_CASE.name}, {len(case.seams)} seams, approach {approach} m")
    print(
        f"  search: {search.evaluations} evaluations, {search_cpu:.1f} s CPU, "
        f"{search.status.value}; X = ({', '.join(f'{v:.4f}' for v in X)})"
    )
    print(f"  optimised sequence: {order}")
    for name, result in (("optimised", optimised), ("as written", given)):
        print(
            f"  {name:10s}: cycle {result.duration:.3f} s, welding {result.seam_time:.3f} s, "
            f"approach/retract/air {result.air_time:.3f} s, J = {result.objective:.4f}, "
            f"{'feasible' if result.success else result.status.value}"
        )
    print(
        f"  optimised / as written: cycle time {optimised.duration / given.duration:.3f}, "
        f"air time {optimised.air_time / given.air_time:.3f}"
    )


def main() -> None:
    air_moves()
    sequencing()
    cycle()


if __name__ == "__main__":
    main()
