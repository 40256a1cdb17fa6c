"""Panda closed-form IK throughput (joint 7 given): all eight branches and one alone, on
200,000 random poses, with each pose's own q7 (every pose reached) and with a random q7 (about
half out of reach), against roboticstoolbox's ``ikine_LM`` on the same arm.

Run with ``.venv/bin/python -m benchmarks panda``. Serial kernels (one core); each figure is
the best of five repeats of the process's CPU time (``benchmarks.best_time``).
"""

from __future__ import annotations

import warnings

import numpy as np

from benchmarks import best_time
from trackplan.io.robot_file import builtin_robot
from trackplan.robots.families.panda import PandaFamily, panda_from_chain
from trackplan.robots.kinematics import forward_kinematics

N_IK = 200_000
N_RTB = 100
TARGET_IK_RATE = 1e6  # poses/s per core, all branches (issue 30)


def main() -> None:
    """Measure and print the rates."""
    rng = np.random.default_rng(0)
    robot = builtin_robot("franka_panda")
    params = panda_from_chain(robot)
    assert params is not None
    family = PandaFamily(robot, params)
    q = rng.uniform(robot.q_min, robot.q_max, (N_IK, 7))
    T = forward_kinematics(robot, q)
    R, p = T[:, :3, :3].copy(), T[:, :3, 3].copy()
    out = (np.empty((N_IK, 8, 7)), np.empty((N_IK, 8), dtype=bool), np.empty((N_IK, 8, 5)))
    rows = []
    for label, free in (
        ("own q7", q[:, 6].copy()),
        ("random q7", rng.uniform(robot.q_min[6], robot.q_max[6], N_IK)),
    ):
        all_time = best_time(lambda free=free: family.solve_flat(T, free=free, out=out))
        reached = float(out[1].any(axis=1).mean())
        one_time = best_time(
            lambda free=free: family.solve_branch_parts(R, p, 0, free=free, with_aux=False)
        )
        rows.append((f"Panda closed form, 8 branches, {label} ({reached:.0%} reached)", all_time))
        rows.append((f"Panda closed form, 1 branch alone, {label}", one_time))
    print(f"{'IK [poses/s, one core]':60}{'rate':>12}")
    for label, seconds in rows:
        print(f"{label:60}{N_IK / seconds:12.3g}")
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            import roboticstoolbox as rtb
    except ImportError:
        print("roboticstoolbox not installed: no ikine_LM reference")
    else:
        reference = rtb.models.DH.Panda()
        reference.tool = np.eye(4)
        sample = T[:N_RTB]
        q0 = 0.5 * (robot.q_min + robot.q_max)
        seconds = best_time(lambda: [reference.ikine_LM(Tk, q0=q0) for Tk in sample], 2)
        rate = N_RTB / seconds
        ours = N_IK / rows[0][1]
        print(f"{'Panda, rtb ikine_LM, 1 solution':60}{rate:12.3g}   ours / it {ours / rate:.0f}×")
    verdict = "met" if N_IK / max(rows[0][1], rows[2][1]) >= TARGET_IK_RATE else "NOT met"
    print(f"target ≥ {TARGET_IK_RATE:.0e} poses/s, all branches: {verdict}")


if __name__ == "__main__":
    main()
