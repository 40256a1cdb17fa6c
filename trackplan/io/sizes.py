"""Size limits of a case, derived from the memory a plan and a search need.

A case that validates must plan, or be refused here with exit code 2, not run out of
memory half-way. The two sizes that grow without bound are the number of trajectory
samples (path length / (speed · Ts)) and the number of candidate × grid-point pairs a
search holds at once (population × path length / grid step). Both are bounded by
:data:`MEMORY_BUDGET` with the per-item costs measured on the shipped cases (see
``docs/guarantees.md``), with a margin.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

from trackplan.io.yaml_input import Problem
from trackplan.paths.specs import ArcSpec, LineSpec, PointsSpec, SegmentSpec

MEMORY_BUDGET = 2**30
"""Working memory a plan or a search may count on, bytes (1 GiB)."""

BYTES_PER_SAMPLE_JOINT = 700
"""Memory per trajectory sample and joint while planning and checking, bytes (measured
190 for a 6-joint arm at 1.1 KiB a sample; the margin covers the between-sample check)."""

BYTES_PER_CANDIDATE_POINT = 4096
"""Memory per candidate and screening grid point during a search, bytes (measured 2.6 KiB)."""

GRID_STEP = 2e-3
"""Arc-length step of the search's screening grid, m (planning.plan.GEOMETRIC_STEP)."""

POINTS_PER_TURN = 16
"""Fewest screening grid points one turn of an arc needs."""

MAX_SAMPLE_TIME = 0.05
"""Longest controller period accepted, s: 20 Hz, slower than any robot controller."""

MAX_POINTS_ROWS = 2**20
"""Most lines of a points file (1,048,576; comments and blank lines count): a curve sampled
every 0.25 mm over the longest path a search can hold, parsed in about a second."""

MAX_POINTS_BYTES = 2**27
"""Largest points file, bytes (128 MiB: 128 characters a line at the most lines)."""

MAX_TRAJECTORY_BYTES = 2**29
"""Largest ``trajectory.csv`` that ``check`` reads, bytes (512 MiB): the longest plan any
robot may have (:func:`max_samples` rows) with every column a run writes (about 600
characters a row for six joints) takes some 150 MiB."""


def max_samples(n_dof: int) -> int:
    """Most trajectory samples a plan of an ``n_dof``-joint robot may have."""
    return MEMORY_BUDGET // (BYTES_PER_SAMPLE_JOINT * max(n_dof, 1))


def path_length(start: np.ndarray, segments: Sequence[SegmentSpec]) -> tuple[float, list[float]]:
    """Length of the path as given (lines, arcs, polylines) and each segment's, m."""
    current = np.asarray(start, dtype=float)
    lengths: list[float] = []
    for spec in segments:
        if isinstance(spec, LineSpec):
            lengths.append(float(np.linalg.norm(spec.to - current)))
            current = spec.to
        elif isinstance(spec, ArcSpec):
            axis = spec.normal / np.linalg.norm(spec.normal)
            radius_vector = current - spec.center
            radius = float(np.linalg.norm(radius_vector - (radius_vector @ axis) * axis))
            lengths.append(radius * abs(spec.angle))
            rotation = _rotation(axis, spec.angle)
            current = spec.center + rotation @ radius_vector
        elif isinstance(spec, PointsSpec):
            points = np.vstack([current[None], spec.points])
            lengths.append(float(np.sum(np.linalg.norm(np.diff(points, axis=0), axis=1))))
            current = spec.points[-1]
    return float(sum(lengths)), lengths


def _rotation(axis: np.ndarray, angle: float) -> np.ndarray:
    """Rotation matrix about a unit axis (Rodrigues)."""
    k = np.array([[0, -axis[2], axis[1]], [axis[2], 0, -axis[0]], [-axis[1], axis[0], 0]])
    return np.eye(3) + math.sin(angle) * k + (1 - math.cos(angle)) * (k @ k)


def size_problems(
    start: np.ndarray,
    segments: Sequence[SegmentSpec],
    *,
    n_dof: int,
    rated_speed: float,
    sample_time: float,
    population: int,
) -> list[Problem]:
    """Problems of a case too large to plan or search in :data:`MEMORY_BUDGET`.

    Parameters
    ----------
    start, segments
        The path (the segments already checked for degenerate geometry).
    n_dof
        Joints of the robot.
    rated_speed, sample_time
        v_r (m/s) and Ts (s): the trajectory has at least length / (v_r · Ts) samples.
    population
        Candidates a search evaluates at once.

    Returns
    -------
    list of Problem
        Located at the arc angle, the segment, ``task.sample_time`` or
        ``optimizer.population``, each stating the limit and the memory it comes from.
    """
    problems: list[Problem] = []
    budget = f"{MEMORY_BUDGET / 2**30:g} GiB"
    grid_max = MEMORY_BUDGET // BYTES_PER_CANDIDATE_POINT // 2  # a population of at least 2
    max_turns = grid_max // POINTS_PER_TURN
    for i, spec in enumerate(segments):
        if isinstance(spec, ArcSpec) and abs(spec.angle) > 2 * math.pi * max_turns:
            problems.append(
                (
                    ("path", "segments", i, "arc", "angle"),
                    f"expected at most {max_turns} turns (|angle| ≤ {2 * math.pi * max_turns:.6g}"
                    f" rad: {POINTS_PER_TURN} grid points a turn in {budget}), "
                    f"got {abs(spec.angle):.6g} rad",
                )
            )
    if problems:
        return problems
    length, lengths = path_length(start, segments)
    max_length = grid_max * GRID_STEP
    if not math.isfinite(length) or length > max_length:
        longest = int(np.argmax(lengths)) if lengths else 0
        return [
            (
                ("path", "segments", longest),
                f"the path is {length:.6g} m long, more than {max_length:.6g} m (a search grid "
                f"point every {GRID_STEP * 1e3:g} mm for 2 candidates in {budget}); "
                "split the job into shorter paths",
            )
        ]
    samples = length / (rated_speed * sample_time)
    limit = max_samples(n_dof)
    if samples > limit:
        problems.append(
            (
                ("task", "sample_time"),
                f"the trajectory would have at least {samples:.4g} samples (path length "
                f"{length:.4g} m / (rated speed × sample time)), more than the {limit} "
                f"that fit in {budget} for {n_dof} joints; raise the sample time or the speed, "
                "or shorten the path",
            )
        )
    grid_points = max(length / GRID_STEP, 1.0)
    max_population = int(MEMORY_BUDGET // (BYTES_PER_CANDIDATE_POINT * grid_points))
    if population > max_population:
        problems.append(
            (
                ("optimizer", "population"),
                f"expected at most {max_population} candidates: {grid_points:.0f} screening "
                f"grid points each fit {max_population} times in {budget}, got {population}",
            )
        )
    return problems
