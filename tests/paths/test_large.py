"""A 20,000-point sampled helix plans and checks end to end (the sizes of a scanned seam),
and the spatial index finds on a finely sampled path exactly the pieces a dense search finds."""

from __future__ import annotations

import numpy as np
import pytest

from tests.large_paths import HELIX_PLACEMENT, helix_points, write_helix_case
from trackplan.io.case_file import load_case
from trackplan.paths import NominalPath, PointsSpec
from trackplan.paths.path_geometry import PathGeometry
from trackplan.planning.plan import check, plan


@pytest.mark.slow
def test_a_20k_point_helix_plans_feasibly_and_rechecks(tmp_path):
    case = load_case(write_helix_case(tmp_path, 20_000))
    geometry = PathGeometry.from_case(case)
    assert geometry.nominal.n_pieces == 20_000
    result = plan(case, np.array(HELIX_PLACEMENT), geometries={(0, False): geometry})
    assert result.feasible, result.message
    assert 0.0 < result.check.max_tracking_error <= case.task.tolerance
    report = check(case, np.array(HELIX_PLACEMENT), result.trajectory.q, case.task.sample_time)
    assert report.success
    assert report.max_tracking_error == result.check.max_tracking_error


def test_candidates_on_a_finely_sampled_helix_equal_the_dense_ones():
    """Pieces of 0.1 mm at a slack of 1 mm: many balls hold more than the first query's 32
    chunks and are asked again for 128; points farther out go ball by ball."""
    vertices = helix_points(20_000)[:1_500]
    nominal = NominalPath.from_specs(vertices[0], [PointsSpec(vertices[1:])])
    rng = np.random.default_rng(5)
    on = vertices[rng.integers(0, len(vertices), 300)]
    scale = np.array([3e-4, 1e-3, 4e-3])[rng.integers(0, 3, len(on))]
    points = on + scale[:, None] * rng.standard_normal(on.shape)
    slack = 1e-3
    found = nominal.index.candidates(points, slack)
    table = nominal.table
    rows = np.repeat(np.arange(len(points)), table.n_pieces)
    pieces = np.tile(np.arange(table.n_pieces), len(points))
    distance = table.project_on(points[rows], pieces)[1].reshape(len(points), -1)
    nearest = distance.min(axis=1)
    np.testing.assert_allclose(found.nearest, nearest, rtol=0, atol=1e-15)
    assert np.all(np.diff(found.row) >= 0)
    for b in range(len(points)):
        expected = np.flatnonzero(distance[b] <= nearest[b] + slack)
        np.testing.assert_array_equal(found.piece[found.row == b], expected)
    assert np.bincount(found.row).max() > 32  # some balls needed the second query or more
