"""The named choices of a case and of the API: time law, search method, penalty.

Each is a :class:`enum.StrEnum`, so a member compares equal to its value and is written
to files as that word. :func:`choose` turns user input into a member, or raises a
:class:`~trackplan.errors.CaseError` that lists the allowed values.
"""

from __future__ import annotations

import enum
from typing import TypeVar

from trackplan.errors import CaseError


class Timing(enum.StrEnum):
    """Time laws (see ``docs/timing.md``)."""

    SMOOTH = "smooth"
    """Jerk-limited law on G2-blended corners: trackplan's default."""
    PAPER = "paper"
    """The reference paper's Section 3.1 as written, for reproduction."""


class Method(enum.StrEnum):
    """Placement search methods (see ``docs/search.md``)."""

    MULTISTART = "multistart"
    """Uniform samples, then local CMA-ES runs from the best distinct ones (default)."""
    GA = "ga"
    """The reference paper's MATLAB GA configuration."""
    CMAES = "cmaes"
    DE = "de"
    RANDOM = "random"


class Penalty(enum.StrEnum):
    """How infeasible candidates rank in the search (Eq. 30)."""

    GRADED = "graded"
    """By their distance from feasibility."""
    FLAT = "flat"
    """The paper's constant M."""


ChoiceT = TypeVar("ChoiceT", bound=enum.StrEnum)


def choose(kind: type[ChoiceT], value: object, key: str) -> ChoiceT:
    """The member of ``kind`` named by ``value``.

    Parameters
    ----------
    kind
        The enum class.
    value
        A member or its value (``"smooth"``).
    key
        Where the value came from (``task.timing``, ``--method``), for the error.

    Raises
    ------
    CaseError
        When ``value`` names no member; the message lists the allowed values.
    """
    if isinstance(value, kind):
        return value
    try:
        return kind(str(value))
    except ValueError:
        allowed = ", ".join(member.value for member in kind)
        raise CaseError(f"{key} must be one of {allowed}, got {value!r}", key=key) from None


OBJECTIVE_KINDS: dict[str, bool] = {"travel": False, "time": False, "energy": True, "copper": True}
"""The single search objectives by name (``objective.kind``), each mapped to whether it
needs the robot's dynamics; :data:`trackplan.planning.objectives.OBJECTIVES` implements
them."""


__all__ = ["OBJECTIVE_KINDS", "Method", "Penalty", "Timing", "choose"]
