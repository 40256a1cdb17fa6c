"""The work cell: obstacles, the workpiece, robot link and tool capsules, and distances.

- :mod:`trackplan.cell.model`: bodies and capsules as data (:class:`Cell`).
- :mod:`trackplan.cell.robot_bodies`: the robot's link capsules in the cell, self-collision pairs.
- :mod:`trackplan.cell.screening`: the cell laid out for the batched compiled kernel.
- :mod:`trackplan.cell.exact`: exact distances through coal.
- :mod:`trackplan.cell.check`: the exact check of a trajectory (clearance, collisions).
"""

from trackplan.cell.model import DEFAULT_CLEARANCE, Body, Capsules, Cell, Shape

__all__ = ["DEFAULT_CLEARANCE", "Body", "Capsules", "Cell", "Shape"]
