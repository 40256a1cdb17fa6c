"""Programs with external axes for the writer tests: the hand-built programs of the
language tests with a track and a positioner added to every joint move and target."""

from __future__ import annotations

import dataclasses
import itertools

import numpy as np

from trackplan.programs.model import (
    CircularMove,
    ExternalAxis,
    JointMove,
    LinearMove,
    Move,
    Program,
    Section,
    SplineMove,
    Target,
)

TRACK = ExternalAxis(name="track", kind="track", unit="m", v_max=1.0)
TILT = ExternalAxis(name="tilt", kind="positioner", unit="rad", v_max=1.6)
ROTATE = ExternalAxis(name="rotate", kind="positioner", unit="rad", v_max=2.4)

CARRIER_PART = np.array(
    [
        [0.0, -1.0, 0.0, 0.05],
        [1.0, 0.0, 0.0, -0.02],
        [0.0, 0.0, 1.0, 0.12],
        [0.0, 0.0, 0.0, 1.0],
    ]
)
"""The part on the positioner's flange (a coordinated program's base), m."""


def external_values(axes: tuple[ExternalAxis, ...], k: int) -> np.ndarray:
    """Values of ``axes`` at the k-th target: a track of a few metres (m), positioner
    angles over more than a turn (rad), none of them round in mm or degrees."""
    out = []
    for j, axis in enumerate(axes):
        if axis.kind == "track":
            out.append(1.2345678 + 0.0731 * k)
        else:
            out.append(-2.7182818 + (0.3141 + 0.1 * j) * k)
    return np.array(out, dtype=float)


def with_external(
    program: Program, axes: tuple[ExternalAxis, ...], *, base: np.ndarray | None = None
) -> Program:
    """``program`` with ``axes`` on every joint move and target (:func:`external_values`
    in execution order); ``base`` replaces its base (the part on the positioner's flange
    for a coordinated program)."""
    counter = itertools.count()

    def target(old: Target) -> Target:
        return dataclasses.replace(old, external=external_values(axes, next(counter)))

    def move(old: Move) -> Move:
        if isinstance(old, JointMove):
            return dataclasses.replace(old, external=external_values(axes, next(counter)))
        if isinstance(old, LinearMove):
            return dataclasses.replace(old, target=target(old.target))
        if isinstance(old, CircularMove):
            via = target(old.via)
            return dataclasses.replace(old, via=via, target=target(old.target))
        assert isinstance(old, SplineMove)
        return dataclasses.replace(old, targets=tuple(target(t) for t in old.targets))

    sections = tuple(
        Section(kind=s.kind, label=s.label, moves=tuple(move(m) for m in s.moves))
        for s in program.sections
    )
    return dataclasses.replace(
        program,
        sections=sections,
        external_axes=axes,
        base=program.base if base is None else base,
    )


def written_units(axes: tuple[ExternalAxis, ...], values: np.ndarray) -> np.ndarray:
    """SI values as the languages print them: a track in mm, rotary axes in degrees."""
    scale = np.array([1000.0 if axis.kind == "track" else np.degrees(1.0) for axis in axes])
    return np.asarray(values, dtype=float) * scale


__all__ = [
    "CARRIER_PART",
    "ROTATE",
    "TILT",
    "TRACK",
    "external_values",
    "with_external",
    "written_units",
]
