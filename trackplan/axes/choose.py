"""The external axes' motion along one seam: the positioner keeps the weld downhand, the
track carries the arm along (``docs/positioner.md``, "Downhand and the track").

:func:`choose_axes` is the one call the planner makes per seam and placement X. It returns
one smooth profile per external axis over the planned path's arc length
(:class:`~trackplan.axes.profile.AxesProfile`), or an :class:`AxesFailure` that names the
stretch where the weld cannot be held downhand with the given axes.

- **Positioner with ``downhand``.** Held still (:func:`~trackplan.axes.pointwise.hold_values`)
  when that already meets the rule. Otherwise the pointwise closed form
  (:func:`~trackplan.axes.pointwise.upright_branches`) turns the weld normal straight up at
  every sample; each branch, and each path that passes from one branch to the other where
  they meet (:func:`~trackplan.axes.pointwise.crossed_branches`), is made continuous
  (unwrapped) and its free winding chosen at the start so that it stays inside every
  axis's range, nearest to the hold value; the candidate with the least travel wins.
  Samples over a bound (the normal not square to the travel) are leaned by
  :func:`~trackplan.axes.polish.polish`, trading rotation for slope. A
  constant at the middle of that motion is taken when it meets the rule; else B-splines are
  fitted to it with 8, 16, 32 and 64 coefficients (more while none meets the rule) and the
  :data:`SMOOTHINGS`, each checked on a grid twice as dense as the fit's (the rule with
  :data:`FIT_SLACK` to spare), and of those that meet it the one that lets the seam run
  fastest on the axes' velocity and acceleration limits wins: the least motion the rule's
  bounds leave room for, no needless wiggles.
- **Positioner without ``downhand``**: held still at the hold value.
- **Track**: the arm's base abreast of the TCP along the track's axis, ``t(s) = axis ·
  p_cell_tool(s) − TRACK_LEAD``, clipped to the range, fitted with one coefficient per
  :data:`TRACK_SPACING` of seam.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from trackplan.axes.figures import (
    SeamDirections,
    angles_in_cell,
    carrier_points,
    describe_excess,
)
from trackplan.axes.fit import SplineFit, fit_coefficients
from trackplan.axes.pointwise import (
    crossed_branches,
    fill_undetermined,
    hold_values,
    upright_branches,
)
from trackplan.axes.polish import polish
from trackplan.axes.profile import AxesProfile
from trackplan.axes.rules import Downhand
from trackplan.paths.path_geometry import PathGeometry
from trackplan.profiles import DEGREE, Profile
from trackplan.robots.machine import Machine
from trackplan.robots.model import Robot
from trackplan.status import Status
from trackplan.tool.spec import ToolSpec

SAMPLE_STEP = 1e-3
"""Arc-length step of the fit's samples, m (at least 201, at most 4001 samples)."""
FIT_SLACK = 1e-3
"""The fitted profile meets each bound of the rule with this much to spare, rad; where the
pointwise solution is within this of the bound or over it (a rule of 0° cannot be met by a
spline exactly), it may exceed the pointwise solution's angle by this much."""
MAX_COEFFICIENTS = 512
"""Most coefficients of a positioner axis's profile."""
FIT_TRIES = (8, 16, 32, 64)
"""Coefficient counts every one of which is fitted (more only while none meets the rule);
of those that meet the rule the one that lets the seam run fastest wins."""
SMOOTHINGS = (1e-6, 1e-3, 1.0, 1e3)
"""Weights of the second derivative tried with each coefficient count
(:func:`~trackplan.axes.fit.fit_coefficients`): the heavier ones flatten the motion where
the rule's bounds leave room (a positioner that need not follow the exact "straight up")."""
TRACK_LEAD = 0.0
"""The arm's preferred offset along the track's axis behind the TCP, m: 0 keeps the base
abreast of the TCP, where a welding arm has its reach to both sides."""
TRACK_SPACING = 0.25
"""Seam length per coefficient of the track's profile, m: a smooth ramp, no wiggles."""
TAU = 2.0 * np.pi


@dataclass(frozen=True)
class AxesFailure:
    """Why a seam cannot be held downhand with the given axes (the planner's exit 3).

    Attributes
    ----------
    status
        :attr:`~trackplan.status.Status.LIMITS_VIOLATED` (the downhand bounds),
        :attr:`~trackplan.status.Status.POSITION_LIMITS` (every branch leaves an axis's
        range) or :attr:`~trackplan.status.Status.NOT_CONVERGED` (no fit met the rule).
    message
        One line naming the stretch (s from–to, m) and the angle reached.
    s_from, s_to
        The stretch, m (None when the failure is not about a stretch).
    reached
        The angle reached over the stretch, rad (None likewise).
    """

    status: Status
    message: str
    s_from: float | None = None
    s_to: float | None = None
    reached: float | None = None


def sample_grid(length: float) -> np.ndarray:
    """Arc lengths at which the profiles are solved and checked, shape (2N − 1,), m: the
    fit uses every other one."""
    n = int(np.clip(np.ceil(length / SAMPLE_STEP) + 1, 201, 4001))
    return np.linspace(0.0, length, 2 * n - 1)


def choose_axes(
    machine: Machine,
    geometry: PathGeometry,
    tool: ToolSpec,
    X: np.ndarray,
    downhand: Downhand | None,
) -> AxesProfile | AxesFailure:
    """The track's and the positioner's profiles along one seam at placement X.

    Parameters
    ----------
    machine
        The arm with its external axes.
    geometry
        The seam's planned path.
    tool
        The seam's tool spec (its weld normals).
    X
        The part's placement in the carrier frame, shape (6,).
    downhand
        The downhand rule, or None.

    Returns
    -------
    AxesProfile | AxesFailure
        One profile per external axis (track first), or why the rule cannot be met.

    Raises
    ------
    CaseError
        With ``downhand`` and a seam without a weld normal.
    """
    length = float(geometry.planned.length)
    s = sample_grid(length)
    X = np.asarray(X, dtype=float)
    directions = SeamDirections.sample(geometry, tool, X, s) if downhand is not None else None
    positioner = machine.positioner
    if positioner is None:
        values = np.zeros((len(s), 0))
        profiles: tuple[Profile, ...] = ()
        if downhand is not None and directions is not None:
            R = np.broadcast_to(np.eye(3), (len(s), 3, 3))
            failure = _rule_failure(
                s, R, directions, downhand, "there is no positioner to turn the part"
            )
            if failure is not None:
                return failure
    elif downhand is None or directions is None:
        hold = hold_values(positioner.chain)
        values = np.broadcast_to(hold, (len(s), len(hold)))
        profiles = tuple(Profile.constant(v, length) for v in hold)
    else:
        chosen = _downhand_positioner(machine, directions, downhand, length)
        if isinstance(chosen, AxesFailure):
            return chosen
        profiles = chosen
        values = np.stack([p.value(s) for p in profiles], axis=1)
    if machine.track is not None:
        position = directions.position if directions is not None else carrier_points(geometry, X, s)
        profiles = (_track_profile(machine, values, position, s, length), *profiles)
    return AxesProfile(profiles)


def _carrier_rotations(machine: Machine, values: np.ndarray) -> np.ndarray:
    """The carrier's rotation in the cell (M, 3, 3) at positioner angles (M, n)."""
    q = np.zeros((len(values), machine.n_dof))
    q[:, machine.positioner_columns] = values
    R: np.ndarray = machine.T_cell_carrier(q)[:, :3, :3]
    return R


def _rule_failure(
    s: np.ndarray,
    R: np.ndarray,
    directions: SeamDirections,
    downhand: Downhand,
    reason: str,
) -> AxesFailure | None:
    """The failure where the angles under carrier rotations R (M, 3, 3) exceed the rule."""
    slope, rotation = angles_in_cell(R, directions.normal, directions.tangent)
    for what, value, bound in (
        ("rotation", rotation, downhand.rotation),
        ("slope", slope, downhand.slope),
    ):
        excess = describe_excess(s, value, bound, what, reason)
        if excess is not None:
            return AxesFailure(
                Status.LIMITS_VIOLATED, excess.message, excess.s_from, excess.s_to, excess.reached
            )
    return None


def _wind(
    values: np.ndarray, lower: np.ndarray, upper: np.ndarray, hold: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """Continuous angles (M, n) shifted by whole turns into [lower, upper] (n,) each,
    nearest to ``hold`` (n,); with the axes that no turn brings inside, shape (n,) bool."""
    low, high = values.min(axis=0), values.max(axis=0)
    k_min = np.ceil((lower - low) / TAU - 1e-12)
    k_max = np.floor((upper - high) / TAU + 1e-12)
    k_best = np.round((hold - 0.5 * (low + high)) / TAU)
    k = np.clip(k_best, k_min, np.maximum(k_min, k_max))
    return values + TAU * k, k_min > k_max


def _downhand_positioner(
    machine: Machine, directions: SeamDirections, downhand: Downhand, length: float
) -> tuple[Profile, ...] | AxesFailure:
    """The positioner's profiles that keep the weld downhand, or why they cannot."""
    assert machine.positioner is not None
    chain = machine.positioner.chain
    s = directions.s
    hold = hold_values(chain)
    held = np.broadcast_to(hold, (len(s), len(hold)))
    if _rule_failure(s, _carrier_rotations(machine, held), directions, downhand, "") is None:
        return tuple(Profile.constant(v, length) for v in hold)
    R_pose = machine.positioner.T_cell_base[:3, :3]
    branches, gamma = upright_branches(chain, R_pose, directions.normal, hold)
    if len(branches) == 2:
        branches = np.concatenate([branches, crossed_branches(branches, gamma)])
    candidates = []
    for branch in branches:
        continuous = np.unwrap(fill_undetermined(branch, hold), axis=0)
        wound, outside = _wind(continuous, chain.q_min, chain.q_max, hold)
        travel = float(np.abs(np.diff(wound, axis=0)).sum())
        candidates.append((bool(outside.any()), travel, wound, outside))
    candidates.sort(key=lambda c: (c[0], c[1]))
    outside_any, _, solution, outside = candidates[0]
    if outside_any:
        j = int(np.flatnonzero(outside)[0])
        lo, hi = np.degrees(solution[:, j].min()), np.degrees(solution[:, j].max())
        return AxesFailure(
            Status.POSITION_LIMITS,
            f"downhand: the positioner's axis {chain.joint_names[j]} must turn from "
            f"{lo:.1f}° to {hi:.1f}° (a sweep of {hi - lo:.1f}°) at s = 0.000–{length:.3f} m "
            "to hold the weld downhand, and no whole turn of its start brings that inside "
            f"its range [{np.degrees(chain.q_min[j]):.1f}°, {np.degrees(chain.q_max[j]):.1f}°]",
            0.0,
            length,
        )
    solution = _lean(machine, directions, downhand, solution)
    R = _carrier_rotations(machine, solution)
    failure = _rule_failure(
        s, R, directions, downhand, "the positioner's axes cannot turn it further"
    )
    if failure is not None:
        return failure
    pointwise_slope, pointwise_rotation = angles_in_cell(R, directions.normal, directions.tangent)
    slope_bound = np.maximum(downhand.slope - FIT_SLACK, pointwise_slope + FIT_SLACK)
    rotation_bound = np.maximum(downhand.rotation - FIT_SLACK, pointwise_rotation + FIT_SLACK)

    def meets(values: np.ndarray) -> bool:
        slope, rotation = angles_in_cell(
            _carrier_rotations(machine, values), directions.normal, directions.tangent
        )
        return bool(np.all(slope <= slope_bound) and np.all(rotation <= rotation_bound))

    middle = 0.5 * (solution.min(axis=0) + solution.max(axis=0))
    if meets(np.broadcast_to(middle, solution.shape)):
        return tuple(Profile.constant(v, length) for v in middle)
    k = FIT_TRIES[0]
    fitted = solution
    met: list[tuple[float, int, np.ndarray]] = []
    largest = min(MAX_COEFFICIENTS, (len(s) + 1) // 4)
    while k <= largest and (not met or k <= FIT_TRIES[-1]):
        fitter = SplineFit(s[::2], s, length, k)
        for smoothing in SMOOTHINGS:
            coefficients, fitted = fitter.fit(solution[::2], chain.q_min, chain.q_max, smoothing)
            if meets(fitted):
                rate, curvature = fitter.rate_bounds(coefficients)
                met.append((_seam_speed(chain, rate, curvature), -k, coefficients))
        k *= 2
    if met:
        best = max(met, key=lambda m: (m[0], m[1]))[2]
        return tuple(Profile(best[:, j], length) for j in range(chain.n_dof))
    k //= 2
    slope, rotation = angles_in_cell(
        _carrier_rotations(machine, fitted), directions.normal, directions.tangent
    )
    over = (slope > slope_bound) | (rotation > rotation_bound)
    where = s[over]
    return AxesFailure(
        Status.NOT_CONVERGED,
        f"downhand: no smooth positioner profile of up to {k} coefficients keeps the weld "
        f"within the rule at s = {where.min():.3f}–{where.max():.3f} m (rotation reached "
        f"{np.degrees(rotation.max()):.1f}°, slope {np.degrees(slope.max()):.1f}°): the "
        "pointwise solution turns too fast there",
        float(where.min()),
        float(where.max()),
        float(max(rotation.max(), slope.max())),
    )


def _lean(
    machine: Machine, directions: SeamDirections, downhand: Downhand, solution: np.ndarray
) -> np.ndarray:
    """The pointwise solution (M, n) with the samples over a bound (within
    :data:`FIT_SLACK` of it) leaned by :func:`~trackplan.axes.polish.polish` to trade
    rotation for slope, kept inside the axes' ranges."""
    assert machine.positioner is not None
    chain = machine.positioner.chain
    slope, rotation = angles_in_cell(
        _carrier_rotations(machine, solution), directions.normal, directions.tangent
    )
    over = (slope > downhand.slope - FIT_SLACK) | (rotation > downhand.rotation - FIT_SLACK)
    if not over.any():
        return solution
    normal, tangent = directions.normal[over], directions.tangent[over]

    def angles(values: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        return angles_in_cell(_carrier_rotations(machine, values), normal, tangent)

    target = 2.0 * FIT_SLACK
    leaned = polish(angles, solution[over], downhand.slope - target, downhand.rotation - target)
    result = solution.copy()
    result[over] = np.clip(leaned, chain.q_min, chain.q_max)
    return result


def _seam_speed(chain: Robot, rate: np.ndarray, curvature: np.ndarray) -> float:
    """The fastest seam speed (m/s) that profiles with |e'| ≤ rate and |e''| ≤ curvature
    (n,) each allow on the axes' velocity and acceleration limits alone:
    ``min_j min(v_j / |e_j'|, sqrt(a_j / |e_j''|))``."""
    with np.errstate(divide="ignore"):
        by_velocity = np.where(rate > 0.0, chain.v_max / rate, np.inf)
        by_acceleration = np.where(curvature > 0.0, np.sqrt(chain.a_max / curvature), np.inf)
    return float(np.minimum(by_velocity, by_acceleration).min())


def _track_profile(
    machine: Machine,
    positioner: np.ndarray,
    position: np.ndarray,
    s: np.ndarray,
    length: float,
) -> Profile:
    """The track's profile: the base abreast of the TCP, clipped to the range, smoothed."""
    track = machine.track
    assert track is not None
    q = np.zeros((len(s), machine.n_dof))
    q[:, machine.positioner_columns] = positioner
    T = machine.T_cell_carrier(q)
    tcp = np.einsum("mij,mj->mi", T[:, :3, :3], position) + T[:, :3, 3]
    target = np.clip(tcp @ track.axis - TRACK_LEAD, track.lower, track.upper)
    k = int(np.clip(np.ceil(length / TRACK_SPACING) + DEGREE, DEGREE + 1, 64))
    coefficients = fit_coefficients(
        s, target[:, None], length, k, np.array([track.lower]), np.array([track.upper])
    )
    return Profile(coefficients[:, 0], length)
