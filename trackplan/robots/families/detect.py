"""Which IK family a robot belongs to, decided once per robot from its chain at q = 0."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from trackplan.derived import derived
from trackplan.errors import CaseError
from trackplan.robots.families.base import ClosedFormIK, IKFamily
from trackplan.robots.families.crx import CRXFamily, crx_from_chain
from trackplan.robots.families.numeric import NumericFamily
from trackplan.robots.families.opw import OPWFamily, opw_from_chain
from trackplan.robots.families.panda import PandaFamily, panda_from_chain
from trackplan.robots.families.srs import SRSFamily, srs_from_chain
from trackplan.robots.families.ur import URFamily, ur_from_chain
from trackplan.robots.model import Robot


def ik_family(robot: Robot) -> IKFamily:
    """The IK family of a robot: OPW, else UR, else numeric (cached per robot).

    Parameters
    ----------
    robot
        Any robot.

    Returns
    -------
    IKFamily
        :class:`OPWFamily`, :class:`URFamily` or :class:`NumericFamily`.
    """
    return derived(robot, "ik family", lambda: _detect(robot))


STRUCTURED_FAMILIES: dict[str, tuple[Callable[[Robot], object | None], Callable[..., IKFamily]]] = {
    "opw": (opw_from_chain, OPWFamily),
    "ur": (ur_from_chain, URFamily),
    "srs": (srs_from_chain, SRSFamily),
    "panda": (panda_from_chain, PandaFamily),
    "crx": (crx_from_chain, CRXFamily),
}
"""The structured families, tried in this order: how to derive each one's parameters from a
chain (None when the chain is not of the family) and the family built from them."""


def _detect(robot: Robot) -> IKFamily:
    """The family the robot file names (``ik.family``), else the first of
    :data:`STRUCTURED_FAMILIES` whose structure the chain has, else numeric.

    Raises
    ------
    CaseError
        When the named family does not fit the chain.
    """
    choice = robot.ik
    if choice.family == "numeric":
        return NumericFamily(robot, choice.free_joint)
    if choice.family != "auto":
        if choice.family not in STRUCTURED_FAMILIES:
            raise CaseError(
                f"unknown IK family {choice.family!r}: expected one of auto, "
                f"{', '.join(STRUCTURED_FAMILIES)}, numeric",
                key="ik.family",
            )
        derive, family = STRUCTURED_FAMILIES[choice.family]
        params = derive(robot)
        if params is None:
            raise CaseError(
                f"the chain of {robot.name} does not have the {choice.family} structure "
                "(without ik.family, trackplan robots FILE shows the detected one): "
                "use ik.family auto or numeric",
                key="ik.family",
            )
        return family(robot, params)
    for derive, family in STRUCTURED_FAMILIES.values():
        params = derive(robot)
        if params is not None:
            return family(robot, params)
    return NumericFamily(robot, choice.free_joint)


def solve_ik(robot: Robot, T_base_tool: np.ndarray, free: np.ndarray | None = None) -> ClosedFormIK:
    """Every closed-form IK solution of tool poses.

    Parameters
    ----------
    robot
        A robot of a closed-form family (OPW, UR, S-R-S, Panda).
    T_base_tool
        Tool poses in the base frame, shape (..., 4, 4), metres. The tool transform
        ``robot.T_flange_tool`` is removed exactly.
    free
        A redundant arm's free parameter per pose, shape (...,), rad; None for the others.

    Returns
    -------
    ClosedFormIK
        ``q`` of shape (..., K, n) in (−π, π] and ``valid`` of shape (..., K), K the
        family's branches (8).

    Raises
    ------
    CaseError
        When the robot has no closed form or the poses are not (..., 4, 4).
    """
    T = np.asarray(T_base_tool, dtype=float)
    if T.ndim < 2 or T.shape[-2:] != (4, 4):
        raise CaseError(f"T_base_tool must have shape (..., 4, 4), got {T.shape}")
    lead = T.shape[:-2]
    family = ik_family(robot)
    flat_free = None if free is None else np.asarray(free, dtype=float).reshape(-1)
    q, valid, _ = family.solve_flat(T.reshape(-1, 4, 4), free=flat_free, with_aux=False)
    n_k = family.n_branches
    return ClosedFormIK(q.reshape(*lead, n_k, robot.n_dof), valid.reshape(*lead, n_k))
