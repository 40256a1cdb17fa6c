"""A case file's welding-cell keys: ``positioner``, ``track``, ``downhand`` and ``weave``.

The keys (``docs/files.md``, ``docs/positioner.md``)::

    positioner:
      model: two-axis-500              # a built-in positioner or a positioner file (.yaml)
      pose: [x, y, z, roll, pitch, yaw]  # its base in the cell frame, m and rad, or a mapping
                                       # of a number (fixed) or [min, max] (searched) per key;
                                       # a key left out is 0, fixed
    track:
      axis: [1, 0, 0]                  # its direction in the cell frame
      position: [0.0, 4.0]             # m
      velocity: 1.0                    # m/s
      acceleration: 2.0                # m/s²
      jerk: 20.0                       # m/s³
    downhand: {slope: 0.1745, rotation: 0.1745}   # rad; needs the weld's normal
    task:
      weave: {pattern: triangle, plane: seam, amplitude: 0.002, frequency: 2.0, dwell: 0.0}

``weave`` may also be given in a seam's ``task`` (``paths[i].task.weave``), where
``weave: null`` turns the case's weave off for that seam. The schema is here; the checks
that need more than one value are :func:`axes_problems`; :func:`with_axes` puts the
values into the :class:`~trackplan.case.Case`.
"""

from __future__ import annotations

import dataclasses
import math
from pathlib import Path
from typing import Annotated, Any, Literal

import numpy as np
from pydantic import Discriminator, Tag

from trackplan.axes.rules import Downhand
from trackplan.case import PLACEMENT_KEYS, Case
from trackplan.errors import CaseError
from trackplan.io.positioner_file import load_positioner_spec
from trackplan.io.yaml_input import (
    Coordinate,
    Loc,
    NonEmptyStr,
    NonNegative,
    Positive,
    Problem,
    Range,
    StrictModel,
    Vec3,
    Vec6,
    key_path,
    list_default,
    show,
)
from trackplan.paths.specs import SegmentSpec
from trackplan.robots.machine import Positioner, Track
from trackplan.robots.model import Robot
from trackplan.tool.weave import Weave, WeavePattern, WeavePlane
from trackplan.tool.weld_normal import declares_normals

MAX_WEAVE_AMPLITUDE = 0.05
"""Largest weave amplitude, m (to each side): 50 mm, past any welding torch's weave; a
larger value is a length in millimetres."""

MIN_WEAVE_SAMPLES = 8
"""Fewest samples per weave period at the case's sample time (``task.sample_time``)."""


def _value_kind(value: Any) -> str | None:
    if isinstance(value, list):
        return "<range>"
    if isinstance(value, int | float) and not isinstance(value, bool):
        return "<fixed>"
    return None


PoseValue = Annotated[
    Annotated[Coordinate, Tag("<fixed>")] | Annotated[Range, Tag("<range>")],
    Discriminator(
        _value_kind,
        custom_error_type="pose_value",
        custom_error_message="expected a number (fixed) or [min, max] (searched), m or rad",
    ),
]


class PoseBoundsModel(StrictModel):
    """``positioner.pose`` as a mapping: a number (fixed) or [min, max] per key."""

    x: PoseValue = 0.0
    y: PoseValue = 0.0
    z: PoseValue = 0.0
    roll: PoseValue = 0.0
    pitch: PoseValue = 0.0
    yaw: PoseValue = 0.0


def _pose_kind(value: Any) -> str | None:
    if isinstance(value, list):
        return "<list>"
    if isinstance(value, dict):
        return "<bounds>"
    return None


PoseModel = Annotated[
    Annotated[Vec6, Tag("<list>")] | Annotated[PoseBoundsModel, Tag("<bounds>")],
    Discriminator(
        _pose_kind,
        custom_error_type="pose_type",
        custom_error_message=(
            "expected [x, y, z, roll, pitch, yaw] (m, rad) or a mapping of a number or "
            "[min, max] per key"
        ),
    ),
]


class PositionerModel(StrictModel):
    """``positioner``: a built-in positioner or a positioner file, and its pose in the cell."""

    model: NonEmptyStr
    pose: PoseModel = list_default(0.0, 0.0, 0.0, 0.0, 0.0, 0.0)


class TrackModel(StrictModel):
    """``track``: a linear axis under the arm: direction, travel (m) and its limits."""

    axis: Vec3
    position: Range
    velocity: Positive
    acceleration: Positive
    jerk: Positive


class DownhandModel(StrictModel):
    """``downhand``: largest slope and rotation of the weld, rad."""

    slope: float = Downhand.slope
    rotation: float = Downhand.rotation


class WeaveModel(StrictModel):
    """``weave``: pattern, plane, amplitude (m), frequency (Hz), dwell (s)."""

    pattern: Literal["triangle", "sine", "trapezoid"] = "triangle"
    plane: Literal["seam", "tool"] = "seam"
    amplitude: Positive
    frequency: Positive
    dwell: NonNegative = 0.0


# --------------------------------------------------------------------------- value checks


def pose_bounds(pose: list[float] | PoseBoundsModel) -> tuple[np.ndarray, np.ndarray]:
    """The lower and upper bounds of a positioner pose, shape (6,) each (equal where fixed)."""
    if isinstance(pose, list):
        values = np.array(pose, dtype=float)
        return values, values.copy()
    rows = [
        (value[0], value[1]) if isinstance(value, list) else (value, value)
        for value in (getattr(pose, key) for key in PLACEMENT_KEYS)
    ]
    bounds = np.array(rows, dtype=float)
    return bounds[:, 0], bounds[:, 1]


def axes_problems(
    model: Any,
    seams: list[tuple[Loc, Any]],
    paths: list[tuple[np.ndarray, tuple[SegmentSpec, ...]]],
) -> list[Problem]:
    """Problems of the welding-cell keys that the schema cannot see: pose and travel ranges,
    the track's direction, the downhand angles and its need of a weld normal, the weaves.

    Parameters
    ----------
    model
        The validated :class:`~trackplan.io.case_schema.CaseModel`.
    seams
        Each path's location in the file and its model (``path`` or ``paths[k]``).
    paths
        Each path's start and segments, in the order of ``seams``.
    """
    problems: list[Problem] = []
    if model.positioner is not None and isinstance(model.positioner.pose, PoseBoundsModel):
        for key in PLACEMENT_KEYS:
            value = getattr(model.positioner.pose, key)
            if isinstance(value, list) and value[0] > value[1]:
                problems.append(
                    (
                        ("positioner", "pose", key),
                        f"expected [min, max] with min ≤ max, got {show(value)}",
                    )
                )
    if model.track is not None:
        problems += _track_problems(model.track)
    if model.downhand is not None:
        problems += _downhand_problems(model, seams, paths)
    problems += _objective_problems(model)
    sample_time = model.task.sample_time
    problems += _weave_problems(model.task.weave, ("task", "weave"), sample_time)
    for loc, seam in seams:
        own = getattr(seam, "task", None)
        if own is not None:
            problems += _weave_problems(own.weave, (*loc, "task", "weave"), sample_time)
    return problems


def _track_problems(track: TrackModel) -> list[Problem]:
    problems: list[Problem] = []
    if math.hypot(*track.axis) < 1e-9:
        problems.append(
            (("track", "axis"), f"expected a non-zero direction [x, y, z], got {show(track.axis)}")
        )
    low, high = track.position
    if not low < high:
        problems.append(
            (
                ("track", "position"),
                f"expected [min, max] with min < max, m, got {show(track.position)}",
            )
        )
    return problems


def _downhand_problems(
    model: Any,
    seams: list[tuple[Loc, Any]],
    paths: list[tuple[np.ndarray, tuple[SegmentSpec, ...]]],
) -> list[Problem]:
    problems: list[Problem] = []
    for key in ("slope", "rotation"):
        value = getattr(model.downhand, key)
        if not 0.0 <= value <= math.pi / 2:
            problems.append(
                (
                    ("downhand", key),
                    f"expected an angle in [0, pi/2] rad (10° is 0.1745), got {value:g}",
                )
            )
    for (loc, seam), (_, segments) in zip(seams, paths, strict=True):
        own = getattr(seam, "task", None)
        tool = own.tool if own is not None and own.tool is not None else model.task.tool
        if tool is not None and (tool.normal is not None or tool.normals is not None):
            continue
        bare = [k for k, segment in enumerate(segments) if not declares_normals([segment])]
        if bare:
            problems.append(
                (
                    ("downhand",),
                    "needs the weld's normal: give task.tool.normal (or normals) with "
                    f"frame: seam, or a weld normal on every segment ({key_path(loc)}"
                    f".segments[{bare[0]}] has none)",
                )
            )
            break
    return problems


def _weave_problems(weave: WeaveModel | None, loc: Loc, sample_time: float) -> list[Problem]:
    if weave is None:
        return []
    problems: list[Problem] = []
    if weave.amplitude > MAX_WEAVE_AMPLITUDE:
        problems.append(
            (
                (*loc, "amplitude"),
                f"expected at most {MAX_WEAVE_AMPLITUDE:g} m to each side, got "
                f"{weave.amplitude:g}: the amplitude is in metres (2 mm is 0.002)",
            )
        )
    highest = 1.0 / (MIN_WEAVE_SAMPLES * sample_time)
    if weave.frequency > highest:
        problems.append(
            (
                (*loc, "frequency"),
                f"expected at most {highest:g} Hz ({MIN_WEAVE_SAMPLES} samples a period at "
                f"task.sample_time {sample_time:g} s), got {weave.frequency:g}",
            )
        )
    elif weave.dwell != 0.0 and weave.pattern != "trapezoid":
        problems.append(((*loc, "dwell"), "a dwell needs pattern: trapezoid"))
    elif weave.dwell >= 0.5 / weave.frequency:
        problems.append(
            (
                (*loc, "dwell"),
                f"expected less than half a period ({0.5 / weave.frequency:g} s at "
                f"{weave.frequency:g} Hz), got {weave.dwell:g} s",
            )
        )
    return problems


# --------------------------------------------------------------------------- building


def load_positioner_chain(
    model: Any, base_dir: str | Path, file: str | None, assume_limits: bool = False
) -> Robot | None:
    """The positioner's chain a case names (None without ``positioner``); ``assume_limits``
    as for :func:`~trackplan.io.positioner_file.load_positioner`."""
    if model.positioner is None:
        return None
    return load_positioner_spec(
        model.positioner.model, base_dir, case_file=file, assume_limits=assume_limits
    )


def as_weave(weave: WeaveModel | None) -> Weave | None:
    """The weave of a validated ``weave`` block."""
    if weave is None:
        return None
    pattern, plane = WeavePattern(weave.pattern), WeavePlane(weave.plane)
    return Weave(pattern, plane, weave.amplitude, weave.frequency, weave.dwell)


TORQUE_KINDS = ("energy", "copper")
"""Objectives that read the arm's torques: not computed for an arm on a moving base."""


def _objective_problems(model: Any) -> list[Problem]:
    """``objective`` against the external axes: a torque objective refused with a track or a
    positioner; ``external_weights`` only with them (its length is checked once the
    positioner is loaded)."""
    objective = model.objective
    external = model.track is not None or model.positioner is not None
    problems: list[Problem] = []
    kinds = set((objective.mix or {}) if objective.kind == "weighted" else [objective.kind])
    torque = sorted(kinds & set(TORQUE_KINDS))
    if external and torque:
        problems.append(
            (
                ("objective", "kind"),
                f"{', '.join(torque)} needs the arm's joint torques, which trackplan does not "
                "compute for an arm on a track or with a positioner: use travel or time",
            )
        )
    if objective.external_weights is not None and not external:
        problems.append(
            (
                ("objective", "external_weights"),
                "weights the external axes' travel, and the case has no track or positioner: "
                "remove it",
            )
        )
    return problems


def with_axes(case: Case, model: Any, chain: Robot | None) -> Case:
    """The case with its positioner, track, downhand rule and weaves (checked values)."""
    weave = as_weave(model.task.weave)
    seams = case.paths
    if model.paths is not None:
        seams = tuple(
            dataclasses.replace(
                seam,
                task=dataclasses.replace(seam.task, weave=_seam_weave(own.task, weave)),
            )
            for seam, own in zip(case.paths, model.paths, strict=True)
        )
    task = seams[0].task if model.paths is not None else dataclasses.replace(case.task, weave=weave)
    positioner = None
    if chain is not None:
        lower, upper = pose_bounds(model.positioner.pose)
        searched = bool(np.any(upper > lower))
        positioner = Positioner(
            chain,
            (lower + upper) / 2,
            lower if searched else None,
            upper if searched else None,
            model.positioner.model,
        )
    track = None
    if model.track is not None:
        t = model.track
        low, high = t.position
        track = Track(np.array(t.axis), low, high, t.velocity, t.acceleration, t.jerk)
    downhand = None
    if model.downhand is not None:
        downhand = Downhand(model.downhand.slope, model.downhand.rotation)
    objective = case.objective
    given = model.objective.external_weights
    if given is not None:
        n_external = (track is not None) + (0 if chain is None else chain.n_dof)
        if len(given) != n_external:
            raise CaseError(
                f"expected {n_external} weights (the track, then the positioner's axes), "
                f"got {len(given)}: {show(given)}",
                file=case.source,
                key="objective.external_weights",
            )
        objective = dataclasses.replace(objective, external_weights=np.array(given, dtype=float))
    return dataclasses.replace(
        case,
        task=task,
        paths=seams,
        positioner=positioner,
        track=track,
        downhand=downhand,
        objective=objective,
    )


def _seam_weave(own: Any, case_weave: Weave | None) -> Weave | None:
    """A seam's weave: its task's (``weave: null`` turns it off), else the case's."""
    if own is None or "weave" not in own.model_fields_set:
        return case_weave
    return as_weave(own.weave)
