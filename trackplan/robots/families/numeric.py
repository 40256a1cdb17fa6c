"""The numeric family: arms without a closed form (any chain of 5, 6 or 7 joints).

The path IK (:mod:`trackplan.robots.path_ik`) solves them by damped Newton
(:mod:`trackplan.robots.ik_numeric`), seeded sample to sample; a branch is a seed.
A 7-joint arm resolves its redundancy by the rule :data:`REDUNDANCY_RULE`.
"""

from __future__ import annotations

import numpy as np

from trackplan.errors import CaseError

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

    def __init__(self, n_dof: int):
        self.n_dof = n_dof

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
        self, T_base_tool: np.ndarray, branch: int, *, with_aux: bool = False
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Not available: a numeric branch is a seed (see :meth:`solve_flat`)."""
        return self.solve_flat(T_base_tool)

    def solve_branch_parts(
        self,
        R_base_tool: np.ndarray,
        p_base_tool: np.ndarray,
        branch: int,
        *,
        with_aux: bool,
        wind_to: tuple[np.ndarray, np.ndarray, np.ndarray] | None = None,
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Not available: a numeric branch is a seed (see :meth:`solve_flat`)."""
        return self.solve_flat(np.empty((0, 4, 4)))
