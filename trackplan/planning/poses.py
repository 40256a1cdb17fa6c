"""Tool poses along the path for placed workpieces (Eq. 3 and Eq. 4)."""

from __future__ import annotations

import numpy as np

from trackplan.planning.placement import placement_transform, rpy_matrix


def tool_poses(X: np.ndarray, positions: np.ndarray, tool_rpy: np.ndarray) -> np.ndarray:
    """``T_base_tool = T_X · [R_tool  p; 0 1]`` for every placement and path point.

    Parameters
    ----------
    X
        Placements, shape (B, 6) (or (6,)), metres and radians.
    positions
        Path points in the definition frame, shape (M, 3), m.
    tool_rpy
        Tool orientation in the definition frame, shape (3,), rad.

    Returns
    -------
    numpy.ndarray
        Shape (B, M, 4, 4) (or (M, 4, 4) for a single placement).
    """
    X = np.asarray(X, dtype=float)
    single = X.ndim == 1
    T_base_part = placement_transform(np.atleast_2d(X))  # (B, 4, 4)
    R = T_base_part[:, :3, :3]
    poses = np.empty((len(R), len(positions), 4, 4))
    poses[..., :3, :3] = (R @ rpy_matrix(np.asarray(tool_rpy, dtype=float)))[:, None]
    poses[..., :3, 3] = np.asarray(positions, dtype=float) @ R.transpose(0, 2, 1)
    poses[..., :3, 3] += T_base_part[:, None, :3, 3]
    poses[..., 3, :3] = 0.0
    poses[..., 3, 3] = 1.0
    return poses[0] if single else poses
