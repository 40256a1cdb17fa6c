"""Random nominal paths for property tests: lines, arcs (some closed) and sampled curves."""

from __future__ import annotations

import numpy as np
from hypothesis import strategies as st

from trackplan.paths import ArcSpec, LineSpec, NominalPath, PointsSpec


def _unit(rng: np.random.Generator) -> np.ndarray:
    v = rng.normal(size=3)
    return v / np.linalg.norm(v)


def random_nominal(seed: int, n_segments: int) -> NominalPath:
    """A path of ``n_segments`` random lines, arcs (up to 1.5 turns) and sampled curves.

    Consecutive segments meet at random angles, sharp reversals excluded (the case loader
    refuses a sampled curve that doubles back); sampled curves are wiggly polylines of 3 to
    400 points, some of them nearly straight, some crossing earlier parts of the path.
    """
    rng = np.random.default_rng(seed)
    current = np.zeros(3)
    segments: list = []
    tangent = _unit(rng)
    for _ in range(n_segments):
        kind = rng.choice(["line", "arc", "points"])
        if kind == "line":
            direction = _unit(rng)
            if direction @ tangent < -0.9:
                direction = -direction
            end = current + rng.uniform(0.005, 0.3) * direction
            segments.append(LineSpec(end))
            tangent, current = direction, end
        elif kind == "arc":
            normal = _unit(rng)
            radial = _unit(rng)
            radial -= (radial @ normal) * normal
            radial /= np.linalg.norm(radial)
            center = current - rng.uniform(0.01, 0.2) * radial
            angle = rng.choice([-1.0, 1.0]) * rng.uniform(0.1, 3 * np.pi)
            arc = NominalPath.from_specs(current, [ArcSpec(center, normal, angle)])
            segments.append(ArcSpec(center, normal, angle))
            tangent = arc.table.end_tangents()[-1]
            current = arc.table.evaluate(np.array([arc.length]))[0].position[0]
        else:
            n = int(rng.integers(3, 400))
            step = rng.uniform(2e-4, 5e-3)
            wiggle = rng.uniform(0.0, 0.3)
            directions = [tangent]
            for _ in range(n - 1):
                d = directions[-1] + wiggle * rng.normal(size=3)
                directions.append(d / np.linalg.norm(d))
            points = current + step * np.cumsum(directions, axis=0)
            segments.append(PointsSpec(points))
            tangent = directions[-1]
            current = points[-1]
    return NominalPath.from_specs(np.zeros(3), segments)


def points_near(nominal: NominalPath, seed: int, n: int, scale: float) -> np.ndarray:
    """``n`` points near the path: on it at random arc lengths, moved by ~``scale`` (m)."""
    rng = np.random.default_rng(seed)
    s = np.sort(rng.uniform(0.0, nominal.length, n))
    on = nominal.evaluate(s)[0].position
    return on + rng.normal(scale=scale, size=on.shape)


paths = st.tuples(st.integers(0, 2**31), st.integers(1, 6))
"""(seed, number of segments) of :func:`random_nominal`."""
