"""Free profiles: the degrees of freedom the planner chooses along the path.

A :class:`FreeProfile` holds the data of one (nodes over the path parameter s, bounds per
node, a rate bound, the map from the search's decision variables to the nodes); a
:class:`Profile` is one chosen curve, evaluated with its derivatives in s, vectorised over
candidates and samples. The tool's spin is a free profile
(:meth:`trackplan.tool.ToolSpec.spin_profile`); external axes and a redundant arm's arm angle
are more of the same data, searched and checked the same way.
"""

from trackplan.profiles.bspline import DEGREE, clamped_knots, increment_spans, profile_values
from trackplan.profiles.free import FreeProfile, Profile

__all__ = [
    "DEGREE",
    "FreeProfile",
    "Profile",
    "clamped_knots",
    "increment_spans",
    "profile_values",
]
