"""Kinematics throughput: closed-form IK, FK + Jacobian, numeric and path IK, against
roboticstoolbox-python's per-pose calls on the same DH table.

Run with ``.venv/bin/python -m benchmarks kinematics``. Every kernel is serial (one core);
each figure is the best of several repeats, so other load on the machine only lowers it.
"""

from __future__ import annotations

import time
import warnings
from collections.abc import Callable

import numpy as np

from trackplan.frames import pose_matrix, rpy_matrix
from trackplan.robots.builtin import puma560, ur5
from trackplan.robots.ik_closed_form import solve_ik_closed_form
from trackplan.robots.ik_numeric import solve_ik_numeric
from trackplan.robots.kinematics import forward_kinematics, jacobian
from trackplan.robots.path_ik import solve_path_ik
from trackplan.robots.resolved_rate import solve_path_resolved_rate

N_IK = 200_000
N_FK = 50_000
N_RTB = 300
TARGET_IK_RATE = 1e6
TARGET_IK_RATIO = 200.0


def best_time(function: Callable[[], object], repeats: int = 5) -> float:
    """Shortest wall time of ``repeats`` calls after one warm-up call, s."""
    function()
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        function()
        times.append(time.perf_counter() - start)
    return min(times)


def rtb_puma():
    """roboticstoolbox's Puma560 with our table: no pedestal (d1 = 0), d3 = 0.15."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        import roboticstoolbox as rtb
    robot = rtb.models.DH.Puma560()
    robot.links[0].d = 0.0
    robot.links[2].d = 0.15
    return robot


def line_poses(n_poses: int) -> np.ndarray:
    """A 1 m line with constant orientation inside the PUMA's workspace, (n_poses, 4, 4)."""
    direction = np.array([0.5758, 0.7321, -0.3639])
    s = np.linspace(-0.5, 0.5, n_poses)[:, None] * direction / np.linalg.norm(direction)
    return pose_matrix(
        np.array([0.403, -0.159, 0.081]) + s, rpy_matrix(np.array([0.027, -0.128, -0.671]))
    )


def main() -> None:
    """Measure and print the table."""
    robot = puma560()
    rng = np.random.default_rng(0)
    q = rng.uniform(-np.pi, np.pi, (N_IK, 6))
    T = forward_kinematics(robot, q)

    ik_rate = N_IK / best_time(lambda: solve_ik_closed_form(robot, T))
    fk_rate = N_FK / best_time(
        lambda: (forward_kinematics(robot, q[:N_FK]), jacobian(robot, q[:N_FK]))
    )
    seeds = q[:20_000] + rng.normal(0.0, 0.05, (20_000, 6))
    numeric_rate = 20_000 / best_time(
        lambda: solve_ik_numeric(ur5(), forward_kinematics(ur5(), q[:20_000]), seeds), 3
    )

    oracle = rtb_puma()
    sample = T[:N_RTB]
    ours = solve_ik_closed_form(robot, sample).q[:, 5]  # rtb's default "lun" is our branch 5
    theirs = np.array([oracle.ikine_a(Tk, "lun").q for Tk in sample])
    agree = np.abs(np.angle(np.exp(1j * (ours - theirs)))).max()
    rtb_ik_rate = N_RTB / best_time(lambda: [oracle.ikine_a(Tk, "lun") for Tk in sample], 2)
    rtb_fk_rate = N_RTB / best_time(
        lambda: [(oracle.fkine(qk), oracle.jacob0(qk)) for qk in q[:N_RTB]], 2
    )

    candidates = np.broadcast_to(line_poses(200), (30, 200, 4, 4)).copy()
    long_line = line_poses(8000)[None]
    path_all = best_time(lambda: solve_path_ik(robot, candidates), 10)
    path_forced = best_time(lambda: solve_path_ik(robot, long_line, branch=2), 10)
    q0 = solve_path_ik(robot, long_line[:, :2000], branch=2).q[0, 0]
    rate_paper = best_time(lambda: solve_path_resolved_rate(robot, long_line[0, :2000], q0), 3)
    rate_newton = best_time(
        lambda: solve_path_resolved_rate(robot, long_line[0, :2000], q0, mode="newton"), 3
    )

    rows = [
        ("closed-form IK, all 8 branches [poses/s]", ik_rate, rtb_ik_rate, "ikine_a (1 branch)"),
        ("FK + Jacobian, batched numpy [configs/s]", fk_rate, rtb_fk_rate, "fkine + jacob0"),
    ]
    print(f"{'':44}{'trackplan':>12}{'rtb':>12}{'ratio':>10}  rtb call")
    for label, mine, other, call in rows:
        print(f"{label:44}{mine:12.3g}{other:12.3g}{mine / other:9.0f}×  {call}")
    print(f"{'numeric IK, UR5, seeds 0.05 rad off [poses/s]':44}{numeric_rate:12.3g}")
    print(f"{'path IK, 30 candidates × 200 poses, 8 branches':44}{path_all * 1e3:10.2f} ms")
    print(f"{'path IK, 1 candidate × 8000 poses, forced':44}{path_forced * 1e3:10.2f} ms")
    print(f"{'resolved rate, paper mode, 2000 poses':44}{rate_paper * 1e3:10.2f} ms")
    print(f"{'resolved rate, newton mode, 2000 poses':44}{rate_newton * 1e3:10.2f} ms")
    print(f"closed form agrees with rtb ikine_a to {agree:.1e} rad on {N_RTB} poses")
    ok_rate = "met" if ik_rate >= TARGET_IK_RATE else "MISSED"
    ok_ratio = "met" if ik_rate / rtb_ik_rate > TARGET_IK_RATIO else "MISSED"
    print(f"target ≥ {TARGET_IK_RATE:.0e} IK poses/s: {ok_rate}")
    print(f"target > {TARGET_IK_RATIO:.0f}× rtb's per-pose IK: {ok_ratio}")


if __name__ == "__main__":
    main()
