"""The external axes' motion along one seam: one smooth profile per axis over s."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from trackplan.profiles import Profile


@dataclass(frozen=True, eq=False)
class AxesProfile:
    """The track and positioner positions along a seam, as functions of the planned path's
    arc length s.

    Attributes
    ----------
    profiles
        One :class:`~trackplan.profiles.Profile` per external axis, in the machine's order
        (track, then the positioner's axes); m for the track, rad for the positioner.
    """

    profiles: tuple[Profile, ...]

    @property
    def n_axes(self) -> int:
        """Number of external axes."""
        return len(self.profiles)

    def values(self, s: np.ndarray) -> np.ndarray:
        """Positions at arc lengths ``s`` (M,), shape (M, n_axes), m or rad."""
        s = np.asarray(s, dtype=float)
        if not self.profiles:
            return np.zeros((s.size, 0))
        return np.stack([profile.value(s) for profile in self.profiles], axis=-1)

    def derivative(self, s: np.ndarray, order: int) -> np.ndarray:
        """d^order/ds^order of the positions at ``s`` (M,), shape (M, n_axes)."""
        s = np.asarray(s, dtype=float)
        if not self.profiles:
            return np.zeros((s.size, 0))
        return np.stack([profile.derivative(s, order) for profile in self.profiles], axis=-1)

    def as_dict(self) -> dict[str, object]:
        """The profiles as result.json writes them."""
        return {"profiles": [profile.as_dict() for profile in self.profiles]}
