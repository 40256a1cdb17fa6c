"""Built-in robots given by a DH table: the paper's PUMA560 (Tables I and II) and a UR5.

The industrial arms of the library are URDFs with robot files in ``library/``
(``docs/robots.md``).
"""

from __future__ import annotations

import numpy as np

from trackplan.robots.collision import puma560_capsules, ur5_capsules
from trackplan.robots.controller import ControllerConvention
from trackplan.robots.dynamics.builtin import puma560_dynamics
from trackplan.robots.model import Robot

HALF_PI = np.pi / 2
PUMA_PLACEMENT_REACH = (0.150333, 0.853756)
"""The PUMA's placement reach range, m: sqrt(0.0226) and sqrt(0.7289) of the paper's Eq. 32,
rounded inwards."""


def puma560() -> Robot:
    """PUMA560 of the paper: DH of Table I (α = ±π/2 exactly), limits of Table II.

    Dynamics: Corke and Armstrong-Hélouvry's parameters (see
    :mod:`trackplan.robots.dynamics.builtin`).
    """
    d = np.array([0.0, 0.0, 0.15, 0.4318, 0.0, 0.0])
    a = np.array([0.0, 0.4318, 0.0203, 0.0, 0.0, 0.0])
    alpha = np.array([HALF_PI, 0.0, -HALF_PI, HALF_PI, -HALF_PI, 0.0])
    return Robot.from_dh(
        name="puma560",
        d=d,
        a=a,
        alpha=alpha,
        offset=np.zeros(6),
        q_min=-np.array(
            [np.pi, 0.75 * np.pi, 0.75 * np.pi, 0.75 * np.pi, 0.75 * np.pi, 0.75 * np.pi]
        ),
        q_max=np.array(
            [np.pi, 0.75 * np.pi, 0.75 * np.pi, 0.75 * np.pi, 0.75 * np.pi, 0.75 * np.pi]
        ),
        v_max=np.array([8.0, 10.0, 10.0, 5.0, 5.0, 5.0]),
        a_max=np.array([10.0, 12.0, 12.0, 8.0, 8.0, 8.0]),
        j_max=np.array([30.0, 40.0, 40.0, 20.0, 20.0, 20.0]),
        source=(
            "Reference paper, Tables I (DH, alpha = ±pi/2) and II (limits); "
            "base frame at the shoulder (d1 = 0)."
        ),
        dynamics=puma560_dynamics(d, a, alpha),
        placement_reach=PUMA_PLACEMENT_REACH,
        collision=puma560_capsules(),
    )


def ur5() -> Robot:
    """UR5 (CB3): a 6R arm without a spherical wrist, so it takes the numerical IK path.

    DH: Universal Robots, "DH parameters for calculations of kinematics and dynamics"
    (UR5: d1 = 0.089159, a2 = -0.425, a3 = -0.39225, d4 = 0.10915, d5 = 0.09465,
    d6 = 0.0823, alpha = (π/2, 0, 0, π/2, -π/2, 0)).
    Limits: UR5 technical specifications: every joint ±360°, 180 °/s. The datasheet gives no
    acceleration or jerk limits; 15 rad/s² and 150 rad/s³ are conservative values
    chosen here for process motion (state your own in a robot file if they differ).
    """
    two_pi = 2 * np.pi
    return Robot.from_dh(
        name="ur5",
        d=np.array([0.089159, 0.0, 0.0, 0.10915, 0.09465, 0.0823]),
        a=np.array([0.0, -0.425, -0.39225, 0.0, 0.0, 0.0]),
        alpha=np.array([HALF_PI, 0.0, 0.0, HALF_PI, -HALF_PI, 0.0]),
        offset=np.zeros(6),
        q_min=-np.full(6, two_pi),
        q_max=np.full(6, two_pi),
        v_max=np.full(6, np.pi),
        a_max=np.full(6, 15.0),
        j_max=np.full(6, 150.0),
        source=(
            "Universal Robots UR5 (CB3) published DH table and technical specifications "
            "(±360°, 180°/s); acceleration 15 rad/s² and jerk 150 rad/s³ are assumptions."
        ),
        collision=ur5_capsules(),
        controller=ControllerConvention(
            vendor="ur",
            signs=np.ones(6),
            offsets=np.zeros(6),
            cycle=0.008,
            source=(
                "Universal Robots: the DH table is given in the controller's Base frame and "
                "joint zero (UR CB3 user manual, appendix 'Robot DH parameters'; ur_description "
                "docs 'Robot Frames': at all-zero joints the arm points along -x of Base); "
                "CB3 controller step 8 ms (Universal_Robots_Client_Library rtde_client.h, "
                "CB3_MAX_FREQUENCY = 125)"
            ),
        ),
    )


DH_ROBOTS = {"puma560": puma560, "ur5": ur5}
"""The built-in robots defined by a DH table here; the URDF library is in ``library/``
(:func:`trackplan.io.robot_file.builtin_robot` serves both)."""
