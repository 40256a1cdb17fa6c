"""The external axes' motion along one seam at one placement (the planner's entry point)."""

from __future__ import annotations

import numpy as np

from trackplan.axes.profile import AxesProfile
from trackplan.axes.rules import Downhand
from trackplan.frames import placement_transform
from trackplan.paths.path_geometry import PathGeometry
from trackplan.profiles import Profile
from trackplan.robots.machine import Machine
from trackplan.tool import ToolSpec

TRACK_SPACING = 0.05
"""m of path per coefficient of the track's profile."""


def choose_axes(
    machine: Machine,
    geometry: PathGeometry,
    tool: ToolSpec,
    X: np.ndarray,
    downhand: Downhand | None,
) -> AxesProfile:
    """The external axes along the seam: the positioner held in the middle of its ranges,
    the track following the tool along its axis (clipped to its range)."""
    length = float(geometry.planned.length)
    profiles: list[Profile] = []
    held = np.zeros(machine.n_positioner)
    if machine.positioner is not None:
        chain = machine.positioner.chain
        held = np.clip(0.0, chain.q_min, chain.q_max)
    if machine.track is not None:
        track = machine.track
        k = max(4, int(np.ceil(length / TRACK_SPACING)) + 3)
        s = np.linspace(0.0, length, 4 * k)
        sample = geometry.planned.sample(s)
        q = np.zeros((len(s), machine.n_dof))
        q[:, machine.positioner_columns] = held
        carrier = machine.T_cell_carrier(q) @ placement_transform(X)
        p_cell = np.einsum("mij,mj->mi", carrier[:, :3, :3], sample.position) + carrier[:, :3, 3]
        along = np.clip(p_cell @ track.axis, track.lower, track.upper)
        from scipy.interpolate import make_lsq_spline

        from trackplan.profiles.bspline import DEGREE, clamped_knots

        knots = clamped_knots(k, length)
        spline = make_lsq_spline(s, along, knots, DEGREE)
        coefficients = np.clip(spline.c, track.lower, track.upper)
        profiles.append(Profile(coefficients, length))
    profiles.extend(Profile.constant(float(v), length) for v in held)
    return AxesProfile(tuple(profiles))
