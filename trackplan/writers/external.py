"""External axes as the controller languages write them: a track in mm, a positioner's
axes in degrees (``docs/export.md``, *External axes*)."""

from __future__ import annotations

import numpy as np

from trackplan.programs.model import ExternalAxis


def language_values(axes: tuple[ExternalAxis, ...], values: np.ndarray) -> np.ndarray:
    """External axis values (SI: m, rad) in the languages' units: mm for a linear axis,
    degrees for a rotary one.

    Parameters
    ----------
    axes
        The program's external axes.
    values
        Their values, shape (e,) or (k, e).

    Returns
    -------
    numpy.ndarray
        The same shape.
    """
    values = np.asarray(values, dtype=float)
    scale = np.array([1000.0 if axis.unit == "m" else 180.0 / np.pi for axis in axes])
    return values * scale if len(axes) else values


def unit_names(axes: tuple[ExternalAxis, ...]) -> tuple[str, ...]:
    """``mm`` or ``deg`` for each axis."""
    return tuple("mm" if axis.unit == "m" else "deg" for axis in axes)


__all__ = ["language_values", "unit_names"]
