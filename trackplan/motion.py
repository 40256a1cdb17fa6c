"""Sampled joint motion: the samples and what every check reads from them, computed once.

A plan's samples are read by the time law's sample checks, the checker, the energy figures
and the trajectory it returns. Each of them needs the same backward differences
(``docs/conventions.md``), the same joint torques and the same tool poses:
:class:`JointSamples` computes each of them on first use and hands the same arrays to
every reader, so that one plan makes one derivative pass, one FK pass and one inverse
dynamics pass over its samples. It is a working set of the checks, not a result: the
plan's output record is :class:`trackplan.planning.result.Trajectory` (times, joints and
tool figures per sample, written to ``trajectory.csv``).
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass
from functools import cached_property

import numpy as np

from trackplan.derivatives import REST_PADDING, backward_derivatives
from trackplan.robots.dynamics.rne import inverse_dynamics
from trackplan.robots.kinematics import forward_kinematics
from trackplan.robots.machine import Machine
from trackplan.robots.model import Robot


@dataclass(frozen=True, eq=False)
class JointSamples:
    """Joint positions at Ts from rest to rest, with their derivatives, torques and FK.

    Every derived array is computed on first use and read-only; the arrays of the
    :data:`~trackplan.derivatives.REST_PADDING` samples after the end (the robot holding
    ``q[-1]``) are included where a check reads them.

    Attributes
    ----------
    robot
        The robot, or a machine (the arm with a track or a positioner: ``q`` is its whole
        joint vector).
    q
        Joint positions, shape (N, n), rad, one row per controller period; not to be
        changed once the motion exists (the derived arrays are those of these values).
    sample_time
        Ts, s.
    """

    robot: Robot | Machine
    q: np.ndarray
    sample_time: float

    def __post_init__(self) -> None:
        object.__setattr__(self, "q", np.asarray(self.q, dtype=float))

    @property
    def n_samples(self) -> int:
        """Number of samples N."""
        return len(self.q)

    @cached_property
    def _derivatives(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Backward differences padded with the rest samples after the end, (N + 3, n) each."""
        found = backward_derivatives(self.q, self.sample_time, pad_end=True)
        for array in found:
            array.flags.writeable = False
        return found

    @property
    def qd(self) -> np.ndarray:
        """Velocity by backward differences, shape (N + 3, n), rad/s (the last three rows:
        the rest after the end)."""
        return self._derivatives[0]

    @property
    def qdd(self) -> np.ndarray:
        """Acceleration, shape (N + 3, n), rad/s²."""
        return self._derivatives[1]

    @property
    def qddd(self) -> np.ndarray:
        """Jerk, shape (N + 3, n), rad/s³."""
        return self._derivatives[2]

    @cached_property
    def q_held(self) -> np.ndarray:
        """Positions with the rest samples after the end, shape (N + 3, n), rad."""
        held = np.concatenate([self.q, np.repeat(self.q[-1:], REST_PADDING, axis=0)])
        held.flags.writeable = False
        return held

    @cached_property
    def torque(self) -> np.ndarray | None:
        """Joint torques by inverse dynamics of ``q_held``, ``qd``, ``qdd``, shape (N + 3, n),
        N·m (``docs/dynamics.md``); None for a robot without dynamics."""
        if isinstance(self.robot, Machine) or self.robot.dynamics is None:
            return None
        tau = inverse_dynamics(self.robot, self.q_held, self.qd, self.qdd)
        tau.flags.writeable = False
        return tau

    @cached_property
    def T_base_tool(self) -> np.ndarray:
        """Tool poses by FK in the base frame, shape (N, 4, 4); for a machine, in its
        carrier frame (the frame the placement X refers to: the positioner's flange, or the
        cell), :meth:`~trackplan.robots.machine.Machine.T_carrier_tool`."""
        if isinstance(self.robot, Machine):
            poses = self.robot.T_carrier_tool(self.q)
        else:
            poses = forward_kinematics(self.robot, self.q)
        poses.flags.writeable = False
        return poses


def __getattr__(name: str) -> type[JointSamples]:
    """``SampledMotion``, the old name of :class:`JointSamples`, with a
    :class:`DeprecationWarning` (one release)."""
    if name == "SampledMotion":
        warnings.warn(
            "trackplan.motion.SampledMotion is now trackplan.motion.JointSamples",
            DeprecationWarning,
            stacklevel=2,
        )
        return JointSamples
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
