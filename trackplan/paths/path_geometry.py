"""The case's path, built once: the nominal path, the planned path and its zones.

Every placement of a case shares one :class:`PathGeometry`; a time law states which planned
path it needs (G2 blends, or the paper's tangent arcs). The path is built from anything that
has a start, segments and a task with a tolerance (:class:`PathSource`, which a case and each
of its seams satisfy), so this module imports nothing above :mod:`trackplan.paths`.
"""

from __future__ import annotations

import itertools
from collections.abc import Sequence
from dataclasses import dataclass
from functools import cached_property
from typing import Literal, Protocol

import numpy as np

from trackplan.errors import CaseError
from trackplan.paths.nominal import NominalPath
from trackplan.paths.planned import Path, build_path
from trackplan.paths.specs import SegmentSpec

GEOMETRIC_STEP = 2e-3
"""Arc-length step of the planning grid on straight zones, m."""
CURVED_GRID_POINTS = 80
"""Grid intervals on each curved zone at least (blends change their derivatives fast)."""
MAX_ZONE_POINTS = 2000
"""Grid intervals on one straight zone at most (a long line needs no finer grid), unless a
weave needs more."""
WEAVE_GRID_POINTS = 48
"""Grid intervals per weave period λ at least: the time law sees the weave's joint
accelerations and jerks on the grid (a triangle's turn-around spans 10 of them)."""

PathMode = Literal["g2", "paper"]
"""``g2``: curvature-continuous blends; ``paper``: the paper's tangent arcs (Eq. 10)."""


class Toleranced(Protocol):
    """A task that states how far the planned path may leave the nominal one."""

    @property
    def tolerance(self) -> float:
        """ρ, the largest distance of the planned path from the nominal one, m."""
        ...


class Oscillation(Protocol):
    """A lateral oscillation laid over arc length (:class:`trackplan.tool.weave.WeaveTrack`)."""

    @property
    def wavelength(self) -> float:
        """λ, its spatial period, m."""
        ...

    @property
    def amplitude(self) -> float:
        """Its largest offset to either side, m."""
        ...

    def offset(self, s: np.ndarray) -> np.ndarray:
        """The lateral offset at arc lengths ``s`` (M,), m, shape (M,)."""
        ...


class PathSource(Protocol):
    """What :meth:`PathGeometry.from_case` reads: a case, or one seam of it."""

    @property
    def start(self) -> np.ndarray:
        """First point of the path, shape (3,), m."""
        ...

    @property
    def segments(self) -> Sequence[SegmentSpec]:
        """The path segments, in order."""
        ...

    @property
    def task(self) -> Toleranced:
        """The task (its :attr:`Toleranced.tolerance`)."""
        ...


@dataclass(frozen=True, eq=False)
class PathGeometry:
    """The case's path, built once and shared by every placement.

    Attributes
    ----------
    nominal
        The path as the user gave it.
    planned
        The path the tool follows (blended corners).
    mode
        How corners are rounded.
    weave
        The weave the tool point adds across the planned path (``task.weave`` at the
        rated speed), or None; the planning grid resolves it.
    """

    nominal: NominalPath
    planned: Path

    mode: PathMode = "g2"
    weave: Oscillation | None = None

    @classmethod
    def build(
        cls,
        start: np.ndarray,
        segments: Sequence[SegmentSpec],
        tolerance: float,
        mode: PathMode = "g2",
        weave: Oscillation | None = None,
    ) -> PathGeometry:
        """Build the nominal and planned paths of a start point and segments.

        Parameters
        ----------
        start
            First point of the path, shape (3,), m.
        segments
            The path segments, in order.
        tolerance
            ρ, the largest distance of the planned path from the nominal one, m, > 0.
        mode
            How corners are rounded; a time law names the mode it needs
            (:attr:`trackplan.timing.TimeLaw.path_mode`).
        weave
            The weave laid over the planned path, or None.

        Raises
        ------
        CaseError
            When the weave's amplitude reaches the radius of a curve of the planned path
            (the woven path would fold on the curve's inner side).
        """
        nominal = NominalPath.from_specs(start, segments)
        geometry = cls(nominal, build_path(nominal, tolerance, mode=mode), mode, weave)
        if weave is not None:
            geometry._check_weave(weave)
        return geometry

    def _check_weave(self, weave: Oscillation) -> None:
        """Refuse a weave at least as wide as the radius of the planned path's tightest
        curve (on the planning grid), in one line."""
        s = np.concatenate(self.zone_grids())
        curvature = np.linalg.norm(self.planned.sample(s).curvature, axis=1)
        worst = int(np.argmax(curvature))
        if weave.amplitude * curvature[worst] < 1.0:
            return
        raise CaseError(
            f"{weave.amplitude:g} m reaches the radius {1.0 / curvature[worst]:.2g} m of the "
            f"planned path's tightest curve at s = {s[worst]:.4g} m: the weave would fold "
            "there; give a smaller amplitude, a larger tolerance (wider corner blends) or "
            "split the seam at the corner",
            key="task.weave.amplitude",
        )

    @classmethod
    def from_case(cls, case: PathSource, mode: PathMode = "g2") -> PathGeometry:
        """Build the nominal and planned paths of a case (see :meth:`build`).

        Parameters
        ----------
        case
            A case or one of its seams: its start, segments and ``task.tolerance``.
        mode
            How corners are rounded.

        A task with a ``weave`` (and a ``rated_speed``) lays it over the planned path
        (:meth:`trackplan.tool.weave.Weave.along`).
        """
        weave = getattr(case.task, "weave", None)
        track = None if weave is None else weave.along(case.task.rated_speed)  # type: ignore[attr-defined]
        return cls.build(case.start, case.segments, case.task.tolerance, mode, track)

    def zones(self) -> list[tuple[float, float, str]]:
        """Zones of the planned path with stops inserted as zero-length zones."""
        zones: list[tuple[float, float, str]] = []
        stops = sorted(float(s) for s in self.planned.stops)
        for s0, s1, kind in self.planned.zones:
            start = float(s0)
            for stop in (s for s in stops if s0 - 1e-12 <= s <= s1 + 1e-12):
                if stop > start + 1e-12:
                    zones.append((start, stop, kind))
                if not zones or zones[-1][2] != "stop":
                    zones.append((stop, stop, "stop"))
                start = stop
            if s1 > start + 1e-12:
                zones.append((start, float(s1), kind))
        return zones

    def on_curved_zone(self, s: np.ndarray) -> np.ndarray:
        """Whether arc lengths ``s`` (M,) lie on an arc or blend (corner speed), shape (M,)."""
        curved = np.zeros(np.shape(s), dtype=bool)
        for s0, s1, kind in self.planned.zones:
            if kind == "curved":
                curved |= (s >= s0) & (s <= s1)
        return curved

    def corner_intervals(self) -> np.ndarray:
        """Nominal arc-length intervals where the corner speed applies, shape (K, 2)."""
        return self._corner_intervals

    @cached_property
    def _corner_intervals(self) -> np.ndarray:
        """:meth:`corner_intervals`, computed once (read-only)."""
        curved = [(s0, s1) for s0, s1, kind in self.planned.zones if kind == "curved"]
        if not curved:
            intervals = np.zeros((0, 2))
        else:
            ends = self.planned.sample(np.asarray(curved).ravel()).position
            s_nominal, _ = self.nominal.project(ends)
            intervals = np.sort(s_nominal.reshape(-1, 2), axis=1)
        intervals.flags.writeable = False
        return intervals

    def zone_grids(self) -> list[np.ndarray]:
        """The planning grid of each zone of :meth:`zones`, in order.

        Straight zones get a step of about :data:`GEOMETRIC_STEP` (at most
        :data:`MAX_ZONE_POINTS` intervals), curved ones at least :data:`CURVED_GRID_POINTS`
        intervals; each grid holds both ends of its zone, so a boundary appears in the
        grids of both zones it separates. A stop is one point. With a weave, every zone's
        step is at most λ / :data:`WEAVE_GRID_POINTS` (no cap on the count).

        Returns
        -------
        list of numpy.ndarray
            One array of arc lengths per zone, shape (G_z,), m.
        """
        grids = []
        for s0, s1, kind in self.zones():
            span = s1 - s0
            if span <= 0.0:
                grids.append(np.array([s0]))
                continue
            n = int(np.ceil(span / GEOMETRIC_STEP))
            if kind == "straight":
                n = int(np.clip(n, 8, MAX_ZONE_POINTS))
            else:
                n = max(n, CURVED_GRID_POINTS)
            if self.weave is not None:
                n = max(n, int(np.ceil(span * WEAVE_GRID_POINTS / self.weave.wavelength)))
            grids.append(np.linspace(s0, s1, n + 1))
        return grids

    def grid(self, step: float = GEOMETRIC_STEP) -> np.ndarray:
        """Arc lengths covering the planned path with every zone boundary, shape (M,)."""
        edges = np.array([z[0] for z in self.planned.zones] + [self.planned.length])
        parts = [
            np.linspace(a, b, max(2, int(np.ceil((b - a) / step)) + 1), endpoint=False)
            for a, b in itertools.pairwise(edges)
            if b > a
        ]
        return np.concatenate([*parts, [self.planned.length]])
