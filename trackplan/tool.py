"""The tool orientation along the path: part or seam frame, work and travel angles, spin.

One mechanism serves every caller (the joint path, the screening of the search, the
checker, the report): a :class:`ToolSpec` says how the tool is held relative to the part
or the seam, a :class:`SpinProfile` says how far it is turned about its own axis at each
arc length, and :meth:`ToolOrientation.rotations` gives ``R_part_tool(s)``.

Conventions (``docs/tool.md``):

- seam frame at a path point with unit tangent t and surface normal n (n made
  perpendicular to t): ``x_s = t``, ``z_s = −n``, ``y_s = z_s × x_s``;
- ``frame: seam``: ``R = [x_s y_s z_s] · Rx(work_angle) · Ry(travel_angle) · Rz(spin)``;
- ``frame: part``: ``R = RPY(rpy) · Rz(spin)``;
- the tool axis is the tool's z axis;
- one ``normal`` for the whole path, or ``normals``: one per path segment.

The tangent is the planned path's, so through a blend the orientation turns with the
blend's tangent, which is continuous with its curvature (G2 blends). Per-segment normals
change the same way, across the same windows: where the normal jumps at a junction it is
blended with the smooth step that rounds the tangent (:class:`SeamNormal`). The checker holds
the tool axis to the spec on the nominal path; inside a *transition zone* (a blend, a
corner arc or a fitted curve: a piece of the planned path that is not on the nominal path)
it allows the deviation bound of :func:`trackplan.planning.tool_zones.transition_zones`.
"""

from __future__ import annotations

import enum
import itertools
from dataclasses import dataclass, field

import numpy as np

from trackplan.errors import CaseError
from trackplan.frames import rpy_matrix
from trackplan.paths.nominal import NominalPath
from trackplan.paths.path_geometry import PathGeometry
from trackplan.paths.pieces import Piece

SPIN_COEFFICIENTS = 6
"""B-spline coefficients of a ``free-varying`` spin profile (clamped cubic, uniform knots)."""
SPIN_DEGREE = 3
"""Degree of the spin profile."""
DEFAULT_SPIN_RATE = 20.0
"""Largest |d spin / ds| of a ``free-varying`` profile when the case gives none, rad/m."""
MIN_NORMAL_LENGTH = 1e-6
"""Shortest surface normal accepted (any length is normalised): a shorter one is refused as
zero, well above where its squared length underflows."""
PARALLEL_SINE = 1e-3
"""A normal whose component across the tangent is below this share of its length is parallel."""
ZONE_STEP = 1e-3
"""Arc-length step on which the seam frame is checked for a normal along the path, m."""
SEAM_SMOOTHING = 5e-3
"""Half-width of the window in which the seam tangent is rounded at a junction, m."""


class ToolFrame(enum.StrEnum):
    """What the tool orientation is given relative to."""

    PART = "part"
    SEAM = "seam"


class SpinMode(enum.StrEnum):
    """How the spin about the tool axis is chosen."""

    FIXED = "fixed"
    FREE = "free"
    FREE_VARYING = "free-varying"


def rotation_z(angle: np.ndarray) -> np.ndarray:
    """Rotations about z by ``angle`` (...,), rad, shape (..., 3, 3)."""
    angle = np.asarray(angle, dtype=float)
    c, s = np.cos(angle), np.sin(angle)
    R = np.zeros((*angle.shape, 3, 3))
    R[..., 0, 0] = c
    R[..., 0, 1] = -s
    R[..., 1, 0] = s
    R[..., 1, 1] = c
    R[..., 2, 2] = 1.0
    return R


def spun(R: np.ndarray, angle: np.ndarray) -> np.ndarray:
    """``R @ rotation_z(angle)`` for rotations R (..., 3, 3) and angles (...,), rad.

    Elementwise: the columns ``(c x + s y, c y − s x, z)`` of each R = (x, y, z), without
    a small matrix product per rotation.
    """
    angle = np.asarray(angle, dtype=float)
    c, s = np.cos(angle)[..., None], np.sin(angle)[..., None]
    x, y = R[..., 0], R[..., 1]
    out = np.empty(np.broadcast_shapes(R.shape, (*angle.shape, 3, 3)))
    out[..., 0] = x * c + y * s
    out[..., 1] = y * c - x * s
    out[..., 2] = R[..., 2]
    return out


def rotation_angle(R_a: np.ndarray, R_b: np.ndarray) -> np.ndarray:
    """Angle of ``R_aᵀ R_b`` for rotations (..., 3, 3), shape (...,), rad."""
    trace = np.einsum("...ji,...ji->...", R_a, R_b)
    return np.arccos(np.clip((trace - 1.0) / 2.0, -1.0, 1.0))


@dataclass(frozen=True, eq=False)
class SpinProfile:
    """Spin about the tool axis along the planned path, rad.

    One coefficient: a constant spin. More: a clamped cubic B-spline on uniform knots over
    [0, length]; by the convex-hull property the spin stays between the smallest and the
    largest coefficient and its rate below :attr:`max_rate`.

    Attributes
    ----------
    coefficients
        Shape (k,), rad.
    length
        Length of the planned path the profile spans, m.
    """

    coefficients: np.ndarray
    length: float

    @classmethod
    def constant(cls, value: float, length: float) -> SpinProfile:
        """A constant spin ``value`` (rad)."""
        return cls(np.array([float(value)]), float(length))

    @property
    def knots(self) -> np.ndarray:
        """Knot vector in s, shape (k + 4,), m (empty for a constant)."""
        return spin_knots(len(self.coefficients), self.length)

    @property
    def max_rate(self) -> float:
        """Bound of |d spin / ds| from the coefficients (convex hull), rad/m."""
        if len(self.coefficients) == 1:
            return 0.0
        return float(
            np.max(
                np.abs(np.diff(self.coefficients))
                / increment_spans(len(self.coefficients), self.length)
            )
        )

    def value(self, s: np.ndarray) -> np.ndarray:
        """Spin at arc lengths ``s`` (M,), shape (M,), rad."""
        return spin_values(self.coefficients[None], s, self.length)[0]

    def rate(self, s: np.ndarray) -> np.ndarray:
        """d spin / ds at arc lengths ``s`` (M,), shape (M,), rad/m."""
        s = np.asarray(s, dtype=float)
        if len(self.coefficients) == 1:
            return np.zeros(s.shape)
        from scipy.interpolate import BSpline  # only spin profiles need scipy

        spline = BSpline(self.knots, self.coefficients, SPIN_DEGREE, extrapolate=False)
        return np.nan_to_num(spline.derivative()(np.clip(s, 0.0, self.length)))

    def as_dict(self) -> dict[str, object]:
        """``{value}`` or ``{knots, coefficients}`` for result files (rad, m)."""
        if len(self.coefficients) == 1:
            return {"value": float(self.coefficients[0])}
        return {
            "knots": self.knots.tolist(),
            "coefficients": self.coefficients.tolist(),
            "degree": SPIN_DEGREE,
        }


def spin_knots(n_coefficients: int, length: float) -> np.ndarray:
    """Clamped uniform knot vector of a cubic B-spline on [0, length], shape (k + 4,), m."""
    if n_coefficients == 1:
        return np.zeros(0)
    inner = np.linspace(0.0, length, n_coefficients - SPIN_DEGREE + 1)
    return np.concatenate([[0.0] * SPIN_DEGREE, inner, [length] * SPIN_DEGREE])


def increment_spans(n_coefficients: int, length: float) -> np.ndarray:
    """``(t_{i+4} − t_{i+1}) / 3`` of a profile's knots, shape (k − 1,), m.

    ``|c_{i+1} − c_i| ≤ rate · span_i`` for every i bounds the profile's |d spin / ds| by rate.
    """
    t = spin_knots(n_coefficients, length)
    i = np.arange(n_coefficients - 1)
    return (t[i + SPIN_DEGREE + 1] - t[i + 1]) / SPIN_DEGREE


def spin_values(coefficients: np.ndarray, s: np.ndarray, length: float) -> np.ndarray:
    """Spins of B profiles at arc lengths ``s``.

    Parameters
    ----------
    coefficients
        Shape (B, k), rad (k = 1: constant spins).
    s
        Arc lengths, shape (M,), m.
    length
        Length of the planned path, m.

    Returns
    -------
    numpy.ndarray
        Shape (B, M), rad.
    """
    coefficients = np.atleast_2d(np.asarray(coefficients, dtype=float))
    s = np.asarray(s, dtype=float)
    if coefficients.shape[1] == 1:
        return np.broadcast_to(coefficients, (len(coefficients), s.size)).copy()
    from scipy.interpolate import BSpline  # only spin profiles need scipy

    knots = spin_knots(coefficients.shape[1], length)
    basis = BSpline.design_matrix(np.clip(s, 0.0, length), knots, SPIN_DEGREE).toarray()
    return coefficients @ basis.T


@dataclass(frozen=True, eq=False)
class ToolSpec:
    """How the tool is held: frame, normal, work and travel angles, spin.

    Attributes
    ----------
    frame
        ``part``: constant ``rpy`` in the part frame; ``seam``: relative to the seam frame.
    rpy
        Roll, pitch, yaw for ``frame: part``, shape (3,), rad.
    normal
        Surface normal in the part frame for ``frame: seam``, shape (3,) (any length > 0).
    normals
        Instead of ``normal``: one surface normal per path segment, shape (S, 3).
    work_angle, travel_angle
        Rotations about the seam's x and y axes, rad (``frame: seam``).
    spin
        ``fixed``, ``free`` (one constant chosen by the search) or ``free-varying`` (a
        profile along s chosen by the search).
    spin_value
        The spin of ``fixed``, rad.
    spin_range
        (lo, hi) of ``free`` and ``free-varying`` spins, rad.
    spin_rate
        Largest |d spin / ds| of ``free-varying``, rad/m.
    """

    frame: ToolFrame = ToolFrame.PART
    rpy: np.ndarray = field(default_factory=lambda: np.zeros(3))
    normal: np.ndarray | None = None
    normals: np.ndarray | None = None
    work_angle: float = 0.0
    travel_angle: float = 0.0
    spin: SpinMode = SpinMode.FIXED
    spin_value: float = 0.0
    spin_range: tuple[float, float] = (-np.pi, np.pi)
    spin_rate: float = DEFAULT_SPIN_RATE

    def __post_init__(self) -> None:
        object.__setattr__(self, "frame", ToolFrame(self.frame))
        object.__setattr__(self, "spin", SpinMode(self.spin))
        object.__setattr__(self, "rpy", np.asarray(self.rpy, dtype=float))
        if self.normal is not None:
            object.__setattr__(self, "normal", np.asarray(self.normal, dtype=float))
        if self.normals is not None:
            normals = np.asarray(self.normals, dtype=float).reshape(-1, 3)
            object.__setattr__(self, "normals", normals)

    @classmethod
    def part(cls, rpy: np.ndarray) -> ToolSpec:
        """The paper's tool: constant ``rpy`` (3,) rad in the part frame, no spin."""
        return cls(frame=ToolFrame.PART, rpy=np.asarray(rpy, dtype=float))

    @property
    def n_spin(self) -> int:
        """Number of spin decision variables: 0, 1 or :data:`SPIN_COEFFICIENTS`."""
        return {SpinMode.FIXED: 0, SpinMode.FREE: 1}.get(self.spin, SPIN_COEFFICIENTS)

    def spin_bounds(self) -> tuple[np.ndarray, np.ndarray]:
        """Box of the spin variables (see :meth:`spin_profiles`), each shape (n_spin,)."""
        lo, hi = self.spin_range
        if self.n_spin <= 1:
            return np.full(self.n_spin, lo), np.full(self.n_spin, hi)
        ones = np.ones(self.n_spin - 1)
        return np.concatenate([[lo], -ones]), np.concatenate([[hi], ones])

    def spin_coefficients(self, variables: np.ndarray, length: float) -> np.ndarray:
        """Profile coefficients of spin variables.

        ``free``: the variable is the spin. ``free-varying``: the first variable is the
        first coefficient and each further one, in [−1, 1], the step to the next
        coefficient as a share of the largest step the rate allows; the running sum is
        clipped to the range, which keeps every step within the rate bound.

        Parameters
        ----------
        variables
            Shape (B, n_spin).
        length
            Length of the planned path, m.

        Returns
        -------
        numpy.ndarray
            Shape (B, k), rad (k = 1 for ``fixed`` and ``free``).
        """
        variables = np.atleast_2d(np.asarray(variables, dtype=float))
        if self.spin is SpinMode.FIXED:
            return np.full((len(variables), 1), self.spin_value)
        if self.spin is SpinMode.FREE:
            return variables[:, :1].copy()
        steps = variables[:, 1:] * self.spin_rate * increment_spans(self.n_spin, length)
        running = [np.clip(variables[:, 0], *self.spin_range)]
        for i in range(1, self.n_spin):  # the clip depends on the clipped predecessor
            running.append(np.clip(running[-1] + steps[:, i - 1], *self.spin_range))
        return np.stack(running, axis=1)

    def spin_variables(self, coefficients: np.ndarray, length: float) -> np.ndarray:
        """Spin variables nearest to the given coefficients (B, k), shape (B, n_spin)."""
        c = np.atleast_2d(np.asarray(coefficients, dtype=float))
        if self.n_spin <= 1:
            return c[:, : self.n_spin].copy()
        spans = self.spin_rate * increment_spans(self.n_spin, length)
        return np.concatenate([c[:, :1], np.clip(np.diff(c, axis=1) / spans, -1, 1)], axis=1)

    def profile(self, variables: np.ndarray | None, length: float) -> SpinProfile:
        """The spin profile of one set of variables (n_spin,); None: the middle of the range."""
        if variables is None:
            variables = self.default_variables()
        coefficients = self.spin_coefficients(np.asarray(variables, dtype=float)[None], length)
        return SpinProfile(coefficients[0], float(length))

    def default_variables(self) -> np.ndarray:
        """Spin variables of a constant spin in the middle of the range, shape (n_spin,)."""
        middle = 0.5 * (self.spin_range[0] + self.spin_range[1])
        if self.n_spin <= 1:
            return np.full(self.n_spin, middle)
        return np.concatenate([[middle], np.zeros(self.n_spin - 1)])

    def segment_normals(self, segment: np.ndarray) -> np.ndarray:
        """Unit surface normals of path segments ``segment`` (M,) (ints), shape (M, 3).

        With one ``normal``, that normal for every segment.
        """
        segment = np.asarray(segment, dtype=int)
        given = self.normals if self.normals is not None else self.normal
        assert given is not None  # frame: seam, checked by the case loader
        unit = np.atleast_2d(given)
        unit = unit / np.linalg.norm(unit, axis=1, keepdims=True)
        return unit[segment] if self.normals is not None else np.repeat(unit, segment.size, 0)

    def base_rotations(self, tangent: np.ndarray, normal: np.ndarray | None = None) -> np.ndarray:
        """``R_part_tool`` at zero spin for unit path tangents (M, 3), shape (M, 3, 3).

        ``normal`` (M, 3): the surface normal at each point (any length > 0); None: the
        spec's one ``normal`` (a spec with per-segment ``normals`` needs them given, see
        :meth:`segment_normals`).
        """
        tangent = np.asarray(tangent, dtype=float)
        if self.frame is ToolFrame.PART:
            return np.broadcast_to(rpy_matrix(self.rpy), (len(tangent), 3, 3)).copy()
        if normal is None:
            if self.normal is None:
                raise ValueError("per-segment normals: give the normal at each point")
            normal = np.broadcast_to(self.normal, tangent.shape)
        n = normal / np.linalg.norm(normal, axis=-1, keepdims=True)
        n_perp = n - np.einsum("mk,mk->m", tangent, n)[:, None] * tangent
        z = -n_perp / np.linalg.norm(n_perp, axis=1, keepdims=True)
        y = np.cross(z, tangent)
        R_seam = np.stack([tangent, y, z], axis=-1)
        return R_seam @ _rotation_x(self.work_angle) @ _rotation_y(self.travel_angle)

    def describe(self) -> dict[str, object]:
        """The spec as plain data (result files, the report)."""
        data: dict[str, object] = {"frame": str(self.frame)}
        if self.frame is ToolFrame.PART:
            data["rpy"] = self.rpy.tolist()
        else:
            if self.normals is not None:
                data["normals"] = self.normals.tolist()
            else:
                data["normal"] = None if self.normal is None else self.normal.tolist()
            data["work_angle"] = self.work_angle
            data["travel_angle"] = self.travel_angle
        data["spin"] = str(self.spin)
        if self.spin is SpinMode.FIXED:
            data["spin_value"] = self.spin_value
        else:
            data["spin_range"] = list(self.spin_range)
        if self.spin is SpinMode.FREE_VARYING:
            data["spin_rate"] = self.spin_rate
        return data


def _rotation_x(angle: float) -> np.ndarray:
    c, s = np.cos(angle), np.sin(angle)
    return np.array([[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]])


def _rotation_y(angle: float) -> np.ndarray:
    c, s = np.cos(angle), np.sin(angle)
    return np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]])


@dataclass(frozen=True, eq=False)
class ToolOrientation:
    """The tool spec with one chosen spin: ``R_part_tool(s)`` along the planned path.

    Attributes
    ----------
    spec
        The case's tool spec.
    spin
        The chosen spin profile over the planned path.
    seam
        The rounded seam tangent (``frame: seam``).
    normals
        The surface normal along the planned path (per-segment ``normals``).
    """

    spec: ToolSpec
    spin: SpinProfile
    seam: SeamTangent | None = None
    normals: SeamNormal | None = None

    @classmethod
    def choose(
        cls,
        spec: ToolSpec,
        geometry: PathGeometry,
        spin: np.ndarray | SpinProfile | None = None,
    ) -> ToolOrientation:
        """The orientation on the planned path of ``geometry`` with a chosen spin.

        Parameters
        ----------
        spec
            The tool spec.
        geometry
            The case's paths.
        spin
            Spin variables (n_spin,) of the spec, or a given profile (its coefficients are
            laid over this planned path), or None for the middle of the spin range.

        Raises
        ------
        CaseError
            When a given profile leaves the spin range or exceeds the spin rate, or the
            spin is fixed.
        """
        length = geometry.planned.length
        seam = SeamTangent.from_geometry(geometry) if spec.frame is ToolFrame.SEAM else None
        normals = None
        if spec.frame is ToolFrame.SEAM and spec.normals is not None:
            normals = SeamNormal.from_geometry(spec, geometry)
        if not isinstance(spin, SpinProfile):
            return cls(spec, spec.profile(spin, length), seam, normals)
        profile = SpinProfile(np.asarray(spin.coefficients, dtype=float), length)
        lo, hi = spec.spin_range
        if spec.spin is SpinMode.FIXED:
            raise CaseError("a spin is given but task.tool.spin is fixed", key="--spin")
        if np.any(profile.coefficients < lo - 1e-12) or np.any(profile.coefficients > hi + 1e-12):
            raise CaseError(
                f"spin {profile.coefficients.tolist()} leaves spin_range [{lo}, {hi}] rad",
                key="--spin",
            )
        if spec.spin is SpinMode.FREE and len(profile.coefficients) != 1:
            raise CaseError("spin: free takes one value, not a profile", key="--spin-profile")
        if profile.max_rate > spec.spin_rate * (1 + 1e-9):
            raise CaseError(
                f"the profile's rate bound {profile.max_rate:.4g} rad/m exceeds spin_rate "
                f"{spec.spin_rate:.4g}",
                key="--spin-profile",
            )
        if len(profile.coefficients) not in (1,) and len(profile.coefficients) <= SPIN_DEGREE:
            raise CaseError(
                f"a profile needs 1 or at least {SPIN_DEGREE + 1} coefficients",
                key="--spin-profile",
            )
        return cls(spec, profile, seam, normals)

    def base_rotations(self, s: np.ndarray, tangent: np.ndarray) -> np.ndarray:
        """``R_part_tool`` at zero spin at arc lengths ``s`` (M,), shape (M, 3, 3).

        ``tangent`` (M, 3) is the planned path's; the seam frame rounds it at the
        junctions (:class:`SeamTangent`) and blends per-segment normals across the same
        windows (:class:`SeamNormal`).
        """
        if self.seam is not None:
            tangent = self.seam(s, tangent)
        normal = None if self.normals is None else self.normals(s)
        return self.spec.base_rotations(tangent, normal)

    def rotations(self, s: np.ndarray, tangent: np.ndarray) -> np.ndarray:
        """``R_part_tool`` at arc lengths ``s`` (M,) with planned tangents (M, 3), (M, 3, 3)."""
        return spun(self.base_rotations(s, tangent), self.spin.value(s))


@dataclass(frozen=True, eq=False)
class SeamTangent:
    """The planned path's tangent, rounded at every junction so that it is C2 in s.

    A G2 blend keeps the tangent's turning rate continuous but not its derivative, so a
    seam frame that followed the tangent exactly would jump in angular acceleration at
    every junction of the planned path and jolt the wrist. Within ``h`` of a junction
    (``h`` the smaller of :data:`SEAM_SMOOTHING` and half of each neighbouring piece) the
    tangent is ``(1 − w) T_a + w T_b`` normalised: ``T_a`` the incoming piece's tangent,
    continued past the junction by its second-order Taylor expansion (tangent, curvature
    vector and its derivative there), ``T_b`` the outgoing one continued backwards, and
    ``w`` the quintic step ``6u⁵ − 15u⁴ + 10u³`` of ``u`` from 0 to 1 across the window
    (zero first and second derivatives at both ends). Outside the windows it is the exact
    tangent. :func:`trackplan.planning.tool_zones.transition_zones` measures the deviation.

    Attributes
    ----------
    geometry
        The case's paths.
    junctions
        Per junction: s (m), h (m), then the incoming and outgoing tangent, curvature vector
        and its derivative there, shape (J, 20).
    """

    geometry: PathGeometry
    junctions: np.ndarray

    @classmethod
    def from_geometry(cls, geometry: PathGeometry) -> SeamTangent:
        """The junctions of the planned path and their windows."""
        pieces = geometry.planned.pieces
        rows = []
        for a, b in itertools.pairwise(pieces):
            h = junction_window(a, b)
            if h <= 0.0:
                continue
            end = a.curve.evaluate(np.array([a.length]))
            start = b.curve.evaluate(np.array([0.0]))
            jets = [end.tangent, end.curvature, end.curvature_derivative]
            jets += [start.tangent, start.curvature, start.curvature_derivative]
            rows.append(np.concatenate([[b.s_start, h], *[j[0] for j in jets]]))
        return cls(geometry, np.array(rows, dtype=float).reshape(-1, 20))

    def __call__(self, s: np.ndarray, tangent: np.ndarray | None = None) -> np.ndarray:
        """Unit tangents at arc lengths ``s`` (M,), shape (M, 3).

        ``tangent`` (M, 3), the planned path's at ``s``, saves sampling the path again.
        """
        s = np.asarray(s, dtype=float)
        exact = self.geometry.planned.sample(s).tangent if tangent is None else tangent
        result = np.array(exact, dtype=float)
        for row in self.junctions:
            s_j, h = row[0], row[1]
            near = np.abs(s - s_j) < h
            if not near.any():
                continue
            d = (s[near] - s_j)[:, None]
            t_a, k_a, dk_a, t_b, k_b, dk_b = row[2:].reshape(6, 3)
            before = d < 0.0
            T_a = np.where(before, exact[near], t_a + k_a * d + 0.5 * dk_a * d**2)
            T_b = np.where(before, t_b + k_b * d + 0.5 * dk_b * d**2, exact[near])
            w = smooth_step((d + h) / (2 * h))
            mixed = (1.0 - w) * T_a + w * T_b
            norm = np.linalg.norm(mixed, axis=1, keepdims=True)
            result[near] = np.where(norm > 1e-9, mixed / np.maximum(norm, 1e-300), exact[near])
        return result


def junction_window(a: Piece, b: Piece) -> float:
    """Half-width h of the window in which the seam frame is rounded at the junction of
    planned pieces a and b: :data:`SEAM_SMOOTHING`, at most half of either piece, m."""
    return min(SEAM_SMOOTHING, 0.5 * a.length, 0.5 * b.length)


def smooth_step(u: np.ndarray) -> np.ndarray:
    """The quintic step ``6u⁵ − 15u⁴ + 10u³`` from 0 to 1 for u in [0, 1] (zero first and
    second derivatives at both ends), shape of u."""
    return u**3 * (10.0 - 15.0 * u + 6.0 * u**2)


@dataclass(frozen=True, eq=False)
class SeamNormal:
    """The surface normal along the planned path for per-segment normals, C2 in s.

    Each planned piece gets the segment of the nominal path its ends lie on (the nearest
    segment whose tangent agrees, never going back along the path). Where the segment
    changes, the normal changes from the one segment's ``n_a`` to the next one's ``n_b``
    as ``(1 − w) n_a + w n_b`` normalised, ``w`` the :func:`smooth_step` across a window:
    the blend piece that joins the two segments widened by the seam tangent's windows at
    its ends (:func:`junction_window`), or ``± h`` around a junction of two pieces. These
    are the windows in which :class:`SeamTangent` rounds the tangent, so a normal jump is
    blended where a tangent jump is, and the normal is exact everywhere else.

    Attributes
    ----------
    starts
        s of each planned piece's start, shape (P,), m.
    piece_normals
        Unit normal of each planned piece outside the windows, shape (P, 3).
    windows
        Per change of the normal: s0, s1 (m), then n_a and n_b, shape (K, 8).
    """

    starts: np.ndarray
    piece_normals: np.ndarray
    windows: np.ndarray

    @classmethod
    def from_geometry(cls, spec: ToolSpec, geometry: PathGeometry) -> SeamNormal:
        """The segments of the planned pieces and the windows where the normal changes."""
        pieces = geometry.planned.pieces
        segment = _piece_segments(geometry)
        unit = spec.segment_normals(segment.ravel()).reshape(-1, 2, 3)
        h = [junction_window(a, b) for a, b in itertools.pairwise(pieces)] + [0.0]
        windows = []
        for k, piece in enumerate(pieces):
            before = h[k - 1] if k > 0 else 0.0
            if segment[k, 0] != segment[k, 1]:  # a blend from one segment into the next
                s0, s1 = piece.s_start - before, piece.s_end + h[k]
                windows.append([s0, s1, *unit[k, 0], *unit[k, 1]])
            if k + 1 < len(pieces) and segment[k, 1] != segment[k + 1, 0]:
                s0, s1 = piece.s_end - h[k], piece.s_end + h[k]
                windows.append([s0, s1, *unit[k, 1], *unit[k + 1, 0]])
        windows = [row for row in windows if row[1] > row[0] and row[2:5] != row[5:8]]
        starts = np.array([piece.s_start for piece in pieces])
        return cls(starts, unit[:, 0].copy(), np.array(windows, dtype=float).reshape(-1, 8))

    def __call__(self, s: np.ndarray) -> np.ndarray:
        """Unit surface normals at arc lengths ``s`` (M,) of the planned path, shape (M, 3)."""
        s = np.asarray(s, dtype=float)
        piece = np.clip(np.searchsorted(self.starts, s, side="right") - 1, 0, len(self.starts) - 1)
        result = self.piece_normals[piece]
        for s0, s1, *ends in self.windows:
            inside = (s > s0) & (s < s1)
            if not inside.any():
                continue
            w = smooth_step((s[inside] - s0) / (s1 - s0))[:, None]
            n_a, n_b = np.reshape(ends, (2, 3))
            mixed = (1.0 - w) * n_a + w * n_b
            result[inside] = mixed / np.linalg.norm(mixed, axis=1, keepdims=True)
        return result


def _piece_segments(geometry: PathGeometry) -> np.ndarray:
    """The nominal segment at the start and at the end of each planned piece, (P, 2) ints.

    A point just inside each end (1 µm, or a quarter of a shorter piece) is assigned the
    nearest nominal piece (within 1e-9 m of the nearest) whose tangent agrees with the
    planned one, and the first such piece at or after the previous assignment, so that a
    path that doubles back on itself keeps its order.
    """
    pieces, nominal = geometry.planned.pieces, geometry.nominal
    inset = np.array(
        [[min(1e-6, 0.25 * p.length), p.length - min(1e-6, 0.25 * p.length)] for p in pieces]
    )
    jets = [piece.curve.evaluate(sigma) for piece, sigma in zip(pieces, inset, strict=True)]
    points = np.concatenate([jet.position for jet in jets])
    tangents = np.concatenate([jet.tangent for jet in jets])
    distance = np.empty((len(points), len(nominal.pieces)))
    agrees = np.empty(distance.shape, dtype=bool)
    for j, curve in enumerate(nominal.curves):
        sigma, distance[:, j] = curve.project(points)
        agrees[:, j] = np.einsum("nk,nk->n", curve.evaluate(sigma).tangent, tangents) > 0.0
    near = distance <= distance.min(axis=1, keepdims=True) + 1e-9
    candidate = near & agrees
    none = ~candidate.any(axis=1)
    candidate[none] = near[none]
    assigned = np.empty(len(points), dtype=int)
    previous = 0
    for i, row in enumerate(candidate):
        later = np.flatnonzero(row[previous:])
        previous = previous + int(later[0]) if later.size else int(np.flatnonzero(row)[0])
        assigned[i] = previous
    return nominal.segment_index[assigned].reshape(-1, 2)


def spin_rotations(base: np.ndarray, spins: np.ndarray) -> np.ndarray:
    """``base · Rz(spin)`` for B spin candidates: base (M, 3, 3), spins (B, M) → (B, M, 3, 3)."""
    return base[None] @ rotation_z(spins)


def tool_axis_twist(rotations: np.ndarray) -> np.ndarray:
    """How far the tool turns about its own axis along a sequence of rotations.

    Parameters
    ----------
    rotations
        ``R_part_tool`` at increasing s, shape (M, 3, 3).

    Returns
    -------
    numpy.ndarray
        Cumulative signed rotation about the tool z axis from the first rotation, shape
        (M,), rad.
    """
    relative = np.einsum("mji,mjk->mik", rotations[:-1], rotations[1:])
    step = np.arctan2(relative[:, 1, 0] - relative[:, 0, 1], relative[:, 0, 0] + relative[:, 1, 1])
    return np.concatenate([[0.0], np.cumsum(step)])


def seam_problems(spec: ToolSpec, nominal: NominalPath) -> list[tuple[int | None, str]]:
    """Why the seam frame is undefined on this path (empty when it is defined).

    Each segment's normal must have a component across the tangent everywhere on the
    segment; checked on every piece at its ends and on a 1 mm grid. Per-segment normals of
    neighbouring segments must not be opposite (their blend would pass through zero).

    Returns
    -------
    list of (int or None, str)
        The index into ``normals`` the problem is about (None for the one ``normal``) and
        the message.
    """
    if spec.frame is not ToolFrame.SEAM:
        return []
    given = spec.normals if spec.normals is not None else spec.normal
    if given is None or not np.all(
        np.linalg.norm(np.atleast_2d(given), axis=1) >= MIN_NORMAL_LENGTH
    ):  # refused by the file's own check
        return []
    table = nominal.table
    s = np.unique(
        np.concatenate(
            [
                np.linspace(0.0, nominal.length, max(2, int(nominal.length / ZONE_STEP))),
                table.s_start,
                table.s_start + table.length - 1e-12,
            ]
        )
    )
    s = np.clip(s, 0.0, nominal.length)
    jet, piece = nominal.evaluate(s)
    segment = nominal.segment_index[piece]
    n = spec.segment_normals(segment)
    tangent = jet.tangent
    across = np.linalg.norm(n - np.einsum("mk,mk->m", tangent, n)[:, None] * tangent, axis=1)
    bad = np.flatnonzero(across < PARALLEL_SINE)
    if len(bad):
        at = bad[0]
        index = None if spec.normals is None else int(segment[at])
        whose = "" if index is None else f" of path.segments[{index}]"
        return [
            (
                index,
                f"the normal {np.round(n[at], 6).tolist()}{whose} is parallel to the path "
                f"tangent at s = {s[at]:.4g} m: the seam frame is undefined there; give a "
                "normal across the path (the surface normal)",
            )
        ]
    if spec.normals is not None:
        unit = spec.segment_normals(np.arange(len(spec.normals)))
        opposite = np.flatnonzero(np.einsum("mk,mk->m", unit[:-1], unit[1:]) < -1.0 + 1e-9)
        if len(opposite):
            i = int(opposite[0])
            return [
                (
                    i + 1,
                    f"the normals of path.segments[{i}] and [{i + 1}] are opposite: the normal "
                    "cannot turn smoothly between them; give the surface normal of each side",
                )
            ]
    return []
