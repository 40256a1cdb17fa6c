"""The tool orientation with one chosen spin: ``R_part_tool(s)`` along the planned path."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from trackplan.errors import CaseError
from trackplan.paths.path_geometry import PathGeometry
from trackplan.tool.rotations import spun
from trackplan.tool.seam import SeamNormal, SeamTangent
from trackplan.tool.spec import ToolFrame, ToolSpec
from trackplan.tool.spin import SPIN_DEGREE, SpinMode, SpinProfile
from trackplan.tool.weld_normal import declares_normals


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
        The surface normal along the planned path (per-segment ``normals``, or segments
        with their own weld normal).
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
        own = declares_normals(geometry.nominal.segments)
        if spec.frame is ToolFrame.SEAM and (spec.normals is not None or own):
            normals = SeamNormal.from_geometry(spec, geometry)
        if not isinstance(spin, SpinProfile):
            return cls(spec, spec.profile(spin, length), seam, normals)
        profile = SpinProfile(np.asarray(spin.coefficients, dtype=float), length)
        lo, hi = spec.spin_range
        if spec.spin is SpinMode.FIXED:
            raise CaseError("a spin is given but task.tool.spin is fixed", key="--spin")
        if spec.spin_profile.outside_bounds(profile.coefficients):
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
