"""A redundant (7-joint) arm's free parameter along a seam: how it is steered and chosen.

:class:`RedundancySpec` is what a case says (``task.redundancy``: fixed, one constant, or a
smooth profile, with bounds and a rate); :func:`choose_redundancy` chooses the profile for
each candidate placement and IK branch, for the joint travel, within those bounds
(``docs/robots.md``, "Redundancy").
"""

from trackplan.redundancy.choose import RedundancyChoice, choose_redundancy
from trackplan.redundancy.spec import RedundancyMode, RedundancySpec

__all__ = ["RedundancyChoice", "RedundancyMode", "RedundancySpec", "choose_redundancy"]
