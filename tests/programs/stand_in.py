"""An export source that serves a given program, for the writer tests that need no run."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np

from trackplan.io.export import TrajectoryTable
from trackplan.programs import Program
from trackplan.robots.model import Robot
from trackplan.writers import ExportSource


@dataclass(eq=False, kw_only=True)
class StandInSource(ExportSource):
    """:class:`ExportSource` whose :meth:`program` is ``build(**arguments)`` and whose
    robot is given: the writer's own code (``program_of``, ``robot``) runs unchanged."""

    build: Callable[..., Program]
    given_robot: Robot

    def program(self, **arguments: Any) -> Program:  # type: ignore[override]
        return self.build(**arguments)

    @property
    def robot(self) -> Robot:
        return self.given_robot


def stand_in(build: Callable[..., Program], robot: Robot) -> StandInSource:
    """A source of one resting sample whose program is ``build(motion=, name=, period=,
    force=)``."""
    n = robot.n_dof
    table = TrajectoryTable(
        joint_names=robot.joint_names,
        t=np.zeros(1),
        q=np.zeros((1, n)),
        qd=np.zeros((1, n)),
        qdd=np.zeros((1, n)),
        qddd=np.zeros((1, n)),
        tool_position=np.zeros((1, 3)),
        speed=np.zeros(1),
    )
    return StandInSource(table=table, build=build, given_robot=robot)
