"""The process requirements of a case: speeds, tolerance, controller period, tool, time law.

Pure data, below the case (:class:`trackplan.case.Case` holds one) so that the time laws
read it without importing the case.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from trackplan.choices import Timing, choose
from trackplan.redundancy.spec import RedundancySpec
from trackplan.tool import ToolSpec
from trackplan.tool.weave import Weave


@dataclass(frozen=True, eq=False)
class Task:
    """Process requirements.

    Attributes
    ----------
    rated_speed
        Tool speed on straight pieces, v_r, m/s.
    corner_speed
        Highest tool speed on arcs and corner blends, v_t^max, m/s.
    tolerance
        Largest distance of the tool point from the nominal path, ρ, m.
    sample_time
        Controller period Ts, s.
    tool
        How the tool is held along the path (:class:`trackplan.tool.ToolSpec`).
    timing
        The time law: ``smooth`` (jerk-limited, G2 blends) or ``paper`` (Section 3.1 as
        written).
    weave
        The torch's weave across the seam (:class:`~trackplan.tool.weave.Weave`), or None.
    redundancy
        How a redundant (7-joint) arm's free parameter is chosen along the seam
        (:class:`~trackplan.redundancy.RedundancySpec`); other arms ignore it.
    """

    rated_speed: float
    corner_speed: float
    tolerance: float
    sample_time: float
    tool: ToolSpec = field(default_factory=ToolSpec)
    timing: Timing = Timing.SMOOTH
    weave: Weave | None = None
    redundancy: RedundancySpec = field(default_factory=RedundancySpec)

    def __post_init__(self) -> None:
        object.__setattr__(self, "timing", choose(Timing, self.timing, "task.timing"))
