"""The protocol every IK family implements, and the closed-form result type."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Protocol

import numpy as np

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
        return np.any(self.valid, axis=-1)


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
        self, T_base_tool: np.ndarray, *, with_aux: bool = True
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """All branches of a flat batch of tool poses (N, 4, 4).

        ``with_aux=False`` skips the branch quantities (aux is then (1, 8, 5) scratch).

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


CHUNK = 2048
"""Poses per pass of a closed-form solver: its scratch stays in the L2 cache."""


def solve_in_chunks(
    arguments: Callable[..., None],
    assemble: Callable[..., None],
    n_angles: int,
    geometry: np.ndarray,
    tail_inv: np.ndarray,
    T_base_tool: np.ndarray,
    with_aux: bool,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Run a closed-form family's compiled kernels over poses, :data:`CHUNK` at a time.

    A family's solver is two kernels around one vectorised ``arctan2``: ``arguments``
    writes the sine and cosine arguments of every angle of every branch (and the validity
    flags and branch quantities), ``assemble`` turns the angles into joint values.

    Parameters
    ----------
    arguments, assemble
        The family's kernels (``opw_*`` or ``ur_*`` of ``families/_kernels.py``).
    n_angles
        Angles the arguments kernel writes per pose.
    geometry, tail_inv
        The family's parameter array and the inverse of its tool transform, as the
        kernels take them.
    T_base_tool
        Tool poses, shape (N, 4, 4), m.
    with_aux
        False skips the branch quantities (aux is then (1, 8, AUX_SIZE) scratch).

    Returns
    -------
    tuple of numpy.ndarray
        q (N, 8, 6) rad, valid (N, 8) bool, aux (N, 8, AUX_SIZE).
    """
    T = np.ascontiguousarray(T_base_tool, dtype=float)
    n_poses = T.shape[0]
    q = np.empty((n_poses, N_BRANCHES, 6))
    valid = np.empty((n_poses, N_BRANCHES), dtype=np.bool_)
    aux = np.empty((n_poses if with_aux else 1, N_BRANCHES, AUX_SIZE))
    size = min(CHUNK, n_poses)
    Y = np.zeros((size, n_angles))  # slots a pose leaves unset stay finite
    X = np.ones((size, n_angles))
    angles = np.empty((size, n_angles))
    for start in range(0, n_poses, CHUNK):
        stop = min(start + CHUNK, n_poses)
        m = stop - start
        arguments(
            geometry,
            tail_inv,
            T[start:stop],
            Y[:m],
            X[:m],
            valid[start:stop],
            aux[start:stop] if with_aux else aux,
        )
        np.arctan2(Y[:m], X[:m], out=angles[:m])
        assemble(geometry, angles[:m], valid[start:stop], q[start:stop])
    return q, valid, aux
