"""The downhand rule of a welding cell (case key ``downhand``)."""

from __future__ import annotations

import math
from dataclasses import dataclass

from trackplan.errors import CaseError


@dataclass(frozen=True)
class Downhand:
    """Keep the weld flat: bounds on the weld's slope and rotation at every sample.

    Attributes
    ----------
    slope
        Largest angle of the travel direction to the horizontal plane, rad.
    rotation
        Largest angle of the weld normal (``task.tool.normal``) to straight up (+z of the
        cell frame), rad.
    """

    slope: float = math.radians(10.0)
    rotation: float = math.radians(10.0)

    def __post_init__(self) -> None:
        for key in ("slope", "rotation"):
            value = getattr(self, key)
            if not (isinstance(value, int | float) and 0.0 <= value <= math.pi / 2):
                raise CaseError(
                    f"must be an angle in [0, pi/2] rad, got {value!r}", key=f"downhand.{key}"
                )
