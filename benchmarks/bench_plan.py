"""Planning one placement against per-pose IK, toppra and copp-py's TOPP3, in one run.

Run with ``python -m benchmarks plan``. Prints one table:

- planning time of one placement of the corner case at Ts = 1 ms in-process (warm: the
  first call, with its JIT compilation and imports, is excluded; median of several runs),
  against the same plan's poses solved one by one with roboticstoolbox-python's analytic
  IK (``ikine_a`` of its Puma560 with our DH table: d1 = 0, d3 = 0.15);
- toppra's and copp-py's compute times on the same joint path;
- for the three paper cases at their ``placement.example`` placements (or
  :data:`FALLBACK_PLACEMENTS` when the case file has none): our duration against the toppra
  (no jerk limit) and TOPP3 (jerk-limited optimum) durations, every output re-checked by
  :func:`trackplan.planning.checker.check_trajectory`.

Targets printed alongside: ≤ 50 ms per placement, duration ≤ 1.05 × TOPP3 on every paper
case, ≥ 20× less compute than copp-py.
"""

from __future__ import annotations

import statistics
import time
from pathlib import Path

import numpy as np

from trackplan.io.case_file import load_case
from trackplan.paths.path_geometry import PathGeometry
from trackplan.planning.checker import check_trajectory
from trackplan.planning.plan import plan_placement
from trackplan.robots.kinematics import forward_kinematics
from trackplan.timing.references import reference_inputs, topp3_reference, toppra_reference

CASES = Path(__file__).resolve().parent.parent / "cases"
PAPER_CASES = ("paper-line", "paper-corner", "paper-circle")
FALLBACK_PLACEMENTS = {
    # Case 1's published X puts the line inside the shoulder cylinder (unreachable):
    # the same X with (x, y) moved 0.1 m away from joint 1's axis
    "paper-line": np.array([-0.2230, 0.1029, 0.1829, 0.0312, -0.4124, 0.5020]),
    # the paper's Case 3 placement (Section 4)
    "paper-corner": np.array([0.0902, 0.2090, 0.2020, 0.3263, 0.3016, -0.2522]),
    # the paper gives none for the circle: a feasible placement found by random search
    "paper-circle": np.array([0.3922, 0.4626, 0.1924, -0.799, 0.8431, -0.9053]),
}
"""Placements used when a case file has no ``placement.example``."""
PLAN_RUNS = 7
"""Warm planning runs whose median is reported."""
TARGET_PLAN_MS = 50.0
TARGET_TOPP3_RATIO = 1.05
TARGET_COPP_SPEEDUP = 20.0


def _placement(case) -> np.ndarray:  # type: ignore[no-untyped-def]
    example = case.bounds.example
    return np.asarray(example if example is not None else FALLBACK_PLACEMENTS[case.name], float)


def _time_plan(case, X: np.ndarray) -> tuple[float, float, object]:  # type: ignore[no-untyped-def]
    """Median wall times of warm ``plan_placement`` calls, s.

    Returns the time with the case's paths shared (as the optimizer calls it), the time
    with the paths built inside the call, and the result.
    """
    geometry = PathGeometry.from_case(case)
    result = plan_placement(case, X, geometry=geometry)  # warm-up: JIT and imports
    shared, alone = [], []
    for _ in range(PLAN_RUNS):
        start = time.perf_counter()
        result = plan_placement(case, X, geometry=geometry)
        shared.append(time.perf_counter() - start)
        start = time.perf_counter()
        plan_placement(case, X)
        alone.append(time.perf_counter() - start)
    return statistics.median(shared), statistics.median(alone), result


def _time_rtb_ik(poses: np.ndarray) -> float:
    """Wall time of roboticstoolbox's ``ikine_a`` on every pose (our DH table), s."""
    import roboticstoolbox as rtb

    puma = rtb.models.DH.Puma560()
    puma.links[0].d = 0.0
    puma.links[2].d = 0.15
    puma.ikine_a(poses[0])  # warm-up
    start = time.perf_counter()
    for T in poses:
        puma.ikine_a(T)
    return time.perf_counter() - start


def _jerk_ratio(robot, q: np.ndarray, Ts: float) -> float:  # type: ignore[no-untyped-def]
    """Largest |jerk| / limit over the samples (backward differences, at rest at both ends)."""
    report = check_trajectory(robot, q, Ts)
    return float(1.0 - np.min(report.joint_margins["jerk"]))


def _compare_case(name: str) -> dict[str, object]:
    """Our smooth plan and both references for one paper case at its placement."""
    case = load_case(CASES / f"{name}.yaml")
    X = _placement(case)
    plan_time, alone, result = _time_plan(case, X)
    row: dict[str, object] = {
        "case": name,
        "X": X,
        "plan_time": plan_time,
        "plan_alone": alone,
        "result": result,
    }
    if result.trajectory.n_samples == 0:
        return row
    Ts = case.task.sample_time
    s_grid, q_grid, caps, ok = reference_inputs(case, X, result.planned_path, result.branch)
    if not ok:
        return row
    row["toppra"] = toppra_reference(case.robot, s_grid, q_grid, caps, Ts)
    row["topp3"] = topp3_reference(case.robot, s_grid, q_grid, caps, Ts)
    row["grid"] = len(s_grid)
    return row


def _fmt(value: float, spec: str = ".4f") -> str:
    return "—" if value is None or not np.isfinite(value) else format(value, spec)


def _verdict(ok: bool) -> str:
    return "met" if ok else "NOT met"


def main() -> None:
    """Print the benchmark table."""
    rows = [_compare_case(name) for name in PAPER_CASES]
    corner = next(r for r in rows if r["case"] == "paper-corner")
    case = load_case(CASES / "paper-corner.yaml")
    poses = forward_kinematics(case.robot, corner["result"].trajectory.q)
    rtb_time = _time_rtb_ik(poses) if len(poses) else float("nan")
    plan_time = corner["plan_time"]
    plan_ms = 1e3 * plan_time

    print("Planning one placement of paper-corner at Ts = 1 ms (smooth timing)")
    print(
        f"  trackplan plan_placement (warm, median of {PLAN_RUNS}): {plan_ms:8.1f} ms"
        f"   target ≤ {TARGET_PLAN_MS:.0f} ms: {_verdict(plan_ms <= TARGET_PLAN_MS)}"
    )
    print(
        "    (paths shared as in the optimizer; building them too: "
        f"{1e3 * corner['plan_alone']:.1f} ms)"
    )
    per_pose = 1e6 * rtb_time / max(len(poses), 1)
    print(
        f"  rtb ikine_a per pose, {len(poses)} poses:          {1e3 * rtb_time:8.1f} ms"
        f"   ({rtb_time / plan_time:.0f}× trackplan's whole plan; {per_pose:.0f} µs/pose)"
    )
    for key, label in (("toppra", "toppra (seidel)"), ("topp3", "copp-py TOPP3")):
        ref = corner.get(key)
        if ref is not None:
            print(
                f"  {label:<16} compute, {corner['grid']} grid points: "
                f"{1e3 * ref.compute_time_s:8.1f} ms   ({ref.compute_time_s / plan_time:.1f}×"
                " trackplan)"
            )
    topp3 = corner.get("topp3")
    if topp3 is not None:
        speedup = topp3.compute_time_s / plan_time
        print(
            f"  copp-py / trackplan compute: {speedup:.1f}×"
            f"   target ≥ {TARGET_COPP_SPEEDUP:.0f}×: {_verdict(speedup >= TARGET_COPP_SPEEDUP)}"
        )

    print()
    header = (
        f"{'case':<13} {'plan ms':>8} {'ours s':>8} {'toppra s':>9} {'TOPP3 s':>8} "
        f"{'/toppra':>8} {'/TOPP3':>7} {'ours ok':>8} {'toppra jerk×':>13} {'TOPP3 jerk×':>12}"
    )
    print(header)
    print("-" * len(header))
    all_met = True
    for row in rows:
        result = row["result"]
        robot = load_case(CASES / f"{row['case']}.yaml").robot
        if "toppra" not in row:
            plan_ms = 1e3 * row["plan_time"]
            print(f"{row['case']:<13} {plan_ms:8.1f}  no trajectory: {result.message}")
            all_met = False
            continue
        second, third = row["toppra"], row["topp3"]
        Ts = result.trajectory.sample_time
        ratio3 = result.duration / third.duration if third.success else float("nan")
        all_met &= bool(np.isfinite(ratio3) and ratio3 <= TARGET_TOPP3_RATIO)
        jerk2 = _jerk_ratio(robot, second.q, Ts) if second.success else float("nan")
        jerk3 = _jerk_ratio(robot, third.q, Ts) if third.success else float("nan")
        print(
            f"{row['case']:<13} {1e3 * row['plan_time']:8.1f} {result.duration:8.3f} "
            f"{_fmt(second.duration, '9.3f')} {_fmt(third.duration, '8.3f')} "
            f"{_fmt(result.duration / second.duration, '8.4f')} {_fmt(ratio3, '7.4f')} "
            f"{'yes' if result.feasible else 'NO':>8} {_fmt(jerk2, '13.1f')} "
            f"{_fmt(jerk3, '12.2f')}"
        )
    print(f"duration ≤ {TARGET_TOPP3_RATIO} × TOPP3 on every paper case: {_verdict(all_met)}")
    placements = "; ".join(
        f"{row['case']} {np.array2string(row['X'], precision=4, separator=', ')}" for row in rows
    )
    print(f"X per case: {placements}")
    print(
        "jerk× = largest |jerk| / limit of the sampled output (backward differences at Ts);"
        " > 1 breaks the limit."
    )


if __name__ == "__main__":
    main()
