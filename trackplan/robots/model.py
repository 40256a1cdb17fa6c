"""The robot model: a standard-DH serial chain with per-joint limits.

The model is immutable and shared; every computation keeps its scratch space local
(pinocchio's Model/Data split).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from trackplan.errors import CaseError
from trackplan.robots.dynamics.parameters import RobotDynamics

LIMIT_KINDS = ("position", "velocity", "acceleration", "jerk")


@dataclass(frozen=True, eq=False)
class Robot:
    """A serial robot described by standard DH parameters.

    Link transform (docs/conventions.md):
    ``A_i = Rz(q_i + offset_i) · Tz(d_i) · Tx(a_i) · Rx(alpha_i)``.
    The world frame is the DH base frame; the end effector is DH frame n followed by
    ``T_flange_tool``.

    Attributes
    ----------
    name
        Robot name.
    d, a, alpha, offset
        DH parameters, shape (n,), metres and radians.
    q_min, q_max
        Joint position limits, shape (n,), rad.
    v_max, a_max, j_max
        Symmetric joint velocity, acceleration and jerk limits, shape (n,),
        rad/s, rad/s², rad/s³.
    T_flange_tool
        Tool transform in the flange (DH frame n), shape (4, 4).
    source
        Where the numbers come from (free text, shown by ``trackplan robots``).
    dynamics
        Masses, inertias, actuators, friction and torque limits, or None when the robot has
        no published dynamics (then it has no torque check).
    """

    name: str
    d: np.ndarray
    a: np.ndarray
    alpha: np.ndarray
    offset: np.ndarray
    q_min: np.ndarray
    q_max: np.ndarray
    v_max: np.ndarray
    a_max: np.ndarray
    j_max: np.ndarray
    T_flange_tool: np.ndarray = field(default_factory=lambda: np.eye(4))
    source: str = ""
    dynamics: RobotDynamics | None = None

    def __post_init__(self) -> None:
        n = len(self.d)
        for key in ("d", "a", "alpha", "offset", "q_min", "q_max", "v_max", "a_max", "j_max"):
            value = np.array(getattr(self, key), dtype=float)
            if value.shape != (n,):
                raise CaseError(f"{key} must have {n} entries, got shape {value.shape}", key=key)
            if not np.all(np.isfinite(value)):
                raise CaseError(f"{key} must be finite, got {value.tolist()}", key=key)
            value.flags.writeable = False
            object.__setattr__(self, key, value)
        tool = np.array(self.T_flange_tool, dtype=float)
        tool.flags.writeable = False
        object.__setattr__(self, "T_flange_tool", tool)
        if self.dynamics is not None and self.dynamics.n_dof != n:
            raise CaseError(
                f"dynamics must have {n} joints, got {self.dynamics.n_dof}", key="dynamics"
            )

    @property
    def n_dof(self) -> int:
        """Number of joints."""
        return len(self.d)

    @property
    def joint_names(self) -> tuple[str, ...]:
        """Joint names ``q1 … qn`` (also used in exported trajectories)."""
        return tuple(f"q{i + 1}" for i in range(self.n_dof))

    @property
    def has_tool(self) -> bool:
        """True when the tool transform is not the identity."""
        return not np.allclose(self.T_flange_tool, np.eye(4))

    def limits(self, kind: str) -> np.ndarray:
        """Symmetric bound of one limit kind, shape (n,).

        For ``position`` this is not symmetric: use :attr:`q_min`, :attr:`q_max`.
        """
        return {"velocity": self.v_max, "acceleration": self.a_max, "jerk": self.j_max}[kind]

    @property
    def reach(self) -> float:
        """An upper bound of the distance from the base origin to the flange, m."""
        return float(np.sum(np.abs(self.a)) + np.sum(np.abs(self.d)))
