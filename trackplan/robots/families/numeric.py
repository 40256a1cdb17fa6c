"""The numeric family: arms without a closed form (any chain of 5, 6 or 7 joints).

The path IK (:mod:`trackplan.robots.path_ik`) solves them by damped Newton
(:mod:`trackplan.robots.ik_numeric`), seeded sample to sample; a branch is a seed.
A 7-joint arm resolves its redundancy by the rule :data:`REDUNDANCY_RULE`.
"""

from __future__ import annotations

import numpy as np

from trackplan.errors import CaseError
from trackplan.robots.families.base import (
    N_BRANCHES,
    RedundancyParameter,
    _no_free,
    wrap_and_deduplicate,
)
from trackplan.robots.ik_numeric import solve_ik_numeric
from trackplan.robots.model import Robot

REDUNDANCY_RULE = (
    "continuous minimum-norm steps: each sample is solved by damped least squares "
    "(Δq = Jᵀ(JJᵀ + μI)⁻¹e) from the previous sample's solution, so the arm stays "
    "continuous and moves no joint further than the task needs; the seed starts every "
    "joint at the middle of its range, away from the limits"
)
"""How a chain of more than six joints picks one of its infinitely many solutions."""


class NumericFamily:
    """Arms solved numerically (:class:`~trackplan.robots.families.base.IKFamily`)."""

    name = "numeric"
    closed_form = False
    n_branches = N_BRANCHES
    redundancy: RedundancyParameter | None = None

    def __init__(self, robot: Robot):
        self.robot = robot
        self.n_dof = robot.n_dof

    def parameters(self) -> dict[str, object]:
        """The redundancy rule for chains of more than six joints, else nothing."""
        return {"redundancy": REDUNDANCY_RULE} if self.n_dof > 6 else {}

    def describe_branch(self, branch: int) -> str:
        """``"seed b"``."""
        return f"seed {branch}"

    def solve_flat(
        self,
        T_base_tool: np.ndarray,
        *,
        free: np.ndarray | None = None,
        with_aux: bool = True,
        out: tuple[np.ndarray, np.ndarray, np.ndarray] | None = None,
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Not available: numeric IK needs seeds (use :mod:`trackplan.robots.ik_numeric`)."""
        raise CaseError(
            "this robot has no closed-form IK (neither OPW nor UR geometry): "
            "use trackplan.robots.ik_numeric",
            key="robot",
        )

    def solve_branch(
        self,
        T_base_tool: np.ndarray,
        branch: int,
        *,
        free: np.ndarray | None = None,
        with_aux: bool = False,
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Not available: a numeric branch is a seed (see :meth:`solve_flat`)."""
        return self.solve_flat(T_base_tool)

    def solve_branch_parts(
        self,
        R_base_tool: np.ndarray,
        p_base_tool: np.ndarray,
        branch: int,
        *,
        free: np.ndarray | None = None,
        with_aux: bool,
        wind_to: tuple[np.ndarray, np.ndarray, np.ndarray] | None = None,
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Not available: a numeric branch is a seed (see :meth:`solve_flat`)."""
        return self.solve_flat(np.empty((0, 4, 4)))

    def seed_solutions(
        self,
        T_base_tool: np.ndarray,
        q_min: np.ndarray,
        q_max: np.ndarray,
        *,
        free: np.ndarray | None = None,
    ) -> tuple[np.ndarray, np.ndarray]:
        """The distinct solutions of poses (N, 4, 4) that damped Newton reaches from the
        eight seeds of :func:`numeric_seeds`, inside the
        limits, deduplicated (:func:`~trackplan.robots.families.base.wrap_and_deduplicate`).

        Returns
        -------
        q, found
            Shapes (N, 8, n) (NaN where not found) and (N, 8).
        """
        _no_free(free)
        T = np.asarray(T_base_tool, dtype=float)
        seeds = numeric_seeds(self.robot)  # (8, n)
        solved = solve_ik_numeric(self.robot, T[:, None], seeds[None], tol=1e-10)
        return wrap_and_deduplicate(solved.q, solved.success, q_min, q_max)


def numeric_seeds(robot: Robot) -> np.ndarray:
    """The eight seed configurations that define the numerical branches.

    Branch ``b = 4·s + 2·e + w`` starts from the middle of the joint range plus
    ``(π·s, −π/4, ±π/3, 0, ±π/2, 0)`` on joints 1 to 6 (+π/3 for e = 0, +π/2 for w = 0;
    joints past the sixth stay in the middle); a joint that lands outside its limits is
    moved by a multiple of 2π into them where possible. Away from the usual singular
    configurations of 6R arms (stretched elbow, q5 = 0), they sample the shoulder, elbow
    and wrist alternatives of most industrial arms.

    Returns
    -------
    numpy.ndarray
        Shape (8, n), rad.
    """
    n = robot.n_dof
    b = np.arange(N_BRANCHES)
    shoulder, elbow, wrist = (b >> 2) & 1, (b >> 1) & 1, b & 1
    pattern = np.zeros((N_BRANCHES, max(n, 6)))
    pattern[:, 0] = np.pi * shoulder
    pattern[:, 1] = -np.pi / 4
    pattern[:, 2] = (1 - 2 * elbow) * np.pi / 3
    pattern[:, 4] = (1 - 2 * wrist) * np.pi / 2
    middle = 0.5 * (robot.q_min + robot.q_max)
    seeds = middle + pattern[:, :n]
    shifted = seeds + 2 * np.pi * np.ceil((robot.q_min - seeds) / (2 * np.pi))  # lowest ≥ q_min
    outside = (seeds < robot.q_min) | (seeds > robot.q_max)
    moved: np.ndarray = np.where(outside & (shifted <= robot.q_max), shifted, seeds)
    return moved
