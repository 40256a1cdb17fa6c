"""Published dynamic parameters of built-in robots.

PUMA560: Corke and Armstrong-Hélouvry, "A search for consensus among model parameters
reported for the PUMA 560 robot", ICRA 1994, as roboticstoolbox-python's
``models/DH/Puma560.py`` states them (link inertials in the DH link frames; motor inertia,
gear ratio and friction on the motor side). Torque limits: Armstrong, Khatib and Burdick,
"The explicit dynamic model and inertial parameters of the PUMA 560 arm", ICRA 1986.
"""

from __future__ import annotations

import numpy as np

from trackplan.robots.dynamics_parameters import (
    RobotDynamics,
    inertia_matrix,
    inertials_from_dh,
)

PUMA560_SOURCE = (
    "Corke & Armstrong-Hélouvry 1994 (roboticstoolbox Puma560: masses, centres of mass, "
    "inertias in the DH link frames, motor inertia, gear ratios, friction); torque limits "
    "97.6, 186.4, 89.4, 24.2, 20.1, 21.3 N·m (Armstrong, Khatib, Burdick 1986)"
)


def puma560_dynamics(d: np.ndarray, a: np.ndarray, alpha: np.ndarray) -> RobotDynamics:
    """PUMA560 dynamics on a DH chain ``(d, a, alpha)`` (inertials converted to child frames).

    Parameters
    ----------
    d, a, alpha
        DH parameters of the arm the parameters are attached to, shape (6,), m and rad.
        Only ``D_i`` of each link matters: the base height d1 does not change the torques.

    Returns
    -------
    RobotDynamics
    """
    com_dh = np.array(
        [
            [0.0, 0.0, 0.0],
            [-0.3638, 0.006, 0.2275],
            [-0.0203, -0.0141, 0.070],
            [0.0, 0.019, 0.0],
            [0.0, 0.0, 0.0],
            [0.0, 0.0, 0.032],
        ]
    )
    inertia_dh = inertia_matrix(
        np.array(
            [
                [0.0, 0.35, 0.0, 0.0, 0.0, 0.0],
                [0.13, 0.524, 0.539, 0.0, 0.0, 0.0],
                [0.066, 0.086, 0.0125, 0.0, 0.0, 0.0],
                [1.8e-3, 1.3e-3, 1.8e-3, 0.0, 0.0, 0.0],
                [0.3e-3, 0.4e-3, 0.3e-3, 0.0, 0.0, 0.0],
                [0.15e-3, 0.15e-3, 0.04e-3, 0.0, 0.0, 0.0],
            ]
        )
    )
    # As published, links 1 and 3 break the triangle inequality (0.35 > 0 + 0 and
    # 0.086 > 0.066 + 0.0125 kg·m²): the consensus values are fitted, not measured on
    # bodies. They are kept exactly, so the torques match the reference; robot files are
    # held to the physical check (:func:`~trackplan.robots.dynamics_parameters.inertia_problem`).
    com, inertia = inertials_from_dh(d, a, alpha, com_dh, inertia_dh)
    return RobotDynamics(
        mass=np.array([0.0, 17.4, 4.8, 0.82, 0.34, 0.09]),
        com=com,
        inertia=inertia,
        torque_max=np.array([97.6, 186.4, 89.4, 24.2, 20.1, 21.3]),
        motor_inertia=np.array([200e-6, 200e-6, 200e-6, 33e-6, 33e-6, 33e-6]),
        gear_ratio=np.array([-62.6111, 107.815, -53.7063, 76.0364, 71.923, 76.686]),
        viscous=np.array([1.48e-3, 0.817e-3, 1.38e-3, 71.2e-6, 82.6e-6, 36.7e-6]),
        coulomb=np.array(
            [
                [0.395, -0.435],
                [0.126, -0.071],
                [0.132, -0.105],
                [11.2e-3, -16.9e-3],
                [9.26e-3, -14.5e-3],
                [3.96e-3, -10.5e-3],
            ]
        ),
        source=PUMA560_SOURCE,
    )
