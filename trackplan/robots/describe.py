"""What a robot is, in plain data: family, derived parameters, reach and assumptions.

Used by ``trackplan robots`` and written into ``result.json`` as the ``robot`` block.
"""

from __future__ import annotations

from trackplan.robots.families import ik_family
from trackplan.robots.families.numeric import REDUNDANCY_RULE
from trackplan.robots.model import Robot


def robot_info(robot: Robot) -> dict[str, object]:
    """The robot block of ``result.json``.

    Returns
    -------
    dict
        ``name``, ``joints``, ``family`` (opw, ur or numeric), ``parameters`` (the
        derived family parameters, m and rad), ``reach`` (m), ``source``, ``assumptions``
        (limits that were assumed, one sentence each), ``link_capsules`` (how many
        capsules model the links, 0 for none) and, for a redundant arm, ``redundancy`` (its
        free parameter's name and natural range, rad; longer chains: ``redundancy_rule``).
    """
    family = ik_family(robot)
    info: dict[str, object] = {
        "name": robot.name,
        "joints": robot.n_dof,
        "family": family.name,
        "parameters": {
            key: value for key, value in family.parameters().items() if key != "redundancy"
        },
        "reach": round(robot.reach, 6),
        "source": robot.source,
        "assumptions": list(robot.assumptions),
        "link_capsules": 0 if robot.collision is None else len(robot.collision),
    }
    if family.redundancy is not None:
        info["redundancy"] = {
            "parameter": family.redundancy.name,
            "range": [family.redundancy.lower, family.redundancy.upper],
        }
    elif robot.n_dof > 6:
        info["redundancy_rule"] = REDUNDANCY_RULE
    return info
