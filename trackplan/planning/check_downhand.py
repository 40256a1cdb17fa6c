"""The checker's downhand check: the weld flat at every sample (``docs/positioner.md``).

At every sample the weld's normal and its travel direction are taken on the nominal path
where the checker located the tool (the declared weld normal of the segment there, or the
tool's ``normal``/``normals``; the nominal tangent), turned into the cell frame by the part's
pose at that sample (the placement, carried by the positioner's axes for a machine), and
measured against gravity (−z of the cell frame): the **rotation** is the normal's angle to
straight up, the **slope** the travel direction's angle to the horizontal plane.
"""

from __future__ import annotations

import numpy as np

from trackplan.check_report import DownhandFigures, Violation
from trackplan.motion import JointSamples
from trackplan.paths import NominalPath
from trackplan.paths.specs import PointsSpec
from trackplan.planning.check_reference import TrackingReference
from trackplan.planning.check_violations import RELATIVE_SLACK, met
from trackplan.robots.machine import Machine
from trackplan.tool import ToolSpec
from trackplan.tool.weld_normal import declares_normals, nominal_normals


def weld_directions(
    spec: ToolSpec, nominal: NominalPath, s: np.ndarray, piece: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """The weld's unit normal and travel direction in the part frame at arc lengths ``s``
    (N,) on pieces ``piece`` (N,) of the nominal path, shape (N, 3) each.

    Raises
    ------
    ValueError
        When neither the segments nor the tool give a normal (the case loader refuses a
        downhand rule without one).
    """
    tangent = smooth_tangents(nominal, s, piece)
    if declares_normals(nominal.segments):
        normal = nominal_normals(spec, nominal, s, piece)
    elif spec.normals is not None:
        normal = spec.segment_normals(nominal.segment_index[piece])
    elif spec.normal is not None:
        normal = np.broadcast_to(spec.normal, tangent.shape)
    else:
        raise ValueError("the downhand rule needs the weld's normal (task.tool.normal)")
    normal = normal / np.linalg.norm(normal, axis=1, keepdims=True)
    return normal, tangent


def smooth_tangents(nominal: NominalPath, s: np.ndarray, piece: np.ndarray) -> np.ndarray:
    """Unit travel directions on the nominal path at arc lengths ``s`` (N,) on pieces
    ``piece`` (N,), shape (N, 3): the tangent of a line or arc, and along the polyline of a
    sampled curve (``points``) the direction of the curve the points sample: at each point
    the mean of its two edges' directions, in between linear in the arc length (the edges'
    own directions jump from edge to edge, by the curve's turn between two points)."""
    table = nominal.table
    n_pieces = table.n_pieces
    middle = table.s_start + 0.5 * table.length
    edge = nominal.tangents(middle, np.arange(n_pieces))  # (P, 3): each piece's mid tangent
    segment = nominal.segment_index
    sampled = np.array([isinstance(spec, PointsSpec) for spec in nominal.segments])[segment]
    # the mean direction at each piece's start and end where its neighbour samples the same curve
    before = np.r_[False, (segment[1:] == segment[:-1]) & sampled[1:] & sampled[:-1]]
    after = np.r_[before[1:], False]
    start = np.where(before[:, None], edge + np.roll(edge, 1, axis=0), edge)
    end = np.where(after[:, None], edge + np.roll(edge, -1, axis=0), edge)
    start /= np.linalg.norm(start, axis=1, keepdims=True)
    end /= np.linalg.norm(end, axis=1, keepdims=True)
    tangent = nominal.tangents(s, piece)
    on_points = sampled[piece]
    if on_points.any():
        k = piece[on_points]
        u = np.clip((s[on_points] - table.s_start[k]) / table.length[k], 0.0, 1.0)[:, None]
        blended = (1.0 - u) * start[k] + u * end[k]
        tangent[on_points] = blended / np.linalg.norm(blended, axis=1, keepdims=True)
    return tangent


def weld_angles(
    R_cell_part: np.ndarray, normal: np.ndarray, tangent: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """The weld's slope and rotation with the part at ``R_cell_part`` (N, 3, 3) or (3, 3):
    the travel direction's angle to the horizontal and the normal's angle to straight up,
    rad, shape (N,) each, from the part-frame normal and tangent (N, 3)."""
    up_normal = np.einsum("...j,...j->...", R_cell_part[..., 2, :], normal)
    up_tangent = np.einsum("...j,...j->...", R_cell_part[..., 2, :], tangent)
    rotation = np.arccos(np.clip(up_normal, -1.0, 1.0))
    slope = np.arcsin(np.clip(np.abs(up_tangent), 0.0, 1.0))
    return slope, rotation


def check_downhand(
    motion: JointSamples,
    ref: TrackingReference,
    s_nominal: np.ndarray,
    piece: np.ndarray,
    t: np.ndarray,
) -> tuple[DownhandFigures, float, list[Violation]]:
    """The downhand rule at every sample.

    Parameters
    ----------
    motion
        The samples (a machine's whole joint vector, or a robot's joints).
    ref
        The task, with its ``downhand`` rule (not None).
    s_nominal, piece
        Where the checker located each sample on the nominal path, shape (N,) each.
    t
        Sample times, shape (N,), s.

    Returns
    -------
    tuple
        The figures reached, the margin ``1 − max(slope / bound, rotation / bound)`` and a
        ``downhand`` violation per rule broken (slope, rotation), naming where.
    """
    rule = ref.downhand
    assert rule is not None
    normal, tangent = weld_directions(ref.tool, ref.nominal, s_nominal, piece)
    R_cell_part = ref.T_base_part[:3, :3]
    if isinstance(motion.robot, Machine):
        R_cell_part = motion.robot.T_cell_carrier(motion.q)[:, :3, :3] @ R_cell_part
    slope, rotation = weld_angles(R_cell_part, normal, tangent)
    slope_use = slope / max(rule.slope, 1e-12)
    rotation_use = rotation / max(rule.rotation, 1e-12)
    within = (slope_use <= 1.0 + RELATIVE_SLACK) & (rotation_use <= 1.0 + RELATIVE_SLACK)
    figures = DownhandFigures(
        max_slope=float(slope.max(initial=0.0)),
        max_rotation=float(rotation.max(initial=0.0)),
        slope=rule.slope,
        rotation=rule.rotation,
        share=float(within.mean()) if len(within) else 1.0,
    )
    worst = max(float(slope_use.max(initial=0.0)), float(rotation_use.max(initial=0.0)))
    found = [
        _violation(what, values, use, bound, t, s_nominal)
        for what, values, use, bound in (
            ("the travel direction's slope to the horizontal", slope, slope_use, rule.slope),
            ("the weld normal's angle to straight up", rotation, rotation_use, rule.rotation),
        )
        if (use > 1.0 + RELATIVE_SLACK).any()
    ]
    return figures, float(met(1.0 - worst, RELATIVE_SLACK)), found


def _violation(
    what: str,
    values: np.ndarray,
    use: np.ndarray,
    bound: float,
    t: np.ndarray,
    s: np.ndarray,
) -> Violation:
    """One downhand violation: the angle reached, the bound, and the stretch (time and arc
    length along the seam) where it is over."""
    bad = np.flatnonzero(use > 1.0 + RELATIVE_SLACK)
    worst = int(bad[np.argmax(use[bad])])
    message = (
        f"downhand: {what} reaches {np.degrees(values[worst]):.1f}° (at most "
        f"{np.degrees(bound):.1f}°) at t = {t[worst]:.3f} s, s = {s[worst]:.3f} m; "
        f"over it on {len(bad)} of {len(t)} samples, s = {s[bad].min():.3f}–"
        f"{s[bad].max():.3f} m along the seam"
    )
    return Violation(
        limit="downhand",
        joint=None,
        t_first=float(t[bad[0]]),
        t_last=float(t[bad[-1]]),
        worst=float(values[worst]),
        bound=bound,
        message=message,
    )
