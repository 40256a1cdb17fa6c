"""A 20,000-point sampled helix plans and checks end to end (the sizes of a scanned seam)."""

from __future__ import annotations

import numpy as np
import pytest

from tests.large_paths import HELIX_PLACEMENT, write_helix_case
from trackplan.io.case_file import load_case
from trackplan.paths.path_geometry import PathGeometry
from trackplan.planning.plan import check_case_trajectory, plan_placement


@pytest.mark.slow
def test_a_20k_point_helix_plans_feasibly_and_rechecks(tmp_path):
    case = load_case(write_helix_case(tmp_path, 20_000))
    geometry = PathGeometry.from_case(case)
    assert geometry.nominal.n_pieces == 20_000
    result = plan_placement(case, np.array(HELIX_PLACEMENT), geometry=geometry)
    assert result.feasible, result.message
    assert 0.0 < result.check.max_tracking_error <= case.task.tolerance
    report = check_case_trajectory(
        case, np.array(HELIX_PLACEMENT), result.trajectory.q, case.task.sample_time
    )
    assert report.success
    assert report.max_tracking_error == result.check.max_tracking_error
