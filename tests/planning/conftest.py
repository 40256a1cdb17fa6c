"""Planned trajectories shared by the planning tests (planned once per session)."""

from __future__ import annotations

import numpy as np
import pytest

from tests.conftest import CASES
from trackplan.io.case_file import load_case
from trackplan.paths.path_geometry import PathGeometry
from trackplan.planning.plan import plan


@pytest.fixture(scope="session")
def corner_case():
    """The paper's corner case."""
    return load_case(CASES / "paper-corner.yaml")


@pytest.fixture(scope="session")
def corner_geometry(corner_case):
    """Nominal and planned paths of the corner case."""
    return PathGeometry.from_case(corner_case)


@pytest.fixture(scope="session")
def corner_plan(corner_case, corner_geometry):
    """The corner case planned at its example placement (smooth timing)."""
    return plan(corner_case, corner_case.bounds.example, geometries={(0, False): corner_geometry})


@pytest.fixture(scope="session")
def three_segment_case(corner_case, tmp_path_factory):
    """A path of three lines, to skip the middle one."""
    text = (CASES / "paper-corner.yaml").read_text()
    text = text.replace(
        "    - line: {to: [0.3, 0, 0.5]}",
        "    - line: {to: [0.5, 0, 0.15]}\n    - line: {to: [0.2, 0, 0.15]}",
    )
    file = tmp_path_factory.mktemp("three") / "three.yaml"
    file.write_text(text)
    return load_case(file)


def placement_of(result) -> np.ndarray:
    """The placement of a plan result."""
    return np.asarray(result.placement)
