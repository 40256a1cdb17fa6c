"""Kinematics throughput: closed-form IK of an OPW and a UR arm (all eight branches and one
alone), FK with and without the Jacobian, numeric and path IK, against
roboticstoolbox-python (``ikine_LM``, ``fkine``) and py-opw-kinematics on the same robots,
in the same run.

Run with ``.venv/bin/python -m benchmarks kinematics``. Every kernel is serial (one core);
each figure is the best of several repeats of the process's CPU time, which other load on the
machine inflates far less than wall time (it still lowers the rates: shared caches and cores).
"""

from __future__ import annotations

import warnings

import numpy as np

from benchmarks import best_time
from trackplan.frames import pose_matrix, rpy_matrix
from trackplan.io.robot_file import builtin_robot
from trackplan.robots.builtin import puma560, ur5
from trackplan.robots.families import ik_family, solve_ik
from trackplan.robots.ik_numeric import solve_ik_numeric
from trackplan.robots.kinematics import forward_kinematics, jacobian
from trackplan.robots.model import Robot
from trackplan.robots.path_ik import solve_path_ik
from trackplan.robots.resolved_rate import solve_path_resolved_rate

N_IK = 200_000
N_FK = 50_000
N_RTB = 300
N_OPW = 50_000
TARGET_IK_RATE = 2e6
OPW_PARAMETERS = {  # py-opw-kinematics' description of the KR6 R700 sixx (opw_kinematics)
    "a1": 0.025,
    "a2": -0.035,
    "b": 0.0,
    "c1": 0.400,
    "c2": 0.315,
    "c3": 0.365,
    "c4": 0.080,
    "offsets": (0.0, -np.pi / 2, 0.0, 0.0, 0.0, 0.0),
    "flip_axes": (True, False, False, True, False, True),
}


def rtb_ets(robot: Robot):
    """roboticstoolbox's ETS of our chain: ``Π SE3(C_i) Rz(q_i) · SE3(tail)``."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        import roboticstoolbox as rtb
    chain, tail = robot.kernel_chain
    ets = rtb.ETS()
    for C in chain:
        ets = ets * rtb.ET.SE3(np.array(C)) * rtb.ET.Rz()
    return ets * rtb.ET.SE3(np.array(tail))


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


def closed_form_rows(name: str, rng: np.random.Generator) -> list[tuple[str, float, str]]:
    """IK rates of one built-in robot: ours (all 8 branches), rtb ikine_LM, py-opw-kinematics."""
    robot = builtin_robot(name)
    q = rng.uniform(robot.q_min, robot.q_max, (N_IK, 6))
    T = forward_kinematics(robot, q)
    family = ik_family(robot).name
    rows = [
        (
            f"{name} ({family}) closed form, 8 branches",
            N_IK / best_time(lambda: solve_ik(robot, T)),
            "",
        )
    ]
    solver = ik_family(robot)
    rows.append(
        (
            f"{name} ({family}) closed form, 1 branch alone",
            N_IK / best_time(lambda: solver.solve_branch(T, 3)),
            "",
        )
    )
    ets = rtb_ets(robot)
    sample = T[:N_RTB]
    q0 = np.zeros(6)
    rows.append(
        (
            f"{name} rtb ikine_LM, 1 solution",
            N_RTB / best_time(lambda: [ets.ikine_LM(Tk, q0=q0) for Tk in sample], 2),
            "roboticstoolbox",
        )
    )
    if family == "opw":
        import py_opw_kinematics as opw
        from scipy.spatial.transform import RigidTransform

        oracle = opw.Robot(opw.KinematicModel(**OPW_PARAMETERS), degrees=False)
        poses = RigidTransform.from_matrix(T[:N_OPW])
        rows.append(
            (
                f"{name} py-opw-kinematics reach, 8 branches",
                N_OPW / best_time(lambda: oracle.reach(poses, threads=1), 3),
                "py-opw-kinematics",
            )
        )
    return rows


def main() -> None:
    """Measure and print the tables."""
    rng = np.random.default_rng(0)
    rows = [*closed_form_rows("kuka_kr6_r700_sixx", rng), *closed_form_rows("ur5e", rng)]
    print(f"{'IK [poses/s, one core]':52}{'rate':>12}{'ours / it':>11}")
    ours = 0.0
    for label, rate, _ in rows:
        if "closed form, 8" in label:
            ours = rate
        if "closed form" in label:
            print(f"{label:52}{rate:12.3g}")
        else:
            print(f"{label:52}{rate:12.3g}{ours / rate:10.0f}×")
    closed = [rate for label, rate, _ in rows if "closed form, 8" in label]
    verdict = "met" if min(closed) >= TARGET_IK_RATE else "MISSED"
    print(f"target ≥ {TARGET_IK_RATE:.0e} closed-form poses/s for both families: {verdict}")

    robot = puma560()
    q = rng.uniform(-np.pi, np.pi, (N_IK, 6))
    fk_rate = N_FK / best_time(
        lambda: (forward_kinematics(robot, q[:N_FK]), jacobian(robot, q[:N_FK]))
    )
    fk_alone = N_FK / best_time(lambda: forward_kinematics(robot, q[:N_FK]))
    seeds = q[:20_000] + rng.normal(0.0, 0.05, (20_000, 6))
    numeric_rate = 20_000 / best_time(
        lambda: solve_ik_numeric(ur5(), forward_kinematics(ur5(), q[:20_000]), seeds), 3
    )
    oracle = rtb_puma()
    rtb_fk_rate = N_RTB / best_time(
        lambda: [(oracle.fkine(qk), oracle.jacob0(qk)) for qk in q[:N_RTB]], 2
    )
    rtb_fk_alone = N_RTB / best_time(lambda: [oracle.fkine(qk) for qk in q[:N_RTB]], 2)
    candidates = np.broadcast_to(line_poses(200), (30, 200, 4, 4)).copy()
    long_line = line_poses(8000)[None]
    path_all = best_time(lambda: solve_path_ik(robot, candidates), 10)
    path_forced = best_time(lambda: solve_path_ik(robot, long_line, branch=2), 10)
    q0 = solve_path_ik(robot, long_line[:, :2000], branch=2).q[0, 0]
    rate_paper = best_time(lambda: solve_path_resolved_rate(robot, long_line[0, :2000], q0), 3)
    rate_newton = best_time(
        lambda: solve_path_resolved_rate(robot, long_line[0, :2000], q0, mode="newton"), 3
    )
    print()
    print(f"{'PUMA560':44}{'trackplan':>12}{'rtb':>12}{'ratio':>10}")
    print(
        f"{'FK + Jacobian, batched compiled [configs/s]':44}{fk_rate:12.3g}{rtb_fk_rate:12.3g}"
        f"{fk_rate / rtb_fk_rate:9.0f}×"
    )
    print(
        f"{'FK alone, batched compiled [configs/s]':44}{fk_alone:12.3g}{rtb_fk_alone:12.3g}"
        f"{fk_alone / rtb_fk_alone:9.0f}×"
    )
    print(f"{'numeric IK, UR5, seeds 0.05 rad off [poses/s]':44}{numeric_rate:12.3g}")
    print(f"{'path IK, 30 candidates × 200 poses, 8 branches':44}{path_all * 1e3:10.2f} ms")
    print(f"{'path IK, 1 candidate × 8000 poses, forced':44}{path_forced * 1e3:10.2f} ms")
    print(f"{'resolved rate, paper mode, 2000 poses':44}{rate_paper * 1e3:10.2f} ms")
    print(f"{'resolved rate, newton mode, 2000 poses':44}{rate_newton * 1e3:10.2f} ms")


if __name__ == "__main__":
    main()
