"""Curves of a path: line, circular arc and quintic Bézier blend.

Every curve is parametrised by its own arc length σ ∈ [0, length] (m) and evaluates,
vectorised over samples, the position and its first three derivatives with respect
to σ. Lines and arcs are exact. A blend is a quintic Bézier curve B(u), u ∈ [0, 1];
σ ↦ u is found by Newton's method on a composite Gauss–Legendre arc-length integral,
converged to machine precision, so that position is a smooth function of σ to
rounding level (the trajectory is differentiated three times downstream).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from math import comb
from typing import ClassVar, NamedTuple, cast

import numpy as np

from trackplan.paths._kernels import blend_parameter

#: A line is an arc whose turning angle is below this (rad): its sagitta is < 1e-9 of its length.
STRAIGHT_ANGLE = 8e-9

#: Tangents closer than this (rad) are the same direction: the junction is not a corner.
COLLINEAR_ANGLE = 1e-9

_GAUSS_NODES, _GAUSS_WEIGHTS = np.polynomial.legendre.leggauss(16)

# Bernstein (degree 5) to power basis: a = _BERNSTEIN_TO_POWER @ P.
_BERNSTEIN_TO_POWER = np.array(
    [
        [comb(5, j) * comb(j, i) * (-1.0) ** (j - i) if i <= j else 0.0 for i in range(6)]
        for j in range(6)
    ]
)


def bezier_basis(u: np.ndarray, order: int) -> np.ndarray:
    """Matrix (M, 6) taking quintic control points to the ``order``-th u-derivative at u (M,)."""
    exponents = np.arange(6) - order
    factor = np.ones(6)
    for k in range(order):
        factor *= np.arange(6) - k
    u = np.asarray(u, dtype=float)[:, None]
    powers = np.where(exponents >= 0, u ** np.maximum(exponents, 0), 0.0)
    return cast(np.ndarray, (factor * powers) @ _BERNSTEIN_TO_POWER)


class CurveJet(NamedTuple):
    """Position and its arc-length derivatives at M samples, each of shape (M, 3).

    Attributes
    ----------
    position
        p(σ), m.
    tangent
        dp/dσ, unit.
    curvature
        d²p/dσ², the curvature vector, 1/m.
    curvature_derivative
        d³p/dσ³, 1/m².
    """

    position: np.ndarray
    tangent: np.ndarray
    curvature: np.ndarray
    curvature_derivative: np.ndarray


def hermite_offsets(start: CurveJet, end: CurveJet, speed: float) -> np.ndarray:
    """Control points minus P0, shape (6, 3), of the quintic with second-order Hermite ends.

    B'(0) = speed·t0, B''(0) = speed²·k0 and likewise at u = 1, so the curve matches
    position, unit tangent and curvature vector at both ends (G2). The offsets are formed
    without the absolute position, so the end derivatives carry no rounding of it.

    Parameters
    ----------
    start, end
        Position (m), unit tangent and curvature vector (1/m) at the two ends, each of shape
        (1, 3) (``curvature_derivative`` is not used).
    speed
        Parametric speed |dB/du| at both ends, m, > 0: the shape parameter.
    """
    t0, k0 = start.tangent[0], start.curvature[0]
    t1, k1 = end.tangent[0], end.curvature[0]
    chord = end.position[0] - start.position[0]
    # B'(0) = 5 (P1 - P0) and B''(0) = 20 (P2 - 2 P1 + P0), mirrored at u = 1.
    v, a = speed / 5.0, speed**2 / 20.0
    zero = np.zeros(3)
    return np.array(
        [zero, v * t0, 2 * v * t0 + a * k0, chord - 2 * v * t1 + a * k1, chord - v * t1, chord]
    )


def unit(vector: np.ndarray) -> np.ndarray:
    """``vector`` (..., 3) divided by its norm along the last axis."""
    return cast(np.ndarray, vector / np.linalg.norm(vector, axis=-1, keepdims=True))


def turning_angle(t_in: np.ndarray, t_out: np.ndarray) -> float:
    """Angle between unit tangents ``t_in`` (3,) and ``t_out`` (3,), rad, in [0, π]."""
    return float(np.arctan2(np.linalg.norm(np.cross(t_in, t_out)), t_in @ t_out))


def project_onto_lines(
    points: np.ndarray, starts: np.ndarray, directions: np.ndarray, lengths: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """Nearest points of N points on L line segments, all pairs at once.

    Parameters
    ----------
    points
        Shape (N, 3), m.
    starts, directions
        Segment start points (L, 3), m, and unit directions (L, 3).
    lengths
        Segment lengths (L,), m.

    Returns
    -------
    sigma
        Arc length of the nearest point along each segment, shape (N, L), m.
    distance
        Distance to it, shape (N, L), m.
    """
    rel = points[:, None, :] - starts[None, :, :]
    sigma = np.clip(np.einsum("nlk,lk->nl", rel, directions), 0.0, lengths)
    distance = np.linalg.norm(rel - sigma[..., None] * directions, axis=-1)
    return sigma, distance


def project_onto_arcs(
    points: np.ndarray,
    centers: np.ndarray,
    radii: np.ndarray,
    axes: np.ndarray,
    e1: np.ndarray,
    angles: np.ndarray,
) -> tuple[np.ndarray, np.ndarray]:
    """Nearest points of N points on A circular arcs, all pairs at once.

    An arc is ``c + r (cos φ e1 + sin φ e2)``, ``e2 = axis × e1``, φ ∈ [0, angle]. For an arc
    of more than one turn the first turn is reported (the distance is the same).

    Parameters
    ----------
    points
        Shape (N, 3), m.
    centers, radii
        Shape (A, 3) and (A,), m.
    axes, e1
        Unit normals of the arcs' planes and unit vectors from the centres to the start
        points, each of shape (A, 3).
    angles
        Turning angles (A,), rad, > 0.

    Returns
    -------
    sigma
        Arc length of the nearest point along each arc, shape (N, A), m.
    distance
        Distance to it, shape (N, A), m.
    """
    e2 = np.cross(axes, e1)
    rel = points[:, None, :] - centers[None, :, :]
    x = np.einsum("nak,ak->na", rel, e1)
    y = np.einsum("nak,ak->na", rel, e2)
    z = np.einsum("nak,ak->na", rel, axes)
    phi = np.mod(np.arctan2(y, x), 2.0 * np.pi)
    inside = phi <= angles
    d_inside = np.hypot(z, np.hypot(x, y) - radii)
    cos_end, sin_end = np.cos(angles)[:, None], np.sin(angles)[:, None]
    start = centers + radii[:, None] * e1
    end = centers + radii[:, None] * (cos_end * e1 + sin_end * e2)
    d_start = np.linalg.norm(points[:, None, :] - start[None], axis=-1)
    d_end = np.linalg.norm(points[:, None, :] - end[None], axis=-1)
    at_end = d_end < d_start
    sigma = np.where(inside, phi, np.where(at_end, angles, 0.0)) * radii
    distance = np.where(inside, d_inside, np.minimum(d_start, d_end))
    return sigma, distance


@dataclass(frozen=True, eq=False)
class Line:
    """A straight segment ``start + σ direction``, σ ∈ [0, length].

    Attributes
    ----------
    start
        Shape (3,), m.
    direction
        Unit vector (3,).
    length
        m, > 0.
    """

    start: np.ndarray
    direction: np.ndarray
    length: float
    kind: ClassVar[str] = "line"
    straight: ClassVar[bool] = True

    @classmethod
    def between(cls, a: np.ndarray, b: np.ndarray) -> Line:
        """The segment from ``a`` (3,) to ``b`` (3,), m; they must differ."""
        a = np.asarray(a, dtype=float)
        chord = np.asarray(b, dtype=float) - a
        length = float(np.linalg.norm(chord))
        return cls(a, chord / length, length)

    @property
    def end(self) -> np.ndarray:
        """End point (3,), m."""
        return self.start + self.length * self.direction

    def evaluate(self, sigma: np.ndarray) -> CurveJet:
        """Position and derivatives at arc lengths ``sigma`` (M,), m."""
        sigma = np.asarray(sigma, dtype=float)
        zero = np.zeros((sigma.size, 3))
        position = self.start + sigma[:, None] * self.direction
        return CurveJet(position, np.broadcast_to(self.direction, zero.shape).copy(), zero, zero)

    def point_tangent(self, sigma: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Position (M, 3), m, and unit tangent (M, 3, read-only) at ``sigma`` (M,), m:
        those of :meth:`evaluate`."""
        sigma = np.asarray(sigma, dtype=float)
        position = self.start + sigma[:, None] * self.direction
        return position, np.broadcast_to(self.direction, position.shape)

    def trimmed(self, head: float, tail: float) -> Line:
        """The part from σ = ``head`` to σ = length − ``tail`` (m), non-empty."""
        return Line(
            self.start + head * self.direction, self.direction, float(self.length - head - tail)
        )

    def project(self, points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Arc length (N,) of the nearest point of ``points`` (N, 3) and distance (N,), m."""
        sigma, distance = project_onto_lines(
            np.asarray(points, dtype=float),
            self.start[None],
            self.direction[None],
            np.array([self.length]),
        )
        return sigma[:, 0], distance[:, 0]


@dataclass(frozen=True, eq=False)
class Arc:
    """A circular arc ``center + radius (cos φ e1 + sin φ e2)``, φ = σ / radius ∈ [0, angle].

    The arc turns right-handedly about ``axis``; ``e2 = axis × e1`` (computed) is the start
    tangent.

    Attributes
    ----------
    center
        Shape (3,), m.
    radius
        m, > 0.
    axis
        Unit normal of the arc's plane (3,).
    e1
        Unit vector from the centre to the start point (3,).
    angle
        Turning angle, rad, > 0 (may exceed 2π).
    """

    center: np.ndarray
    radius: float
    axis: np.ndarray
    e1: np.ndarray
    angle: float
    e2: np.ndarray = field(init=False, repr=False)
    kind: ClassVar[str] = "arc"
    straight: ClassVar[bool] = False

    def __post_init__(self) -> None:
        object.__setattr__(self, "e2", np.cross(self.axis, self.e1))

    @classmethod
    def from_rotation(
        cls, start: np.ndarray, center: np.ndarray, normal: np.ndarray, angle: float
    ) -> Arc:
        """The path of ``start`` rotated right-handedly by ``angle`` about ``normal``.

        The rotation axis passes through ``center``; a start point off the plane through
        ``center`` normal to the axis rotates on a circle in a parallel plane.

        Parameters
        ----------
        start, center
            Shape (3,), m.
        normal
            Rotation axis (3,), non-zero.
        angle
            rad, non-zero; a negative angle turns about ``-normal``.
        """
        axis = unit(np.asarray(normal, dtype=float))
        if angle < 0.0:
            axis, angle = -axis, -angle
        rel = np.asarray(start, dtype=float) - np.asarray(center, dtype=float)
        offset = float(rel @ axis)
        radial = rel - offset * axis
        radius = float(np.linalg.norm(radial))
        return cls(center + offset * axis, radius, axis, radial / radius, float(angle))

    @classmethod
    def from_tangent(cls, start: np.ndarray, tangent: np.ndarray, end: np.ndarray) -> Arc | Line:
        """The arc leaving ``start`` (3,) along unit ``tangent`` (3,) and ending at ``end`` (3,).

        Returns the chord as a :class:`Line` when the arc would turn less than
        :data:`STRAIGHT_ANGLE`. The tangent must not point away from ``end`` by π or more.
        """
        chord = end - start
        length = float(np.linalg.norm(chord))
        along = float(chord @ tangent)
        inward = chord - along * tangent
        across = float(np.linalg.norm(inward))
        half_turn = float(np.arctan2(across, along))
        if 2.0 * half_turn < STRAIGHT_ANGLE:
            return Line.between(start, end)
        radius = length / (2.0 * np.sin(half_turn))
        inward = inward / across
        return cls(
            start + radius * inward, radius, np.cross(tangent, inward), -inward, 2 * half_turn
        )

    @classmethod
    def through(cls, a: np.ndarray, b: np.ndarray, c: np.ndarray) -> Arc | Line:
        """The arc from ``a`` through ``b`` to ``c`` (each (3,), m).

        Returns the line from ``a`` to ``c`` when the three points are collinear to within
        :data:`STRAIGHT_ANGLE` (then ``b`` is not checked to lie between them).
        """
        u, v = b - a, c - a
        w = np.cross(u, v)
        w2 = float(w @ w)
        if np.sqrt(w2) <= 0.25 * STRAIGHT_ANGLE * float(np.linalg.norm(u) * np.linalg.norm(v)):
            return Line.between(a, c)
        center = a + (float(u @ u) * np.cross(v, w) + float(v @ v) * np.cross(w, u)) / (2.0 * w2)
        radius = float(np.linalg.norm(a - center))
        axis = w / np.sqrt(w2)
        e1 = (a - center) / radius
        rel = c - center
        angle = np.mod(np.arctan2(rel @ np.cross(axis, e1), rel @ e1), 2.0 * np.pi)
        return cls(center, radius, axis, e1, float(angle))

    @property
    def length(self) -> float:
        """Arc length, m."""
        return self.radius * self.angle

    @property
    def start(self) -> np.ndarray:
        """Start point (3,), m."""
        return self.center + self.radius * self.e1

    @property
    def end(self) -> np.ndarray:
        """End point (3,), m."""
        return cast(np.ndarray, self.evaluate(np.array([self.length])).position[0])

    def evaluate(self, sigma: np.ndarray) -> CurveJet:
        """Position and derivatives at arc lengths ``sigma`` (M,), m."""
        phi = np.asarray(sigma, dtype=float)[:, None] / self.radius
        radial = np.cos(phi) * self.e1 + np.sin(phi) * self.e2
        tangent = np.cos(phi) * self.e2 - np.sin(phi) * self.e1
        return CurveJet(
            self.center + self.radius * radial,
            tangent,
            -radial / self.radius,
            -tangent / self.radius**2,
        )

    def point_tangent(self, sigma: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Position (M, 3), m, and unit tangent (M, 3) at ``sigma`` (M,), m: those of
        :meth:`evaluate`."""
        phi = np.asarray(sigma, dtype=float)[:, None] / self.radius
        cos, sin = np.cos(phi), np.sin(phi)
        radial = cos * self.e1 + sin * self.e2
        return self.center + self.radius * radial, cos * self.e2 - sin * self.e1

    def trimmed(self, head: float, tail: float) -> Arc:
        """The part from σ = ``head`` to σ = length − ``tail`` (m), non-empty."""
        phi = head / self.radius
        e1 = np.cos(phi) * self.e1 + np.sin(phi) * self.e2
        angle = float(self.angle - phi - tail / self.radius)
        return Arc(self.center, self.radius, self.axis, e1, angle)

    def project(self, points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Arc length (N,) of the nearest point of ``points`` (N, 3) and distance (N,), m."""
        sigma, distance = project_onto_arcs(
            np.asarray(points, dtype=float),
            self.center[None],
            np.array([self.radius]),
            self.axis[None],
            self.e1[None],
            np.array([self.angle]),
        )
        return sigma[:, 0], distance[:, 0]


@dataclass(frozen=True, eq=False)
class QuinticBlend:
    """A quintic Bézier curve parametrised by arc length.

    Built from second-order Hermite data at both ends (:meth:`from_hermite`), it matches
    position, unit tangent and curvature vector of the curves it joins (G2).

    Attributes
    ----------
    origin
        P0, shape (3,), m.
    offsets
        Control points minus P0, shape (6, 3), m (the first row is zero).
    length
        Arc length, m (computed).
    """

    origin: np.ndarray
    offsets: np.ndarray
    length: float = field(init=False)
    _coefficients: np.ndarray = field(init=False, repr=False)
    _speed_squared: np.ndarray = field(init=False, repr=False)
    _breaks: np.ndarray = field(init=False, repr=False)
    _cumulative: np.ndarray = field(init=False, repr=False)
    kind: ClassVar[str] = "blend"
    straight: ClassVar[bool] = False

    def __post_init__(self) -> None:
        # Power-basis coefficients of B(u) - P0: small numbers, no rounding of P0 in them.
        coefficients = _BERNSTEIN_TO_POWER @ np.asarray(self.offsets, dtype=float)
        object.__setattr__(self, "_coefficients", coefficients)
        # |B'(u)|² is a scalar polynomial of degree 8: far cheaper to integrate than B'.
        first = coefficients[1:] * np.arange(1, 6)[:, None]
        speed_squared = sum(np.convolve(first[:, k], first[:, k]) for k in range(3))
        object.__setattr__(self, "_speed_squared", speed_squared)
        # Panels in u, refined until the arc length no longer changes at rounding level.
        n_panels = 16
        breaks, cumulative = self._panel_table(n_panels)
        while n_panels < 1024:
            finer_breaks, finer = self._panel_table(2 * n_panels)
            converged = abs(finer[-1] - cumulative[-1]) <= 1e-15 * finer[-1]
            breaks, cumulative, n_panels = finer_breaks, finer, 2 * n_panels
            if converged:
                break
        object.__setattr__(self, "_breaks", breaks)
        object.__setattr__(self, "_cumulative", cumulative)
        object.__setattr__(self, "length", float(cumulative[-1]))

    @classmethod
    def from_hermite(
        cls,
        start: CurveJet,
        end: CurveJet,
        speed: float,
    ) -> QuinticBlend:
        """The quintic with B'(0) = speed·t0, B''(0) = speed²·k0 and likewise at u = 1.

        Parameters
        ----------
        start, end
            Position, unit tangent and curvature vector at the two ends, each array of
            shape (1, 3) (``curvature_derivative`` is not used).
        speed
            Parametric speed |dB/du| at both ends, m, > 0: the shape parameter.
        """
        return cls(start.position[0], hermite_offsets(start, end, speed))

    def derivatives(self, u: np.ndarray, order: int = 3) -> list[np.ndarray]:
        """B(u) and its u-derivatives up to ``order`` at parameters ``u`` (M,), each (M, 3)."""
        u = np.asarray(u, dtype=float)
        out = []
        coefficients = self._coefficients
        degrees = np.arange(6)
        for k in range(order + 1):
            n = 6 - k
            powers = u[:, None] ** np.arange(n)
            value = powers @ coefficients
            out.append(value + self.origin if k == 0 else value)
            coefficients = coefficients[1:] * degrees[1:n, None]
            degrees = degrees[:-1]
        return out

    @property
    def control(self) -> np.ndarray:
        """Control points P0 … P5, shape (6, 3), m."""
        return cast(np.ndarray, self.origin + self.offsets)

    @property
    def start(self) -> np.ndarray:
        """Start point P0 (3,), m."""
        return self.origin

    @property
    def end(self) -> np.ndarray:
        """End point P5 (3,), m."""
        return cast(np.ndarray, self.origin + self.offsets[-1])

    def speed(self, u: np.ndarray) -> np.ndarray:
        """Parametric speed |dB/du| at ``u`` (M,), m."""
        u = np.asarray(u, dtype=float)
        return cast(np.ndarray, np.sqrt(np.polynomial.polynomial.polyval(u, self._speed_squared)))

    def _panel_table(self, n_panels: int) -> tuple[np.ndarray, np.ndarray]:
        breaks = np.linspace(0.0, 1.0, n_panels + 1)
        nodes = breaks[:-1, None] + (0.5 / n_panels) * (_GAUSS_NODES + 1.0)
        panel = (0.5 / n_panels) * (self.speed(nodes.ravel()).reshape(nodes.shape) @ _GAUSS_WEIGHTS)
        return breaks, np.concatenate([[0.0], np.cumsum(panel)])

    def arc_length(self, u: np.ndarray) -> np.ndarray:
        """Arc length S(u) from u = 0, shape (M,), m, for ``u`` (M,) in [0, 1]."""
        u = np.asarray(u, dtype=float)
        n_panels = self._breaks.size - 1
        panel = np.minimum((u * n_panels).astype(int), n_panels - 1)
        lower = self._breaks[panel]
        half = 0.5 * (u - lower)
        nodes = lower[:, None] + half[:, None] * (_GAUSS_NODES + 1.0)
        partial = half * (self.speed(nodes.ravel()).reshape(nodes.shape) @ _GAUSS_WEIGHTS)
        return cast(np.ndarray, self._cumulative[panel] + partial)

    def parameter(self, sigma: np.ndarray) -> np.ndarray:
        """Curve parameter u (M,) at arc lengths ``sigma`` (M,), m, to machine precision.

        Each point starts from the cubic Hermite interpolant of u(S) on the panel table
        (du/dS = 1/speed) and takes Newton steps until one is below 1e-9, the next one
        landing at rounding level: one compiled pass
        (:func:`~trackplan.paths._kernels.blend_parameter`).
        """
        sigma = np.ascontiguousarray(sigma, dtype=float).ravel()
        return blend_parameter(
            sigma, self._breaks, self._cumulative, self._speed_squared, _GAUSS_NODES, _GAUSS_WEIGHTS
        )

    def evaluate(self, sigma: np.ndarray) -> CurveJet:
        """Position and arc-length derivatives at ``sigma`` (M,), m."""
        b0, b1, b2, b3 = self.derivatives(self.parameter(sigma))
        v = np.linalg.norm(b1, axis=-1)[:, None]
        ab = np.sum(b1 * b2, axis=-1)[:, None]
        dv = ab / v
        curvature = b2 / v**2 - ab * b1 / v**4
        d_ab = (np.sum(b2 * b2, axis=-1) + np.sum(b1 * b3, axis=-1))[:, None]
        d_curvature = (
            b3 / v**2
            - 2.0 * b2 * dv / v**3
            - (d_ab * b1 + ab * b2) / v**4
            + 4.0 * ab * b1 * dv / v**5
        )
        return CurveJet(b0, b1 / v, curvature, d_curvature / v)

    def point_tangent(self, sigma: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Position (M, 3), m, and unit tangent (M, 3) at ``sigma`` (M,), m: those of
        :meth:`evaluate`, without its curvature terms."""
        b0, b1 = self.derivatives(self.parameter(sigma), order=1)
        return b0, b1 / np.linalg.norm(b1, axis=-1)[:, None]


#: A primitive of the user's path or of a fit.
Primitive = Line | Arc

Curve = Line | Arc | QuinticBlend


def start_jet(curve: Curve) -> CurveJet:
    """Position and derivatives of ``curve`` at its start, each of shape (1, 3)."""
    return curve.evaluate(np.zeros(1))


def end_jet(curve: Curve) -> CurveJet:
    """Position and derivatives of ``curve`` at its end, each of shape (1, 3)."""
    return curve.evaluate(np.array([curve.length]))


def unwrap_closed_arc(sigma: np.ndarray, period: float, length: float) -> np.ndarray:
    """Arc lengths on a closed (≥ 2π) arc made continuous along a sequence of samples.

    A projection reports the first turn, so where the samples pass the arc's start again
    their arc length wraps from ``period`` back to 0; unwrapping restores it, and the
    sequence begins on the first turn (the start and the end of a full circle are one point).

    Parameters
    ----------
    sigma
        Arc lengths of samples in time order, shape (M,), m.
    period
        2π · radius, m.
    length
        The arc's length, m (the result is clipped to [0, length]).

    Returns
    -------
    numpy.ndarray
        Shape (M,), m.
    """
    if len(sigma) == 0:
        return sigma
    values = np.unwrap(sigma, period=period)
    values -= period * np.round(values.min() / period)
    return np.clip(values, 0.0, length)
