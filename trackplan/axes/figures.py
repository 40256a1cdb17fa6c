"""The downhand figures of a seam: the slope and rotation the weld reaches at each sample.

``rotation`` is the angle of the weld normal to straight up (+z of the cell frame) and
``slope`` the angle of the travel direction to the horizontal plane, both in rad, from the
carrier's motion (:meth:`~trackplan.robots.machine.Machine.T_cell_carrier`), the placement X
and the seam frame along the planned path (:class:`~trackplan.tool.seam.SeamNormal`,
:class:`~trackplan.tool.seam.SeamTangent`). :func:`stretches` turns the samples over a bound
into the verdict's wording.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from trackplan.derived import derived
from trackplan.errors import CaseError
from trackplan.frames import placement_transform
from trackplan.paths.path_geometry import PathGeometry
from trackplan.robots.machine import Machine
from trackplan.tool.seam import SeamNormal, SeamTangent
from trackplan.tool.spec import ToolSpec
from trackplan.tool.weld_normal import ConstantNormal, segment_fields


@dataclass(frozen=True, eq=False)
class SeamDirections:
    """The weld normal and travel direction in the carrier frame at arc lengths s.

    Attributes
    ----------
    s
        Arc lengths on the planned path, shape (M,), m.
    normal, tangent
        Unit weld normals and travel directions in the carrier frame, shape (M, 3) each.
    position
        The planned path's points in the carrier frame, shape (M, 3), m.
    """

    s: np.ndarray
    normal: np.ndarray
    tangent: np.ndarray
    position: np.ndarray

    @classmethod
    def sample(
        cls, geometry: PathGeometry, tool: ToolSpec, X: np.ndarray, s: np.ndarray
    ) -> SeamDirections:
        """The seam frame at ``s`` (M,) taken through the placement X (6,) to the carrier.

        Raises
        ------
        CaseError
            When the seam has no weld normal (``task.tool.normal`` or a segment's own).
        """
        s = np.asarray(s, dtype=float)
        s_bytes = s.tobytes()
        # sampled once per seam, tool spec and grid: every placement of a search reuses it;
        # the spec is kept alive with its values (its id stays its own)
        _, (normal, tangent, position) = derived(
            geometry,
            ("seam directions", id(tool), s_bytes),
            lambda: (tool, _in_part(geometry, tool, s_bytes)),
        )
        T = placement_transform(np.asarray(X, dtype=float))
        R = T[:3, :3]
        return cls(s, normal @ R.T, tangent @ R.T, position @ R.T + T[:3, 3])


def _in_part(
    geometry: PathGeometry, tool: ToolSpec, s_bytes: bytes
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The weld normals, travel directions and points (M, 3) each in the part frame at the
    arc lengths ``s`` given as bytes (the same for every placement of a seam)."""
    s = np.frombuffer(s_bytes, dtype=float)
    fields = segment_fields(tool, geometry.nominal)
    if any(isinstance(f, ConstantNormal) and not np.any(f.normal) for f in fields):
        raise CaseError(
            "needs a weld normal: give task.tool.normal (frame: seam) or a normal on "
            "every segment (arc weld_normal, points nx,ny,nz)",
            key="downhand",
        )
    sample = geometry.planned.sample(s)
    normal = SeamNormal.from_geometry(tool, geometry)(s, sample.position)
    tangent = SeamTangent.from_geometry(geometry)(s, sample.tangent)
    for array in (normal, tangent, sample.position):
        array.flags.writeable = False
    return normal, tangent, sample.position


def carrier_points(geometry: PathGeometry, X: np.ndarray, s: np.ndarray) -> np.ndarray:
    """The planned path's points at ``s`` (M,) in the carrier frame, shape (M, 3), m."""
    T = placement_transform(np.asarray(X, dtype=float))
    position = geometry.planned.sample(np.asarray(s, dtype=float)).position
    points: np.ndarray = position @ T[:3, :3].T + T[:3, 3]
    return points


def angles_in_cell(
    R_cell_carrier: np.ndarray, normal: np.ndarray, tangent: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """Slope and rotation (M,) each, rad, of carrier-frame normals and tangents (M, 3)
    under carrier rotations (M, 3, 3)."""
    n_z = np.einsum("mk,mk->m", R_cell_carrier[:, 2, :], normal)
    t_z = np.einsum("mk,mk->m", R_cell_carrier[:, 2, :], tangent)
    rotation = np.arccos(np.clip(n_z, -1.0, 1.0))
    slope = np.arcsin(np.clip(np.abs(t_z), 0.0, 1.0))
    return slope, rotation


def downhand_figures(
    machine: Machine,
    q: np.ndarray,
    geometry: PathGeometry,
    tool: ToolSpec,
    X: np.ndarray,
    s: np.ndarray,
) -> tuple[np.ndarray, np.ndarray]:
    """The slope and rotation the weld reaches at each sample, for result.json and the
    report.

    Parameters
    ----------
    machine
        The arm with its external axes.
    q
        The machine's joint vectors at the samples, shape (M, n) (only the positioner's
        columns move the part).
    geometry, tool
        The seam's planned path and tool spec (its weld normals).
    X
        The part's placement in the carrier frame, shape (6,).
    s
        Arc lengths of the samples on the planned path, shape (M,), m.

    Returns
    -------
    slope, rotation
        Shape (M,) each, rad: the travel direction's angle to the horizontal, the weld
        normal's angle to straight up.
    """
    directions = SeamDirections.sample(geometry, tool, X, s)
    R = machine.T_cell_carrier(np.asarray(q, dtype=float))[..., :3, :3]
    return angles_in_cell(R, directions.normal, directions.tangent)


def stretches(s: np.ndarray, over: np.ndarray) -> list[tuple[float, float]]:
    """The runs of consecutive samples where ``over`` (M,) holds, as (s from, s to), m."""
    flags = np.concatenate([[False], np.asarray(over, dtype=bool), [False]])
    edges = np.flatnonzero(np.diff(flags.astype(np.int8)))
    starts, ends = edges[0::2], edges[1::2] - 1
    return [(float(s[a]), float(s[b])) for a, b in zip(starts, ends, strict=True)]


@dataclass(frozen=True)
class Excess:
    """Where an angle exceeds its bound most: the stretch and the angle reached there.

    Attributes
    ----------
    message
        The verdict's sentence.
    s_from, s_to
        The stretch's ends, m.
    reached
        The smallest angle over the stretch (the angle the axes cannot go below), rad.
    """

    message: str
    s_from: float
    s_to: float
    reached: float


def describe_excess(
    s: np.ndarray,
    value: np.ndarray,
    bound: float,
    what: str,
    reason: str,
) -> Excess | None:
    """The stretch where ``value`` (M,) rad exceeds ``bound`` most, with the verdict's
    sentence (None when it never does); ``what`` is ``rotation`` or ``slope``."""
    over = value > bound
    if not over.any():
        return None
    runs = stretches(s, over)
    worst = max(runs, key=lambda run: float(value[(s >= run[0]) & (s <= run[1])].max()))
    inside = (s >= worst[0]) & (s <= worst[1])
    reached = float(value[inside].min())
    peak = np.degrees(float(value[inside].max()))
    subject = (
        "the weld normal stays {:.1f}° from straight up"
        if what == "rotation"
        else "the travel direction stays {:.1f}° from the horizontal"
    ).format(np.degrees(reached))
    more = f" ({len(runs)} stretches in all)" if len(runs) > 1 else ""
    up_to = f" (up to {peak:.1f}°)" if peak - np.degrees(reached) >= 0.05 else ""
    message = (
        f"downhand: {subject}{up_to} at s = {worst[0]:.3f}–{worst[1]:.3f} m "
        f"({what} ≤ {np.degrees(bound):.1f}°){more}: {reason}"
    )
    return Excess(message, worst[0], worst[1], reached)
