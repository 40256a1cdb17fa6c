"""The numeric family: arms without a closed form (any chain of 5, 6 or 7 joints).

The path IK (:mod:`trackplan.robots.path_ik`) solves them by damped Newton
(:mod:`trackplan.robots.ik_numeric`), seeded sample to sample; a branch is a seed.
A 7-joint arm's redundancy is one of its joints (:data:`DEFAULT_FREE_JOINT` unless the robot
file says which), whose profile along the path the planner chooses; longer chains resolve it
by the rule :data:`REDUNDANCY_RULE`.
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
from trackplan.robots.ik_numeric import solve_ik_numeric, track_poses
from trackplan.robots.model import Robot

DEFAULT_FREE_JOINT = 2
"""The joint (0-based) that carries a 7-joint arm's redundancy in the numeric family: the
third, the upper arm's roll of the usual anthropomorphic arms, which moves the elbow about
the shoulder–wrist line much as the arm angle does."""

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

    def __init__(self, robot: Robot, free_joint: int | None = None):
        self.robot = robot
        self.n_dof = robot.n_dof
        if robot.n_dof == 7:
            k = DEFAULT_FREE_JOINT if free_joint is None else int(free_joint)
            if not 0 <= k < 7:
                raise CaseError(f"free_joint must be 1 … 7, got {k + 1}", key="ik.free_joint")
            self.redundancy = RedundancyParameter(
                f"joint {k + 1}", float(robot.q_min[k]), float(robot.q_max[k]), joint=k
            )

    def parameters(self) -> dict[str, object]:
        """The joint that carries a 7-joint arm's redundancy (1-based), the minimum-norm
        rule of longer chains, else nothing."""
        if self.redundancy is not None and self.redundancy.joint is not None:
            return {"free_joint": self.redundancy.joint + 1}
        return {"redundancy": REDUNDANCY_RULE} if self.n_dof > 7 else {}

    def describe_branch(self, branch: int) -> str:
        """``"solution b of the first pose"``: the distinct solution the branch follows."""
        return f"solution {branch} of the first pose"

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
        T = np.asarray(T_base_tool, dtype=float)
        seeds = numeric_seeds(self.robot)  # (8, n)
        if self.redundancy is None:
            _no_free(free)
            solved = solve_ik_numeric(self.robot, T[:, None], seeds[None], tol=1e-10)
            return wrap_and_deduplicate(solved.q, solved.success, q_min, q_max)
        if free is None:
            raise ValueError(f"the numeric family needs its {self.redundancy.name} per pose")
        n_poses, n_seeds = len(T), len(seeds)
        reference = np.tile(seeds, (n_poses, 1))  # row p·8 + k
        q, success = track_poses(
            self.robot,
            np.repeat(T[:, :3, :3], n_seeds, axis=0),
            np.repeat(T[:, :3, 3], n_seeds, axis=0),
            reference,
            np.repeat(np.asarray(free, dtype=float), n_seeds),
            self.redundancy.joint if self.redundancy.joint is not None else -1,
        )
        shape = (n_poses, n_seeds)
        return wrap_and_deduplicate(q.reshape(*shape, -1), success.reshape(shape), q_min, q_max)


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
