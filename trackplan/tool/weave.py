"""Weaving: the torch's oscillation across the seam (``task.weave``, ``docs/positioner.md``)."""

from __future__ import annotations

import enum
import math
from dataclasses import dataclass

from trackplan.choices import choose
from trackplan.errors import CaseError


class WeavePattern(enum.StrEnum):
    """The shape of one weave period."""

    TRIANGLE = "triangle"
    SINE = "sine"
    TRAPEZOID = "trapezoid"


class WeavePlane(enum.StrEnum):
    """Where "across the seam" lies: the seam frame's y axis (``seam``) or the tool's
    (``tool``)."""

    SEAM = "seam"
    TOOL = "tool"


@dataclass(frozen=True)
class Weave:
    """A weave superposed on the seam: the tolerance holds for its centre line.

    Attributes
    ----------
    pattern
        ``triangle``, ``sine`` or ``trapezoid``.
    plane
        ``seam`` or ``tool``.
    amplitude
        Excursion to each side of the centre line, m (half the weave's width).
    frequency
        Full periods per second at the rated speed, Hz.
    dwell
        Time held at each side, s (``trapezoid``; 0 otherwise).
    """

    pattern: WeavePattern = WeavePattern.TRIANGLE
    plane: WeavePlane = WeavePlane.SEAM
    amplitude: float = 0.002
    frequency: float = 2.0
    dwell: float = 0.0

    def __post_init__(self) -> None:
        object.__setattr__(self, "pattern", choose(WeavePattern, self.pattern, "weave.pattern"))
        object.__setattr__(self, "plane", choose(WeavePlane, self.plane, "weave.plane"))
        for key, unit in (("amplitude", "m"), ("frequency", "Hz")):
            value = getattr(self, key)
            if not (isinstance(value, int | float) and math.isfinite(value) and value > 0):
                raise CaseError(
                    f"must be a finite number > 0 ({unit}), got {value!r}", key=f"weave.{key}"
                )
        if not (math.isfinite(self.dwell) and 0.0 <= self.dwell < 0.5 / self.frequency):
            raise CaseError(
                f"must be in [0, half a period = {0.5 / self.frequency:g}) s, got {self.dwell!r}",
                key="weave.dwell",
            )
        if self.pattern is not WeavePattern.TRAPEZOID and self.dwell != 0.0:
            raise CaseError("a dwell needs pattern: trapezoid", key="weave.dwell")
