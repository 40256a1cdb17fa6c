"""The protocol every IK family implements, and the closed-form result type."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Protocol

import numpy as np

from trackplan._kernels import read_only

N_BRANCHES = 8
"""Number of closed-form solutions of a pose (and of numeric seeds)."""

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


class IKFamily(Protocol):
    """What the path IK needs from a family of arms.

    Attributes
    ----------
    name
        ``"opw"``, ``"ur"`` or ``"numeric"``.
    closed_form
        True when :meth:`solve_flat` gives all eight branches in closed form; False for
        the numeric family, whose branches are seeds
        (:func:`trackplan.robots.path_ik.numeric_seeds`).
    """

    name: str
    closed_form: bool

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
        with_aux: bool = True,
        out: tuple[np.ndarray, np.ndarray, np.ndarray] | None = None,
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """All branches of a flat batch of tool poses (N, 4, 4).

        ``with_aux=False`` skips the branch quantities (aux is then (1, 8, 5) scratch).
        ``out``: C-contiguous arrays (q, valid, aux) of the shapes below to write into
        and return instead of new ones (with_aux is then ignored).

        Returns
        -------
        q
            Shape (N, 8, 6), rad in (−π, π], NaN where not valid.
        valid
            Shape (N, 8), bool.
        aux
            Shape (N, 8, :data:`AUX_SIZE`): the branch-defining quantities, NaN out of reach.
        """
        ...

    def solve_branch(
        self, T_base_tool: np.ndarray, branch: int, *, with_aux: bool = False
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """One branch of a flat batch of tool poses (N, 4, 4): what :meth:`solve_flat`
        gives for that branch, solving that branch only.

        ``with_aux=True`` keeps the branch quantities (else aux is (1, 5) scratch).

        Returns
        -------
        q
            Shape (N, 6), rad in (−π, π], NaN where not valid.
        valid
            Shape (N,), bool.
        aux
            Shape (N, :data:`AUX_SIZE`): that branch's quantities of :meth:`solve_flat`.
        """
        ...

    def solve_branch_parts(
        self,
        R_base_tool: np.ndarray,
        p_base_tool: np.ndarray,
        branch: int,
        *,
        with_aux: bool,
        wind_to: tuple[np.ndarray, np.ndarray, np.ndarray] | None = None,
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """:meth:`solve_branch` of poses given by their rotations (N, 3, 3), or one rotation
        (3, 3) for all, and positions (N, 3), m: no (N, 4, 4) array needed.

        ``wind_to = (s, s_grid, q_grid)`` (shapes (N,), (G,), (G, 6)) then holds the
        joints of a missed pose at those of the reachable pose before it and moves each
        joint by the multiple of 2π nearest the linear interpolation of ``q_grid`` at ``s``,
        in the same compiled pass (``hold_and_wind`` of ``families/_kernels.py``).
        """
        ...


class FusedClosedForm:
    r"""The solve methods of a closed-form family (:class:`IKFamily`) whose compiled kernels
    (``families/_opw_kernels.py``, ``families/_ur_kernels.py``) take its parameter array
    and the inverse of its tool transform.

    A subclass sets ``_geometry`` and ``_tail_inv`` and names its kernels: ``_all_branches``
    (pose in, eight branches out: ``opw_solve``, ``ur_solve``) and ``_one_branch``
    (``opw_solve_branch``, ``ur_solve_branch``), as ``staticmethod``\ s.
    """

    closed_form = True
    _all_branches: Callable[..., None]
    _one_branch: Callable[..., None]
    _geometry: np.ndarray
    _tail_inv: np.ndarray

    def solve_flat(
        self,
        T_base_tool: np.ndarray,
        *,
        with_aux: bool = True,
        out: tuple[np.ndarray, np.ndarray, np.ndarray] | None = None,
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """All eight branches of poses (N, 4, 4), m: q (N, 8, 6) rad, valid (N, 8) bool,
        aux (N, 8, AUX_SIZE); ``with_aux=False`` skips the branch quantities (aux is then
        (1, 8, AUX_SIZE) scratch); ``out`` (q, valid, aux) of those shapes are written
        instead of new arrays (the kernel releases the GIL: threads may solve at once)."""
        T = np.ascontiguousarray(T_base_tool, dtype=float)
        n_poses = T.shape[0]
        if out is not None:
            q, valid, aux = out
        else:
            q = np.empty((n_poses, N_BRANCHES, 6))
            valid = np.empty((n_poses, N_BRANCHES), dtype=np.bool_)
            aux = np.empty((n_poses if with_aux else 1, N_BRANCHES, AUX_SIZE))
        self._all_branches(
            read_only(self._geometry), read_only(self._tail_inv), read_only(T), q, valid, aux
        )
        return q, valid, aux

    def solve_branch(
        self, T_base_tool: np.ndarray, branch: int, *, with_aux: bool = False
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Branch ``branch`` of poses (N, 4, 4) alone: q (N, 6), valid (N,), aux (N, 5) (or
        (1, 5) scratch without ``with_aux``), the values :meth:`solve_flat` gives for it."""
        T = np.asarray(T_base_tool, dtype=float)
        return self.solve_branch_parts(T[:, :3, :3], T[:, :3, 3], branch, with_aux=with_aux)

    def solve_branch_parts(
        self,
        R_base_tool: np.ndarray,
        p_base_tool: np.ndarray,
        branch: int,
        *,
        with_aux: bool,
        wind_to: tuple[np.ndarray, np.ndarray, np.ndarray] | None = None,
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """:meth:`solve_branch` of poses given by rotations (N, 3, 3) (or one, (3, 3)) and
        positions (N, 3), m; ``wind_to`` None, or (s, s_grid, q_grid) to hold and wind the
        joints (:meth:`IKFamily.solve_branch_parts`).

        Returns
        -------
        tuple of numpy.ndarray
            q (N, 6) rad (NaN where not valid, unless wound), valid (N,) bool, aux
            (N, AUX_SIZE).
        """
        R = np.ascontiguousarray(R_base_tool, dtype=float).reshape(-1, 3, 3)
        p = np.ascontiguousarray(p_base_tool, dtype=float)
        n_poses = p.shape[0]
        q = np.empty((n_poses, 6))
        valid = np.empty(n_poses, dtype=np.bool_)
        aux = np.empty((n_poses if with_aux else 1, AUX_SIZE))
        if wind_to is None:
            s, s_grid, q_grid = _NO_GRID
        else:
            s, s_grid, q_grid = (np.ascontiguousarray(x, dtype=float) for x in wind_to)
        self._one_branch(
            read_only(self._geometry),
            read_only(self._tail_inv),
            read_only(R),
            read_only(p),
            int(branch),
            q,
            valid,
            aux,
            read_only(s),
            read_only(s_grid),
            read_only(q_grid),
        )
        return q, valid, aux


_NO_GRID = (np.empty(0), np.empty(0), np.empty((0, 6)))
"""The kernels' reference arguments when the joints are not wound (s_grid empty)."""
