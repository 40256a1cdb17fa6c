"""One outcome vocabulary for IK, time laws, checks, plans, searches and studies.

Every result of trackplan carries a :class:`Status` and a boolean ``success`` that is true
exactly when the status is :attr:`Status.FEASIBLE`. "It worked" is spelled ``success``
everywhere; ``feasible`` is a read-only alias on plan results. Code compares members
(``status is Status.FEASIBLE``), never their words; the words are what files hold
(``docs/architecture.md``, "Outcomes and errors").
"""

from __future__ import annotations

import enum


class Status(enum.Enum):
    """Outcome of one computation (the first problem that applies).

    The values are the words written to result files and summaries. New members go at the
    end; a value, once written to a file, never changes.
    """

    FEASIBLE = "feasible"
    """Everything asked for was met (IK: every pose solved on one branch inside the limits;
    plan: the checker found no violation; search: the final plan is feasible)."""
    LIMITS_VIOLATED = "limits_violated"
    """A trajectory exists but breaks a limit (the checker says which, where)."""
    UNREACHABLE = "unreachable"
    """Some path pose has no IK solution."""
    BRANCH_SWITCH = "branch_switch"
    """The path crosses a singularity (or the joints jump between poses)."""
    POSITION_LIMITS = "position_limits"
    """Every IK branch leaves the joint range."""
    COLLISION = "collision"
    """Every limit is met, but the robot breaks the work cell's clearance."""
    NOT_CONVERGED = "not_converged"
    """An iterative method stopped before meeting its own tolerance."""
    INTERRUPTED = "interrupted"
    """Stopped by a signal; the result is the best found until then."""
    FAILED = "failed"
    """The computation raised (a study job: or lost its workers); the message says why."""
    REACH = "reach"
    """The placement lies outside the reach interval (Eq. 32): no pose is solved."""
    HOLDING_TORQUE = "holding_torque"
    """Holding a pose still against gravity needs more than a torque limit (no speed helps)."""

    @property
    def success(self) -> bool:
        """True for :attr:`FEASIBLE` only."""
        return self is Status.FEASIBLE


__all__ = ["Status"]
