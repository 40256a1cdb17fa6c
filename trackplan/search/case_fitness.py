"""The fitness of a case: one placement for every seam, with the moves between them.

The decision vector holds the 6 placement variables, then each seam's spin variables in the
order written (:meth:`trackplan.search.space.SearchSpace.from_case`; :func:`spin_slices`).
The fitness of a batch of B candidates screens every seam on its own screening grid
(:class:`~trackplan.search.fitness.PlacementFitness`, each call batched over the whole
population and every IK branch, on the placement and the seam's own slice of spin
variables), keeps per seam and candidate the branch clear of the cell with the least J,
and adds the moves between the seams: per candidate the best sequence
(:func:`trackplan.planning.sequence.best_sequence`) on the estimated air moves between the
seams' end configurations on the screening grid
(:func:`trackplan.timing.airmove.air_time_estimate`; a reversed seam on the same branch
swaps its ends). A case of one seam and no home has no move. A candidate is feasible only if
every seam is (:func:`~trackplan.search.screening.evaluate_seams`).

Fitness (minimised)
-------------------
- feasible: ``Σ_seams (J + w·T) + air``, ``J`` Eq. 8 on each seam's screening grid,
  ``T`` the duration bound of :mod:`trackplan.search.fitness` (the planned duration where the
  time law runs in the search), ``w`` the time weight, and ``air`` the sequence's estimated
  moves, each costing ``Σ C_i |Δq_i| + w·T_air``;
- infeasible: ``M + v`` (graded) or ``M`` (flat), ``v`` the largest graded violation over
  the seams (the scale of :mod:`trackplan.search.fitness`).
"""

from __future__ import annotations

from concurrent.futures import Executor

import numpy as np

from trackplan.case import Case
from trackplan.paths.path_geometry import PathGeometry
from trackplan.search.fitness import SCREEN_POSES, PlacementFitness
from trackplan.search.positioner_pose import pose_indices
from trackplan.search.screening import Screening, SeamScreen, evaluate_seams
from trackplan.search.space import N_VAR, SearchSpace

POSE_SPACING = 0.005
"""Screening grid spacing along each seam of a case with several seams, m (about that of a
single 0.8 m path's 150 poses); short seams need far fewer poses than
:data:`~trackplan.search.fitness.SCREEN_POSES`."""
MIN_POSES = 20
"""Fewest poses of a seam's screening grid."""

SeamGeometries = dict[tuple[int, bool], PathGeometry]
"""Paths of each seam direction ``(seam index, reversed)`` for one time law's path mode."""

SeamSpin = np.ndarray | None
"""The spin variables of one seam's tool (n_spin,), or None for a fixed spin."""


def spin_slices(case: Case) -> tuple[slice, ...]:
    """Where each seam's spin variables lie in the decision vector (as written; an empty
    slice for a fixed spin)."""
    slices = []
    first = N_VAR
    for seam in case.seams:
        slices.append(slice(first, first + seam.task.tool.n_spin))
        first += seam.task.tool.n_spin
    return tuple(slices)


def pose_slice(case: Case) -> slice:
    """Where the positioner pose's searched variables lie in the decision vector: after
    every seam's spin variables (empty when the pose is fixed)."""
    first = spin_slices(case)[-1].stop
    return slice(first, first + len(pose_indices(case)))


def screening_poses(case: Case, geometries: SeamGeometries) -> tuple[int, ...]:
    """Target size of each seam's screening grid.

    One seam: :data:`~trackplan.search.fitness.SCREEN_POSES` (what the shipped single-path
    cases' figures in ``docs/search.md`` are measured with); several: one pose per
    :data:`POSE_SPACING` along each seam, at least :data:`MIN_POSES` (a tenth of the poses
    on short fillets, ``python -m benchmarks seams``). Only the grid differs: the
    fitness is the same mechanism.
    """
    if len(case.seams) == 1:
        return (SCREEN_POSES,)
    return tuple(
        max(MIN_POSES, int(np.ceil(geometries[i, False].planned.length / POSE_SPACING)) + 1)
        for i in range(len(case.seams))
    )


class CaseFitness:
    """The batched fitness of one placement for every seam (see the module docstring).

    Parameters
    ----------
    case
        The case.
    space
        Its search space (:meth:`SearchSpace.from_case`: the placement, then each seam's
        spin).
    geometries
        The seams' paths (:func:`trackplan.search.plan_calls.seam_geometries`); the forward
        direction of each is screened.
    timing
        The time law.
    executor
        Runs the time law of several candidates concurrently where it runs during the
        search (paper timing, or ``objective.time_weight > 0``); None: one after the other.

    Attributes
    ----------
    seams
        One :class:`~trackplan.search.fitness.PlacementFitness` per seam.
    feasible_count
        How many evaluated candidates reach each seam feasibly, shape (m,), int.
    slices
        Each seam's spin variables in the decision vector (:func:`spin_slices`).
    """

    def __init__(
        self,
        case: Case,
        space: SearchSpace,
        geometries: SeamGeometries,
        timing: str,
        *,
        executor: Executor | None = None,
    ):
        self.case = case
        self.space = space
        poses = screening_poses(case, geometries)
        self.seams = [
            PlacementFitness(
                case.seam_case(i),
                space,
                geometries[i, False],
                timing,
                n_poses=poses[i],
                executor=executor,
            )
            for i in range(len(case.seams))
        ]
        self.penalty = float(case.objective.flat_penalty)
        self.flat = self.seams[0].flat
        self.time_weight = float(case.objective.time_weight)
        self.weights = case.travel_weights
        self.reversible = np.array([seam.reversible for seam in case.seams])
        self.home = case.sequencing.home
        self.feasible_count = np.zeros(len(case.seams), dtype=int)
        self.slices = spin_slices(case)
        pose = pose_slice(case)
        # each seam's own variables after the placement: its spin, then the positioner pose
        self.columns = [
            np.r_[np.arange(part.start, part.stop), np.arange(pose.start, pose.stop)]
            for part in self.slices
        ]
        if space.n_var != pose_slice(case).stop:
            raise ValueError(
                f"the search space has {space.n_var} variables, the seams need "
                f"{pose_slice(case).stop} (use SearchSpace.from_case)"
            )

    def full(self, X: np.ndarray) -> np.ndarray:
        """Candidates (B, n_var); placements alone (B, 6) get every free spin in the middle
        of its range."""
        X = np.atleast_2d(np.asarray(X, dtype=float))
        if X.shape[1] == N_VAR and self.space.n_var > N_VAR:
            X = np.hstack([X, np.tile(self.space.anchor[N_VAR:], (len(X), 1))])
        return X

    def seam_spins(self, X: np.ndarray) -> tuple[SeamSpin, ...]:
        """Each seam's spin variables of one candidate X (n_var,), None for a fixed spin."""
        X = self.full(X)[0]
        return tuple(X[part] if part.stop > part.start else None for part in self.slices)

    def screen_seams(self, X: np.ndarray) -> SeamScreen:
        """Screen every seam of candidates inside the reach interval.

        Parameters
        ----------
        X
            Candidates, shape (B, n_var): placements (metres and radians), then the
            seams' spin variables.

        Returns
        -------
        SeamScreen
        """
        X = self.full(X)
        return SeamScreen.stack(
            [
                fitness.screen_seam(np.hstack([X[:, :N_VAR], X[:, part]]))
                for fitness, part in zip(self.seams, self.columns, strict=True)
            ]
        )

    def air_costs(self, seams: SeamScreen, feasible: np.ndarray) -> np.ndarray:
        """Estimated cost of the moves of the feasible candidates in their best sequences,
        shape (B,) (0 elsewhere, and for a case of one seam and no home: no move)."""
        costs = np.zeros(len(feasible))
        if len(self.seams) == 1 and self.home is None:
            return costs
        for k in np.flatnonzero(feasible):
            costs[k] = self.air_cost(seams, int(k))
        return costs

    def air_cost(self, seams: SeamScreen, b: int) -> float:
        """Estimated cost of the moves of candidate ``b`` in its best sequence: per move
        ``Σ C_i |Δq_i| + w · T``."""
        from trackplan.planning.sequence import best_sequence

        ends = np.stack([seams.q_first[:, b], seams.q_last[:, b]], axis=1)  # (m, 2, n)
        q_in = ends  # forward starts at the first end, reversed at the last
        q_out = ends[:, ::-1]
        air = self._move(q_out[:, :, None, None], q_in[None, None])
        m = len(self.seams)
        seam_cost = np.zeros((m, 2))
        if self.home is None:
            start = np.zeros((m, 2))
            end = np.zeros((m, 2))
        else:
            start = self._move(self.home, q_in)
            end = self._move(q_out, self.home)
        return float(best_sequence(seam_cost, air, start, end, self.reversible).cost)

    def _move(self, q_from: np.ndarray, q_to: np.ndarray) -> np.ndarray:
        robot = self.case.machine
        travel = np.sum(self.weights * np.abs(q_to - q_from), axis=-1)
        if self.time_weight == 0.0:
            return np.asarray(travel)
        from trackplan.timing.airmove import air_time_estimate

        duration = air_time_estimate(q_from, q_to, robot.v_max, robot.a_max, robot.j_max)
        return np.asarray(travel + self.time_weight * duration)

    def evaluate(self, X: np.ndarray, incumbent: float = np.inf) -> Screening:
        """Fitness of a batch of candidates.

        Parameters
        ----------
        X
            Candidates, shape (B, n_var) (placements alone, (B, 6): every free spin in the
            middle of its range).
        incumbent
            Best fitness found so far (where the time law runs in the search, only the
            candidates whose lower bound is below it are timed).

        Returns
        -------
        Screening
            ``objective`` is Σ J of the seams, ``duration_bound`` the sum of their bounds;
            ``branch`` the first seam's branch.
        """
        screening, seams = evaluate_seams(
            self.space, self.seams, self.columns, self.full(X), incumbent, self.air_costs
        )
        if seams is not None:
            self.feasible_count += seams.ok.sum(axis=1)
        return screening

    def branches(self, X: np.ndarray) -> tuple[int, ...]:
        """The branch the screening chooses for each seam at one candidate X (n_var,)."""
        seams = self.screen_seams(np.asarray(X, dtype=float)[None])
        return tuple(int(b) for b in seams.branch[:, 0])

    def unreachable_seams(self) -> tuple[str, ...]:
        """Seams that no evaluated candidate reached feasibly, by name."""
        names = self.case.seams
        return tuple(names[i].name for i in np.flatnonzero(self.feasible_count == 0))
