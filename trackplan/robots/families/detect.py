"""Which IK family a robot belongs to, decided once per robot from its chain at q = 0."""

from __future__ import annotations

import numpy as np

from trackplan.derived import derived
from trackplan.errors import CaseError
from trackplan.robots.families.base import N_BRANCHES, ClosedFormIK, IKFamily
from trackplan.robots.families.numeric import NumericFamily
from trackplan.robots.families.opw import OPWFamily, opw_from_chain
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


def _detect(robot: Robot) -> IKFamily:
    """OPW, else UR, else numeric."""
    opw = opw_from_chain(robot)
    if opw is not None:
        return OPWFamily(robot, opw)
    ur = ur_from_chain(robot)
    return URFamily(robot, ur) if ur is not None else NumericFamily(robot)


def solve_ik(robot: Robot, T_base_tool: np.ndarray) -> ClosedFormIK:
    """All eight closed-form IK solutions of tool poses.

    Parameters
    ----------
    robot
        A robot of the OPW or UR family.
    T_base_tool
        Tool poses in the base frame, shape (..., 4, 4), metres. The tool transform
        ``robot.T_flange_tool`` is removed exactly.

    Returns
    -------
    ClosedFormIK
        ``q`` of shape (..., 8, 6) in (−π, π] and ``valid`` of shape (..., 8).

    Raises
    ------
    CaseError
        When the robot has no closed form or the poses are not (..., 4, 4).
    """
    T = np.asarray(T_base_tool, dtype=float)
    if T.ndim < 2 or T.shape[-2:] != (4, 4):
        raise CaseError(f"T_base_tool must have shape (..., 4, 4), got {T.shape}")
    lead = T.shape[:-2]
    q, valid, _ = ik_family(robot).solve_flat(T.reshape(-1, 4, 4), with_aux=False)
    return ClosedFormIK(q.reshape(*lead, N_BRANCHES, 6), valid.reshape(*lead, N_BRANCHES))
