"""The wrist centre of a six-axis arm: where the axes of joints 4 and 5 meet.

The controllers' configuration fields (KUKA Status, ABB cfx, FANUC T/B and U/D) say on
which side of axis 1 and of the lower arm the wrist centre lies; the program writers
compute it here, once.
"""

from __future__ import annotations

import numpy as np

PARALLEL = 1e-12
"""1 − cos² of the angle between axes 4 and 5 below which they count as parallel."""


def wrist_centres(frames: np.ndarray) -> np.ndarray:
    """Wrist centres from axis frames: the midpoint of the common perpendicular of the
    axes of joints 4 and 5 (their intersection on a spherical wrist), or the origin of
    axis 5 where the two are parallel.

    Parameters
    ----------
    frames
        Axis frames of :func:`~trackplan.robots.kinematics.axis_frames`, shape
        (N, n + 2, 4, 4): base, the joints' axis frames (z the axis), flange; n ≥ 5.

    Returns
    -------
    numpy.ndarray
        Shape (N, 3), m, in the frames' base frame.
    """
    p4, d4 = frames[:, 4, :3, 3], frames[:, 4, :3, 2]
    p5, d5 = frames[:, 5, :3, 3], frames[:, 5, :3, 2]
    w = p5 - p4
    cos = np.einsum("ki,ki->k", d4, d5)
    denominator = 1.0 - cos**2
    parallel = denominator < PARALLEL
    safe = np.where(parallel, 1.0, denominator)
    along_4 = (np.einsum("ki,ki->k", w, d4) - cos * np.einsum("ki,ki->k", w, d5)) / safe
    along_5 = (cos * np.einsum("ki,ki->k", w, d4) - np.einsum("ki,ki->k", w, d5)) / safe
    middle = 0.5 * ((p4 + along_4[:, None] * d4) + (p5 + along_5[:, None] * d5))
    centres: np.ndarray = np.where(parallel[:, None], p5, middle)
    return centres


__all__ = ["PARALLEL", "wrist_centres"]
