"""Time laws: joint path and task in, samples at Ts out (``docs/timing.md``).

A :class:`TimeLaw` times a joint path into a :class:`TimedPath`. :data:`TIME_LAWS` lists the
laws by name; :func:`time_law` looks one up from user input.
The reference laws (toppra, copp-py's TOPP3) are in :mod:`trackplan.timing.references`.
"""

from __future__ import annotations

import warnings

from trackplan.choices import Timing, choose
from trackplan.timing import paper, smooth
from trackplan.timing.protocol import SlowDown, TimedPath, TimeLaw, TimeLawPlanner

TIME_LAWS: dict[Timing, TimeLaw] = {Timing.SMOOTH: smooth.LAW, Timing.PAPER: paper.LAW}
"""Every time law, by name."""


def time_law(name: str | Timing, key: str = "timing") -> TimeLaw:
    """The law called ``name``.

    Raises
    ------
    CaseError
        When no law has that name (the message lists the names).
    """
    return TIME_LAWS[choose(Timing, name, key)]


def __getattr__(name: str) -> type[TimeLaw]:
    """``TimeLawSpec``, the law's old name, with a :class:`DeprecationWarning` (one release)."""
    if name == "TimeLawSpec":
        warnings.warn(
            "trackplan.timing.TimeLawSpec is now trackplan.timing.TimeLaw (a law's output is "
            "trackplan.timing.TimedPath)",
            DeprecationWarning,
            stacklevel=2,
        )
        return TimeLaw
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


__all__ = ["TIME_LAWS", "SlowDown", "TimeLaw", "TimeLawPlanner", "TimedPath", "time_law"]
