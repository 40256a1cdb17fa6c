"""The tool orientation along the path: part or seam frame, work and travel angles, spin.

One mechanism serves every caller (the joint path, the screening of the search, the
checker, the report): a :class:`ToolSpec` says how the tool is held relative to the part
or the seam, a :class:`SpinProfile` says how far it is turned about its own axis at each
arc length, and :meth:`ToolOrientation.rotations` gives ``R_part_tool(s)``. The spin is a
free profile (:mod:`trackplan.profiles`, :meth:`ToolSpec.spin_profile`).

Modules: :mod:`~trackplan.tool.spec` (the spec), :mod:`~trackplan.tool.spin` (the spin's
free profile), :mod:`~trackplan.tool.seam` (the seam frame's tangent and normal),
:mod:`~trackplan.tool.weld_normal` (normals declared on segments),
:mod:`~trackplan.tool.orientation` (the orientation with a chosen spin) and
:mod:`~trackplan.tool.rotations` (rotation helpers).

Conventions (``docs/tool.md``):

- seam frame at a path point with unit tangent t and surface normal n (n made
  perpendicular to t): ``x_s = t``, ``z_s = −n``, ``y_s = z_s × x_s``;
- ``frame: seam``: ``R = [x_s y_s z_s] · Rx(work_angle) · Ry(travel_angle) · Rz(spin)``;
- ``frame: part``: ``R = RPY(rpy) · Rz(spin)``;
- the tool axis is the tool's z axis;
- one ``normal`` for the whole path, or ``normals``: one per path segment; a segment's own
  weld normal (an arc's ``weld_normal`` turned with it, or points with normals) wins on
  that segment (:mod:`~trackplan.tool.weld_normal`).

The tangent is the planned path's, so through a blend the orientation turns with the
blend's tangent, which is continuous with its curvature (G2 blends). Per-segment normals
change the same way, across the same windows: where the normal jumps at a junction it is
blended with the smooth step that rounds the tangent (:class:`SeamNormal`). The checker holds
the tool axis to the spec on the nominal path; inside a *transition zone* (a blend, a
corner arc or a fitted curve: a piece of the planned path that is not on the nominal path)
it allows the deviation bound of :func:`trackplan.planning.tool_zones.transition_zones`.
"""

from trackplan.tool.orientation import ToolOrientation
from trackplan.tool.rotations import (
    rotation_angle,
    rotation_z,
    spin_rotations,
    spun,
    tool_axis_twist,
)
from trackplan.tool.seam import (
    PARALLEL_SINE,
    SEAM_SMOOTHING,
    ZONE_STEP,
    SeamNormal,
    SeamTangent,
    junction_window,
    seam_problems,
    smooth_step,
)
from trackplan.tool.spec import MIN_NORMAL_LENGTH, ToolFrame, ToolSpec
from trackplan.tool.spin import (
    DEFAULT_SPIN_RATE,
    SPIN_COEFFICIENTS,
    SPIN_DEGREE,
    SpinMode,
    SpinProfile,
    increment_spans,
    spin_free_profile,
    spin_knots,
    spin_values,
)

__all__ = [
    "DEFAULT_SPIN_RATE",
    "MIN_NORMAL_LENGTH",
    "PARALLEL_SINE",
    "SEAM_SMOOTHING",
    "SPIN_COEFFICIENTS",
    "SPIN_DEGREE",
    "ZONE_STEP",
    "SeamNormal",
    "SeamTangent",
    "SpinMode",
    "SpinProfile",
    "ToolFrame",
    "ToolOrientation",
    "ToolSpec",
    "increment_spans",
    "junction_window",
    "rotation_angle",
    "rotation_z",
    "seam_problems",
    "smooth_step",
    "spin_free_profile",
    "spin_knots",
    "spin_rotations",
    "spin_values",
    "spun",
    "tool_axis_twist",
]
