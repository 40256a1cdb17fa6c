"""Physical energy figures of a sampled trajectory, from its joint torques.

The torques are those the checker sees: inverse dynamics (``docs/dynamics.md``) of ``q`` and
its backward differences at Ts, the robot at rest before the first and after the last
sample. Integrals are sums over the samples times Ts.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from trackplan.motion import JointSamples
from trackplan.robots.model import Robot


@dataclass(frozen=True)
class EnergyFigures:
    """What a trajectory costs physically.

    Attributes
    ----------
    mechanical_energy
        ``∫ Σ_i max(τ_i q̇_i, 0) dt``: work the motors put in (braking recovers nothing), J.
    copper_loss
        ``∫ Σ_i (τ_i / (G_i k_m,i))² dt``: heat in the motor windings, in
        :attr:`copper_loss_unit` (W·s with motor constants ``k_m``, else (N·m)²·s with
        ``k_m = 1``).
    copper_loss_unit
        ``W·s`` or ``(N·m)²·s``.
    peak_torque_ratio
        ``max_k max_i |τ_i| / τ_max,i``; above 1 a torque limit is exceeded.
    peak_torque_joint
        The joint of the peak, 1-based.
    """

    mechanical_energy: float
    copper_loss: float
    copper_loss_unit: str
    peak_torque_ratio: float
    peak_torque_joint: int


def joint_torques(robot: Robot, q: np.ndarray, sample_time: float) -> tuple[np.ndarray, np.ndarray]:
    """Joint torques and velocities at every sample, the rest samples after the end included.

    Parameters
    ----------
    robot
        A robot with dynamics.
    q
        Joint positions, shape (N, n), rad.
    sample_time
        Ts, s.

    Returns
    -------
    tuple of numpy.ndarray
        ``(tau, qd)``, each shape (N + 3, n), N·m and rad/s.
    """
    motion = JointSamples(robot, q, sample_time)
    if motion.torque is None:
        raise ValueError(f"robot {robot.name!r} has no dynamic parameters")
    return motion.torque, motion.qd


def energy_figures(robot: Robot, q: np.ndarray, sample_time: float) -> EnergyFigures:
    """Mechanical energy, copper loss and peak torque ratio of a sampled trajectory.

    Parameters
    ----------
    robot
        A robot with dynamics.
    q
        Joint positions, shape (N, n), rad.
    sample_time
        Ts, s.

    Returns
    -------
    EnergyFigures
    """
    return motion_energy(JointSamples(robot, q, sample_time))


def motion_energy(motion: JointSamples) -> EnergyFigures:
    """:func:`energy_figures` from the torques of a :class:`~trackplan.motion.JointSamples`
    (computed once for every reader).

    Parameters
    ----------
    motion
        Joint samples at Ts of a robot with dynamics.

    Returns
    -------
    EnergyFigures
    """
    robot, sample_time = motion.robot, motion.sample_time
    dynamics = robot.dynamics
    if dynamics is None or motion.torque is None:
        raise ValueError(f"robot {robot.name!r} has no dynamic parameters")
    tau, qd = motion.torque, motion.qd
    k_m = np.ones(robot.n_dof) if dynamics.motor_constant is None else dynamics.motor_constant
    # each figure in one scratch array (the same values as the plain expressions)
    scratch = np.multiply(tau, qd)
    mechanical = float(np.maximum(scratch, 0.0, out=scratch).sum() * sample_time)
    np.divide(tau, np.asarray(dynamics.gear_ratio) * k_m, out=scratch)  # motor torque
    copper = float(np.square(scratch, out=scratch).sum() * sample_time)
    use = np.divide(np.abs(tau, out=scratch), dynamics.torque_max, out=scratch)
    worst = np.unravel_index(int(np.argmax(use)), use.shape)
    return EnergyFigures(
        mechanical_energy=mechanical,
        copper_loss=copper,
        copper_loss_unit=dynamics.copper_loss_unit,
        peak_torque_ratio=float(use[worst]),
        peak_torque_joint=int(worst[1]) + 1,
    )
