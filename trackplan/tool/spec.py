"""How the tool is held: :class:`ToolSpec` (frame, normal, work and travel angles, spin)."""

from __future__ import annotations

import enum
from dataclasses import dataclass, field
from functools import cached_property

import numpy as np

from trackplan.frames import rpy_matrix
from trackplan.profiles import FreeProfile
from trackplan.tool.rotations import rotation_x, rotation_y
from trackplan.tool.spin import (
    DEFAULT_SPIN_RATE,
    SpinMode,
    SpinProfile,
    spin_free_profile,
)

MIN_NORMAL_LENGTH = 1e-6
"""Shortest surface normal accepted (any length is normalised): a shorter one is refused as
zero, well above where its squared length underflows."""


class ToolFrame(enum.StrEnum):
    """What the tool orientation is given relative to."""

    PART = "part"
    SEAM = "seam"


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

    @cached_property
    def spin_profile(self) -> FreeProfile:
        """The spin as a free profile (:func:`trackplan.tool.spin.spin_free_profile`)."""
        return spin_free_profile(self.spin, self.spin_value, self.spin_range, self.spin_rate)

    @property
    def n_spin(self) -> int:
        """Number of spin decision variables: 0, 1 or :data:`SPIN_COEFFICIENTS`."""
        return self.spin_profile.n_variables

    def spin_bounds(self) -> tuple[np.ndarray, np.ndarray]:
        """Box of the spin variables (see :meth:`spin_coefficients`), each shape (n_spin,)."""
        return self.spin_profile.bounds()

    def spin_coefficients(self, variables: np.ndarray, length: float) -> np.ndarray:
        """Profile coefficients of spin variables (:meth:`FreeProfile.coefficients`).

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
        return self.spin_profile.coefficients(variables, length)

    def spin_variables(self, coefficients: np.ndarray, length: float) -> np.ndarray:
        """Spin variables nearest to the given coefficients (B, k), shape (B, n_spin)."""
        return self.spin_profile.variables(coefficients, length)

    def profile(self, variables: np.ndarray | None, length: float) -> SpinProfile:
        """The spin profile of one set of variables (n_spin,); None: the middle of the range."""
        return self.spin_profile.profile(variables, length)

    def default_variables(self) -> np.ndarray:
        """Spin variables of a constant spin in the middle of the range, shape (n_spin,)."""
        return self.spin_profile.default_variables()

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
        R: np.ndarray = R_seam @ rotation_x(self.work_angle) @ rotation_y(self.travel_angle)
        return R

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
