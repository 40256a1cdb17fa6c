"""Batched fitness of placements (Eq. 30) with geometric screening (docs/search.md, "Screening").

Joint travel J (Eq. 8) and reachability depend only on the geometric path, not on the
time law: J sums |Δq| along the joint path whatever the speed. So a whole population is
screened at once on a coarse arc-length grid of the planned path: one batched IK call
solves every candidate on all eight branches, and per candidate the feasible branch with
the smallest J is chosen. The smooth time law always meets the rate limits by slowing
down, and the speed caps up to the IK's error, which the checker's speed slack allows
(:func:`trackplan.planning.checker.speed_slack`), so in smooth timing a geometrically
feasible candidate is feasible; the time law
runs only where the duration matters (``objective.time_weight > 0``) and the candidate
can still beat the incumbent. In paper timing (Section 3.1 as written) every screened
candidate is planned and checked, since that time law does not respect the limits.

Fitness (Eq. 30, minimised)
---------------------------
- feasible: ``J + time_weight · duration``;
- infeasible, ``penalty: flat``: the paper's constant ``M = objective.flat_penalty``;
- infeasible, ``penalty: graded``: ``M + v`` with the violation ``v > 0`` below, so every
  infeasible candidate ranks below every feasible one (M exceeds any J) and infeasible
  candidates rank by how far they are from feasibility.

Graded violation v (the smallest over the branches, in the order of the checks)
-------------------------------------------------------------------------------
- ``4 + e / 0.1 m``: the translation lies ``e`` outside the reach interval (Eq. 32);
  the path is not solved;
- ``0.5 + u + s + l`` (in [0.5, 2.5]): on the geometric path, ``u`` the share of poses out
  of reach, ``s`` the share of poses where the branch switches (a singularity crossing)
  or jumps, ``l = min(1, excess / π)`` with ``excess`` how far (rad) the joint path leaves
  the position limits;
- ``0.5 + min(1, r - 1)`` (robots with dynamics): every continuous branch within the joint
  range needs more than a torque limit just to hold a pose against gravity, ``r`` being
  the largest holding torque over its limit; no speed helps (``docs/dynamics.md``);
- ``0.25 + 0.25 e / (e + 0.05 m)`` (in [0.25, 0.5)): geometrically feasible on some branch,
  but every such branch comes closer to the cell than its clearance (screened by the
  compiled kernel, :mod:`trackplan.cell.screening`), ``e`` the least shortfall in metres;
- ``0.5 L / (1 + L)`` with ``L = ln(1 + x)`` (in (0, 0.5)): geometrically feasible but the
  planned trajectory fails the checker, ``x`` being the worst excess over a limit as a
  fraction of the limit (logarithmic: the paper's time law exceeds jerk limits 1000-fold).

Duration bound
--------------
With ``time_weight > 0`` a candidate is timed only when ``J + time_weight · T_low`` is
below the incumbent, ``T_low`` a lower bound of its duration from the screening grid: on
each grid interval the tool needs at least ``Δs / v_cap`` (rated speed, corner speed on
curved zones) and every joint at least ``|Δq_i| / q̇max_i``.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable
from concurrent.futures import Executor
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from trackplan.axes.choose import AxesFailure, choose_axes
from trackplan.axes.profile import AxesProfile
from trackplan.case import Case, Objective
from trackplan.choices import Penalty
from trackplan.frames import placement_transform, tool_poses
from trackplan.paths.path_geometry import PathGeometry
from trackplan.paths.screening_grid import CURVED_POSES as CURVED_POSES
from trackplan.paths.screening_grid import SCREEN_POSES, screening_grid
from trackplan.planning.objectives import ScreenInput, screen_objective
from trackplan.planning.result import PlanResult
from trackplan.redundancy import choose_redundancy
from trackplan.robots.dynamics.rne import holding_torque_ratio
from trackplan.robots.families import ik_family
from trackplan.robots.machine import Machine, carried_poses
from trackplan.robots.path_ik import solve_path_ik_branches
from trackplan.robots.thread_sharing import ThreadSharing
from trackplan.search.plan_calls import plan_seam
from trackplan.search.positioner_pose import pose_bounds, positioned
from trackplan.search.screening import (
    FEASIBLE,
    GEOMETRY_LEVEL,
    Screening,
    SeamScreen,
    code,
    evaluate_seams,
)
from trackplan.search.space import N_VAR, SearchSpace
from trackplan.status import Status
from trackplan.timing import time_law
from trackplan.tool import ToolOrientation, spin_rotations, spin_values

if TYPE_CHECKING:  # the cell's compiled screening only for cases with a cell
    from trackplan.cell.screening import CellGeometry

AXES_LEVEL = 2.5
"""Graded violation of a candidate whose external axes cannot keep the downhand rule:
``2.5 + min(1, reached / π)`` (in [2.5, 3.5]), ``reached`` the angle over the bound where
the positioner gives up; above every geometric failure, below the reach's."""
CLEARANCE_LEVEL = 0.25
"""Graded violation of a placement whose only problem is the clearance, before its shortfall."""
CLEARANCE_SCALE = 0.05
"""Clearance shortfall at which the graded violation is halfway to the next level, m."""
CELL_MARGIN = 0.003
"""The search asks for this much more than the clearance, m: its optimum lies on the
clearance boundary, and the final plan, checked at every sample, must not dip below it."""
CELL_STRIDE = 3
"""The clearance is screened on every third pose of the screening grid (about 2 cm apart on
the paper's corner path): the search's cost of the cell stays within 2× (``python -m
benchmarks collision``); the final plan is checked exactly at every sample."""


def plan_candidate(
    args: tuple[Case, np.ndarray, str, int, PathGeometry],
) -> PlanResult:
    """The plan of one ``(case, X, timing, branch, geometry)`` (for executors); X holds the
    placement, then the spin variables."""
    case, X, timing, branch, geometry = args
    return plan_seam(case, X, timing=timing, branch=branch, geometry=geometry)


@dataclass(frozen=True, eq=False)
class BranchScreen:
    """Every IK branch of B placements on the screening grid (K branches).

    Attributes
    ----------
    grid
        Joint paths (B, K, M, n) and least interval times (B, K, M - 1) for the objectives
        (where not ``ok``, the tool's alone).
    branches
        The branch of each column, shape (K,), int.
    ok
        Geometrically feasible and able to hold its poses against gravity, shape (B, K).
    violation
        Graded violation, 0 where ``ok``, shape (B, K).
    finding
        Outcome code (:func:`~trackplan.search.screening.outcome`), shape (B, K), int.
    """

    grid: ScreenInput
    branches: np.ndarray
    ok: np.ndarray
    violation: np.ndarray
    finding: np.ndarray

    def values(self, objective: Objective) -> np.ndarray:
        """An objective on every branch, shape (B, K); inf where not ``ok``.

        Evaluated on the ``ok`` branches only: most sampled candidates have none, and the
        objective over every branch took a fifth of the screening time.
        """
        values = np.full(self.ok.shape, np.inf)
        if self.ok.any():
            grid = self.grid
            usable = ScreenInput(grid.robot, grid.q[self.ok], grid.dt[self.ok], grid.weights)
            values[self.ok] = screen_objective(objective, usable)
        return values


class PlacementFitness:
    """The batched fitness function of one case (see the module docstring).

    Parameters
    ----------
    case
        The case.
    space
        Its search space (for the reach constraint).
    geometry
        The case's paths for the timing used.
    timing
        The time law (:data:`trackplan.timing.TIME_LAWS`).
    n_poses
        Target size of the screening grid.
    executor
        Runs the time law of several candidates concurrently (``executor.map``); None
        plans them one after the other in this process.
    """

    def __init__(
        self,
        case: Case,
        space: SearchSpace,
        geometry: PathGeometry,
        timing: str,
        *,
        n_poses: int = SCREEN_POSES,
        executor: Executor | None = None,
    ):
        self.case = case
        self.space = space
        self.geometry = geometry
        self.timing = timing
        self.law = time_law(timing)
        self.s_grid = screening_grid(geometry, n_poses)
        sample = geometry.planned.sample(self.s_grid)
        self.points = sample.position
        self.R_base = ToolOrientation.choose(case.task.tool, geometry).base_rotations(
            self.s_grid, sample.tangent
        )  # (M, 3, 3), zero spin
        self.weights = case.travel_weights
        self.flat = case.objective.penalty == Penalty.FLAT
        self.penalty = float(case.objective.flat_penalty)
        self.time_weight = float(case.objective.time_weight)
        curved = geometry.on_curved_zone(0.5 * (self.s_grid[1:] + self.s_grid[:-1]))
        cap = np.where(curved, case.task.corner_speed, case.task.rated_speed)
        self.tool_time = np.diff(self.s_grid) / cap  # (M - 1,), s
        self.cell: CellGeometry | None = None
        if case.cell:
            from trackplan.cell.screening import CellGeometry

            self.cell = CellGeometry.from_cell(case.cell, case.machine)
        self._map: Callable[[Callable, Iterable], Iterable] = (
            executor.map if executor is not None else map
        )
        self.sharing = ThreadSharing()  # whether the path IK's threads pay, call after call

    def evaluate(self, X: np.ndarray, incumbent: float = np.inf) -> Screening:
        """Fitness of a batch of placements on this seam alone: the case fitness
        (:func:`~trackplan.search.screening.evaluate_seams`) of one seam, no moves.

        Parameters
        ----------
        X
            Variables, shape (B, 6 + k): placements, metres and radians, then spin (or
            (B, 6): the spin in the middle of its range).
        incumbent
            Best fitness found so far: with ``time_weight > 0`` a feasible candidate is
            timed only when ``J + time_weight · T_low`` (its lowest possible fitness)
            is below it; otherwise its fitness is that lower bound (``T_low`` instead of its
            duration, see the module docstring).

        Returns
        -------
        Screening
        """
        X = np.atleast_2d(np.asarray(X, dtype=float))
        tool = self.case.task.tool
        if X.shape[1] == N_VAR:  # placements alone: the middle of the spin range, the pose given
            defaults = np.concatenate([tool.default_variables(), pose_bounds(self.case)[2]])
            X = np.hstack([X, np.tile(defaults, (len(X), 1))])
        return evaluate_seams(self.space, [self], [slice(N_VAR, None)], X, incumbent)[0]

    def screen_branches(self, X: np.ndarray) -> BranchScreen:
        """Every IK branch of placements inside the reach interval, on the screening grid.

        Parameters
        ----------
        X
            Variables, shape (B, 6 + k).

        Returns
        -------
        BranchScreen
        """
        n_spin = self.case.task.tool.n_spin
        poses = tool_poses(X[:, :6], self.points, self.rotations(X[:, 6 : 6 + n_spin]))
        external, failed = self.external_axes(X[:, :6], X[:, 6 + n_spin :])
        if external is not None:
            poses = carried_poses(self.case.machine, external, poses)
        arm = self.case.robot
        if ik_family(arm).redundancy is None:
            paths = solve_path_ik_branches(arm, poses, sharing=self.sharing)
        else:  # the free parameter chosen per candidate and branch, as a plan chooses it
            length = self.geometry.planned.length
            spec = self.case.task.redundancy
            weights = self.weights[: arm.n_dof]
            paths = choose_redundancy(
                arm, poses, self.s_grid, length, spec, weights, sharing=self.sharing
            ).paths
        n_poses = len(self.s_grid)
        unreachable = 1.0 - paths.reachable_fraction
        switches = paths.n_switches / n_poses
        limits = np.minimum(1.0, np.maximum(0.0, -paths.margin) / np.pi)
        graded = GEOMETRY_LEVEL + unreachable + switches + limits  # (B, K)
        ok = paths.success
        too_heavy = np.zeros_like(ok)
        if self.case.robot.dynamics is not None:
            holding = np.zeros(ok.shape)  # (B, K): only usable branches can be too heavy
            holding[ok] = holding_torque_ratio(self.case.robot, paths.q[ok])
            too_heavy = ok & (holding > 1.0)
            ok = ok & ~too_heavy
            graded = np.where(too_heavy, GEOMETRY_LEVEL + np.minimum(1.0, holding - 1.0), graded)
        finding = np.select(
            [ok, too_heavy, unreachable > 0.0, paths.n_switches > 0],
            [
                FEASIBLE,
                code(Status.HOLDING_TORQUE),
                code(Status.UNREACHABLE),
                code(Status.BRANCH_SWITCH),
            ],
            code(Status.POSITION_LIMITS),
        )
        for b, failure in failed.items():  # the external axes cannot keep the rule
            ok[b] = False
            graded[b] = AXES_LEVEL + (
                1.0 if failure.reached is None else min(1.0, failure.reached / np.pi)
            )
            finding[b] = code(failure.status)
        # the joints' least interval times on the usable branches only (few of them while
        # sampling); the others keep the tool's
        q = paths.q
        if external is not None:  # the machine's joint vector: the arm's, then the axes'
            shape = (*q.shape[:3], external.shape[-1])
            q = np.concatenate([q, np.broadcast_to(external[:, None], shape)], axis=-1)
        dt = np.tile(self.tool_time, (*ok.shape, 1))  # (B, K, M - 1), s
        steps = np.abs(np.diff(q[ok], axis=1))  # (P, M - 1, n), rad
        dt[ok] = np.fmax(self.tool_time, np.max(steps / self.case.machine.v_max, axis=2))
        return BranchScreen(
            ScreenInput(self.case.machine, q, dt, self.weights),
            paths.branches,
            ok,
            np.where(ok, 0.0, graded),
            finding,
        )

    def screen_objectives(
        self, X: np.ndarray, objectives: tuple[Objective, ...]
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """Objectives of placements inside the reach interval, on one branch each.

        Every branch is screened (:meth:`screen_branches`), then the cell's clearance on the
        feasible branches best first by the first objective (:meth:`_screen_cell`); each
        placement keeps its clear branch with the smallest first objective, else its least
        violating branch.

        Parameters
        ----------
        X
            Variables, shape (B, 6 + k).
        objectives
            One or more objectives; the first chooses the branch.

        Returns
        -------
        tuple of numpy.ndarray
            Values ``(B, len(objectives))`` (NaN when infeasible), branch ``(B,)``, graded
            violation ``(B,)``, outcome code ``(B,)`` and duration bound ``(B,)`` (s).
        """
        branches, values, choice, any_ok, violation, finding = self._choose(X, objectives)
        rows = np.arange(len(X))
        chosen = np.stack([np.where(any_ok, v[rows, choice], np.nan) for v in values], axis=1)
        return (
            chosen,
            branches.branches[choice],
            np.where(any_ok, 0.0, violation[rows, choice]),
            np.where(any_ok, FEASIBLE, finding[rows, choice]),
            branches.grid.dt[rows, choice].sum(axis=1),
        )

    def screen_seam(self, X: np.ndarray) -> SeamScreen:
        """This seam of placements inside the reach interval on its chosen branch
        (:meth:`screen_objectives` with the case's objective, and the branch's ends).

        Parameters
        ----------
        X
            Variables, shape (B, 6 + k).

        Returns
        -------
        SeamScreen
            With one seam (m = 1); the objective is inf where no branch is feasible.
        """
        branches, values, choice, ok, violation, finding = self._choose(X, (self.case.objective,))
        rows = np.arange(len(X))
        q = branches.grid.q[rows, choice]  # (B, M, n)
        columns = (
            ok,
            np.where(ok, values[0][rows, choice], np.inf),
            branches.grid.dt[rows, choice].sum(axis=1),
            branches.branches[choice],
            np.where(ok, 0.0, violation[rows, choice]),
            np.where(ok, FEASIBLE, finding[rows, choice]),
            q[:, 0],
            q[:, -1],
        )
        return SeamScreen(*(column[None] for column in columns))

    def _choose(
        self, X: np.ndarray, objectives: tuple[Objective, ...]
    ) -> tuple[BranchScreen, list[np.ndarray], np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """Every branch screened, the cell's clearance on the feasible ones; per placement
        the objectives (B, K) each, the chosen branch's column (B,), whether it is feasible
        (B,), and the graded violations and outcome codes (B, K)."""
        branches = self.screen_branches(X)
        values = [branches.values(objective) for objective in objectives]
        violation = branches.violation
        finding = branches.finding
        if self.cell is not None:
            first, violation = self._screen_cell(X, branches.grid.q, values[0], violation)
            blocked = np.isinf(first) & branches.ok
            values = [np.where(blocked, np.inf, v) for v in values]
            finding = np.where(blocked, code(Status.COLLISION), finding)
        any_ok = np.isfinite(values[0]).any(axis=1)
        choice = np.where(any_ok, np.argmin(values[0], axis=1), np.argmin(violation, axis=1))
        return branches, values, choice, any_ok, violation, finding

    def _screen_cell(
        self, X: np.ndarray, q: np.ndarray, J: np.ndarray, graded: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray]:
        """Drop the branches that break the clearance; grade the candidates left with none.

        Branches are screened best J first, so mostly one branch per candidate is screened,
        on every :data:`CELL_STRIDE`-th pose of the screening grid.

        Parameters
        ----------
        X
            Variables, shape (B, 6 + k): placements, spin, the positioner pose's.
        q
            Joint paths of every branch, shape (B, K, M, n), rad (a machine's whole joint
            vector).
        J, graded
            Objective (inf where the branch is geometrically infeasible) and graded
            violation per branch, shape (B, K).

        Returns
        -------
        tuple of numpy.ndarray
            J with colliding branches set to inf, and the graded violation with colliding
            branches graded by their clearance shortfall, shape (B, K) each.
        """
        assert self.cell is not None
        J = J.copy()
        graded = graded.copy()
        T_base_part = placement_transform(X[:, :6])
        pose = X[:, 6 + self.case.task.tool.n_spin :]
        clearance = self.cell.cell.clearance + CELL_MARGIN
        # every CELL_STRIDE-th pose of the screening grid, and the last
        poses = np.unique(np.r_[np.arange(0, q.shape[2], CELL_STRIDE), q.shape[2] - 1])
        q = q[:, :, poses]
        n_poses = q.shape[2]
        pending = np.isfinite(J)
        rows = np.arange(len(X))
        while True:
            best = np.argmin(np.where(pending, J, np.inf), axis=1)
            todo = np.flatnonzero(pending[rows, best])
            if not len(todo):
                return J, graded
            body, own = self._screen_poses(q[todo, best[todo]], T_base_part[todo], pose[todo])
            least = (
                np.minimum(body.min(axis=1, initial=np.inf), own.min(axis=1, initial=np.inf))
                .reshape(len(todo), n_poses)
                .min(axis=1)
            )
            shortfall = np.maximum(0.0, clearance - least)
            blocked = shortfall > 0.0
            b, k = todo[blocked], best[todo[blocked]]
            J[b, k] = np.inf
            e = shortfall[blocked]
            graded[b, k] = CLEARANCE_LEVEL + CLEARANCE_LEVEL * e / (e + CLEARANCE_SCALE)
            pending[todo, best[todo]] = False
            # a candidate with a clear branch is done
            pending[todo[~blocked]] = False

    def _screen_poses(
        self, q: np.ndarray, T_base_part: np.ndarray, pose: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray]:
        """Screened distances of candidates' poses: q (C, P, n), placements (C, 4, 4) and the
        positioner pose's variables (C, k); capsule–body (C·P, pairs) and self (C·P, pairs).
        One batched call, or one per candidate where each stands its positioner elsewhere."""
        assert self.cell is not None
        n_candidates, n_poses, n_dof = q.shape
        group = np.repeat(np.arange(n_candidates), n_poses)
        if not pose.shape[1]:
            return self.cell.screen_joints(
                self.case.machine, q.reshape(-1, n_dof), T_base_part, group
            )
        found = [
            self.cell.screen_joints(positioned(self.case, variables).machine, q_c, T[None])
            for q_c, T, variables in zip(q, T_base_part, pose, strict=True)
        ]
        return np.concatenate([f[0] for f in found]), np.concatenate([f[1] for f in found])

    def external_axes(
        self, X: np.ndarray, pose: np.ndarray
    ) -> tuple[np.ndarray | None, dict[int, AxesFailure]]:
        """A machine's external axes on the screening grid at placements X (B, 6) with the
        positioner pose's searched variables (B, k), shape (B, M, e)
        (:func:`~trackplan.axes.choose.choose_axes` per candidate; None for a robot), and
        the candidates whose axes cannot keep the downhand rule, by row (their axes held,
        to grade how far they are from the rest)."""
        if not isinstance(self.case.machine, Machine):
            return None, {}
        tool, downhand = self.case.task.tool, self.case.downhand
        found = []
        failed: dict[int, AxesFailure] = {}
        for b, (x, variables) in enumerate(zip(X, pose, strict=True)):
            machine = positioned(self.case, variables).machine
            assert isinstance(machine, Machine)
            axes = choose_axes(machine, self.geometry, tool, x, downhand)
            if isinstance(axes, AxesFailure):
                failed[b] = axes
                axes = choose_axes(machine, self.geometry, tool, x, None)
                assert isinstance(axes, AxesProfile)
            found.append(axes.values(self.s_grid))
        return np.stack(found), failed

    def rotations(self, spin: np.ndarray) -> np.ndarray:
        """``R_part_tool`` on the screening grid for spin variables (B, k), (B, M, 3, 3)."""
        tool = self.case.task.tool
        if not tool.n_spin:
            return self.R_base
        length = self.geometry.planned.length
        coefficients = tool.spin_coefficients(spin, length)
        return spin_rotations(self.R_base, spin_values(coefficients, self.s_grid, length))

    def plan_candidates(self, X: np.ndarray, branch: np.ndarray) -> list[PlanResult]:
        """This seam planned with the time law and checked at candidates X (B, 6 + k), each
        on its branch (B,): concurrently on the executor when one was given."""
        n_spin = self.case.task.tool.n_spin
        jobs = [
            (
                positioned(self.case, x[6 + n_spin :]),
                x[: 6 + n_spin],
                self.timing,
                int(b),
                self.geometry,
            )
            for x, b in zip(X, branch, strict=True)
        ]
        return list(self._map(plan_candidate, jobs))
