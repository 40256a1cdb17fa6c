"""Weaving: the torch's oscillation across the seam (``task.weave``, ``docs/positioner.md``)."""

from __future__ import annotations

import enum
import math
from dataclasses import dataclass
from functools import cached_property
from typing import TYPE_CHECKING

import numpy as np

from trackplan.choices import choose
from trackplan.errors import CaseError
from trackplan.paths.planned import Path
from trackplan.tool.orientation import ToolOrientation
from trackplan.tool.rotations import rotation_x, rotation_y
from trackplan.tool.spec import ToolFrame

if TYPE_CHECKING:  # scipy's tree only where a weaving seam is checked (startup time)
    from scipy.spatial import cKDTree


class WeavePattern(enum.StrEnum):
    """The shape of one weave period."""

    TRIANGLE = "triangle"
    SINE = "sine"
    TRAPEZOID = "trapezoid"


class WeavePlane(enum.StrEnum):
    """Where "across the seam" lies: the seam frame's y axis (``seam``) or the tool's
    (``tool``)."""

    SEAM = "seam"
    TOOL = "tool"


@dataclass(frozen=True)
class Weave:
    """A weave superposed on the seam: the tolerance holds for its centre line.

    Attributes
    ----------
    pattern
        ``triangle``, ``sine`` or ``trapezoid``.
    plane
        ``seam`` or ``tool``.
    amplitude
        Excursion to each side of the centre line, m (half the weave's width).
    frequency
        Full periods per second at the rated speed, Hz.
    dwell
        Time held at each side, s (``trapezoid``; 0 otherwise).
    """

    pattern: WeavePattern = WeavePattern.TRIANGLE
    plane: WeavePlane = WeavePlane.SEAM
    amplitude: float = 0.002
    frequency: float = 2.0
    dwell: float = 0.0

    def __post_init__(self) -> None:
        object.__setattr__(self, "pattern", choose(WeavePattern, self.pattern, "weave.pattern"))
        object.__setattr__(self, "plane", choose(WeavePlane, self.plane, "weave.plane"))
        for key, unit in (("amplitude", "m"), ("frequency", "Hz")):
            value = getattr(self, key)
            if not (isinstance(value, int | float) and math.isfinite(value) and value > 0):
                raise CaseError(
                    f"must be a finite number > 0 ({unit}), got {value!r}", key=f"weave.{key}"
                )
        if not (math.isfinite(self.dwell) and 0.0 <= self.dwell < 0.5 / self.frequency):
            raise CaseError(
                f"must be in [0, half a period = {0.5 / self.frequency:g}) s, got {self.dwell!r}",
                key="weave.dwell",
            )
        if self.pattern is not WeavePattern.TRAPEZOID and self.dwell != 0.0:
            raise CaseError("a dwell needs pattern: trapezoid", key="weave.dwell")

    def wavelength(self, rated_speed: float) -> float:
        """The weave's spatial period λ = v_r / f, m: the phase runs over the planned path's
        arc length, so the frequency is exact where the seam runs at its rated speed."""
        return float(rated_speed) / self.frequency

    def along(self, rated_speed: float) -> WeaveTrack:
        """The weave laid over arc length at the rated speed ``rated_speed``, m/s."""
        return WeaveTrack(self, self.wavelength(rated_speed))


TRIANGLE_ROUNDING = 0.1
"""Half-width of a triangle's rounded turn-around, in periods: each turn-around takes
``2 · 0.1`` of the period (both together 40 %), the straight flanks the rest."""


@dataclass(frozen=True, eq=False)
class WeaveTrack:
    """A weave laid over the planned path's arc length s.

    Attributes
    ----------
    weave
        The weave.
    wavelength
        λ, the spatial period, m (:meth:`Weave.wavelength`).
    """

    weave: Weave
    wavelength: float

    @property
    def amplitude(self) -> float:
        """The weave's amplitude, m."""
        return self.weave.amplitude

    def offset(self, s: np.ndarray) -> np.ndarray:
        """The lateral offset w(s) at arc lengths ``s`` (M,), m, shape (M,): 0 at s = 0,
        rising first, ±amplitude at the turn-arounds, C2 in s."""
        u = np.asarray(s, dtype=float) / self.wavelength
        weave = self.weave
        return weave.amplitude * weave_shape(weave.pattern, u, weave.dwell * weave.frequency)


def weave_shape(pattern: WeavePattern, u: np.ndarray, dwell: float = 0.0) -> np.ndarray:
    """One weave of unit amplitude at phases ``u`` (M,), in periods, shape (M,), in [−1, 1].

    Every shape is 0 at u = 0 and rising, +1 at the first turn-around and −1 at the second,
    and C2 in u (its third derivative jumps where pieces meet, so the jerk stays bounded):

    - ``sine``: sin 2πu;
    - ``triangle``: straight flanks of slope ±k per period; each turn-around (within
      r = :data:`TRIANGLE_ROUNDING` periods of it, x its phase distance) is the quartic
      ``1 − 3k x²/(4r) + k x⁴/(8r³)``, which meets the flanks at x = r with equal value,
      slope and zero curvature; k = 1 / (1/4 − 3r/8) puts the peak exactly at 1;
    - ``trapezoid``: holds ±1 for ``dwell`` periods at each side, and crosses between them
      on the quintic smooth step 10x³ − 15x⁴ + 6x⁵ (zero slope and curvature at its ends).

    Parameters
    ----------
    pattern
        The weave pattern.
    u
        Phase, periods (s / λ).
    dwell
        Time at each side as a share of the period (dwell · frequency), trapezoid only.
    """
    u = np.asarray(u, dtype=float)
    if pattern is WeavePattern.SINE:
        out: np.ndarray = np.sin(2.0 * np.pi * u)
        return out
    if pattern is WeavePattern.TRIANGLE:
        r = TRIANGLE_ROUNDING
        k = 1.0 / (0.25 - 3.0 * r / 8.0)  # flank slope, per period
        # x: phase distance from the nearest turn-around (peak at u = 1/4, trough at 3/4)
        v = np.mod(u - 0.25, 1.0)
        from_peak = np.minimum(v, 1.0 - v)  # in [0, 1/2]
        sign = np.where(from_peak < 0.25, 1.0, -1.0)
        x = np.where(from_peak < 0.25, from_peak, 0.5 - from_peak)
        # the flank 1 + 3kr/8 − k x crosses 0 at x = 1/4; the round p(x) = 1 + a2 x² + a4 x⁴
        # meets it at x = r with equal value, slope and (zero) curvature
        a4 = k / (8.0 * r**3)
        a2 = -3.0 * k / (4.0 * r)
        flank = 1.0 + 3.0 * k * r / 8.0 - k * x
        round_ = 1.0 + a2 * x**2 + a4 * x**4
        return sign * np.where(x < r, round_, flank)
    # trapezoid: rising across u in [−τ/2, τ/2], holding +1, falling across [½ − τ/2, ½ + τ/2]
    tau = 0.5 - dwell
    v = np.mod(u + tau / 2.0, 1.0)  # 0 at the start of the rise
    rise = np.clip(v / tau, 0.0, 1.0)
    fall = np.clip((v - 0.5) / tau, 0.0, 1.0)
    step = _smooth_step(rise) - _smooth_step(fall)  # 0 → 1 → 0
    shape: np.ndarray = 2.0 * step - 1.0
    return shape


def _smooth_step(x: np.ndarray) -> np.ndarray:
    """10x³ − 15x⁴ + 6x⁵ for x in [0, 1]."""
    out: np.ndarray = x**3 * (10.0 + x * (-15.0 + 6.0 * x))
    return out


def weave_axes(
    plane: WeavePlane,
    tool: ToolOrientation,
    s: np.ndarray,
    tangent: np.ndarray,
    rotations: np.ndarray,
) -> np.ndarray:
    """The unit axis the weave runs along at arc lengths ``s`` (M,), definition frame,
    shape (M, 3).

    ``plane: tool``: the tool's y axis. ``plane: seam``: the seam frame's y axis
    (``docs/tool.md``: ``y_s = z_s × x_s``, across the seam in the surface), taken from the
    orientation at zero spin with the work and travel angles undone; for ``frame: part``,
    which has no seam frame, the axis across the travel direction perpendicular to the tool
    axis (``z_tool × t``, normalised).

    Parameters
    ----------
    plane
        ``seam`` or ``tool``.
    tool
        The tool orientation along the planned path.
    s, tangent
        Arc lengths (M,), m, and the planned path's unit tangents there (M, 3).
    rotations
        ``R_part_tool`` at ``s``, (M, 3, 3), or one (3, 3) the whole path holds.
    """
    rotations = np.broadcast_to(rotations, (len(s), 3, 3))
    if plane is WeavePlane.TOOL:
        return np.ascontiguousarray(rotations[:, :, 1])
    spec = tool.spec
    if spec.frame is ToolFrame.SEAM:
        undo = rotation_y(-spec.travel_angle) @ rotation_x(-spec.work_angle)
        seam = tool.base_rotations(s, tangent) @ undo
        return np.ascontiguousarray(seam[:, :, 1])
    across = np.cross(rotations[:, :, 2], tangent)
    out: np.ndarray = across / np.linalg.norm(across, axis=1, keepdims=True)
    return out


def weave_offsets(
    track: WeaveTrack,
    tool: ToolOrientation,
    s: np.ndarray,
    tangent: np.ndarray,
    rotations: np.ndarray,
) -> np.ndarray:
    """The weave's displacement of the tool point at arc lengths ``s`` (M,), definition
    frame, shape (M, 3), m: ``w(s) · axis(s)`` (:meth:`WeaveTrack.offset`,
    :func:`weave_axes`); parameters as :func:`weave_axes`."""
    axes = weave_axes(track.weave.plane, tool, s, tangent, rotations)
    out: np.ndarray = track.offset(s)[:, None] * axes
    return out


LOCATE_STEP = 2.5e-4
"""Spacing of the planned-path points a sample is first located on, m (at most λ / 40)."""
LOCATE_ITERATIONS = 5
"""Newton steps that refine a sample's arc length on the woven path."""


@dataclass(frozen=True, eq=False)
class WovenPath:
    """A weave over one planned path: where a tool point lies along it and its centre line.

    Attributes
    ----------
    track
        The weave over arc length.
    planned
        The planned path (:class:`trackplan.paths.planned.Path`), definition frame.
    tool
        The tool orientation along it (any spin: only the seam frame is read).
    """

    track: WeaveTrack
    planned: Path
    tool: ToolOrientation

    @cached_property
    def _index(self) -> tuple[cKDTree, np.ndarray]:
        """A k-d tree of planned-path points and their arc lengths (M,), m."""
        length = self.planned.length
        step = min(LOCATE_STEP, self.track.wavelength / 40.0)
        s = np.linspace(0.0, length, max(2, int(np.ceil(length / step)) + 1))
        from scipy.spatial import cKDTree  # only a weaving seam's check needs the tree

        return cKDTree(self.planned.sample(s).position), s

    def axes(self, s: np.ndarray, R_part_tool: np.ndarray) -> np.ndarray:
        """The weave's axis at arc lengths ``s`` (N,) for tools at ``R_part_tool`` (N, 3, 3),
        definition frame, shape (N, 3) (:func:`weave_axes`; ``plane: tool`` reads the
        tool's own y axis, so no spin is needed)."""
        _, _, tangent = self.planned.points(s)
        return weave_axes(self.track.weave.plane, self.tool, s, tangent, R_part_tool)

    def locate(self, points: np.ndarray, R_part_tool: np.ndarray) -> np.ndarray:
        """Arc length on the planned path of woven tool points (N, 3) with their tool
        orientations (N, 3, 3), shape (N,), m.

        The nearest planned-path point seeds Newton's method on
        ``(p − c(s) − w(s) a(s)) · t(s) = 0``: the point along the path whose woven point
        has no offset from ``p`` along the travel direction (exact on lines; the weave's
        amplitude must stay below the planned path's radius of curvature).
        """
        points = np.asarray(points, dtype=float).reshape(-1, 3)
        tree, grid = self._index
        _, nearest = tree.query(points)
        s = grid[nearest]
        length, h = self.planned.length, 1e-3 * self.track.wavelength
        for _ in range(LOCATE_ITERATIONS):
            sample = self.planned.sample(s)
            tangent = sample.tangent
            axis = self.axes(s, R_part_tool)
            w = self.track.offset(s)
            slope = (self.track.offset(s + h) - self.track.offset(s - h)) / (2.0 * h)
            rest = points - sample.position - w[:, None] * axis
            f = np.einsum("nk,nk->n", rest, tangent)
            # −f'(s), with t' = κ and a' · t = −a · κ for an axis across the path
            bend = np.einsum("nk,nk->n", rest + w[:, None] * axis, sample.curvature)
            along = np.einsum("nk,nk->n", axis, tangent)
            step = f / np.maximum(1.0 + slope * along - bend, 0.2)
            s = np.clip(s + step, 0.0, length)
        located: np.ndarray = s
        return located

    def unweave(
        self, points: np.ndarray, R_part_tool: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """The centre line of woven tool points.

        Parameters
        ----------
        points
            Tool points, definition frame, shape (N, 3), m.
        R_part_tool
            Their tool orientations, shape (N, 3, 3).

        Returns
        -------
        centre
            ``p − w(s) a(s)``: the points with the weave's offset taken off, (N, 3), m.
        lateral
            Each point's offset from the planned path along the weave's axis, (N,), m.
        expected
            The weave's offset w(s) there, (N,), m.
        s
            Their arc lengths on the planned path, (N,), m.
        """
        points = np.asarray(points, dtype=float).reshape(-1, 3)
        s = self.locate(points, R_part_tool)
        _, centre, _ = self.planned.points(s)
        axis = self.axes(s, R_part_tool)
        expected = self.track.offset(s)
        lateral = np.einsum("nk,nk->n", points - centre, axis)
        return points - expected[:, None] * axis, lateral, expected, s


def tool_rotations(x_axis: np.ndarray, z_axis: np.ndarray) -> np.ndarray:
    """Rotations (N, 3, 3) with tool x axes ``x_axis`` and z axes ``z_axis`` (N, 3)."""
    return np.stack([x_axis, np.cross(z_axis, x_axis), z_axis], axis=-1)


RATED_SHARE = 0.99
"""Samples whose centre-line speed is at least this share of the rated speed count as
running at the rated speed (where the weave's frequency is measured)."""


@dataclass(frozen=True)
class WeaveReached:
    """The weave a trajectory reached, measured on its samples.

    Attributes
    ----------
    amplitude
        Half the spread of the lateral offset along the weave's axis, m.
    frequency
        One over the mean time between rising zero crossings of the lateral offset, over
        the periods run wholly at the rated speed (at least :data:`RATED_SHARE` of it), or
        over every period when none is, Hz (NaN without two crossings).
    pattern, plane
        The weave's.
    """

    amplitude: float
    frequency: float
    pattern: str
    plane: str

    def as_dict(self) -> dict[str, object]:
        """The figures as plain data (``result.json``'s ``weave``)."""
        frequency = self.frequency if math.isfinite(self.frequency) else None
        return {
            "amplitude": self.amplitude,
            "frequency": frequency,
            "pattern": self.pattern,
            "plane": self.plane,
        }


def weave_reached(
    weave: WovenPath,
    points: np.ndarray,
    R_part_tool: np.ndarray,
    sample_time: float,
    rated_speed: float,
) -> WeaveReached:
    """Measure the weave of sampled tool points.

    Parameters
    ----------
    weave
        The weave over the planned path.
    points, R_part_tool
        The tool points (N, 3), m, and orientations (N, 3, 3), definition frame, at Ts.
    sample_time
        Ts, s.
    rated_speed
        v_r, m/s.
    """
    centre, lateral, _, _ = weave.unweave(points, R_part_tool)
    pattern, plane = str(weave.track.weave.pattern), str(weave.track.weave.plane)
    if len(lateral) < 2:
        return WeaveReached(0.0, math.nan, pattern, plane)
    amplitude = float(lateral.max() - lateral.min()) / 2.0
    speed = np.zeros(len(centre))
    speed[1:] = np.linalg.norm(np.diff(centre, axis=0), axis=1) / sample_time
    slow = np.cumsum(speed < RATED_SHARE * rated_speed)  # slow samples up to each sample
    k = np.flatnonzero((lateral[:-1] < 0.0) & (lateral[1:] >= 0.0))  # rising crossings
    t_cross = (k - lateral[k] / (lateral[k + 1] - lateral[k])) * sample_time
    periods = np.diff(t_cross)
    steady = slow[k[1:] + 1] == slow[k[:-1]]  # every sample of the period at the rated speed
    if steady.any():
        periods = periods[steady]
    frequency = 1.0 / float(periods.mean()) if len(periods) else math.nan
    return WeaveReached(amplitude, frequency, pattern, plane)
