"""How a case steers a redundant arm's free parameter: ``task.redundancy``."""

from __future__ import annotations

import enum
import math
from dataclasses import dataclass

import numpy as np

from trackplan.choices import choose
from trackplan.profiles import FreeProfile
from trackplan.robots.families.base import RedundancyParameter

NODES = 8
"""B-spline coefficients of a ``free-varying`` profile over the seam."""
DEFAULT_RATE = 10.0
"""Largest |d parameter / ds| of a ``free-varying`` profile by default, rad/m: a 10 mm/s
weld turns the arm angle by at most 0.1 rad/s."""


class RedundancyMode(enum.StrEnum):
    """How the free parameter is chosen along a seam."""

    FIXED = "fixed"
    FREE = "free"
    FREE_VARYING = "free-varying"


@dataclass(frozen=True)
class RedundancySpec:
    """A case's steering of the free parameter of a redundant arm (``task.redundancy``).

    Attributes
    ----------
    mode
        ``fixed``: the parameter is :attr:`value` along the whole seam; ``free``: one
        constant the planner chooses; ``free-varying`` (default): a smooth profile along
        the seam the planner chooses (a clamped cubic B-spline of :data:`NODES`
        coefficients).
    value
        The parameter of ``fixed``, rad; None: the middle of :attr:`range`.
    range
        (lower, upper) bounds of the parameter, rad; None: the family's natural range
        (the arm angle's [−π, π], a joint's limits).
    rate
        Largest |d parameter / ds| of ``free-varying``, rad/m (> 0).
    """

    mode: RedundancyMode = RedundancyMode.FREE_VARYING
    value: float | None = None
    range: tuple[float, float] | None = None
    rate: float = DEFAULT_RATE

    def __post_init__(self) -> None:
        object.__setattr__(self, "mode", choose(RedundancyMode, self.mode, "task.redundancy.mode"))

    def bounds(self, parameter: RedundancyParameter) -> tuple[float, float]:
        """(lower, upper) of the parameter, rad: :attr:`range` within the natural range."""
        if self.range is None:
            return float(parameter.lower), float(parameter.upper)
        lower = max(float(self.range[0]), float(parameter.lower))
        upper = min(float(self.range[1]), float(parameter.upper))
        return lower, upper

    def fixed_value(self, parameter: RedundancyParameter) -> float:
        """The value of ``fixed``, rad (the middle of the bounds when none is given)."""
        lower, upper = self.bounds(parameter)
        return 0.5 * (lower + upper) if self.value is None else float(self.value)

    def free_profile(self, parameter: RedundancyParameter) -> FreeProfile:
        """The free profile (:class:`~trackplan.profiles.FreeProfile`) of this steering."""
        lower, upper = self.bounds(parameter)
        nodes = {RedundancyMode.FIXED: 0, RedundancyMode.FREE: 1}.get(self.mode, NODES)
        return FreeProfile(
            nodes,
            np.asarray(lower),
            np.asarray(upper),
            rate=self.rate,
            fixed=self.fixed_value(parameter),
        )

    def full_turn(self, parameter: RedundancyParameter) -> bool:
        """Whether the bounds span a whole turn of an angle (the ends are the same arm)."""
        lower, upper = self.bounds(parameter)
        return parameter.joint is None and upper - lower >= 2.0 * math.pi - 1e-9
