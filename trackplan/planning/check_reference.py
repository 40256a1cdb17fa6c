"""What the tool must do, for the checker's task checks: :class:`TrackingReference`."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from trackplan.axes.rules import Downhand
from trackplan.paths import NominalPath
from trackplan.tool import ToolSpec
from trackplan.tool.weave import WovenPath

ORIENTATION_TOLERANCE = 1e-3
"""Largest tool orientation error accepted, rad."""


@dataclass(frozen=True, eq=False)
class TrackingReference:
    """What the tool must do, for the task checks.

    Attributes
    ----------
    nominal
        The path as the user gave it (:class:`trackplan.paths.NominalPath`), definition frame.
    T_base_part
        Placement of the definition frame, shape (4, 4).
    tool
        How the tool is held (:class:`trackplan.tool.ToolSpec`): the tool axis is checked
        against it at every sample, the spin against its value, range and rate.
    tolerance
        ρ, m.
    rated_speed, corner_speed
        Speed caps on straight pieces and at corners, m/s.
    corner_intervals
        Arc-length intervals of the nominal path where the corner speed applies, shape (K, 2), m.
    tool_zones
        Transition zones (:func:`trackplan.planning.tool_zones.transition_zones`), shape
        (K, 3): nominal arc lengths (m) and the extra tool axis deviation allowed (rad).
    orientation_tolerance
        Largest tool axis error, and spin error of a fixed spin, rad.
    downhand
        The downhand rule to hold at every sample (:class:`~trackplan.axes.rules.Downhand`),
        or None.
    weave
        The task's weave over the planned path, or None: the tracking and speed checks
        read the weave's centre line, and the lateral offset is held to the weave.
    """

    nominal: NominalPath
    T_base_part: np.ndarray
    tool: ToolSpec
    tolerance: float
    rated_speed: float
    corner_speed: float
    corner_intervals: np.ndarray
    tool_zones: np.ndarray = field(default_factory=lambda: np.zeros((0, 3)))
    orientation_tolerance: float = ORIENTATION_TOLERANCE
    downhand: Downhand | None = None
    weave: WovenPath | None = None
