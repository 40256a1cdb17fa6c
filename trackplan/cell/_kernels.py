"""Compiled screening kernels: signed distances between capsules and primitive bodies.

Every distance is signed: positive when apart, negative when the bodies overlap. For a
capsule (segment ``a``–``b``, radius r) against a convex solid the kernels return
``min over the segment of sd(p) − r``, ``sd`` the signed distance to the solid: the exact
distance when apart, a graded overlap measure when not. Shape codes are
:class:`trackplan.cell.model.Shape`.
"""

from __future__ import annotations

import numba
import numpy as np

PLANE, BOX, CYLINDER, SPHERE, CAPSULE = 0, 1, 2, 3, 4
GOLDEN_STEPS = 60
"""Golden-section steps on the segment parameter: the bracket shrinks to 0.618^60 ≈ 3e-13."""
OVERLAP_STEPS = 16
"""Golden-section steps for the overlap measure of a segment inside a box (a grade, not a
distance: the exact check measures penetration depth with the exact library)."""
INV_PHI = 0.6180339887498949


@numba.njit(cache=True, inline="always")
def _segment_origin(a: np.ndarray, b: np.ndarray) -> float:
    """Distance from the origin to segment a–b."""
    d0, d1, d2 = b[0] - a[0], b[1] - a[1], b[2] - a[2]
    w0, w1, w2 = -a[0], -a[1], -a[2]
    dd = d0 * d0 + d1 * d1 + d2 * d2
    t = 0.0
    if dd > 0.0:
        t = min(1.0, max(0.0, (w0 * d0 + w1 * d1 + w2 * d2) / dd))
    e0, e1, e2 = w0 - t * d0, w1 - t * d1, w2 - t * d2
    return np.sqrt(e0 * e0 + e1 * e1 + e2 * e2)


@numba.njit(cache=True)
def segment_segment(p0: np.ndarray, p1: np.ndarray, q0: np.ndarray, q1: np.ndarray) -> float:
    """Distance between segments p0–p1 and q0–q1 (Ericson, Real-Time Collision Detection 5.1.9)."""
    return _segment_segment(
        (p0[0], p0[1], p0[2]),
        (p1[0] - p0[0], p1[1] - p0[1], p1[2] - p0[2]),
        (q0[0], q0[1], q0[2]),
        (q1[0] - q0[0], q1[1] - q0[1], q1[2] - q0[2]),
    )


@numba.njit(cache=True, inline="always")
def _segment_segment(
    p0: tuple[float, float, float],
    d1: tuple[float, float, float],
    q0: tuple[float, float, float],
    d2: tuple[float, float, float],
) -> float:
    """Distance between segments p0 + s·d1 and q0 + t·d2, s, t in [0, 1] (no allocation)."""
    r = (p0[0] - q0[0], p0[1] - q0[1], p0[2] - q0[2])
    a = d1[0] * d1[0] + d1[1] * d1[1] + d1[2] * d1[2]
    e = d2[0] * d2[0] + d2[1] * d2[1] + d2[2] * d2[2]
    f = d2[0] * r[0] + d2[1] * r[1] + d2[2] * r[2]
    eps = 1e-300
    if a <= eps and e <= eps:
        s = 0.0
        t = 0.0
    elif a <= eps:
        s = 0.0
        t = min(1.0, max(0.0, f / e))
    else:
        c = d1[0] * r[0] + d1[1] * r[1] + d1[2] * r[2]
        if e <= eps:
            t = 0.0
            s = min(1.0, max(0.0, -c / a))
        else:
            b = d1[0] * d2[0] + d1[1] * d2[1] + d1[2] * d2[2]
            denom = a * e - b * b
            s = min(1.0, max(0.0, (b * f - c * e) / denom)) if denom > 1e-14 * a * e else 0.0
            t = (b * s + f) / e
            if t < 0.0:
                t = 0.0
                s = min(1.0, max(0.0, -c / a))
            elif t > 1.0:
                t = 1.0
                s = min(1.0, max(0.0, (b - c) / a))
    x0 = p0[0] + d1[0] * s - q0[0] - d2[0] * t
    x1 = p0[1] + d1[1] * s - q0[1] - d2[1] * t
    x2 = p0[2] + d1[2] * s - q0[2] - d2[2] * t
    return np.sqrt(x0 * x0 + x1 * x1 + x2 * x2)


@numba.njit(cache=True, inline="always")
def _box_sd(x: float, y: float, z: float, h: np.ndarray) -> float:
    """Signed distance of a point to a centred box of half extents h."""
    e0 = abs(x) - h[0]
    e1 = abs(y) - h[1]
    e2 = abs(z) - h[2]
    o0, o1, o2 = max(e0, 0.0), max(e1, 0.0), max(e2, 0.0)
    outside = np.sqrt(o0 * o0 + o1 * o1 + o2 * o2)
    return outside + min(max(e0, max(e1, e2)), 0.0)


@numba.njit(cache=True, inline="always")
def _cylinder_sd(x: float, y: float, z: float, radius: float, half: float) -> float:
    """Signed distance of a point to a cylinder on the z axis."""
    er = np.sqrt(x * x + y * y) - radius
    ez = abs(z) - half
    o0, o1 = max(er, 0.0), max(ez, 0.0)
    return np.sqrt(o0 * o0 + o1 * o1) + min(max(er, ez), 0.0)


@numba.njit(cache=True)
def _golden_min(
    a: np.ndarray, d: np.ndarray, kind: int, size: np.ndarray, steps: int = GOLDEN_STEPS
) -> float:
    """Minimum over t in [0, 1] of the (convex) signed distance of a + t·d to a box or cylinder."""
    lo, hi = 0.0, 1.0
    t1 = hi - INV_PHI * (hi - lo)
    t2 = lo + INV_PHI * (hi - lo)
    if kind == BOX:
        f1 = _box_sd(a[0] + t1 * d[0], a[1] + t1 * d[1], a[2] + t1 * d[2], size)
        f2 = _box_sd(a[0] + t2 * d[0], a[1] + t2 * d[1], a[2] + t2 * d[2], size)
    else:
        f1 = _cylinder_sd(a[0] + t1 * d[0], a[1] + t1 * d[1], a[2] + t1 * d[2], size[0], size[1])
        f2 = _cylinder_sd(a[0] + t2 * d[0], a[1] + t2 * d[1], a[2] + t2 * d[2], size[0], size[1])
    for _ in range(steps):
        if f1 <= f2:
            hi = t2
            t2 = t1
            f2 = f1
            t1 = hi - INV_PHI * (hi - lo)
            x, y, z = a[0] + t1 * d[0], a[1] + t1 * d[1], a[2] + t1 * d[2]
            f1 = _box_sd(x, y, z, size) if kind == BOX else _cylinder_sd(x, y, z, size[0], size[1])
        else:
            lo = t1
            t1 = t2
            f1 = f2
            t2 = lo + INV_PHI * (hi - lo)
            x, y, z = a[0] + t2 * d[0], a[1] + t2 * d[1], a[2] + t2 * d[2]
            f2 = _box_sd(x, y, z, size) if kind == BOX else _cylinder_sd(x, y, z, size[0], size[1])
    best = min(f1, f2)
    # the ends, where a convex minimum on the boundary is exact
    for t in (0.0, 1.0):
        x, y, z = a[0] + t * d[0], a[1] + t * d[1], a[2] + t * d[2]
        f = _box_sd(x, y, z, size) if kind == BOX else _cylinder_sd(x, y, z, size[0], size[1])
        best = min(best, f)
    return best


@numba.njit(cache=True)
def _segment_box(a: np.ndarray, d: np.ndarray, h: np.ndarray, ts: np.ndarray) -> float:
    """Signed distance from segment a + t·d, t in [0, 1], to a centred box of half extents h.

    Apart: exact. Squared distance is piecewise quadratic in t, with breaks where the
    point crosses a face plane; each piece is minimised in closed form. Overlapping: the
    least signed distance along the segment (golden section on a convex function).
    """
    ts = np.empty(8)
    ts[0] = 0.0
    n = 1
    for i in range(3):
        if d[i] != 0.0:
            for side in (-1.0, 1.0):
                t = (side * h[i] - a[i]) / d[i]
                if 0.0 < t < 1.0:
                    ts[n] = t
                    n += 1
    ts[n] = 1.0
    n += 1
    for i in range(2, n - 1):  # insertion sort of the breaks
        value = ts[i]
        j = i - 1
        while j >= 1 and ts[j] > value:
            ts[j + 1] = ts[j]
            j -= 1
        ts[j + 1] = value
    best = np.inf
    for k in range(n - 1):
        t0, t1 = ts[k], ts[k + 1]
        tm = 0.5 * (t0 + t1)
        qa, qb, qc = 0.0, 0.0, 0.0
        for i in range(3):
            x = a[i] + tm * d[i]
            if x > h[i]:
                c = a[i] - h[i]
            elif x < -h[i]:
                c = a[i] + h[i]
            else:
                continue
            qa += d[i] * d[i]
            qb += 2.0 * d[i] * c
            qc += c * c
        t = t0
        if qa > 0.0:
            t = min(t1, max(t0, -qb / (2.0 * qa)))
        value = (qa * t + qb) * t + qc
        # the piece's ends as well (round-off at the breaks)
        value = min(value, (qa * t0 + qb) * t0 + qc, (qa * t1 + qb) * t1 + qc)
        best = min(best, value)
    if best > 0.0:
        return np.sqrt(best)
    return min(0.0, _golden_min(a, d, BOX, h, OVERLAP_STEPS))


@numba.njit(cache=True)
def capsule_body(
    a_world: np.ndarray,
    b_world: np.ndarray,
    radius: float,
    kind: int,
    size: np.ndarray,
    T_body_world: np.ndarray,
) -> float:
    """Signed distance between a capsule (world end points, radius) and one body.

    ``T_body_world`` (3, 4) maps world points into the body frame.
    """
    return _capsule_body(a_world, b_world, radius, kind, size, T_body_world, np.empty((4, 8)))


@numba.njit(cache=True, inline="always")
def _capsule_body(
    a_world: np.ndarray,
    b_world: np.ndarray,
    radius: float,
    kind: int,
    size: np.ndarray,
    T_body_world: np.ndarray,
    scratch: np.ndarray,
) -> float:
    """:func:`capsule_body` with scratch space (4, 8) supplied by the caller."""
    a = scratch[0]
    b = scratch[1]
    d = scratch[2]
    for r in range(3):
        a[r] = (
            T_body_world[r, 0] * a_world[0]
            + T_body_world[r, 1] * a_world[1]
            + T_body_world[r, 2] * a_world[2]
            + T_body_world[r, 3]
        )
        b[r] = (
            T_body_world[r, 0] * b_world[0]
            + T_body_world[r, 1] * b_world[1]
            + T_body_world[r, 2] * b_world[2]
            + T_body_world[r, 3]
        )
    if kind == PLANE:
        return min(a[2], b[2]) - radius
    if kind == SPHERE:
        return _segment_origin(a, b) - size[0] - radius
    if kind == CAPSULE:
        return (
            _segment_segment(
                (a[0], a[1], a[2]),
                (b[0] - a[0], b[1] - a[1], b[2] - a[2]),
                (0.0, 0.0, -size[1]),
                (0.0, 0.0, 2.0 * size[1]),
            )
            - size[0]
            - radius
        )
    for r in range(3):
        d[r] = b[r] - a[r]
    if kind == BOX:
        return _segment_box(a, d, size, scratch[3]) - radius
    return _golden_min(a, d, CYLINDER, size) - radius


@numba.njit(cache=True, inline="always")
def _world_segments(
    frames: np.ndarray, frame: np.ndarray, segment: np.ndarray, out: np.ndarray
) -> None:
    """Capsule end points in the world of one sample: frames (F, 3, 4) → out (K, 2, 3)."""
    for k in range(len(frame)):
        T = frames[frame[k]]
        for e in range(2):
            for r in range(3):
                out[k, e, r] = (
                    T[r, 0] * segment[k, e, 0]
                    + T[r, 1] * segment[k, e, 1]
                    + T[r, 2] * segment[k, e, 2]
                    + T[r, 3]
                )


@numba.njit(cache=True)
def screen_pairs(
    frames: np.ndarray,
    frame: np.ndarray,
    segment: np.ndarray,
    radius: np.ndarray,
    kind: np.ndarray,
    size: np.ndarray,
    T_body_world: np.ndarray,
    group: np.ndarray,
    pair_capsule: np.ndarray,
    pair_body: np.ndarray,
    self_pairs: np.ndarray,
) -> tuple[np.ndarray, np.ndarray]:
    """Signed distances of every capsule–body pair and self pair at every sample.

    Parameters
    ----------
    frames
        Chain frames per sample, shape (N, F, 3, 4) (rows of the 4×4 transforms).
    frame, segment, radius
        Capsules: frame index (K,), end points in their frames (K, 2, 3), radii (K,).
    kind, size
        Bodies: shape codes (O,) and parameters (O, 3).
    T_body_world
        World → body transforms per group (placement), shape (G, O, 3, 4).
    group
        The group of each sample, shape (N,).
    pair_capsule, pair_body
        Capsule–body pairs to check, shape (P,) each.
    self_pairs
        Capsule–capsule pairs to check, shape (Q, 2).

    Returns
    -------
    tuple of numpy.ndarray
        Shapes (N, P) and (N, Q), m.
    """
    n_samples = frames.shape[0]
    out = np.empty((n_samples, len(pair_capsule)))
    out_self = np.empty((n_samples, len(self_pairs)))
    world = np.empty((len(frame), 2, 3))
    scratch = np.empty((4, 8))
    for s in range(n_samples):
        _world_segments(frames[s], frame, segment, world)
        g = group[s]
        for p in range(len(pair_capsule)):
            k = pair_capsule[p]
            o = pair_body[p]
            out[s, p] = _capsule_body(
                world[k, 0], world[k, 1], radius[k], kind[o], size[o], T_body_world[g, o], scratch
            )
        for p in range(len(self_pairs)):
            i = self_pairs[p, 0]
            j = self_pairs[p, 1]
            a0, b0, a1, b1 = world[i, 0], world[i, 1], world[j, 0], world[j, 1]
            out_self[s, p] = (
                _segment_segment(
                    (a0[0], a0[1], a0[2]),
                    (b0[0] - a0[0], b0[1] - a0[1], b0[2] - a0[2]),
                    (a1[0], a1[1], a1[2]),
                    (b1[0] - a1[0], b1[1] - a1[1], b1[2] - a1[2]),
                )
                - radius[i]
                - radius[j]
            )
    return out, out_self


@numba.njit(cache=True)
def capsule_body_batch(
    a: np.ndarray,
    b: np.ndarray,
    radius: np.ndarray,
    kind: np.ndarray,
    size: np.ndarray,
    T_body_world: np.ndarray,
) -> np.ndarray:
    """:func:`capsule_body` over aligned arrays: a, b (N, 3), radius (N,), kind (N,),
    size (N, 3), T_body_world (N, 3, 4) → (N,)."""
    out = np.empty(len(a))
    scratch = np.empty((4, 8))
    for i in range(len(a)):
        out[i] = _capsule_body(a[i], b[i], radius[i], kind[i], size[i], T_body_world[i], scratch)
    return out
