"""The checker's tool checks: the tool axis against its spec, the spin's value, range and rate.

Most samples' arccos and arctan2 are spared by screens (:func:`_smallest`,
:func:`_largest_spin_errors`) that keep every sample whose value may be the largest.
"""

from __future__ import annotations

import numpy as np

from trackplan.check_report import Violation
from trackplan.planning.check_reference import TrackingReference
from trackplan.planning.check_violations import RELATIVE_SLACK, met, violation_over
from trackplan.planning.tool_zones import nominal_rotations
from trackplan.tool import SpinMode, ToolFrame


def check_tool(
    ref: TrackingReference,
    x_part: np.ndarray,
    z_part: np.ndarray,
    s_nominal: np.ndarray,
    piece: np.ndarray,
    t: np.ndarray,
    margins: dict[str, float],
) -> tuple[float, list[Violation]]:
    """Tool axis against the spec on the nominal path; spin value, range and rate.

    Outside transition zones the tool axis must match the spec to the orientation
    tolerance; inside, to the tolerance plus the zone's bound. The spin is measured about
    the actual tool axis from the spec's zero-spin frame, outside transition zones.

    Parameters
    ----------
    x_part, z_part
        The tool's x axis and its axis (z) at the samples in the definition frame, shape
        (N, 3) each.

    Returns
    -------
    tuple
        The largest tool axis error, rad, and the violations found.
    """
    nominal, spec, tol = ref.nominal, ref.tool, ref.orientation_tolerance
    if spec.frame is ToolFrame.PART:  # one rotation (3, 3) for the whole path
        R_spec = spec.base_rotations(np.zeros((1, 3)))[0]
    else:
        R_spec = nominal_rotations(spec, nominal, s_nominal, piece)
    axis_cos = np.clip(_along(z_part, R_spec, 2), -1.0, 1.0)
    allowed = np.full(len(t), tol)
    for s0, s1, bound in np.asarray(ref.tool_zones).reshape(-1, 3):
        allowed[(s_nominal >= s0) & (s_nominal <= s1)] += bound
    outside = allowed == tol
    everywhere = bool(outside.all())  # no transition zone: one tolerance, no copies
    found: list[Violation] = []
    if everywhere and tol > 0.0:
        # the largest error over the one tolerance: the arccos of the smallest cosines only
        largest = float(np.arccos(_smallest(axis_cos)).max())
        margins["orientation"] = float(met(1.0 - largest / tol, RELATIVE_SLACK))
    else:
        axis_error = np.arccos(axis_cos)
        largest = float(axis_error.max())
        margins["orientation"] = float(met(1.0 - (axis_error / allowed).max(), RELATIVE_SLACK))
    if margins["orientation"] < 0:
        axis_error = np.arccos(axis_cos)
        found.append(violation_over("orientation", None, t, axis_error, axis_error / allowed, tol))

    if not outside.any():
        return largest, found
    x_along = [_along(x_part, R_spec, j) for j in (0, 1)]
    x_along = x_along if everywhere else [x[outside] for x in x_along]
    t_out, s_out, piece_out = (
        (t, s_nominal, piece) if everywhere else (t[outside], s_nominal[outside], piece[outside])
    )
    if spec.spin is SpinMode.FIXED:
        # the error is taken modulo 2π: only a reported spin needs unwrapping
        rows = _largest_spin_errors(x_along[0], x_along[1], spec.spin_value)
        error = _spin_error(np.arctan2(x_along[1][rows], x_along[0][rows]), spec.spin_value)
        margins["spin"] = float(met(1.0 - error.max() / tol, RELATIVE_SLACK))
        if margins["spin"] < 0:
            spin = np.arctan2(x_along[1], x_along[0])
            error = _spin_error(spin, spec.spin_value)
            unwrapped = np.unwrap(spin)
            found.append(
                violation_over("spin", None, t_out, unwrapped, error / tol, spec.spin_value)
            )
        return largest, found
    spin = np.unwrap(np.arctan2(x_along[1], x_along[0]))
    lo, hi = spec.spin_range
    spin = spin + 2 * np.pi * np.round((0.5 * (lo + hi) - np.median(spin)) / (2 * np.pi))
    excess = np.maximum(lo - spin, spin - hi)
    margins["spin"] = float(met(-excess.max() / max(hi - lo, tol), RELATIVE_SLACK)) + 0.0
    if excess.max() > tol:
        bound = hi if spin.max() > hi else lo
        found.append(violation_over("spin", None, t_out, spin, 1.0 + excess / tol, bound))
    rate_cap = 0.0 if spec.spin is SpinMode.FREE else spec.spin_rate
    ds = np.diff(s_out)
    same = (piece_out[1:] == piece_out[:-1]) & (ds > 0.0)
    step = np.abs(np.diff(spin))[same]
    cap = rate_cap * ds[same] + tol * (1.0 if rate_cap == 0.0 else 1e-6)
    if step.size and np.any(step > cap):
        rate = step / np.maximum(ds[same], 1e-12)
        worst = int(np.argmax(step / cap))
        when = float(t_out[1:][same][worst])
        found.append(
            Violation(
                limit="spin rate",
                joint=None,
                t_first=when,
                t_last=when,
                worst=float(rate[worst]),
                bound=rate_cap,
                message=(
                    f"spin rate {rate[worst]:.4g} rad/m exceeds {rate_cap:.4g} at t = {when:.3f} s"
                ),
            )
        )
    return largest, found


SCREEN_WINDOW = 1e-9
"""Relative width of the screens that spare the checker most of its arccos and arctan2
(:func:`_smallest`, :func:`_largest_spin_errors`): far wider than their round-off, so that
the largest of the screened values is the largest of all, to the bit."""


def _smallest(cosines: np.ndarray) -> np.ndarray:
    """The cosines in [-1, 1] whose arccos may be the largest, shape (K,).

    On [c, 1] with c ≥ 0 arccos falls with a slope of at least 1/√(1 - c²): a cosine more
    than ``1e-3 · SCREEN_WINDOW · (1 - c)`` above the smallest c has an arccos smaller by
    more than a thousand times its round-off, so the largest arccos of all is among these
    few (each evaluated as numpy does). A smallest cosine below 0, or a NaN: all of them.
    """
    low = cosines.min()
    if not low >= 0.0:
        return cosines
    kept: np.ndarray = cosines[cosines <= low + 1e-3 * SCREEN_WINDOW * (1.0 - low)]
    return kept


def _spin_error(spin: np.ndarray, value: float) -> np.ndarray:
    """The distance of each spin (M,) from ``value`` modulo 2π, rad, shape (M,)."""
    turn = spin - value
    return np.abs(turn - 2 * np.pi * np.round(turn / (2 * np.pi)))


def _largest_spin_errors(x_cos: np.ndarray, x_sin: np.ndarray, value: float) -> np.ndarray:
    """Rows whose spin ``arctan2(x_sin, x_cos)`` may be the farthest from ``value``.

    While every spin error θ is under 60°, ``tan θ = |x_sin cos v - x_cos sin v| /
    (x_cos cos v + x_sin sin v)`` ranks them: rows whose tangent is below the largest by more
    than :data:`SCREEN_WINDOW` (relative) have a smaller θ by more than round-off. The
    computed error also carries an absolute round-off of about 1e-15 (|v| + 8) rad (of the
    arctan2 near v and of the turns taken off), zero for v = 0: rows within a thousand times
    that of the largest tangent stay. Otherwise (an error of 60° or more, or a NaN) every
    row.

    Returns
    -------
    numpy.ndarray
        Row indices into the (M,) inputs, shape (K,).
    """
    c, s = np.cos(value), np.sin(value)
    along = x_cos * c + x_sin * s
    if not np.all(along > 0.5 * np.sqrt(x_cos * x_cos + x_sin * x_sin)):
        return np.arange(len(x_cos))
    tangent = np.abs(x_sin * c - x_cos * s) / along
    high = tangent.max()
    if not np.isfinite(high):
        return np.arange(len(x_cos))
    noise = 0.0 if value == 0.0 else 1e-12 * (abs(value) + 8.0)
    return np.flatnonzero(tangent >= high * (1.0 - SCREEN_WINDOW) - noise)


def _along(v: np.ndarray, R: np.ndarray, j: int) -> np.ndarray:
    """Per sample, ``v`` (N, 3) dotted with column j of R: one rotation (3, 3) or one per
    sample (N, 3, 3); shape (N,)."""
    along: np.ndarray = v @ R[:, j] if R.ndim == 2 else np.einsum("ni,ni->n", v, R[:, :, j])
    return along
