"""Small studies and an in-process Dask cluster shared by the study tests."""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path

import pytest

from tests.conftest import CASES

TINY = """
set:
  optimizer.budget: [20]
  optimizer.population: [10]
  optimizer.restarts: [1]
"""
"""Study settings that make each job a search of 20 placements (about a second)."""

UNREACHABLE_CASE = """
name: out-of-reach
robot: puma560
path:
  start: [0, 0, 0]
  segments:
    - line: {to: [0.1, 0, 0]}
task: {rated_speed: 0.1}
placement: {x: [0.9, 0.95], y: [0.9, 0.95], z: [0.9, 0.95]}
"""
"""A valid case file whose search raises: no placement of its box lies within reach."""


def write_study(folder: Path, body: str, tiny: bool = True) -> Path:
    """A study file ``study.yaml`` in ``folder`` (with the tiny search settings)."""
    file = folder / "study.yaml"
    file.write_text(body + (TINY if tiny else ""), encoding="utf-8")
    return file


def six_jobs(folder: Path) -> Path:
    """Two shipped cases × three seeds on the PUMA560."""
    body = f"cases: ['{CASES}/paper-corner.yaml', '{CASES}/paper-circle.yaml']\nseeds: [0, 1, 2]\n"
    return write_study(folder, body)


@pytest.fixture(scope="module")
def client() -> Iterator[object]:
    """A Dask client on an in-process cluster: one worker, two threads."""
    from distributed import Client, LocalCluster

    with (
        LocalCluster(
            processes=False, n_workers=1, threads_per_worker=2, dashboard_address=None
        ) as cluster,
        Client(cluster) as connected,
    ):
        yield connected
