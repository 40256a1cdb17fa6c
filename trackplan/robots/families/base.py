"""The protocol every IK family implements, and the closed-form result type."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Protocol

import numpy as np

from trackplan._kernels import read_only
from trackplan.errors import CaseError

N_BRANCHES = 8
"""Number of labelled solutions of a pose of the OPW and UR families (and of the numeric
family's starting seeds)."""

AUX_SIZE = 5
"""Per pose and branch, the branch-defining quantities a closed-form solver writes: the
shoulder measure (m, ≥ 0, zero at the shoulder singularity), the elbow measure
(≥ 0, zero with the arm stretched or folded) and a wrist vector (3,) whose norm is zero
at the wrist singularity and which reverses when the path crosses it."""


def branch_bits(branch: int) -> tuple[int, int, int]:
    """The (shoulder, elbow, wrist) bits of a branch number ``4·shoulder + 2·elbow + wrist``."""
    return (branch >> 2) & 1, (branch >> 1) & 1, branch & 1


def describe_bits(branch: int) -> str:
    """A short name of a closed-form branch, e.g. ``"front/elbow up/wrist 0"``."""
    shoulder, elbow, wrist = branch_bits(branch)
    return "/".join(
        (
            ("front", "back")[shoulder],
            ("elbow up", "elbow down")[elbow],
            ("wrist 0", "wrist flipped")[wrist],
        )
    )


@dataclass(frozen=True, eq=False)
class ClosedFormIK:
    """All eight closed-form solutions of a batch of poses.

    Attributes
    ----------
    q
        Joint positions, shape (..., 8, n), rad, in (−π, π]; NaN where not ``valid``.
        Axis −2 is the branch ``b = 4·shoulder + 2·elbow + wrist``.
    valid
        Shape (..., 8), bool: the branch reaches the pose (joint limits not applied).
    """

    q: np.ndarray
    valid: np.ndarray

    @property
    def reachable(self) -> np.ndarray:
        """Shape (...,), bool: at least one branch reaches the pose."""
        reached: np.ndarray = np.any(self.valid, axis=-1)
        return reached


@dataclass(frozen=True)
class RedundancyParameter:
    """The free parameter of a redundant (7-joint) arm's IK.

    A pose of a 7-joint arm has a one-parameter family of solutions on each branch; one
    value of this parameter per pose picks one of them. The planner chooses it along the
    path as a free profile (``docs/robots.md``, "Redundancy").

    Attributes
    ----------
    name
        ``"arm angle"`` (the elbow's angle about the shoulder–wrist line, S-R-S arms) or
        ``"joint k"`` (k 1-based: that joint's own position).
    lower, upper
        The parameter's natural range, rad: [−π, π] for the arm angle, the joint's
        position limits for a joint.
    joint
        The joint it is (0-based), or None for the arm angle.
    """

    name: str
    lower: float
    upper: float
    joint: int | None = None


class IKFamily(Protocol):
    """What the path IK needs from a family of arms.

    Two kinds of family:

    - **closed form** (``closed_form`` True: OPW, UR, S-R-S, Panda): :meth:`solve_flat`
      gives the :attr:`n_branches` labelled solutions of every pose, a label keeping its
      meaning along a path until a singularity; the path IK solves every pose on a
      branch.
    - **tracked** (``closed_form`` False: the CRX family, numeric): :meth:`seed_solutions`
      gives the distinct solutions of one pose (up to :attr:`n_branches`); the path IK
      starts a branch at each solution of the path's first pose and follows it by
      warm-started Newton steps (a cuspidal arm changes solution without a singularity,
      so labels do not keep their meaning along a path).

    A redundant family (:attr:`redundancy` not None) takes the value of its free
    parameter at every pose (``free``, shape (N,), rad); the others take ``free=None``.

    Attributes
    ----------
    name
        ``"opw"``, ``"ur"``, ``"srs"``, ``"panda"``, ``"crx"`` or ``"numeric"``.
    closed_form
        True when :meth:`solve_flat` gives every branch in closed form.
    n_branches
        K: labelled solutions per pose (closed form; unused columns are never valid), or
        most distinct solutions tracked from a path's first pose.
    redundancy
        The free parameter of a 7-joint family, else None.
    """

    name: str
    closed_form: bool
    n_branches: int
    redundancy: RedundancyParameter | None

    def parameters(self) -> dict[str, object]:
        """The derived parameters, for display (lengths m, angles rad)."""
        ...

    def describe_branch(self, branch: int) -> str:
        """A short human-readable name of a branch."""
        ...

    def solve_flat(
        self,
        T_base_tool: np.ndarray,
        *,
        free: np.ndarray | None = None,
        with_aux: bool = True,
        out: tuple[np.ndarray, np.ndarray, np.ndarray] | None = None,
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """All branches of a flat batch of tool poses (N, 4, 4) (closed form only).

        ``free``: the redundancy parameter per pose, shape (N,), rad (redundant families
        only). ``with_aux=False`` skips the branch quantities (aux is then (1, K, 5)
        scratch). ``out``: C-contiguous arrays (q, valid, aux) of the shapes below to write
        into and return instead of new ones (with_aux is then ignored).

        Returns
        -------
        q
            Shape (N, K, n), rad in (−π, π], NaN where not valid.
        valid
            Shape (N, K), bool (joint limits not applied).
        aux
            Shape (N, K, :data:`AUX_SIZE`): the branch-defining quantities, NaN out of reach.
        """
        ...

    def solve_branch(
        self,
        T_base_tool: np.ndarray,
        branch: int,
        *,
        free: np.ndarray | None = None,
        with_aux: bool = False,
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """One branch of a flat batch of tool poses (N, 4, 4): what :meth:`solve_flat`
        gives for that branch, solving that branch only (closed form only).

        Returns
        -------
        q
            Shape (N, n), rad in (−π, π], NaN where not valid.
        valid
            Shape (N,), bool.
        aux
            Shape (N, :data:`AUX_SIZE`) (``with_aux``), else (1, AUX_SIZE) scratch.
        """
        ...

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
        """:meth:`solve_branch` of poses given by their rotations (N, 3, 3), or one rotation
        (3, 3) for all, and positions (N, 3), m: no (N, 4, 4) array needed.

        ``wind_to = (s, s_grid, q_grid)`` (shapes (N,), (G,), (G, n)) then holds the
        joints of a missed pose at those of the reachable pose before it and moves each
        joint by the multiple of 2π nearest the linear interpolation of ``q_grid`` at ``s``,
        in the same compiled pass (``hold_and_wind`` of ``families/_kernels.py``).
        """
        ...

    def seed_solutions(
        self,
        T_base_tool: np.ndarray,
        q_min: np.ndarray,
        q_max: np.ndarray,
        *,
        free: np.ndarray | None = None,
    ) -> tuple[np.ndarray, np.ndarray]:
        """The distinct IK solutions of each pose inside the position limits (every family).

        Parameters
        ----------
        T_base_tool
            Tool poses, shape (N, 4, 4), m.
        q_min, q_max
            Position limits, shape (n,), rad: a solution is moved by multiples of 2π
            into them where it fits, and dropped where it does not.
        free
            The redundancy parameter per pose, shape (N,), rad (redundant families).

        Returns
        -------
        q
            Shape (N, K, n), rad; NaN where not ``found``. Solutions that agree to 1e-6
            rad in every joint are one; they fill the columns in a fixed order (a closed
            form's branch order; a tracked family's own), the found ones first.
        found
            Shape (N, K), bool.
        """
        ...


class FusedClosedForm:
    r"""The solve methods of a closed-form family (:class:`IKFamily`) whose compiled kernels
    (``families/_opw_kernels.py``, ``_ur_kernels.py``, ``_srs_kernels.py``,
    ``_panda_kernels.py``) take its parameter array and the inverse of its tool transform.

    A subclass sets ``_geometry`` and ``_tail_inv``, ``_n_joints`` (6, or 7 for a redundant
    arm) and names its kernels: ``_all_branches`` (poses in, eight branches out, e.g.
    ``opw_solve``) and ``_one_branch`` (e.g. ``opw_solve_branch``), as ``staticmethod``\ s.
    A redundant family (``redundancy`` not None) has kernels that take the free parameter
    per pose right after the poses (all branches) or the positions (one branch).
    """

    closed_form = True
    n_branches = N_BRANCHES
    redundancy: RedundancyParameter | None = None
    _n_joints = 6
    _all_branches: Callable[..., None]
    _one_branch: Callable[..., None]
    _geometry: np.ndarray
    _tail_inv: np.ndarray

    def _free_arguments(self, free: np.ndarray | None, n_poses: int) -> tuple[np.ndarray, ...]:
        """The kernels' free-parameter argument: none without redundancy, else the values
        (N,), C-contiguous (a scalar applies to every pose).

        Raises
        ------
        ValueError
            When the free parameter is missing, or given to a family without one.
        """
        if self.redundancy is None:
            _no_free(free)
            return ()
        if free is None:
            raise ValueError(
                f"this IK family needs its {self.redundancy.name} per pose: pass free (N,), rad"
            )
        values = np.broadcast_to(np.asarray(free, dtype=float), (n_poses,))
        return (read_only(np.ascontiguousarray(values)),)

    def solve_flat(
        self,
        T_base_tool: np.ndarray,
        *,
        free: np.ndarray | None = None,
        with_aux: bool = True,
        out: tuple[np.ndarray, np.ndarray, np.ndarray] | None = None,
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """All eight branches of poses (N, 4, 4), m, at the free parameter ``free`` (N,)
        of a redundant family (None otherwise): q (N, 8, n) rad, valid (N, 8) bool, aux
        (N, 8, AUX_SIZE); ``with_aux=False`` skips the branch quantities (aux is then
        (1, 8, AUX_SIZE) scratch); ``out`` (q, valid, aux) of those shapes are written
        instead of new arrays (the kernel releases the GIL: threads may solve at once)."""
        T = np.ascontiguousarray(T_base_tool, dtype=float)
        n_poses = T.shape[0]
        free_arguments = self._free_arguments(free, n_poses)
        if out is not None:
            q, valid, aux = out
        else:
            q = np.empty((n_poses, N_BRANCHES, self._n_joints))
            valid = np.empty((n_poses, N_BRANCHES), dtype=np.bool_)
            aux = np.empty((n_poses if with_aux else 1, N_BRANCHES, AUX_SIZE))
        self._all_branches(
            read_only(self._geometry),
            read_only(self._tail_inv),
            read_only(T),
            *free_arguments,
            q,
            valid,
            aux,
        )
        return q, valid, aux

    def solve_branch(
        self,
        T_base_tool: np.ndarray,
        branch: int,
        *,
        free: np.ndarray | None = None,
        with_aux: bool = False,
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Branch ``branch`` of poses (N, 4, 4) alone: q (N, n), valid (N,), aux (N, 5)
        (or (1, 5) scratch without ``with_aux``), the values :meth:`solve_flat` gives for
        it."""
        T = np.asarray(T_base_tool, dtype=float)
        return self.solve_branch_parts(
            T[:, :3, :3], T[:, :3, 3], branch, free=free, with_aux=with_aux
        )

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
        """:meth:`solve_branch` of poses given by rotations (N, 3, 3) (or one, (3, 3)) and
        positions (N, 3), m; ``wind_to`` None, or (s, s_grid, q_grid) to hold and wind the
        joints (:meth:`IKFamily.solve_branch_parts`).

        Returns
        -------
        tuple of numpy.ndarray
            q (N, n) rad (NaN where not valid, unless wound), valid (N,) bool, aux
            (N, AUX_SIZE).
        """
        R = np.ascontiguousarray(R_base_tool, dtype=float).reshape(-1, 3, 3)
        p = np.ascontiguousarray(p_base_tool, dtype=float)
        n_poses = p.shape[0]
        free_arguments = self._free_arguments(free, n_poses)
        q = np.empty((n_poses, self._n_joints))
        valid = np.empty(n_poses, dtype=np.bool_)
        aux = np.empty((n_poses if with_aux else 1, AUX_SIZE))
        if wind_to is None:
            s, s_grid, q_grid = np.empty(0), np.empty(0), np.empty((0, self._n_joints))
        else:
            s, s_grid, q_grid = (np.ascontiguousarray(x, dtype=float) for x in wind_to)
        self._one_branch(
            read_only(self._geometry),
            read_only(self._tail_inv),
            read_only(R),
            read_only(p),
            *free_arguments,
            int(branch),
            q,
            valid,
            aux,
            read_only(s),
            read_only(s_grid),
            read_only(q_grid),
        )
        return q, valid, aux

    def seed_solutions(
        self,
        T_base_tool: np.ndarray,
        q_min: np.ndarray,
        q_max: np.ndarray,
        *,
        free: np.ndarray | None = None,
    ) -> tuple[np.ndarray, np.ndarray]:
        """The eight branches of poses (N, 4, 4) inside the limits, deduplicated
        (:func:`closed_form_seeds`)."""
        return closed_form_seeds(self, T_base_tool, q_min, q_max, free)


class TrackedFamily:
    """The closed-form calls of a tracked family (:class:`IKFamily` with ``closed_form``
    False: the CRX family, numeric IK), refused: its branches are solutions followed along
    a path from its first pose (:meth:`IKFamily.seed_solutions`), not labels a pose can be
    solved for."""

    closed_form = False
    name: str

    def solve_flat(
        self,
        T_base_tool: np.ndarray,
        *,
        free: np.ndarray | None = None,
        with_aux: bool = True,
        out: tuple[np.ndarray, np.ndarray, np.ndarray] | None = None,
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Not available: a tracked family's solutions come from :meth:`seed_solutions`.

        Raises
        ------
        CaseError
            Always.
        """
        raise CaseError(
            f"this robot has no closed-form IK (the {self.name} family: its solutions are "
            "tracked along a path): use seed_solutions and trackplan.robots.ik_numeric",
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
        """Not available (:meth:`solve_flat`)."""
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
        """Not available (:meth:`solve_flat`)."""
        return self.solve_flat(np.empty((0, 4, 4)))


class SolvesFlat(Protocol):
    """Anything with :meth:`IKFamily.solve_flat` (a closed-form family)."""

    def solve_flat(
        self,
        T_base_tool: np.ndarray,
        *,
        free: np.ndarray | None = None,
        with_aux: bool = True,
        out: tuple[np.ndarray, np.ndarray, np.ndarray] | None = None,
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """All branches of poses (N, 4, 4): q (N, K, n), valid (N, K), aux."""
        ...


def closed_form_seeds(
    family: SolvesFlat,
    T_base_tool: np.ndarray,
    q_min: np.ndarray,
    q_max: np.ndarray,
    free: np.ndarray | None,
) -> tuple[np.ndarray, np.ndarray]:
    """:meth:`IKFamily.seed_solutions` of a closed-form family: its branches of each pose,
    each joint moved by the multiple of 2π that puts it in its limits (the lowest that
    fits), a branch dropped where a joint fits nowhere or it repeats an earlier branch
    (within :data:`SAME_SOLUTION`), in branch order.

    Returns
    -------
    q, found
        Shapes (N, K, n) (NaN where not found) and (N, K).
    """
    q, valid, _ = family.solve_flat(
        np.ascontiguousarray(T_base_tool, dtype=float), free=free, with_aux=False
    )
    return wrap_and_deduplicate(q, valid, q_min, q_max)


SAME_SOLUTION = 1e-6
"""Largest joint difference (rad) between two solutions of one pose that are the same."""


def wrap_and_deduplicate(
    q: np.ndarray, valid: np.ndarray, q_min: np.ndarray, q_max: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """Solutions (N, K, n) with their validity (N, K): each joint moved into [q_min, q_max]
    by the lowest multiple of 2π that fits, the solutions that fit nowhere or repeat an
    earlier column (every joint within :data:`SAME_SOLUTION`) dropped, the rest moved to
    the front in their order.

    Returns
    -------
    q, found
        Shapes (N, K, n) (NaN where not found) and (N, K), bool.
    """
    two_pi = 2.0 * np.pi
    lifted = q + two_pi * np.ceil((q_min - q) / two_pi)  # the lowest ≥ q_min
    fits = valid & np.all(lifted <= q_max, axis=-1)
    lifted = np.where(fits[..., None], lifted, np.nan)
    n_k = q.shape[1]
    same = np.all(np.abs(lifted[:, :, None] - lifted[:, None, :]) <= SAME_SOLUTION, axis=-1)
    earlier = np.tril(np.ones((n_k, n_k), dtype=bool), -1)  # [k, j]: j before k
    repeat = np.any(same & earlier & fits[:, None, :], axis=-1)
    found = fits & ~repeat
    order = np.argsort(~found, axis=1, kind="stable")  # found first, in order
    rows = np.arange(len(q))[:, None]
    ordered = np.where(found[rows, order][..., None], lifted[rows, order], np.nan)
    return ordered, found[rows, order]


def _no_free(free: np.ndarray | None) -> None:
    """Refuse a redundancy parameter given to a family without redundancy."""
    if free is not None:
        raise ValueError("this IK family has no redundancy parameter: pass free=None")
