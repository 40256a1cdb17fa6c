"""Time laws: joint path and task in, samples at Ts out (``docs/timing.md``).

:data:`TIME_LAWS` lists the laws by name; :func:`time_law` looks one up from user input.
The reference laws (toppra, copp-py's TOPP3) are in :mod:`trackplan.timing.references`.
"""

from __future__ import annotations

from trackplan.choices import Timing, choose
from trackplan.timing import paper, smooth
from trackplan.timing.protocol import SlowDown, TimeLaw, TimeLawPlanner, TimeLawSpec

TIME_LAWS: dict[Timing, TimeLawSpec] = {Timing.SMOOTH: smooth.SPEC, Timing.PAPER: paper.SPEC}
"""Every time law, by name."""


def time_law(name: str | Timing, key: str = "timing") -> TimeLawSpec:
    """The law called ``name``.

    Raises
    ------
    CaseError
        When no law has that name (the message lists the names).
    """
    return TIME_LAWS[choose(Timing, name, key)]


__all__ = ["TIME_LAWS", "SlowDown", "TimeLaw", "TimeLawPlanner", "TimeLawSpec", "time_law"]
