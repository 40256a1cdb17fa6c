"""The numeric family: arms without a closed form (any chain of 5, 6, 7 or more joints).

A tracked family (:class:`~trackplan.robots.families.base.IKFamily`): the distinct
solutions of a pose come from multi-start Newton (:mod:`trackplan.robots.numeric_seeding`),
and the path IK follows each by warm-started Newton (:mod:`trackplan.robots.ik_numeric`).
A 7-joint arm's redundancy is one of its joints, held at a value per pose
(:data:`~trackplan.robots.ik_numeric.DEFAULT_FREE_JOINT` unless chosen); a chain of more
than seven joints resolves it by the rule :data:`REDUNDANCY_RULE`.
"""

from __future__ import annotations

import numpy as np

from trackplan.errors import CaseError
from trackplan.robots.families.base import (
    N_BRANCHES,
    SAME_SOLUTION,
    RedundancyParameter,
    TrackedFamily,
    _no_free,
)
from trackplan.robots.ik_numeric import (
    DEFAULT_FREE_JOINT,
    chain_arrays,
    track_poses,
)
from trackplan.robots.model import Robot
from trackplan.robots.numeric_seeding import (
    MAX_ITER,
    SOLVED_TOL,
    multi_start,
    select_solutions,
    start_configurations,
)

REDUNDANCY_RULE = (
    "continuous minimum-norm steps: each sample is solved by damped least squares "
    "(Δq = Jᵀ(JJᵀ + μI)⁻¹e) from the previous sample's solution, so the arm stays "
    "continuous and moves no joint further than the task needs; the seed starts every "
    "joint at the middle of its range, away from the limits"
)
"""How a chain of more than seven joints (or a 7-joint chain tracked without a held joint)
picks one of its infinitely many solutions."""


class NumericFamily(TrackedFamily):
    """Arms solved numerically (:class:`~trackplan.robots.families.base.IKFamily`)."""

    name = "numeric"
    n_branches = N_BRANCHES
    redundancy: RedundancyParameter | None

    def __init__(self, robot: Robot, free_joint: int | None = None):
        """The numeric family of ``robot``.

        Parameters
        ----------
        robot
            Any chain.
        free_joint
            A 7-joint arm's redundancy joint, 0-based (default
            :data:`~trackplan.robots.ik_numeric.DEFAULT_FREE_JOINT`, joint 3); must be
            None for other chains.

        Raises
        ------
        CaseError
            When ``free_joint`` is given for a chain that is not 7-joint, or is no joint.
        """
        self.robot = robot
        self.n_dof = n = robot.n_dof
        if n != 7:
            if free_joint is not None:
                raise CaseError(
                    f"free_joint applies to 7-joint arms only; this chain has {n} joints: "
                    "leave it out",
                    key="robot",
                )
            self.redundancy = None
        else:
            k = DEFAULT_FREE_JOINT if free_joint is None else int(free_joint)
            if not 0 <= k < n:
                raise CaseError(
                    f"free_joint {k} is no joint of this 7-joint arm: give 0 to 6", key="robot"
                )
            self.redundancy = RedundancyParameter(
                f"joint {k + 1}", float(robot.q_min[k]), float(robot.q_max[k]), joint=k
            )
        self._starts: np.ndarray | None = None

    @property
    def locked(self) -> int:
        """The held joint (0-based), −1 for none."""
        joint = None if self.redundancy is None else self.redundancy.joint
        return -1 if joint is None else joint

    def parameters(self) -> dict[str, object]:
        """The joint that carries a 7-joint arm's redundancy (1-based), the minimum-norm
        rule of longer chains, else nothing."""
        if self.locked >= 0:
            return {"free_joint": self.locked + 1}
        return {"redundancy": REDUNDANCY_RULE} if self.n_dof > 7 else {}

    def describe_branch(self, branch: int) -> str:
        """``"solution b of the first pose"``: the distinct solution the branch follows."""
        return f"solution {branch} of the first pose"

    def seed_solutions(
        self,
        T_base_tool: np.ndarray,
        q_min: np.ndarray,
        q_max: np.ndarray,
        *,
        free: np.ndarray | None = None,
    ) -> tuple[np.ndarray, np.ndarray]:
        """The distinct solutions of poses (N, 4, 4) inside the limits, by multi-start
        Newton (:mod:`trackplan.robots.numeric_seeding`): from the eight seeds of
        :func:`numeric_seeds` and 64 scrambled Sobol points, kept where the pose error is
        at most 1e-10 (m and rad), moved into [q_min, q_max] by multiples of 2π,
        deduplicated (1e-6 rad), ordered by structural signature (shoulder, elbow, wrist
        signs), then by margin to the limits; at most :attr:`n_branches`.

        ``free`` (a 7-joint arm): the held joint's value per pose, shape (N,), rad; None
        holds it at the middle of its range. Other chains: None.

        Returns
        -------
        q, found
            Shapes (N, 8, n) (NaN where not found) and (N, 8), the found first.
        """
        T = np.ascontiguousarray(T_base_tool, dtype=float)
        held = self._free_values(free, T.shape[0])
        chain, tail = chain_arrays(self.robot)
        q, solved, measures = multi_start(
            chain,
            tail,
            T,
            self.starts(),
            self.locked,
            held,
            3 if self.n_dof >= 7 else 2,
            SOLVED_TOL,
            MAX_ITER,
        )
        lower = np.ascontiguousarray(q_min, dtype=float)
        upper = np.ascontiguousarray(q_max, dtype=float)
        return select_solutions(q, solved, measures, lower, upper, self.n_branches, SAME_SOLUTION)

    def track(
        self,
        R_base_tool: np.ndarray,
        p_base_tool: np.ndarray,
        q_ref: np.ndarray,
        free: np.ndarray | None = None,
    ) -> tuple[np.ndarray, np.ndarray]:
        """:func:`~trackplan.robots.ik_numeric.track_poses` with this family's held joint:
        poses (R (N, 3, 3) or (3, 3), p (N, 3) m) solved from references q_ref (N, n) rad;
        ``free`` (N,) rad for a 7-joint arm (None: the references' values of the joint).

        Returns
        -------
        q, ok
            Shapes (N, n) rad and (N,) bool.
        """
        if self.locked >= 0 and free is None:
            free = np.asarray(q_ref, dtype=float)[:, self.locked]
        _check_free(self.locked, free)
        joint = self.locked if self.locked >= 0 else DEFAULT_FREE_JOINT
        return track_poses(self.robot, R_base_tool, p_base_tool, q_ref, free, free_joint=joint)

    def starts(self) -> np.ndarray:
        """The multi-start configurations, shape (72, n), rad (computed once)."""
        if self._starts is None:
            self._starts = start_configurations(
                numeric_seeds(self.robot), self.robot.q_min, self.robot.q_max
            )
        return self._starts

    def _free_values(self, free: np.ndarray | None, count: int) -> np.ndarray:
        """The held joint's values (count,), or an empty array without a held joint."""
        _check_free(self.locked, free)
        if self.locked < 0:
            return np.empty(0)
        if free is None:
            k = self.locked
            return np.full(count, 0.5 * (self.robot.q_min[k] + self.robot.q_max[k]))
        held = np.ascontiguousarray(free, dtype=float)
        if held.shape != (count,):
            raise ValueError(f"free must have shape ({count},), got {held.shape}")
        return held


def _check_free(locked: int, free: np.ndarray | None) -> None:
    """Refuse ``free`` for a family without a held joint."""
    if locked < 0:
        _no_free(free)


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
